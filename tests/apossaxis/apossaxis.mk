# APOSSAXIS tests: the APOSS-style axis device on the simulated plant, tick by
# tick (1 tick = 1 ms), expected values from closed-form kinematics and the
# seed's rules (see run.sh and each program's CHECK lines).
APOSSAXIS_TESTS := $(wildcard tests/apossaxis/t_*.st)

TESTS += test-apossaxis
MATIEC_TESTS += test-apossaxis

.PHONY: test-apossaxis
test-apossaxis: $(ST_LIB) $(STC)
	@mk/suite.sh $(RESULTS) apossaxis env STC="$(STC)" STC_INC="$(STC_INC)" CC="$(CC)" \
	    CFLAGS="$(CFLAGS)" tests/apossaxis/run.sh $(BUILD)/tests/apossaxis $(ST_LIB) $(APOSSAXIS_TESTS)

# test-apossaxis-tune: the seed 001 tuning procedure (tools/aposs_tune.py) on
# the APOSS example under plcrt, over Modbus and the trace, then the test's
# own onset bisection and standard moves (about 1.5 min: some 45 moves in
# real time)
TESTS += test-apossaxis-tune
STRESS_TESTS += test-apossaxis-tune
.PHONY: test-apossaxis-tune
test-apossaxis-tune: $(BUILD)/plc/aposs/plcrt $(ST_LIB) $(STC)
	@mk/suite.sh $(RESULTS) apossaxis-tune env STC="$(abspath $(STC))" STC_INC="$(abspath $(STC_INC))" CC="$(CC)" \
	    CFLAGS="$(CFLAGS)" ST_LIB="$(abspath $(ST_LIB))" python3 tests/apossaxis/test_tune.py \
	    $(BUILD)/plc/aposs/plcrt examples/aposs/aposs.ini $(abspath $(BUILD))/tests/apossaxis-tune
