# What make run and make test install and build (tests/deps/check_deps.sh).
.PHONY: test-deps
test-deps:
	@rm -rf $(BUILD)/tests/deps && mkdir -p $(BUILD)/tests/deps
	@mk/suite.sh $(RESULTS) deps tests/deps/check_deps.sh $(abspath $(BUILD)/tests/deps)
TESTS += test-deps
