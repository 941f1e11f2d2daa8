#!/usr/bin/env python3
"""demo_fake_run.py - a stand-in for `occmap run` (issue 21 interface) while it does not exist.

Used by tools/demo_run.py --fake: plays the companion side of the link as the interface file says
(HEARTBEAT from 1/196, SET_MESSAGE_INTERVAL for LOCAL_POSITION_NED and ATTITUDE until they come,
TIMESYNC for the clock offset), releases the depth frames at their recorded autopilot time once a
pose covers them, and "integrates" by rebuilding the map with `occmap build --depth-dir --frames K`
(all frames up to the newest released one, occmap's own integrator and ground-truth poses), then
sends OBSTACLE_DISTANCE at 2 Hz computed by tools/sector_ref.py on that map at the latest pose from
the link, and writes the feed log and stats lines of the interface. Slow and simple on purpose: it
exercises the stand-in, the checker and the pictures, not occmap run.
usage: demo_fake_run.py --occmap BIN run --udp 127.0.0.1:PORT --depth-dir DIR [--depth-stride N]
       [--res R] [--feed-log F] [--stats F] [--exit-after-depth] [--duration S] [ignored options]
"""
import json
import math
import os
import subprocess
import sys
import tempfile
import time

os.environ.setdefault("MAVLINK20", "1")
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from pymavlink import mavutil  # noqa: E402
from octomap_bt import read_bt  # noqa: E402
import sector_ref  # noqa: E402
import autopilot_standin as sa  # noqa: E402

BAND, MIN_CM, MAX_CM, OFFSET = 0.15, 20, 400, -20.0
INTR = (517.3, 516.5, 318.6, 255.3)  # what occmap build uses for a freiburg1 path


def opts(argv):
    o = {"--depth-stride": "1", "--res": "0.1", "--duration": "0"}
    i = 0
    while i < len(argv):
        a = argv[i]
        if a == "--exit-after-depth":
            o[a] = True
            i += 1
        else:
            o[a] = argv[i + 1]
            i += 2
    return o


def enu_pose(ned, rpy):
    """LOCAL_POSITION_NED + ATTITUDE -> ENU position, FLU quaternion (w x y z)."""
    R_nf = sa.rpy_mat(*rpy)
    R_wb = sa.mul(sa.mul(sa.tr(sa.NED_FROM_ENU), R_nf), sa.tr(sa.FLU_FROM_FRD))
    return [ned[1], ned[0], -ned[2]], sa.mat_to_quat(R_wb)


def main():
    occmap = sys.argv[2]
    o = opts(sys.argv[4:])
    frames, _ = sa.read_recording(o["--depth-dir"])
    t_ref = sa.t_ref_of(frames)
    frame_us = [int(round((t - t_ref) * 1e6)) for t, _ in frames]
    conn = mavutil.mavlink_connection("udpout:" + o["--udp"], source_system=1, source_component=196,
                                      dialect="ardupilotmega")
    stats = open(o["--stats"], "w") if "--stats" in o else sys.stderr
    feed = open(o["--feed-log"], "w") if "--feed-log" in o else None
    res, stride = float(o["--res"]), int(o["--depth-stride"])
    stats.write(json.dumps({"config": {"fake": True, "res": res, "stride": stride, "method": "simple",
                                       "intrinsics": [float(v) for v in o.get("--depth-intrinsics", ",".join(map(str, INTR))).split(",")], "mount": [0, 0, 0, 0, 0, 0],
                                       "band_below_m": BAND, "band_above_m": BAND, "ignore_ground": True,
                                       "ground_clearance_m": 0.1, "angle_offset_deg": OFFSET,
                                       "min_cm": MIN_CM, "max_cm": MAX_CM}}) + "\n")
    tmp = tempfile.mkdtemp(prefix="fake_run_")
    bt = os.path.join(tmp, "map.bt")
    t0 = time.monotonic()
    now_us = lambda: int((time.monotonic() - t0) * 1e6)  # noqa: E731
    offset_us = None
    lpn, att = {}, {}
    next_hb = next_req = next_sync = next_feed = next_stats = 0
    released = integrated = 0  # frames released / in the map
    logged = 0                 # frames named in the feed log so far
    version, seq, done = 0, 0, False
    tree = None
    end = t0 + float(o["--duration"]) if float(o["--duration"]) > 0 else None
    while end is None or time.monotonic() < end:
        t = now_us()
        if t >= next_hb:
            conn.mav.heartbeat_send(18, 8, 0, 0, 4)
            next_hb = t + 1000000
        if t >= next_sync:
            conn.mav.timesync_send(0, t * 1000)
            next_sync = t + 1000000
        if t >= next_req and (not lpn or not att):
            for mid in (32, 30):
                conn.mav.command_long_send(1, 1, 511, 0, mid, 20000, 0, 0, 0, 0, 0)
            next_req = t + 1000000
        m = conn.recv_msg()
        if m is not None:
            typ = m.get_type()
            if typ == "TIMESYNC" and m.tc1 != 0:
                offset_us = m.tc1 // 1000 - (m.ts1 // 1000 + now_us()) // 2
            elif typ == "LOCAL_POSITION_NED":
                lpn[m.time_boot_ms] = (m.x, m.y, m.z)
            elif typ == "ATTITUDE":
                att[m.time_boot_ms] = (m.roll, m.pitch, m.yaw)
        else:
            time.sleep(0.002)
        both = sorted(set(lpn) & set(att))
        if offset_us is None or not both:
            continue
        ap_now = now_us() + offset_us
        while released < len(frames) and frame_us[released] <= min(ap_now, both[-1] * 1000):
            released += 1
        if t >= next_feed:
            next_feed = t + 500000
            if released > integrated:
                subprocess.run([occmap, "build", "--depth-dir", o["--depth-dir"], "--frames", str(released),
                                "--stride", str(stride), "--res", str(res), "-o", bt], check=True,
                               stdout=subprocess.DEVNULL)
                integrated = released
                version += 1
                tree = read_bt(bt)
            if tree is None:
                continue
            k = both[-1]
            p, q = enu_pose(lpn[k], att[k])
            r = sa.quat_to_mat(q)
            yaw = math.atan2(r[1][0], r[0][0])
            rs, depth, leaves = tree
            za, zb = sector_ref.ground_band(rs, depth, leaves, p[0], p[1], p[2], BAND, BAND)
            sl = sector_ref.Slice(rs, depth, leaves, za, zb)
            d = sector_ref.sectors(sl, p[0], p[1], yaw, off_deg=OFFSET, min_cm=MIN_CM, max_cm=MAX_CM)[0]
            tu = k * 1000
            conn.mav.obstacle_distance_send(tu, 0, d, 0, MIN_CM, MAX_CM, 5.0, OFFSET, 12)
            if feed:
                feed.write(json.dumps({"time_usec": tu, "seq": seq, "version": version,
                                       "frames": list(range(logged, integrated)), "frames_dropped": [],
                                       "pose": p + list(q), "distances": d, "increment_deg": 5,
                                       "min_cm": MIN_CM, "max_cm": MAX_CM}) + "\n")
                feed.flush()
            logged = integrated
            seq += 1
            if done:
                break
            done = "--exit-after-depth" in o and integrated == len(frames)
        if t >= next_stats:
            next_stats = t + 1000000
            stats.write(json.dumps({"t_s": t / 1e6, "frames_integrated": integrated, "obstacle_tx": seq,
                                    "clock_offset_us": offset_us}) + "\n")
            stats.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
