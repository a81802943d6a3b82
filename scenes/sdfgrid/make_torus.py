#!/usr/bin/env python3
"""Writes torus.vol: the signed distance of a torus (major radius 0.7, minor radius 0.28, around
the y axis) sampled on a 44 x 14 x 44 grid over [-1.1, 1.1] x [-0.33, 0.33] x [-1.1, 1.1], in
Mitsuba's .vol format (little-endian: 'VOL', version 3, encoding 1 = float32, xres, yres, zres,
1 channel, the bounding box as 6 float32, then the values with x fastest). scene.xml maps the
grid's unit cube back onto that box with its to_world.

Run from this folder: python3 make_torus.py
"""
import math
import struct

R, r = 0.7, 0.28
lo = (-1.1, -0.33, -1.1)
hi = (1.1, 0.33, 1.1)
res = (44, 14, 44)


def sdf(x, y, z):
    q = math.hypot(x, z) - R
    return math.hypot(q, y) - r


values = []
for k in range(res[2]):
    for j in range(res[1]):
        for i in range(res[0]):
            p = [lo[a] + (hi[a] - lo[a]) * (n / (res[a] - 1)) for a, n in enumerate((i, j, k))]
            values.append(sdf(*p))

with open("torus.vol", "wb") as f:
    f.write(b"VOL" + bytes([3]))
    f.write(struct.pack("<iiiii", 1, res[0], res[1], res[2], 1))
    f.write(struct.pack("<6f", *lo, *hi))
    f.write(struct.pack("<%df" % len(values), *values))
