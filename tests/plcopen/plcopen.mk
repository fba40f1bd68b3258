# PLCopen tests: ST programs driving the MC_* blocks over EPICPOS and
# APOSS-style axes on the simulated plant (c_blocks/sim_axis.st), compiled
# with $(STC) and run by the EPICPOS harness (see run.sh); with both
# compilers (the adapters own their devices: no block instance is passed as
# a parameter).
PLCOPEN_TESTS := $(wildcard tests/plcopen/t_*.st)

TESTS += test-plcopen
MATIEC_TESTS += test-plcopen

.PHONY: test-plcopen
test-plcopen: $(ST_LIB) $(STC)
	@mk/suite.sh $(RESULTS) plcopen env STC="$(STC)" STC_INC="$(STC_INC)" CC="$(CC)" \
	    CFLAGS="$(CFLAGS)" tests/plcopen/run.sh $(BUILD)/tests/plcopen $(ST_LIB) $(PLCOPEN_TESTS)
