#!/usr/bin/env bash
# Run a command while stress-ng keeps every core busy: STRESS_WORKERS CPU
# workers (default twice the cores) at normal priority, as a build or a
# second job would. Prints the load average before the end.
#   mk/stress.sh command [args...]
set -u
n=${STRESS_WORKERS:-$((2 * $(nproc)))}
command -v stress-ng > /dev/null || { echo "stress: stress-ng is missing (apt-get install stress-ng)" >&2; exit 2; }
stress-ng --cpu "$n" --timeout 0 --quiet &
pid=$!
trap 'kill $pid 2> /dev/null; wait $pid 2> /dev/null' EXIT
echo "stress: $n CPU workers (stress-ng) on $(nproc) cores"
"$@"
rc=$?
echo "stress: load average $(cut -d' ' -f1-3 /proc/loadavg)"
exit $rc
