#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The SocketCAN port on a real kernel CAN bus: boots a stock Debian kernel under qemu (software
# emulation) with a tiny initramfs that loads the CAN modules, creates vcan0, runs the test binary
# against the kernel's CAN stack while can-utils' candump captures the bus; the host then checks
# the marker line and has pydronecan decode the captured frames.
# usage: qemu_socketcan.sh BUILD_DIR GUEST_BINARY PYTHON [OCCMAP MAP]
# With OCCMAP and MAP, `occmap can-feed --socketcan vcan0` also runs in the guest (node 101).
# Exit 0 = pass; exit 77 with a SKIP line naming an environment limit (no qemu, no kernel package)
# = skipped, which tests/run_all.sh counts (and fails under CI=true).
set -uo pipefail
build=$1; guest_bin=$2; py=$3; occmap=${4:-}; map=${5:-}
here=$(cd "$(dirname "$0")" && pwd)
cache=$build/cache/can-guest
work=$build/can/guest
t_start=$(date +%s%N)
ms() { echo $(( ($(date +%s%N) - $1) / 1000000 )); }

skip() { echo "SKIP qemu-socketcan: $* (environment limit)"; exit 77; }

qemu=$(command -v qemu-system-x86_64 || true)
[ -n "$qemu" ] || skip "qemu-system-x86_64 is not installed (Debian package qemu-system-x86)"
bb=/bin/busybox
[ -x "$bb" ] && ! ldd "$bb" >/dev/null 2>&1 || skip "busybox-static is not installed (a static /bin/busybox)"
candump=$(command -v candump || true)
[ -n "$candump" ] || skip "candump (can-utils) is not installed"
command -v cpio >/dev/null || skip "cpio is not installed"

if ! bash "$here/guest_kernel.sh" "$cache"; then
  skip "the Debian kernel package could not be fetched with apt-get download"
fi
echo "guest kernel: $(cat "$cache/package" 2>/dev/null)"

