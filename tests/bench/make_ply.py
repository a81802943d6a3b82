#!/usr/bin/env python3
"""Writes a binary little-endian PLY grid mesh for the loading benchmark.

    make_ply.py out.ply [triangles]   (default 1,000,000 triangles)

A (n+1) x (n+1) vertex grid, bumped so that its normals vary, with per-vertex float positions,
normals and uv, and faces as a uchar count and int indices (the layout Blender and most
scanners write). Generated on demand: a million triangles is some 30 MB, too big to commit.
"""
import math
import sys

import numpy as np


def main():
    out = sys.argv[1]
    triangles = int(sys.argv[2]) if len(sys.argv) > 2 else 1_000_000
    n = max(1, int(math.ceil(math.sqrt(triangles / 2))))
    u, v = np.meshgrid(np.linspace(0, 1, n + 1, dtype=np.float32),
                       np.linspace(0, 1, n + 1, dtype=np.float32))
    u, v = u.ravel(), v.ravel()
    h = 0.05 * np.sin(12 * u) * np.cos(9 * v)
    dhdu = 0.05 * 12 * np.cos(12 * u) * np.cos(9 * v)
    dhdv = -0.05 * 9 * np.sin(12 * u) * np.sin(9 * v)
    nrm = np.stack([-dhdu, -dhdv, np.ones_like(u)], axis=1)
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    vert = np.empty(u.size, dtype=[('x', '<f4'), ('y', '<f4'), ('z', '<f4'), ('nx', '<f4'),
                                   ('ny', '<f4'), ('nz', '<f4'), ('u', '<f4'), ('v', '<f4')])
    vert['x'], vert['y'], vert['z'] = 2 * u - 1, 2 * v - 1, h
    vert['nx'], vert['ny'], vert['nz'] = nrm[:, 0], nrm[:, 1], nrm[:, 2]
    vert['u'], vert['v'] = u, v

    i, j = np.meshgrid(np.arange(n), np.arange(n))
    a = (j * (n + 1) + i).ravel()
    b, c, d = a + 1, a + n + 2, a + n + 1
    tri = np.stack([np.stack([a, b, c], 1), np.stack([a, c, d], 1)], 1).reshape(-1, 3)
    tri = tri[:triangles]
    face = np.empty(len(tri), dtype=[('n', 'u1'), ('i', '<i4', 3)])
    face['n'] = 3
    face['i'] = tri

    header = ("ply\nformat binary_little_endian 1.0\n"
              f"element vertex {len(vert)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              "property float nx\nproperty float ny\nproperty float nz\n"
              "property float u\nproperty float v\n"
              f"element face {len(face)}\n"
              "property list uchar int vertex_indices\nend_header\n")
    with open(out, 'wb') as f:
        f.write(header.encode('ascii'))
        f.write(vert.tobytes())
        f.write(face.tobytes())


if __name__ == '__main__':
    main()
