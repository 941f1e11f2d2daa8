#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""stack_measured_check.py - the stack an entry point really used on the emulated target
(port/baremetal/m0_selftest.c paints the stack, makes the call and finds the lowest word
written; lines "stack-measured TARGET NAME WRAPPER BYTES") against the static call-chain bound of
tests/stack_budget.py. The measurement includes the test's wrapper function (its frame from the
.su file). Fails when a measurement exceeds bound + wrapper: the static analysis missed stack.

usage: stack_measured_check.py LOG OBJ_ROOT CFLAGS WRAPPER_SU"""
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import stack_budget  # noqa: E402


def main():
    log, root, cflags, su = sys.argv[1:5]
    wrappers = {}
    for line in open(su):
        parts = line.rstrip("\n").split("\t")
        wrappers[parts[0].rsplit(":", 1)[-1]] = int(parts[1])
    t = stack_budget.Target("m0", root, cflags)
    n, bad = 0, 0
    for line in open(log, errors="replace"):
        m = re.match(r"^stack-measured (\S+) (\S+) (\S+) (\d+)", line)
        if not m:
            continue
        name, wrapper, used = m.group(2), m.group(3), int(m.group(4))
        bound = t.worst(name)[0]
        own = used - wrappers.get(wrapper, 0)
        ok = wrapper in wrappers and own <= bound and not t.problems
        n += 1
        bad += 0 if ok else 1
        print("%s stack-measured: %-22s used %5d B (+ %s %d B), static bound %5d B%s" % (
            "PASS" if ok else "FAIL", name, own, wrapper, wrappers.get(wrapper, -1), bound,
            "" if ok else ": the call-chain analysis misses stack"))
    if n == 0:
        print("FAIL stack-measured: no measurements in %s" % log)
        return 1
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
