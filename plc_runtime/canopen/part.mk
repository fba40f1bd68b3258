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
	$(CC) $(CFLAGS) -c $< -o $@

$(CO_LIB): $(CO_OBJ)
	rm -f $@ && ar rcs $@ $^

$(CO_BUILD)/test_co: $(CO_TSRC) $(CO_LIB) $(CO_HDR)
	$(CC) $(CFLAGS) -I$(CO_DIR) $(CO_TSRC) $(CO_LIB) -o $@ $$(pkg-config --cflags --libs check)

$(CO_BUILD)/test_co_san: $(CO_TSRC) $(CO_SRC) $(CO_HDR)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) $(SAN) -I$(CO_DIR) $(CO_TSRC) $(CO_SRC) -o $@ $$(pkg-config --cflags --libs check)

ALL += $(CO_LIB) $(CO_BUILD)/test_co $(CO_BUILD)/test_co_san

.PHONY: canopen_unit canopen_unit_san
canopen_unit: $(CO_BUILD)/test_co
	@mk/suite.sh $(RESULTS) canopen_unit $<
canopen_unit_san: $(CO_BUILD)/test_co_san
	@mk/suite.sh $(RESULTS) canopen_unit_san $<
TESTS += canopen_unit canopen_unit_san

# stand-alone master on the core, for the bus tests and the benchmarks
$(CO_BUILD)/co_testmaster: tests/canopen/co_testmaster.c $(CO_LIB) $(CO_HDR)
	$(CC) $(CFLAGS) -I$(CO_DIR) $< $(CO_LIB) -o $@
ALL += $(CO_BUILD)/co_testmaster

# real-bus tests: User-Mode Linux with vcan0, python-canopen slaves
.PHONY: canopen_bus
canopen_bus: $(CO_BUILD)/co_testmaster
	@mk/suite.sh $(RESULTS) canopen_bus tests/canopen/run_bus.sh $(CO_BUILD)
TESTS += canopen_bus

# the plcrt backend `canopen` (built once the runtime's interface is there);
# plcrt links $(CO_BACKEND)
ifneq ($(wildcard plc_runtime/io_backend.h),)
$(CO_BUILD)/io_canopen.o: $(CO_DIR)/io_canopen.c $(CO_HDR) $(wildcard plc_runtime/*.h)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) -Iplc_runtime -I$(CO_DIR) -c $< -o $@
CO_BACKEND := $(CO_BUILD)/io_canopen.o $(CO_LIB)
endif

# benchmarks: SYNC-to-RPDO latency, PDO throughput, bus load (bench/canopen)
$(CO_BUILD)/co_bench: bench/canopen/co_bench.c
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) $< -o $@ -lm
ALL += $(CO_BUILD)/co_bench
.PHONY: bench_canopen
bench_canopen: $(CO_BUILD)/co_bench $(CO_BUILD)/co_testmaster
	@bench/canopen/run.sh $(CO_BUILD)
BENCHES += bench_canopen
$(CO_BUILD)/co_core_bench: bench/canopen/co_core_bench.c $(CO_LIB) $(CO_HDR)
	$(CC) $(CFLAGS) -I$(CO_DIR) $< $(CO_LIB) -o $@
ALL += $(CO_BUILD)/co_core_bench
bench_canopen: $(CO_BUILD)/co_core_bench
