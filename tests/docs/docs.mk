# The scripts behind the docs' plots (docs/tuning.sh, docs/cam_stamping.sh)
# run against the real plcrt: they wait for conditions, not for time.
.PHONY: test-docs-scripts
test-docs-scripts: $(BUILD)/plc/epicpos/plcrt $(BUILD)/plc/cam_stamping/plcrt
	@mk/suite.sh $(RESULTS) docs-scripts sh tests/docs/run.sh $(BUILD)/tests/docs
TESTS += test-docs-scripts
STRESS_TESTS += test-docs-scripts
