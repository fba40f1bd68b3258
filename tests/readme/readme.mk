# The README's trace, get/watch and forcing lines against the demo
# (tests/readme/run_readme.py).
RM_T := $(BUILD)/tests/readme
.PHONY: test-readme
test-readme: $(BUILD)/plc/epicpos/plcrt
	@rm -rf $(RM_T) && mkdir -p $(RM_T)
	@mk/suite.sh $(RESULTS) readme python3 tests/readme/run_readme.py . $(abspath $(RM_T))
TESTS += test-readme
STRESS_TESTS += test-readme
