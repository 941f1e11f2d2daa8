#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""table.py - the one table of `make bench` (issue 22) and the README section made from it.

Every bench writes its rows (bench/bench_rows.hpp) to build/bench/rows/<bench>.json. This script
  - reads every *.json there and validates every row (the fields and types of BenchRow; a file
    that is not a JSON list of such rows is an error naming the file, and nothing is written);
  - joins them with EXPECTED below (the rows issue 22 asks for, grouped as its table): a bench's
    id matches an expected id when it is that id or continues it ("query/lookup_random/geb079"
    takes ".../geb079/cursor" and ".../geb079/root"), compared without case, '/', '_', '-' or
    '.', numbers as numbers ("0.1" is "0.10") - takes() below; what matched another spelling is
    printed;
  - an expected row no bench wrote stays in the table as "not measured"; a row no expected id
    takes goes to a last group "other rows", so nothing is dropped silently;
  - writes OUT/table.json (the joined rows, the date, commit and machine) and OUT/table.md, and
    prints the table.
The README's "Performance" section, between BEGIN and END below, is render() of the committed
bench/results/latest.json (`make bench-readme` copies build/bench/table.json there and rewrites
the section; `make test-bench-table` checks the two agree).

usage: table.py [--rows DIR] [--out DIR]              join, write table.md / table.json, print
       table.py --render JSON                         print the Markdown of a joined file
       table.py --readme README --results JSON --write|--check
