# plcrt's tests (included from plc_runtime/part.mk). Check units built twice,
# plainly and with $(SAN); integration tests against a running plcrt.

RT_T := $(BUILD)/tests/runtime
RT_CHECK_LIBS := $(shell pkg-config --libs check 2>/dev/null || echo -lcheck -lsubunit -lm -lrt -lpthread)
RT_SRC_MAP := $(addprefix plc_runtime/,mbmap.c config.c program.c plc_image.c log.c io_backends.c io_multi.c io_modbus.c io_none.c io_sim.c) c_blocks/plant.c $(CO_BACKEND)
RT_SRC_CFG := $(addprefix plc_runtime/,config.c plc_image.c log.c io_backends.c io_multi.c io_modbus.c io_none.c io_sim.c) c_blocks/plant.c $(CO_BACKEND)
RT_SRC_RET := plc_runtime/retain.c plc_runtime/log.c
RT_SRC_TRACE := plc_runtime/trace.c plc_runtime/force.c plc_runtime/plc_image.c
RT_SRC_TRACEMB := $(RT_SRC_TRACE) $(addprefix plc_runtime/,tracemb.c mbmap.c scan.c stats.c log.c program.c)

define rt_unit
$(RT_T)/$(1): tests/runtime/$(1).c $(2) $$(PLCRT_HDRS)
	@mkdir -p $$(@D)
	$$(CC) $$(PLCRT_CFLAGS) -o $$@ tests/runtime/$(1).c $(2) $$(RT_CHECK_LIBS) $$(PLCRT_LIBS)
$(RT_T)/$(1)-san: tests/runtime/$(1).c $(2) $$(PLCRT_HDRS)
	@mkdir -p $$(@D)
	$$(CC) $$(PLCRT_CFLAGS) $$(SAN) -o $$@ tests/runtime/$(1).c $(2) $$(RT_CHECK_LIBS) $$(PLCRT_LIBS)
endef
$(eval $(call rt_unit,check_mbmap,$(RT_SRC_MAP)))
$(eval $(call rt_unit,check_config,$(RT_SRC_CFG)))
$(eval $(call rt_unit,check_retain,$(RT_SRC_RET)))
$(eval $(call rt_unit,check_plant,c_blocks/plant.c))
$(eval $(call rt_unit,check_plant_modes,c_blocks/plant.c))
$(eval $(call rt_unit,check_trace,$(RT_SRC_TRACE)))
$(eval $(call rt_unit,check_tracemb,$(RT_SRC_TRACEMB)))
RT_UNITS := check_mbmap check_config check_retain check_plant check_plant_modes check_trace check_tracemb
RT_UNIT_BINS := $(foreach u,$(RT_UNITS),$(RT_T)/$(u) $(RT_T)/$(u)-san)

.PHONY: test-runtime-units
test-runtime-units: $(RT_UNIT_BINS)
	@rc=0; for u in $(RT_UNITS); do \
	  TMPDIR=$(abspath $(RT_T)) mk/suite.sh $(RESULTS) runtime-$$u $(RT_T)/$$u || rc=1; \
	  TMPDIR=$(abspath $(RT_T)) mk/suite.sh $(RESULTS) runtime-$$u-san $(RT_T)/$$u-san || rc=1; \
	done; exit $$rc
TESTS += test-runtime-units

# image binding: the real compiler's output of st/iotest.st
$(eval $(call plcrt_program,rt_iotest,tests/runtime/st/iotest.st))
$(RT_T)/check_image: tests/runtime/check_image.c $(BUILD)/plc/rt_iotest/program.o $(PLCRT_B)/plc_image.o $(PLCRT_B)/program.o
	@mkdir -p $(@D)
	$(CC) $(PLCRT_CFLAGS) -o $@ $^ $(RT_CHECK_LIBS)

# the plant as an ST block (c_blocks/sim_axis.st) beside the sim backend
$(eval $(call plcrt_program,rt_simblock,$(C_BLOCKS_ST) tests/runtime/st/simblock.st))
$(RT_T)/check_sim_block: tests/runtime/check_sim_block.c $(BUILD)/plc/rt_simblock/program.o $(PLCRT_OBJ)
	@mkdir -p $(@D)
	$(CC) $(PLCRT_CFLAGS) -o $@ $^ $(RT_CHECK_LIBS) $(PLCRT_LIBS)

