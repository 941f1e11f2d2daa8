#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""bench_table_check.py OUT_DIR - `make test-bench-table` (issue 22): bench/table.py on synthetic
rows, and the README's Performance section against the committed bench/results/latest.json.

(a) Good rows in two files (one id spelled otherwise, two rows under one expected id, a row no
    expected id takes, a '|' in a work text, a row compared with a base instead of OctoMap):
    table.md holds the hand-written lines below, every other expected row reads "not measured",
    the groups come in the issue's order, stdout prints the table and what matched by prefix.
    Malformed files (truncated JSON, nan, a missing field, wrong types, a median outside its
    spread, a duplicate id, not a list): exit status 1, the message names the file, no table.
(b) The README section is render(bench/results/latest.json), byte for byte; and a README with
    one digit changed, or without its markers, fails the same check (so the check can fail).
"""
import json
import os
import shutil
import subprocess
import sys

TABLE = "bench/table.py"
FAILS = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        FAILS.append(what)


def row(rid, work, octomap, occmap, ratio, lo, hi, **kw):
    r = {"id": rid, "work": work, "unit": "ms", "lower_is_better": True, "octomap": octomap,
         "occmap": occmap, "base_label": "", "base": -1, "ratio": ratio, "ratio_min": lo,
         "ratio_max": hi, "reps": 7, "target": "ratio >= 35", "met": False, "equal": "yes"}
    r.update(kw)
    return r


GOOD_A = [
    row("insert/scan.dat/0.10/simple", "scan.dat 0.1 m, SIMPLE (exact)", 1006, 71.04, 14.16,
        13.21, 15.07),
    row("insert/scan_dat/0.1/discrete", "scan.dat 0.1 m, DISCRETE | exact", 1006, 25.0, 40.24,
        38.0, 41.5, met=True),
    row("query/lookup_random/geb079/cursor", "random lookup geb079, cursor", 209, 84.0, 2.488,
        2.4, 2.6, unit="ns", target="occmap <= 50 ns, ratio >= 4", equal="n/a"),
    row("query/lookup_random/geb079/root", "random lookup geb079, root", 209, 104.0, 2.01,
        2.01, 2.01, unit="ns", target="occmap <= 50 ns, ratio >= 4", reps=1),
]
GOOD_B = [
    row("memory/scan.dat/0.05/8bit", "map memory 0.05 m, 8-bit", -1, 9.0, 1.989, 1.989, 1.989,
        unit="MB", base_label="16-bit values", base=17.9, target="occmap <= 10% of OctoMap",
        equal="n/a", reps=1),
    row("query/something_new", "a row the issue does not list", 10.0, 5.0, 2.0, 1.5, 2.5,
        target="none set", equal="no"),
]
# The lines table.md must hold for the rows above (worked out by hand from bench/table.py's
# rules: 3 significant digits, spread shown when reps > 1 and its ends differ, '|' escaped).
WANT_LINES = [
    "| scan.dat 0.1 m, SIMPLE (exact) | 1006 | 71.0 | ms | 14.2x (13.2..15.1) | ratio >= 35 | no "
    "| yes | 7 |",
    "| scan.dat 0.1 m, DISCRETE \\| exact | 1006 | 25.0 | ms | 40.2x (38.0..41.5) | ratio >= 35 "
    "| yes | yes | 7 |",
    "| random lookup geb079, cursor | 209 | 84.0 | ns | 2.49x (2.40..2.60) | occmap <= 50 ns, "
    "ratio >= 4 | no | n/a | 7 |",
    "| random lookup geb079, root | 209 | 104 | ns | 2.01x | occmap <= 50 ns, ratio >= 4 | no "
    "| yes | 1 |",
    "| map memory 0.05 m, 8-bit | 17.9 (16-bit values) | 9.00 | MB | 1.99x | occmap <= 10% of "
    "OctoMap | no | n/a | 1 |",
    "| a row the issue does not list | 10.0 | 5.00 | ms | 2.00x (1.50..2.50) | none set | no | "
    "no | 7 |",
    "| trajectory lookup | not measured | not measured |  |  | occmap < 20 ns |  |  |  |",
]
GROUPS = ["integration", "lookups", "collision / ray", "memory / scratch", "projective",
          "shared map (issue 20)", "where the time goes (callgrind instructions)",
          "other rows (not in the issue's list)"]


# (expected id, a bench's id, whether the first takes the second): bench/table.py's takes().
MATCH_CASES = [
    ("query/lookup_random/geb079", "query/lookup_random/geb079/cursor", True),
    ("query/lookup_random/geb079", "query/lookup_random/geb079.bt", True),
    ("query/lookup_random/geb079", "query/lookuprandom/geb079", True),
    ("query/lookup_random/geb079", "query/lookup_random/fr_079", False),
    ("query/sphere_0.25", "query/sphere/0.250/unknown_unsafe", True),
    ("query/sphere_0.25", "query/sphere_0.255", False),
    ("insert/scan.dat/0.10/simple", "insert/scan_dat/0.1/simple", True),
    ("insert/scan.dat/0.10/simple", "insert/scan.dat/0.05/simple", False),
    ("insert/tum/0.10/superray_vs_simple", "insert/tum/0.1/superrays_vs_simple", True),
    ("memory/scan.dat/0.05/16bit", "memory/scan.dat/0.05/16-bit", True),
    ("memory/scan.dat/0.05/8bit", "memory/scan.dat/0.05/16bit", False),
    ("scratch/scan.dat/0.05/8MB", "scratch/scan.dat/0.05/8_mb", True),
    ("projective/fr1_rpy/frame_p50", "projective/fr1_rpy/frame_p99", False),
    ("query/raycast_10m", "query/ray_cast_10m", True),
    ("shared/reader_latency/view", "shared/reader_latency/view/p99", True),
    ("shared/reader_latency/begin_end", "shared/reader_latency/view/p50", False),
    ("shared/writer_cpu/shared_vs_plain", "shared/writer_cpu/readers_vs_plain", False),
]


def matching():
    sys.dont_write_bytecode = True  # no __pycache__ in the source tree
    sys.path.insert(0, os.path.dirname(TABLE))
    import table  # noqa: E402 - bench/table.py itself
    for e, b, want in MATCH_CASES:
        check(table.takes(e, b) == want, "takes(%s, %s) is %s" % (e, b, want))
    ids = table.expected_ids()
    overlap = [(x, y) for x in ids for y in ids if x != y and table.takes(x, y)]
    check(len(ids) == 27 and len(set(ids)) == 27 and not overlap,
          "27 distinct expected ids, none takes another's (%s)" % overlap)


def run(*args):
    p = subprocess.run([sys.executable, TABLE] + list(args), capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def write_rows(d, files):
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(os.path.join(d, "rows"))
    for name, content in files.items():
        with open(os.path.join(d, "rows", name), "w", encoding="utf-8") as f:
            f.write(content if isinstance(content, str) else json.dumps(content))


def good_rows(out):
    d = os.path.join(out, "good")
    write_rows(d, {"a.json": GOOD_A, "b.json": GOOD_B, "notes.txt": "not a rows file"})
    rc, so, se = run("--rows", os.path.join(d, "rows"), "--out", d)
    check(rc == 0, "good rows: exit 0 (%d: %s)" % (rc, se.strip()))
    with open(os.path.join(d, "table.md"), encoding="utf-8") as f:
        md = f.read()
    lines = md.split("\n")
    for want in WANT_LINES:
        check(want in lines, "table.md has the line %s" % want)
    nm = [l for l in lines if "| not measured | not measured |" in l]
    check(len(nm) == 27 - 4, "23 of the 27 expected rows read 'not measured' (%d)" % len(nm))
    at = [lines.index("| **%s** | | | | | | | | |" % g) if "| **%s** | | | | | | | | |" % g
          in lines else -1 for g in GROUPS]
    check(-1 not in at and at == sorted(at), "the groups come in the issue's order %s" % at)
    check(md in so, "stdout ends with the table")
    check("table: insert/scan.dat/0.10/discrete <- insert/scan_dat/0.1/discrete (a.json)" in so,
          "stdout says which id matched another spelling")
    check("table: rows no expected id takes (shown under \"other rows (not in the issue's list)\")"
          ": query/something_new (b.json)" in so, "stdout names the row no expected id takes")
    check(lines[0].startswith("Made by `make bench` on ") and lines[0].endswith(
        ". Rows measured: 6 (target met: 1); expected rows not measured: 23."),
        "header line: %s" % lines[0])
    with open(os.path.join(d, "table.json"), encoding="utf-8") as f:
        joined = json.load(f)
    check(len(joined["rows"]) == 23 + 6 and joined["files"] == ["a.json", "b.json"],
          "table.json joins 29 lines from a.json and b.json")
    rc, so2, _ = run("--render", os.path.join(d, "table.json"))
    check(rc == 0 and so2 == md, "--render of table.json is table.md")


def malformed(out):
    bad = dict(GOOD_A[0])
    cases = {
        "truncated": '[{"id": "x", "work": ',
        "nan": json.dumps([bad]).replace('"occmap": 71.04', '"occmap": nan'),
        "infinity": json.dumps([bad]).replace('"octomap": 1006', '"octomap": Infinity'),
        "missing_met": [{k: v for k, v in bad.items() if k != "met"}],
        "reps_string": [dict(bad, reps="7")],
        "met_int": [dict(bad, met=1)],
        "equal_word": [dict(bad, equal="maybe")],
        "empty_id": [dict(bad, id=" ")],
        "outside_spread": [dict(bad, ratio=20.0)],
        "not_a_list": bad,
        "not_objects": [[1, 2]],
    }
    for name, content in cases.items():
        d = os.path.join(out, "bad_" + name)
        write_rows(d, {"a_good.json": GOOD_B, "z_%s.json" % name: content})
        rc, _, se = run("--rows", os.path.join(d, "rows"), "--out", d)
        check(rc == 1 and ("z_%s.json" % name) in se and
              not os.path.exists(os.path.join(d, "table.md")),
              "malformed %s: exit 1, names the file, writes nothing (%d: %s)" % (
                  name, rc, se.strip()))
    d = os.path.join(out, "bad_duplicate")
    write_rows(d, {"a.json": GOOD_A, "b.json": [GOOD_A[1]]})
    rc, _, se = run("--rows", os.path.join(d, "rows"), "--out", d)
    check(rc == 1 and "a.json" in se and "b.json" in se, "duplicate id: exit 1, names both files")


def readme(out):
    rc, so, _ = run("--readme", "README.md", "--results", "bench/results/latest.json", "--check")
    check(rc == 0, "README.md's Performance section is render(bench/results/latest.json): %s"
          % so.strip())
    with open("README.md", encoding="utf-8") as f:
        text = f.read()
    start = text.index("<!-- bench-table:begin")
    digit = next(i for i in range(start, len(text)) if text[i].isdigit())
    planted = text[:digit] + str((int(text[digit]) + 1) % 10) + text[digit + 1:]
    for name, body in (("digit", planted), ("markers", text.replace("<!-- bench-table:end -->",
                                                                      ""))):
        p = os.path.join(out, "README_%s.md" % name)
        with open(p, "w", encoding="utf-8") as f:
            f.write(body)
        rc, so, se = run("--readme", p, "--results", "bench/results/latest.json", "--check")
        check(rc != 0, "planted README (%s changed) fails the check: %s" % (
            name, (so + se).strip().split("\n")[0]))
    p = os.path.join(out, "README_written.md")
    shutil.copy("README.md", p)
    rc, _, _ = run("--readme", p, "--results", os.path.join(out, "good", "table.json"), "--write")
    with open(p, encoding="utf-8") as f:
        written = f.read()
    rc2, _, _ = run("--readme", p, "--results", os.path.join(out, "good", "table.json"), "--check")
    outside = written[:written.index("<!-- bench-table:begin")] == text[:start] and \
        written.split("<!-- bench-table:end -->")[1] == text.split("<!-- bench-table:end -->")[1]
    check(rc == 0 and rc2 == 0 and outside and WANT_LINES[0] in written,
          "--write puts another table between the markers, the rest unchanged, --check agrees")


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    matching()
    good_rows(out)
    malformed(out)
    readme(out)
    print("%s test-bench-table (%d failed)" % ("FAIL" if FAILS else "PASS", len(FAILS)))
    return 1 if FAILS else 0


if __name__ == "__main__":
    sys.exit(main())
