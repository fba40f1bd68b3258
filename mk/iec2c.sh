#!/bin/sh
# stc's command line over upstream matiec's iec2c, so that `make
# test-matiec` builds the same suites with the other compiler:
#   mk/iec2c.sh [-T outdir] file.st      iec2c -I $MATIEC_DIR/lib ...
#   mk/iec2c.sh --include-dir            matiec's C headers (lib/C)
#   mk/iec2c.sh --version
# MATIEC_DIR is a folder where iec2c was built by hand (docs/stc.md).
set -u
dir=${MATIEC_DIR:?MATIEC_DIR: the folder where iec2c was built}
case ${1:-} in
    --include-dir) echo "$dir/lib/C"; exit 0 ;;
    --version) "$dir/iec2c" -v; exit $? ;;
esac
exec "$dir/iec2c" -I "$dir/lib" "$@"