.PHONY: test-runtime-image
test-runtime-image: $(RT_T)/check_image $(RT_T)/check_sim_block $(STC)
	@rc=0; mk/suite.sh $(RESULTS) runtime-image $(RT_T)/check_image || rc=1; \
	mk/suite.sh $(RESULTS) runtime-sim-block $(RT_T)/check_sim_block || rc=1; \
	mk/suite.sh $(RESULTS) runtime-located-outside tests/runtime/located_outside.sh \
	  $(STC) $(STC_INC) $(RT_T)/outside $(CC) $(PLC_GEN_CFLAGS) || rc=1; exit $$rc
TESTS += test-runtime-image
MATIEC_TESTS += test-runtime-image

# integration: libmodbus's own random-test-client, pointed at the port the
# test picks (free at run time, so that several runs may share a machine)
RT_MB_EXAMPLES := /usr/share/doc/libmodbus-dev/examples
$(RT_T)/random-test-client: $(RT_MB_EXAMPLES)/random-test-client.c tests/runtime/tests.mk
	@mkdir -p $(@D)
	sed 's/1502)/atoi(getenv("MODBUS_PORT")))/' $< > $@.c
	$(CC) -O2 -w -o $@ $@.c $(shell pkg-config --cflags --libs libmodbus)

.PHONY: test-runtime-integration
test-runtime-integration: $(BUILD)/plc/rt_iotest/plcrt $(RT_T)/random-test-client
	@mk/suite.sh $(RESULTS) runtime-integration python3 tests/runtime/test_plcrt.py \
	  $(BUILD)/plc/rt_iotest/plcrt $(RT_T)/random-test-client auto $(abspath $(RT_T))/integration
TESTS += test-runtime-integration
STRESS_TESTS += test-runtime-integration
MATIEC_TESTS += test-runtime-integration
# overruns: a program made too slow over Modbus, counted as its own
$(eval $(call plcrt_program,rt_spin,tests/runtime/st/spin.st))
.PHONY: test-runtime-overrun
test-runtime-overrun: $(BUILD)/plc/rt_spin/plcrt
	@mk/suite.sh $(RESULTS) runtime-overrun python3 tests/runtime/test_overrun.py \
	  $(BUILD)/plc/rt_spin/plcrt $(abspath $(RT_T))/overrun
TESTS += test-runtime-overrun
STRESS_TESTS += test-runtime-overrun
# the configuration checked whole: --check-config and the start on
# temporary files (docs/config.md)
.PHONY: test-runtime-config
test-runtime-config: $(BUILD)/plc/rt_iotest/plcrt
	@mk/suite.sh $(RESULTS) runtime-config python3 tests/runtime/test_config.py \
	  $(BUILD)/plc/rt_iotest/plcrt $(abspath $(RT_T))/config
TESTS += test-runtime-config
STRESS_TESTS += test-runtime-config
# the Modbus server against misbehaving clients, and the 1 ms scan under a
# flood of them
$(eval $(call plcrt_program,rt_fast,tests/runtime/st/fast.st))
.PHONY: test-runtime-mbserver
test-runtime-mbserver: $(BUILD)/plc/rt_iotest/plcrt $(BUILD)/plc/rt_fast/plcrt
	@mk/suite.sh $(RESULTS) runtime-mbserver python3 tests/runtime/test_mbserver.py \
	  $(BUILD)/plc/rt_iotest/plcrt $(BUILD)/plc/rt_fast/plcrt $(abspath $(RT_T))/mbserver
TESTS += test-runtime-mbserver
STRESS_TESTS += test-runtime-mbserver
# program instances named p, axis and res0: matiec's instance macros stay in
# its resource file
$(eval $(call plcrt_program,rt_names,tests/runtime/st/names.st))
.PHONY: test-runtime-names
test-runtime-names: $(BUILD)/plc/rt_names/plcrt
	@mk/suite.sh $(RESULTS) runtime-names tests/runtime/names.sh $< $(RT_T)/names
TESTS += test-runtime-names
STRESS_TESTS += test-runtime-names
MATIEC_TESTS += test-runtime-names
# arrays, structures and block instances: retained, and exposed by IEC path
$(eval $(call plcrt_program,rt_aggregates,tests/runtime/st/aggregates.st))
.PHONY: test-runtime-aggregates
test-runtime-aggregates: $(BUILD)/plc/rt_aggregates/plcrt
	@mk/suite.sh $(RESULTS) runtime-aggregates python3 tests/runtime/test_aggregates.py $< $(abspath $(RT_T))/aggregates
