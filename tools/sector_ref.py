#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""sector_ref.py - an independent reference for occmap's sector distances (pure Python, double).

A map slice is a 2D grid of voxel columns over the vertical band [z - below, z + above): a column
is OCC if any voxel of it in the band is occupied, UNK if any is unknown (never observed), FREE
otherwise. For each sector (body angles clockwise from forward), the distance is the smallest
distance from the vehicle to the part of a column's square footprint inside the sector's wedge,
found by clipping the square against the wedge's two half-planes (Sutherland-Hodgman). The
reported value follows occ_sectors.h: obstacle -> clamp(floor(cm)), unknown nearer -> 65535 (or its
distance), nothing within max -> max_distance + 1 (MAVLink's "no obstacle").
ground_band() applies occ_sectors.h's ground rule to the band; ardupilot_faces() is ArduPilot's
documented OBSTACLE_DISTANCE handler (8 faces of 45 degrees) applied to a decoded message.
"""
import math

OCC, UNK = 1, 2


class Slice:
    """Columns of a .bt map (octomap_bt.read_bt output) over the band [za, zb), ENU metres."""

    def __init__(self, res, depth, leaves, za, zb, margin_m=6.0):
        self.res = res
        half = 1 << (depth - 1)
        self.half = half
        kz0 = math.floor(za / res) + half
        kz1 = math.ceil(zb / res) - 1 + half
        nz = kz1 - kz0 + 1
        band = [l for l in leaves if l[2] <= kz1 and l[2] + l[3] - 1 >= kz0]
        m = int(math.ceil(margin_m / res))
        self.kx0 = min(l[0] for l in band) - m
        self.ky0 = min(l[1] for l in band) - m
        self.w = max(l[0] + l[3] for l in band) + m - self.kx0
        self.h = max(l[1] + l[3] for l in band) + m - self.ky0
        occ = bytearray(self.w * self.h)
        seen = [0] * (self.w * self.h)
        for (kx, ky, kz, s, o) in band:
            c = min(kz + s - 1, kz1) - max(kz, kz0) + 1
            x0 = kx - self.kx0
            for y in range(ky - self.ky0, ky - self.ky0 + s):
                row = y * self.w
                for i in range(row + x0, row + x0 + s):
                    seen[i] += c
                    if o:
                        occ[i] = 1
        st = bytearray(self.w * self.h)
        for i in range(self.w * self.h):
            st[i] = (OCC if occ[i] else 0) | (UNK if seen[i] < nz else 0)
        self.state = st

    def cell_xy(self, ix, iy):
        """Lower-left corner (metres) of grid cell (ix, iy)."""
        return ((ix + self.kx0 - self.half) * self.res, (iy + self.ky0 - self.half) * self.res)

    def at(self, x, y):
        ix = math.floor(x / self.res) + self.half - self.kx0
        iy = math.floor(y / self.res) + self.half - self.ky0
        if 0 <= ix < self.w and 0 <= iy < self.h:
            return self.state[iy * self.w + ix]
        return UNK


def _clip(poly, dx, dy, sign):
    out = []
    n = len(poly)
    for i in range(n):
        ax, ay = poly[i]
        bx, by = poly[(i + 1) % n]
        fa = sign * (dx * ay - dy * ax)
        fb = sign * (dx * by - dy * bx)
        if fa >= 0.0:
            out.append((ax, ay))
        if (fa >= 0.0) != (fb >= 0.0):
            t = fa / (fa - fb)
            out.append((ax + t * (bx - ax), ay + t * (by - ay)))
    return out


def _seg_dist(a, b):
    vx, vy = b[0] - a[0], b[1] - a[1]
    l2 = vx * vx + vy * vy
    t = -(a[0] * vx + a[1] * vy) / l2 if l2 > 0 else 0.0
    t = min(1.0, max(0.0, t))
    return math.hypot(a[0] + t * vx, a[1] + t * vy)


def wedge_dist(x0, y0, x1, y1, lo, inc):
    """Distance from the origin to square [x0,x1]x[y0,y1] within map angles [lo, lo+inc]."""
    p = _clip([(x0, y0), (x1, y0), (x1, y1), (x0, y1)], math.cos(lo), math.sin(lo), 1.0)
    if not p:
        return None
    p = _clip(p, math.cos(lo + inc), math.sin(lo + inc), -1.0)
    if not p:
        return None
    if x0 <= 0.0 <= x1 and y0 <= 0.0 <= y1:
        return 0.0
    return min(_seg_dist(p[i], p[(i + 1) % len(p)]) for i in range(len(p)))


def sectors(sl, x, y, yaw, n=72, inc_deg=5.0, off_deg=0.0, min_cm=20, max_cm=2000,
            unknown_as_distance=False):
    """Reference distances (cm) for a vehicle at ENU (x, y), map yaw (rad, CCW from east)."""
    inc = math.radians(inc_deg)
    off = math.radians(off_deg)
    R = max_cm / 100.0
    d_occ = [math.inf] * n
    d_unk = [math.inf] * n
    res = sl.res
    ix0 = max(0, math.floor((x - R) / res) + sl.half - sl.kx0 - 1)
    ix1 = min(sl.w - 1, math.floor((x + R) / res) + sl.half - sl.kx0 + 1)
    iy0 = max(0, math.floor((y - R) / res) + sl.half - sl.ky0 - 1)
    iy1 = min(sl.h - 1, math.floor((y + R) / res) + sl.half - sl.ky0 + 1)
    cells = []
    for iy in range(iy0, iy1 + 1):
        row = iy * sl.w
        for ix in range(ix0, ix1 + 1):
            s = sl.state[row + ix]
            if s:
                cx, cy = sl.cell_xy(ix, iy)
                ax0, ay0 = cx - x, cy - y
                qx = min(max(0.0, ax0), ax0 + res)
                qy = min(max(0.0, ay0), ay0 + res)
                dn = math.hypot(qx, qy)
                if dn < R:
                    cells.append((dn, ax0, ay0, s))
    cells.sort()
    two_pi = 2.0 * math.pi
    for dn, ax0, ay0, s in cells:
        ax1, ay1 = ax0 + res, ay0 + res
        if dn <= 0.0:
            cand = range(n)
        else:
            # Body-angle span from the 4 corners, relative to the centre direction.
            bc = math.atan2(ay0 + res / 2, ax0 + res / 2)
            rel = []
            for (px, py) in ((ax0, ay0), (ax1, ay0), (ax0, ay1), (ax1, ay1)):
                d = math.atan2(py, px) - bc
                d = (d + math.pi) % two_pi - math.pi
                rel.append(d)
            lo_b, hi_b = bc + min(rel), bc + max(rel)
            # body angle = yaw - bearing; sector u = (body - off)/inc + 0.5
            u_lo = ((yaw - hi_b - off) / inc + 0.5) % (two_pi / inc)
            width = (hi_b - lo_b) / inc
            cand = set()
            k = math.floor(u_lo) - 1
            P = round(two_pi / inc)
            while k <= math.floor(u_lo + width) + 1:
                kk = k % P
                if kk < n:
                    cand.add(kk)
                k += 1
        for k in cand:
            best = min(d_occ[k], d_unk[k])
            if dn > best:
                continue
            lo = yaw - (off + k * inc) - inc / 2.0
            d = wedge_dist(ax0, ay0, ax1, ay1, lo, inc)
            if d is None:
                continue
            if s & OCC and d < d_occ[k]:
                d_occ[k] = d
            if s & UNK and d < d_unk[k]:
                d_unk[k] = d
    out = []
    for k in range(n):
        if d_occ[k] <= d_unk[k] and d_occ[k] < R:
            out.append(_cm(d_occ[k], min_cm, max_cm))
        elif d_unk[k] < R:
            out.append(_cm(d_unk[k], min_cm, max_cm) if unknown_as_distance else 65535)
        else:
            out.append(max_cm + 1)
    return out, d_occ, d_unk


def _cm(d, lo, hi):
    cm = math.floor(d * 100.0)
    return lo if cm <= lo else (hi if cm >= hi else int(cm))


def agree(got, want, d_occ, d_unk, max_cm):
    """Sector indices where `got` (from the wire) and the reference disagree beyond 1 cm, allowing
    the kind to flip only on a near tie of occupied and unknown or at the search radius."""
    bad = []
    R = max_cm / 100.0
    for k, (g, w) in enumerate(zip(got, want)):
        if abs(g - w) <= 1:
            continue
        if g == 65535 or w == 65535:
            if abs(d_occ[k] - d_unk[k]) < 0.01 or abs(d_unk[k] - R) < 0.01 or abs(d_occ[k] - R) < 0.01:
                continue
        bad.append(k)
    return bad


def ground_band(res, depth, leaves, x, y, z, below, above, clearance=0.1):
    """occ_sectors.h's ground rule for an ENU vehicle at (x, y, z): the band [za, zb), its lower edge
    lifted to clearance above the first occupied voxel down the vehicle's own column."""
    half = 1 << (depth - 1)
    za, zb = z - below, z + above
    kx, ky = math.floor(x / res) + half, math.floor(y / res) + half
    col = {}
    for (lx, ly, lz, s, o) in leaves:
        if lx <= kx < lx + s and ly <= ky < ly + s:
            for k in range(lz, lz + s):
                col[k] = o
    kz = math.floor(z / res) + half
    while kz >= 0:
        top = (kz - half + 1) * res
        if not top > za:
            break
        if col.get(kz) == 1:
            lifted = top + clearance
            return (lifted, zb) if za < lifted < zb else (za, zb)
        kz -= 1
    return za, zb


def face_m(d, min_cm, max_cm):
    """What a face of nearest obstacle d metres must read: d as sent (floor cm, clamped), m."""
    return _cm(d, min_cm, max_cm) / 100.0


def ardupilot_faces(m):
    """Faces (metres, None = no obstacle) ArduPilot's AP_Proximity_MAV makes of one decoded
    OBSTACLE_DISTANCE: reset 8 faces of 45 deg centred on 0, 45, ...; walk elements in order,
    skip 0, 65535, < min, > max; keep the nearest per face; store a face each time a valid
    element's face differs from the previous valid one's."""
    faces = [None] * 8
    inc = m.increment_f if m.increment_f > 0 else m.increment
    prev, best = None, None
    for i, d in enumerate(m.distances):
        if d == 0 or d == 65535 or d < m.min_distance or d > m.max_distance:
            continue
        face = int(((i * inc + m.angle_offset) % 360.0 + 22.5) % 360.0 // 45.0) % 8
        if prev is not None and face != prev:
            faces[prev] = best
            prev = None
        dm = d * 0.01
        if prev is None or dm < best:
            best = dm
        prev = face
    if prev is not None:
        faces[prev] = best
    return faces
