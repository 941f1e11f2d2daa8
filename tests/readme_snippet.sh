# SPDX-License-Identifier: BSD-3-Clause
# readme_snippet.sh - sourced by the README snippet checks (readme_depth.sh, readme_ranges.sh).
# readme_snippet HEADING OUTFILE: the first ```c block after the line "### HEADING" of README.md
# into OUTFILE; fails when there is none or when it has 15 lines or more (the README promises
# embedding code under 15 lines).
readme_snippet() {
    local heading=$1 file=$2 lines
    awk -v h="### $heading" '$0 == h {f=1} f&&/^```c/{g=1;next} g&&/^```/{exit} g{print}' README.md > "$file"
    [ -s "$file" ] || { echo "no '$heading' snippet found in README.md"; return 1; }
    lines=$(wc -l < "$file")
    [ "$lines" -lt 15 ] || { echo "the '$heading' snippet has $lines lines (must be under 15)"; return 1; }
}
