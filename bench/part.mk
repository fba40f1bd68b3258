# Benchmarks. Each prints its figures and the comparison it makes.

BENCH_B := $(BUILD)/bench

# plcrt: latency beside cyclictest, Modbus throughput, cost per cycle
$(eval $(call plcrt_program,bench_empty,bench/runtime/empty.st))
$(eval $(call plcrt_program,bench_empty250,bench/runtime/empty250.st))

# Modbus throughput: plcrt beside a reference server on libmodbus's
# modbus_reply, under the same load client
$(BENCH_B)/runtime/%: bench/runtime/%.c
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) -o $@ $< $(shell pkg-config --cflags --libs libmodbus) -lpthread

.PHONY: bench-runtime
bench-runtime: $(BUILD)/plc/bench_empty/plcrt $(BUILD)/plc/bench_empty250/plcrt $(BENCH_B)/runtime/refserver $(BENCH_B)/runtime/mbload
	python3 bench/runtime/bench.py $(BUILD)/plc/bench_empty/plcrt $(BUILD)/plc/bench_empty250/plcrt \
	  auto $(abspath $(BENCH_B))/runtime \
	  $(BENCH_B)/runtime/refserver $(BENCH_B)/runtime/mbload
BENCHES += bench-runtime

# remote I/O: modbus_io polling 1, 10, 32 devices beside a plain libmodbus
# client loop, input age at the scan, scan cost with and without it
.PHONY: bench-remoteio
bench-remoteio: $(BUILD)/plc/bench_empty/plcrt $(BENCH_B)/runtime/refserver $(BENCH_B)/runtime/mbloop
	python3 bench/runtime/remoteio_bench.py $(BUILD)/plc/bench_empty/plcrt $(BENCH_B)/runtime/refserver \
	  $(BENCH_B)/runtime/mbloop $(abspath $(BENCH_B))/remoteio
BENCHES += bench-remoteio

# EPICPOS: instructions and ns per call, per scan with 1, 16 and 256 axes,
# and the most axes plcrt runs at 1 ms with no overrun (bench/epicpos/)
.PHONY: bench-epicpos
bench-epicpos: $(STC) $(ST_LIB) $(C_BLOCKS_OBJ) $(PLCRT_MAIN) $(PLCRT_OBJ)
	@env STC="$(abspath $(STC))" STC_INC="$(abspath $(STC_INC))" ST_LIB="$(abspath $(ST_LIB))" \
	  C_BLOCKS_ST="$(abspath $(C_BLOCKS_ST))" C_BLOCKS_OBJ="$(abspath $(C_BLOCKS_OBJ))" CC="$(CC)" \
	  GEN_CFLAGS="$(PLC_GEN_CFLAGS)" CFLAGS="$(CFLAGS)" PLCRT_LINK="$(abspath $(PLCRT_MAIN) $(PLCRT_OBJ))" \
	  PLCRT_LIBS="$(PLCRT_LIBS)" python3 bench/epicpos/bench.py $(BENCH_B)/epicpos
BENCHES += bench-epicpos

# LJPROF: p50/p99 cost of a re-plan call in stc's generated C, and planned
# durations against Ruckig on thousands of random moves (bench/ljprof/)
$(BENCH_B)/ljprof/replan: bench/ljprof/replan.c tests/ljprof/drive.st st/parts/ljprof.st $(STC) tests/common/st_build.sh
	@rm -rf $(@D) && mkdir -p $(@D)
	cat st/parts/ljprof.st tests/ljprof/drive.st > $(@D)/all.st
	@bash -c '. tests/common/st_build.sh && STC="$(STC)" STC_INC="$(STC_INC)" CC="$(CC)" \
	    CFLAGS="$(CFLAGS)" && st_compile $(@D)/all.st $(@D) bench-ljprof && \
	    st_link $(@D) bench/ljprof/replan.c $@ bench-ljprof'

