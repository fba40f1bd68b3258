# Dropping the library into other environments:
#  test-cxx-link   C-bodied blocks (c_blocks/) linked from C++, as OpenPLC v3
#                  builds the PLC program with g++
#  test-xmlexport  the PLCopen TC6-XML export of the library (tools/st2xml.py)
CXX_LINK_OUT := $(BUILD)/tests/cxxlink

.PHONY: test-cxx-link
test-cxx-link: $(STC)
	@mk/suite.sh $(RESULTS) cxx-link env STC="$(STC)" STC_INC="$(STC_INC)" \
	    CC="$(CC)" CFLAGS="$(CFLAGS)" CXX="$(CXX)" tests/xmlexport/cxx_link.sh $(CXX_LINK_OUT)

TESTS += test-cxx-link

.PHONY: test-xmlexport
test-xmlexport: $(ST_LIB_XML) $(C_BLOCKS_XML) $(STC)
	@mk/suite.sh $(RESULTS) xmlexport env STC="$(STC)" tests/xmlexport/run_xml.sh \
	    $(BUILD)/tests/xmlexport $(ST_LIB_XML) $(C_BLOCKS_XML) -- $(ST_LIB_SRC) -- $(C_BLOCKS_ST)

TESTS += test-xmlexport

# make check-beremiz BEREMIZ_DIR=DIR [BEREMIZ_PYTHON=python-with-lxml]: the
# exports validated with xmllint against DIR/plcopen/tc6_xml_v201.xsd, then
# loaded and turned back into ST by Beremiz's own code (DIR: a checkout of
# beremiz, outside this tree; docs/openplc.md). Never part of `make test`.
BEREMIZ_PYTHON ?= python3
XE_OUT := $(BUILD)/tests/xmlexport

.PHONY: check-beremiz
check-beremiz: test-xmlexport
	@if [ -z "$(BEREMIZ_DIR)" ] || [ ! -f "$(BEREMIZ_DIR)/plcopen/tc6_xml_v201.xsd" ]; then \
	  echo "check-beremiz: set BEREMIZ_DIR to a checkout of beremiz (docs/openplc.md)"; exit 2; fi
	xmllint --noout --schema $(BEREMIZ_DIR)/plcopen/tc6_xml_v201.xsd \
	    $(ST_LIB_XML) $(C_BLOCKS_XML) $(XE_OUT)/features.xml
	STC="$(abspath $(STC))" $(BEREMIZ_PYTHON) tests/xmlexport/beremiz_check.py \
	    $(BEREMIZ_DIR) library $(abspath $(ST_LIB_XML)) $(abspath $(XE_OUT)/library)
	STC="$(abspath $(STC))" $(BEREMIZ_PYTHON) tests/xmlexport/beremiz_check.py \
	    $(BEREMIZ_DIR) c_blocks $(abspath $(C_BLOCKS_XML)) $(abspath $(XE_OUT)/c_blocks)
