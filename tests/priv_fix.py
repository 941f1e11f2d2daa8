#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""priv_fix.py - after fields of a public instance struct move into its internal `priv` member
(issue 17, Headers: "nothing a caller must never touch looks public"), rewrite every use the
compiler rejects: `m->root_child` -> `m->priv.root_child`.

The compiler finds the uses, so the rename follows types, not spellings (a test's own struct
with a field of the same name is left alone). Each round runs `make -k -j2 TARGETS`, reads GCC's
"'T' has no member named 'F'" errors for the (T, F) pairs below, inserts `priv.` at the reported
column (after the `->` or `.` it points at), and repeats until no such error is left; then the build must pass. For the lead after a
merge: take the other side of a conflicting line and run this again.
usage: tests/priv_fix.py [MAKE TARGETS...]   (default: all test-build cross-objs lint)
"""
import os
import re
import subprocess
import sys

MOVED = {
    "occ_map_t": {"q_hit", "q_miss", "q_clamp_min", "q_clamp_max", "q_free_max", "q_occ_min",
                  "arena", "block_budget", "geo_res", "geo_inv", "geo_res_f", "geo_inv_f",
                  "root_child", "root_value", "root_flags"},
    "occ_pool_t": {"free_head"},
    "occ_mav_parser_t": {"pos", "need", "buf"},
    "occ_mav_feed_t": {"tx", "have_pos", "have_att", "started", "request_mask", "pos_us",
                       "att_us", "next_request_us", "north", "east", "down", "yaw_ned", "roll",
                       "pitch", "ned_m", "ned_from_frd", "next_obstacle_us", "next_heartbeat_us", "sectors"},
    "occ_dronecan_node_t": {"iface", "tid_proximity", "tid_status", "started", "start_us",
                            "sectors"},
}
ERROR = re.compile(r"^([^:\s]+):(\d+):(\d+): error: .*?['\u2018](?:const )?(?:struct )?(\w+)['\u2019]"
                   r".*?has no member named ['\u2018](\w+)['\u2019]")


def fix_round(targets):
    env = dict(os.environ, LC_ALL="C")  # plain quotes in GCC's messages
    run = subprocess.run(["make", "-k", "-j2", *targets], capture_output=True, text=True, env=env)
    spots = set()
    for line in (run.stdout + run.stderr).splitlines():
        m = ERROR.match(line)
        if m and m.group(5) in MOVED.get(m.group(4), set()):
            path = os.path.relpath(os.path.realpath(m.group(1)))  # one file, many spellings
            spots.add((path, int(m.group(2)), int(m.group(3)), m.group(5)))
    by_file = {}
    for path, line, col, field in spots:
        by_file.setdefault(path, []).append((line, col, field))
    for path, edits in by_file.items():
        with open(path, encoding="utf-8") as fh:
            lines = fh.read().split("\n")
        for line, col, field in sorted(edits, reverse=True):
            text = lines[line - 1]
            # GCC points at the member access operator ('.' or '->') or at the member itself.
            op = re.match(r"(->|\.)?\s*" + field + r"\b", text[col - 1:])
            if not op:
                sys.exit("priv_fix: %s:%d:%d is not `.%s`" % (path, line, col, field))
            at = col - 1 + op.end() - len(field)
            lines[line - 1] = text[:at] + "priv." + text[at:]
        with open(path, "w", encoding="utf-8") as fh:
            fh.write("\n".join(lines))
    return len(spots), run.returncode, run.stdout + run.stderr


def main():
    targets = sys.argv[1:] or ["all", "test-build", "cross-objs", "lint"]
    total = 0
    for _ in range(20):
        n, rc, out = fix_round(targets)
        total += n
        print("priv_fix: %d use(s) rewritten this round" % n)
        if n == 0:
            if rc != 0:
                print("\n".join(l for l in out.splitlines() if "error:" in l)[:4000])
            print("priv_fix: %d in all; make %s %s" % (total, " ".join(targets),
                                                       "passes" if rc == 0 else "FAILS"))
            return rc
    return 1


if __name__ == "__main__":
    sys.exit(main())
