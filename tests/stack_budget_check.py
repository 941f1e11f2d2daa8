#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""stack_budget_check.py - tests/stack_budget.py against hand-made call graphs (GCC 12's .ci
format) with hand-computed answers: a chain sum through a static helper and a library call
(memset, whose frame comes from newlib's disassembly), an indirect call listed with '+', an
entry point over budget, an entry point over its class limit (planted), a budget above its
class limit, a row naming no class, recursion, a declared function missing from the build, a
function without a budget, a header's Budgets section: a stated stack bound below the chain, an
entry point without a statement, a statement without a work bound. Prints PASS / FAIL lines;
exit 1 on a failure.

usage: stack_budget_check.py   (needs arm-none-eabi-gcc / objdump, like make cross)"""
import json
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
M4 = "-mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard"

CI = '''graph: { title: "src/a.c"
node: { title: "src/a.c:helper" label: "helper\\nsrc/a.c:3:13\\n40 bytes (static)" }
node: { title: "memset" label: "memset\\n/usr/include/string.h:1:1" shape : ellipse }
edge: { sourcename: "src/a.c:helper" targetname: "memset" label: "src/a.c:4:5" }
node: { title: "occ_deep" label: "occ_deep\\nsrc/a.c:9:6\\n100 bytes (static)" }
edge: { sourcename: "occ_deep" targetname: "src/a.c:helper" label: "src/a.c:10:5" }
edge: { sourcename: "occ_deep" targetname: "occ_leaf" label: "src/a.c:11:5" }
node: { title: "occ_leaf" label: "occ_leaf\\nsrc/a.c:15:6\\n16 bytes (static)" }
node: { title: "__indirect_call" label: "Indirect Call Placeholder" shape : ellipse }
node: { title: "occ_cb" label: "occ_cb\\nsrc/a.c:20:6\\n24 bytes (static)" }
edge: { sourcename: "occ_cb" targetname: "__indirect_call" label: "src/a.c:21:5" }
%s
}
'''
RECURSION = '''node: { title: "occ_loop" label: "occ_loop\\nsrc/a.c:30:6\\n8 bytes (static)" }
node: { title: "src/a.c:again" label: "again\\nsrc/a.c:35:13\\n8 bytes (static)" }
edge: { sourcename: "occ_loop" targetname: "src/a.c:again" label: "src/a.c:31:5" }
edge: { sourcename: "src/a.c:again" targetname: "occ_loop" label: "src/a.c:36:5" }'''
HEADER = '''/* fixture */
void occ_deep(void);
void occ_leaf(void);
void occ_cb(void (*fn)(void));
%s
%s
'''
# The header's Budgets section (stack_budget.py reads the statements of that section only).
STATED = '''/* ---- Budgets ----
 *   occ_deep: stack <= 4096 / 4096 B; work: O(1)
 *   occ_leaf, occ_cb: stack <= 24 / 24 B; work: O(1), the callback's
 *       own on top
 */'''
CLASSES = "class q 1024 queries\nclass big 4096 the rest\n"

failed = 0


def check(ok, what):
    global failed
    print("%s stack-budget-check: %s" % ("PASS" if ok else "FAIL", what))
    failed += 0 if ok else 1


def run(tmp, ci_extra="", header_extra="", budgets="* q 1024 1024\n", stated=STATED):
    os.makedirs(os.path.join(tmp, "m4"), exist_ok=True)
    os.makedirs(os.path.join(tmp, "inc"), exist_ok=True)
    open(os.path.join(tmp, "m4", "a.ci"), "w").write(CI % ci_extra)
    open(os.path.join(tmp, "inc", "x.h"), "w").write(HEADER % (header_extra, stated))
    open(os.path.join(tmp, "budgets.txt"), "w").write(CLASSES + budgets)
    p = subprocess.run([sys.executable, os.path.join(HERE, "stack_budget.py"),
                        os.path.join(tmp, "budgets.txt"), os.path.join(tmp, "inc"),
                        "m4=%s=%s" % (os.path.join(tmp, "m4"), M4)],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    return p.returncode, p.stdout.decode()


def row(out, fn):
    m = re.search(r"^%s\s+\S+\s+(\d+)(\+?)\s+(\d+)" % fn, out, re.M)
    return (int(m.group(1)), m.group(2)) if m else (None, None)


def memset_frame():
    lib = subprocess.run(["arm-none-eabi-gcc"] + M4.split() + ["-print-file-name=libc_nano.a"],
                         stdout=subprocess.PIPE, check=True).stdout.decode().strip()
    sys.path.insert(0, HERE)
    import stack_budget
    frames, _ = stack_budget.read_libs(M4)
    return frames["memset"][0], lib


def uldivmod_chain():
    """__aeabi_uldivmod's chain on M4 from the archives; an assembler routine whose callee
    (__udivmoddi4) and whose other names (__aeabi_ldiv0) objdump does not label."""
    import stack_budget
    frames, calls = stack_budget.read_libs(M4)
    t = stack_budget.Target.__new__(stack_budget.Target)
    t.frames, t.calls, t.problems, t.memo = frames, calls, [], {}
    b = t.worst("__aeabi_uldivmod")[0]
    return b if not t.problems else -1


def main():
    ms, lib = memset_frame()
    with tempfile.TemporaryDirectory() as tmp:
        rc, out = run(tmp)
        check(rc == 0 and "PASS stack budget: 3 entry points" in out, "clean fixture passes")
        check(row(out, "occ_deep") == (100 + 40 + ms, ""),
              "occ_deep = 100 + helper 40 + memset %d (from %s) = %d" % (ms, lib, 140 + ms))
        check(row(out, "occ_leaf") == (16, ""), "occ_leaf = its own 16 B")
        check(row(out, "occ_cb") == (24, "+") and "src/a.c:21" in out and "occ_cb 24 B" in out,
              "occ_cb: 24 B + the callback, its call site listed with the 24 B in use there")
        rc, out = run(tmp, budgets="occ_deep q %d 0\n* q 1024 1024\n" % (139 + ms))
        check(rc == 1 and re.search(r"FAIL stack budget: occ_deep: %d B on m4, budget %d B" %
                                    (140 + ms, 139 + ms), out) is not None,
              "one byte over its budget fails")
        lim = 139 + ms
        rc, out = run(tmp, budgets="class tiny %d planted\nocc_deep tiny %d %d\n* q 1024 1024\n"
                      % (lim, lim, lim))
        check(rc == 1 and "FAIL stack budget: occ_deep: %d B on m4, above its class tiny limit "
              "of %d B" % (140 + ms, lim) in out,
              "a planted entry point one byte over its class limit fails, naming the class")
        rc, out = run(tmp, budgets="occ_deep q 2048 2048\n* q 1024 1024\n")
        check(rc == 1 and "occ_deep: budget 2048 / 2048 B above its class q limit of 1024 B" in out,
              "a budget above its class limit fails (within it or not)")
        rc, out = run(tmp, budgets="occ_deep nosuch 1024 1024\n* q 1024 1024\n")
        check(rc == 1 and "occ_deep: class nosuch is not defined" in out,
              "a row naming no defined class fails")
        rc, out = run(tmp, ci_extra=RECURSION, header_extra="void occ_loop(void);",
                      stated=STATED.replace("occ_leaf, occ_cb:", "occ_leaf, occ_cb, occ_loop:"))
        check(rc == 1 and "FAIL stack budget: m4: recursion: occ_loop -> again -> occ_loop" in out,
              "recursion fails, with its cycle")
        rc, out = run(tmp, header_extra="int occ_gone(int x);")
        check(rc == 1 and "occ_gone (x.h) is declared but not in the firmware build" in out,
              "a declared function missing from the build fails")
        rc, out = run(tmp, header_extra="int occ_gone(int x);",
                      budgets="not-built occ_gone\n* q 1024 1024\n")
        check(rc == 0, "... unless the budget file lists it as not-built")
        rc, out = run(tmp, budgets="occ_deep q 1024 1024\n")
        check(rc == 1 and "occ_leaf has no budget" in out, "a function without a budget fails")
        rc, out = run(tmp, budgets="occ_deep big 1024 1024\n* q 1024 1024\n")
        check(rc == 0 and re.search(r"^  big +<= 4096 B +1 entry points; m4 occ_deep %d B" %
                                    (140 + ms), out, re.M) is not None,
              "the class summary names each class's deepest entry point")
        libcall = 'edge: { sourcename: "occ_leaf" targetname: "__aeabi_uldivmod" }'
        rc, out = run(tmp, ci_extra=libcall,
                      stated=STATED.replace("24 / 24 B", "4096 / 4096 B"))
        ul = uldivmod_chain()
        check(rc == 0 and row(out, "occ_leaf") == (16 + ul, "") and ul > 0,
              "a libcall edge without a label (GCC's __aeabi_uldivmod) counts: 16 + %d B" % ul)
        check("3 entry points checked, 0 without a statement, 0 without a work bound" in out,
              "the header's statements that hold pass (a pattern list, a continued work bound)")
        deep = " *   occ_deep: stack <= 4096 / 4096 B; work: O(1)\n"
        rc, out = run(tmp, stated=STATED.replace(deep, ""))
        check(rc == 1 and "occ_deep has no statement in the Budgets section of x.h" in out,
              "an entry point without a statement in its header fails")
        rc, out = run(tmp, stated=STATED.replace("occ_deep: stack <= 4096 / 4096 B; work: O(1)",
                                                 "occ_deep: stack <= 4096 / 4096 B;"))
        check(rc == 1 and "occ_deep: its statement in x.h (occ_deep) gives no work bound" in out,
              "a statement without a work bound fails")
        rc, out = run(tmp, stated=STATED.replace("24 / 24 B", "15 / 15 B"))
        check(rc == 1 and "occ_leaf: 16 B on m4, but x.h states <= 15 B" in out,
              "a header stating one byte less than the chain fails")
        rc, out = run(tmp, stated="/* occ_deep: stack <= 4096 / 4096 B; work: O(1) */\n" + STATED)
        check(rc == 0, "a statement outside the Budgets section is not read")
        rc, out = run(tmp, budgets="occ_deep q 1024 1024\n* q 1024 1024\n")
        check(rc == 0 and "occ_deep m4 1024 > %d" % (-(-(140 + ms) * 105 // 100 // 64) * 64) in out,
              "a budget above the file's rule (+5 %, 64 B) is listed, not failed")
        path = os.path.join(tmp, "stack.json")
        p = subprocess.run([sys.executable, os.path.join(HERE, "stack_budget.py"), "--json", path,
                            os.path.join(tmp, "budgets.txt"), os.path.join(tmp, "inc"),
                            "m4=%s=%s" % (os.path.join(tmp, "m4"), M4)], stdout=subprocess.PIPE)
        data = json.load(open(path))
        check(p.returncode == 0 and data["entries"]["occ_deep"]["stack"]["m4"] == 140 + ms and
              data["entries"]["occ_deep"]["class"] == "q" and
              data["classes"][0] == {"name": "q", "limit": 1024, "text": "queries"},
              "--json writes every entry point's bound, budget and class")
    print("%s stack-budget-check: %d failed" % ("FAIL" if failed else "PASS", failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
