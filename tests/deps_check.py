#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""deps_check.py - the module graph of src/ from its #include lines, and the allowed direction.

Every src/<module>/*.c|h is read; each #include "..." is resolved the way the compiler does it
(the including file's folder first, then include/ and src/ as -Iinclude -Isrc). An edge
module -> module is allowed only downwards:

    geom <- core <- {integrate, query, io, evict} <- front ends (sensors, sectors, mavlink, dronecan)

geom is the bottom: it reads only the public occ_map_t, and core's key conversion calls it.
The four map modules above core are peers and do not use each other's internals (their public
headers are fine). Front ends use only include/occmap (public headers). Nothing in src may
include port/ or tools/, and a portable module may not include include/occmap/host/.
The public headers: occmap.h includes only the chapters, no include cycle, and a portable header
(include/occmap/*.h, not host/) includes only freestanding C headers and declares nothing of an
OS (FILE, file descriptors, sockets, threads, libccd).
Prints the graph it found, then proves itself on planted wrong-way includes in a scratch copy.
Exit 1 on a wrong-way edge, an include it cannot resolve, or a planted edge it misses.
usage: deps_check.py [ROOT]
"""
import os
import re
import shutil
import sys
import tempfile

MAP = ["geom", "core", "integrate", "query", "io", "evict"]
FRONT = ["sensors", "sectors", "mavlink", "dronecan"]
# module -> the other modules whose internal headers it may include
ALLOWED = {"geom": set(), "core": {"geom"}}
for _m in ("integrate", "query", "io", "evict"):
    ALLOWED[_m] = {"geom", "core"}
for _m in FRONT:
    ALLOWED[_m] = set()
# Host-only sources (libccd) may use include/occmap/host.
HOST_OK = {"src/query/collide_ccd.c"}
# Generated MAVLink C headers a front end finds through -isystem build/gen/mavlink.
GENERATED_OK = re.compile(r"^(ardupilotmega|common|standard|minimal)/")
INCLUDE = re.compile(r'^\s*#\s*include\s*"([^"]+)"')


def resolve(root, src_file, name):
    for base in (os.path.dirname(src_file), os.path.join(root, "include"), os.path.join(root, "src")):
        cand = os.path.normpath(os.path.join(base, name))
        if os.path.isfile(cand):
            return cand
    return None


def classify(root, path):
    """'public', 'host', ('src', module) or ('other', top folder) for a resolved path."""
    parts = os.path.relpath(path, root).split(os.sep)
    if parts[0] == "include":
        return "host" if len(parts) > 2 and parts[2] == "host" else "public"
    if parts[0] == "src" and len(parts) > 2:
        return ("src", parts[1])
    return ("other", parts[0])


def edge_problem(root, module, rel, path, name, graph):
    """None if the include is allowed (recording the edge), else why not."""
    target = resolve(root, path, name)
    if target is None:
        if module in FRONT and GENERATED_OK.match(name):
            graph[module].add("(generated mavlink)")
            return None
        return "not found in the file's folder, include/ or src/"
    kind = classify(root, target)
    if kind == "public":
        graph[module].add("include/occmap")
        return None
    if kind == "host":
        graph[module].add("include/occmap/host")
        return None if rel in HOST_OK else "a host-only header in a portable module"
    if kind[0] == "other":
        graph[module].add(kind[1] + "/")
        return "src must not include %s/" % kind[1]
    dep = kind[1]
    if dep == module:
        return None
    graph[module].add(dep)
    if dep in ALLOWED.get(module, set()):
        return None
    if module in FRONT:
        return "wrong-way edge %s -> %s (front ends use only include/occmap)" % (module, dep)
    allowed = ", ".join(sorted(ALLOWED[module])) or "nothing in src"
    return "wrong-way edge %s -> %s (allowed from %s: %s)" % (module, dep, module, allowed)


def check(root):
    """(graph, problems, files, includes) of the tree at root."""
    src = os.path.join(root, "src")
    graph, bad, nfiles, nincs = {}, [], 0, 0
    for module in sorted(os.listdir(src)):
        folder = os.path.join(src, module)
        if not os.path.isdir(folder):
            continue
        sources = sorted(f for f in os.listdir(folder) if f.endswith((".c", ".h")))
        if not sources:
            continue  # an empty folder left by a checkout holds no edge
        if module not in ALLOWED:
            bad.append("src/%s: a folder the dependency rule does not know (add it here)" % module)
            continue
        graph.setdefault(module, set())
        for f in sources:
            path = os.path.join(folder, f)
            rel = os.path.relpath(path, root)
            nfiles += 1
            with open(path, encoding="utf-8") as fh:
                for lineno, line in enumerate(fh, 1):
                    hit = INCLUDE.match(line)
                    if not hit:
                        continue
                    nincs += 1
                    why = edge_problem(root, module, rel, path, hit.group(1), graph)
                    if why:
                        bad.append('%s:%d: #include "%s": %s' % (rel, lineno, hit.group(1), why))
    return graph, bad, nfiles, nincs


# Wrong includes planted one at a time in a scratch copy of the tree: each must be reported.
PLANTED = [
    ("src/core/tree.c", '#include "../query/query_internal.h"', "core -> query"),
    ("src/geom/geom.c", '#include "../core/tree_internal.h"', "geom -> core"),
    ("src/query/query.c", '#include "../integrate/integrate_internal.h"', "query -> integrate"),
    ("src/sectors/sectors.c", '#include "core/tree_internal.h"', "sectors -> core"),
    ("src/io/io.c", '#include "../../port/posix/fd_wait.h"', "io -> port"),
    ("src/core/map.c", '#include "occmap/host/occ_file.h"', "core -> host header"),
]


# Host-only declarations planted one at a time in a portable header: each must be reported.
PLANTED_HEADER = [
    ("include/occmap/occ_port.h", "#include <stdio.h>", "<stdio.h>"),
    ("include/occmap/occ_port.h", "typedef struct { int fd; } occ_x_t;", "`fd`"),
    ("include/occmap/occ_core.h", "void occ_x(FILE *f);", "`FILE`"),
    ("include/occmap/occ_port.h", '#include "occmap/host/occ_file.h"', "host/occ_file.h"),
]


def selftest_headers(tmp):
    ok = True
    for rel, line, what in PLANTED_HEADER:
        path = os.path.join(tmp, rel)
        with open(path, encoding="utf-8") as fh:
            before = fh.read()
        with open(path, "w", encoding="utf-8") as fh:
            fh.write(line + "\n" + before)
        name = os.path.basename(rel)
        caught = any(name in b and what in b for b in check_headers(tmp))
        with open(path, "w", encoding="utf-8") as fh:
            fh.write(before)
        print("deps_check selftest: planted %-20s in %-12s %s" % (what, name, "caught" if caught else "MISSED"))
        ok = ok and caught
    return ok


def selftest(root):
    ok = True
    with tempfile.TemporaryDirectory() as tmp:
        for top in ("src", "include", "port"):
            shutil.copytree(os.path.join(root, top), os.path.join(tmp, top))
        ok = selftest_headers(tmp)
        for rel, line, what in PLANTED:
            path = os.path.join(tmp, rel)
            if not os.path.isfile(path):
                print("deps_check selftest: %s is gone, nothing planted" % rel)
                continue
            with open(path, encoding="utf-8") as fh:
                before = fh.read()
            with open(path, "w", encoding="utf-8") as fh:
                fh.write(line + "\n" + before)
            caught = any(b.startswith(rel + ":1:") for b in check(tmp)[1])
            with open(path, "w", encoding="utf-8") as fh:
                fh.write(before)
            print("deps_check selftest: planted %-20s %s" % (what, "caught" if caught else "MISSED"))
            ok = ok and caught
    return ok


CHAPTERS = ["occ_core.h", "occ_integrate.h", "occ_query.h", "occ_io.h", "occ_evict.h", "occ_shared.h"]
# A portable header (include/occmap/*.h, what firmware sees) includes only freestanding C headers
# and declares nothing of an OS: no FILE, file descriptors, sockets, threads or libccd. The
# firmware compile of every portable header alone (make fw-headers) is the other half.
FREESTANDING = {"stddef.h", "stdint.h", "stdbool.h", "float.h", "limits.h", "stdarg.h"}
SYS_INCLUDE = re.compile(r"^\s*#\s*include\s*<([^>]+)>", re.M)
HOST_ONLY = re.compile(r"\b(FILE|fopen|sockaddr\w*|socklen_t|pthread_\w+|ccd\w*|fd|\w+_fd)\b")


def portable_problems(name, text):
    """Why a portable header is not portable (empty list when it is)."""
    code = re.sub(r"/\*.*?\*/|//[^\n]*", " ", text, flags=re.S)
    bad = ["include/occmap/%s (portable) includes <%s>" % (name, h)
           for h in SYS_INCLUDE.findall(code) if h not in FREESTANDING]
    bad += ["include/occmap/%s (portable) declares host-only `%s`" % (name, w)
            for w in sorted(set(m.group(1) for m in HOST_ONLY.finditer(code)))]
    return bad


