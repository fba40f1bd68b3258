# Example PLC projects, each linked into its own plcrt (build/plc/NAME/plcrt).
# `make run` starts the EPICPOS example; `make run-EXAMPLE` starts another
# (INI=file: with another configuration). Ctrl-C reaches plcrt alone
# (mk/run_fg.sh): it stops cleanly and make ends without "Interrupt".
$(eval $(call plcrt_program,demo,examples/demo/demo.st))
$(eval $(call plcrt_program,epicpos,$(ST_LIB) examples/epicpos/epicpos.st))
$(eval $(call plcrt_program,multiaxis,$(ST_LIB) examples/multiaxis/multiaxis.st))
$(eval $(call plcrt_program,preset,$(ST_LIB) examples/preset/preset.st))
$(eval $(call plcrt_program,plcopen,$(ST_LIB) examples/plcopen/plcopen.st))
$(eval $(call plcrt_program,aposs,$(ST_LIB) examples/aposs/aposs.st))
$(eval $(call plcrt_program,cia402,$(ST_LIB) examples/cia402/cia402.st))
$(eval $(call plcrt_program,plcopen_cia402,$(ST_LIB) examples/plcopen/plcopen_cia402.st))
CAM_COMMON := $(ST_LIB) examples/cam_common/camaxis.st
$(eval $(call plcrt_program,cam_stamping,$(CAM_COMMON) examples/cam_stamping/cam_stamping.st))
$(eval $(call plcrt_program,cam_dryer,$(ST_LIB) examples/cam_dryer/cam_dryer.st))
$(eval $(call plcrt_program,cam_printing,$(CAM_COMMON) examples/cam_printing/cam_printing.st))
$(eval $(call plcrt_program,cam_slavesync,$(CAM_COMMON) examples/cam_slavesync/cam_slavesync.st))
CAM_EXAMPLES := cam_stamping cam_dryer cam_printing cam_slavesync
EXAMPLES := demo epicpos multiaxis preset plcopen aposs $(CAM_EXAMPLES)
ALL += $(EXAMPLES:%=$(BUILD)/plc/%/plcrt)

.PHONY: $(EXAMPLES:%=run-%)
$(EXAMPLES:%=run-%): run-%: $(BUILD)/plc/%/plcrt
	@$(RUN_WEB) mk/run_fg.sh $(BUILD)/plc/$*/plcrt -c $(or $(INI),examples/$*/$*.ini)
# two simulated CiA 402 drives on vcan0 with the example (docs/drives.md)
ALL += $(BUILD)/plc/cia402/plcrt $(BUILD)/plc/plcopen_cia402/plcrt
.PHONY: run-cia402
run-cia402: $(BUILD)/plc/cia402/plcrt
	@examples/cia402/run.sh $< $(or $(INI),examples/cia402/cia402.ini)
# the PLCopen program on the same two drives
.PHONY: run-plcopen-cia402
run-plcopen-cia402: $(BUILD)/plc/plcopen_cia402/plcrt
	@examples/cia402/run.sh $< $(or $(INI),examples/plcopen/plcopen_cia402.ini)
RUN_DEMO := run-epicpos
# remote I/O (docs/remote-io.md): two pymodbus modules beside plcrt
$(eval $(call plcrt_program,remoteio,examples/remoteio/remoteio.st))
ALL += $(BUILD)/plc/remoteio/plcrt
.PHONY: run-remoteio
run-remoteio: $(BUILD)/plc/remoteio/plcrt
	@examples/remoteio/run.sh $(BUILD)/plc/remoteio/plcrt $(INI)
RUN_DEMO_BIN := $(BUILD)/plc/epicpos/plcrt
