# Test suites of tests/. Each part of the test tree adds its own block.

# ---- stc: ST programs run tick by tick, error diagnostics, robustness ----
STC_TESTS := $(BUILD)/tests/stc

test-stc-run: $(STC)
	@mkdir -p $(STC_TESTS)
	@mk/suite.sh $(RESULTS) stc-run env STC="$(STC)" STC_INC="$(STC_INC)" \
	    CC="$(CC)" CFLAGS="$(CFLAGS)" SAN="$(SAN)" \
	    tests/stc/run.sh $(STC_TESTS)/run $(sort $(wildcard tests/stc/run/*.st))

test-stc-errors: $(STC)
	@mkdir -p $(STC_TESTS)
	@mk/suite.sh $(RESULTS) stc-errors env STC="$(STC)" \
	    tests/stc/errors.sh $(STC_TESTS)/errors \
	    $(sort $(wildcard tests/stc/errors/*.st)) $(sort $(wildcard tests/stc/robust/*.st))

test-stc-contract: $(STC)
	@mkdir -p $(STC_TESTS)
	@mk/suite.sh $(RESULTS) stc-contract env STC="$(STC)" STC_INC="$(STC_INC)" \
	    CC="$(CC)" CFLAGS="$(CFLAGS)" tests/stc/contract.sh $(STC_TESTS)/contract

TESTS += test-stc-run test-stc-errors test-stc-contract
.PHONY: test-stc-run test-stc-errors test-stc-contract

# ---- examples: the example programs under plcrt, over Modbus ----
include tests/examples/tests.mk

# ---- apossctl: the APOSS controller part ----
include tests/apossctl/apossctl.mk
# ---- apossaxis: the APOSS-style axis device ----
include tests/apossaxis/apossaxis.mk
# ---- cia402: the CiA 402 drive device ----
include tests/cia402/cia402.mk

# ---- isg: the ISG damping part (seed 004) ----
include tests/isg/isg.mk
# ---- plcopen: the MC_* blocks over an EPICPOS axis ----
include tests/plcopen/plcopen.mk
# ---- LJPROF: limited-jerk profiles, closed-form cases and Ruckig ----
include tests/ljprof/ljprof.mk
# ---- the library in other environments: C++ linkage, PLCopen XML export ----
include tests/xmlexport/xmlexport.mk
# ---- cam: the CAM curve and the CAM box parts ----
include tests/cam/cam.mk
# ---- docs/getting-started.md, run as the page says ----
include tests/getting_started/getting_started.mk
# ---- the scripts that make the docs' plots ----
include tests/docs/docs.mk
# ---- plcweb: the web page in a headless browser, its security ----
include tests/web/web.mk

include tests/editor_export/editor_export.mk

include tests/deps/deps.mk

include tests/install/install.mk

include tests/tags/tags.mk

include tests/readme/readme.mk
