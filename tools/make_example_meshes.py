#!/usr/bin/env python3
"""Writes the small mesh files of examples/scenes/ (standard library only; run it again after an
edit: the files are committed, so the examples need no script to run).

  slab.obj    a 10 x 10 cm slab, 4 mm thick, flat-shaded (no normals), no UVs
  sphere.ply  a 3 cm radius icosphere (3 subdivisions), ASCII PLY with smooth normals
  tile.obj    an 8 x 8 x 1.5 cm tile, flat-shaded, with per-corner UVs (each face its own cell)
"""
import math
import os
import sys


def write_box_obj(path, half, uvs, comment):
    """An axis-aligned box; with uvs, each face gets its own cell of a 3 x 2 UV layout."""
    hx, hy, hz = half
    corners = [(x, y, z) for x in (-hx, hx) for y in (-hy, hy) for z in (-hz, hz)]
    index = {c: i + 1 for i, c in enumerate(corners)}
    faces = []  # (axis, sign): four corners wound counter-clockwise seen from outside
    for axis in range(3):
        for sign in (1, -1):
            b, c = (axis + 1) % 3, (axis + 2) % 3
            if sign < 0:
                b, c = c, b
            quad = []
            for (i, j) in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = [0.0, 0.0, 0.0]
                p[axis] = sign * half[axis]
                p[b] = i * half[b]
                p[c] = j * half[c]
                quad.append((tuple(p), ((i + 1) // 2, (j + 1) // 2)))
            faces.append(quad)
    with open(path, "w", newline="\n") as f:
        f.write("# %s\n# written by tools/make_example_meshes.py\n" % comment)
        for c in corners:
            f.write("v %.6g %.6g %.6g\n" % c)
        if uvs:
            for k in range(6):
                u0, v0 = (k % 3) / 3.0 + 0.02, (k // 3) / 2.0 + 0.02
                du, dv = 1.0 / 3.0 - 0.04, 0.5 - 0.04
                for (cu, cv) in ((0, 0), (1, 0), (1, 1), (0, 1)):
                    f.write("vt %.6g %.6g\n" % (u0 + du * cu, v0 + dv * cv))
        for k, quad in enumerate(faces):
            if uvs:
                f.write("f " + " ".join("%d/%d" % (index[p], 4 * k + n + 1) for n, (p, _) in enumerate(quad)) + "\n")
            else:
                f.write("f " + " ".join("%d" % index[p] for p, _ in quad) + "\n")


def icosphere(subdivisions):
    t = (1.0 + math.sqrt(5.0)) / 2.0
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
             (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    verts = [tuple(x / math.sqrt(1 + t * t) for x in v) for v in verts]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
             (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        cache = {}

        def middle(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                m = [(verts[a][k] + verts[b][k]) / 2 for k in range(3)]
                n = math.sqrt(sum(x * x for x in m))
                verts.append(tuple(x / n for x in m))
                cache[key] = len(verts) - 1
            return cache[key]

        new = []
        for a, b, c in faces:
            ab, bc, ca = middle(a, b), middle(b, c), middle(c, a)
            new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = new
    return verts, faces


def write_sphere_ply(path, radius, subdivisions):
    verts, faces = icosphere(subdivisions)
    with open(path, "w", newline="\n") as f:
        f.write("ply\nformat ascii 1.0\ncomment a %g m icosphere, written by tools/make_example_meshes.py\n" % radius)
        f.write("element vertex %d\nproperty float x\nproperty float y\nproperty float z\n" % len(verts))
        f.write("property float nx\nproperty float ny\nproperty float nz\n")
        f.write("element face %d\nproperty list uchar int vertex_indices\nend_header\n" % len(faces))
        for v in verts:
            f.write("%.6f %.6f %.6f %.5f %.5f %.5f\n" % (radius * v[0], radius * v[1], radius * v[2], v[0], v[1], v[2]))
        for a, b, c in faces:
            f.write("3 %d %d %d\n" % (a, b, c))


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    out = os.path.join(here, "..", "examples", "scenes")
    if len(sys.argv) > 1:
        out = sys.argv[1]
    write_box_obj(os.path.join(out, "slab.obj"), (0.05, 0.002, 0.05), False, "a 10 x 10 cm slab, 4 mm thick (y)")
    write_sphere_ply(os.path.join(out, "sphere.ply"), 0.03, 3)
    write_box_obj(os.path.join(out, "tile.obj"), (0.04, 0.04, 0.0075), True, "an 8 x 8 x 1.5 cm tile with UVs")


if __name__ == "__main__":
    main()
