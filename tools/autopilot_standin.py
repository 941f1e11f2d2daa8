#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""autopilot_standin.py - plays ArduPilot on a UDP link for `occmap run` (make demo).

Listens like SITL's udpin and, as a companion port of ArduPilot does:
  - sends HEARTBEAT at 1 Hz (quadrotor, ArduPilot, ACTIVE) from sysid/compid 1/1 once a peer is known;
  - streams nothing until asked: COMMAND_LONG MAV_CMD_SET_MESSAGE_INTERVAL (511, param1 = message
    id, param2 = interval us; -1 stops) gets COMMAND_ACK ACCEPTED for LOCAL_POSITION_NED (32),
    ATTITUDE (30), ATTITUDE_QUATERNION (31) and ODOMETRY (331), FAILED for other ids; other
    commands get UNSUPPORTED;
  - answers TIMESYNC requests (tc1 == 0) with tc1 = its boot time in ns and ts1 echoed;
  - streams of equal interval share one tick (ArduPilot's deferred-message buckets), so
    LOCAL_POSITION_NED and ATTITUDE of one pose go out together;
  - streams the recording's poses at their timestamps: its boot clock starts at 0 when it starts,
    and a pose recorded at TUM time t is due at boot time (t - T_REF) (interface file, issue 21:
    T_REF = first depth.txt timestamp - 1 s). At each stream tick the newest due pose is sent once,
    stamped with its own time (so the rate is min(requested, recorded)).
  - records what it receives: OBSTACLE_DISTANCE, STATUSTEXT, HEARTBEAT (and a count of the rest).

Frames (interface file): the map is the motion-capture world frame read as ENU; the recording gives
world_from_camera (optical: x right, y down, z forward); the body (FLU) is the camera with the mount
(--depth-mount x,y,z,roll,pitch,yaw: body -> camera, default 0 = camera at the body origin looking
forward), so world_from_body = world_from_camera * camera_from_body. LOCAL_POSITION_NED =
(y, x, -z) of the body origin, ATTITUDE = roll, pitch, yaw of body FRD in NED.

usage (standalone): autopilot_standin.py --depth-dir DIR [--poses FILE] --listen 127.0.0.1:PORT
                    [--record FILE] [--duration S]
The demo (tools/demo_run.py) uses the Standin class in a thread.
"""
import argparse
import bisect
import json
import math
import os
import sys
import threading
import time

os.environ.setdefault("MAVLINK20", "1")
from pymavlink import mavutil  # noqa: E402

MSG_LPN, MSG_ATT, MSG_ATTQ, MSG_ODOM = 32, 30, 31, 331
STREAMABLE = (MSG_LPN, MSG_ATT, MSG_ATTQ, MSG_ODOM)
CMD_SET_MESSAGE_INTERVAL = 511
MAV_RESULT_ACCEPTED, MAV_RESULT_UNSUPPORTED, MAV_RESULT_FAILED = 0, 3, 4


# ---- rotations (3x3 lists, quaternions w x y z) -----------------------------------------------

def quat_to_mat(q):
    w, x, y, z = q
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]


def mat_to_quat(m):
    tr = m[0][0] + m[1][1] + m[2][2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        q = (0.25 * s, (m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s)
    elif m[0][0] > m[1][1] and m[0][0] > m[2][2]:
        s = math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]) * 2
        q = ((m[2][1] - m[1][2]) / s, 0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s)
    elif m[1][1] > m[2][2]:
        s = math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]) * 2
        q = ((m[0][2] - m[2][0]) / s, (m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s)
    else:
        s = math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]) * 2
        q = ((m[1][0] - m[0][1]) / s, (m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s)
    return q if q[0] >= 0 else tuple(-v for v in q)


def mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def tr(a):
    return [[a[j][i] for j in range(3)] for i in range(3)]


def apply(m, v):
    return [m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2] for i in range(3)]


def rpy_mat(roll, pitch, yaw):
    """R = Rz(yaw) Ry(pitch) Rx(roll), radians."""
    cr, sr, cp, sp, cy, sy = (math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch),
                              math.cos(yaw), math.sin(yaw))
    return [[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr]]


# body FLU <- camera optical with the default mount: camera x (right) = -y_b, y (down) = -z_b,
# z (forward) = x_b; columns are the camera axes in the body.
BODY_FROM_OPTICAL = [[0, 0, 1], [-1, 0, 0], [0, -1, 0]]
NED_FROM_ENU = [[0, 1, 0], [1, 0, 0], [0, 0, -1]]
FLU_FROM_FRD = [[1, 0, 0], [0, -1, 0], [0, 0, -1]]


def body_from_camera(mount):
    """Mount x,y,z (m), roll,pitch,yaw (deg) -> (R, t) of body_from_camera (optical)."""
    x, y, z, r, p, yw = mount
    R = mul(rpy_mat(math.radians(r), math.radians(p), math.radians(yw)), BODY_FROM_OPTICAL)
    return R, [x, y, z]


def to_mavlink(p_wc, q_wc, mount_rt):
    """World_from_camera (ENU, optical) -> (ned xyz, roll, pitch, yaw, q_ned_frd, ENU body pose)."""
    R_bc, t_bc = mount_rt
    R_wc = quat_to_mat(q_wc)
    R_wb = mul(R_wc, tr(R_bc))
    tb = apply(R_wb, t_bc)
    p_wb = [p_wc[i] - tb[i] for i in range(3)]
    R_nf = mul(mul(NED_FROM_ENU, R_wb), FLU_FROM_FRD)
    roll = math.atan2(R_nf[2][1], R_nf[2][2])
    pitch = -math.asin(max(-1.0, min(1.0, R_nf[2][0])))
    yaw = math.atan2(R_nf[1][0], R_nf[0][0])
    ned = (p_wb[1], p_wb[0], -p_wb[2])
    return ned, roll, pitch, yaw, mat_to_quat(R_nf), (p_wb, mat_to_quat(R_wb))


# ---- the recording ------------------------------------------------------------------------------

def read_recording(depth_dir, poses_path=None):
    """(frames [(t, png)], poses [(t, p, q wxyz)]) of a TUM directory: depth.txt + groundtruth.txt,
    or my_association.txt (rgb depth tx ty tz qx qy qz qw per frame, time = the depth file's name)."""
    frames, poses = [], []
    assoc = os.path.join(depth_dir, "my_association.txt")
    if os.path.exists(assoc):
        for line in open(assoc):
            f = line.split()
            if not f or line.startswith("#") or len(f) < 9:
                continue
            t = float(os.path.basename(f[1])[:-4])
            frames.append((t, f[1]))
            v = [float(x) for x in f[2:9]]
            poses.append((t, v[0:3], (v[6], v[3], v[4], v[5])))
    else:
        for line in open(os.path.join(depth_dir, "depth.txt")):
            f = line.split()
            if f and not line.startswith("#"):
                frames.append((float(f[0]), f[1]))
    if poses_path or not poses:
        poses = []
        for line in open(poses_path or os.path.join(depth_dir, "groundtruth.txt")):
            f = line.split()
            if f and not line.startswith("#"):
                v = [float(x) for x in f[1:8]]
                poses.append((float(f[0]), v[0:3], (v[6], v[3], v[4], v[5])))
    poses.sort(key=lambda p: p[0])
    return frames, poses


def t_ref_of(frames):
    """Interface clock rule: autopilot time 0 is 1 s before the first frame listed."""
    return frames[0][0] - 1.0


# ---- the autopilot ------------------------------------------------------------------------------

class Standin:
    def __init__(self, poses, t_ref, mount=(0, 0, 0, 0, 0, 0), listen="127.0.0.1:0", sysid=1, compid=1,
                 record=None):
        self.conn = mavutil.mavlink_connection("udpin:" + listen, source_system=sysid, source_component=compid,
                                               dialect="ardupilotmega")
        self.port = self.conn.port.getsockname()[1]
        self.sysid, self.compid = sysid, compid
        self.mount_rt = body_from_camera(mount)
        # Poses in autopilot time (us), only those at or after boot.
        self.poses = [(int(round((t - t_ref) * 1e6)), p, q) for (t, p, q) in poses if t - t_ref >= 0.0]
        self.pose_us = [p[0] for p in self.poses]
        self.record = open(record, "w") if record else None
        self.lock = threading.Lock()
        self.intervals = {}      # msg id -> interval us (requested)
        self.next_due = {}       # msg id -> boot us of the next tick
        self.last_sent = {}      # msg id -> index of the last pose sent
        self.obstacles, self.statustexts, self.heartbeats = [], [], []
        self.requests, self.timesyncs, self.other = [], 0, {}
        self.bad = 0
        self.sent = {MSG_LPN: 0, MSG_ATT: 0, MSG_ATTQ: 0, MSG_ODOM: 0}
        self.t0 = time.monotonic()
        self.stop = threading.Event()
        self.next_hb = 0

    def boot_us(self):
        return int((time.monotonic() - self.t0) * 1e6)

    def _log(self, obj):
        if self.record:
            self.record.write(json.dumps(obj) + "\n")

    def _answer_command(self, m):
        h = m.get_header()
        self.requests.append((self.boot_us(), int(m.command), m.param1, m.param2, h.srcSystem, h.srcComponent))
        result = MAV_RESULT_UNSUPPORTED
        if m.command == CMD_SET_MESSAGE_INTERVAL:
            mid, iv = int(m.param1), m.param2
            if mid in STREAMABLE:
                result = MAV_RESULT_ACCEPTED
                with self.lock:
                    if iv < 0:
                        self.intervals.pop(mid, None)
                    else:
                        self.intervals[mid] = int(iv) if iv > 0 else 100000  # 0: the default rate
                        # ArduPilot keeps messages of equal interval in one bucket, sent together:
                        # join the tick of a stream already running at this interval.
                        mate = [m for m, v in self.intervals.items() if m != mid and v == self.intervals[mid]]
                        self.next_due[mid] = self.next_due[mate[0]] if mate else self.boot_us()
            else:
                result = MAV_RESULT_FAILED
        self.conn.mav.command_ack_send(m.command, result, 0, 0, h.srcSystem, h.srcComponent)
        self._log({"rx_us": self.boot_us(), "command": int(m.command), "param1": m.param1, "param2": m.param2,
                   "result": result})

    def _send_pose(self, mid, k):
        t_us, p, q = self.poses[k]
        ned, roll, pitch, yaw, q_nf, _ = to_mavlink(p, q, self.mount_rt)
        j = max(0, k - 1)
        vel = (0.0, 0.0, 0.0)
        if j < k:
            ned0 = to_mavlink(self.poses[j][1], self.poses[j][2], self.mount_rt)[0]
            dt = (t_us - self.poses[j][0]) * 1e-6
            vel = tuple((ned[i] - ned0[i]) / dt for i in range(3)) if dt > 0 else vel
        ms = t_us // 1000
        if mid == MSG_LPN:
            self.conn.mav.local_position_ned_send(ms, ned[0], ned[1], ned[2], vel[0], vel[1], vel[2])
        elif mid == MSG_ATT:
            self.conn.mav.attitude_send(ms, roll, pitch, yaw, 0.0, 0.0, 0.0)
        elif mid == MSG_ATTQ:
            self.conn.mav.attitude_quaternion_send(ms, q_nf[0], q_nf[1], q_nf[2], q_nf[3], 0.0, 0.0, 0.0)
        elif mid == MSG_ODOM:
            nan = float("nan")
            self.conn.mav.odometry_send(t_us, 1, 12, ned[0], ned[1], ned[2], list(q_nf), nan, nan, nan,
                                        nan, nan, nan, [nan] * 21, [nan] * 21)
        self.sent[mid] += 1

    def _streams(self, now):
        k = bisect.bisect_right(self.pose_us, now) - 1
        with self.lock:
            due = [mid for mid, iv in self.intervals.items() if now >= self.next_due.get(mid, 0)]
            for mid in due:
                iv = self.intervals[mid]
                self.next_due[mid] = max(self.next_due.get(mid, 0) + iv, now - iv)
        for mid in due:
            if k >= 0 and self.last_sent.get(mid) != k:
                self.last_sent[mid] = k
                self._send_pose(mid, k)

    def _receive(self, m):
        typ = m.get_type()
        now = self.boot_us()
        h = m.get_header()
        if typ == "BAD_DATA":
            self.bad += 1
        elif typ == "OBSTACLE_DISTANCE":
            rec = {"rx_us": now, "time_usec": m.time_usec, "distances": list(m.distances), "increment": m.increment,
                   "increment_f": m.increment_f, "angle_offset": m.angle_offset, "min_cm": m.min_distance,
                   "max_cm": m.max_distance, "frame": m.frame, "sensor_type": m.sensor_type,
                   "src": [h.srcSystem, h.srcComponent]}
            self.obstacles.append(rec)
            self._log({"obstacle_distance": rec})
        elif typ == "STATUSTEXT":
            rec = {"rx_us": now, "severity": m.severity, "text": m.text, "src": [h.srcSystem, h.srcComponent]}
            self.statustexts.append(rec)
            self._log({"statustext": rec})
        elif typ == "HEARTBEAT":
            rec = {"rx_us": now, "type": m.type, "autopilot": m.autopilot, "system_status": m.system_status,
                   "src": [h.srcSystem, h.srcComponent]}
            self.heartbeats.append(rec)
            self._log({"heartbeat": rec})
        elif typ == "COMMAND_LONG":
            self._answer_command(m)
        elif typ == "TIMESYNC":
            if m.tc1 == 0:
                self.timesyncs += 1
                self.conn.mav.timesync_send(self.boot_us() * 1000, m.ts1)
        else:
            self.other[typ] = self.other.get(typ, 0) + 1

    def run(self, duration=None):
        end = None if duration is None else time.monotonic() + duration
        while not self.stop.is_set() and (end is None or time.monotonic() < end):
            now = self.boot_us()
            if self.conn.clients:
                if now >= self.next_hb:
                    self.conn.mav.heartbeat_send(2, 3, 0, 0, 4)  # quadrotor, ArduPilot, ACTIVE
                    self.next_hb = now + 1000000
                self._streams(now)
            m = self.conn.recv_msg()
            if m is None:
                time.sleep(0.001)
                continue
            self._receive(m)
        if self.record:
            self.record.flush()

    def start(self):
        th = threading.Thread(target=self.run, daemon=True)
        th.start()
        return th

    def summary(self):
        return {"obstacle_distance_rx": len(self.obstacles), "statustext_rx": len(self.statustexts),
                "heartbeat_rx": len(self.heartbeats), "timesync_answered": self.timesyncs,
                "commands_rx": len(self.requests), "poses_sent": {str(k): v for k, v in self.sent.items()},
                "bad_data": self.bad, "other_rx": self.other}


def selftest():
    """The frame rules on hand-worked poses; returns a list of failures."""
    bad = []
    near = lambda a, b: all(abs(x - y) < 1e-9 for x, y in zip(a, b))  # noqa: E731
    mrt = body_from_camera((0, 0, 0, 0, 0, 0))
    # Camera looking north (ENU +y), image x to the east, image y down: level, heading north.
    R_wc = [[1, 0, 0], [0, 0, 1], [0, -1, 0]]
    ned, roll, pitch, yaw, q_nf, (p, q) = to_mavlink([1.0, 2.0, 3.0], mat_to_quat(R_wc), mrt)
    if not near(ned, (2.0, 1.0, -3.0)) or not near((roll, pitch, yaw), (0.0, 0.0, 0.0)):
        bad.append("north-looking camera: ned %s rpy %s (want (2,1,-3), 0,0,0)" % (ned, (roll, pitch, yaw)))
    # The same camera looking east (ENU +x): yaw +90 deg (NED, clockwise from north).
    R_wc = [[0, 0, 1], [-1, 0, 0], [0, -1, 0]]
    _, roll, pitch, yaw, _, _ = to_mavlink([0, 0, 0], mat_to_quat(R_wc), mrt)
    if not near((roll, pitch, yaw), (0.0, 0.0, math.pi / 2)):
        bad.append("east-looking camera: rpy %s (want 0, 0, pi/2)" % ((roll, pitch, yaw),))
    # Looking north, tilted 30 deg down (pitch -30), rolled: body x = camera z, body up = -camera y.
    R_wc = mul(rpy_mat(0.0, 0.0, math.pi / 2), mul(rpy_mat(0.2, math.radians(30), 0.0), BODY_FROM_OPTICAL))
    _, roll, pitch, yaw, _, (p, q) = to_mavlink([0, 0, 0], mat_to_quat(R_wc), mrt)
    R_wb = quat_to_mat(q)
    if not near([R_wb[i][0] for i in range(3)], [R_wc[i][2] for i in range(3)]) or \
            not near([R_wb[i][2] for i in range(3)], [-R_wc[i][1] for i in range(3)]) or \
            not near((roll, pitch, yaw), (0.2, -math.radians(30), 0.0)):
        bad.append("tilted camera: rpy %s (want 0.2, -0.524, 0)" % ((roll, pitch, yaw),))
    # A mount 0.1 m forward: the body origin is 0.1 m behind the camera.
    ned, _, _, _, _, _ = to_mavlink([0, 0, 0], mat_to_quat([[1, 0, 0], [0, 0, 1], [0, -1, 0]]),
                                    body_from_camera((0.1, 0, 0, 0, 0, 0)))
    if not near(ned, (-0.1, 0.0, 0.0)):
        bad.append("mount 0.1 m forward: ned %s (want -0.1, 0, 0)" % (ned,))
    return bad


def main():
    if "--selftest" in sys.argv:
        bad = selftest()
        for b in bad:
            print("FAIL standin frames: " + b)
        print("%s standin frames" % ("FAIL" if bad else "PASS"))
        return 1 if bad else 0
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--depth-dir", required=True)
    ap.add_argument("--poses", help="groundtruth.txt (default: the directory's)")
    ap.add_argument("--listen", default="127.0.0.1:14550")
    ap.add_argument("--depth-mount", default="0,0,0,0,0,0")
    ap.add_argument("--record")
    ap.add_argument("--duration", type=float, default=60.0)
    a = ap.parse_args()
    frames, poses = read_recording(a.depth_dir, a.poses)
    s = Standin(poses, t_ref_of(frames), tuple(float(v) for v in a.depth_mount.split(",")), a.listen,
                record=a.record)
    print("standin: listening on 127.0.0.1:%d, %d poses, T_REF %.6f" % (s.port, len(s.poses), t_ref_of(frames)),
          flush=True)
    s.run(a.duration)
    print(json.dumps(s.summary()))


if __name__ == "__main__":
    sys.exit(main())
