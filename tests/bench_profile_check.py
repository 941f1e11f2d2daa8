#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""bench_profile_check.py - `make test-bench-profile`: bench/callgrind_phases.py on a hand-written
callgrind_annotate text (no valgrind run).

- parse_counts takes the largest count of the lines that name a function: the absolute-path
  line without a binary where it holds code inlined from a header that the binary's line
  lacks (bench/projective's occi_proj_pixels and its Morton code), else the binary's line; a
  header's own piece ("morton_internal.h:occi_proj_pixels") never wins; clone suffixes
  (key_lanes.avx2) and C names only; not the header or the totals line;
- SIMPLE's phases (walk = the eight mark_* octants, set-up = the ray loop less the walk, tree =
  set_sort + set_bricks, rest) add up to the call, per visit, with hand-computed values;
- PROJECTIVE's top-level phases and rest add up to the call, the walk's two parts are not
  counted twice, a phase whose function is missing (inlined) gives no row;
- every row is a valid row of the bench table (bench/table.py's row_error) and the table's
  expected ids take every id;
- frames_of reads bench/projective's frame count and None from a SKIP log.
"""
import os
import sys
import tempfile

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "bench"))
import callgrind_phases as prof  # noqa: E402
import table  # noqa: E402

FAILS = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        FAILS.append(what)


BIN = "[/x/build/occmap]"
SIMPLE_TEXT = "\n".join([
    "Profile data file 'cg.out' (creator: callgrind-3.19.0)",
    "Ir",
    "1,100 (100.0%)  PROGRAM TOTALS",
    "1,100 (100.0%)  src/integrate/integrate.c:occ_map_insert_cloud " + BIN,
    "1,100 (100.0%)  /x/src/integrate/integrate.c:occ_map_insert_cloud",
    "  900 (81.8%)  /x/src/integrate/integrate.c:occi_ictx_points",
    "  800 (72.7%)  src/integrate/integrate.c:occi_ictx_points " + BIN,
    "  100 (9.1%)  src/integrate/../geom/geom_internal.h:occi_ictx_points",
    "  300 (27.3%)  src/integrate/integrate_internal.h:mark_ppp",
    "  400 (40.0%)  src/integrate/raycast.c:mark_ppp " + BIN,
    "  200 (20.0%)  src/integrate/raycast.c:mark_nnn " + BIN,
    "   50 (5.0%)  src/integrate/raycast.c:mark_walk_helper " + BIN,
    "  120 (12.0%)  src/integrate/integrate.c:set_bricks " + BIN,
    "   40 (4.0%)  src/integrate/integrate.c:set_sort " + BIN,
    "   45 (4.5%)  src/integrate/integrate.c:set_sort " + BIN,
    "   30 (3.0%)  src/x.cpp:std::vector<int>::push_back(int const&) " + BIN,
])


def rows_by_key(rows, prefix):
    return {r["id"][len(prefix) + 1:]: r for r in rows}


def test_parse():
    c = prof.parse_counts(SIMPLE_TEXT + "\n 77 (7.7%)  src/p.c:key_lanes.avx2 " + BIN)
    check(c.get("occi_ictx_points") == 900,
          "the whole: the absolute-path line, where the binary's lacks a header's part (900)")
    check(c.get("mark_ppp") == 400, "the binary's line, where it is the whole (400, not 300)")
    check(c.get("set_sort") == 45, "a name listed twice: the larger count (45)")
    check(c.get("key_lanes.avx2") == 77, "a clone's suffix stays in its name")
    check("PROGRAM" not in c and not any("push_back" in k for k in c),
          "the totals line and C++ names are not functions here")


def test_simple():
    c = prof.parse_counts(SIMPLE_TEXT)
    rows = prof.simple_rows(c, 100)
    r = rows_by_key(rows, prof.SIMPLE_ID)
    check(set(r) == {"total", "walk", "setup", "tree", "rest"}, "SIMPLE: five rows %s" % sorted(r))
    # walk 400 + 200 (mark_walk_helper is no octant), set-up 900 - 600, tree 120 + 45,
    # rest 1100 - 900 - 165; per visit: / 100
    want = {"total": 11.0, "walk": 6.0, "setup": 3.0, "tree": 1.65, "rest": 0.35}
    check(all(abs(r[k]["occmap"] - v) < 1e-9 for k, v in want.items()),
          "SIMPLE: per-visit values %s" % {k: r[k]["occmap"] for k in r})
    check("54.5 % of the call" in r["walk"]["work"], "SIMPLE: the walk's share in its text")
    return rows


def test_projective():
    c = {"occ_map_insert_projective": 2000, "occi_proj_pixels": 500, "occi_proj_hits_sort": 100,
         "occi_proj_build": 100, "occi_proj_near": 50, "occi_proj_walk": 800, "test_node": 300,
         "kids_mixed": 80, "occi_proj_bulk": 200, "occi_tree_apply_frame": 400}
    rows = prof.projective_rows(c, 10)
    r = rows_by_key(rows, prof.PROJ_ID)
    # rest = 2000 - (500 + 100 + 100 + 50 + 800 + 400); the walk's parts are inside the walk
    check(abs(r["rest"]["occmap"] - 50 / 10 / 1e6) < 1e-12, "PROJECTIVE: rest 50 over 10 frames")
    top = ["pixels", "sort", "pyramid", "near", "walk", "tree", "rest"]
    check(abs(sum(r[k]["occmap"] for k in top) - r["total"]["occmap"]) < 1e-9,
          "PROJECTIVE: the top-level phases add up to the call")
    check(all(p in r for p in ("walk/node_tests", "walk/kids", "walk/bulk")),
          "PROJECTIVE: the walk's three parts")
    del c["test_node"]
    r2 = rows_by_key(prof.projective_rows(c, 10), prof.PROJ_ID)
    check("walk/node_tests" not in r2 and abs(r2["rest"]["occmap"] - r["rest"]["occmap"]) < 1e-12,
          "PROJECTIVE: an inlined part gives no row and changes no other")
    return rows


def test_rows_valid(rows):
    bad = [(x["id"], table.row_error(x)) for x in rows if table.row_error(x)]
    check(not bad, "every row is a valid table row %s" % bad)
    ids = table.expected_ids()
    lost = [x["id"] for x in rows if not any(table.takes(e, x["id"]) for e in ids)]
    check(not lost, "the table's expected ids take every row %s" % lost)


def test_frames():
    with tempfile.TemporaryDirectory() as d:
        good, skip = os.path.join(d, "good.log"), os.path.join(d, "skip.log")
        with open(good, "w") as f:
            f.write("PROJECTIVE only: 67.83 ms per frame (median of 1, 10 frames), scratch 5\n")
        with open(skip, "w") as f:
            f.write("SKIP: ../shared/data/depth/tum_fr2_pioneer_slam2: no such directory\n")
        check(prof.frames_of(good) == 10 and prof.frames_of(skip) is None,
              "frames_of: 10 from the log, None from a SKIP")


def main():
    test_parse()
    rows = test_simple() + test_projective()
    test_rows_valid(rows)
    test_frames()
    print("test-bench-profile: %d failed" % len(FAILS))
    return 1 if FAILS else 0


if __name__ == "__main__":
    sys.exit(main())
