#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# test-install (tests/install.mk): `make install` into a staging DESTDIR, then a consumer outside
# the tree built both ways against what was installed - pkg-config (shared libocc.so.0 and the
# static host port) and CMake's find_package (static occmap::occmap) - and run; its answers are
# the hand-computed ones in consumer.c. Then `make uninstall` must leave nothing behind.
# usage: run.sh BUILD_DIR
set -euo pipefail
build=$1
work=$(realpath -m "$build/install-test")
stage=$work/stage
prefix=/opt/occmap
rm -rf "$work"; mkdir -p "$work"
fail() { echo "FAIL test-install: $*"; exit 1; }

make --no-print-directory -s install PREFIX=$prefix DESTDIR="$stage" >"$work/install.log" 2>&1 \
  || { cat "$work/install.log"; fail "make install"; }
root=$stage$prefix
for f in bin/occmap lib/libocc.a lib/libocc_posix.a lib/libocc.so lib/libocc.so.0 \
         include/occmap/occmap.h include/occmap/host/occ_file.h lib/pkgconfig/occmap.pc \
         lib/cmake/occmap/occmapConfig.cmake lib/cmake/occmap/occmapConfigVersion.cmake; do
  [ -e "$root/$f" ] || fail "$f not installed"
done
out=$("$root/bin/occmap" --help)
grep -q "view MAP" <<<"$out" || fail "installed occmap --help"
out=$("$root/bin/occmap" view /usr/share/doc/liboctomap-dev/examples/data/geb079.bt -o "$work/geb079.html")
grep -q "assets $root/share/occmap/view\$" <<<"$out" || fail "the installed occmap view does not use its installed scripts"
[ "$(readelf -d "$root/lib/libocc.so" | sed -n 's/.*SONAME.*\[\(.*\)\]/\1/p')" = libocc.so.0 ] \
  || fail "libocc.so soname is not libocc.so.0"
echo "PASS test-install: make install PREFIX=$prefix DESTDIR=$stage"

# pkg-config: the .pc files keep the real prefix; the sysroot maps it into the staging tree.
export PKG_CONFIG_PATH=$root/lib/pkgconfig PKG_CONFIG_SYSROOT_DIR=$stage
[ "$(pkg-config --modversion occmap)" = "$(sed -n 's/^OCC_VERSION := //p' port/install.mk)" ] \
  || fail "pkg-config --modversion occmap"
# shellcheck disable=SC2046
gcc -std=c99 -pedantic-errors -Wall -Wextra -Werror tests/install_consumer/consumer.c \
  $(pkg-config --cflags --libs occmap-host) -o "$work/consumer_pc"
# (ldd's output is read whole: grep -q stopping early would fail the pipe under pipefail)
libs=$(LD_LIBRARY_PATH=$root/lib ldd "$work/consumer_pc")
grep -q "libocc.so.0 => $root/lib/libocc.so.0" <<<"$libs" || fail "the pkg-config consumer does not use the installed libocc.so.0"
LD_LIBRARY_PATH=$root/lib "$work/consumer_pc" "$work/pc.occ" || fail "pkg-config consumer"
echo "PASS test-install: pkg-config consumer (shared libocc.so.0, static host port)"

# CMake: find_package(occmap 0.1) from the staged prefix, static occmap::occmap.
unset PKG_CONFIG_PATH PKG_CONFIG_SYSROOT_DIR
cmake -S tests/install_consumer -B "$work/cmake" -DCMAKE_PREFIX_PATH="$root" \
  -DCMAKE_BUILD_TYPE=Release >"$work/cmake.log" 2>&1 || { cat "$work/cmake.log"; fail "cmake configure"; }
cmake --build "$work/cmake" >>"$work/cmake.log" 2>&1 || { cat "$work/cmake.log"; fail "cmake build"; }
libs=$(ldd "$work/cmake/consumer")
if grep -q libocc <<<"$libs"; then fail "CMake consumer is not static"; fi
"$work/cmake/consumer" "$work/cmake.occ" || fail "CMake consumer"
cmp -s "$work/pc.occ" "$work/cmake.occ" || fail "the two consumers saved different maps"
echo "PASS test-install: CMake consumer (find_package(occmap 0.1), static occmap::occmap)"
libs=$(ldd "$work/cmake/consumer_shared")
grep -q "libocc.so.0 => $root/lib/libocc.so.0" <<<"$libs" || fail "CMake consumer_shared does not load the installed libocc.so.0 (RPATH)"
"$work/cmake/consumer_shared" || fail "CMake consumer_shared"
echo "PASS test-install: CMake consumer_shared (occmap::occmap_shared, libocc.so.0 by RPATH)"

make --no-print-directory -s uninstall PREFIX=$prefix DESTDIR="$stage" >/dev/null 2>&1 || fail "make uninstall"
left=$(find "$stage" -type f -o -type l)
[ -z "$left" ] || fail "make uninstall left: $left"
echo "PASS test-install: make uninstall removes every installed file"
