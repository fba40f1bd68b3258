# An OpenPLC editor export (tests/editor_export/project, made by the
# editor's own generator: README.md there) built with plcrt-build as it is
# and moved over Modbus; a block it changes, names declared twice, a
# configuration first in name order (stc --join for iec2c). Under make
# test-matiec the export is also built with upstream iec2c and moved.
EE_T := $(BUILD)/tests/editor_export
.PHONY: test-editor-export
test-editor-export: plcrt-parts
	@rm -rf $(EE_T) && mkdir -p $(EE_T)
	@mk/suite.sh $(RESULTS) editor-export env ST_LIB_SRC="$(ST_LIB_SRC)" \
	    MATIEC_DIR=$(if $(filter matiec,$(COMPILER)),$(MATIEC_DIR)) \
	    python3 tests/editor_export/run_export.py . $(abspath $(EE_T))
TESTS += test-editor-export
STRESS_TESTS += test-editor-export
MATIEC_TESTS += test-editor-export
