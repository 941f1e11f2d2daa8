#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Fetch a stock Debian kernel and its CAN modules for the qemu guest, without installing the
# package (an install would run bootloader hooks and upgrade host packages). Cached in $1.
# usage: guest_kernel.sh CACHE_DIR   -> CACHE_DIR/vmlinuz, CACHE_DIR/modules/{can,can-raw,can-dev,vcan}.ko
set -euo pipefail
cache=$1
# The bzImage's payload, decompressed once: qemu boots the ELF through its PVH entry note, which
# skips the firmware and the in-guest decompression (about 10 s of emulated time). Best effort.
extract_vmlinux() {
  [ -s "$cache/vmlinux" ] && return 0
  python3 - "$cache/vmlinuz" "$cache/vmlinux.tmp" <<'PY' && mv "$cache/vmlinux.tmp" "$cache/vmlinux" || rm -f "$cache/vmlinux.tmp"
import lzma, sys, zlib
d = open(sys.argv[1], "rb").read()
for magic, make in ((b"\xfd7zXZ\x00", lambda: lzma.LZMADecompressor(format=lzma.FORMAT_XZ)),
                    (b"\x1f\x8b\x08", lambda: zlib.decompressobj(31))):
    off = d.find(magic)
    if off < 0:
        continue
    try:
        out = make().decompress(d[off:])
    except Exception:
        continue
    if out[:4] == b"\x7fELF":
        open(sys.argv[2], "wb").write(out)
        sys.exit(0)
sys.exit(1)
PY
}
if [ -s "$cache/vmlinuz" ] && [ -s "$cache/modules/vcan.ko" ] && [ -s "$cache/modules/can-raw.ko" ]; then
  extract_vmlinux || true
  exit 0
fi
mkdir -p "$cache"
# The package the meta package points at now (the ABI number changes with security updates).
pkg=$(apt-cache depends linux-image-amd64 2>/dev/null | awk '/Depends: linux-image-[0-9]/ {print $2; exit}')
if [ -z "$pkg" ]; then
  apt-get update -q >/dev/null 2>&1 || true
  pkg=$(apt-cache depends linux-image-amd64 2>/dev/null | awk '/Depends: linux-image-[0-9]/ {print $2; exit}')
fi
[ -n "$pkg" ] || { echo "guest_kernel: cannot resolve linux-image-amd64 with apt-cache" >&2; exit 1; }
work=$(mktemp -d "$cache/tmp.XXXXXX")
trap 'rm -rf "$work"' EXIT
echo "guest_kernel: downloading $pkg (not installing it)"
(cd "$work" && apt-get download -q "$pkg" >/dev/null 2>&1) || {
  apt-get update -q >/dev/null 2>&1 || true
  (cd "$work" && apt-get download -q "$pkg")
}
deb=$(ls "$work"/*.deb | head -1)
mkdir -p "$work/x"
dpkg-deb --fsys-tarfile "$deb" | tar -x -C "$work/x" --wildcards \
  './boot/vmlinuz-*' './lib/modules/*/kernel/net/can/*' \
  './lib/modules/*/kernel/drivers/net/can/vcan.ko*' \
  './lib/modules/*/kernel/drivers/net/can/dev/can-dev.ko*'
mkdir -p "$cache/modules"
for m in can can-raw can-dev vcan; do
  f=$(find "$work/x/lib/modules" -name "$m.ko*" | head -1)
  [ -n "$f" ] || { echo "guest_kernel: $m.ko missing in $pkg" >&2; exit 1; }
  case "$f" in
    *.ko) cp "$f" "$cache/modules/$m.ko" ;;
    *.ko.xz) xz -dc "$f" > "$cache/modules/$m.ko" ;;
    *.ko.zst) zstd -qdc "$f" > "$cache/modules/$m.ko" ;;
    *.ko.gz) gzip -dc "$f" > "$cache/modules/$m.ko" ;;
  esac
done
cp "$(ls "$work"/x/boot/vmlinuz-* | head -1)" "$cache/vmlinuz"
echo "$pkg" > "$cache/package"
extract_vmlinux || echo "guest_kernel: no ELF payload extracted; qemu will boot the bzImage (slower)"
echo "guest_kernel: $pkg cached in $cache"
