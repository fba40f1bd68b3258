# plcrt's tests (included from plc_runtime/part.mk). Check units built twice,
# plainly and with $(SAN); integration tests against a running plcrt.

RT_T := $(BUILD)/tests/runtime
RT_CHECK_LIBS := $(shell pkg-config --libs check 2>/dev/null || echo -lcheck -lsubunit -lm -lrt -lpthread)
RT_SRC_MAP := $(addprefix plc_runtime/,mbmap.c config.c program.c plc_image.c log.c io_backends.c io_none.c io_sim.c) c_blocks/plant.c
RT_SRC_CFG := $(addprefix plc_runtime/,config.c plc_image.c log.c io_backends.c io_none.c io_sim.c) c_blocks/plant.c
RT_SRC_RET := plc_runtime/retain.c plc_runtime/log.c

define rt_unit
$(RT_T)/$(1): tests/runtime/$(1).c $(2) $$(PLCRT_HDRS)
	@mkdir -p $$(@D)
	$$(CC) $$(PLCRT_CFLAGS) -o $$@ tests/runtime/$(1).c $(2) $$(RT_CHECK_LIBS) $$(PLCRT_LIBS)
$(RT_T)/$(1)-san: tests/runtime/$(1).c $(2) $$(PLCRT_HDRS)
	@mkdir -p $$(@D)
	$$(CC) $$(PLCRT_CFLAGS) $$(SAN) -o $$@ tests/runtime/$(1).c $(2) $$(RT_CHECK_LIBS) $$(PLCRT_LIBS)
endef
$(eval $(call rt_unit,check_mbmap,$(RT_SRC_MAP)))
$(eval $(call rt_unit,check_config,$(RT_SRC_CFG)))
$(eval $(call rt_unit,check_retain,$(RT_SRC_RET)))
RT_UNITS := check_mbmap check_config check_retain
RT_UNIT_BINS := $(foreach u,$(RT_UNITS),$(RT_T)/$(u) $(RT_T)/$(u)-san)

.PHONY: test-runtime-units
test-runtime-units: $(RT_UNIT_BINS)
	@rc=0; for u in $(RT_UNITS); do \
	  TMPDIR=$(abspath $(RT_T)) mk/suite.sh $(RESULTS) runtime-$$u $(RT_T)/$$u || rc=1; \
	  TMPDIR=$(abspath $(RT_T)) mk/suite.sh $(RESULTS) runtime-$$u-san $(RT_T)/$$u-san || rc=1; \
	done; exit $$rc
TESTS += test-runtime-units