"""
import argparse
import json
import math
import os
import platform
import re
import subprocess
import sys
import time

# (group, [(expected id, work, the issue's target)]) in the order of issue 22's table.
EXPECTED = [
    ("integration", [
        ("insert/scan.dat/0.10/simple", "scan.dat 0.1 m, SIMPLE (exact)", "ratio >= 35"),
        ("insert/scan.dat/0.10/discrete", "scan.dat 0.1 m, DISCRETE (exact)", "ratio >= 35"),
        ("insert/scan.dat/0.05/simple", "scan.dat 0.05 m, SIMPLE (exact)", "ratio >= 45"),
        ("insert/scan.dat/0.05/discrete", "scan.dat 0.05 m, DISCRETE (exact)", "ratio >= 45"),
        ("insert/scan.dat/0.05/best", "scan.dat 0.05 m, best exact method", "ratio >= 45"),
        ("insert/tum/0.05/best", "10 TUM frames 0.05 m, best exact method", "ratio >= 10"),
        ("insert/tum/0.10/superray_vs_simple", "10 TUM frames 0.1 m, super rays vs SIMPLE",
         "ratio >= 1.5 vs SIMPLE"),
        ("insert/tum/0.20/superray_vs_simple", "10 TUM frames 0.2 m, super rays vs SIMPLE",
         "ratio >= 1.5 vs SIMPLE"),
    ]),
    ("lookups", [
        ("query/lookup_random/geb079", "random point lookup, geb079",
         "occmap <= 50 ns, ratio >= 4"),
        ("query/lookup_random/fr_079", "random point lookup, fr_079",
         "occmap <= 50 ns, ratio >= 4"),
        ("query/lookup_trajectory", "trajectory lookup", "occmap < 20 ns"),
    ]),
    ("collision / ray", [
        ("query/sphere_0.25", "sphere r=0.25, unknown unsafe", "none set"),
        ("query/raycast_10m", "10 m ray cast", "none set"),
    ]),
    ("memory / scratch", [
        ("scratch/scan.dat/0.05/8MB", "scan.dat 0.05 m exact in 8 MB of scratch",
         "scratch <= 8 MB, speed loss <= 10%"),
        ("scratch/peak_rss", "peak RSS, scan.dat 0.05 m exact", "none set"),
        ("memory/scan.dat/0.05/16bit", "map memory, scan.dat 0.05 m, 16-bit values",
         "occmap <= 17.4% of OctoMap"),
        ("memory/scan.dat/0.05/8bit", "map memory, scan.dat 0.05 m, 8-bit values",
         "occmap <= 10% of OctoMap"),
    ]),
    ("projective", [
        ("projective/tum/0.05", "10 TUM frames 0.05 m, projective", "ratio >= 150 (issue 19)"),
        ("projective/fr1_rpy/frame_p50", "fr1_rpy per-frame time, median", "none set"),
        ("projective/fr1_rpy/frame_p99", "fr1_rpy per-frame time, p99", "none set"),
        ("projective/scratch_per_pixel", "projective scratch per pixel", "none set"),
    ]),
    # Issue 20: ratio = plain / shared writer CPU time, so higher is better as in every row.
    ("shared map (issue 20)", [
        ("shared/writer_cpu/shared_vs_plain", "shared map writer CPU per scan, shared vs plain",
         "shared <= 1.20x plain (ratio >= 0.83)"),
        ("shared/writer_cpu/readers_vs_plain",
         "shared map writer CPU per scan, shared with 4 readers vs plain",
         "shared <= 1.20x plain (ratio >= 0.83)"),
        ("shared/reader_latency/begin_end", "reader latency, occ_read_begin + occ_read_end",
         "none set"),
        ("shared/reader_latency/view", "reader latency, a whole view with its queries",
         "none set"),
    ]),
    # Not in issue 22's table: where the time goes (bench/callgrind_phases.py; issue 19 asks
    # for the projective phases, issue 22 for SIMPLE's instructions per voxel visit).
    ("where the time goes (callgrind instructions)", [
        ("profile/simple/scan.dat/0.10", "SIMPLE scan.dat 0.1 m, instructions per voxel visit",
         "none set"),
        ("profile/projective/tum/0.05", "PROJECTIVE, 10 TUM frames 0.05 m, per frame",
         "none set"),
    ]),
]
OTHER_GROUP = "other rows (not in the issue's list)"
NOT_MEASURED = "not measured"
BEGIN = "<!-- bench-table:begin (generated by `make bench-readme` from bench/results/latest.json:" \
        " do not edit) -->"
END = "<!-- bench-table:end -->"

# The fields of BenchRow (bench/bench_rows.hpp) and their JSON types.
FIELDS = [("id", str), ("work", str), ("unit", str), ("lower_is_better", bool),
          ("octomap", float), ("occmap", float), ("base_label", str), ("base", float),
          ("ratio", float), ("ratio_min", float), ("ratio_max", float), ("reps", int),
          ("target", str), ("met", bool), ("equal", str)]
EQUAL_VALUES = ("yes", "no", "n/a")


class TableError(Exception):
    """A rows file or a README that cannot be used; the message names it."""


def expected_ids():
    return [e[0] for _, rows in EXPECTED for e in rows]


def field_error(row, name, kind):
    """Why row[name] is not a valid value of type kind, or None."""
    if name not in row:
        return "no field '%s'" % name
    v = row[name]
    if kind is bool:
        return None if isinstance(v, bool) else "'%s' must be true or false" % name
    if kind is int:
        ok = isinstance(v, int) and not isinstance(v, bool) and v >= 0
        return None if ok else "'%s' must be an integer >= 0" % name
    if kind is float:
        ok = isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
        return None if ok else "'%s' must be a finite number" % name
    return None if isinstance(v, str) else "'%s' must be a string" % name


def row_error(row):
    """Why one row is not a BenchRow, or None."""
    if not isinstance(row, dict):
        return "not an object"
    for name, kind in FIELDS:
        why = field_error(row, name, kind)
        if why:
            return why
    if not row["id"].strip() or not row["work"].strip() or not row["unit"].strip():
        return "'id', 'work' and 'unit' must not be empty"
    if row["equal"] not in EQUAL_VALUES:
        return "'equal' must be one of %s" % ", ".join(EQUAL_VALUES)
    # %.4g in the file: allow its rounding, not a median outside its own spread.
    slack = 1e-3 * max(abs(row["ratio"]), 1e-12)
    if row["reps"] > 0 and row["ratio"] > 0 and \
            not row["ratio_min"] - slack <= row["ratio"] <= row["ratio_max"] + slack:
        return "ratio %g outside its spread %g..%g" % (row["ratio"], row["ratio_min"],
                                                       row["ratio_max"])
    return None


def reject_constant(name):
    raise ValueError("%s is not a number JSON allows" % name)


def load_rows(rows_dir):
    """Every row of rows_dir/*.json, each with its 'source' file; TableError names a bad file."""
    out, seen = [], {}
    names = sorted(n for n in os.listdir(rows_dir) if n.endswith(".json")) \
        if os.path.isdir(rows_dir) else []
    for name in names:
        path = os.path.join(rows_dir, name)
        try:
            with open(path, encoding="utf-8") as f:
                rows = json.load(f, parse_constant=reject_constant)
        except (OSError, ValueError) as e:
            raise TableError("%s: not a JSON file of rows: %s" % (path, e))
        if not isinstance(rows, list):
            raise TableError("%s: not a JSON list of rows" % path)
        for i, row in enumerate(rows):
            why = row_error(row)
            if why:
                raise TableError("%s: row %d: %s" % (path, i + 1, why))
            extra = sorted(set(row) - {n for n, _ in FIELDS})
            if extra:
                print("table: %s: row %d: ignoring unknown fields %s" % (path, i + 1,
                      ", ".join(extra)), file=sys.stderr)
            if row["id"] in seen:
                raise TableError("%s: row %d: id '%s' is also in %s" % (
                    path, i + 1, row["id"], seen[row["id"]]))
            seen[row["id"]] = path
            clean = {n: row[n] for n, _ in FIELDS}
            clean["source"] = name
            out.append(clean)
    return out, names


def tokens(rid):
    """An id as compared: split at '/', '_' and '-', lower case, numbers by value ("0.1" is
    "0.10", "16" is "16.0"), '.' dropped inside words ("scan.dat" is "scandat")."""
    out = []
    for t in re.split(r"[/_\-]+", rid.lower()):
        if is_number(t):
            out.append("%.12g" % float(t))
        elif t.replace(".", ""):
            out.append(t.replace(".", ""))
    return out


def is_number(token):
    try:
        return math.isfinite(float(token))
    except ValueError:
        return False


def token_takes(e, b):
    """A number only its value; a word also a longer word ("superray" takes "superrays")."""
    return e == b or (not is_number(e) and b.startswith(e))


def takes(expected, bench_id):
    """Whether an expected id takes a bench's id: token by token (token_takes), the bench's id
    may go on (".../geb079" takes ".../geb079/cursor"); or the same text without separators
    ("query/lookuprandom/geb079" for "query/lookup_random/geb079")."""
    e, b = tokens(expected), tokens(bench_id)
    if len(b) >= len(e) and all(token_takes(x, y) for x, y in zip(e, b)):
        return True
    joined, acc = "".join(e), ""
    for t in b:
        acc += t
        if acc == joined:
            return True
        if not joined.startswith(acc):
            break
    return False


def join(rows):
    """The table's lines: expected ids in order with their rows or 'not measured', then others."""
    lines, used, matched = [], set(), []
    for group, items in EXPECTED:
        for eid, work, target in items:
            hits = [r for r in rows if r["id"] not in used and takes(eid, r["id"])]
            for r in hits:
                used.add(r["id"])
                if r["id"] != eid:
                    matched.append((eid, r["id"], r["source"]))
                lines.append(dict(r, group=group, expected=eid, status="measured",
                                  target=r["target"] or target))
            if not hits:
                lines.append({"group": group, "expected": eid, "status": NOT_MEASURED,
                              "work": work, "target": target})
    for r in rows:
        if r["id"] not in used:
            lines.append(dict(r, group=OTHER_GROUP, expected=None, status="measured"))
    return lines, matched


def run_text(cmd):
    try:
        return subprocess.run(cmd, capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return ""


def commit_line():
    sha = run_text(["git", "rev-parse", "--short=10", "HEAD"]) or "unknown"
    dirty = run_text(["git", "status", "--porcelain", "--untracked-files=no"])
    return sha + ("+changes" if dirty else "")


def machine_line():
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            names = [l.split(":", 1)[1].strip() for l in f if l.startswith("model name")]
        if names:
            cpu = names[0]
    except OSError:
        pass
    return "%s, %d cores, %s %s" % (cpu, os.cpu_count() or 0, platform.system(),
                                    platform.release())


def num(v):
    """A value with about 3 significant digits, never in exponent form."""
    a = abs(v)
    if a >= 100:
        return "%.0f" % v
    if a >= 10:
        return "%.1f" % v
    if a >= 1:
        return "%.2f" % v
    return "%.3g" % v if a > 0 else "0"


def cell(text):
    return str(text).replace("|", "\\|").replace("\n", " ")


def ratio_cell(r):
    if r["ratio"] <= 0 or (r["octomap"] < 0 and r["base"] < 0):
        return "-"
    text = num(r["ratio"]) + "x"
    if r["reps"] > 1 and num(r["ratio_min"]) != num(r["ratio_max"]):
        text += " (%s..%s)" % (num(r["ratio_min"]), num(r["ratio_max"]))
    return text


def row_cells(line):
    """The 9 cells: work, OctoMap, occmap, unit, ratio, target, met, equal, reps."""
    if line["status"] == NOT_MEASURED:
        return [line["work"], NOT_MEASURED, NOT_MEASURED, "", "", line["target"], "", "", ""]
    if line["octomap"] >= 0:
        base = num(line["octomap"])
    elif line["base"] >= 0:
        base = "%s (%s)" % (num(line["base"]), line["base_label"] or "base")
    else:
        base = "-"
    return [line["work"], base, num(line["occmap"]), line["unit"], ratio_cell(line),
            line["target"], "yes" if line["met"] else "no", line["equal"], str(line["reps"])]


def render(joined):
    """The Markdown of a joined table: one header line, then one table grouped by the issue's."""
    lines = joined["rows"]
    measured = [l for l in lines if l["status"] != NOT_MEASURED]
    missing = len(lines) - len(measured)
    met = sum(1 for l in measured if l["met"])
    out = ["Made by `make bench` on %s at commit %s on %s. Rows measured: %d (target met: %d); "
           "expected rows not measured: %d." % (
               joined["date"], joined["commit"], joined["machine"], len(measured), met, missing),
           "",
           "| work | OctoMap | occmap | unit | ratio (min..max) | target | met | equal | reps |",
           "|---|---|---|---|---|---|---|---|---|"]
    group = None
    for l in lines:
        if l["group"] != group:
            group = l["group"]
            out.append("| **%s** | | | | | | | | |" % cell(group))
        out.append("| " + " | ".join(cell(c) for c in row_cells(l)) + " |")
    return "\n".join(out) + "\n"


def make_table(rows_dir, out_dir):
    rows, files = load_rows(rows_dir)
    lines, matched = join(rows)
    joined = {"date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
              "commit": commit_line(), "machine": machine_line(), "files": files,
              "file_times": {n: time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime(
                  os.path.getmtime(os.path.join(rows_dir, n)))) for n in files},
              "expected": expected_ids(), "rows": lines}
    text = render(joined)
    os.makedirs(out_dir, exist_ok=True)
    with open(os.path.join(out_dir, "table.json"), "w", encoding="utf-8") as f:
        json.dump(joined, f, indent=1, sort_keys=True)
        f.write("\n")
    with open(os.path.join(out_dir, "table.md"), "w", encoding="utf-8") as f:
        f.write(text)
    for eid, bid, src in matched:
        print("table: %s <- %s (%s)" % (eid, bid, src))
    other = ["%s (%s)" % (l["id"], l["source"]) for l in lines if l["group"] == OTHER_GROUP]
    if other:
        print("table: rows no expected id takes (shown under \"%s\"): %s" % (
            OTHER_GROUP, ", ".join(other)))
    missing = [l["expected"] for l in lines if l["status"] == NOT_MEASURED]
    print("table: %d rows from %s; not measured: %s" % (
        len(rows), ", ".join(files) or "no rows file", ", ".join(missing) or "none"))
    print("table: wrote %s and %s\n" % (os.path.join(out_dir, "table.md"),
                                        os.path.join(out_dir, "table.json")))
    sys.stdout.write(text)


def load_joined(path):
    try:
        with open(path, encoding="utf-8") as f:
            joined = json.load(f, parse_constant=reject_constant)
        for key in ("date", "commit", "machine", "expected", "rows"):
            if key not in joined:
                raise ValueError("no '%s'" % key)
        for i, line in enumerate(joined["rows"]):
            why = line_error(line)
            if why:
                raise ValueError("row %d: %s" % (i + 1, why))
    except (OSError, ValueError, TypeError) as e:
        raise TableError("%s: not a joined table (table.json): %s" % (path, e))
    return joined


def line_error(line):
    """Why one line of a joined table cannot be rendered, or None."""
    if not isinstance(line, dict) or not isinstance(line.get("group"), str):
        return "not an object with a 'group'"
    if line.get("status") == NOT_MEASURED:
        ok = isinstance(line.get("work"), str) and isinstance(line.get("target"), str)
        return None if ok else "a row not measured wants 'work' and 'target'"
    if line.get("status") != "measured":
        return "'status' must be 'measured' or '%s'" % NOT_MEASURED
    return row_error(line)


def readme_split(path, begin=BEGIN, end=END):
    """README text as (before, section, after), section being what lies between the markers
    (also port/baremetal/fw_table.py's, with its own markers)."""
    with open(path, encoding="utf-8") as f:
        text = f.read()
    begins = [m.start() for m in re.finditer(re.escape(begin) + "\n", text)]
    ends = [m.start() for m in re.finditer("^" + re.escape(end) + "$", text, re.M)]
    if len(begins) != 1 or len(ends) != 1 or ends[0] < begins[0]:
        raise TableError("%s: wants one line '%s' and, after it, one line '%s' (found %d and %d)"
                         % (path, begin, end, len(begins), len(ends)))
    a = begins[0] + len(begin) + 1
    return text[:a], text[a:ends[0]], text[ends[0]:]


def readme(path, results, write):
    joined = load_joined(results)
    want = render(joined)
    before, have, after = readme_split(path)
    if write:
        with open(path, "w", encoding="utf-8") as f:
            f.write(before + want + after)
        times = joined.get("file_times", {})
        print("table: %s: Performance section rewritten from %s, made %s from %s" % (
            path, results, joined["date"], ", ".join(
                "%s (written %s)" % (n, times.get(n, "?")) for n in joined.get("files", []))
            or "no rows file"))
        return 0
    if joined["expected"] != expected_ids():
        print("FAIL: %s was joined with another list of expected rows than bench/table.py's: "
              "run `make bench-table bench-readme`" % results)
        return 1
    if have != want:
        print("FAIL: %s: the section between the bench-table markers is not what bench/table.py "
              "renders from %s (numbers typed by hand?): run `make bench-readme`" % (path, results))
        for a, b in zip(have.split("\n"), want.split("\n")):
            if a != b:
                print("  README:   %s\n  rendered: %s" % (a, b))
                break
        return 1
    print("PASS: %s: the Performance table is render(%s)" % (path, results))
    return 0


def main(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--rows", default="build/bench/rows")
    p.add_argument("--out", default="build/bench")
    p.add_argument("--render", metavar="JSON")
    p.add_argument("--readme", metavar="README")
    p.add_argument("--results", metavar="JSON", default="bench/results/latest.json")
    mode = p.add_mutually_exclusive_group()
    mode.add_argument("--write", action="store_true")
    mode.add_argument("--check", action="store_true")
    a = p.parse_args(argv)
    try:
        if a.render:
            sys.stdout.write(render(load_joined(a.render)))
            return 0
        if a.readme:
            if not (a.write or a.check):
                p.error("--readme wants --write or --check")
            return readme(a.readme, a.results, a.write)
        make_table(a.rows, a.out)
        return 0
    except TableError as e:
        print("table.py: error: %s" % e, file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
