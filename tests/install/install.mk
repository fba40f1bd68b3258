# make install, make deb and the systemd unit (tests/install/check_install.sh);
# plcrt's readiness and watchdog messages seen by a test socket (notify.py).
INST_T := $(BUILD)/tests/install
.PHONY: test-install
test-install: $(BUILD)/plc/epicpos/plcrt
	@rm -rf $(INST_T) && mkdir -p $(INST_T)
	@mk/suite.sh $(RESULTS) install-notify python3 tests/install/notify.py \
	    $(BUILD)/plc/epicpos/plcrt examples/epicpos/epicpos.ini $(abspath $(INST_T))/notify
	@mk/suite.sh $(RESULTS) install env BUILD=$(BUILD) tests/install/check_install.sh $(abspath $(INST_T))/files
TESTS += test-install
STRESS_TESTS += test-install
