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

# One short line per build step (`CC plc_runtime/scan.c`); `make V=1` shows
# the commands instead. A rule writes $(call say,CC,what) then $(Q)command.
V ?= 0
ifeq ($(V),1)
Q   :=
say  = @true
else
Q   := @
say  = @printf '  %-4s %s\n' '$(1)' '$(2)'
endif

# make test-matiec: the suites of MATIEC_TESTS built again with upstream
# matiec's iec2c (MATIEC_DIR: where it was built by hand, outside this
# tree; docs/stc.md) in build-matiec/, to show both compilers give the same
# results. Never part of `make test`.
ifeq ($(COMPILER),matiec)
STC     := mk/iec2c.sh
STC_INC := $(MATIEC_DIR)/lib/C
export MATIEC_DIR
# matiec's output is not written for -Wall -Werror
CFLAGS  := -std=gnu11 -O2 -g -D_DEFAULT_SOURCE -D_GNU_SOURCE -w
endif

ALL     :=
TESTS   :=
MATIEC_TESTS :=
STRESS_TESTS :=
BENCHES :=
FUZZES  :=
RUN_DEMO :=

.PHONY: all deps test run bench fuzz clean check-results test-matiec test-stress install deb
all:

include $(wildcard stc/part.mk) $(wildcard c_blocks/part.mk) $(wildcard st/part.mk)
include $(wildcard plc_runtime/part.mk) $(wildcard tests/part.mk)
include $(wildcard examples/part.mk) $(wildcard bench/part.mk)
include mk/install.mk

all: $(ALL)

deps:
	@mk/deps.sh

# Every suite runs even when one fails; the summary decides the exit status.
test:
	@mk/deps.sh all
	@$(MAKE) --no-print-directory all
	@rm -rf $(RESULTS) && mkdir -p $(RESULTS)
	@$(MAKE) --no-print-directory -k $(TESTS) || touch $(RESULTS)/.make-failed
	@mk/summary.sh $(RESULTS)

# make test-stress: the suites that start plcrt or time anything (each .mk
# adds them to STRESS_TESTS) while stress-ng keeps every core busy
# (docs/testing.md). Passing here is what says no check depends on the
# host's speed.
test-stress:
	@mk/deps.sh
	@$(MAKE) --no-print-directory all
	@rm -rf $(RESULTS) && mkdir -p $(RESULTS)
	@mk/stress.sh $(MAKE) --no-print-directory -k $(STRESS_TESTS) || touch $(RESULTS)/.make-failed
	@mk/summary.sh $(RESULTS)

test-matiec:
	@if [ -z "$(MATIEC_DIR)" ] || [ ! -x "$(MATIEC_DIR)/iec2c" ]; then \
	  echo "test-matiec: set MATIEC_DIR to the folder where matiec's iec2c was built (docs/stc.md says how)"; \
	  exit 2; fi
	@mk/deps.sh
	@rm -rf build-matiec/results && mkdir -p build-matiec/results
	@$(MAKE) --no-print-directory -k COMPILER=matiec BUILD=build-matiec \
	  RESULTS=build-matiec/results $(MATIEC_TESTS) || touch build-matiec/results/.make-failed
	@mk/summary.sh build-matiec/results

# make run: only what the runtime and the demo need (mk/deps.sh run), built
# on every core; make run PROJECT=dir: build and run a project outside the
# tree (plcrt-build)
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
run:
	@mk/deps.sh run
ifeq ($(PROJECT),)
	@$(MAKE) --no-print-directory -j$(JOBS) $(RUN_DEMO_BIN)
	@$(MAKE) --no-print-directory $(RUN_DEMO) RUN_WEB=mk/run_web.sh
else
	@./plcrt-build --run $(PROJECT)
endif

bench:
	@mk/deps.sh
	@$(MAKE) --no-print-directory all
	@$(MAKE) --no-print-directory $(BENCHES)

fuzz:
	@mk/deps.sh
	@$(MAKE) --no-print-directory $(FUZZES)

clean:
	rm -rf $(BUILD) build-matiec
