#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# io_tools.sh BUILD - `occmap convert` against OctoMap's own command-line tools (octomap-tools):
#  geb079.bt -> .occ -> .bt is byte-identical to the original; occmap's .ot converted back by
#  OctoMap's convert_octree is byte-identical too; compare_octrees finds occmap's .ot equal to
#  OctoMap's own .ot up to the fixed-point step (KLD ~ 3e-4, clamp 3.5110 vs 3.5107).
set -eu
build=$1
occ=$build/occmap
g=/usr/share/doc/liboctomap-dev/examples/data/geb079.bt
d=$(mktemp -d /tmp/occ_io_tools.XXXXXX)
trap 'rm -rf "$d"' EXIT
$occ convert "$g" "$d/a.occ"
$occ convert "$d/a.occ" "$d/b.bt"
cmp "$g" "$d/b.bt" && echo "PASS geb079.bt -> .occ -> .bt byte-identical"
$occ convert "$d/b.bt" "$d/c.ot"
convert_octree "$d/c.ot" "$d/d.bt" >/dev/null 2>&1
cmp "$g" "$d/d.bt" && echo "PASS occmap .ot -> OctoMap convert_octree -> .bt byte-identical"
convert_octree "$g" "$d/e.ot" >/dev/null 2>&1
kld=$(compare_octrees "$d/e.ot" "$d/c.ot" 2>&1 | sed -n 's/^KLD: //p')
echo "compare_octrees KLD: $kld"
awk -v k="$kld" 'BEGIN { exit !(k != "" && k + 0 < 0.001) }' && echo "PASS compare_octrees KLD < 1e-3"
$occ info "$d/a.occ" --json | grep -q '"format": "occ"' && echo "PASS occmap info --json"
# A corrupt file gives a clear error and a non-zero exit.
head -c 1000 "$g" > "$d/cut.bt"
if $occ info "$d/cut.bt" 2>"$d/err.txt"; then echo "FAIL truncated file accepted"; exit 1; fi
grep -q "at byte" "$d/err.txt" && echo "PASS truncated file: $(cat "$d/err.txt")"
