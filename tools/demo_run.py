#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""demo_run.py - `make demo`: the onboard loop (`occmap run`) on real data, checked by OctoMap.

  1. tools/autopilot_standin.py plays ArduPilot on UDP loopback (HEARTBEAT, TIMESYNC, streams
     only once SET_MESSAGE_INTERVAL asks) and streams the recording's ground-truth poses as
     LOCAL_POSITION_NED + ATTITUDE at their timestamps;
  2. `occmap run --depth-dir DIR ... --feed-log --stats --exit-after-depth` maps the depth frames
     as they come and sends OBSTACLE_DISTANCE; the stand-in records every message it receives;
  3. every received OBSTACLE_DISTANCE must be a feed-log line (same time_usec and distances) with
     the fields the autopilots need, every frame of the directory must be integrated or counted
     dropped, and build/demo_ref (OctoMap, tools/demo_ref.cpp) recomputes every logged message's
     sectors from the frames integrated up to it: the agreement must reach --min-agree;
  4. pictures in OUT (loop_map.png, loop_strip.png) and the telemetry summary.
usage: demo_run.py --occmap BIN --ref build/demo_ref --depth-dir DIR --out OUT [--frames N]
       [--res 0.1] [--stride 4] [--tol-m 0.2] [--min-agree 0.9] [--min-agree-seen 0.9] [--plant]
       [--run-args "..."]
Exit 0 when every check passes; prints PASS/FAIL lines.
"""
import argparse
import json
import os
import shlex
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import autopilot_standin as sa  # noqa: E402

FR1 = (517.3, 516.5, 318.6, 255.3)  # freiburg1 calibration (tum_fr1_rpy/SOURCE.md)
FR2 = (520.9, 521.0, 325.1, 249.7)  # freiburg2 (data/README.md)


def short_copy(src, out, n):
    """A TUM directory with the first n frames of src (index file cut, depth/ and poses linked)."""
    dst = os.path.join(out, "%s_first%d" % (os.path.basename(os.path.normpath(src)), n))
    shutil.rmtree(dst, ignore_errors=True)
    os.makedirs(dst)
    src = os.path.abspath(src)
    os.symlink(os.path.join(src, "depth"), os.path.join(dst, "depth"))
    idx = "my_association.txt" if os.path.exists(os.path.join(src, "my_association.txt")) else "depth.txt"
    kept = 0
    with open(os.path.join(src, idx)) as f, open(os.path.join(dst, idx), "w") as g:
        for line in f:
            if line.startswith("#") or not line.strip():
                g.write(line)
            elif kept < n:
                g.write(line)
                kept += 1
    if idx == "depth.txt":
        os.symlink(os.path.join(src, "groundtruth.txt"), os.path.join(dst, "groundtruth.txt"))
    return dst


def sequence_copy(src, out):
    """The association layout (my_association.txt: rgb depth tx ty tz qx qy qz qw per frame, only
    some PNGs present) as the TUM sequence layout `occmap run --depth-dir` reads: depth.txt with
    the frames whose PNG is here, groundtruth.txt with every line's pose (the time is the depth
    file's name), depth/ linked."""
    dst = os.path.join(out, os.path.basename(os.path.normpath(src)) + "_seq")
    shutil.rmtree(dst, ignore_errors=True)
    os.makedirs(dst)
    src = os.path.abspath(src)
    os.symlink(os.path.join(src, "depth"), os.path.join(dst, "depth"))
    rows = []
    for line in open(os.path.join(src, "my_association.txt")):
        f = line.split()
        if len(f) >= 9 and not line.startswith("#"):
            rows.append((os.path.basename(f[1])[:-4], f[1], f[2:9]))
    rows.sort(key=lambda r: float(r[0]))
    # A depth frame associated with two RGB frames is listed twice: keep its first pose.
    rows = [r for i, r in enumerate(rows) if i == 0 or float(r[0]) > float(rows[i - 1][0])]
    with open(os.path.join(dst, "depth.txt"), "w") as g:
        g.write("# depth maps\n# from %s/my_association.txt (frames present)\n# timestamp filename\n" % src)
        for t, png, _ in rows:
            if os.path.exists(os.path.join(src, png)):
                g.write("%s %s\n" % (t, png))
    with open(os.path.join(dst, "groundtruth.txt"), "w") as g:
        g.write("# ground truth trajectory\n# from my_association.txt\n# timestamp tx ty tz qx qy qz qw\n")
        for t, _, v in rows:
            g.write("%s %s\n" % (t, " ".join(v)))
    return dst