def check_headers(root):
    """The public headers: occmap.h only includes the chapters, a chapter includes only
    occ_core.h, no portable header includes occmap/host/, and no include cycle anywhere."""
    inc = os.path.join(root, "include", "occmap")
    edges, bad = {}, []
    for folder in (inc, os.path.join(inc, "host")):
        for f in sorted(os.listdir(folder)):
            if not f.endswith(".h"):
                continue
            name = os.path.relpath(os.path.join(folder, f), inc)
            with open(os.path.join(folder, f), encoding="utf-8") as fh:
                text = fh.read()
            deps = [m.group(1)[len("occmap/"):] for m in map(INCLUDE.match, text.split("\n")) if m]
            if not name.startswith("host/"):
                bad += portable_problems(name, text)
            edges[name] = deps
            allowed = (set(CHAPTERS) if name == "occmap.h" else
                       {"occ_core.h"} if name in CHAPTERS else None)
            for d in deps:
                if allowed is not None and d not in allowed:
                    bad.append("include/occmap/%s includes %s (allowed: %s)" % (name, d, ", ".join(sorted(allowed))))
                if not name.startswith("host/") and d.startswith("host/"):
                    bad.append("include/occmap/%s (portable) includes %s" % (name, d))

    def cycle_from(node, path):
        for d in edges.get(node, []):
            if d in path:
                return path[path.index(d):] + [d]
            found = cycle_from(d, path + [d])
            if found:
                return found
        return None

    for h in sorted(edges):
        found = cycle_from(h, [h])
        if found:
            bad.append("include cycle: " + " -> ".join(found))
            break
    return bad


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else ".")
    graph, bad, nfiles, nincs = check(root)
    header_bad = check_headers(root)
    print("deps_check: public headers: occmap.h -> %s; %s"
          % (", ".join(CHAPTERS), "chapters include only occ_core.h, no cycle, portable headers declare nothing host-only"
          if not header_bad else "PROBLEMS below"))
    bad += header_bad
    print("deps_check: module graph of src/ (%d files, %d includes), module -> what it includes:"
          % (nfiles, nincs))
    for module in [m for m in MAP + FRONT if m in graph]:
        print("  %-10s -> %s" % (module, ", ".join(sorted(graph[module])) or "(nothing)"))
    print("  allowed: geom <- core <- {integrate, query, io, evict} <- {sensors, sectors, mavlink, dronecan}"
          " (front ends: include/occmap only)")
    for b in bad:
        print("deps_check: " + b)
    if not selftest(root):
        print("FAIL deps-check: a planted wrong-way include was not caught")
        return 1
    if bad:
        print("FAIL deps-check: %d wrong include(s)" % len(bad))
        return 1
    print("PASS deps-check")
    return 0


if __name__ == "__main__":
    sys.exit(main())
