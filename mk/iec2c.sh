#!/bin/bash
# stc's command line over upstream matiec's iec2c, so that `make
# test-matiec` builds the same suites with the other compiler:
#   mk/iec2c.sh [-T outdir] file.st      iec2c -I $MATIEC_DIR/lib ...
#   mk/iec2c.sh --include-dir            matiec's C headers (lib/C)
#   mk/iec2c.sh --version
# MATIEC_DIR is a folder where iec2c was built by hand (docs/stc.md).
# iec2c lists the files it wrote on stdout; like stc, this says nothing
# unless there is something to say.
set -u -o pipefail
dir=${MATIEC_DIR:?MATIEC_DIR: the folder where iec2c was built}
case ${1:-} in
    --include-dir) echo "$dir/lib/C"; exit 0 ;;
    --version) "$dir/iec2c" -v; exit $? ;;
esac
"$dir/iec2c" -I "$dir/lib" "$@" | { grep -Ev '^[A-Za-z0-9_]+\.(c|h|csv)$' || true; }
