#!/usr/bin/env bash
# Install what the build needs:
#   mk/deps.sh run     what the runtime and the demo need (`make run`): the
#                      Debian packages of */deps-run.debian, the Python
#                      packages of */deps-run.pip
#   mk/deps.sh [all]   that and what the tests and benchmarks need (`make
#                      test`): */deps.debian and */deps.pip too
#   mk/deps.sh --list run|all   print the two lists (debian: ..., pip: ...)
# One name per line or several, '#' starts a comment; a Python entry is
# "pip-requirement[:import-name]", each module named once (the entry with a
# version wins). As root, missing packages are installed; otherwise the
# exact command to run is printed and the script fails.
set -euo pipefail
shopt -s nullglob
cd "$(dirname "$0")/.."

list_only=0
[ "${1:-}" = --list ] && { list_only=1; shift; }
mode=${1:-all}
case $mode in
    run) deb_files=(*/deps-run.debian */*/deps-run.debian); pip_files=(*/deps-run.pip */*/deps-run.pip) ;;
    all) deb_files=(*/deps-run.debian */*/deps-run.debian */deps.debian */*/deps.debian)
         pip_files=(*/deps-run.pip */*/deps-run.pip */deps.pip */*/deps.pip) ;;
    *) echo "usage: mk/deps.sh [--list] [run|all]" >&2; exit 2 ;;
esac

words() { [ $# -gt 0 ] || return 0; cat "$@" | sed 's/#.*//' | tr -s ' \t' '\n' | sed '/^$/d'; }
debs=$(words "${deb_files[@]}" | sort -u)
# one entry per import name; a pinned or bounded one over a bare name
pips=$(words "${pip_files[@]}" | awk '{
        req = $0; mod = $0
        if (index($0, ":")) { req = substr($0, 1, index($0, ":") - 1); mod = substr($0, index($0, ":") + 1) }
        sub(/[=<>!~].*/, "", mod)
        if (!(mod in best) || (best[mod] !~ /[=<>!~]/ && req ~ /[=<>!~]/)) best[mod] = req
    } END { for (m in best) print best[m] ":" m }' | sort)

if [ $list_only = 1 ]; then
    echo "debian:" $debs
    echo "pip:" $(for p in $pips; do echo "${p%%:*}"; done)
    exit 0
fi

missing_deb=()
for p in $debs; do
    dpkg-query -W -f='${Status}\n' "$p" 2>/dev/null | grep -q '^install ok installed' || missing_deb+=("$p")
done
if [ ${#missing_deb[@]} -gt 0 ]; then
    if [ "$(id -u)" -eq 0 ] && command -v apt-get >/dev/null; then
        echo "deps: installing Debian packages: ${missing_deb[*]}"
        export DEBIAN_FRONTEND=noninteractive
        apt-get update -qq
        apt-get install -y -qq --no-install-recommends "${missing_deb[@]}" >/dev/null
    else
        echo "deps: missing Debian packages; run as root:" >&2
        echo "  apt-get update && apt-get install -y --no-install-recommends ${missing_deb[*]}" >&2
        exit 1
    fi
fi

# Python packages, for the python3 first on PATH (the one the tests run).
missing_pip=()
for p in $pips; do
    name=${p%%:*}; mod=${p##*:}
    python3 -c "import $mod" 2>/dev/null || missing_pip+=("$name")
done
if [ ${#missing_pip[@]} -gt 0 ]; then
    flags=()
    python3 -c 'import sys,sysconfig,os; sys.exit(0 if os.path.exists(os.path.join(sysconfig.get_paths()["stdlib"],"EXTERNALLY-MANAGED")) else 1)' && flags+=(--break-system-packages)
    if ! python3 -m pip --version >/dev/null 2>&1; then
        echo "deps: python3 has no pip; run as root: apt-get install -y --no-install-recommends python3-pip" >&2
        exit 1
    fi
    echo "deps: installing Python packages: ${missing_pip[*]}"
    python3 -m pip install -q "${flags[@]}" "${missing_pip[@]}" || {
        echo "deps: failed; run: python3 -m pip install ${missing_pip[*]}" >&2; exit 1; }
fi
if [ "$mode" = run ]; then echo "deps: all present for make run"; else echo "deps: all present"; fi
