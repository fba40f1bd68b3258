#!/usr/bin/env bash
# Install what the build and the tests need: the Debian packages listed in
# */deps.debian and the Python packages listed in */deps.pip (one name per
# line, '#' starts a comment). As root, missing packages are installed;
# otherwise the exact command to run is printed and the script fails.
set -euo pipefail
cd "$(dirname "$0")/.."

list() { cat "$@" 2>/dev/null | sed 's/#.*//' | tr -s ' \t' '\n' | sed '/^$/d' | sort -u; }

missing_deb=()
for p in $(list */deps.debian */*/deps.debian); do
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
        echo "  apt-get update && apt-get install -y ${missing_deb[*]}" >&2
        exit 1
    fi
fi

# Python packages, for the python3 first on PATH (the one the tests run).
missing_pip=()
for p in $(list */deps.pip */*/deps.pip); do
    # an entry is "pip-requirement[:import-name]"
    name=${p%%:*}; mod=${p##*:}; mod=${mod%%[=<>]*}
    python3 -c "import $mod" 2>/dev/null || missing_pip+=("$name")
done
if [ ${#missing_pip[@]} -gt 0 ]; then
    flags=()
    python3 -c 'import sys,sysconfig,os; sys.exit(0 if os.path.exists(os.path.join(sysconfig.get_paths()["stdlib"],"EXTERNALLY-MANAGED")) else 1)' && flags+=(--break-system-packages)
    if ! python3 -m pip --version >/dev/null 2>&1; then
        echo "deps: python3 has no pip; run as root: apt-get install -y python3-pip" >&2
        exit 1
    fi
    echo "deps: installing Python packages: ${missing_pip[*]}"
    python3 -m pip install -q "${flags[@]}" "${missing_pip[@]}" || {
        echo "deps: failed; run: python3 -m pip install ${missing_pip[*]}" >&2; exit 1; }
fi
echo "deps: all present"
