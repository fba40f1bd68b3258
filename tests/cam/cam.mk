# CAM tests: the CAM curve against scipy's cubic spline and seed 001's worked
# examples (programs written by gen_curve.py), the CAM box against closed
# forms (t_*.st), compiled with $(STC) and run by the EPICPOS harness.
CAM_TESTS := $(wildcard tests/cam/t_*.st)

TESTS += test-cam
MATIEC_TESTS += test-cam

.PHONY: test-cam
test-cam: $(ST_LIB) $(STC)
	@mk/suite.sh $(RESULTS) cam env STC="$(STC)" STC_INC="$(STC_INC)" CC="$(CC)" \
	    CFLAGS="$(CFLAGS)" tests/cam/run.sh $(BUILD)/tests/cam $(ST_LIB) $(CAM_TESTS)
