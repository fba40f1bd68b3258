# Remote I/O (the modbus_io backend, docs/remote-io.md) against real peers:
# pymodbus over TCP and over RTU on socat's pseudo-terminals, libmodbus's
# unit-test server (its port taken from MODBUS_PORT, so that several runs
# may share a machine). Included from plc_runtime/part.mk.

RIO_T := $(BUILD)/tests/remoteio
$(eval $(call plcrt_program,rio_copy,tests/remoteio/st/copy.st))

$(RIO_T)/unit-test-server: $(RT_MB_EXAMPLES)/unit-test-server.c tests/remoteio/tests.mk
	@mkdir -p $(@D)
	cp $(RT_MB_EXAMPLES)/unit-test.h $(@D)/unit-test.h
	sed 's/1502)/atoi(getenv("MODBUS_PORT")))/' $< > $@.c
	$(CC) -O2 -w -I $(@D) -o $@ $@.c $(shell pkg-config --cflags --libs libmodbus)

.PHONY: test-remoteio
test-remoteio: $(BUILD)/plc/rio_copy/plcrt $(RIO_T)/unit-test-server
	@mk/suite.sh $(RESULTS) remoteio python3 tests/remoteio/test_remoteio.py \
	  $(BUILD)/plc/rio_copy/plcrt $(RIO_T)/unit-test-server $(abspath $(RIO_T))/work
TESTS += test-remoteio

# plcrt's own map on a serial line ([modbus_rtu]): mbpoll -m rtu and
# pymodbus over a socat pseudo-terminal pair, malformed frames
.PHONY: test-rtuserver
test-rtuserver: $(BUILD)/plc/rio_copy/plcrt
	@mk/suite.sh $(RESULTS) rtuserver python3 tests/remoteio/test_rtuserver.py \
	  $(BUILD)/plc/rio_copy/plcrt $(abspath $(RIO_T))/rtuserver
TESTS += test-rtuserver

# the example as a user runs it (make run-remoteio)
.PHONY: test-remoteio-example
test-remoteio-example: $(BUILD)/plc/remoteio/plcrt
	@mk/suite.sh $(RESULTS) remoteio-example python3 tests/remoteio/test_example.py $(BUILD)/plc/remoteio/plcrt \
	  $(abspath $(RIO_T))/example
TESTS += test-remoteio-example
MATIEC_TESTS += test-remoteio test-rtuserver test-remoteio-example
STRESS_TESTS += test-remoteio test-rtuserver test-remoteio-example
