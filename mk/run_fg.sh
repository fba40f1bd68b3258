#!/bin/bash
# mk/run_fg.sh COMMAND...: run COMMAND (plcrt) as the terminal's foreground
# job, in a process group of its own, so that Ctrl-C reaches it alone: it
# stops cleanly and exits 0, and make, which never sees the signal, does not
# end with "Interrupt". Without a terminal (CI, a pipe) it simply runs it.
if [ -t 0 ] && [ -t 2 ]; then
    set -m
    "$@" &
    fg %1 >/dev/null
    exit $?
fi
exec "$@"
