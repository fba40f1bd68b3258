# plcrt as the CANopen master (included from plc_runtime/part.mk once the
# runtime is there): the real-bus tests of plcrt inside a kernel with CAN
# (tests/canopen/bus_run.sh).

# bus_suite SUITE,SCRIPT,PLCRT: SCRIPT (Python) run in the bus kernel with
# PLCRT (nothing for a suite without plcrt) and its folder there,
# CO_BUILD/uml_NAME for SUITE canopen_NAME; in make test and make test-stress
define bus_suite
.PHONY: $(1)
$(1): $(3) | bus-backend
	@mk/suite.sh $$(RESULTS) $(1) $$(BUS_RUN) $$(CO_BUILD)/uml_$(patsubst canopen_%,%,$(1)) \
	  @PY@ $(2) $(3) $$(CO_BUILD)/uml_$(patsubst canopen_%,%,$(1))
TESTS += $(1)
STRESS_TESTS += $(1)
endef

$(eval $(call plcrt_program,canopen_io,tests/canopen/st/canopen_io.st))
$(eval $(call bus_suite,canopen_plcrt,tests/canopen/plcrt_bus_test.py,$(BUILD)/plc/canopen_io/plcrt))

# the CAN-driven axis, once the positioner library is there
ifneq ($(ST_LIB),)
$(eval $(call plcrt_program,canopen_axis,$(ST_LIB) tests/canopen/st/canopen_axis.st))
$(eval $(call bus_suite,canopen_axis,tests/canopen/plcrt_axis_test.py,$(BUILD)/plc/canopen_axis/plcrt))
endif

# the simulated CiA 402 drive against the standard's table and python-canopen's
# BaseNode402, then plcrt driving two of them with CIA402DRIVE (examples/cia402)
$(eval $(call bus_suite,canopen_drive402,tests/canopen/drive402_test.py,))
$(eval $(call bus_suite,canopen_cia402,tests/canopen/plcrt_cia402_test.py,$(BUILD)/plc/cia402/plcrt))
MATIEC_TESTS += canopen_cia402
# the CODESYS-style PLCopen program (examples/plcopen) on the same two drives,
# against its sim-plant run (taken on the host first)
.PHONY: canopen_plcopen402
canopen_plcopen402: $(BUILD)/plc/plcopen_cia402/plcrt $(BUILD)/plc/plcopen/plcrt | bus-backend
	@mk/suite.sh $(RESULTS) canopen_plcopen402 env BUS_RUN="$(BUS_RUN)" tests/canopen/plcopen402.sh \
	  $(BUILD)/plc/plcopen_cia402/plcrt $(BUILD)/plc/plcopen/plcrt $(CO_BUILD)/uml_plcopen402
TESTS += canopen_plcopen402
STRESS_TESTS += canopen_plcopen402
MATIEC_TESTS += canopen_plcopen402

# seed 000's DRIVETYPE 91: an APOSS axis on the analog output of a guarded CiA 401 module
ifneq ($(ST_LIB),)
$(eval $(call plcrt_program,canopen_aposs,$(ST_LIB) tests/canopen/st/canopen_aposs.st))
$(eval $(call bus_suite,canopen_drivetype,tests/canopen/plcrt_drivetype_test.py,$(BUILD)/plc/canopen_aposs/plcrt))
MATIEC_TESTS += canopen_drivetype
endif

# the EDS/DCF reader (CiA 306), under the sanitizers: it reads vendors' files
$(CO_BUILD)/eds_test: tests/canopen/eds_test.c $(CO_DIR)/eds.c $(CO_SRC) $(CO_HDR)
	@mkdir -p $(@D)
	$(call say,LD,$@)
	$(Q)$(CC) $(CFLAGS) $(SAN) -I$(CO_DIR) tests/canopen/eds_test.c $(CO_DIR)/eds.c $(CO_SRC) -o $@ \
	    -linih $$(pkg-config --cflags --libs check)
.PHONY: canopen_eds
canopen_eds: $(CO_BUILD)/eds_test
	@mkdir -p $(CO_BUILD)/eds_files
	@mk/suite.sh $(RESULTS) canopen_eds $< $(CO_BUILD)/eds_files
TESTS += canopen_eds

# seed 000's ENCODERTYPE 50: the APOSS axis' loop closed through a guarded CiA 406
# encoder (node 5), its reference on the analog output of a CiA 401 module (node 4)
ifneq ($(ST_LIB),)
$(eval $(call plcrt_program,canopen_enc,$(ST_LIB) tests/canopen/st/canopen_enc.st))
$(eval $(call bus_suite,canopen_encodertype,tests/canopen/plcrt_encodertype_test.py,$(BUILD)/plc/canopen_enc/plcrt))
MATIEC_TESTS += canopen_encodertype
endif