.PHONY: bench-ljprof
bench-ljprof: $(BENCH_B)/ljprof/replan $(BUILD)/tests/ljprof/drive/drive
	python3 bench/ljprof/bench.py $(BENCH_B)/ljprof/replan $(BUILD)/tests/ljprof/drive/drive 3000
BENCHES += bench-ljprof

# the trace: what 16 channels add to a scan (bench/runtime/tracecost.c) and
# the download of 16 x 16384 samples over Modbus with plctrace's client
$(eval $(call plcrt_program,bench_trace,bench/runtime/trace.st))
$(BENCH_B)/runtime/tracecost: bench/runtime/tracecost.c plc_runtime/trace.c plc_runtime/trace.h plc_runtime/plc_image.h
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) -I plc_runtime -o $@ bench/runtime/tracecost.c plc_runtime/trace.c

.PHONY: bench-trace
bench-trace: $(BUILD)/plc/bench_trace/plcrt $(BENCH_B)/runtime/tracecost
	python3 bench/runtime/trace_bench.py $(BUILD)/plc/bench_trace/plcrt $(BENCH_B)/runtime/tracecost \
	  $(abspath $(BENCH_B))/trace
BENCHES += bench-trace

# CAM curve: ns per evaluation at 1000 fix points; CAM box: ns per scan
# with 32 cams (bench/cam/)
.PHONY: bench-cam
bench-cam: $(STC) $(ST_LIB)
	@env STC="$(abspath $(STC))" STC_INC="$(abspath $(STC_INC))" CC="$(CC)" CFLAGS="$(CFLAGS)" \
	  bench/cam/bench.sh $(BENCH_B)/cam $(abspath $(ST_LIB))
BENCHES += bench-cam

# ISGDAMP through EPICPOS: the seed's procedure's figures on the 53 Hz
# plant (weights, the other sign, move times, the highest stable pgain) and
# the cost per stage per sample (bench/isg/)
.PHONY: bench-isg
bench-isg: $(STC) $(ST_LIB)
	@env STC="$(STC)" STC_INC="$(STC_INC)" CC="$(CC)" CFLAGS="$(CFLAGS)" \
	  bench/isg/run.sh $(BENCH_B)/isg $(ST_LIB)
BENCHES += bench-isg

# APOSSAXIS: ns per 1 ms scan with 256 axes in limited-jerk motion, each on
# its own simulated plant, beside one axis; whether 256 fit 1 ms on one
# core, and the cost per axis; the tuning tool run on examples/aposs and its
# gains beside hand tunings of the same plant (bench/aposs/)
.PHONY: bench-aposs
bench-aposs: $(STC) $(ST_LIB) $(BUILD)/plc/aposs/plcrt
	@env STC="$(abspath $(STC))" STC_INC="$(abspath $(STC_INC))" CC="$(CC)" CFLAGS="$(CFLAGS)" \
	  bench/aposs/bench.sh $(BENCH_B)/aposs $(abspath $(ST_LIB)) 3000 5 $(abspath $(BUILD)/plc/aposs/plcrt)
BENCHES += bench-aposs

# plcweb: plcrt's overruns and exec p99 alone and while 10 clients watch 50
# variables each at 10 Hz through plcweb (bench/web/)
.PHONY: bench-web
bench-web: $(BUILD)/plc/epicpos/plcrt
	@mkdir -p $(BENCH_B)/web
	python3 bench/web/bench.py $(BUILD)/plc/epicpos/plcrt examples/epicpos/epicpos.ini $(abspath $(BENCH_B))/web
BENCHES += bench-web
# CIA402DRIVE: scan cost per drive in CSP, and CiA 402 drives per 1 Mbit/s
# bus at a 1 ms and a 4 ms SYNC period (bench/cia402/)
.PHONY: bench-cia402
bench-cia402: $(STC) $(ST_LIB)
	@env STC="$(abspath $(STC))" STC_INC="$(abspath $(STC_INC))" CC="$(CC)" CFLAGS="$(CFLAGS)" \
	  bench/cia402/bench.sh $(BENCH_B)/cia402 $(abspath $(ST_LIB)) 3000 5
BENCHES += bench-cia402