def read_jsonl(path):
    out = []
    if os.path.exists(path):
        for line in open(path):
            line = line.strip()
            if line.startswith("{"):
                try:
                    out.append(json.loads(line))
                except ValueError:
                    pass
    return out


def pick(cfg, names, default):
    """The first of `names` found in the config object (nested one level), else default."""
    for n in names:
        if n in cfg:
            return cfg[n], n
        for v in cfg.values():
            if isinstance(v, dict) and n in v:
                return v[n], n
    return default, None


def ref_args(cfg, res, stride, intr):
    """demo_ref options from occmap run's {"config": ...} line (defaults where it is silent)."""
    used, missing = [], []

    def get(names, default):
        v, n = pick(cfg, names, default)
        (used if n else missing).append(names[0])
        return v
    res = get(["res", "resolution_m"], res)
    stride = get(["stride", "depth_stride"], stride)
    intr = get(["intrinsics", "depth_intrinsics"], list(intr))
    below = get(["band_below_m"], 0.5)
    above = get(["band_above_m"], 0.5)
    a = ["--res", str(res), "--stride", str(stride), "--intrinsics", ",".join(str(v) for v in intr),
         "--band", "%s,%s" % (below, above),
         "--ignore-ground", str(int(bool(get(["ignore_ground"], True)))),
         "--clearance", str(get(["ground_clearance_m"], 0.1)),
         "--offset-deg", str(get(["angle_offset_deg", "angle_offset"], -20.0)),
         "--unknown-as-distance", str(int(bool(get(["unknown_as_distance"], False)))),
         "--min-range", str(get(["min_range_m", "depth_min_range_m"], 0.0)),
         "--max-range", str(get(["max_range_m", "depth_max_range_m"], -1.0) or -1.0)]
    return a, used, missing


def check_link(st, feed, frames_n, errors):
    """Received messages against the feed log, fields, heartbeats, requests, frame accounting."""
    logged = {(m["time_usec"], tuple(m["distances"])) for m in feed}
    unmatched = [o for o in st.obstacles if (o["time_usec"], tuple(o["distances"])) not in logged]
    if unmatched:
        errors.append("%d OBSTACLE_DISTANCE received that the feed log does not hold (first: time_usec %d)"
                      % (len(unmatched), unmatched[0]["time_usec"]))
    if len(st.obstacles) + 1 < len(feed):
        errors.append("feed log has %d messages, the autopilot received %d" % (len(feed), len(st.obstacles)))
    for o in st.obstacles:
        d = o["distances"]
        inc = o["increment_f"] or o["increment"]
        if o["src"] != [1, 196] or o["frame"] != 12 or inc != 5.0 or len(d) != 72 or 0 in d \
                or not (0 < o["min_cm"] < o["max_cm"]):
            errors.append("bad OBSTACLE_DISTANCE fields: %s" % {k: v for k, v in o.items() if k != "distances"})
            break
    ours = [h for h in st.heartbeats if h["src"] == [1, 196]]
    if not ours or any(h["type"] != 18 for h in ours):  # MAV_TYPE_ONBOARD_CONTROLLER
        errors.append("no HEARTBEAT from 1/196 as an onboard controller: %s" % ours[:1])
    elif st.obstacles and not any(h["system_status"] == 4 for h in ours):  # MAV_STATE_ACTIVE
        errors.append("OBSTACLE_DISTANCE sent but HEARTBEAT never said ACTIVE")
    asked = {int(r[2]) for r in st.requests if r[1] == sa.CMD_SET_MESSAGE_INTERVAL}
    if sa.MSG_LPN not in asked and sa.MSG_ODOM not in asked:
        errors.append("occmap run never asked for LOCAL_POSITION_NED / ODOMETRY (asked %s)" % sorted(asked))
    seen = [i for m in feed for i in m.get("frames", [])] + [i for m in feed for i in m.get("frames_dropped", [])]
    if sorted(seen) != frames_n:
        dup = len(seen) - len(set(seen))
        errors.append("frames accounted %d of %d (%d twice)" % (len(set(seen)), len(frames_n), dup))


def telemetry(stats):
    """The telemetry summary: occmap run's config line, then its final line (or the last one),
    one key a line."""
    cfg = next((s["config"] for s in stats if "config" in s), {})
    lines = [s for s in stats if "config" not in s]
    print("demo: occmap run config: %s" % json.dumps(cfg))
    if lines:
        last = lines[-1].get("final", lines[-1])
        print("demo: telemetry (%d lines a second; %s):" % (len(lines), "final" if "final" in lines[-1] else "last"))
        for k, v in last.items():
            print("demo:   %-14s %s" % (k, json.dumps(v)))
    return cfg


