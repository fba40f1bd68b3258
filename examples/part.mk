# Example PLC projects, each linked into its own plcrt.
$(eval $(call plcrt_program,demo,examples/demo/demo.st))
ALL += $(BUILD)/plc/demo/plcrt

.PHONY: run-demo
run-demo: $(BUILD)/plc/demo/plcrt
	$(BUILD)/plc/demo/plcrt -c examples/demo/demo.ini
RUN_DEMO := run-demo
