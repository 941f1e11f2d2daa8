#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""stack_budget.py - worst call-chain stack of every public entry point on the cross targets.

Sources: GCC 12's -fcallgraph-info=su (.ci files: one node per function with its -fstack-usage
frame, one edge per call left after inlining) for the core, and the disassembly of the target's
newlib / libgcc archives for the library functions the core calls (frame = every push, vpush,
sub sp and sp pre-decrement in the function summed, an upper bound; callees from the call
relocations; an assembler routine's other names share its frame).
An entry point is every function declared in include/occmap/*.h (host/ excluded). Its bound is
its frame plus the worst bound of its callees. Calls through function pointers (GCC's
__indirect_call) count as 0 here and are listed: the caller adds its own callback's stack.
Recursion anywhere below an entry point fails the check (no bound is claimed for a cycle).

The BUDGETS file is the one table that classifies the entry points: `class NAME LIMIT text`
lines give each class its limit (issue 24: queries and sector updates 1 KB, integration and file
loading 1.5 KB), and every row `PATTERN CLASS M4 M0` puts the entry points it matches (first
matching row wins) in a class, with their enforced budgets.
Fails (exit 1) when an entry point exceeds its budget or its class limit, a budget exceeds its
class limit, a row names no known class, an entry point has no row, is declared but missing from
the build (unless the budgets file says so), reaches a function whose stack is unknown or
dynamic, or has no statement in its header's Budgets section (a stack bound that holds and a
work bound: "occ_x, occ_y: stack <= M4 / M0 B; work: ...").

usage: stack_budget.py [--json OUT] BUDGETS HEADER_DIR TARGET=OBJ_ROOT=CFLAGS...
       (e.g. m4=build/cross/m4/src="-mcpu=.."); OUT gets every entry point's bounds and class
"""
import collections
import fnmatch
import glob
import json
import os
import re
import subprocess
import sys

NODE_RE = re.compile(r'^node: \{ title: "([^"]+)" label: "([^"]*)"')
EDGE_RE = re.compile(r'^edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"(?: label: "([^"]*)")?')
FRAME_RE = re.compile(r'\\n(\d+) bytes \(([a-z,]+)\)')
INDIRECT = "__indirect_call"


def read_callgraph(root):
    """Frames {function: (bytes, kind, where)}, calls {function: [(callee, site)]}."""
    frames, calls = {}, collections.defaultdict(list)
    for ci in sorted(glob.glob(os.path.join(root, "**", "*.ci"), recursive=True)):
        for line in open(ci, encoding="utf-8", errors="replace"):
            m = NODE_RE.match(line)
            if m:
                f = FRAME_RE.search(m.group(2))
                if f:
                    where = m.group(2).split("\\n")[1] if "\\n" in m.group(2) else ""
                    frames[m.group(1)] = (int(f.group(1)), f.group(2), where)
                continue
            m = EDGE_RE.match(line)
            if m:
                calls[m.group(1)].append((m.group(2), m.group(3) or ""))
    return frames, calls


PUSH_RE = re.compile(r'\t(push|stmdb\s+sp!,|vpush)(?:\.w)?\s+\{([^}]*)\}')
SUBSP_RE = re.compile(r'\tsub(?:\.w|w)?\s+sp,\s*(?:sp,\s*)?#(\d+)')
PREINDEX_RE = re.compile(r'\[sp,\s*#-(\d+)\]!')  # str / strd with sp write-back
CALL_RE = re.compile(r'R_ARM_THM_(?:CALL|JUMP24|JUMP11)\s+(\S+)')


def reg_count(regs):
    n = 0
    for part in regs.split(","):
        part = part.strip()
        if "-" in part:
            a, b = part.split("-")
            n += int(b[1:]) - int(a[1:]) + 1
        elif part:
            n += 1
    return n


SYM_RE = re.compile(r"^([0-9a-f]{8}) (.{7}) (\S+)\t[0-9a-f]+ (?:\.hidden )?(\S+)$")


def lib_aliases(path):
    """{(member, section, address): [global names]}: assembler routines have several names
    (__aeabi_uidiv = __udivsi3) and objdump labels only one of them."""
    out = subprocess.run(["arm-none-eabi-objdump", "-t", path], stdout=subprocess.PIPE,
                         check=True).stdout.decode(errors="replace")
    groups, member = collections.defaultdict(list), None
    for line in out.splitlines():
        m = re.match(r"^(\S+\.o):\s+file format", line)
        if m:
            member = m.group(1)
            continue
        m = SYM_RE.match(line)
        if m and m.group(3).startswith(".text") and ("g" in m.group(2) or "w" in m.group(2)):
            groups[(member, m.group(3), int(m.group(1), 16))].append(m.group(4))
    return groups


def parse_objdump(out, origin, aliases=None):
    """Frames {label: [bytes, "static", origin]} and calls from `objdump -dr` text (frame = every
    push, vpush, sub sp and sp pre-decrement summed: an upper bound)."""
    frames, calls = {}, collections.defaultdict(list)
    cur, member, section, labels = None, None, None, []
    for line in out.splitlines():
        m = re.match(r"^(\S+\.o):\s+file format", line)
        if m:
            member = m.group(1)
            continue
        m = re.match(r"^Disassembly of section (\S+):", line)
        if m:
            section = m.group(1)
            continue
        m = re.match(r'^([0-9a-f]+) <([^>]+)>:$', line)
        if m:
            cur = m.group(2)
            if cur in frames:  # a name defined twice: keep the first (the linker's choice)
                cur = None
            else:
                frames[cur] = [0, "static", origin]
                labels.append((cur, (aliases or {}).get((member, section, int(m.group(1), 16)),
                                                        ())))
            continue
        if cur is None:
            continue
        m = PUSH_RE.search(line)
        if m:
            per = 8 if m.group(1) == "vpush" and "d" in m.group(2) else 4
            frames[cur][0] += per * reg_count(m.group(2))
            continue
        m = SUBSP_RE.search(line) or PREINDEX_RE.search(line)
        if m:
            frames[cur][0] += int(m.group(1))
            continue
        m = CALL_RE.search(line)
        if m and m.group(1) != cur and not m.group(1).startswith("."):
            calls[cur].append((m.group(1), origin))
    for label, names in labels:  # every other name of the same code: the same frame
        for n in names:
            if n not in frames:
                frames[n] = frames[label]
                calls[n] = calls[label]
    return frames, calls


def read_libs(cflags):
    """Library frames and calls from objdump -dr of libc_nano, libm and libgcc for the target."""
    frames, calls = {}, collections.defaultdict(list)
    for lib in ("libc_nano.a", "libm.a", "libgcc.a"):
        path = subprocess.run(["arm-none-eabi-gcc"] + cflags.split() + ["-print-file-name=" + lib],
                              stdout=subprocess.PIPE, check=True).stdout.decode().strip()
        if not os.path.exists(path):
            continue
        out = subprocess.run(["arm-none-eabi-objdump", "-dr", path], stdout=subprocess.PIPE,
                             check=True).stdout.decode(errors="replace")
        f, c = parse_objdump(out, os.path.basename(path), lib_aliases(path))
        for k, v in f.items():
            if k not in frames:
                frames[k], calls[k] = v, c.get(k, [])
    return {k: tuple(v) for k, v in frames.items()}, calls


def code_frames(root, frames):
    """GCC's -fstack-usage leaves out the pretend-args area a function that takes a struct by
    value partly in registers pushes first (soft-float Cortex-M0+: `sub sp, #8` before the
    push; seen by the stack painting of test-m0-qemu). Take the larger of the .su frame and
    the object's own disassembly."""
    for ci in glob.glob(os.path.join(root, "**", "*.ci"), recursive=True):
        obj = ci[:-3] + ".o"
        if not os.path.exists(obj):
            continue
        src = None
        for line in open(ci, encoding="utf-8", errors="replace"):
            m = re.match(r'^graph: \{ title: "([^"]+)"', line)
            if m:
                src = m.group(1)
                break
        out = subprocess.run(["arm-none-eabi-objdump", "-dr", obj], stdout=subprocess.PIPE,
                             check=True).stdout.decode(errors="replace")
        f, _ = parse_objdump(out, obj)
        for label, v in f.items():
            base = re.sub(r"\.\d+$", "", label)
            for key in (src + ":" + label, src + ":" + base, label, base):
                if key in frames and frames[key][0] < v[0]:
                    frames[key] = (v[0], frames[key][1], frames[key][2])
                    break
                if key in frames:
                    break


def public_functions(header_dir):
    """Names declared in the portable public headers (comments stripped)."""
    names = {}
    for h in sorted(glob.glob(os.path.join(header_dir, "*.h"))):
        text = open(h, encoding="utf-8").read()
        text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
        text = re.sub(r"//[^\n]*", " ", text)
        text = re.sub(r"^\s*#.*$", " ", text, flags=re.M)
        for m in re.finditer(r"[\w*]\s+\**\s*(occ_\w+)\s*\(", text):
            if not m.group(1).endswith("_t"):  # a type before a function-pointer member
                names.setdefault(m.group(1), os.path.basename(h))
    return names


STATED_RE = re.compile(r"^\s*\*\s+((?:occ_[\w*]+,?\s*)+):\s+stack <= ([\d,]+) / ([\d,]+) B")
BUDGETS_RE = re.compile(r"^/\* ---- Budgets")


def stated_bounds(header_dir):
    """The headers' own statements (their "Budgets" sections): {header: [(patterns, m4, m0,
    work)]}; work is false when the statement (its line and the continuation lines up to the
    next statement or the end of the section) gives no "work:" bound."""
    out = collections.defaultdict(list)
    for h in sorted(glob.glob(os.path.join(header_dir, "*.h"))):
        section, cur = False, None
        for line in open(h, encoding="utf-8"):
            section = section or BUDGETS_RE.match(line) is not None
            if not section:
                continue
            m = STATED_RE.match(line)
            if m:
                pats = [p.strip() for p in m.group(1).replace(",", " ").split()]
                cur = [pats, int(m.group(2).replace(",", "")), int(m.group(3).replace(",", "")),
                       False]
                out[os.path.basename(h)].append(cur)
            if cur is not None and "work:" in line:
                cur[3] = True
            if "*/" in line:
                break
    return {k: [tuple(x) for x in v] for k, v in out.items()}


def read_budgets(path, bad):
    """Classes {name: (limit, text)}, rows [(pattern, class, m4, m0)], names not built."""
    classes, rules, missing_ok = {}, [], []
    for line in open(path, encoding="utf-8"):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        parts = line.split()
        if parts[0] == "not-built":
            missing_ok.extend(parts[1:])
        elif parts[0] == "class":
            classes[parts[1]] = (int(parts[2]), " ".join(parts[3:]))
        else:
            rules.append((parts[0], parts[1], int(parts[2]), int(parts[3])))
    for pat, cls, m4, m0 in rules:
        if cls not in classes:
            bad.append("%s: class %s is not defined in %s" % (pat, cls, path))
        elif max(m4, m0) > classes[cls][0]:
            bad.append("%s: budget %d / %d B above its class %s limit of %d B" % (
                pat, m4, m0, cls, classes[cls][0]))
    return classes, rules, missing_ok


class Target:
    def __init__(self, name, root, cflags):
        self.name = name
        self.frames, self.calls = read_callgraph(root)
        if not self.frames:
            sys.exit("FAIL stack budget: no -fcallgraph-info=su .ci files under %s" % root)
        code_frames(root, self.frames)
        lf, lc = read_libs(cflags)
        for k, v in lf.items():
            self.frames.setdefault(k, v)
        for k, v in lc.items():
            self.calls.setdefault(k, v)
        self.problems = []
        self.memo = {}

    def worst(self, fn, path=()):
        """(bytes, chain, indirect call sites) of the deepest chain below fn (memoized)."""
        if fn == INDIRECT:
            return 0, (), ()
        if fn in self.memo:
            return self.memo[fn]
        if fn in path:
            self.problems.append("recursion: " + " -> ".join(map(short, path[path.index(fn):]
                                                                 + (fn,))))
            return 0, (fn,), ()
        if fn not in self.frames:
            self.problems.append("unknown stack: %s (called from %s)" % (
                fn, short(path[-1]) if path else "-"))
            return 0, (fn,), ()
        size, kind, _ = self.frames[fn]
        if kind != "static":
            self.problems.append("%s stack (%s): %s" % (kind, fn, self.frames[fn][2]))
        best, chain, sites = 0, (), set()
        for callee, site in self.calls.get(fn, ()):
            if callee == INDIRECT:
                sites.add(site)
                continue
            b, c, s = self.worst(callee, path + (fn,))
            sites.update(s)
            if b > best or not chain:
                best, chain = b, c
        self.memo[fn] = (size + best, (fn,) + chain, tuple(sorted(sites)))
        return self.memo[fn]


def depth_to(t, fn, target, memo, path=()):
    """Deepest stack from fn's frame down to and including target's frame (None: unreachable)."""
    if fn == target:
        return t.frames[fn][0]
    if fn in memo:
        return memo[fn]
    if fn in path or fn not in t.frames:
        return None
    best = None
    for callee, _ in t.calls.get(fn, ()):
        if callee == INDIRECT:
            continue
        d = depth_to(t, callee, target, memo, path + (fn,))
        if d is not None and (best is None or d > best):
            best = d
    memo[fn] = None if best is None else best + t.frames[fn][0]
    return memo[fn]


def site_function(t, site):
    return next((f for f, cs in t.calls.items() if (INDIRECT, site) in cs), None)


def short(fn):
    return fn.rsplit(":", 1)[-1]


def source_line(site):
    m = re.match(r"(.+):(\d+):\d+$", site)
    if not m or not os.path.exists(m.group(1)):
        return site
    lines = open(m.group(1), encoding="utf-8").read().splitlines()
    return "%s:%s %s" % (m.group(1), m.group(2), lines[int(m.group(2)) - 1].strip()[:60])


def print_table(targets, names, rules, classes, missing_ok, budgets, bad):
    """One row per entry point; returns {indirect call site: entry points} and {entry point:
    (class, [bound per target], [budget per target], header)}."""
    indirect, rows = collections.defaultdict(set), {}
    head = "%-36s %-14s" % ("entry point", "header")
    for t in targets:
        head += " %6s %6s" % (t.name, "budget")
    print("== worst call-chain stack per public entry point, bytes (-fcallgraph-info=su; "
          "+ = calls a callback, its stack is the caller's to add)")
    print(head + " %-17s deepest chain (%s)" % ("class (limit)", targets[0].name))
    for fn in sorted(names):
        rule = next((r for r in rules if fnmatch.fnmatchcase(fn, r[0])), None)
        if fn not in targets[0].frames:
            if fn not in missing_ok:
                bad.append("%s (%s) is declared but not in the firmware build" % (fn, names[fn]))
            continue
        if rule is None:
            bad.append("%s has no budget in %s" % (fn, budgets))
            continue
        limit = classes.get(rule[1], (0, ""))[0]
        row = "%-36s %-14s" % (fn, names[fn].replace(".h", ""))
        chain0, bounds, budgets_t = (), [], []
        for i, t in enumerate(targets):
            b, chain, sites = t.worst(fn)
            chain0 = chain0 or chain
            budget = rule[2 + min(i, 1)]
            bounds.append(b)
            budgets_t.append(budget)
            row += " %5d%s %6d" % (b, "+" if sites else " ", budget)
            for site in sites:
                indirect[site].add(fn)
            if b > budget:
                bad.append("%s: %d B on %s, budget %d B (%s)" % (fn, b, t.name, budget,
                                                               " > ".join(map(short, chain))))
            if b > limit:
                bad.append("%s: %d B on %s, above its class %s limit of %d B (%s)" % (
                    fn, b, t.name, rule[1], limit, " > ".join(map(short, chain))))
        rows[fn] = (rule[1], bounds, budgets_t, names[fn])
        print(row + " %-17s " % ("%s (%d)" % (rule[1], limit)) +
              " > ".join(map(short, chain0[1:5])) + (" ..." if len(chain0) > 5 else ""))
    return indirect, rows


def print_classes(targets, classes, rows):
    """Per class: its limit and its deepest entry point per target."""
    print("== classes (%s): limit, deepest entry point per target" % "/".join(
        t.name for t in targets))
    for cls, (limit, text) in classes.items():
        members = [fn for fn, r in rows.items() if r[0] == cls]
        worst = []
        for i, t in enumerate(targets):
            fn = max(members, key=lambda f: rows[f][1][i]) if members else None
            worst.append("%s %s %d B" % (t.name, fn, rows[fn][1][i]) if fn else t.name + " -")
        print("  %-12s <= %4d B  %3d entry points; %s  (%s)" % (cls, limit, len(members),
                                                              "; ".join(worst), text))


def loose_rules(targets, rules, rows):
    """Rows whose budget is above the file's rule (the measured bound + 5 %, rounded up to 64 B;
    at most the class limit): printed, so the budgets stay as low as the code allows."""
    out = []
    for pat, cls, m4, m0 in rules:
        matched = [fn for fn in rows if next((r for r in rules if fnmatch.fnmatchcase(fn, r[0])),
                                             None) == (pat, cls, m4, m0)]
        if not matched:
            continue
        for i, t in enumerate(targets):
            worst = max(rows[fn][1][i] for fn in matched)
            want = -(-worst * 105 // 100 // 64) * 64 if worst > 0 else 64
            want = max(want, -(-worst // 64) * 64)
            if (m4, m0)[min(i, 1)] > want:
                out.append("%s %s %d > %d" % (pat, t.name, (m4, m0)[min(i, 1)], want))
    return out


def write_json(path, targets, classes, rows):
    data = {"targets": [t.name for t in targets],
            "classes": [{"name": c, "limit": v[0], "text": v[1]} for c, v in classes.items()],
            "entries": {fn: {"class": r[0], "header": r[3],
                             "stack": dict(zip([t.name for t in targets], r[1])),
                             "budget": dict(zip([t.name for t in targets], r[2]))}
                        for fn, r in sorted(rows.items())}}
    with open(path, "w", encoding="utf-8") as f:
        json.dump(data, f, indent=1, sort_keys=True)
        f.write("\n")


def check_stated(targets, names, header_dir, bad):
    """Every entry point's header states its stack bound, which must hold, and a work bound."""
    stated = stated_bounds(header_dir)
    unstated, no_work, checked = [], [], 0
    for fn in sorted(names):
        if fn not in targets[0].frames:
            continue
        st = next((x for x in stated.get(names[fn], ()) if any(fnmatch.fnmatchcase(fn, p)
                                                              for p in x[0])), None)
        if st is None:
            unstated.append(fn)
            bad.append("%s has no statement in the Budgets section of %s" % (fn, names[fn]))
            continue
        if not st[3]:
            no_work.append(fn)
            bad.append("%s: its statement in %s (%s) gives no work bound" % (
                fn, names[fn], ", ".join(st[0])))
        checked += 1
        for i, t in enumerate(targets):
            b = t.worst(fn)[0]
            if b > st[1 + min(i, 1)]:
                bad.append("%s: %d B on %s, but %s states <= %d B" % (fn, b, t.name, names[fn],
                                                                      st[1 + min(i, 1)]))
    print("== stack and work bounds the headers state: %d entry points checked, %d without a "
          "statement, %d without a work bound" % (checked, len(unstated), len(no_work)))


def print_indirect(t, indirect):
    print("== indirect calls below the entry points (the caller adds its callback's stack)")
    print("   (stack in use at the call, %s: the callback's own stack comes on top of it)" %
          t.name)
    for site in sorted(indirect):
        sf = site_function(t, site)
        memo = {}
        at = ["%s %d B" % (fn, depth_to(t, fn, sf, memo) or 0) for fn in sorted(indirect[site])]
        print("  %s\n      %s" % (source_line(site), "; ".join(at)))


def main():
    args = sys.argv[1:]
    json_out = None
    if args[:1] == ["--json"]:
        json_out, args = args[1], args[2:]
    budgets, header_dir = args[0], args[1]
    targets = []
    for spec in args[2:]:
        name, root, cflags = spec.split("=", 2)
        targets.append(Target(name, root, cflags))
    bad = []
    classes, rules, missing_ok = read_budgets(budgets, bad)
    names = public_functions(header_dir)
    indirect, rows = print_table(targets, names, rules, classes, missing_ok, budgets, bad)
    check_stated(targets, names, header_dir, bad)
    print_indirect(targets[0], indirect)
    print_classes(targets, classes, rows)
    loose = loose_rules(targets, rules, rows)
    print("== budgets above the rule of %s (measured + 5 %%, rounded up to 64 B): %s" % (
        os.path.basename(budgets), "none" if not loose else "; ".join(loose)))
    for t in targets:
        for p in sorted(set(t.problems)):
            bad.append("%s: %s" % (t.name, p))
    for b in bad:
        print("FAIL stack budget: " + b)
    if json_out is not None:
        write_json(json_out, targets, classes, rows)
    n = len([n for n in names if n in targets[0].frames])
    print("%s stack budget: %d entry points on %s, budgets in %s" % (
        "FAIL" if bad else "PASS", n, "/".join(t.name for t in targets), budgets))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
