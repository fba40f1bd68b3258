#!/usr/bin/env bash
# Choose the kernel the real-bus tests boot, once (make test calls this
# before the first bus suite; every bus suite then uses the same one), and
# say which and why in one line:
#   bus: uml (xstate shim: 2696 -> 11008 bytes)
#   bus: qemu/tcg (uml: guest panicked at boot)
# CAN_BUS_BACKEND=auto (default) | uml | qemu forces a choice. auto boots
# User-Mode Linux with nothing to run (about 1.5 s) and takes it if that
# works, else QEMU: with KVM where the CPU has vmx or svm and /dev/kvm is a
# real KVM (not kvm_pvm, which cannot run a stock kernel), otherwise TCG.
# A backend that cannot run is recorded as "none REASON": the bus suites
# then FAIL with that reason.
#   tests/canopen/bus_backend.sh CHOICE_FILE BUILD_DIR
set -u
here=$(cd "$(dirname "$0")" && pwd)
choice=$1 build=$2
mkdir -p "$(dirname "$choice")" "$build/probe"
want=${CAN_BUS_BACKEND:-auto}

decide() {   # decide BACKEND REASON
    echo "$1 $2" > "$choice"
    if [ "$1" = none ]; then echo "bus: none: $2"; else echo "bus: $1 ($2)"; fi
    exit 0
}

try_uml() {   # sets why; status 0 when UML boots here
    local kernel modules
    kernel=$(command -v linux.uml || command -v linux)
    modules=$(ls -d /usr/lib/uml/modules/*/kernel 2>/dev/null | head -1)
    if [ -z "$kernel" ] || [ -z "$modules" ]; then
        why="uml: user-mode-linux is not installed"; return 1
    fi
    if [ ! -e "$build/xstate_shim.so" ]; then
        why="uml: $build/xstate_shim.so is not built"; return 1
    fi
    if BUS_BACKEND=uml BUS_BUILD=$build "$here/bus_run.sh" --probe "$build/probe"; then
        if [ -s "$build/probe/xstate.log" ]; then
            why=$(head -1 "$build/probe/xstate.log")
        else
            why="host XSAVE area $(xsave_size) bytes: fits UML's buffer"
        fi
        return 0
    fi
    if grep -q "Kernel panic" "$build/probe/boot.log" 2>/dev/null; then
        why="uml: guest panicked at boot"
        fp=$(grep -m1 -o 'ptrace set fp regs failed, errno = [0-9]*' "$build/probe/boot.log")
        [ -n "$fp" ] && why="$why ($fp)"
    else
        why="uml: the probe boot did not finish (see $build/probe/boot.log)"
    fi
    return 1
}

xsave_size() {   # the host's XSAVE area for the enabled features (cpuid leaf 0xD)
    "$build/xstate_guest" --xsave-size 2>/dev/null || echo "?"
}

qemu_kind() {   # sets kind to qemu/kvm or qemu/tcg, and kvm_why to the reason for TCG
    kvm_why=""
    if ! grep -qwE 'vmx|svm' /proc/cpuinfo; then kvm_why="no vmx/svm in this CPU"
    elif [ ! -w /dev/kvm ]; then kvm_why="no usable /dev/kvm"
    elif [ -d /sys/module/kvm_pvm ]; then kvm_why="/dev/kvm is kvm_pvm"
    fi
    if [ -n "$kvm_why" ]; then kind=qemu/tcg; else kind=qemu/kvm; fi
}

use_qemu() {   # use_qemu REASON_UML_WAS_NOT_TAKEN
    local msg
    if ! msg=$("$here/qemu_prepare.sh" "$build/qemu" 2>&1); then
        decide none "${1:+$1; }${msg##*$'\n'}"
    fi
    qemu_kind
    decide "$kind" "${1}${kvm_why:+; $kvm_why}"
}

case $want in
    uml) try_uml && decide uml "$why"; decide none "$why" ;;
    qemu) use_qemu "forced by CAN_BUS_BACKEND=qemu" ;;
    auto) try_uml && decide uml "$why"; use_qemu "$why" ;;
    *) decide none "CAN_BUS_BACKEND=$want: use auto, uml or qemu" ;;
esac
