#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""mav_demo.py --occmap BIN --map MAP.bt --out DIR   (make demo)

A replayed flight through a real map. pymavlink plays the autopilot (listening like SITL's
udpin); `occmap feed` loads the map, sends HEARTBEAT and OBSTACLE_DISTANCE to us, and we send it
the vehicle's pose (LOCAL_POSITION_NED + ATTITUDE at 20 Hz) along a path planned through the free
space of the corridor (0.6 m above the map origin, ~0.9 m above the floor). Each pose is held until two OBSTACLE_DISTANCE messages came
back, so every message can be checked against an independent computation of the sector
distances from the .bt file (octomap_bt.py + sector_ref.py). Prints one line per second, a final
table, and writes a PNG top view to DIR/demo_mavlink.png. Exit 0 when every check passes."""
import argparse
import collections
import concurrent.futures
import json
import math
import os
import struct
import subprocess
import sys
import time
import zlib

os.environ["MAVLINK20"] = "1"
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from pymavlink import mavutil  # noqa: E402
from octomap_bt import read_bt  # noqa: E402
import sector_ref  # noqa: E402
from sector_ref import OCC, UNK  # noqa: E402

Z_UP = 0.6
BAND = 0.15
MIN_CM, MAX_CM = 20, 600
OFFSET = -20.0  # the feed's default angle_offset: ArduPilot's faces are contiguous runs
STEP_M = 0.4
CLEARANCE_M = 0.15
AP_TYPE, AP_AUTOPILOT = 2, 3  # the HEARTBEAT of an ArduPilot quad: the feed takes its poses

_BT = None
_SLICES = {}


def _init_worker(path):
    global _BT
    _BT = read_bt(path)
    res, depth, leaves = _BT
    _SLICES[(Z_UP - BAND, Z_UP + BAND)] = sector_ref.Slice(res, depth, leaves, Z_UP - BAND, Z_UP + BAND)


def _ref(args):
    """72 x 5 deg reference and the 8 x 45 deg faces' nearest obstacles for one pose, in the band
    the feed uses there (its ground rule lifts the band over ground under the vehicle)."""
    x, y, yaw = args
    res, depth, leaves = _BT
    band = sector_ref.ground_band(res, depth, leaves, x, y, Z_UP, BAND, BAND)
    if band not in _SLICES:
        _SLICES[band] = sector_ref.Slice(res, depth, leaves, band[0], band[1])
    sl = _SLICES[band]
    want, d_occ, d_unk = sector_ref.sectors(sl, x, y, yaw, off_deg=OFFSET, min_cm=MIN_CM, max_cm=MAX_CM)
    _, d_occ8, d_unk8 = sector_ref.sectors(sl, x, y, yaw, n=8, inc_deg=45.0, off_deg=0.0,
                                           min_cm=MIN_CM, max_cm=MAX_CM)
    return want, d_occ, d_unk, d_occ8, d_unk8


# ---- planning ------------------------------------------------------------------------------

def clearance(sl):
    """Metres from each cell to the nearest non-free cell (8-neighbour BFS, chamfer-ish)."""
    w, h = sl.w, sl.h
    INF = 1 << 30
    dist = [INF] * (w * h)
    q = collections.deque()
    for i, s in enumerate(sl.state):
        if s:
            dist[i] = 0
            q.append(i)
    while q:
        i = q.popleft()
        d = dist[i] + 1
        x, y = i % w, i // w
        for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (1, -1), (-1, 1), (-1, -1)):
            nx, ny = x + dx, y + dy
            if 0 <= nx < w and 0 <= ny < h:
                j = ny * w + nx
                if dist[j] > d:
                    dist[j] = d
                    q.append(j)
    return [d * sl.res for d in dist]


def plan(sl, clear, start, goal):
    w, h = sl.w, sl.h
    ok = [c >= CLEARANCE_M for c in clear]

    def cell(p):
        return (math.floor(p[0] / sl.res) + sl.half - sl.kx0, math.floor(p[1] / sl.res) + sl.half - sl.ky0)

    def nearest_ok(p):
        cx, cy = cell(p)
        best = None
        for r in range(0, 40):
            for y in range(cy - r, cy + r + 1):
                for x in range(cx - r, cx + r + 1):
                    if 0 <= x < w and 0 <= y < h and ok[y * w + x]:
                        d = (x - cx) ** 2 + (y - cy) ** 2
                        if best is None or d < best[0]:
                            best = (d, y * w + x)
            if best:
                return best[1]
        raise SystemExit("demo: no free cell near %s" % (p,))

    s, g = nearest_ok(start), nearest_ok(goal)
    # Dijkstra, a step costs its length times (1 + 0.5 m / clearance): stay mid-corridor.
    import heapq
    prev = {s: -1}
    best = {s: 0.0}
    heap = [(0.0, s)]
    while heap:
        c, i = heapq.heappop(heap)
        if i == g:
            break
        if c > best[i]:
            continue
        x, y = i % w, i // w
        for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (1, -1), (-1, 1), (-1, -1)):
            nx, ny = x + dx, y + dy
            j = ny * w + nx
            if 0 <= nx < w and 0 <= ny < h and ok[j]:
                nc = c + math.hypot(dx, dy) * (1.0 + 0.5 / clear[j])
                if nc < best.get(j, math.inf):
                    best[j] = nc
                    prev[j] = i
                    heapq.heappush(heap, (nc, j))
    if g not in prev:
        raise SystemExit("demo: no path through free space from %s to %s" % (start, goal))
    cells = []
    i = g
    while i != -1:
        cells.append(i)
        i = prev[i]
    cells.reverse()
    pts = []
    for i in cells:
        x0, y0 = sl.cell_xy(i % w, i // w)
        pts.append((x0 + sl.res / 2, y0 + sl.res / 2))
    # Smooth (moving average, keeping the ends), then resample every STEP_M.
    k = 6
    sm = []
    for i in range(len(pts)):
        a, b = max(0, i - k), min(len(pts), i + k + 1)
        sm.append((sum(p[0] for p in pts[a:b]) / (b - a), sum(p[1] for p in pts[a:b]) / (b - a)))
    out = [sm[0]]
    acc = 0.0
    for p, q2 in zip(sm, sm[1:]):
        seg = math.dist(p, q2)
        while acc + seg >= STEP_M:
            t = (STEP_M - acc) / seg
            p = (p[0] + t * (q2[0] - p[0]), p[1] + t * (q2[1] - p[1]))
            seg = math.dist(p, q2)
            acc = 0.0
            out.append(p)
        acc += seg
    return out


# ---- PNG (no matplotlib) ------------------------------------------------------------------------

def write_png(path, w, h, rgb):
    raw = bytearray()
    for y in range(h):
        raw.append(0)
        raw += rgb[y * w * 3:(y + 1) * w * 3]

    def chunk(t, d):
        c = struct.pack(">I", len(d)) + t + d
        return c + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


def render(sl, path_pts, shots, out_path):
    S = 3  # pixels per cell
    occ_cells = [i for i, s in enumerate(sl.state) if s != UNK]
    xs = [i % sl.w for i in occ_cells]
    ys = [i // sl.w for i in occ_cells]
    cx0, cx1, cy0, cy1 = min(xs) - 4, max(xs) + 5, min(ys) - 4, max(ys) + 5
    W, H = (cx1 - cx0) * S, (cy1 - cy0) * S
    img = bytearray(W * H * 3)
    col = {0: (255, 255, 255), OCC: (20, 20, 20), UNK: (190, 190, 190), OCC | UNK: (20, 20, 20)}
    for cy in range(cy0, cy1):
        for cx in range(cx0, cx1):
            c = col[sl.state[cy * sl.w + cx]]
            for py in range(S):
                yy = H - 1 - ((cy - cy0) * S + py)
                base = (yy * W + (cx - cx0) * S) * 3
                img[base:base + 3 * S] = bytes(c) * S

    def px(x, y):
        fx = (x / sl.res + sl.half - sl.kx0 - cx0) * S
        fy = (y / sl.res + sl.half - sl.ky0 - cy0) * S
        return int(fx), H - 1 - int(fy)

    def dot(x, y, c, r=1):
        for dy in range(-r, r + 1):
            for dx in range(-r, r + 1):
                if 0 <= x + dx < W and 0 <= y + dy < H:
                    i = ((y + dy) * W + x + dx) * 3
                    img[i:i + 3] = bytes(c)

    def line(a, b, c, r=0):
        n = max(abs(b[0] - a[0]), abs(b[1] - a[1]), 1)
        for k in range(n + 1):
            dot(a[0] + (b[0] - a[0]) * k // n, a[1] + (b[1] - a[1]) * k // n, c, r)

    for (x, y, yaw, dist) in shots:
        for k, d in enumerate(dist):
            body = math.radians(OFFSET + 5.0 * k)
            ang = yaw - body
            if d == 65535:
                L, c = 0.5, (230, 140, 0)
            elif d > MAX_CM:
                L, c = MAX_CM / 100.0, (120, 200, 120)
            else:
                L, c = d / 100.0, (220, 30, 30)
            line(px(x, y), px(x + L * math.cos(ang), y + L * math.sin(ang)), c)
    for a, b in zip(path_pts, path_pts[1:]):
        line(px(*a), px(*b), (30, 60, 230), 1)
    for (x, y, yaw, _) in shots:
        p = px(x, y)
        dot(p[0], p[1], (30, 60, 230), 3)
        line(p, px(x + 0.6 * math.cos(yaw), y + 0.6 * math.sin(yaw)), (30, 60, 230), 1)
    write_png(out_path, W, H, img)
    return W, H


# ---- the flight -------------------------------------------------------------------------------

def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--occmap", required=True)
    ap.add_argument("--map", required=True)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    t_start = time.monotonic()
    pool = concurrent.futures.ProcessPoolExecutor(max_workers=max(1, min(4, os.cpu_count() or 1)),
                                                  initializer=_init_worker, initargs=(args.map,))
    res, depth, leaves = read_bt(args.map)
    sl = sector_ref.Slice(res, depth, leaves, Z_UP - BAND, Z_UP + BAND)
    clear = clearance(sl)
    path = plan(sl, clear, (-5.0, -0.2), (27.0, -0.2))
    length = STEP_M * (len(path) - 1)
    print("demo: %s res %.2f m, slice z %.1f..%.1f m, path %d poses over %.1f m (clearance >= %.2f m)"
          % (os.path.basename(args.map), res, Z_UP - BAND, Z_UP + BAND, len(path), length, CLEARANCE_M))
    poses = []
    for i, (x, y) in enumerate(path):
        a = path[max(0, i - 1)]
        b = path[min(len(path) - 1, i + 1)]
        heading = math.atan2(b[1] - a[1], b[0] - a[0])
        yaw = heading + math.radians(35.0) * math.sin(i * 0.25)  # look around while flying
        poses.append((x, y, math.atan2(math.sin(yaw), math.cos(yaw))))

    # The reference distances are computed in the worker processes while we fly.
    refs_iter = pool.map(_ref, poses, chunksize=4)
    conn = mavutil.mavlink_connection("udpin:127.0.0.1:0", source_system=1, source_component=1,
                                      dialect="ardupilotmega")
    port = conn.port.getsockname()[1]
    proc = subprocess.Popen([args.occmap, "feed", "--map", args.map, "--udp", "127.0.0.1:%d" % port,
                             "--max-m", str(MAX_CM / 100.0), "--min-m", str(MIN_CM / 100.0),
                             "--band-m", str(BAND), "--rate-hz", "10", "--duration-s", "600"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    counts = collections.Counter()
    bad_data = 0
    heartbeats = []
    got = []  # (pose index, msg)
    errors = []

    def poll():
        nonlocal bad_data
        m = conn.recv_msg()
        if m is None:
            return None
        t = m.get_type()
        counts[t] += 1
        if t == "BAD_DATA":
            bad_data += 1
        elif t == "HEARTBEAT":
            heartbeats.append(time.monotonic())
        return m

    t_hb = time.monotonic() + 20
    while not heartbeats and time.monotonic() < t_hb and proc.poll() is None:
        if poll() is None:
            time.sleep(0.005)
    if not heartbeats:
        pool.shutdown()
        raise SystemExit("demo: FAIL no HEARTBEAT from occmap feed: %s" % (proc.stderr.read() if proc.poll() is not None else ""))
    t0 = time.monotonic()
    next_line = t0 + 1.0
    next_send = t0
    next_hb = t0
    for k, (x, y, yaw) in enumerate(poses):
        north, east, down, yaw_ned = y, x, -Z_UP, math.pi / 2 - yaw
        n_here = 0
        deadline = time.monotonic() + 2.0
        while n_here < 2:
            now = time.monotonic()
            if now > deadline:
                errors.append("pose %d: no OBSTACLE_DISTANCE within 2 s" % k)
                break
            if now >= next_hb:
                conn.mav.heartbeat_send(AP_TYPE, AP_AUTOPILOT, 0, 0, 4)
                next_hb = now + 1.0
            if now >= next_send:
                ms = int((now - t0) * 1000)
                conn.mav.local_position_ned_send(ms, north, east, down, 0, 0, 0)
                conn.mav.attitude_send(ms, 0.0, 0.0, yaw_ned, 0, 0, 0)
                next_send = max(next_send + 0.05, now)
            m = poll()
            if m is None:
                time.sleep(0.002)
            elif m.get_type() == "OBSTACLE_DISTANCE":
                got.append((k, n_here, m))
                n_here += 1
            if now >= next_line:
                next_line += 1.0
                last = got[-1][2] if got else None
                if last is not None:
                    d = list(last.distances)
                    ob = [(v, i) for i, v in enumerate(d) if v < MAX_CM]
                    near = ("nearest %4d cm at %3d deg" % (min(ob)[0], (OFFSET + min(ob)[1] * 5) % 360)
                            if ob else "nothing within %d cm" % MAX_CM)
                else:
                    near = "-"
                print("t=%4.1fs pose %3d/%d at (%6.2f, %5.2f) yaw %6.1f deg | OBSTACLE_DISTANCE %4d HEARTBEAT %3d | %s"
                      % (now - t0, k + 1, len(poses), x, y, math.degrees(yaw), counts["OBSTACLE_DISTANCE"],
                         len(heartbeats), near), flush=True)
    t_flight = time.monotonic() - t0
    proc.terminate()
    out, err = proc.communicate(timeout=20)
    try:
        stats = json.loads(out.strip().splitlines()[-1])
    except (ValueError, IndexError):
        stats = {}
        errors.append("no statistics from occmap feed: %s" % err)

    # Independent check of every message: the second one per pose against that pose, the first
    # one against that pose or the previous one (it may have been computed before the new pose
    # arrived).
    refs = list(refs_iter)
    pool.shutdown()
    checked = mismatched = faces_checked = 0
    classes = collections.Counter()
    R = MAX_CM / 100.0

    def faces_ok(m, ref):
        """ArduPilot's face rule on the message: a face whose nearest point is an obstacle holds
        it (1 cm), a free face reads no obstacle."""
        faces = sector_ref.ardupilot_faces(m)
        _, _, _, d_occ8, d_unk8 = ref
        for f in range(8):
            if d_occ8[f] <= d_unk8[f] and d_occ8[f] < R:
                if faces[f] is None or abs(faces[f] - sector_ref.face_m(d_occ8[f], MIN_CM, MAX_CM)) > 0.011:
                    return False
            elif d_occ8[f] >= R and d_unk8[f] >= R and faces[f] is not None:
                return False
        return True

    for k, j, m in got:
        d = list(m.distances)
        h = m.get_header()
        if (h.srcSystem, h.srcComponent, m.frame, m.min_distance, m.max_distance) != (1, 196, 12, MIN_CM, MAX_CM) \
                or abs(m.increment_f - 5.0) > 0 or m.angle_offset != OFFSET or 0 in d or MAX_CM in d:
            errors.append("pose %d: bad fields %s" % (k, m))
        cands = [k] if j > 0 or k == 0 else [k, k - 1]
        ok = False
        for c in cands:
            want, d_occ, d_unk = refs[c][:3]
            if not sector_ref.agree(d, want, d_occ, d_unk, MAX_CM) and faces_ok(m, refs[c]):
                ok = True
                break
        checked += 1
        faces_checked += 8
        if not ok:
            mismatched += 1
            want, d_occ, d_unk = refs[k][:3]
            badk = sector_ref.agree(d, want, d_occ, d_unk, MAX_CM)
            errors.append("pose %d message %d: sectors %s got %s want %s, faces %s want %s" % (
                k, j, badk[:4], [d[i] for i in badk[:4]], [want[i] for i in badk[:4]],
                sector_ref.ardupilot_faces(m), [round(v, 3) for v in refs[k][3]]))
        for v in d:
            classes["unknown" if v == 65535 else ("free" if v > MAX_CM else "obstacle")] += 1
    shots_idx = [int(i * (len(poses) - 1) / 7) for i in range(8)]
    last_msg = {}
    for k, j, m in got:
        last_msg[k] = list(m.distances)
    shots = [(poses[i][0], poses[i][1], poses[i][2], last_msg[i]) for i in shots_idx if i in last_msg]
    png = os.path.join(args.out, "demo_mavlink.png")
    W, H = render(sl, path, shots, png)
    n_ob = counts["OBSTACLE_DISTANCE"]
    nearest = min((min(m.distances), k) for k, _, m in got) if got else (0, 0)
    if bad_data:
        errors.append("pymavlink saw %d bad frames" % bad_data)
    if len(heartbeats) < max(1, int(t_flight) - 1):
        errors.append("only %d heartbeats in %.1f s" % (len(heartbeats), t_flight))
    total = sum(classes.values()) or 1
    print()
    print("=== make demo: occmap feed -> pymavlink, %s ===" % os.path.basename(args.map))
    rows = [
        ("path", "%d poses, %.1f m at z = %.1f m, flown in %.1f s" % (len(poses), length, Z_UP, t_flight)),
        ("OBSTACLE_DISTANCE received", "%d (%.1f Hz)" % (n_ob, n_ob / t_flight)),
        ("HEARTBEAT received", "%d (%.2f Hz)" % (len(heartbeats), len(heartbeats) / max(t_flight, 1e-9))),
        ("messages checked vs .bt", "%d (%d sectors, %d ArduPilot faces), %d disagree" % (
            checked, checked * 72, faces_checked, mismatched)),
        ("sector values", "obstacle %.1f%%  free (max + 1) %.1f%%  unknown %.1f%%" % (
            100.0 * classes["obstacle"] / total, 100.0 * classes["free"] / total, 100.0 * classes["unknown"] / total)),
        ("closest obstacle", "%d cm (pose %d)" % nearest),
        ("bad frames seen by pymavlink", "%d" % bad_data),
        ("feed: sent / stale skips", "%s OBSTACLE_DISTANCE, %s HEARTBEAT / %s" % (
            stats.get("obstacle_tx"), stats.get("heartbeat_tx"), stats.get("stale_skips"))),
        ("feed: poses received", "%s positions, %s attitudes, %s bad CRC" % (
            stats.get("positions_rx"), stats.get("attitudes_rx"), stats.get("bad_crc"))),
        ("feed: sector update", "mean %s us, max %s us (72 sectors, R = %.1f m)" % (
            stats.get("update_us_mean"), stats.get("update_us_max"), MAX_CM / 100.0)),
        ("picture", "%s (%dx%d)" % (png, W, H)),
        ("wall time", "%.1f s" % (time.monotonic() - t_start)),
    ]
    for a, b in rows:
        print("  %-30s %s" % (a, b))
    for e in errors[:20]:
        print("FAIL", e)
    print("demo: %s" % ("PASS" if not errors else "FAIL (%d problems)" % len(errors)))
    return 0 if not errors else 1


if __name__ == "__main__":
    sys.exit(main())