# ---- initramfs ------------------------------------------------------------------------------
rm -rf "$work"; mkdir -p "$work/root"/{bin,lib/modules,proc,sys,dev,tmp}
root=$work/root
cp "$bb" "$root/bin/busybox"
cp "$cache"/modules/*.ko "$root/lib/modules/"
cp "$guest_bin" "$root/bin/socketcan_guest"
cp "$candump" "$root/bin/candump"
libs_of="$candump"
if [ -n "$occmap" ]; then
  cp "$occmap" "$root/bin/occmap"; cp "$map" "$root/map.occ"; libs_of="$libs_of $occmap"
fi
for lib in $(for b in $libs_of; do ldd "$b"; done | awk '/=>/ {print $3} /^[ \t]*\// {print $1}' | sort -u); do
  [ -f "$lib" ] || continue
  mkdir -p "$root$(dirname "$lib")"; cp -L "$lib" "$root$lib"
done
cat > "$root/init" <<'INIT'
#!/bin/busybox sh
/bin/busybox --install -s /bin
mount -t proc proc /proc
mount -t sysfs sys /sys
mount -t devtmpfs dev /dev 2>/dev/null
echo OCC-GUEST-START
for m in can can-raw can-dev vcan; do insmod /lib/modules/$m.ko || echo "OCC-GUEST-INSMOD-FAIL $m"; done
ip link add dev vcan0 type vcan && ip link set vcan0 up || echo OCC-GUEST-VCAN-FAIL
candump -L vcan0 > /tmp/candump.log 2>&1 &
cdpid=$!
sleep 0.3
echo "OCC-GUEST-UPTIME-BEFORE $(cut -d" " -f1 /proc/uptime)"
/bin/socketcan_guest vcan0
rc=$?
echo "OCC-GUEST-UPTIME-AFTER $(cut -d" " -f1 /proc/uptime)"
if [ -x /bin/occmap ]; then
  /bin/occmap can-feed --map /map.occ --socketcan vcan0 --node-id 101 --sensor-id 3 \
    --pose 0,0,0,30 --duration-s 1.5 > /tmp/feed.json 2>&1
  echo "OCC-CANFEED-EXIT $? $(cat /tmp/feed.json)"
fi
sleep 0.2
kill $cdpid; wait $cdpid 2>/dev/null
echo OCC-CANDUMP-BEGIN
cat /tmp/candump.log
echo OCC-CANDUMP-END
echo "OCC-GUEST-EXIT $rc"
poweroff -f
INIT
chmod +x "$root/init" "$root/bin/socketcan_guest"
(cd "$root" && find . | cpio -o -H newc --quiet | gzip -1) > "$work/initramfs.gz"
echo "initramfs: $(stat -c %s "$work/initramfs.gz") bytes, built in $(ms "$t_start") ms"

# ---- boot -----------------------------------------------------------------------------------
log=$work/console.log
kernel=$cache/vmlinuz
[ -s "$cache/vmlinux" ] && kernel=$cache/vmlinux   # PVH entry: no firmware, no decompression
echo "qemu: booting $(basename "$kernel") under TCG"
t_boot=$(date +%s%N)
timeout --foreground -k 5 120 "$qemu" -accel tcg -smp 1 -m 256M -nodefaults -no-user-config \
  -nographic -serial stdio -nic none -no-reboot -kernel "$kernel" \
  -initrd "$work/initramfs.gz" -append 'console=ttyS0 panic=-1 quiet' </dev/null >"$log" 2>&1
qrc=$?
boot_ms=$(ms "$t_boot")
tr -d '\r' < "$log" | sed 's/\x1b\[[0-9;?]*[a-zA-Z]//g' > "$work/console.txt"
if [ $qrc -eq 124 ] || [ $qrc -eq 137 ]; then
  echo "FAIL qemu-socketcan: guest hung (timeout after ${boot_ms} ms)"; tail -20 "$work/console.txt"; exit 1
fi
if ! grep -aq OCC-GUEST-START "$work/console.txt"; then
  if [ $qrc -ne 0 ]; then
    head -5 "$work/console.txt"
    skip "qemu-system-x86_64 could not start a guest here (exit $qrc, see above)"
  fi
  echo "FAIL qemu-socketcan: the guest never reached /init"; tail -30 "$work/console.txt"; exit 1
fi
grep -a -E '^(ok  |FAIL|info) ' "$work/console.txt" | sed 's/^/guest: /'
grep -a 'OCC-GUEST-INSMOD-FAIL\|OCC-GUEST-VCAN-FAIL' "$work/console.txt"
grep -a 'OCC-CANFEED-EXIT' "$work/console.txt" | sed 's/^/guest: /'
if [ -n "$occmap" ] && ! grep -aq 'OCC-CANFEED-EXIT 0 {' "$work/console.txt"; then
  echo "FAIL qemu-socketcan: occmap can-feed --socketcan vcan0 failed in the guest"; exit 1
fi
marker=$(grep -a -o 'OCC-GUEST-EXIT [0-9]*' "$work/console.txt" | tail -1)
summary=$(grep -a -o 'OCC-SOCKETCAN checks=[0-9]* failed=[0-9]*' "$work/console.txt" | tail -1)
up0=$(grep -a -o 'OCC-GUEST-UPTIME-BEFORE [0-9.]*' "$work/console.txt" | awk '{print $2}')
up1=$(grep -a -o 'OCC-GUEST-UPTIME-AFTER [0-9.]*' "$work/console.txt" | awk '{print $2}')
echo "qemu: boot + test + poweroff ${boot_ms} ms (qemu exit $qrc); guest uptime at test start ${up0:-?} s, after ${up1:-?} s"
echo "qemu: $summary; $marker"
if [ "$marker" != "OCC-GUEST-EXIT 0" ]; then
  echo "FAIL qemu-socketcan: guest test failed or marker missing"; tail -30 "$work/console.txt"; exit 1
fi
sed -n '/^OCC-CANDUMP-BEGIN/,/^OCC-CANDUMP-END/p' "$work/console.txt" | grep -a '^(' > "$work/candump.log"
echo "candump captured $(wc -l < "$work/candump.log") frames"
"$py" "$here/decode_candump.py" "$work/candump.log" ${occmap:+--can-feed-node 101} || { echo "FAIL qemu-socketcan: pydronecan decode"; exit 1; }
echo "PASS qemu-socketcan (total $(ms "$t_start") ms)"
