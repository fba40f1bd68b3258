# The compiler stc and its tests.
STC_SRCS := $(wildcard stc/*.c)
STC_OBJS := $(patsubst stc/%.c,$(BUILD)/stc/%.o,$(STC_SRCS))
STC_DEFS := -DSTC_INCLUDE_DIR='"$(abspath stc/include)"'

ALL += $(STC)

$(BUILD)/stc/%.o: stc/%.c stc/stc.h
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(STC_DEFS) -c -o $@ $<

$(STC): $(STC_OBJS)
	$(CC) $(CFLAGS) -o $@ $^ -lm
