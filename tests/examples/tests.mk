# The example programs (examples/) under the real plcrt, driven over Modbus
# TCP by pymodbus as their READMEs describe. Each run uses the example's own
# configuration with a port free at run time and a private retain file.
EX_T := $(BUILD)/tests/examples
# the CAM examples (examples/cam_*; this file is read before examples/part.mk)
EX_CAM := cam_stamping cam_dryer cam_printing cam_slavesync
EX_RUN = mk/suite.sh $(RESULTS) examples-$(1) python3 tests/examples/test_$(1).py \
	  $(BUILD)/plc/$(1)/plcrt examples/$(1)/$(1).ini $(abspath $(EX_T))/$(1)

.PHONY: test-examples
test-examples: $(BUILD)/plc/epicpos/plcrt $(BUILD)/plc/multiaxis/plcrt $(BUILD)/plc/preset/plcrt \
	       $(BUILD)/plc/plcopen/plcrt $(EX_CAM:%=$(BUILD)/plc/%/plcrt)
	@rm -rf $(EX_T) && mkdir -p $(EX_T)
	@rc=0; \
	$(call EX_RUN,epicpos) || rc=1; \
	$(call EX_RUN,multiaxis) || rc=1; \
	$(call EX_RUN,preset) || rc=1; \
	$(call EX_RUN,plcopen) || rc=1; \
	$(foreach e,$(EX_CAM),$(call EX_RUN,$(e)) || rc=1; )\
	exit $$rc
TESTS += test-examples
STRESS_TESTS += test-examples
MATIEC_TESTS += test-examples

# Ctrl-C typed at `make run-epicpos` in a terminal (a pseudo-terminal): one
# line, status 0, no "Interrupt" from make.
.PHONY: test-examples-ctrl-c
test-examples-ctrl-c: $(BUILD)/plc/epicpos/plcrt
	@rm -rf $(BUILD)/tests/ctrl-c
	@mk/suite.sh $(RESULTS) examples-ctrl-c python3 tests/examples/test_ctrl_c.py . \
	    examples/epicpos/epicpos.ini $(abspath $(BUILD))/tests/ctrl-c
TESTS += test-examples-ctrl-c
STRESS_TESTS += test-examples-ctrl-c

# The CAM examples alone (they are also in test-examples).
.PHONY: test-examples-cam
test-examples-cam: $(EX_CAM:%=$(BUILD)/plc/%/plcrt)
	@mkdir -p $(EX_T)
	@rc=0; $(foreach e,$(EX_CAM),$(call EX_RUN,$(e)) || rc=1; ) exit $$rc
