#!/usr/bin/env python3
"""Writes the meshes of scenes/cornell-box as Wavefront OBJ files.

The room spans x in [-1, 1], y in [0, 2] (y is up) and z in [-1, 1]; it is open towards +z, where
the camera stands. Every face is wound counter-clockwise seen from the side its normal points to,
so all normals face into the room (the light's faces down). Run it from anywhere:

    python3 scenes/cornell-box/make_cornell_box.py

It only uses the Python standard library; its output (meshes/*.obj) is committed.
"""

import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "meshes")


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def quad(corners, normal):
    """Two triangles for a planar quad given in order around its edge, wound to face `normal`."""
    a, b, c, d = corners
    if dot(cross(sub(b, a), sub(c, a)), normal) < 0:
        a, b, c, d = d, c, b, a
    assert dot(cross(sub(b, a), sub(c, a)), normal) > 0, "degenerate quad"
    return [(a, b, c), (a, c, d)]


def box(center_x, center_z, size_x, size_z, height, angle_deg):
    """The six faces of a box standing on the floor, turned by angle_deg about the vertical."""
    t = math.radians(angle_deg)
    cos_t, sin_t = math.cos(t), math.sin(t)

    def place(x, y, z):
        return (center_x + cos_t * x + sin_t * z, y, center_z - sin_t * x + cos_t * z)

    def turn(v):
        return (cos_t * v[0] + sin_t * v[2], v[1], -sin_t * v[0] + cos_t * v[2])

    hx, hz = size_x / 2, size_z / 2
    faces = []
    # (corners in local coordinates, outward normal in local coordinates)
    sides = [
        ([(-hx, height, -hz), (hx, height, -hz), (hx, height, hz), (-hx, height, hz)], (0, 1, 0)),
        ([(-hx, 0, -hz), (hx, 0, -hz), (hx, 0, hz), (-hx, 0, hz)], (0, -1, 0)),
        ([(hx, 0, -hz), (hx, height, -hz), (hx, height, hz), (hx, 0, hz)], (1, 0, 0)),
        ([(-hx, 0, -hz), (-hx, height, -hz), (-hx, height, hz), (-hx, 0, hz)], (-1, 0, 0)),
        ([(-hx, 0, hz), (hx, 0, hz), (hx, height, hz), (-hx, height, hz)], (0, 0, 1)),
        ([(-hx, 0, -hz), (hx, 0, -hz), (hx, height, -hz), (-hx, height, -hz)], (0, 0, -1)),
    ]
    for corners, normal in sides:
        faces += quad([place(*p) for p in corners], turn(normal))
    return faces


def write_obj(name, triangles, comment):
    """Vertices are shared only between triangles of the same plane: a renderer that smooths
    normals over shared vertices (facet and Mitsuba do when a file has none) then still sees
    flat faces, and the boxes keep their sharp edges."""
    vertices, indices, faces = [], {}, []
    for tri in triangles:
        n = cross(sub(tri[1], tri[0]), sub(tri[2], tri[0]))
        length = math.sqrt(dot(n, n))
        plane = tuple(round(x / length, 4) for x in n)
        face = []
        for v in tri:
            position = tuple(round(x, 6) for x in v)
            key = (position, plane)
            if key not in indices:
                indices[key] = len(vertices) + 1
                vertices.append(position)
            face.append(indices[key])
        faces.append(face)
    path = os.path.join(OUT, name + ".obj")
    with open(path, "w", newline="\n") as f:
        f.write(f"# facet Cornell box: {comment}\n")
        f.write("# Written by make_cornell_box.py\n")
        for v in vertices:
            f.write("v {:.6f} {:.6f} {:.6f}\n".format(*v))
        for face in faces:
            f.write("f {} {} {}\n".format(*face))


def main():
    os.makedirs(OUT, exist_ok=True)
    write_obj("floor", quad([(-1, 0, -1), (1, 0, -1), (1, 0, 1), (-1, 0, 1)], (0, 1, 0)),
              "floor, y = 0")
    write_obj("ceiling", quad([(-1, 2, -1), (1, 2, -1), (1, 2, 1), (-1, 2, 1)], (0, -1, 0)),
              "ceiling, y = 2")
    write_obj("back", quad([(-1, 0, -1), (1, 0, -1), (1, 2, -1), (-1, 2, -1)], (0, 0, 1)),
              "back wall, z = -1")
    write_obj("left", quad([(-1, 0, -1), (-1, 2, -1), (-1, 2, 1), (-1, 0, 1)], (1, 0, 0)),
              "left (red) wall, x = -1")
    write_obj("right", quad([(1, 0, -1), (1, 2, -1), (1, 2, 1), (1, 0, 1)], (-1, 0, 0)),
              "right (green) wall, x = 1")
    write_obj("tall_box", box(-0.34, -0.3, 0.58, 0.58, 1.2, 18.0), "tall box")
    write_obj("short_box", box(0.34, 0.32, 0.58, 0.58, 0.6, -17.0), "short box")
    # The light hangs just below the ceiling so that it never coincides with it.
    y = 1.995
    write_obj("light", quad([(-0.24, y, -0.19), (0.24, y, -0.19), (0.24, y, 0.19), (-0.24, y, 0.19)],
                            (0, -1, 0)), "area light, facing down")


if __name__ == "__main__":
    main()
