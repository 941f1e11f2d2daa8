#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""fw_table_check.py BUILD - `make test-fw-table` (issue 24): the firmware numbers of the READMEs
against port/baremetal/results/firmware.json (port/baremetal/fw_table.py).

(a) README.md's Firmware tables and port/baremetal/README's "How big" list are render() of the
    committed results, byte for byte; a copy of either with one digit changed, or without its
    markers, fails the same check (so the check can fail).
(b) The bench-m4 log parser on a synthetic log: its rows and set-up; a log of failed calls and a
    truncated one are errors.
(c) When make cross has written BUILD/fw/stack.json: the results understate no stack bound of the
    current build that the READMEs show (a bench row's entry point, a class's deepest chain).
"""
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "port", "baremetal"))
import fw_table  # noqa: E402

RESULTS = os.path.join(ROOT, "port", "baremetal", "results", "firmware.json")
FAILS = []

LOG = ("== bench-m4: instructions per call on Cortex-M4F (qemu mps2-an386, -icount shift=0; "
       "timer: 40.0 instructions per tick, so +-40 per call)\n"
       "map: geb079 crop (-2.0 -3.0 -0.4) .. (4.0 3.0 2.8) m, 0.08 m, 105021-byte snapshot in "
       "flash; arena 1024 KB, 2814 inner + 6909 leaf blocks used (268136 bytes) after load; "
       "scratch 192 KB static (bounds: 64-ray scan 96903 B, 8x8 frame 176394 B)\n") + """call                               calls     median        max       mean  work
(subtracted: timer reads + the indirect call, 0 instructions)
occ_map_state_at (point lookup)      300        520        560        510  one descent
occ_map_evict slice (64 blocks)      300     118880     183960     120127  keep 2 m
after the scans and frames: 10638 inner + 23613 leaf blocks (973544 bytes)
occ_io_load (the crop)                 5   16776360   16776360   16776360  the snapshot above
bench-m4: all calls returned OCC_OK
"""


def check(ok, what):
    print("%s fw-table: %s" % ("PASS" if ok else "FAIL", what))
    if not ok:
        FAILS.append(what)


def readme_check(readme, port_readme):
    p = subprocess.run([sys.executable, os.path.join(ROOT, "port", "baremetal", "fw_table.py"),
                        "readme", "--results", RESULTS, "--readme", readme, "--port-readme",
                        port_readme, "--check"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       universal_newlines=True)
    return p.returncode, p.stdout


def one_digit_changed(src, dst, begin):
    """dst: src with the first digit after the begin marker changed."""
    text = open(src, encoding="utf-8").read()
    a = text.index(begin) + len(begin)
    m = re.compile(r"\d").search(text, a)
    with open(dst, "w", encoding="utf-8") as f:
        f.write(text[:m.start()] + str((int(m.group(0)) + 1) % 10) + text[m.end():])


def check_readmes(tmp):
    readme = os.path.join(ROOT, "README.md")
    port = os.path.join(ROOT, "port", "baremetal", "README")
    rc, out = readme_check(readme, port)
    check(rc == 0, "README.md and port/baremetal/README are render(port/baremetal/results/"
          "firmware.json)" + ("" if rc == 0 else ": " + out.strip().replace("\n", " | ")))
    r2, p2 = os.path.join(tmp, "README.md"), os.path.join(tmp, "README")
    one_digit_changed(readme, r2, fw_table.TABLE_BEGIN)
    shutil.copy(port, p2)
    rc, out = readme_check(r2, p2)
    check(rc == 1 and "FAIL: %s" % r2 in out, "a README.md with one digit changed fails")
    shutil.copy(readme, r2)
    one_digit_changed(port, p2, fw_table.SIZE_BEGIN)
    rc, out = readme_check(r2, p2)
    check(rc == 1 and "FAIL: %s" % p2 in out,
          "a port/baremetal/README with one digit changed fails")
    with open(p2, "w", encoding="utf-8") as f:
        f.write(open(port, encoding="utf-8").read().replace(fw_table.SIZE_END, ""))
    rc, out = readme_check(r2, p2)
    check(rc == 1 and "wants one line" in out, "a README without its end marker fails")


def check_parser(tmp):
    log = os.path.join(tmp, "bench.log")
    open(log, "w").write(LOG)
    b = fw_table.parse_bench(log)
    check([(x["fn"], x["what"], x["calls"], x["median"], x["max"]) for x in b["rows"]] ==
          [("occ_map_state_at", "point lookup", 300, 520, 560),
           ("occ_map_evict", "slice (64 blocks)", 300, 118880, 183960),
           ("occ_io_load", "the crop", 5, 16776360, 16776360)] and b["timer"] == 40 and
          b["map"]["snapshot"] == 105021 and b["map"]["grown"] == 973544 and
          b["map"]["x"] == 6.0, "the bench-m4 log parser: rows, timer, map set-up")
    for bad, what in ((LOG.replace("all calls returned OCC_OK", "FAILED calls"), "failed calls"),
                      (LOG.split("after the scans")[0], "a truncated log")):
        open(log, "w").write(bad)
        try:
            fw_table.parse_bench(log)
            check(False, "a bench-m4 log of %s is an error" % what)
        except fw_table.FwError:
            check(True, "a bench-m4 log of %s is an error" % what)


def check_current(stack_json):
    if not os.path.exists(stack_json):
        print("fw-table: no %s (make cross): the current bounds are not compared" % stack_json)
        return
    r = json.load(open(RESULTS, encoding="utf-8"))
    now = json.load(open(stack_json, encoding="utf-8"))
    shown = {x["fn"] for x in r["bench"]["rows"]}
    under = []
    for fn in sorted(shown & set(now["entries"])):
        for t, _ in fw_table.TARGETS:
            b_now, b = now["entries"][fn]["stack"][t], r["entries"][fn]["stack"][t]
            if b_now > b:
                under.append("%s %s %d > %d" % (fn, t, b_now, b))
    for c in r["classes"]:
        for (fn, b), (fn_now, b_now), (t, _) in zip(fw_table.deepest(r, c["name"]),
                                                    fw_table.deepest(now, c["name"]),
                                                    fw_table.TARGETS):
            if b_now > b:
                under.append("class %s %s: %s %d > %s %d" % (c["name"], t, fn_now, b_now, fn, b))
    check(not under, "the results understate no stack bound of the current build (%s)%s" % (
        stack_json, "" if not under else ": " + "; ".join(under) + ": run make fw-readme"))


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else "build"
    with tempfile.TemporaryDirectory() as tmp:
        check_readmes(tmp)
        check_parser(tmp)
    check_current(os.path.join(build, "fw", "stack.json"))
    print("%s test-fw-table: %d failed" % ("FAIL" if FAILS else "PASS", len(FAILS)))
    return 1 if FAILS else 0


if __name__ == "__main__":
    sys.exit(main())
