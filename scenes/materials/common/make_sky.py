#!/usr/bin/env python3
"""Writes a small procedural sky as a Radiance .hdr (RGBE) latitude-longitude map.

Usage: make_sky.py OUTPUT.hdr [WIDTH]

The top row is straight up (+Y), u turns around +Y starting at -Z, as facet's envmap reads it.
The sky blends from a pale horizon to a deeper zenith blue, a warm sun disk (4 degrees in radius) sits 35 degrees
above the horizon, and the ground below the horizon is a dim grey-brown. Only the standard
library is used; the file is uncompressed (flat scanlines), which every RGBE reader accepts.
"""
import math
import struct
import sys


def rgbe(r, g, b):
    v = max(r, g, b)
    if v < 1e-32:
        return b"\x00\x00\x00\x00"
    m, e = math.frexp(v)
    scale = m * 256.0 / v
    return struct.pack("BBBB", int(r * scale), int(g * scale), int(b * scale), e + 128)


def sky(d):
    """Radiance along unit direction d = (x, y, z), y up."""
    x, y, z = d
    sun_elev, sun_az = math.radians(35.0), math.radians(130.0)
    sun = (math.sin(sun_az) * math.cos(sun_elev), math.sin(sun_elev), -math.cos(sun_az) * math.cos(sun_elev))
    cos_sun = x * sun[0] + y * sun[1] + z * sun[2]
    if cos_sun > math.cos(math.radians(4.0)):
        return (300.0, 260.0, 200.0)
    if y < 0.0:
        t = min(1.0, -y * 4.0)
        return (0.30 - 0.12 * t, 0.27 - 0.11 * t, 0.22 - 0.09 * t)
    t = y ** 0.5
    base = (0.95 * (1 - t) + 0.25 * t, 1.05 * (1 - t) + 0.45 * t, 1.20 * (1 - t) + 0.95 * t)
    glow = 0.6 * max(cos_sun, 0.0) ** 8
    return (base[0] + glow * 1.2, base[1] + glow * 1.0, base[2] + glow * 0.7)


def main():
    out = sys.argv[1]
    width = int(sys.argv[2]) if len(sys.argv) > 2 else 256
    height = width // 2
    rows = []
    for j in range(height):
        theta = (j + 0.5) / height * math.pi
        row = bytearray()
        for i in range(width):
            phi = (i + 0.5) / width * 2.0 * math.pi
            d = (math.sin(phi) * math.sin(theta), math.cos(theta), -math.cos(phi) * math.sin(theta))
            row += rgbe(*sky(d))
        rows.append(bytes(row))
    with open(out, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n")
        f.write(("-Y %d +X %d\n" % (height, width)).encode())
        for r in rows:
            f.write(r)


if __name__ == "__main__":
    main()
