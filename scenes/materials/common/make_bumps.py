#!/usr/bin/env python3
"""Writes the tiling textures of the bump- and normal-mapped gallery materials as 8-bit PNGs.

Usage: make_bumps.py HEIGHT.png NORMALS.png [SIZE]

The surface is a hammered sheet: a grid of 4 x 4 shallow round dimples (each a spherical cap)
with a small sine ripple on top. HEIGHT.png holds the height in [0, 1] (grey, for `bumpmap`),
NORMALS.png the tangent-space normal of the same surface, encoded as (n + 1) / 2 (for
`normalmap`, with the relief exaggerated as a height scale of 0.04 per unit of uv would give).
Both tile seamlessly. Only the standard library is used (zlib for the PNG data).
"""
import math
import struct
import sys
import zlib


def height(u, v):
    """Height in [0, 1] at (u, v) in [0, 1)^2: dimples at the cells of a 4 x 4 grid."""
    cells = 4
    cu, cv = (u * cells) % 1.0 - 0.5, (v * cells) % 1.0 - 0.5
    r2 = (cu * cu + cv * cv) / 0.2
    dimple = -math.sqrt(max(0.0, 1.0 - r2)) if r2 < 1.0 else 0.0
    ripple = 0.08 * math.sin(2.0 * math.pi * 8.0 * (u + 0.5 * v))
    return min(1.0, max(0.0, 0.85 + 0.7 * dimple * 0.9 + ripple))


def write_png(path, width, height_px, channels, rows):
    """rows: list of bytes objects, one per scanline (channels bytes per pixel)."""
    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)
    colour_type = {1: 0, 3: 2}[channels]
    header = struct.pack(">IIBBBBB", width, height_px, 8, colour_type, 0, 0, 0)
    raw = b"".join(b"\x00" + row for row in rows)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", header))
        f.write(chunk(b"IDAT", zlib.compress(raw, 9)))
        f.write(chunk(b"IEND", b""))


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    size = int(sys.argv[3]) if len(sys.argv) == 4 else 128
    depth = 0.04  # scene units of height per unit of the texture's value, for the normals
    h = [[height((x + 0.5) / size, (y + 0.5) / size) for x in range(size)] for y in range(size)]
    grey, normals = [], []
    for y in range(size):
        grey.append(bytes(int(round(255 * h[y][x])) for x in range(size)))
        row = bytearray()
        for x in range(size):
            # Central differences with wrap-around: dh/du, dh/dv per unit of uv.
            dhdu = (h[y][(x + 1) % size] - h[y][(x - 1) % size]) * size / 2.0
            dhdv = (h[(y + 1) % size][x] - h[(y - 1) % size][x]) * size / 2.0
            n = (-depth * dhdu, -depth * dhdv, 1.0)
            length = math.sqrt(sum(c * c for c in n))
            row += bytes(int(round(255 * (0.5 * c / length + 0.5))) for c in n)
        normals.append(bytes(row))
    write_png(sys.argv[1], size, size, 1, grey)
    write_png(sys.argv[2], size, size, 3, normals)


if __name__ == "__main__":
    main()
