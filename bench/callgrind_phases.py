#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""callgrind_phases.py - where the integrators' time goes, in instructions (callgrind), as rows of
`make bench`'s table (bench/bench_rows.hpp's fields; issue 19 asks for the projective phases,
issue 22 for SIMPLE's instructions per voxel visit).

Reads callgrind output files (bench/profile.mk made them, each collected inside one public call
with --toggle-collect) through `callgrind_annotate --inclusive=yes`, and splits the call into
phases by the inclusive count of the function that does each phase; what no phase function
holds is the row "rest" (argument checks, scratch layout, the pool check), so the phases add up
to the call.

usage: callgrind_phases.py --rows OUT.json [--simple CALLGRIND.out BUILD.json]
                  [--projective CALLGRIND.out PROJECTIVE.log]
  BUILD.json     `occmap build --json`'s output (its voxel_visits divides SIMPLE's counts)
  PROJECTIVE.log `bench/projective --proj-only`'s output (its frame count divides the
                 projective counts; a log without one, e.g. SKIP without ../shared, adds no row)
"""
import argparse
import json
import re
import subprocess
import sys

# "  1,234,567 (12.34%)  src/x.c:name [/path/binary]" or "... /abs/src/x.c:name": a function's
# inclusive count (callgrind_annotate lists a function under several names; see parse_counts).
LINE = re.compile(r"^\s*([\d,]+)\s+(?:\([^)]*\)\s+)?\S*?:([A-Za-z_][\w.]*)(?:\s+\[[^\]]+\])?\s*$")

SIMPLE_ID = "profile/simple/scan.dat/0.10"
PROJ_ID = "profile/projective/tum/0.05"


def inclusive(path):
    """{function: inclusive instructions} of one callgrind file (parse_counts)."""
    return parse_counts(subprocess.run(
        ["callgrind_annotate", "--inclusive=yes", "--threshold=100", "--auto=no", path],
        check=True, capture_output=True, text=True).stdout)


def parse_counts(text):
    """{function: inclusive instructions} of callgrind_annotate's text: the largest count
    among the lines that name the function. Code inlined from a header is also listed on its
    own line under the header's name ("src/core/morton_internal.h:occi_proj_pixels"), and
    depending on how the binary was linked the function's line with the binary's name either
    holds that part or not; where it does not, a line with the absolute source path and no
    binary holds the whole (bench/projective's occi_proj_pixels: 82.3 M = 69.9 M in the
    binary's line + 12.4 M of Morton code inlined from morton_internal.h). The whole is the
    largest."""
    counts = {}
    for line in text.splitlines():
        m = LINE.match(line)
        if m:
            name, n = m.group(2), int(m.group(1).replace(",", ""))
            counts[name] = max(n, counts.get(name, 0))
    return counts


def row(rid, work, unit, value, reps):
    return {"id": rid, "work": work, "unit": unit, "lower_is_better": True, "octomap": -1,
            "occmap": float("%.5g" % value), "base_label": "", "base": -1, "ratio": 0,
            "ratio_min": 0, "ratio_max": 0, "reps": reps, "target": "none set", "met": False,
            "equal": "n/a"}


def phase_rows(prefix, what, total, phases, parts, rest_label, per, unit, reps):
    """One row for the call, one per phase and its rest (they add up to the call), and one per
    part of a phase (`parts`, counted inside their phase, not in the rest); the share of the call
    in each text. A phase or part without a count (an inlined function) gets no row. Prints
    them."""
    rest = total - sum(n for _, _, n in phases if n is not None)
    rows = [row(prefix + "/total", "%s: the whole call (%.1f M instructions)" % (what, total / 1e6),
                unit, total / per, reps)]
    ordered = []  # each phase, then its parts ("walk/bulk" under "walk")
    for phase in phases + [("rest", rest_label, rest)]:
        ordered += [phase] + [p for p in parts if p[0].startswith(phase[0] + "/")]
    for key, label, n in ordered:
        if n is None:
            print("phases: %s: no count for %s (inlined?): row left out" % (what, label))
            continue
        rows.append(row("%s/%s" % (prefix, key), "%s: %s, %.1f %% of the call" %
                        (what, label, 100.0 * n / total), unit, n / per, reps))
    for r in rows:
        print("  %-100s %10.2f %s" % (r["work"], r["occmap"], unit))
    return rows


def simple_rows(c, visits):
    """SIMPLE's rows from its counts c (parse_counts) and the insert's voxel visits."""
    rays = c["occi_ictx_points"]
    walk = sum(n for name, n in c.items() if re.fullmatch(r"mark_[pn]{3}", name))
    what = "SIMPLE scan.dat 0.1 m, %d voxel visits" % visits
    print("phases: " + what)
    return phase_rows(SIMPLE_ID, what, c["occ_map_insert_cloud"], [
        ("walk", "ray walk (DDA steps marking the voxel set, mark_*)", walk),
        ("setup", "per-ray set-up (keys, direction, tMax, chunk look-ups, hits)", rays - walk),
        ("tree", "voxel set to the tree (sort, bricks, tree updates)",
         c["set_sort"] + c["set_bricks"]),
    ], [], "rest (the sizing pass over every ray's keys before the walk, checks)", visits,
        "instructions per visit", 1)


def projective_rows(c, frames):
    """PROJECTIVE's rows from its counts c over `frames` frames."""
    what = "PROJECTIVE, %d TUM pioneer frames 0.05 m" % frames
    print("phases: " + what)
    return phase_rows(PROJ_ID, what, c["occ_map_insert_projective"], [
        ("pixels", "pixel pass (depths, end points, their codes)", c.get("occi_proj_pixels")),
        ("sort", "sort of the end points", c.get("occi_proj_hits_sort")),
        ("pyramid", "gap fill, min/max pyramid, windows", c.get("occi_proj_build")),
        ("near", "near field", c.get("occi_proj_near")),
        ("walk", "free-space walk", c.get("occi_proj_walk")),
        ("tree", "tree pass (bricks and whole nodes into the tree)",
         c.get("occi_tree_apply_frame")),
    ], [
        ("walk/node_tests", "of the walk: node tests with the footprint query (level 3 and up)",
         c.get("test_node")),
        ("walk/kids", "of the walk: level-2 node tests, 8 at once", c.get("kids_mixed")),
        ("walk/bulk", "of the walk: the 64-voxel rule", c.get("occi_proj_bulk")),
    ], "rest (checks, scratch layout, pool check)", frames * 1e6, "M instructions per frame",
        frames)


def frames_of(log_path):
    """The frame count bench/projective --proj-only printed, or None (SKIP without ../shared)."""
    with open(log_path, encoding="utf-8") as f:
        m = re.search(r"PROJECTIVE only: .*?(\d+) frames", f.read())
    return int(m.group(1)) if m else None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rows", required=True)
    ap.add_argument("--simple", nargs=2, metavar=("CALLGRIND", "BUILD_JSON"))
    ap.add_argument("--projective", nargs=2, metavar=("CALLGRIND", "LOG"))
    a = ap.parse_args()
    rows = []
    if a.simple:
        with open(a.simple[1], encoding="utf-8") as f:
            visits = json.load(f)["voxel_visits"]
        rows += simple_rows(inclusive(a.simple[0]), visits)
    if a.projective:
        frames = frames_of(a.projective[1])
        if frames is None:
            print("phases: %s names no frame count (SKIP without ../shared?): no projective rows"
                  % a.projective[1])
        else:
            rows += projective_rows(inclusive(a.projective[0]), frames)
    with open(a.rows, "w", encoding="utf-8") as f:
        json.dump(rows, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
