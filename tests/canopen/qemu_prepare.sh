#!/usr/bin/env bash
# Make ready the QEMU fallback of the bus tests, once per build folder:
# Debian's stock kernel (linux-image-amd64, fetched with `apt-get download`
# rather than installed, which would pull initramfs-tools and upgrade
# systemd), its CAN, vcan, virtio and 9p modules, and a busybox initramfs
# that loads them and mounts the host's root over virtio-9p.
#   tests/canopen/qemu_prepare.sh CACHE_DIR
# Prints what it did; status 0 when CACHE_DIR/vmlinuz and CACHE_DIR/initrd.gz
# are there, 1 with the reason otherwise. As root, missing Debian packages
# (qemu-system-x86, busybox-static, cpio, kmod) are installed; otherwise the
# exact command is printed.
set -u
cache=$1
mkdir -p "$cache"
cache=$(cd "$cache" && pwd)
[ -s "$cache/vmlinuz" ] && [ -s "$cache/initrd.gz" ] && exit 0

need=()
command -v qemu-system-x86_64 >/dev/null || need+=(qemu-system-x86)
[ -x /bin/busybox ] && /bin/busybox --list | grep -qx switch_root || need+=(busybox-static)
command -v cpio >/dev/null || need+=(cpio)
command -v depmod >/dev/null || [ -x /sbin/depmod ] || need+=(kmod)
if [ ${#need[@]} -gt 0 ]; then
    if [ "$(id -u)" -ne 0 ]; then
        echo "qemu: missing Debian packages; run as root: apt-get install -y --no-install-recommends ${need[*]}"
        exit 1
    fi
    echo "qemu: installing ${need[*]}"
    export DEBIAN_FRONTEND=noninteractive
    apt-get install -y -qq --no-install-recommends "${need[@]}" >"$cache/apt.log" 2>&1 || {
        apt-get update -qq >>"$cache/apt.log" 2>&1
        apt-get install -y -qq --no-install-recommends "${need[@]}" >>"$cache/apt.log" 2>&1
    } || { echo "qemu: apt-get install ${need[*]} failed (see $cache/apt.log)"; exit 1; }
fi

# The versioned image package the meta-package points at.
pkg() { apt-cache depends linux-image-amd64 2>/dev/null | sed -n 's/^ *Depends: \(linux-image-[0-9].*\)$/\1/p' | head -1; }
image=$(pkg)
if [ -z "$image" ] && [ "$(id -u)" -eq 0 ]; then
    apt-get update -qq >/dev/null 2>&1
    image=$(pkg)
fi
[ -n "$image" ] || { echo "qemu: apt-cache knows no linux-image-amd64 (run apt-get update)"; exit 1; }

work=$cache/kernel
rm -rf "$work" && mkdir -p "$work/x"
(cd "$work" && apt-get download "$image" >download.log 2>&1) \
    || { echo "qemu: apt-get download $image failed (see $work/download.log)"; exit 1; }
dpkg-deb -x "$work"/linux-image-*.deb "$work/x" || { echo "qemu: cannot unpack $image"; exit 1; }
ver=$(ls "$work/x/lib/modules" | head -1)
depmod=$(command -v depmod || echo /sbin/depmod)
"$depmod" -b "$work/x" "$ver" || { echo "qemu: depmod failed on $image"; exit 1; }
mods=$work/x/lib/modules/$ver

# The modules and what they need, each once, dependencies first.
order=()
add() {
    local path=$1 dep
    for seen in "${order[@]:-}"; do [ "$seen" = "$path" ] && return; done
    for dep in $(sed -n "s|^$path: *||p" "$mods/modules.dep"); do add "$dep"; done
    order+=("$path")
}
for m in net/can/can net/can/can-raw net/can/can-bcm drivers/net/can/dev/can-dev \
         drivers/net/can/vcan drivers/virtio/virtio_pci net/9p/9pnet_virtio fs/9p/9p; do
    f=$(cd "$mods" && ls kernel/$m.ko* 2>/dev/null | head -1)
    [ -n "$f" ] || { echo "qemu: $image has no module $m"; exit 1; }
    add "$f"
done

root=$work/initramfs
mkdir -p "$root"/{bin,dev,proc,sys,newroot,modules}
cp /bin/busybox "$root/bin/busybox"
: > "$root/modules/order"
for f in "${order[@]}"; do
    b=$(basename "$f")
    case $b in
        *.xz) xz -dc "$mods/$f" > "$root/modules/${b%.xz}"; b=${b%.xz} ;;
        *.zst) zstd -qdc "$mods/$f" > "$root/modules/${b%.zst}"; b=${b%.zst} ;;
        *) cp "$mods/$f" "$root/modules/$b" ;;
    esac
    echo "$b" >> "$root/modules/order"
done
cat > "$root/init" <<'INIT'
#!/bin/busybox sh
# initramfs of the bus tests' QEMU guest: load the modules, mount the host's
# root read-only and the folders the test writes read-write (9p tags given on
# the command line as out= and repo=), then run the test's guest script.
/bin/busybox --install -s /bin
mount -t proc proc /proc
mount -t sysfs sys /sys
mount -t devtmpfs dev /dev
for m in $(cat /modules/order); do insmod /modules/$m || echo "insmod $m failed"; done
o=trans=virtio,version=9p2000.L,msize=512000
mount -t 9p -o $o,ro hostroot /newroot || { echo "cannot mount the host root"; poweroff -f; }
mount -t proc proc /newroot/proc
mount -t sysfs sys /newroot/sys
mount -t devtmpfs dev /newroot/dev
mkdir -p /newroot/dev/shm /newroot/dev/pts
mount -t tmpfs shm /newroot/dev/shm
mount -t devpts pts /newroot/dev/pts
mount -t tmpfs tmp /newroot/tmp
mount -t tmpfs run /newroot/run
for arg in $(cat /proc/cmdline); do
    case $arg in repo=*|out=*)
        d=${arg#*=}; tag=${arg%%=*}
        mkdir -p /newroot$d 2>/dev/null
        mount -t 9p -o $o,rw $tag /newroot$d || echo "cannot mount $tag at $d" ;;
    esac
done
for arg in $(cat /proc/cmdline); do
    case $arg in guest=*) exec switch_root /newroot /bin/sh ${arg#*=} ;; esac
done
echo "no guest= script given"; poweroff -f
INIT
chmod +x "$root/init"
(cd "$root" && find . | cpio -o -H newc --quiet | gzip -1) > "$cache/initrd.gz.tmp" \
    || { echo "qemu: cannot build the initramfs"; exit 1; }
cp "$work"/x/boot/vmlinuz-* "$cache/vmlinuz"
mv "$cache/initrd.gz.tmp" "$cache/initrd.gz"
echo "$image" > "$cache/image"
rm -rf "$work/x" "$work"/*.deb
echo "qemu: prepared $image ($(wc -l < "$root/modules/order") modules)"
