# The library as PLCopen XML (TC6-XML 2.01) for the OpenPLC editor and
# Beremiz: build/st/epicpos.xml from the same sources, in the same order, as
# build/st/epicpos.st; build/c_blocks/sim_axis.xml for the C-bodied blocks
# (they need their C files in the target's build, docs/openplc.md).
ST2XML       := tools/st2xml.py
ST_LIB_XML   := $(BUILD)/st/epicpos.xml
C_BLOCKS_XML := $(BUILD)/c_blocks/sim_axis.xml

ALL += $(ST_LIB_XML) $(C_BLOCKS_XML)

$(ST_LIB_XML): $(ST2XML) $(ST_LIB_SRC)
	@mkdir -p $(@D)
	python3 $(ST2XML) --name epicpos -o $@ $(ST_LIB_SRC)

$(C_BLOCKS_XML): $(ST2XML) $(C_BLOCKS_ST)
	@mkdir -p $(@D)
	python3 $(ST2XML) --name epicpos_sim -o $@ $(C_BLOCKS_ST)
