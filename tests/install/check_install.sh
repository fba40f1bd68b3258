#!/usr/bin/env bash
# make install and make deb, and the systemd unit they carry:
#  - make install PREFIX=WORK/usr: the files of docs/install.md are there, the
#    installed stc names its installed headers, the installed plcrt-build
#    builds docs/getting-started.md's project and checks its configuration;
#  - make install PREFIX=/usr DESTDIR=WORK/dest: everything under DESTDIR,
#    no path in it names DESTDIR;
#  - systemd-analyze verify passes on the installed unit, without a warning,
#    and the unit has what it promises (notify, watchdog, capabilities
#    instead of root, real-time limit, restart on failure);
#  - make deb: dpkg installs the package into a fresh root.
#   BUILD=build tests/install/check_install.sh WORKDIR   Prints PASS:/FAIL: lines.
set -u
work=$1
rm -rf "$work" && mkdir -p "$work"
st=0
pass() { echo "PASS: install/$1"; }
fail() { echo "FAIL: install/$1: $2"; st=1; }
mk() { make --no-print-directory -s "$@" > "$work/make.log" 2>&1 || { cat "$work/make.log"; return 1; }; }

pfx=$work/usr
if mk install PREFIX="$pfx"; then pass "make install PREFIX=$pfx"; else fail "make install" "failed"; fi
missing=
for f in bin/stc bin/plcrt-build bin/plctrace lib/plcrt/parts.sh lib/plcrt/obj/main.o lib/plcrt/include/program.h \
         lib/plcrt/plcrt-start share/stc/include/iec_std_lib.h share/plcrt/epicpos.st share/plcrt/epicpos.xml \
         share/plcrt/st/devices/epicpos.st share/plcrt/c_blocks/sim_axis.st share/plcrt/examples/epicpos/epicpos.ini \
         share/doc/plcrt/getting-started.md share/doc/plcrt/install.md etc/plcrt/plcrt.ini lib/systemd/system/plcrt@.service; do
    [ -e "$pfx/$f" ] || missing="$missing $f"
done
[ -z "$missing" ] && pass "the installed files are there" || fail "installed files" "missing:$missing"
[ "$("$pfx/bin/stc" --include-dir)" = "$pfx/share/stc/include" ] && pass "installed stc names its installed headers" ||
    fail "stc --include-dir" "$("$pfx/bin/stc" --include-dir)"

# the installed plcrt-build, away from the source tree, on getting-started's project
proj=$work/proj/myaxis
mkdir -p "$proj"
awk -v d="$proj" '/^```(st|ini) file=myaxis\//{ f = d "/" substr($2, 13); next } /^```/{ f = ""; next } f { print > f }' \
    docs/getting-started.md
out=$(cd "$work/proj" && env -u MAKEFLAGS -u MAKELEVEL "$pfx/bin/plcrt-build" myaxis 2>&1); rc=$?
if [ $rc -eq 0 ] && printf '%s\n' "$out" | grep -q 'configuration OK (backend sim, 6 Modbus symbols)' && [ -x "$proj/build/plcrt" ]; then
    pass "the installed plcrt-build builds getting-started's project"
else
    fail "installed plcrt-build" "status $rc: $out"
fi

# the sample configuration fits that project (the simulated axis of getting-started)
cp "$pfx/etc/plcrt/plcrt.ini" "$work/proj/sample.ini"
out=$(cd "$work/proj" && myaxis/build/plcrt -c sample.ini --check-config 2>&1)
[ $? -eq 0 ] && pass "the sample /etc configuration passes plcrt --check-config" || fail "sample plcrt.ini" "$out"

dest=$work/dest
if mk install PREFIX=/usr DESTDIR="$dest" && [ -x "$dest/usr/bin/stc" ] && [ -f "$dest/etc/plcrt/plcrt.ini" ] &&
   ! grep -rqs "$dest" "$dest/usr/lib/plcrt/parts.sh" "$dest/lib/systemd/system" "$dest/usr/lib/systemd/system"; then
    pass "DESTDIR install: all under DESTDIR, /etc for PREFIX=/usr, no path names DESTDIR"
else
    fail "DESTDIR install" "$(ls -R "$dest" 2>&1 | head -20)"
fi

unit=$pfx/lib/systemd/system/plcrt@.service
mkdir -p "$work/unit" && cp "$unit" "$work/unit/plcrt@myaxis.service"
v=$(systemd-analyze verify "$work/unit/plcrt@myaxis.service" 2>&1); rc=$?
[ $rc -eq 0 ] && [ -z "$v" ] && pass "systemd-analyze verify passes on plcrt@.service, without a warning" ||
    fail "systemd-analyze verify" "status $rc: $v"
miss=
for l in Type=notify WatchdogSec= Restart=on-failure LimitRTPRIO=99 'AmbientCapabilities=CAP_SYS_NICE' \
         DynamicUser=yes "ExecStart=$pfx/lib/plcrt/plcrt-start"; do
    grep -q "^$l" "$unit" || miss="$miss $l"
done
grep -q '^User=root' "$unit" && miss="$miss (User=root)"
[ -z "$miss" ] && pass "the unit: notify, watchdog, restart on failure, real-time by capability not root" ||
    fail "unit" "missing:$miss"

if mk deb BUILD="$BUILD"; then
    deb=$(ls "$BUILD"/deb/plcrt_*.deb 2>/dev/null | head -1)
    root=$work/froot
    mkdir -p "$root/var/lib/dpkg/info" "$root/var/lib/dpkg/updates" && : > "$root/var/lib/dpkg/status"
    out=$(dpkg --root="$root" --force-depends --force-not-root --log=/dev/null -i "$deb" 2>&1); rc=$?
    if [ $rc -eq 0 ] && dpkg --root="$root" -s plcrt 2>/dev/null | grep -q '^Status: install ok installed' &&
       [ -x "$root/usr/bin/plcrt-build" ] && [ -f "$root/lib/systemd/system/plcrt@.service" ] &&
       grep -q "^ExecStart=/usr/lib/plcrt/plcrt-start" "$root/lib/systemd/system/plcrt@.service" &&
       dpkg-deb -f "$deb" Depends | grep -q libmodbus-dev; then
        pass "make deb: the package installs into a fresh root (dpkg --root)"
    else
        fail "make deb" "status $rc: $out"
    fi
else
    fail "make deb" "failed"
fi
exit $st
