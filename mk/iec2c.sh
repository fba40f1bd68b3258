#!/bin/bash
# stc's command line over upstream matiec's iec2c, so that `make
# test-matiec` builds the same suites with the other compiler:
#   mk/iec2c.sh [-T outdir] file.st...   iec2c -I $MATIEC_DIR/lib ...
# iec2c reads one file: several are concatenated into outdir/all-inputs.st
# first (its diagnostics then name that file).
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
args=() files=() outdir=.
while [ $# -gt 0 ]; do
    case $1 in
        -T) outdir=$2; args+=("$1" "$2"); shift 2 ;;
        -I) args+=("$1" "$2"); shift 2 ;;
        -*) args+=("$1"); shift ;;
        *) files+=("$1"); shift ;;
    esac
done
if [ ${#files[@]} -gt 1 ]; then
    mkdir -p "$outdir"
    cat "${files[@]}" > "$outdir/all-inputs.st"
    files=("$outdir/all-inputs.st")
fi
"$dir/iec2c" -I "$dir/lib" "${args[@]}" "${files[@]}" | { grep -Ev '^[A-Za-z0-9_]+\.(c|h|csv)$' || true; }
