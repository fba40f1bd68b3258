# st/: the positioner library in Structured Text.  The library is one file,
# build/st/epicpos.st (the sources concatenated in dependency order), which a
# PLC project puts in front of its own program before compiling it.
# The three layers of DESIGN.md section 7, each in its own folder, in
# dependency order: parts know nothing of devices, devices nothing of PLCopen.
ST_PARTS   := $(addprefix st/parts/,epicutil.st epicprof.st ljprof.st poscount.st \
              pidff.st isgdamp.st apossctl.st prssearch.st zlatch.st \
              camcurve.st cambox.st camsync.st)
ST_DEVICES := $(addprefix st/devices/,epicpos.st apossaxis.st aposscan.st cia402.st)
ST_PLCOPEN := $(addprefix st/plcopen/,plcopen_types.st plcopen_axis.st plcopen_core.st plcopen.st \
              plcopen_epicpos.st plcopen_aposs.st plcopen_cia402.st \
              plcopen_sync.st)
ST_LIB_SRC := $(ST_PARTS) $(ST_DEVICES) $(ST_PLCOPEN)
ST_LIB     := $(BUILD)/st/epicpos.st

ALL += $(ST_LIB)

$(ST_LIB): $(ST_LIB_SRC)
	@mkdir -p $(@D)
	$(call say,CAT,$@)
	$(Q)cat $(ST_LIB_SRC) > $@

include tests/epicpos/epicpos.mk

include st/export.mk
