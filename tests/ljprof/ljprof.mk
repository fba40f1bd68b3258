# LJPROF (limited-jerk profiles) tests:
#   test-ljprof         ST programs checking named cases against closed-form
#                       kinematics, one call per sample (run.sh)
#   test-ljprof-ruckig  the compiled block against Ruckig on random moves
#                       (ruckig_peer.py driving drive.c + drive.st)
#   test-ljprof-extremes  limits over twelve decades, starts beyond them:
#                       accepted, finite, exactly on target (extremes.py)
#   test-ljprof-fourjerk  a reversal with four different jerks against its
#                       optimum worked out phase by phase (fourjerk.py)
LJPROF_TESTS := $(wildcard tests/ljprof/t_*.st)
LJPROF_B     := $(BUILD)/tests/ljprof

TESTS += test-ljprof test-ljprof-ruckig test-ljprof-extremes test-ljprof-fourjerk
MATIEC_TESTS += test-ljprof

.PHONY: test-ljprof test-ljprof-ruckig test-ljprof-extremes test-ljprof-fourjerk
test-ljprof: $(ST_LIB) $(STC)
	@mk/suite.sh $(RESULTS) ljprof env STC="$(STC)" STC_INC="$(STC_INC)" CC="$(CC)" \
	    CFLAGS="$(CFLAGS) $(SAN)" tests/ljprof/run.sh $(LJPROF_B) $(ST_LIB) $(LJPROF_TESTS)

$(LJPROF_B)/drive/drive: tests/ljprof/drive.c tests/ljprof/drive.st st/parts/ljprof.st $(STC) tests/common/st_build.sh
	@rm -rf $(@D) && mkdir -p $(@D)
	cat st/parts/ljprof.st tests/ljprof/drive.st > $(@D)/all.st
	@bash -c '. tests/common/st_build.sh && STC="$(STC)" STC_INC="$(STC_INC)" CC="$(CC)" \
	    CFLAGS="$(CFLAGS) $(SAN)" && st_compile $(@D)/all.st $(@D) ljprof-ruckig/build && \
	    st_link $(@D) tests/ljprof/drive.c $@ ljprof-ruckig/build'

test-ljprof-ruckig: $(LJPROF_B)/drive/drive
	@mk/suite.sh $(RESULTS) ljprof-ruckig python3 tests/ljprof/ruckig_peer.py $< 400

test-ljprof-extremes: $(LJPROF_B)/drive/drive
	@mk/suite.sh $(RESULTS) ljprof-extremes python3 tests/ljprof/extremes.py $< 4000

test-ljprof-fourjerk: $(LJPROF_B)/drive/drive
	@mk/suite.sh $(RESULTS) ljprof-fourjerk python3 tests/ljprof/fourjerk.py $<
