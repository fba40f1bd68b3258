#!/usr/bin/env bash
# The PLCopen XML export against its ST sources (check_xml.py says how the
# expected side is obtained):
#   run_xml.sh OUTDIR LIB.xml SIM.xml -- LIB_SRC... -- SIM_SRC...
# checks the library's and the C-bodied blocks' exports built by make, and
# the export of tests/xmlexport/features.st (types, RETAIN, arrays, ...).
# Environment: STC.
set -u
out=$1 lib=$2 sim=$3; shift 3
[ "$1" = -- ] && shift
libsrc=(); while [ $# -gt 0 ] && [ "$1" != -- ]; do libsrc+=("$1"); shift; done
shift
simsrc=("$@")
here=$(dirname "$0")
mkdir -p "$out"
rc=0
python3 "$here/check_xml.py" library "$lib" "$out/library" "${libsrc[@]}" || rc=1
python3 "$here/check_xml.py" c_blocks "$sim" "$out/c_blocks" "${simsrc[@]}" || rc=1
if python3 tools/st2xml.py --name features -o "$out/features.xml" "$here/features.st"; then
    python3 "$here/check_xml.py" features "$out/features.xml" "$out/features" "$here/features.st" || rc=1
else
    echo "FAIL: features: st2xml exports tests/xmlexport/features.st"; rc=1
fi
# a declaration it cannot read is an error naming file and line, not a guess
printf 'FUNCTION_BLOCK BAD\n  VAR_INPUT\n    x : ;\n  END_VAR\nEND_FUNCTION_BLOCK\n' > "$out/bad.st"
msg=$(python3 tools/st2xml.py "$out/bad.st" 2>&1 >/dev/null); st=$?
if [ $st = 1 ] && [[ $msg == *"bad.st:3:"* ]]; then
    echo "PASS: st2xml-error (exit 1, $msg)"
else
    echo "FAIL: st2xml-error (exit $st, '$msg')"; rc=1
fi
exit $rc
