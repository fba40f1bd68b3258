# Top-level build. Each part adds its own rules in <part>/part.mk and appends
# to ALL (what `make` builds), TESTS (suites `make test` runs), BENCHES.
# Test suites write "PASS: name" / "FAIL: name" lines to build/results/.

BUILD   := build
CC      ?= gcc
CFLAGS  := -std=c11 -Wall -Wextra -Werror -O2 -g -D_DEFAULT_SOURCE -D_GNU_SOURCE
SAN     := -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all
STC     := $(BUILD)/stc/stc
STC_INC := stc/include
RESULTS := $(BUILD)/results

ALL     :=
TESTS   :=
BENCHES :=
FUZZES  :=
RUN_DEMO :=

.PHONY: all deps test run bench fuzz clean check-results
all:

include $(wildcard stc/part.mk) $(wildcard c_blocks/part.mk) $(wildcard st/part.mk)
include $(wildcard plc_runtime/part.mk) $(wildcard tests/part.mk)
include $(wildcard examples/part.mk) $(wildcard bench/part.mk)

all: $(ALL)

deps:
	@mk/deps.sh

# Every suite runs even when one fails; the summary decides the exit status.
test:
	@mk/deps.sh
	@$(MAKE) --no-print-directory all
	@rm -rf $(RESULTS) && mkdir -p $(RESULTS)
	@$(MAKE) --no-print-directory -k $(TESTS) || touch $(RESULTS)/.make-failed
	@mk/summary.sh $(RESULTS)

run:
	@mk/deps.sh
	@$(MAKE) --no-print-directory all
	@$(MAKE) --no-print-directory $(RUN_DEMO)

bench:
	@mk/deps.sh
	@$(MAKE) --no-print-directory all
	@$(MAKE) --no-print-directory $(BENCHES)

fuzz:
	@mk/deps.sh
	@$(MAKE) --no-print-directory $(FUZZES)

clean:
	rm -rf $(BUILD)
