#!/usr/bin/env bash
# Run a command on a real SocketCAN bus: boot a User-Mode Linux kernel with
# the host's root as hostfs, load the CAN modules, bring up vcan0, run the
# command from the repository folder and power off. The command's output
# (PASS/FAIL lines) is printed here; its exit status is ours.
#   tests/canopen/uml_run.sh OUTDIR command [args...]
# An argument @PY@ stands for the host's python3 (the one mk/deps.sh
# equipped); the guest runs with the same root, so the same interpreter.
set -u
out=$1; shift
mkdir -p "$out"
out=$(cd "$out" && pwd)
repo=$(pwd)
py=$(python3 -c 'import sys; print(sys.executable)')
kernel=$(command -v linux.uml || command -v linux || echo /usr/bin/linux.uml)
modules=$(ls -d /usr/lib/uml/modules/*/kernel 2>/dev/null | head -1)
if [ ! -x "$kernel" ] || [ -z "$modules" ]; then
    echo "FAIL: uml: user-mode-linux is not installed (kernel $kernel, modules ${modules:-none})"
    exit 1
fi
rm -f "$out/result.txt" "$out/output.txt"
args=()
for a in "$@"; do [ "$a" = @PY@ ] && args+=("$py") || args+=("$a"); done
printf '%q ' "${args[@]}" > "$out/cmd"
cat > "$out/init.sh" <<INIT
#!/bin/sh
# init of the UML guest
export PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin HOME=/root
export PY=$py OUT=$out PYTHONDONTWRITEBYTECODE=1 CK_VERBOSITY=verbose
mount -t proc proc /proc
mount -t sysfs sys /sys
case "$repo$out" in /tmp/*) ;; *) mount -t tmpfs tmp /tmp ;; esac
mkdir -p /dev/shm && mount -t tmpfs shm /dev/shm
for m in net/can/can.ko net/can/can-raw.ko net/can/can-bcm.ko \\
         drivers/net/can/dev/can-dev.ko drivers/net/can/vcan.ko; do
    insmod $modules/\$m || echo "insmod \$m failed"
done > $out/modules.txt 2>&1
ip link add dev vcan0 type vcan && ip link set vcan0 up
ip link set lo up
cd $repo
sh -c "\$(cat $out/cmd)" > $out/output.txt 2>&1
echo "\$?" > $out/result.txt
sync
poweroff -f
INIT
chmod +x "$out/init.sh"
# UML keeps its memory in a file under TMPDIR: use shared memory if any
tmp=/dev/shm; [ -d "$tmp" ] && [ -w "$tmp" ] || tmp=$out
start=$(date +%s%N)
TMPDIR=$tmp timeout 270 "$kernel" mem=768M root=/dev/root rootfstype=hostfs rw \
    init="$out/init.sh" con=null con0=fd:0,fd:1 < /dev/null > "$out/boot.log" 2>&1
status=$?
cat "$out/output.txt" 2>/dev/null
echo "uml: $(( ($(date +%s%N) - start) / 1000000 )) ms"
if [ ! -s "$out/result.txt" ]; then
    echo "FAIL: uml: the guest did not finish (status $status; see $out/boot.log)"
    tail -20 "$out/boot.log"
    exit 1
fi
exit "$(cat "$out/result.txt")"
