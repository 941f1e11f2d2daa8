#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""run_peer.py --occmap BIN --data DIR [--test NAME|all] [--out DIR]

`occmap run` (issue 21) over UDP loopback against a pymavlink autopilot stand-in (listening like
SITL's udpin as sysid 1 compid 1): it answers TIMESYNC (tc1 = its boot time in ns, ts1 echoed)
and MAV_CMD_SET_MESSAGE_INTERVAL (COMMAND_ACK), starts a stream only once asked, and streams the
TUM sequence's ground truth as LOCAL_POSITION_NED + ATTITUDE stamped with its boot time
(time_boot = TUM time - T_REF, T_REF = first depth.txt time - 1 s; its clock may run `speed`
times faster so the tests take seconds). Tests (each prints PASS/FAIL):
  requests  the stand-in ignores the first 2 requests of each stream: occmap must repeat them
            until the streams arrive; poses from another system (sysid 2, 100 m away) are
            ignored (every feed-log pose lies on the ground-truth path); a refusing autopilot is
            logged.
  drop      the whole 500-frame sequence, fast replay, in a tiny arena: the stand-in withholds
            the poses of boot time [6, 7) s; every frame is integrated or counted, the frames
            dropped for want of a pose are exactly those the pose history's rule (bracketing
            samples > 100 ms apart, or before the first / after the last) gives, the process
            ends by itself (--exit-after-depth) with exit 0, eviction ran and some frames were
            integrated only in part (both paths of the never-stop rule), occ_map_check holds.
  stale     sensors stale after the last frame (then pose stale with a prior --map): one
            STATUSTEXT each, no OBSTACLE_DISTANCE after it, HEARTBEAT ACTIVE before, CRITICAL after.
  ranges_time   a range reading is integrated with the pose at its own time_boot_ms (TIMESYNC),
            one stamped on another clock with the pose at its arrival.
  ranges_stale  --mavlink-ranges without a camera: the rangefinder stops while the poses go
            on: one STATUSTEXT, no OBSTACLE_DISTANCE after it, HEARTBEAT CRITICAL.
  3d        --3d: OBSTACLE_DISTANCE_3D above / below after each OBSTACLE_DISTANCE, decoded by
            pymavlink, at the points another component reported (within a voxel).
  save      -o with --save-every 0.5 ended by SIGTERM mid-run: exit 0, >= 2 saves counted, the
            map written at the signal loads (occmap info), no temporary file left.
  jitter    mapping busy (full-resolution frames) while the feed runs: its period jitter is
            reported (p50/p99/max, printed), its median below half an integration's (the feed
            never waits for the writer), the feed saw new map versions while it ran; the final
            telemetry's clock source is TIMESYNC and its offset the stand-in's (within half
            the round trip).
