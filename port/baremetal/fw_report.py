#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""fw_report.py - what the firmware image costs: size per module from the link map (text =
.text + .rodata + ARM tables, data = .data, bss = .bss/COMMON), the core's total, the worst
-fstack-usage frames of the image's own objects, and a recursion check on the image's direct
call graph (bl/b.w to symbols; indirect calls through function pointers are not seen).

usage: fw_report.py IMAGE.elf OBJ_ROOT     (IMAGE.elf.map next to it; OBJ_ROOT/... holds .su files)
"""
import collections
import os
import re
import subprocess
import sys


def parse_map(path):
    sizes = collections.defaultdict(lambda: [0, 0, 0])
    started = False
    pending = None
    line_re = re.compile(r"^\s+(0x[0-9a-f]+)\s+(0x[0-9a-f]+)\s+(\S.*)$")
    for line in open(path, encoding="utf-8", errors="replace"):
        if line.startswith("Linker script and memory map"):
            started = True
            continue
        if not started:
            continue
        if line.startswith("OUTPUT("):
            break
        m = re.match(r"^ (\.[\w.\-]+|COMMON)\s*$", line)
        if m:
            pending = m.group(1)
            continue
        m = re.match(r"^ (\.[\w.\-]+|COMMON)\s+(0x[0-9a-f]+)\s+(0x[0-9a-f]+)\s+(\S.*)$", line)
        if m:
            sec, size, obj = m.group(1), int(m.group(3), 16), m.group(4)
        else:
            m = line_re.match(line)
            if not (m and pending):
                pending = None
                continue
            sec, size, obj = pending, int(m.group(2), 16), m.group(3)
        pending = None
        if size == 0 or obj.startswith("load address"):
            continue
        if sec.startswith((".text", ".rodata", ".ARM", ".isr_vector", ".init", ".fini", ".glue")):
            k = 0
        elif sec.startswith(".data"):
            k = 1
        elif sec.startswith((".bss", "COMMON")):
            k = 2
        else:
            continue
        sizes[obj.strip()][k] += size
    return sizes


def core_paths(root):
    """Archive member name -> source-relative object path (src/core/x.o, src/sectors/y.o)."""
    paths = {}
    for d, _, files in os.walk(os.path.join(root, "src")):
        for f in files:
            if f.endswith(".o"):
                rel = os.path.relpath(os.path.join(d, f), root)
                paths[f] = None if f in paths else rel
    return paths


CORE = {}


def module_name(obj):
    m = re.search(r"\(([^)]+)\)$", obj)
    lib = os.path.basename(obj.split("(")[0])
    if lib.startswith("libocc"):
        return (CORE.get(m.group(1)) or "src/" + m.group(1)) if m else obj
    if lib.endswith(".a"):
        return lib  # newlib / libgcc: one line per library
    return obj.split("/m4/", 1)[-1]


def stack_frames(root, objs):
    frames = []
    for obj in objs:
        su = os.path.join(root, obj.replace(".o", ".su"))
        if not os.path.exists(su):
            continue
        for line in open(su):
            parts = line.rstrip("\n").split("\t")
            if len(parts) >= 3:
                frames.append((int(parts[1]), parts[0].split("/m4/")[-1] if "/m4/" in parts[0]
                               else parts[0], parts[2]))
    return sorted(frames, reverse=True)


def call_cycles(elf, core_funcs):
    out = subprocess.run(["arm-none-eabi-objdump", "-d", elf], stdout=subprocess.PIPE,
                         check=True).stdout.decode(errors="replace")
    graph = collections.defaultdict(set)
    cur = None
    for line in out.splitlines():
        m = re.match(r"^[0-9a-f]+ <([^>]+)>:$", line)
        if m:
            cur = m.group(1)
            continue
        m = re.search(r"\t(?:bl|b\.w|b)\s+[0-9a-f]+ <([^>+]+)>", line)
        if m and cur and m.group(1) != cur:
            graph[cur].add(m.group(1))
        elif m and cur and m.group(1) == cur and re.search(r"\tbl\s", line):
            graph[cur].add(cur)  # a direct self call
    # Tarjan's SCC, iterative.
    index, low, onstack, stack, sccs, counter = {}, {}, set(), [], [], [0]
    for root in list(graph):
        if root in index:
            continue
        work = [(root, iter(graph[root]))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        onstack.add(root)
        while work:
            v, it = work[-1]
            nxt = next(it, None)
            if nxt is not None:
                if nxt not in index:
                    index[nxt] = low[nxt] = counter[0]
                    counter[0] += 1
                    stack.append(nxt)
                    onstack.add(nxt)
                    work.append((nxt, iter(graph.get(nxt, ()))))
                elif nxt in onstack:
                    low[v] = min(low[v], index[nxt])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    onstack.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1 or v in graph.get(v, ()):
                    sccs.append(comp)
    return [c for c in sccs if any(f.split(".")[0] in core_funcs for f in c)]


def image_modules(elf, root):
    """{module: [text, data, bss]} of the image (its link map) and the image's own objects;
    also port/baremetal/fw_table.py's source of the core's size in the image."""
    CORE.update(core_paths(root))
    sizes = parse_map(elf + ".map")
    mods = collections.defaultdict(lambda: [0, 0, 0])
    objs = []
    for obj, s in sizes.items():
        name = module_name(obj)
        for k in range(3):
            mods[name][k] += s[k]
        if name.startswith(("src/", "port/", "tests/")):
            objs.append(name)
    return mods, objs


def main():
    elf, root = sys.argv[1], sys.argv[2]
    mods, objs = image_modules(elf, root)
    print("== firmware image %s (Cortex-M4F, -Os): size per module, bytes" % elf)
    print("%-36s %8s %8s %8s" % ("module", "text", "data", "bss"))
    core = [0, 0, 0]
    for name in sorted(mods, key=lambda n: (not n.startswith("src/"), n)):
        t, d, b = mods[name]
        print("%-36s %8d %8d %8d" % (name, t, d, b))
        if name.startswith("src/"):
            core = [core[i] + mods[name][i] for i in range(3)]
    total = [sum(m[i] for m in mods.values()) for i in range(3)]
    print("%-36s %8d %8d %8d" % ("core (src/*: map + front ends) in image", *core))
    print("%-36s %8d %8d %8d" % ("image total", *total))
    print("core .text %d bytes: %s the 32 KB target" % (core[0], "within" if core[0] <= 32768
                                                          else "OVER"))
    frames = stack_frames(root, objs)
    print("== worst -fstack-usage frames of the image's own objects")
    for size, where, kind in frames[:6]:
        print("%6d  %-10s %s" % (size, kind, where))
    core_frames = [f for f in frames if f[1].startswith("src/")]
    if core_frames:
        print("worst core frame: %d bytes (%s): %s the 512-byte target" % (
            core_frames[0][0], core_frames[0][1],
            "within" if core_frames[0][0] <= 512 else "OVER"))
    core_funcs = set()
    for obj in objs:
        if obj.startswith("src/"):
            su = os.path.join(root, obj.replace(".o", ".su"))
            if os.path.exists(su):
                for line in open(su):
                    core_funcs.add(line.split("\t")[0].rsplit(":", 1)[-1].split(".")[0])
    cycles = call_cycles(elf, core_funcs)
    print("recursion (direct calls, core functions): %s" % (
        "none" if not cycles else "; ".join(" -> ".join(c) for c in cycles)))


if __name__ == "__main__":
    sys.exit(main())
