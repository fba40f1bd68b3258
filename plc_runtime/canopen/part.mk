# CANopen master: protocol core (frame level), SocketCAN link, unit tests,
# real-bus tests in User-Mode Linux, benchmarks.

CO_DIR   := plc_runtime/canopen
CO_BUILD := $(BUILD)/canopen
CO_SRC   := $(wildcard $(CO_DIR)/co_*.c)
CO_HDR   := $(wildcard $(CO_DIR)/*.h)
CO_OBJ   := $(CO_SRC:$(CO_DIR)/%.c=$(CO_BUILD)/%.o)
CO_LIB   := $(CO_BUILD)/libcanopen.a
CO_TSRC  := $(wildcard tests/canopen/test_*.c)

$(CO_BUILD)/%.o: $(CO_DIR)/%.c $(CO_HDR)
	@mkdir -p $(@D)
	$(call say,CC,$<)
	$(Q)$(CC) $(CFLAGS) -c $< -o $@

$(CO_LIB): $(CO_OBJ)
	$(call say,AR,$@)
	$(Q)rm -f $@ && ar rcs $@ $^

$(CO_BUILD)/test_co: $(CO_TSRC) $(CO_LIB) $(CO_HDR)
	$(call say,LD,$@)
	$(Q)$(CC) $(CFLAGS) -I$(CO_DIR) $(CO_TSRC) $(CO_LIB) -o $@ $$(pkg-config --cflags --libs check)

$(CO_BUILD)/test_co_san: $(CO_TSRC) $(CO_SRC) $(CO_HDR)
	@mkdir -p $(@D)
	$(call say,LD,$@)
	$(Q)$(CC) $(CFLAGS) $(SAN) -I$(CO_DIR) $(CO_TSRC) $(CO_SRC) -o $@ $$(pkg-config --cflags --libs check)

ALL += $(CO_LIB) $(CO_BUILD)/test_co $(CO_BUILD)/test_co_san

.PHONY: canopen_unit canopen_unit_san
canopen_unit: $(CO_BUILD)/test_co
	@mk/suite.sh $(RESULTS) canopen_unit $<
canopen_unit_san: $(CO_BUILD)/test_co_san
	@mk/suite.sh $(RESULTS) canopen_unit_san $<
TESTS += canopen_unit canopen_unit_san

# stand-alone master on the core, for the bus tests and the benchmarks
$(CO_BUILD)/co_testmaster: tests/canopen/co_testmaster.c $(CO_LIB) $(CO_HDR)
	$(call say,LD,$@)
	$(Q)$(CC) $(CFLAGS) -I$(CO_DIR) $< $(CO_LIB) -o $@
ALL += $(CO_BUILD)/co_testmaster

# real-bus tests: a kernel with CAN (User-Mode Linux, or QEMU where UML
# cannot run) with vcan0 and python-canopen slaves. The backend is chosen
# once per `make test` (tests/canopen/bus_backend.sh; CAN_BUS_BACKEND forces
# one) and every bus suite uses it. UML runs with the xstate shim preloaded,
# which lets it boot on hosts with a large XSAVE area (AMX).
$(CO_BUILD)/xstate_shim.so: tests/canopen/xstate_shim.c
	@mkdir -p $(@D)
	$(call say,LD,$@)
	$(Q)$(CC) $(CFLAGS) -shared -fPIC $< -o $@ -ldl
$(CO_BUILD)/xstate_guest: tests/canopen/xstate_guest.c
	@mkdir -p $(@D)
	$(call say,LD,$@)
	$(Q)$(CC) $(CFLAGS) $< -o $@
$(CO_BUILD)/check_xstate: tests/canopen/check_xstate.c tests/canopen/xstate_shim.c
	$(call say,LD,$@)
	$(Q)$(CC) $(CFLAGS) $^ -o $@ -ldl $$(pkg-config --cflags --libs check)
$(CO_BUILD)/check_xstate_san: tests/canopen/check_xstate.c tests/canopen/xstate_shim.c
	$(call say,LD,$@)
	$(Q)$(CC) $(CFLAGS) $(SAN) $^ -o $@ -ldl $$(pkg-config --cflags --libs check)
ALL += $(CO_BUILD)/xstate_shim.so $(CO_BUILD)/xstate_guest $(CO_BUILD)/check_xstate \
       $(CO_BUILD)/check_xstate_san

.PHONY: xstate_shim xstate_shim_san bus-backend canopen_bus
xstate_shim: $(CO_BUILD)/check_xstate
	@mk/suite.sh $(RESULTS) xstate_shim $<
xstate_shim_san: $(CO_BUILD)/check_xstate_san
	@mk/suite.sh $(RESULTS) xstate_shim_san $<
TESTS += xstate_shim xstate_shim_san

BUS_CHOICE := $(RESULTS)/bus-backend
BUS_RUN    := env BUS_CHOICE_FILE=$(BUS_CHOICE) BUS_BUILD=$(abspath $(CO_BUILD)) tests/canopen/bus_run.sh
bus-backend: $(CO_BUILD)/xstate_shim.so $(CO_BUILD)/xstate_guest
	@[ -s $(BUS_CHOICE) ] || tests/canopen/bus_backend.sh $(BUS_CHOICE) $(CO_BUILD)

canopen_bus: $(CO_BUILD)/co_testmaster | bus-backend
	@mk/suite.sh $(RESULTS) canopen_bus env BUS_RUN="$(BUS_RUN)" tests/canopen/run_bus.sh $(CO_BUILD)
TESTS += canopen_bus
STRESS_TESTS += canopen_bus

# the plcrt backend `canopen` (built once the runtime's interface is there);
# plcrt links $(CO_BACKEND)
ifneq ($(wildcard plc_runtime/io_backend.h),)
$(CO_BUILD)/io_canopen.o: $(CO_DIR)/io_canopen.c $(CO_HDR) $(wildcard plc_runtime/*.h)
	@mkdir -p $(@D)
	$(call say,CC,$<)
	$(Q)$(CC) $(CFLAGS) -Iplc_runtime -I$(CO_DIR) -c $< -o $@
$(CO_BUILD)/eds.o: $(CO_DIR)/eds.c $(CO_HDR)
	@mkdir -p $(@D)
	$(call say,CC,$<)
	$(Q)$(CC) $(CFLAGS) -I$(CO_DIR) -c $< -o $@
CO_BACKEND := $(CO_BUILD)/io_canopen.o $(CO_BUILD)/eds.o $(CO_LIB)
endif

# benchmarks: SYNC-to-RPDO latency, PDO throughput, bus load (bench/canopen)
$(CO_BUILD)/co_bench: bench/canopen/co_bench.c
	@mkdir -p $(@D)
	$(call say,LD,$@)
	$(Q)$(CC) $(CFLAGS) $< -o $@ -lm
ALL += $(CO_BUILD)/co_bench
.PHONY: bench_canopen
bench_canopen: $(CO_BUILD)/co_bench $(CO_BUILD)/co_testmaster
	@bench/canopen/run.sh $(CO_BUILD)
BENCHES += bench_canopen
$(CO_BUILD)/co_core_bench: bench/canopen/co_core_bench.c $(CO_LIB) $(CO_HDR)
	$(call say,LD,$@)
	$(Q)$(CC) $(CFLAGS) -I$(CO_DIR) $< $(CO_LIB) -o $@
ALL += $(CO_BUILD)/co_core_bench
bench_canopen: $(CO_BUILD)/co_core_bench
