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
