# The compiler stc and its tests.
STC_SRCS := $(wildcard stc/*.c)
STC_OBJS := $(patsubst stc/%.c,$(BUILD)/stc/%.o,$(STC_SRCS))
STC_DEFS := -DSTC_INCLUDE_DIR='"$(abspath stc/include)"'

STC_BIN  := $(BUILD)/stc/stc
ALL += $(STC_BIN)

$(BUILD)/stc/%.o: stc/%.c stc/stc.h
	@mkdir -p $(dir $@)
	$(call say,CC,$<)
	$(Q)$(CC) $(CFLAGS) $(STC_DEFS) -c -o $@ $<

$(STC_BIN): $(STC_OBJS)
	$(call say,LD,$@)
	$(Q)$(CC) $(CFLAGS) -o $@ $^ -lm

# ---- unit tests of the compiler's stages (Check), plain and sanitized ----
STC_LIB_OBJS := $(filter-out $(BUILD)/stc/main.o,$(STC_OBJS))
STC_SAN_OBJS := $(patsubst $(BUILD)/stc/%.o,$(BUILD)/stc-san/%.o,$(STC_LIB_OBJS))
CHECK_LIBS := $(shell pkg-config --libs check 2>/dev/null || echo -lcheck -lsubunit -lm -lrt -lpthread)

$(BUILD)/stc-san/%.o: stc/%.c stc/stc.h
	@mkdir -p $(dir $@)
	$(call say,CC,$< (sanitized))
	$(Q)$(CC) $(CFLAGS) $(SAN) -O1 -c -o $@ $<

$(BUILD)/tests/check_stc: tests/stc_unit/check_stc.c $(STC_LIB_OBJS)
	@mkdir -p $(dir $@)
	$(call say,LD,$@)
	$(Q)$(CC) $(CFLAGS) -o $@ $^ $(CHECK_LIBS) -lm

$(BUILD)/tests/check_stc_san: tests/stc_unit/check_stc.c $(STC_SAN_OBJS)
	@mkdir -p $(dir $@)
	$(call say,LD,$@)
	$(Q)$(CC) $(CFLAGS) $(SAN) -O1 -o $@ $^ $(CHECK_LIBS) -lm

.PHONY: test-stc-unit test-stc-unit-san test-stc-fuzz bench-stc fuzz-stc
TESTS += test-stc-unit test-stc-unit-san test-stc-fuzz
test-stc-unit: $(BUILD)/tests/check_stc
	@mk/suite.sh $(RESULTS) stc-unit $<
test-stc-unit-san: $(BUILD)/tests/check_stc_san
	@ASAN_OPTIONS=detect_leaks=0 mk/suite.sh $(RESULTS) stc-unit-san $<

# ---- fuzzing stc with libFuzzer: briefly in `make test`, longer in `make fuzz` ----
FUZZ_CC := clang
$(BUILD)/fuzz/fuzz_stc: tests/fuzz/fuzz_stc.c $(STC_SRCS) stc/stc.h
	@mkdir -p $(dir $@)
	$(call say,CC,$@ (libFuzzer))
	$(Q)$(FUZZ_CC) -g -O1 -std=c11 -D_DEFAULT_SOURCE -fsanitize=fuzzer,address,undefined -o $@ tests/fuzz/fuzz_stc.c $(filter-out stc/main.c,$(STC_SRCS)) -lm

FUZZ_RUN = mkdir -p $(BUILD)/fuzz/corpus && ASAN_OPTIONS=detect_leaks=0 $(BUILD)/fuzz/fuzz_stc \
	-rss_limit_mb=2048 -timeout=5 -max_len=4096 -artifact_prefix=$(BUILD)/fuzz/ \
	$(BUILD)/fuzz/corpus tests/fuzz/corpus
test-stc-fuzz: $(BUILD)/fuzz/fuzz_stc
	@mk/suite.sh $(RESULTS) stc-fuzz sh -c '$(FUZZ_RUN) -max_total_time=30 > $(BUILD)/fuzz/last.log 2>&1 \
	    && echo "PASS: stc survives 30 s of fuzzing" || { tail -n 30 $(BUILD)/fuzz/last.log; echo "FAIL: stc fuzzing found a crash (input in $(BUILD)/fuzz/)"; }'
FUZZES += fuzz-stc
fuzz-stc: $(BUILD)/fuzz/fuzz_stc
	$(FUZZ_RUN) -max_total_time=$${FUZZ_SECONDS:-600}

# ---- benchmarks ----
BENCHES += bench-stc
bench-stc: $(STC)
	@bench/stc/run.sh $(abspath $(STC)) $(abspath $(STC_INC)) $(abspath $(BUILD))/bench/stc
