# plcweb (plcweb/) in a real headless browser against the EPICPOS example's
# plcrt: each page, a watched move, forcing, a trace against plctrace's CSV,
# a project upload with an error and a good one switched in; and its
# security over plain HTTP. `make web-screenshots` writes the pages'
# screenshots of docs/web.md into docs/img.
WEB_T := $(BUILD)/tests/web
.PHONY: test-web web-screenshots
WEB_PLCOPEN = --plcopen $(BUILD)/plc/plcopen/plcrt examples/plcopen/plcopen.ini
test-web: $(BUILD)/plc/epicpos/plcrt $(BUILD)/plc/plcopen/plcrt plcrt-parts
	@rm -rf $(WEB_T) && mkdir -p $(WEB_T)
	@mk/suite.sh $(RESULTS) web python3 tests/web/test_web.py \
	    $(BUILD)/plc/epicpos/plcrt examples/epicpos/epicpos.ini $(abspath $(WEB_T)) $(WEB_PLCOPEN)
TESTS += test-web
STRESS_TESTS += test-web

web-screenshots: $(BUILD)/plc/epicpos/plcrt $(BUILD)/plc/plcopen/plcrt plcrt-parts
	@rm -rf $(WEB_T) && mkdir -p $(WEB_T)
	@python3 tests/web/test_web.py $(BUILD)/plc/epicpos/plcrt examples/epicpos/epicpos.ini \
	    $(abspath $(WEB_T)) $(abspath docs/img) $(WEB_PLCOPEN)

# `make run` starts plcweb beside plcrt and prints its address and a login.
.PHONY: test-web-make-run
test-web-make-run: $(BUILD)/plc/epicpos/plcrt
	@rm -rf $(BUILD)/tests/web-make-run && mkdir -p $(BUILD)/tests/web-make-run
	@mk/suite.sh $(RESULTS) web-make-run python3 tests/web/test_make_run.py . examples/epicpos/epicpos.ini \
	    $(abspath $(BUILD))/tests/web-make-run
TESTS += test-web-make-run
STRESS_TESTS += test-web-make-run
