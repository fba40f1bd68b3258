#!/bin/bash
# mk/run_web.sh COMMAND...: `make run` starts plcweb (plcweb/, docs/web.md)
# beside the plcrt that COMMAND runs, on the Modbus port of COMMAND's -c
# configuration, prints its address and a login, and stops it when COMMAND
# ends. The first run writes a user `demo` (operator) with a random password
# into build/plcweb.users (the password in build/plcweb.password). plcweb
# ignores Ctrl-C (it is plcrt's to take) and ends with this script.
# The program's tag list (plcrt --tags, beside the program's plcrt) lets
# plcweb write parameters and press Stop/Reset through Modbus, without
# forcing; --config names the I/O backends on its overview.
# WEB_PORT: plcweb's HTTP port (default 8080).
set -u
ini= prev= bin=
for a in "$@"; do
    [ "$prev" = -c ] && ini=$a
    [ -z "$bin" ] && [ "$(basename -- "$a")" = plcrt ] && [ -x "$a" ] && bin=$a
    prev=$a
done
tagopt=()
if [ -n "$bin" ] && [ -n "$ini" ] && mkdir -p "$(dirname "$bin")/gen" &&
   "$bin" -c "$ini" --tags "$(dirname "$bin")/gen" > /dev/null 2>&1; then
    tagopt=(--tags "$(dirname "$bin")/gen/TAGS.json")
fi
[ -n "$ini" ] && tagopt+=(--config "$ini")
port=$(awk '/^[ \t]*\[/ { s = $0; gsub(/[ \t\[\]]/, "", s) }
            s == "modbus" && /^[ \t]*port[ \t]*=/ { sub(/^[^=]*=[ \t]*/, ""); sub(/[ \t;#].*/, ""); print }' "$ini" 2>/dev/null)
users=build/plcweb.users pwfile=build/plcweb.password weblog=build/plcweb.log
mkdir -p build
if [ ! -s "$users" ] || [ ! -s "$pwfile" ]; then
    (umask 077; python3 -c 'import secrets; print(secrets.token_urlsafe(9))' > "$pwfile")
    python3 plcweb/plcweb adduser --users "$users" demo operator < "$pwfile" > /dev/null
fi
: > "$weblog"
(trap '' INT QUIT; exec python3 plcweb/plcweb --users "$users" --port "${WEB_PORT:-8080}" \
    --plc "127.0.0.1:${port:-1502}" "${tagopt[@]}" --project-dir build/plcweb-projects --log build/plcweb-writes.log) \
    > "$weblog" 2>&1 < /dev/null &
web=$!
trap 'kill $web 2>/dev/null' EXIT
for _ in $(seq 50); do
    grep -q 'http://' "$weblog" && break
    kill -0 $web 2>/dev/null || break
    sleep 0.1
done
if grep -q 'http://' "$weblog"; then
    # only the address line's own words: plcweb's log may follow in the file
    addr=$(grep -m1 -o 'plcweb: http://[^ ]* (plcrt at [^)]*)' "$weblog")
    echo "$addr: log in as demo, password $(cat "$pwfile") ($pwfile)"
else
    echo "plcweb did not start (plcrt runs on): $(tail -n 3 "$weblog")"
fi
"$@"