def parse_args():
    ap = argparse.ArgumentParser()
    ap.add_argument("--occmap", required=True)
    ap.add_argument("--ref", required=True)
    ap.add_argument("--depth-dir", required=True)
    ap.add_argument("--poses")
    ap.add_argument("--out", required=True)
    ap.add_argument("--frames", type=int, default=0)
    ap.add_argument("--res", type=float, default=0.1)
    ap.add_argument("--stride", type=int, default=4)
    ap.add_argument("--tol-m", type=float, default=0.2)
    ap.add_argument("--min-agree", type=float, default=0.9)
    ap.add_argument("--min-agree-seen", type=float, default=0.9)
    ap.add_argument("--timeout", type=float, default=120.0)
    ap.add_argument("--run-args", default="", help="more options for occmap run")
    ap.add_argument("--name", default="loop")
    ap.add_argument("--plant", action="store_true",
                    help="then prove the checker: planted wrong distances in the feed log must fail it")
    return ap.parse_args()


def run_loop(a, d, frames, poses, intr, path, errors):
    """The stand-in in a thread and `occmap run` against it, until it exits. Returns the stand-in."""
    for f in ("feed.jsonl", "stats.jsonl", "standin.jsonl"):
        if os.path.exists(path(f)):
            os.remove(path(f))
    st = sa.Standin(poses, sa.t_ref_of(frames), record=path("standin.jsonl"))
    th = st.start()
    cmd = [a.occmap, "run", "--udp", "127.0.0.1:%d" % st.port, "--depth-dir", d, "--depth-stride", str(a.stride),
           "--res", str(a.res), "--depth-intrinsics", ",".join(str(v) for v in intr),
           "--feed-log", path("feed.jsonl"), "--stats", path("stats.jsonl"), "--exit-after-depth",
           "--duration", str(int(a.timeout))] + shlex.split(a.run_args)
    print("demo: %d poses; stand-in on 127.0.0.1:%d; %s" % (len(st.poses), st.port, " ".join(cmd)), flush=True)
    t0 = time.monotonic()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        _, err = proc.communicate(timeout=a.timeout + 30)
    except subprocess.TimeoutExpired:
        proc.kill()
        _, err = proc.communicate()
        errors.append("occmap run did not exit within %.0f s" % (a.timeout + 30))
    time.sleep(0.3)  # the last message in flight
    st.stop.set()
    th.join(5)
    if proc.returncode != 0:
        errors.append("occmap run exit %s: %s" % (proc.returncode, err.strip()[-600:]))
    print("demo: loop done in %.1f s: stand-in %s" % (time.monotonic() - t0, json.dumps(st.summary())), flush=True)
    for s in st.statustexts:
        print("demo: STATUSTEXT from %s: %s" % (s["src"], s["text"]))
    return st


def check_ref(a, d, feed, cfg, intr, path, errors):
    """build/demo_ref over the feed log; returns its summary (or None) and its command line."""
    args, _, missing = ref_args(cfg, a.res, a.stride, intr)
    if missing:
        print("demo: config line lacks %s: demo_ref uses its defaults there" % ", ".join(missing))
    seqs = sorted({feed[int(i * (len(feed) - 1) / 5)]["seq"] for i in range(6)})
    cmd_ref = [a.ref, "--feed-log", path("feed.jsonl"), "--depth-dir", d, "--tol-m", str(a.tol_m),
               "--min-agree", str(a.min_agree), "--min-agree-seen", str(a.min_agree_seen), "--out", path("ref.jsonl"), "--slices", a.out,
               "--slice-seqs", ",".join(str(s) for s in seqs)] + args
    if a.poses:
        cmd_ref += ["--poses", a.poses]
    t0 = time.monotonic()
    r = subprocess.run(cmd_ref, stdout=subprocess.PIPE, text=True)
    print("demo: %s\ndemo: OctoMap reference over %d messages in %.1f s: %s"
          % (" ".join(cmd_ref), len(feed), time.monotonic() - t0, r.stdout.strip()), flush=True)
    try:
        ref = json.loads(r.stdout.strip().splitlines()[-1])
    except (ValueError, IndexError):
        ref = None
    if r.returncode != 0:
        errors.append("OctoMap reference disagrees (demo_ref exit %d)" % r.returncode)
    pictures(a, feed, seqs, cfg)
    return ref, cmd_ref


