#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""demo_pictures.py - the loop demo's pictures (PNG written by hand, no plotting library).

loop_map.png: one panel per chosen moment (left to right, top to bottom): the OctoMap reference
  map's slice in the sector band at that moment (black occupied, white free, grey unknown), the
  vehicle's path so far (blue), the vehicle and its heading, and the 72 sectors as `occmap run`
  sent them: red ray to an obstacle, short orange stub = unknown, green ray to the search radius =
  observed free.
loop_strip.png: every OBSTACLE_DISTANCE over time, one column per message (time to the right),
  one row band per sector (sector 0 at the top): obstacle red (near) to yellow (far), unknown grey,
  free green; under it a row per sector, black where the message disagreed with the reference.
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mav_demo import write_png  # noqa: E402

OCC, UNK = 1, 2


def read_slice(path):
    with open(path) as f:
        head = f.readline().split()
        ref = [int(v) for v in f.readline().split()]
        rows = [ln.rstrip("\n") for ln in f]
    seq, x0, y0, res, n = int(head[0]), float(head[1]), float(head[2]), float(head[3]), int(head[4])
    return {"seq": seq, "x0": x0, "y0": y0, "res": res, "n": n, "ref": ref,
            "state": [[int(c) for c in r] for r in rows]}


class Canvas:
    def __init__(self, w, h, bg=(255, 255, 255)):
        self.w, self.h = w, h
        self.px = bytearray(bytes(bg) * (w * h))

    def dot(self, x, y, c, r=0):
        for dy in range(-r, r + 1):
            for dx in range(-r, r + 1):
                if 0 <= x + dx < self.w and 0 <= y + dy < self.h:
                    i = ((y + dy) * self.w + x + dx) * 3
                    self.px[i:i + 3] = bytes(c)

    def line(self, a, b, c, r=0):
        n = max(abs(b[0] - a[0]), abs(b[1] - a[1]), 1)
        for k in range(n + 1):
            self.dot(a[0] + (b[0] - a[0]) * k // n, a[1] + (b[1] - a[1]) * k // n, c, r)

    def rect(self, x0, y0, w, h, c):
        for y in range(max(0, y0), min(self.h, y0 + h)):
            i = (y * self.w + max(0, x0)) * 3
            n = min(self.w, x0 + w) - max(0, x0)
            if n > 0:
                self.px[i:i + 3 * n] = bytes(c) * n

    def save(self, path):
        write_png(path, self.w, self.h, self.px)


def sector_color(d, max_cm):
    if d == 65535:
        return (150, 150, 150)
    if d > max_cm:
        return (110, 200, 110)
    f = min(1.0, d / 600.0)
    return (220, int(30 + 200 * f), 30)


def crop_box(slices, poses, margin_m=1.0):
    """Metres box around every observed cell of the slices and the path."""
    xs, ys = [p[0] for p in poses], [p[1] for p in poses]
    for s in slices:
        for iy, row in enumerate(s["state"]):
            for ix, c in enumerate(row):
                if c != UNK:
                    xs.append(s["x0"] + ix * s["res"])
                    ys.append(s["y0"] + iy * s["res"])
    return min(xs) - margin_m, min(ys) - margin_m, max(xs) + margin_m, max(ys) + margin_m


def map_panels(path, slices, msgs, offset_deg, max_cm, panel_px=260, cols=3):
    """slices: read_slice() dicts; msgs: seq -> feed-log dict."""
    poses = [m["pose"] for m in sorted(msgs.values(), key=lambda m: m["seq"])]
    bx0, by0, bx1, by1 = crop_box(slices, poses)
    scale = panel_px / max(bx1 - bx0, by1 - by0)
    rows = (len(slices) + cols - 1) // cols
    gap = 6
    cv = Canvas(cols * (panel_px + gap) + gap, rows * (panel_px + gap) + gap, (60, 60, 60))
    for n, s in enumerate(slices):
        ox, oy = gap + (n % cols) * (panel_px + gap), gap + (n // cols) * (panel_px + gap)
        cv.rect(ox, oy, panel_px, panel_px, (190, 190, 190))

        def px(x, y, ox=ox, oy=oy):
            return ox + int((x - bx0) * scale), oy + panel_px - 1 - int((y - by0) * scale)

        cell = max(1, int(math.ceil(s["res"] * scale)))
        for iy, row in enumerate(s["state"]):
            for ix, c in enumerate(row):
                if c == UNK:
                    continue
                x, y = s["x0"] + ix * s["res"], s["y0"] + (iy + 1) * s["res"]
                a = px(x, y)
                if ox <= a[0] < ox + panel_px and oy <= a[1] < oy + panel_px:
                    w = min(cell, ox + panel_px - a[0])
                    h = min(cell, oy + panel_px - a[1])
                    cv.rect(a[0], a[1], w, h, (20, 20, 20) if c & OCC else (255, 255, 255))
        m = msgs[s["seq"]]
        x, y = m["pose"][0], m["pose"][1]
        w_, qx, qy, qz = m["pose"][3:7]
        yaw = math.atan2(2 * (w_ * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))

        def clip(p, ox=ox, oy=oy):
            return (min(max(p[0], ox), ox + panel_px - 1), min(max(p[1], oy), oy + panel_px - 1))
        for k, d in enumerate(m["distances"]):
            ang = yaw - math.radians(offset_deg + 5.0 * k)
            L = 0.25 if d == 65535 else (max_cm / 100.0 if d > max_cm else d / 100.0)
            c = (230, 140, 0) if d == 65535 else ((110, 200, 110) if d > max_cm else (220, 30, 30))
            cv.line(clip(px(x, y)), clip(px(x + L * math.cos(ang), y + L * math.sin(ang))), c)
        trail = [p for p in poses[:[mm["seq"] for mm in sorted(msgs.values(), key=lambda mm: mm["seq"])].index(s["seq"]) + 1]]
        for a, b in zip(trail, trail[1:]):
            cv.line(clip(px(a[0], a[1])), clip(px(b[0], b[1])), (30, 60, 230), 1)
        p = clip(px(x, y))
        cv.dot(p[0], p[1], (30, 60, 230), 3)
        cv.line(p, clip(px(x + 0.5 * math.cos(yaw), y + 0.5 * math.sin(yaw))), (30, 60, 230), 1)
    cv.save(path)
    return cv.w, cv.h


def strip(path, msgs, agree_rows, max_cm, col_px=2, row_px=3):
    """msgs: feed-log dicts in order; agree_rows: per message a list of 0/1 per sector (or None)."""
    n = len(msgs[0]["distances"]) if msgs else 72
    w = max(1, len(msgs)) * col_px
    h = n * row_px * 2 + 4
    cv = Canvas(w, h, (60, 60, 60))
    for j, m in enumerate(msgs):
        for k, d in enumerate(m["distances"]):
            cv.rect(j * col_px, k * row_px, col_px, row_px, sector_color(d, max_cm))
            a = agree_rows[j][k] if agree_rows and agree_rows[j] is not None else 1
            cv.rect(j * col_px, n * row_px + 4 + k * row_px, col_px, row_px,
                    (255, 255, 255) if a else (0, 0, 0))
    cv.save(path)
    return w, h