Exit 0 when every test passed."""
import argparse
import json
import math
import os
import signal
import socket
import subprocess
import sys
import time

os.environ["MAVLINK20"] = "1"
from pymavlink import mavutil  # noqa: E402

GAP_US = 100000  # OCC_TUM_MAX_GAP_US


def free_port():
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    p = s.getsockname()[1]
    s.close()
    return p


# ---- TUM ground truth -> MAVLink NED pose of the body (FLU body = camera with the default mount)
def qmul(a, b):
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw)


def qmat(q):
    w, x, y, z = q
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]


def mmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


CAM_FROM_BODY = (0.5, 0.5, -0.5, 0.5)  # inverse of body_from_optical (0.5, -0.5, 0.5, -0.5)
ENU_NED = [[0, 1, 0], [1, 0, 0], [0, 0, -1]]
FLU_FRD = [[1, 0, 0], [0, -1, 0], [0, 0, -1]]


def body_pose(tx, ty, tz, qx, qy, qz, qw):
    """world ENU <- body FLU, and the NED position / roll, pitch, yaw of body FRD."""
    q = qmul((qw, qx, qy, qz), CAM_FROM_BODY)
    r_ned_frd = mmul(mmul(ENU_NED, qmat(q)), FLU_FRD)
    yaw = math.atan2(r_ned_frd[1][0], r_ned_frd[0][0])
    pitch = -math.asin(max(-1.0, min(1.0, r_ned_frd[2][0])))
    roll = math.atan2(r_ned_frd[2][1], r_ned_frd[2][2])
    return (tx, ty, tz), (ty, tx, -tz), (roll, pitch, yaw)


def read_tum(d):
    depth = []
    for line in open(os.path.join(d, "depth.txt")):
        if line.startswith("#") or not line.strip():
            continue
        t, f = line.split()[:2]
        depth.append((float(t), f))
    t_ref = depth[0][0] - 1.0
    gt = []
    for line in open(os.path.join(d, "groundtruth.txt")):
        if line.startswith("#") or not line.strip():
            continue
        v = [float(x) for x in line.split()]
        boot_us = int(round((v[0] - t_ref) * 1e6))
        if boot_us > 0:
            gt.append((boot_us,) + body_pose(*v[1:8]))
    frames = [(i, int(round((t - t_ref) * 1e6))) for i, (t, f) in enumerate(depth)
              if os.path.exists(os.path.join(d, f))]
    return frames, gt


class Peer:
    def __init__(self, port, gt, speed=1.0, ignore=0, refuse=False, foreign=False,
                 withhold=None, stop_at_us=None, hold_last=False):
        self.port = port
        self.conn = mavutil.mavlink_connection("udpin:127.0.0.1:%d" % port, source_system=1,
                                               source_component=1)
        self.other = mavutil.mavlink.MAVLink(None, srcSystem=2, srcComponent=1)
        self.gt, self.speed, self.ignore, self.refuse = gt, speed, ignore, refuse
        self.foreign, self.withhold, self.stop_at_us, self.hold_last = foreign, withhold, stop_at_us, hold_last
        self.t0 = time.monotonic()
        self.next_gt = 0
        self.streaming = False
        self.streams = set()
        self.requests = {}
        self.obstacles = []    # (local time, msg)
        self.statustexts = []  # (local time, severity, text)
        self.heartbeats = []   # (local time, system_status)
        self.sent_us = []      # boot times of the poses sent
        self.sent_at = []      # and the local times they were sent at (a stalled stand-in)
        self.next_hb = 0.0
        self.last_pose_us = 0

    def boot_us(self):
        return int((time.monotonic() - self.t0) * 1e6 * self.speed)

    def handle(self, m):
        t = m.get_type()
        if t == "TIMESYNC" and m.tc1 == 0:
            self.conn.mav.timesync_send(self.boot_us() * 1000, m.ts1)
        elif t == "COMMAND_LONG" and m.command == 511:
            mid = int(m.param1)
            self.requests[mid] = self.requests.get(mid, 0) + 1
            if self.requests[mid] <= self.ignore:
                return
            self.conn.mav.command_ack_send(511, 2 if self.refuse else 0)
            if not self.refuse:
                self.streams.add(mid)
        elif t == "OBSTACLE_DISTANCE":
            self.obstacles.append((time.monotonic(), m))
        elif t == "STATUSTEXT":
            self.statustexts.append((time.monotonic(), m.severity, m.text))
        elif t == "HEARTBEAT" and m.get_srcComponent() == 196:
            self.heartbeats.append((time.monotonic(), m.system_status))

    def send_pose(self, boot, ned, rpy):
        ms = boot // 1000
        if 32 in self.streams:
            self.conn.mav.local_position_ned_send(ms, ned[0], ned[1], ned[2], 0, 0, 0)
        if 30 in self.streams:
            self.conn.mav.attitude_send(ms, rpy[0], rpy[1], rpy[2], 0, 0, 0)
        self.sent_us.append(ms * 1000)  # the stamp occmap sees
        self.sent_at.append(time.monotonic())
        self.last_pose_us = boot

    def poses(self):
        now = self.boot_us()
        if self.stop_at_us is not None and now >= self.stop_at_us:
            return
        if 32 not in self.streams or 30 not in self.streams:
            return
        if not self.streaming:  # a stream starts now, not in the past (as ArduPilot's)
            self.streaming = True
            while self.next_gt < len(self.gt) and self.gt[self.next_gt][0] < now:
                self.next_gt += 1
        while self.next_gt < len(self.gt) and self.gt[self.next_gt][0] <= now:
            boot, enu, ned, rpy = self.gt[self.next_gt]
            self.next_gt += 1
            if self.withhold is None or not (self.withhold[0] <= boot < self.withhold[1]):
                self.send_pose(boot, ned, rpy)
        if self.hold_last and self.next_gt == len(self.gt) and now - self.last_pose_us >= 20000:
            _, _, ned, rpy = self.gt[-1]
            self.send_pose(now, ned, rpy)

    def step(self):
        while True:
            m = self.conn.recv_match(blocking=False)
            if m is None:
                break
            self.handle(m)
        if time.monotonic() >= self.next_hb and self.conn.clients:
            self.next_hb = time.monotonic() + 1.0
            self.conn.mav.heartbeat_send(2, 3, 0, 0, 4)
            if self.foreign:
                self.conn.write(self.other.heartbeat_encode(2, 3, 0, 0, 4).pack(self.other))
        if self.conn.clients:
            self.poses()
            if self.foreign and self.gt:
                _, _, ned, rpy = self.gt[min(self.next_gt, len(self.gt) - 1)]
                ms = self.boot_us() // 1000
                self.conn.write(self.other.local_position_ned_encode(
                    ms, ned[0] + 100, ned[1] + 100, ned[2], 0, 0, 0).pack(self.other))
                self.conn.write(self.other.attitude_encode(ms, 0, 0, 0, 0, 0, 0).pack(self.other))
        time.sleep(0.002)


def run(occmap, args, peer, timeout, term_after=None):
    """occmap run against the peer until it exits (or timeout: killed, a failure); SIGTERM
    after `term_after` s if given (its wall-clock time in peer.term_time)."""
    p = subprocess.Popen([occmap, "run"] + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True)
    start = time.monotonic()
    end = start + timeout
    while p.poll() is None and time.monotonic() < end:
        peer.step()
        if term_after is not None and time.monotonic() - start >= term_after:
            term_after, peer.term_time = None, time.time()
            p.send_signal(signal.SIGTERM)
    if p.poll() is None:
        p.kill()
    out, err = p.communicate()
    peer.conn.close()
    return p.returncode, out, err


def run_sensor(occmap, args, peer, send, send_for=None, period=0.1):
    """occmap run against the peer while another component (1/158) calls send(mav, boot_us)
    every `period` s once the poses flow, for `send_for` s (None: to the end). Returns the exit
    status, stderr and the local times of the first and last send."""
    sensor = mavutil.mavlink.MAVLink(None, srcSystem=1, srcComponent=158)
    p = subprocess.Popen([occmap, "run", "--udp", "127.0.0.1:%d" % peer.port] + args,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    nxt, first, last = 0.0, None, None
    while p.poll() is None:
        peer.step()
        now = time.monotonic()
        if peer.conn.clients and peer.sent_us and now > nxt:
            first = now if first is None else first
            if send_for is None or now - first < send_for:
                nxt, last = now + period, now
                for m in send(sensor, peer.boot_us()):
                    peer.conn.write(m.pack(sensor))
    _, err = p.communicate()
    peer.conn.close()
    return p.returncode, err, first, last


def stats_lines(path):
    return [json.loads(x) for x in open(path) if x.strip()]


def feed_log(path):
    return [json.loads(x) for x in open(path) if x.strip()]


class Check:
    def __init__(self, name):
        self.name, self.bad = name, []

    def that(self, ok, what):
        if not ok:
            self.bad.append(what)
        return ok

    def done(self, summary):
        if self.bad:
            print("FAIL run-%s: %s" % (self.name, "; ".join(self.bad)))
        else:
            print("PASS run-%s: %s" % (self.name, summary))
        return not self.bad


def gt_camera(d):
    """groundtruth.txt as (boot_us, position, quaternion w x y z): TUM's world <- camera."""
    frames, _ = read_tum(d)
    first = None
    for line in open(os.path.join(d, "depth.txt")):
        if not line.startswith("#") and line.strip():
            first = float(line.split()[0])
            break
    out = []
    for line in open(os.path.join(d, "groundtruth.txt")):
        if line.startswith("#") or not line.strip():
            continue
        v = [float(x) for x in line.split()]
        b = int(round((v[0] - first + 1.0) * 1e6))
        if b > 0:
            out.append((b // 1000 * 1000, v[1:4], (v[7], v[4], v[5], v[6])))  # stamps as sent (ms)
    return out


def slerp(a, b, s):
    d = sum(x * y for x, y in zip(a, b))
    if d < 0:
        b, d = tuple(-x for x in b), -d
    if d > 0.9995:
        q = tuple(x + s * (y - x) for x, y in zip(a, b))
    else:
        th = math.acos(d)
        q = tuple((math.sin((1 - s) * th) * x + math.sin(s * th) * y) / math.sin(th)
                  for x, y in zip(a, b))
    n = math.sqrt(sum(x * x for x in q))
    return tuple(x / n for x in q)


def camera_at(cam, t):
    import bisect
    ts = [c[0] for c in cam]
    k = bisect.bisect_left(ts, t)
    if ts[k] == t:
        return cam[k][1], cam[k][2]
    a, b = cam[k - 1], cam[k]
    s = (t - a[0]) / (b[0] - a[0])
    return [x + s * (y - x) for x, y in zip(a[1], b[1])], slerp(a[2], b[2], s)


def pose_errors(lines, frames, cam, sent_us):
    """Largest position (m) and rotation (deg) difference between the camera pose each frame
    was integrated with (feed log) and TUM's ground truth interpolated at the frame's stamp
    from the samples the stand-in sent."""
    sent = set(sent_us)
    cam = [c for c in cam if c[0] in sent]
    t_of = dict(frames)
    dp = da = 0.0
    for ln in lines:
        for idx, p in zip(ln["frames"], ln["frame_poses"]):
            pos, q = camera_at(cam, t_of[idx])
            dp = max(dp, math.sqrt(sum((x - y) ** 2 for x, y in zip(p[:3], pos))))
            d = abs(sum(x * y for x, y in zip(p[3:], q)))
            da = max(da, math.degrees(2 * math.acos(min(1.0, d))))
    return dp, da


def expected_drops(frames, sent_us):
    """The pose history's verdict per frame from the stamps actually sent."""
    out = {}
    s = sorted(sent_us)
    import bisect
    for idx, t in frames:
        if not s or t < s[0]:
            out[idx] = "no_pose_too_old" if s else "no_pose_yet"
        elif t > s[-1]:
            out[idx] = "no_pose_too_new"
        else:
            k = bisect.bisect_left(s, t)
            if s[k] == t:
                continue
            if s[k] - s[k - 1] > GAP_US:
                out[idx] = "no_pose_gap"
    return out


def clock_ok(c, fin, peer):
    """The final telemetry's clock: TIMESYNC answered, and its offset (autopilot - occmap
    clock, us) is the stand-in's: its boot time is (monotonic - t0) x speed, occmap's clock is
    the same CLOCK_MONOTONIC, so at speed 1 the offset is -t0 within half the round trip."""
    clk = fin.get("clock", {})
    c.that(clk.get("source") == "timesync" and clk.get("timesync_replies", 0) > 0,
           "clock %s (want source timesync)" % clk)
    want = -peer.t0 * 1e6
    err = abs(clk.get("offset_us", 0) - want)
    c.that(peer.speed == 1.0 and err <= clk.get("rtt_us", 0) / 2 + 1000,
           "clock offset %s us, the stand-in's %.0f us (off by %.0f, rtt %s us)" %
           (clk.get("offset_us"), want, err, clk.get("rtt_us")))
    return err


def test_requests(o, frames, gt):
    c = Check("requests")
    port = free_port()
    peer = Peer(port, gt, speed=4.0, ignore=2, foreign=True)
    st, fl = os.path.join(o.out, "req_stats.json"), os.path.join(o.out, "req_feed.json")
    rc, out, err = run(o.occmap, ["--udp", "127.0.0.1:%d" % port, "--depth-dir", o.data,
                                  "--replay-speed", "0", "--depth-stride", "16", "--duration", "4",
                                  "--stats", st, "--feed-log", fl], peer, 30)
    c.that(rc == 0, "exit %s: %s" % (rc, err[-500:]))
    c.that(peer.requests.get(32, 0) >= 3 and peer.requests.get(30, 0) >= 3,
           "requests per stream %s (want >= 3: the first 2 ignored)" % peer.requests)
    c.that(len(peer.obstacles) > 0, "no OBSTACLE_DISTANCE once the streams came")
    fin = stats_lines(st)[-1]["final"] if os.path.exists(st) else {}
    c.that(fin.get("poses", {}).get("foreign", 0) > 0, "foreign poses not counted: %s" % fin.get("poses"))
    c.that(fin.get("feed", {}).get("requests_tx", 0) >= 6, "requests_tx %s" % fin.get("feed"))
    lines = feed_log(fl) if os.path.exists(fl) else []
    xs = [g[1] for g in gt]
    lo = [min(p[i] for p in xs) - 0.05 for i in range(3)]
    hi = [max(p[i] for p in xs) + 0.05 for i in range(3)]
    off = [ln["pose"] for ln in lines
           if not all(lo[i] <= ln["pose"][i] <= hi[i] for i in range(3))]
    c.that(lines and not off, "%d feed-log poses off the ground-truth path (foreign taken?): %s"
           % (len(off), off[:2]))
    # a refusing autopilot: logged
    port = free_port()
    peer = Peer(port, gt, refuse=True)
    rc2, _, err2 = run(o.occmap, ["--udp", "127.0.0.1:%d" % port, "--duration", "2.5",
                                  "--stats", os.path.join(o.out, "refuse_stats.json")], peer, 20)
    c.that(rc2 == 0 and "refused SET_MESSAGE_INTERVAL" in err2, "refusal not logged: %s" % err2[-300:])
    return c.done("requests per stream %s before the streams came; %d foreign poses ignored; "
                  "%d feed-log poses on the path; refusal logged" %
                  (peer.requests, fin.get("poses", {}).get("foreign", 0), len(lines)))


def drop_detail(extra, frames, peer, fin):
    """What a wrongly dropped frame saw: its stamp, the poses sent around it, the longest pause
    of the stand-in between two sends (local time), occmap's pose counters; run-drop once
    dropped frame 0 as "too new" on a loaded CI machine, and these say why next time."""
    if not extra:
        return "none"
    t_of = dict(frames)
    s = peer.sent_us
    pause = max((b - a for a, b in zip(peer.sent_at, peer.sent_at[1:])), default=0.0)
    return ("frame stamps %s us; %d poses sent, stamps %s .. %s us; longest pause between sends "
            "%.3f s; occmap poses %s" % ([t_of[i] for i in extra[:3]], len(s), s[:1], s[-1:],
                                          pause, fin.get("poses")))


def test_drop(o, frames, gt):
    c = Check("drop")
    port = free_port()
    peer = Peer(port, gt, speed=4.0, withhold=(6000000, 7000000), hold_last=True)
    st, fl = os.path.join(o.out, "drop_stats.json"), os.path.join(o.out, "drop_feed.json")
    omap = os.path.join(o.out, "drop_map.occ")
    rc, out, err = run(o.occmap, ["--udp", "127.0.0.1:%d" % port, "--depth-dir", o.data,
                                  "--replay-speed", "0", "--depth-stride", "8",
                                  "--arena-bytes", o.tiny_arena, "--keep-radius", "1",
                                  "--exit-after-depth", "--stats", st, "--feed-log", fl,
                                  # the verdicts checked here are the history's rule, not the
                                  # timeout: a stand-in stalled > 500 ms on a loaded CI machine
                                  # made frame 0 "too new" once
                                  "--pose-timeout-ms", "5000",
                                  "-o", omap], peer, 60)
    c.that(rc == 0, "exit %s (alive to the end, map check): %s" % (rc, err[-500:]))
    sl = stats_lines(st) if os.path.exists(st) else [{}]
    fin = sl[-1].get("final", {})
    fr = fin.get("frames", {})
    c.that(fin.get("map_check") == "ok", "map_check %s" % fin.get("map_check"))
    c.that(fr.get("done") == len(frames), "frames done %s of %d" % (fr.get("done"), len(frames)))
    c.that(fr.get("integrated", 0) + sum(fr.get("dropped", {}).values()) == len(frames),
           "integrated + dropped != frames: %s" % fr)
    c.that(fin.get("evictions", 0) > 0 and fr.get("partial", 0) > 0,
           "%s evictions, %s partial frames: the arena was never short enough to prove the "
           "never-stop rule (evict, then integrate the nearest part)" %
           (fin.get("evictions"), fr.get("partial")))
    want = expected_drops(frames, peer.sent_us)
    lines = feed_log(fl) if os.path.exists(fl) else []
    got_int = [i for ln in lines for i in ln["frames"]]
    got_drop = [i for ln in lines for i in ln["frames_dropped"]]
    c.that(sorted(got_int + got_drop) == sorted(i for i, _ in frames),
           "feed log: %d integrated + %d dropped, want every one of %d frames once" %
           (len(got_int), len(got_drop), len(frames)))
    gap = sorted(i for i, why in want.items() if why == "no_pose_gap")
    c.that(len(gap) > 0, "the withheld poses make no gap")
    c.that(set(want) <= set(got_drop), "frames without a pose integrated: %s" %
           sorted(set(want) - set(got_drop))[:10])
    nomem = fr.get("dropped", {}).get("nomem", 0)
    extra = sorted(set(got_drop) - set(want))
    c.that(len(extra) == nomem + fr.get("dropped", {}).get("error", 0),
           "dropped frames that had a pose: %s (%s)" %
           (extra[:10], drop_detail(extra, frames, peer, fin)))
    for why in ("no_pose_gap", "no_pose_too_old", "no_pose_too_new"):
        n = sum(1 for w in want.values() if w == why)
        c.that(fr.get("dropped", {}).get(why) == n, "%s: %s, want %d" % (why, fr.get("dropped"), n))
    c.that(os.path.exists(omap), "-o not saved")
    dp, da = pose_errors(lines, frames, gt_camera(o.data), peer.sent_us)
    c.that(dp < 0.002 and da < 0.1, "integration poses off the ground truth by %.4f m / %.3f deg"
           % (dp, da))
    return c.done("%d frames: %d integrated (%d partial), dropped %s (the %d of the gap as the "
                  "history's rule says); %s evictions, arena %s, map_check ok, exit 0; frame "
                  "poses within %.2g m / %.2g deg of the interpolated ground truth" %
                  (len(frames), fr.get("integrated", 0), fr.get("partial", 0), fr.get("dropped"),
                   len(gap), fin.get("evictions"), fin.get("arena"), dp, da))


def silence(c, peer, phrase):
    """One WARNING STATUSTEXT with `phrase`; OBSTACLE_DISTANCE before it and none after; the
    HEARTBEAT says ACTIVE before and CRITICAL after."""
    warn = [s for s in peer.statustexts if s[1] == 4]
    c.that(len(warn) == 1 and phrase in warn[0][2], "STATUSTEXTs %s" % peer.statustexts)
    if not warn:
        return
    t = warn[0][0]
    before = [x for x in peer.obstacles if x[0] < t]
    after = [x for x in peer.obstacles if x[0] > t]
    c.that(before and not after, "%d OBSTACLE_DISTANCE before, %d after the STATUSTEXT" %
           (len(before), len(after)))
    hb_before = [s for (tt, s) in peer.heartbeats if tt < t]
    hb_after = [s for (tt, s) in peer.heartbeats if tt > t + 0.05]
    c.that(4 in hb_before and hb_after and all(s == 5 for s in hb_after),
           "heartbeat status before %s after %s" % (hb_before, hb_after))


def test_stale(o, frames, gt):
    c = Check("stale")
    port = free_port()
    peer = Peer(port, gt, speed=16.0, hold_last=True)
    st = os.path.join(o.out, "stale_stats.json")
    omap = os.path.join(o.out, "stale_map.occ")
    rc, _, err = run(o.occmap, ["--udp", "127.0.0.1:%d" % port, "--depth-dir", o.data,
                                "--replay-speed", "0", "--depth-stride", "32",
                                "--depth-max-frames", "60",
                                "--sensor-timeout-ms", "600", "--duration", "6", "-o", omap,
                                "--stats", st], peer, 30)
    c.that(rc == 0, "exit %s: %s" % (rc, err[-300:]))
    silence(c, peer, "sensors stale")
    n_sensor = len(peer.obstacles)
    # the pose: a prior map (-o of the run above), poses for 1.5 s, then none
    port = free_port()
    peer = Peer(port, gt, stop_at_us=1500000)
    rc, _, err = run(o.occmap, ["--udp", "127.0.0.1:%d" % port, "--map", omap, "--duration", "4.5",
                                "--stats", os.path.join(o.out, "stale2_stats.json")], peer, 30)
    c.that(rc == 0, "exit %s: %s" % (rc, err[-300:]))
    silence(c, peer, "pose stale")
    return c.done("sensors stale: %d OBSTACLE_DISTANCE then one STATUSTEXT and silence; pose "
                  "stale (prior map): %d then one STATUSTEXT and silence; HEARTBEAT 4 -> 5" %
                  (n_sensor, len(peer.obstacles)))


def test_save(o, frames, gt):
    """-o with --save-every 0.5, ended by SIGTERM while frames are being mapped: exit 0, the
    periodic saves counted (>= 2), the map saved at the signal (written after it) loads with
    `occmap info` and holds occupied voxels, no temporary file left beside it."""
    c = Check("save")
    peer = Peer(free_port(), gt, speed=1.0)
    sub = os.path.join(o.out, "save")
    os.makedirs(sub, exist_ok=True)
    for f in os.listdir(sub):
        os.remove(os.path.join(sub, f))
    omap, st = os.path.join(sub, "map.occ"), os.path.join(o.out, "save_stats.json")
    rc, _, err = run(o.occmap, ["--udp", "127.0.0.1:%d" % peer.port, "--depth-dir", o.data,
                                "--replay-speed", "0", "--depth-stride", "16", "-o", omap,
                                "--save-every", "0.5", "--stats", st], peer, 20, term_after=2.5)
    c.that(rc == 0, "exit %s after SIGTERM: %s" % (rc, err[-300:]))
    fin = stats_lines(st)[-1].get("final", {}) if os.path.exists(st) else {}
    fr = fin.get("frames", {})
    c.that(fin.get("saves", 0) >= 2 and fin.get("save_errors") == 0,
           "saves %s, errors %s (want >= 2 periodic, 0)" % (fin.get("saves"), fin.get("save_errors")))
    c.that(0 < fr.get("done", 0) < len(frames), "SIGTERM not mid-run: %s of %d frames done" %
           (fr.get("done"), len(frames)))
    c.that(os.path.exists(omap) and os.path.getmtime(omap) >= peer.term_time - 0.01,
           "-o not written at the signal")
    info = subprocess.run([o.occmap, "info", omap, "--json"], capture_output=True, text=True)
    occ = json.loads(info.stdout).get("occupied_voxels", 0) if info.returncode == 0 else 0
    c.that(occ > 0, "occmap info %s: exit %d, %d occupied: %s" % (omap, info.returncode, occ,
                                                                  info.stderr[-200:]))
    left = sorted(f for f in os.listdir(sub) if f != "map.occ")
    c.that(not left, "left beside the map: %s" % left)
    return c.done("SIGTERM after 2.5 s (%s frames done): exit 0, %s periodic saves, the map "
                  "written at the signal loads (%d occupied voxels), no temporary file" %
                  (fr.get("done"), fin.get("saves"), occ))


def test_jitter(o, frames, gt):
    c = Check("jitter")
    port = free_port()
    peer = Peer(port, gt, speed=1.0)
    st, fl = os.path.join(o.out, "jitter_stats.json"), os.path.join(o.out, "jitter_feed.json")
    rc, _, err = run(o.occmap, ["--udp", "127.0.0.1:%d" % port, "--depth-dir", o.data,
                                "--replay-speed", "0", "--depth-stride", "1", "--duration", "3",
                                "--stats", st, "--feed-log", fl], peer, 30)
    c.that(rc == 0, "exit %s: %s" % (rc, err[-300:]))
    fin = stats_lines(st)[-1].get("final", {}) if os.path.exists(st) else {}
    clock_err = clock_ok(c, fin, peer)
    feed, im = fin.get("feed", {}), fin.get("integrate_ms", {})
    j = feed.get("jitter_ms", {})
    c.that(j.get("n", 0) == feed.get("sent", 0) - 1 and j.get("n", 0) > 0,
           "jitter over %s periods, %s sent" % (j.get("n"), feed.get("sent")))
    c.that(0 <= j.get("p50", -1) <= j.get("p99", -1) <= j.get("max", -1), "jitter %s" % j)
    lines = feed_log(fl) if os.path.exists(fl) else []
    versions = [ln["version"] for ln in lines]
    c.that(len(set(versions)) > 2, "the feed never saw the map change: versions %s" % versions[:10])
    # The feed reads published versions and never waits for a frame being integrated: its
    # period's median slip stays well below one integration (with a mutex it was about one).
    c.that(j.get("p50", 1e9) < 0.5 * im.get("p50", 0),
           "feed jitter p50 %s ms not below half an integration (p50 %s ms): the feed waited for "
           "the writer" % (j.get("p50"), im.get("p50")))
    return c.done("mapping full frames (integrate p50 %s / p99 %s / max %s ms) while the feed "
                  "sent %s at %s ms: jitter p50 %s / p99 %s / max %s ms (lock-free map: p50 "
                  "below half an integration); TIMESYNC offset within %.0f us of the stand-in's" %
                  (im.get("p50"), im.get("p99"), im.get("max"), feed.get("sent"),
                   feed.get("period_ms"), j.get("p50"), j.get("p99"), j.get("max"), clock_err))


def down_150cm(mav, boot_us):
    """DISTANCE_SENSOR: 1.50 m straight down (PITCH_270), 0.2..4 m, stamped now."""
    return [mav.distance_sensor_encode(boot_us // 1000, 20, 400, 150, 0, 7, 25, 0)]


def test_ranges(o, frames, gt):
    """DISTANCE_SENSOR from another component (1/158, down, 1.50 m) with --mavlink-ranges and no
    camera: the voxel 1.5 m under the vehicle is occupied, the column above it free (hand
    placement: the vehicle holds the first ground-truth pose)."""
    c = Check("ranges")
    port = free_port()
    first = (gt[0][0], gt[0][1], gt[0][2], (0.0, 0.0, 0.3))  # level, heading 0.3 rad
    peer = Peer(port, [first], hold_last=True)
    omap = os.path.join(o.out, "ranges.occ")
    st = os.path.join(o.out, "ranges_stats.json")
    rc, err, _, _ = run_sensor(o.occmap, ["--mavlink-ranges", "--duration", "2", "-o", omap,
                                          "--stats", st], peer, down_150cm)
    c.that(rc == 0, "exit %s: %s" % (rc, err[-300:]))
    fin = stats_lines(st)[-1]["final"] if os.path.exists(st) else {}
    r = fin.get("ranges", {})
    c.that(r.get("integrated", 0) > 0, "ranges %s" % r)
    x, y, z = first[1]

    def q(*a):
        out = subprocess.run([o.occmap, "query", omap] + list(a) + ["--json"], capture_output=True,
                             text=True)
        return json.loads(out.stdout) if out.stdout.strip() else {}
    hit = q("--sphere", "%f,%f,%f,0.08" % (x, y, z - 1.5))
    c.that(hit.get("occupied_voxels", 0) > 0, "nothing occupied 1.5 m down: %s" % hit)
    for dz in (0.3, 0.7, 1.1, 1.3):  # points on the beam: free (unknown counts as unsafe)
        mid = q("--sphere", "%f,%f,%f,0.001" % (x, y, z - dz))
        c.that(mid.get("collides") is False, "%.1f m down not free: %s" % (dz, mid))
    return c.done("%s readings integrated from 1/158: hit 1.5 m down, free above" %
                  r.get("integrated"))


def test_ranges_time(o, frames, gt):
    """A reading is integrated with the pose at its own time_boot_ms (the autopilot's clock,
    through the TIMESYNC offset), not its arrival's: the vehicle (level, heading 0.3 rad) stands
    at A until boot 2.0 s, then moves 1 m east to B within 60 ms. Arriving at boot 2.2..2.45 s,
    sensor 0 reads 1.50 m down stamped 0.5 s before its arrival: the hit lies under A, not B.
    Sensor 1 reads 1.00 m down stamped boot 5 ms (not a time on the autopilot's clock: more
    than --sensor-timeout-ms before its arrival): stamped at arrival, its hit lies under B."""
    c = Check("ranges-time")
    (bx, by, bz), rpy = gt[0][1], (0.0, 0.0, 0.3)
    path = []
    for k in range(301):  # every 20 ms, 0..6 s
        t = k * 20000
        x = bx + min(1.0, max(0.0, (t - 2000000) / 60000.0))
        path.append((t, (x, by, bz), (by, x, -bz), rpy))
    peer = Peer(free_port(), path)
    omap = os.path.join(o.out, "ranges_time.occ")
    st = os.path.join(o.out, "ranges_time_stats.json")

    def send(mav, boot_us):
        if not 2200000 <= boot_us <= 2450000:
            return []
        return [mav.distance_sensor_encode((boot_us - 500000) // 1000, 20, 400, 150, 0, 0, 25, 0),
                mav.distance_sensor_encode(5, 20, 400, 100, 0, 1, 25, 0)]
    rc, err, _, _ = run_sensor(o.occmap, ["--mavlink-ranges", "--duration", "3", "-o", omap,
                                          "--stats", st], peer, send, period=0.05)
    c.that(rc == 0, "exit %s: %s" % (rc, err[-300:]))
    c.that(peer.sent_us and peer.sent_us[0] < 1500000, "poses started at %s us (want < 1.5 s)" %
           (peer.sent_us[:1],))
    fin = stats_lines(st)[-1].get("final", {}) if os.path.exists(st) else {}
    clock_ok(c, fin, peer)
    r = fin.get("ranges", {})
    c.that(r.get("integrated", 0) >= 8 and r.get("stamped", {}).get("own", 0) >= 4 and
           r.get("stamped", {}).get("arrival", 0) >= 4, "ranges %s" % r)

    def occupied(x, y, z):
        out = subprocess.run([o.occmap, "query", omap, "--sphere", "%f,%f,%f,0.08" % (x, y, z),
                              "--json"], capture_output=True, text=True)
        return (json.loads(out.stdout) if out.stdout.strip() else {}).get("occupied_voxels", 0)
    c.that(occupied(bx, by, bz - 1.5) > 0, "nothing 1.5 m under A (the pose at the stamp)")
    c.that(occupied(bx + 1.0, by, bz - 1.5) == 0, "a hit 1.5 m under B (the pose at arrival)")
    c.that(occupied(bx + 1.0, by, bz - 1.0) > 0, "sensor 1 (stamp on another clock): nothing "
           "1.0 m under B (the pose at arrival)")
    return c.done("own stamps %s (0.5 s old) integrated under the vehicle's place then (A), "
                  "stamps on another clock %s under its place at arrival (B)" %
                  (r.get("stamped", {}).get("own"), r.get("stamped", {}).get("arrival")))


def test_ranges_stale(o, frames, gt):
    """--mavlink-ranges and no camera: another component's DISTANCE_SENSOR for 1 s, then none
    while the poses go on: one STATUSTEXT (sensors stale) at least --sensor-timeout-ms after the
    last reading, no OBSTACLE_DISTANCE after it, HEARTBEAT ACTIVE before and CRITICAL after."""
    c = Check("ranges-stale")
    first = (gt[0][0], gt[0][1], gt[0][2], (0.0, 0.0, 0.3))
    peer = Peer(free_port(), [first], hold_last=True)
    st = os.path.join(o.out, "ranges_stale_stats.json")
    rc, err, _, last = run_sensor(o.occmap, ["--mavlink-ranges", "--sensor-timeout-ms", "400",
                                             "--duration", "3.3", "--stats", st], peer,
                                  down_150cm, send_for=1.0)
    c.that(rc == 0, "exit %s: %s" % (rc, err[-300:]))
    silence(c, peer, "sensors stale")
    warn = [s[0] for s in peer.statustexts if s[1] == 4]
    c.that(warn and last is not None and warn[0] - last >= 0.35,
           "STATUSTEXT %.3f s after the last reading (timeout 0.4 s)" %
           ((warn[0] - last) if warn and last else -1))
    fin = stats_lines(st)[-1].get("final", {}) if os.path.exists(st) else {}
    c.that(fin.get("status") == "stale" and fin.get("stale_input") == "mavlink_ranges",
           "final status %s, stale input %s" % (fin.get("status"), fin.get("stale_input")))
    return c.done("rangefinder only: %d OBSTACLE_DISTANCE while it reported, then one STATUSTEXT "
                  "%.2f s after its last reading and silence; HEARTBEAT 4 -> 5" %
                  (len(peer.obstacles), (warn[0] - last) if warn and last else -1))


def test_3d(o, frames, gt):
    """--3d: another component (1/158) reports two OBSTACLE_DISTANCE_3D points (BODY_FRD),
    forward-right 1.2 m above and behind-left 1.4 m below a level vehicle turned 0.3 rad
    (--mavlink-ranges integrates each as a beam): every OBSTACLE_DISTANCE is followed by our
    OBSTACLE_DISTANCE_3D id 0 (above) and id 1 (below), decoded by pymavlink, BODY_FRD, stamped
    with that OBSTACLE_DISTANCE's time; each point lies in the voxel of the point sent in
    (within a voxel diagonal, not farther than it), as the feed log says."""
    c = Check("3d")
    port = free_port()
    first = (gt[0][0], gt[0][1], gt[0][2], (0.0, 0.0, 0.3))
    peer = Peer(port, [first], hold_last=True)
    pts = {0: (1.0, 0.5, -1.2), 1: (-0.8, -0.6, 1.4)}  # FRD m: above, below
    got = []  # (time, msg) of OBSTACLE_DISTANCE and OBSTACLE_DISTANCE_3D in arrival order
    handle = peer.handle

    def grab(m):
        if m.get_type() in ("OBSTACLE_DISTANCE", "OBSTACLE_DISTANCE_3D"):
            got.append(m)
        handle(m)
    peer.handle = grab
    fl = os.path.join(o.out, "3d_feed.json")
    rc, err, _, _ = run_sensor(
        o.occmap, ["--mavlink-ranges", "--3d", "--duration", "2.5", "--feed-log", fl,
                   "--stats", os.path.join(o.out, "3d_stats.json")], peer,
        lambda mav, boot_us: [mav.obstacle_distance_3d_encode(boot_us // 1000, 0, 12, 65535, x, y,
                                                              z, 0.2, 10.0)
                              for x, y, z in pts.values()])
    c.that(rc == 0, "exit %s: %s" % (rc, err[-300:]))
    diag = 0.1 * math.sqrt(3.0) + 1e-4
    batches, od = [], None
    for m in got:
        if m.get_type() == "OBSTACLE_DISTANCE":
            od = m
            batches.append((m, []))
        elif batches:
            batches[-1][1].append(m)
    full = [(a, b) for a, b in batches if len(b) == 2]
    c.that(len(full) >= 5, "%d OBSTACLE_DISTANCE with both 3D points of %d" % (len(full), len(batches)))
    for a, b in full[-5:]:
        for m in b:
            want = pts.get(m.obstacle_id)
            c.that(m.frame == 12 and want is not None, "frame %d id %d" % (m.frame, m.obstacle_id))
            c.that(m.time_boot_ms == a.time_usec // 1000, "stamp %d vs %d" %
                   (m.time_boot_ms, a.time_usec // 1000))
            if want is None:
                continue
            d = math.dist((m.x, m.y, m.z), want)
            c.that(d <= diag and math.hypot(m.x, m.y, m.z) <= math.hypot(*want) + 1e-4,
                   "id %d at (%.3f %.3f %.3f), sent in (%.3f %.3f %.3f)" %
                   ((m.obstacle_id, m.x, m.y, m.z) + want))
            c.that(0.19 < m.min_distance < 0.21 and 19.9 < m.max_distance < 20.1,
                   "range %.2f..%.2f" % (m.min_distance, m.max_distance))
    lines = feed_log(fl) if os.path.exists(fl) else []
    last = lines[-1].get("obstacles_3d") if lines else None
    c.that(last is not None and [v[0] for v in last] == [0, 1], "feed log obstacles_3d %s" % last)
    if last is not None and full:
        c.that(all(math.dist(v[1:], pts[v[0]]) <= diag for v in last), "feed log %s" % last)
    return c.done("%d OBSTACLE_DISTANCE each with OBSTACLE_DISTANCE_3D above and below; last: %s"
                  % (len(full), ["(%.2f %.2f %.2f)" % (m.x, m.y, m.z) for m in full[-1][1]]
                     if full else None))


TESTS = {"3d": test_3d, "ranges": test_ranges, "ranges_stale": test_ranges_stale, "ranges_time": test_ranges_time, "requests": test_requests, "drop": test_drop, "stale": test_stale, "jitter": test_jitter, "save": test_save}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--occmap", required=True)
    ap.add_argument("--data", required=True)
    ap.add_argument("--test", default="all")
    ap.add_argument("--out", default="build/run")
    ap.add_argument("--tiny-arena", default="512K")
    o = ap.parse_args()
    if not os.path.exists(os.path.join(o.data, "depth.txt")):
        print("SKIP: %s absent" % o.data)
        return 77
    os.makedirs(o.out, exist_ok=True)
    frames, gt = read_tum(o.data)
    names = list(TESTS) if o.test == "all" else o.test.split(",")
    ok = all([TESTS[n](o, frames, gt) for n in names])
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
