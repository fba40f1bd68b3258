# ISGDAMP tests (st/parts/isgdamp.st, docs/isg.md):
#  - test-isg: ST programs checking the part's behaviour (refusals, pass-through,
#    clamp, standstill, damping on the plant), run by the EPICPOS harness;
#  - test-isg-filters: the coefficients the part computes, dumped by coef.st and
#    evaluated with scipy against the specification (tests/isg/deps.pip).
ISG_TESTS := $(wildcard tests/isg/t_*.st)
ISG_T := $(BUILD)/tests/isg

TESTS += test-isg test-isg-filters
MATIEC_TESTS += test-isg

.PHONY: test-isg test-isg-filters
# the APOSSCTL runner builds and runs such programs; its lines relabelled
test-isg: $(ST_LIB) $(STC)
	@mk/suite.sh $(RESULTS) isg env STC="$(STC)" STC_INC="$(STC_INC)" CC="$(CC)" \
	    CFLAGS="$(CFLAGS)" bash -c 'set -o pipefail; tests/apossctl/run.sh "$$@" | \
	    sed "s#^\(PASS\|FAIL\): apossctl/#\1: isg/#"' run $(ISG_T) $(ST_LIB) $(ISG_TESTS)

$(ISG_T)/coef/dump: $(ST_LIB) $(STC) tests/isg/coef.st tests/isg/dump.c tests/common/plc_harness.h
	@rm -rf $(ISG_T)/coef && mkdir -p $(ISG_T)/coef
	cat $(ST_LIB) tests/isg/coef.st > $(ISG_T)/coef/all.st
	$(STC) -T $(ISG_T)/coef/c $(ISG_T)/coef/all.st
	srcs=$$(ls $(ISG_T)/coef/c/*.c | grep -v '/POUS\.c$$'); \
	$(CC) $(CFLAGS) -I $(STC_INC) -I $(ISG_T)/coef/c -I tests/common $$srcs tests/isg/dump.c -o $@ -lm

test-isg-filters: $(ISG_T)/coef/dump
	@mk/suite.sh $(RESULTS) isg-filters python3 tests/isg/test_filters.py $(ISG_T)/coef/dump
