#!/bin/sh
# The scripts that make the docs' plots, run as a reader would (from the
# top of the tree), with a free Modbus port and the plots written to OUT
# instead of docs/img: each must end with status 0 and write its plots.
#   tests/docs/run.sh OUT
set -u
out=$1
rm -rf "$out" && mkdir -p "$out"
port() { python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }
check() {   # SCRIPT PLOTS...
    script=$1; shift
    PORT=$(port) IMG=$out sh "$script" > "$out/$(basename "$script").log" 2>&1
    rc=$?
    missing=""
    for p in "$@"; do [ -s "$out/$p" ] || missing="$missing $p"; done
    if [ $rc -eq 0 ] && [ -z "$missing" ]; then
        echo "PASS: docs: $script runs as the page says and writes$(printf ' %s' "$@")"
    else
        echo "FAIL: docs: $script: status $rc, plots missing:${missing:- none}"
        tail -n 5 "$out/$(basename "$script").log"
    fi
}
check docs/tuning.sh tune-1-default.png tune-2-no-feedforward.png tune-3-pgain40.png tune-4-pgain40-feedfw.png
check docs/cam_stamping.sh cam_stamping.png
