# The tag list for HMIs (TAGS.csv, TAGS.json) polled tag by tag over Modbus;
# plctrace get, watch and set by name (tests/tags/run_tags.py).
TAGS_T := $(BUILD)/tests/tags
.PHONY: test-tags
test-tags: plcrt-parts
	@rm -rf $(TAGS_T) && mkdir -p $(TAGS_T)
	@mk/suite.sh $(RESULTS) tags python3 tests/tags/run_tags.py . $(abspath $(TAGS_T))
TESTS += test-tags
STRESS_TESTS += test-tags