def main():
    a = parse_args()
    os.makedirs(a.out, exist_ok=True)
    t_start = time.monotonic()
    d = a.depth_dir
    if os.path.exists(os.path.join(d, "my_association.txt")):
        d = sequence_copy(d, a.out)
    d = short_copy(d, a.out, a.frames) if a.frames else d
    frames, poses = sa.read_recording(d, a.poses)
    intr = FR2 if "fr2" in os.path.basename(d) or "freiburg2" in d else FR1
    path = lambda n: os.path.join(a.out, "%s_%s" % (a.name, n))  # noqa: E731
    # depth.txt may list frames whose PNG is not here (tum_fr1_rpy: 722 listed, 500 copied).
    present = [i for i, f in enumerate(frames) if os.path.exists(os.path.join(d, f[1]))]
    print("demo: %s: %d frames over %.1f s" % (d, len(present), frames[present[-1]][0] - frames[present[0]][0]))
    errors = []
    st = run_loop(a, d, frames, poses, intr, path, errors)
    feed = read_jsonl(path("feed.jsonl"))
    if feed:
        check_link(st, feed, present, errors)
    else:
        errors.append("empty feed log")
    cfg = telemetry(read_jsonl(path("stats.jsonl")))
    ref = None
    if feed:
        ref, cmd_ref = check_ref(a, d, feed, cfg, intr, path, errors)
        if a.plant:
            plant(a, feed, cmd_ref, errors)
    n_int = sum(len(m.get("frames", [])) for m in feed)
    n_drop = sum(len(m.get("frames_dropped", [])) for m in feed)
    print("demo: %d OBSTACLE_DISTANCE received, %d frames integrated, %d dropped, agreement %s, total %.1f s"
          % (len(st.obstacles), n_int, n_drop,
             "%.1f %% of all sectors, %.1f %% of the %d not unknown on both sides"
             % (100 * ref["agree_frac"], 100 * ref["seen_agree_frac"], ref["seen"]) if ref else "-",
             time.monotonic() - t_start))
    for e in errors:
        print("FAIL demo %s: %s" % (a.name, e))
    print("%s demo %s" % ("FAIL" if errors else "PASS", a.name), flush=True)
    return 1 if errors else 0


def plant(a, feed, cmd_ref, errors):
    """The checker must refuse a feed log whose sectors lie: every sector "no obstacle", and every
    sector an obstacle at 1 m (the tolerance is 0.2 m)."""
    for what, val in (("all free", lambda m: m["max_cm"] + 1), ("all obstacles at 1 m", lambda m: 100)):
        p_bad = os.path.join(a.out, "%s_planted.jsonl" % a.name)
        with open(p_bad, "w") as f:
            for m in feed:
                f.write(json.dumps(dict(m, distances=[val(m)] * len(m["distances"]))) + "\n")
        c = list(cmd_ref)
        c[c.index("--feed-log") + 1] = p_bad
        for opt in ("--out", "--slices", "--slice-seqs"):  # keep the real run's outputs
            i = c.index(opt)
            del c[i:i + 2]
        c += ["--min-agree", "0.5", "--min-agree-seen", "0.5"]
        r = subprocess.run(c, stdout=subprocess.PIPE, text=True)
        print("demo: planted %s: demo_ref exit %d %s" % (what, r.returncode, r.stdout.strip()[:160]))
        if r.returncode != 1:
            errors.append("the OctoMap checker accepted a feed log with %s sectors" % what)


def pictures(a, feed, seqs, cfg):
    import demo_pictures as dp
    msgs = {m["seq"]: m for m in feed}
    slices = [dp.read_slice(os.path.join(a.out, "slice_%d.txt" % s)) for s in seqs
              if os.path.exists(os.path.join(a.out, "slice_%d.txt" % s))]
    for s in seqs:
        path = os.path.join(a.out, "slice_%d.txt" % s)
        if os.path.exists(path):
            os.replace(path, os.path.join(a.out, "%s_slice_%d.txt" % (a.name, s)))
    max_cm = feed[-1]["max_cm"]
    off, _ = pick(cfg, ["angle_offset_deg", "angle_offset"], -20.0)
    if slices:
        w, h = dp.map_panels(os.path.join(a.out, "%s_map.png" % a.name), slices, msgs, float(off), max_cm)
        print("demo: %s/%s_map.png (%dx%d): map slice, path and sectors at messages %s"
              % (a.out, a.name, w, h, seqs))
    refs = {r["seq"]: r for r in read_jsonl(os.path.join(a.out, "%s_ref.jsonl" % a.name))}
    rows = [refs.get(m["seq"], {}).get("ok") for m in feed]
    w, h = dp.strip(os.path.join(a.out, "%s_strip.png" % a.name), feed, rows, max_cm)
    print("demo: %s/%s_strip.png (%dx%d): sectors over time, disagreements below" % (a.out, a.name, w, h))


if __name__ == "__main__":
    sys.exit(main())
