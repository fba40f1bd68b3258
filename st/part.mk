# st/: the positioner library in Structured Text.  The library is one file,
# build/st/epicpos.st (the sources concatenated in dependency order), which a
# PLC project puts in front of its own program before compiling it.
ST_LIB_SRC := st/epicutil.st st/epicprof.st st/ljprof.st st/poscount.st st/pidff.st st/isgdamp.st \
              st/apossctl.st st/prssearch.st st/zlatch.st st/epicpos.st \
              st/plcopen_axis.st st/plcopen.st
ST_LIB_SRC += st/camcurve.st st/cambox.st st/camsync.st
ST_LIB_SRC += st/apossaxis.st st/plcopen_aposs.st
ST_LIB_SRC += st/plcopen_sync.st
ST_LIB     := $(BUILD)/st/epicpos.st

ALL += $(ST_LIB)

$(ST_LIB): $(ST_LIB_SRC)
	@mkdir -p $(@D)
	$(call say,CAT,$@)
	$(Q)cat $(ST_LIB_SRC) > $@

include tests/epicpos/epicpos.mk

include st/export.mk
