#!/usr/bin/env bash
# Build and run the APOSSAXIS test programs with the APOSSCTL runner
# (tests/apossctl/run.sh: library, simulated plant SIM_AXIS, the EPICPOS check
# recorder and harness, one PASS:/FAIL: line per "(* CHECK n: ... *)"); the
# results are labelled apossaxis/.
#   tests/apossaxis/run.sh OUTDIR LIBRARY.st prog.st...
# Environment: STC (compiler command), STC_INC (its header folder), CC, CFLAGS.
set -u -o pipefail
here=$(cd "$(dirname "$0")" && pwd)
"$here/../apossctl/run.sh" "$@" | sed 's#^\(PASS\|FAIL\): apossctl/#\1: apossaxis/#'
