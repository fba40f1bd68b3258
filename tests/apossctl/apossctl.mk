# APOSSCTL tests: ST programs driving the APOSS controller part alone and in
# a closed loop on the simulated plant, compiled with $(STC) and run by the
# EPICPOS harness (see run.sh).
APOSSCTL_TESTS := $(wildcard tests/apossctl/t_*.st)

TESTS += test-apossctl
MATIEC_TESTS += test-apossctl

.PHONY: test-apossctl
test-apossctl: $(ST_LIB) $(STC)
	@mk/suite.sh $(RESULTS) apossctl env STC="$(STC)" STC_INC="$(STC_INC)" CC="$(CC)" \
	    CFLAGS="$(CFLAGS)" tests/apossctl/run.sh $(BUILD)/tests/apossctl $(ST_LIB) $(APOSSCTL_TESTS)
