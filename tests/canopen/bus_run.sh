#!/usr/bin/env bash
# Run a command on a real SocketCAN bus: boot a Linux kernel that has CAN
# (User-Mode Linux, or QEMU with Debian's stock kernel where UML cannot run;
# tests/canopen/bus_backend.sh chooses), with the host's root as its root,
# bring up vcan0, run the command from the repository folder and power off.
# The command's output (PASS/FAIL lines) is printed here; its exit status is
# ours.
#   tests/canopen/bus_run.sh OUTDIR command [args...]
#   tests/canopen/bus_run.sh --probe OUTDIR     boot, run nothing, status 0 if it works
# An argument @PY@ stands for the host's python3 (the one mk/deps.sh
# equipped); the guest runs with the same root, so the same interpreter.
# In the guest, BUS_BACKEND names the backend (uml, qemu/kvm, qemu/tcg).
set -u
here=$(cd "$(dirname "$0")" && pwd)
probe=0
[ "${1:-}" = --probe ] && { probe=1; shift; }
out=$1; shift
mkdir -p "$out"
out=$(cd "$out" && pwd)
repo=$(pwd)
py=$(python3 -c 'import sys; print(sys.executable)')
build=${BUS_BUILD:-$repo/build/canopen}

if [ $probe -eq 1 ]; then
    backend=${BUS_BACKEND:?}
else
    # the choice made once per `make test` (or now, when run by hand)
    choice=${BUS_CHOICE_FILE:-$out/bus-backend}
    [ -s "$choice" ] || "$here/bus_backend.sh" "$choice" "$build" >/dev/null
    read -r backend why < "$choice"
    if [ "$backend" = none ]; then
        echo "FAIL: bus: $why"
        exit 1
    fi
fi

rm -f "$out/result.txt" "$out/output.txt"
args=()
for a in "$@"; do [ "$a" = @PY@ ] && args+=("$py") || args+=("$a"); done
if [ $probe -eq 1 ]; then args=(true); fi
printf '%q ' "${args[@]}" > "$out/cmd"

case $backend in
    uml)
        modules=$(ls -d /usr/lib/uml/modules/*/kernel 2>/dev/null | head -1)
        load=""
        for m in net/can/can.ko net/can/can-raw.ko net/can/can-bcm.ko \
                 drivers/net/can/dev/can-dev.ko drivers/net/can/vcan.ko; do
            load="$load insmod $modules/$m || echo 'insmod $m failed';"
        done
        mounts='mount -t proc proc /proc; mount -t sysfs sys /sys;
case "'"$repo$out"'" in /tmp/*) ;; *) mount -t tmpfs tmp /tmp ;; esac
mkdir -p /dev/shm && mount -t tmpfs shm /dev/shm' ;;
    qemu/*) load=""; mounts=":" ;;   # the initramfs did both
    *) echo "FAIL: bus: unknown backend '$backend'"; exit 1 ;;
esac

cat > "$out/guest.sh" <<GUEST
#!/bin/sh
# init of the bus test's guest
export PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin HOME=/root
export PY=$py OUT=$out BUS_BACKEND=$backend PYTHONDONTWRITEBYTECODE=1 CK_VERBOSITY=verbose
$mounts
{ :; $load } > $out/modules.txt 2>&1
ip link add dev vcan0 type vcan && ip link set vcan0 up
ip link set lo up
cd $repo
sh -c "\$(cat $out/cmd)" > $out/output.txt 2>&1
echo "\$?" > $out/result.txt
sync
poweroff -f
GUEST
chmod +x "$out/guest.sh"

start=$(date +%s%N)
case $backend in
    uml)
        kernel=$(command -v linux.uml || command -v linux || echo /usr/bin/linux.uml)
        # UML keeps its memory in a file under TMPDIR: use shared memory if any
        tmp=/dev/shm; [ -d "$tmp" ] && [ -w "$tmp" ] || tmp=$out
        rm -f "$out/xstate.log"
        TMPDIR=$tmp XSTATE_SHIM_LOG=$out/xstate.log LD_PRELOAD=$build/xstate_shim.so \
            timeout 270 "$kernel" mem=768M root=/dev/root rootfstype=hostfs rw \
            init="$out/guest.sh" con=null con0=fd:0,fd:1 < /dev/null > "$out/boot.log" 2>&1
        status=$? ;;
    qemu/*)
        q=$build/qemu
        accel=tcg; [ "$backend" = qemu/kvm ] && accel=kvm
        shares=(-virtfs "local,path=/,mount_tag=hostroot,security_model=none,readonly=on,multidevs=remap"
                -virtfs "local,path=$repo,mount_tag=repo,security_model=none,multidevs=remap"
                -virtfs "local,path=$out,mount_tag=out,security_model=none,multidevs=remap")
        timeout 540 qemu-system-x86_64 -accel "$accel" -cpu max -smp 2 -m 1536 \
            -display none -monitor none -serial stdio -no-reboot -nic none \
            -kernel "$q/vmlinuz" -initrd "$q/initrd.gz" "${shares[@]}" \
            -append "console=ttyS0 quiet panic=-1 rdinit=/init repo=$repo out=$out guest=$out/guest.sh" \
            < /dev/null > "$out/boot.log" 2>&1
        status=$? ;;
esac
ms=$(( ($(date +%s%N) - start) / 1000000 ))
[ $probe -eq 1 ] && { [ -s "$out/result.txt" ]; exit $?; }
cat "$out/output.txt" 2>/dev/null
echo "bus: $backend: $ms ms"
if [ ! -s "$out/result.txt" ]; then
    echo "FAIL: bus: the $backend guest did not finish (status $status; see $out/boot.log)"
    tail -20 "$out/boot.log"
    exit 1
fi
exit "$(cat "$out/result.txt")"
