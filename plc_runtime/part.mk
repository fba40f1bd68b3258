# plcrt: the soft-PLC runtime. A program build links the runtime's objects
# with one compiled ST program: $(call plcrt_program,NAME,ST files) makes
# $(BUILD)/plc/NAME/plcrt (see docs/runtime.md).

PLCRT_B    := $(BUILD)/plc_runtime
PLCRT_CFLAGS := $(CFLAGS) -I plc_runtime $(shell pkg-config --cflags libmodbus 2>/dev/null || echo -I/usr/include/modbus)
PLCRT_LIBS := -linih -lmodbus -lpthread -lm
PLCRT_CORE := plc_image log stats config program mbmap mbserver mbrtu retain scan \
              trace force tracemb sdnotify tags \
              io_none io_sim io_backends io_multi io_modbus
PLCRT_OBJ  := $(PLCRT_CORE:%=$(PLCRT_B)/%.o) $(C_BLOCKS_OBJ)
include $(wildcard plc_runtime/canopen/part.mk)
PLCRT_OBJ  += $(CO_BACKEND)
PLCRT_MAIN := $(PLCRT_B)/main.o
PLCRT_HDRS := $(wildcard plc_runtime/*.h) c_blocks/plant.h
# Flags for the compiler's generated C (override to build another
# compiler's output by hand).
PLC_GEN_CFLAGS ?= $(CFLAGS)

$(PLCRT_B)/%.o: plc_runtime/%.c $(PLCRT_HDRS)
	@mkdir -p $(@D)
	$(call say,CC,$<)
	$(Q)$(CC) $(PLCRT_CFLAGS) -c $< -o $@

# $(call plcrt_program,NAME,ST_FILES): the ST files are joined in order
# (c_blocks/*.st declarations first when used) and compiled with $(STC).
define plcrt_program
$(BUILD)/plc/$(1)/gen/VARIABLES.csv: $(2) $$(STC)
	@rm -rf $(BUILD)/plc/$(1)/gen && mkdir -p $(BUILD)/plc/$(1)/gen
	$$(call say,STC,$(lastword $(2)))
	$$(Q)cat $(2) > $(BUILD)/plc/$(1)/program.st
	$$(Q)$$(STC) -T $(BUILD)/plc/$(1)/gen $(BUILD)/plc/$(1)/program.st
$(BUILD)/plc/$(1)/program.c: $(BUILD)/plc/$(1)/gen/VARIABLES.csv plc_runtime/gen_program.sh
	$$(call say,GEN,$$@)
	$$(Q)plc_runtime/gen_program.sh $(BUILD)/plc/$(1)/gen $$@
$(BUILD)/plc/$(1)/program.o: $(BUILD)/plc/$(1)/program.c $$(PLCRT_HDRS)
	$$(call say,CC,$$<)
	$$(Q)$$(CC) $$(PLC_GEN_CFLAGS) -I $$(STC_INC) -I $(BUILD)/plc/$(1)/gen -I plc_runtime -c $$< -o $$@
$(BUILD)/plc/$(1)/plcrt: $(BUILD)/plc/$(1)/program.o $$(PLCRT_MAIN) $$(PLCRT_OBJ)
	$$(call say,LD,$$@)
	$$(Q)$$(CC) $$(CFLAGS) -o $$@ $$^ $$(PLCRT_LIBS)
endef

-include tests/runtime/tests.mk
-include tests/canopen/tests.mk
-include tests/remoteio/tests.mk

# plcrt-parts: what plcrt-build (a user's project outside the tree) needs
# from here, built, and listed in $(BUILD)/plc_runtime/parts.sh for it.
.PHONY: plcrt-parts
plcrt-parts: $(STC) $(STC_BIN) $(ST_LIB) $(PLCRT_MAIN) $(PLCRT_OBJ)
	@{ echo "STC='$(abspath $(STC))'"; echo "STC_BIN='$(abspath $(STC_BIN))'"; echo "STC_INC='$(abspath $(STC_INC))'"; \
	   echo "ST_LIB_SRC='$(abspath $(ST_LIB_SRC))'"; echo "GEN_PROGRAM='$(abspath plc_runtime/gen_program.sh)'"; \
	   echo "RT_INC='$(abspath plc_runtime)'"; echo "CC='$(CC)'"; echo "CFLAGS='$(CFLAGS)'"; \
	   echo "GEN_CFLAGS='$(PLC_GEN_CFLAGS)'"; \
	   echo "OBJS='$(abspath $(PLCRT_MAIN) $(PLCRT_OBJ))'"; echo "LIBS='$(PLCRT_LIBS)'"; \
	 } > $(BUILD)/plc_runtime/parts.sh
