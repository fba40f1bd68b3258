# plcrt as the CANopen master (included from plc_runtime/part.mk once the
# runtime is there): the real-bus tests of plcrt inside a kernel with CAN
# (tests/canopen/bus_run.sh).
$(eval $(call plcrt_program,canopen_io,tests/canopen/st/canopen_io.st))

.PHONY: canopen_plcrt
canopen_plcrt: $(BUILD)/plc/canopen_io/plcrt | bus-backend
	@mk/suite.sh $(RESULTS) canopen_plcrt $(BUS_RUN) $(CO_BUILD)/uml_plcrt \
	  @PY@ tests/canopen/plcrt_bus_test.py $(BUILD)/plc/canopen_io/plcrt $(CO_BUILD)/uml_plcrt
TESTS += canopen_plcrt
STRESS_TESTS += canopen_plcrt

# the CAN-driven axis, once the positioner library is there
ifneq ($(ST_LIB),)
$(eval $(call plcrt_program,canopen_axis,$(ST_LIB) tests/canopen/st/canopen_axis.st))
.PHONY: canopen_axis
canopen_axis: $(BUILD)/plc/canopen_axis/plcrt | bus-backend
	@mk/suite.sh $(RESULTS) canopen_axis $(BUS_RUN) $(CO_BUILD)/uml_axis \
	  @PY@ tests/canopen/plcrt_axis_test.py $(BUILD)/plc/canopen_axis/plcrt $(CO_BUILD)/uml_axis
TESTS += canopen_axis
STRESS_TESTS += canopen_axis
endif

# the simulated CiA 402 drive against the standard's table and python-canopen's
# BaseNode402, then plcrt driving two of them with CIA402DRIVE (examples/cia402)
.PHONY: canopen_drive402 canopen_cia402
canopen_drive402: | bus-backend
	@mk/suite.sh $(RESULTS) canopen_drive402 $(BUS_RUN) $(CO_BUILD)/uml_drive402 \
	  @PY@ tests/canopen/drive402_test.py $(CO_BUILD)/uml_drive402
TESTS += canopen_drive402
STRESS_TESTS += canopen_drive402
canopen_cia402: $(BUILD)/plc/cia402/plcrt | bus-backend
	@mk/suite.sh $(RESULTS) canopen_cia402 $(BUS_RUN) $(CO_BUILD)/uml_cia402 \
	  @PY@ tests/canopen/plcrt_cia402_test.py $(BUILD)/plc/cia402/plcrt $(CO_BUILD)/uml_cia402
TESTS += canopen_cia402
STRESS_TESTS += canopen_cia402
# the CODESYS-style PLCopen program (examples/plcopen) on the same two drives,
# against its sim-plant run (taken on the host first)
.PHONY: canopen_plcopen402
canopen_plcopen402: $(BUILD)/plc/plcopen_cia402/plcrt $(BUILD)/plc/plcopen/plcrt | bus-backend
	@mk/suite.sh $(RESULTS) canopen_plcopen402 env BUS_RUN="$(BUS_RUN)" tests/canopen/plcopen402.sh \
	  $(BUILD)/plc/plcopen_cia402/plcrt $(BUILD)/plc/plcopen/plcrt $(CO_BUILD)/uml_plcopen402
TESTS += canopen_plcopen402
STRESS_TESTS += canopen_plcopen402

# seed 000's DRIVETYPE 91: an APOSS axis on the analog output of a guarded CiA 401 module
ifneq ($(ST_LIB),)
$(eval $(call plcrt_program,canopen_aposs,$(ST_LIB) tests/canopen/st/canopen_aposs.st))
.PHONY: canopen_drivetype
canopen_drivetype: $(BUILD)/plc/canopen_aposs/plcrt | bus-backend
	@mk/suite.sh $(RESULTS) canopen_drivetype $(BUS_RUN) $(CO_BUILD)/uml_drivetype \
	  @PY@ tests/canopen/plcrt_drivetype_test.py $(BUILD)/plc/canopen_aposs/plcrt $(CO_BUILD)/uml_drivetype
TESTS += canopen_drivetype
STRESS_TESTS += canopen_drivetype
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
.PHONY: canopen_encodertype
canopen_encodertype: $(BUILD)/plc/canopen_enc/plcrt | bus-backend
	@mk/suite.sh $(RESULTS) canopen_encodertype $(BUS_RUN) $(CO_BUILD)/uml_encodertype \
	  @PY@ tests/canopen/plcrt_encodertype_test.py $(BUILD)/plc/canopen_enc/plcrt $(CO_BUILD)/uml_encodertype
TESTS += canopen_encodertype
STRESS_TESTS += canopen_encodertype
endif
