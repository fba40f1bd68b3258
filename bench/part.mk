# Benchmarks. Each prints its figures and the comparison it makes.

BENCH_B := $(BUILD)/bench

# plcrt: latency beside cyclictest, Modbus throughput, cost per cycle
$(eval $(call plcrt_program,bench_empty,bench/runtime/empty.st))
$(eval $(call plcrt_program,bench_empty250,bench/runtime/empty250.st))
$(BENCH_B)/runtime/bandwidth-client: /usr/share/doc/libmodbus-dev/examples/bandwidth-client.c bench/part.mk
	@mkdir -p $(@D)
	sed 's/1502)/atoi(getenv("MODBUS_PORT")))/; s/n_loop = 100000;/n_loop = 5000;/' $< > $@.c
	$(CC) -O2 -w -o $@ $@.c $(shell pkg-config --cflags --libs libmodbus)

.PHONY: bench-runtime
bench-runtime: $(BUILD)/plc/bench_empty/plcrt $(BUILD)/plc/bench_empty250/plcrt $(BENCH_B)/runtime/bandwidth-client
	python3 bench/runtime/bench.py $(BUILD)/plc/bench_empty/plcrt $(BUILD)/plc/bench_empty250/plcrt \
	  $(BENCH_B)/runtime/bandwidth-client auto $(abspath $(BENCH_B))/runtime
BENCHES += bench-runtime

# EPICPOS: instructions and ns per call, per scan with 1, 16 and 256 axes,
# and the most axes plcrt runs at 1 ms with no overrun (bench/epicpos/)
.PHONY: bench-epicpos
bench-epicpos: $(STC) $(ST_LIB) $(C_BLOCKS_OBJ) $(PLCRT_MAIN) $(PLCRT_OBJ)
	@env STC="$(abspath $(STC))" STC_INC="$(abspath $(STC_INC))" ST_LIB="$(abspath $(ST_LIB))" \
	  C_BLOCKS_ST="$(abspath $(C_BLOCKS_ST))" C_BLOCKS_OBJ="$(abspath $(C_BLOCKS_OBJ))" CC="$(CC)" \
	  GEN_CFLAGS="$(PLC_GEN_CFLAGS)" CFLAGS="$(CFLAGS)" PLCRT_LINK="$(abspath $(PLCRT_MAIN) $(PLCRT_OBJ))" \
	  PLCRT_LIBS="$(PLCRT_LIBS)" python3 bench/epicpos/bench.py $(BENCH_B)/epicpos
BENCHES += bench-epicpos

# CAM curve: ns per evaluation at 1000 fix points; CAM box: ns per scan
# with 32 cams (bench/cam/)
.PHONY: bench-cam
bench-cam: $(STC) $(ST_LIB)
	@env STC="$(abspath $(STC))" STC_INC="$(abspath $(STC_INC))" CC="$(CC)" CFLAGS="$(CFLAGS)" \
	  bench/cam/bench.sh $(BENCH_B)/cam $(abspath $(ST_LIB))
BENCHES += bench-cam
