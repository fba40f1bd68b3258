# CIA402DRIVE tests: the CiA 402 device against the standard's state machine
# and transition table written out in tests/cia402/tdrive.st, one PDO
# exchange per tick (run.sh; each program's CHECK lines say what is checked).
CIA402_TESTS := $(wildcard tests/cia402/t_*.st)

TESTS += test-cia402
MATIEC_TESTS += test-cia402

.PHONY: test-cia402
test-cia402: $(ST_LIB) $(STC)
	@mk/suite.sh $(RESULTS) cia402 env STC="$(STC)" STC_INC="$(STC_INC)" CC="$(CC)" \
	    CFLAGS="$(CFLAGS)" tests/cia402/run.sh $(BUILD)/tests/cia402 $(ST_LIB) $(CIA402_TESTS)
