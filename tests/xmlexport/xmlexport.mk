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
