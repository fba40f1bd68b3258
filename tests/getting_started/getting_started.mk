# docs/getting-started.md followed block by block (tests/getting_started/
# run_page.py): a project outside the tree built with plcrt-build, run, moved
# over Modbus with mbpoll and pymodbus, stopped with Ctrl-C, a compile error
# named in the user's file; then the build's one-line-per-step output.
# plcrt-build uses the tree's build/. Under make test-matiec the page's
# project is also built with upstream matiec (plcrt-build COMPILER=matiec)
# and moved.
GS_T := $(BUILD)/tests/getting_started
.PHONY: test-getting-started
test-getting-started: plcrt-parts
	@rm -rf $(GS_T) && mkdir -p $(GS_T)
	@mk/suite.sh $(RESULTS) getting-started env MATIEC_DIR=$(if $(filter matiec,$(COMPILER)),$(MATIEC_DIR)) \
	    python3 tests/getting_started/run_page.py \
	    docs/getting-started.md . $(abspath $(GS_T))
TESTS += test-getting-started
STRESS_TESTS += test-getting-started
MATIEC_TESTS += test-getting-started
