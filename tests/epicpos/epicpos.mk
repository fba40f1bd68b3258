# EPICPOS behaviour tests: ST programs driving the positioner against a plant
# model, compiled with $(STC) and run by harness.c (see run.sh).
EPICPOS_TESTS := $(wildcard tests/epicpos/t_*.st)

TESTS += test-epicpos
MATIEC_TESTS += test-epicpos

.PHONY: test-epicpos
test-epicpos: $(ST_LIB) $(STC)
	@mk/suite.sh $(RESULTS) epicpos env STC="$(STC)" STC_INC="$(STC_INC)" CC="$(CC)" \
	    CFLAGS="$(CFLAGS)" tests/epicpos/run.sh $(BUILD)/tests/epicpos $(ST_LIB) $(EPICPOS_TESTS)
