# The example programs (examples/) under the real plcrt, driven over Modbus
# TCP by pymodbus as their READMEs describe. Each run uses the example's own
# configuration with a port free at run time and a private retain file.
EX_T := $(BUILD)/tests/examples

.PHONY: test-examples
test-examples: $(BUILD)/plc/epicpos/plcrt
	@rm -rf $(EX_T) && mkdir -p $(EX_T)
	@rc=0; \
	mk/suite.sh $(RESULTS) examples-epicpos python3 tests/examples/test_epicpos.py \
	  $(BUILD)/plc/epicpos/plcrt examples/epicpos/epicpos.ini $(abspath $(EX_T))/epicpos || rc=1; \
	exit $$rc
TESTS += test-examples
