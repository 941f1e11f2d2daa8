#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""deps_calls.py - the module graph of src/ from the calls the compiled objects make.

deps_check.py reads #include lines; a call can still go the wrong way through a prototype
written by hand or a public header. This reads `nm` of every object of the library
(OBJDIR/src/<module>/*.o, the release build of libocc.a): each undefined symbol is matched to
the module whose object defines it, and the edge module -> module must go downwards:

    level 0 geom, 1 core, 2 {integrate, query, io, evict}, 3 front ends (sensors, sectors,
    mavlink, dronecan)

- a call to a lower level is allowed if the symbol is public (occ_...), or if it is internal
  (occi_...) and the callee's module is one whose internals the caller may use (geom and core
  for the map modules; nothing for front ends);
- a call between two modules of the same level is allowed only to a public symbol;
- a call to a higher level is never allowed (core must not call an integrator, geom must not
  call core, no map module may call a front end).
Then proves itself on planted wrong-way calls. Exit 1 on a wrong edge or a missed plant.
usage: deps_calls.py OBJDIR [NM]
"""
import os
import subprocess
import sys

LEVEL = {"geom": 0, "core": 1, "integrate": 2, "query": 2, "io": 2, "evict": 2,
         "sensors": 3, "sectors": 3, "mavlink": 3, "dronecan": 3}
INTERNALS_OK = {"core": {"geom"}, "integrate": {"geom", "core"}, "query": {"geom", "core"},
                "io": {"geom", "core"}, "evict": {"geom", "core"}}


def read_objects(objdir, nm):
    """{module: (defined set, undefined set)} from nm of OBJDIR/src/<module>/*.o."""
    mods = {}
    src = os.path.join(objdir, "src")
    for module in sorted(os.listdir(src)):
        folder = os.path.join(src, module)
        objs = sorted(os.path.join(folder, f) for f in os.listdir(folder) if f.endswith(".o"))
        if not objs:
            continue
        out = subprocess.run([nm, "-g"] + objs, check=True, capture_output=True, text=True).stdout
        defined, undefined = set(), set()
        for line in out.splitlines():
            parts = line.split()
            if len(parts) == 2 and parts[0] == "U":
                undefined.add(parts[1])
            elif len(parts) == 3 and parts[1] in "TDBR":
                defined.add(parts[2])
        mods[module] = (defined, undefined - defined)
    return mods


def edge_problem(caller, callee, symbol):
    if caller not in LEVEL or callee not in LEVEL:
        return "a module the rule does not know (add it to LEVEL)"
    public = symbol.startswith("occ_")
    if LEVEL[callee] > LEVEL[caller]:
        return "calls upwards (level %d -> %d)" % (LEVEL[caller], LEVEL[callee])
    if LEVEL[callee] == LEVEL[caller] and not public:
        return "uses a peer's internal symbol"
    if not public and callee not in INTERNALS_OK.get(caller, set()):
        return "uses an internal symbol of a module whose internals it may not use"
    return None


def check(mods):
    """(edges {(caller, callee): n}, problems) of the parsed objects."""
    owner = {}
    for module, (defined, _) in mods.items():
        for s in defined:
            owner[s] = module
    edges, bad = {}, []
    for caller, (_, undefined) in sorted(mods.items()):
        for s in sorted(undefined):
            callee = owner.get(s)
            if callee is None or callee == caller:
                continue  # libc, libm, libccd, or the module itself
            edges[(caller, callee)] = edges.get((caller, callee), 0) + 1
            why = edge_problem(caller, callee, s)
            if why:
                bad.append("%s -> %s: %s %s" % (caller, callee, s, why))
    return edges, bad


# Wrong calls planted one at a time into a copy of the parsed objects: each must be reported.
# (caller, callee module, prefix of the callee's symbol to plant, what it shows)
PLANTED = [("core", "integrate", "occ_", "core calls an integrator"),
           ("geom", "core", "occ_", "geom calls core"),
           ("query", "integrate", "occi_", "query uses integrate's internals"),
           ("sectors", "core", "occi_", "a front end uses core's internals"),
           ("io", "sectors", "occ_", "io calls a front end")]


def selftest(mods):
    ok = True
    for caller, callee, prefix, what in PLANTED:
        symbols = sorted(s for s in mods.get(callee, (set(), set()))[0] if s.startswith(prefix))
        if caller not in mods or not symbols:
            print("deps_calls selftest: no %s... symbol in %s to plant in %s" % (prefix, callee, caller))
            ok = False
            continue
        planted = dict(mods)
        planted[caller] = (mods[caller][0], mods[caller][1] | {symbols[0]})
        caught = any(" %s " % symbols[0] in b for b in check(planted)[1])
        print("deps_calls selftest: planted %-34s (%s) %s" % (what, symbols[0], "caught" if caught else "MISSED"))
        ok = ok and caught
    return ok


def main():
    if len(sys.argv) < 2:
        print(__doc__)
        return 2
    mods = read_objects(sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else "nm")
    edges, bad = check(mods)
    print("deps_calls: calls between modules (%d modules; caller -> callee: symbols):" % len(mods))
    for caller in sorted(mods, key=lambda m: (LEVEL.get(m, 9), m)):
        outs = sorted((c, n) for (a, c), n in edges.items() if a == caller)
        print("  %-10s -> %s" % (caller, ", ".join("%s %d" % cn for cn in outs) or "(nothing)"))
    for b in bad:
        print("deps_calls: " + b)
    if not selftest(mods):
        print("FAIL deps-calls: a planted wrong-way call was not caught")
        return 1
    if bad:
        print("FAIL deps-calls: %d wrong call(s)" % len(bad))
        return 1
    print("PASS deps-calls")
    return 0


if __name__ == "__main__":
    sys.exit(main())
