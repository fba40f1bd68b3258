# Blocks declared in ST with a C body. A program using them lists
# $(C_BLOCKS_ST) before its own ST files and links $(C_BLOCKS_OBJ).
C_BLOCKS_ST  := c_blocks/sim_axis.st
C_BLOCKS_OBJ := $(BUILD)/c_blocks/plant.o

$(BUILD)/c_blocks/%.o: c_blocks/%.c c_blocks/%.h
	@mkdir -p $(@D)
	$(call say,CC,$<)
	$(Q)$(CC) $(CFLAGS) -c $< -o $@