TESTS += test-runtime-aggregates
STRESS_TESTS += test-runtime-aggregates
# the trace and forcing (docs/trace.md): plcrt on a program whose values
# are functions of the cycle, the register block with pymodbus, plctrace
$(eval $(call plcrt_program,rt_trace,tests/runtime/st/trace.st))
.PHONY: test-runtime-trace
test-runtime-trace: $(BUILD)/plc/rt_trace/plcrt
	@mk/suite.sh $(RESULTS) runtime-trace python3 tests/runtime/test_trace.py \
	  $(BUILD)/plc/rt_trace/plcrt $(abspath $(RT_T))/trace
TESTS += test-runtime-trace
STRESS_TESTS += test-runtime-trace
# every stop signal (SIGHUP, SIGQUIT too) the orderly way out, and a stop
# asked for during the start-up before any cycle (docs/runtime.md)
.PHONY: test-runtime-signals
test-runtime-signals: $(BUILD)/plc/rt_iotest/plcrt
	@mk/suite.sh $(RESULTS) runtime-signals python3 tests/runtime/test_signals.py \
	  $(BUILD)/plc/rt_iotest/plcrt $(abspath $(RT_T))/signals
TESTS += test-runtime-signals
STRESS_TESTS += test-runtime-signals
MATIEC_TESTS += test-runtime-signals
# the watchdog: a program that never returns puts the outputs in their safe
# state and stops plcrt (status 3); long cycles do not trip it
.PHONY: test-runtime-watchdog
test-runtime-watchdog: $(BUILD)/plc/rt_spin/plcrt
	@mk/suite.sh $(RESULTS) runtime-watchdog python3 tests/runtime/test_watchdog.py \
	  $(BUILD)/plc/rt_spin/plcrt $(abspath $(RT_T))/watchdog
TESTS += test-runtime-watchdog
STRESS_TESTS += test-runtime-watchdog
# fuzzing what plcrt takes from outside while it runs (tests/fuzz/fuzz_plcrt.c):
# Modbus requests into the map and the trace/forcing block with scan cycles
# between them, and retain files behind a valid checksum. Briefly in `make
# test`, longer in `make fuzz` (FUZZ_SECONDS).
FUZZ_CC ?= clang
RT_SRC_FUZZ := $(filter %.c,$(RT_SRC_MAP)) $(addprefix plc_runtime/,retain.c trace.c force.c tracemb.c scan.c stats.c)
$(BUILD)/fuzz/fuzz_plcrt: tests/fuzz/fuzz_plcrt.c $(RT_SRC_FUZZ) $(CO_BACKEND) $(PLCRT_HDRS)
	@mkdir -p $(dir $@)
	$(call say,CC,$@ (libFuzzer))
	$(Q)$(FUZZ_CC) -g -O1 -std=c11 -D_DEFAULT_SOURCE -D_GNU_SOURCE -I plc_runtime \
	  $(shell pkg-config --cflags libmodbus 2>/dev/null) -fsanitize=fuzzer,address,undefined \
	  -o $@ tests/fuzz/fuzz_plcrt.c $(RT_SRC_FUZZ) $(CO_BACKEND) $(PLCRT_LIBS)
RT_FUZZ_RUN = mkdir -p $(BUILD)/fuzz/corpus_plcrt && ASAN_OPTIONS=detect_leaks=0 $(BUILD)/fuzz/fuzz_plcrt \
	-rss_limit_mb=2048 -timeout=5 -max_len=2048 -artifact_prefix=$(BUILD)/fuzz/plcrt- \
	$(BUILD)/fuzz/corpus_plcrt tests/fuzz/corpus_plcrt
.PHONY: test-runtime-fuzz fuzz-plcrt
test-runtime-fuzz: $(BUILD)/fuzz/fuzz_plcrt
	@mk/suite.sh $(RESULTS) runtime-fuzz sh -c '$(RT_FUZZ_RUN) -max_total_time=15 > $(BUILD)/fuzz/plcrt.log 2>&1 \
	    && echo "PASS: plcrt (Modbus requests, trace and forcing, retain files) survives 15 s of fuzzing" \
	    || { tail -n 30 $(BUILD)/fuzz/plcrt.log; echo "FAIL: plcrt fuzzing found a crash (input in $(BUILD)/fuzz/plcrt-*)"; }'
TESTS += test-runtime-fuzz
FUZZES += fuzz-plcrt
fuzz-plcrt: $(BUILD)/fuzz/fuzz_plcrt
	$(RT_FUZZ_RUN) -max_total_time=$${FUZZ_SECONDS:-600}
