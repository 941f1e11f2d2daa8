# SPDX-License-Identifier: BSD-3-Clause
"""view_png.py - is a screenshot of `occmap view` a drawing of a map? (tests/view_check.sh)

Decodes the PNG with the standard library only (8-bit RGB/RGBA, not interlaced: what Chromium
writes), then requires: enough saturated pixels (the cubes' height colours; the background
#1b1e23, the grey panel and its text are not), and the height colours all there - pixels whose
strongest channel is red, green and blue each make up a visible share (a page that drew
nothing but the box's thin lines, or every cube in one colour, fails).
usage: view_png.py SHOT.png  -> prints the shares, exit 0 (pass) or 1 (fail)
"""
import struct
import sys
import zlib

MIN_DRAWN = 0.05       # share of saturated pixels
MIN_PER_COLOUR = 0.003  # share of pixels per dominant channel (red, green, blue)


def paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    if pa <= pb and pa <= pc:
        return a
    return b if pb <= pc else c


def read_png(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG")
    pos, idat, hdr = 8, [], None
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            hdr = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        pos += 12 + n
    w, h, depth, ctype, _, _, interlace = hdr
    if depth != 8 or ctype not in (2, 6) or interlace != 0:
        raise ValueError("unsupported PNG: depth %d colour type %d interlace %d" % (depth, ctype, interlace))
    bpp = 3 if ctype == 2 else 4
    raw = zlib.decompress(b"".join(idat))
    stride = w * bpp
    rows, prev = [], bytearray(stride)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + ((a + b) >> 1)) & 255
            elif f == 4:
                line[i] = (line[i] + paeth(a, b, c)) & 255
        rows.append(line)
        prev = line
    return w, h, bpp, rows


def main():
    w, h, bpp, rows = read_png(sys.argv[1])
    drawn = 0
    dominant = [0, 0, 0]
    for line in rows:
        for x in range(0, w * bpp, bpp):
            px = (line[x], line[x + 1], line[x + 2])
            hi = max(px)
            if hi - min(px) >= 60:  # saturated: a height colour, not the grey panel or text
                drawn += 1
                dominant[px.index(hi)] += 1
    total = float(w * h)
    shares = [d / total for d in dominant]
    print("screenshot %dx%d: %.1f%% drawn; red %.2f%%, green %.2f%%, blue %.2f%% of pixels"
          % (w, h, 100 * drawn / total, 100 * shares[0], 100 * shares[1], 100 * shares[2]))
    ok = drawn / total >= MIN_DRAWN and min(shares) >= MIN_PER_COLOUR
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
