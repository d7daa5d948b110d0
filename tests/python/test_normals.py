"""The add-on's vertex normals in a fixed order (blender_addon/dwivedi_bake/normals.py), without
Blender: Blender 3.x's own vertex normals change in their last bits from one evaluation to the
next (threads add into them in any order), so the export replaces a smooth face's corner normals
by these. Checked here:
- a cube's corners: the angle-weighted normal of three faces at right angles is (+-1, +-1, +-1) /
  sqrt(3) (to 1e-7); a vertex no face reaches takes its normalised position;
- a UV sphere (quads and pole triangles, loops out of polygon order): every vertex normal within
  0.05 of the radial direction (0.031 at 12 x 6), and the numpy and standard-library paths agree to 1e-6;
- settle_corner_normals on a fake Blender 3.4 mesh whose corner normals carry a different 1-ulp
  jitter each time (what Blender's threads leave): the smooth corners come out the same bits
  every time, the flat face's corners keep their face normal, a 4.1 mesh and an Auto Smooth mesh
  are left as they are.

Standard library (numpy where this Python has it). Run by ctest (tests/CMakeLists.txt).
"""
import array
import math
import os
import random
import struct
import sys
import unittest
from pathlib import Path

SOURCE_DIR = Path(os.environ.get("DWIVEDI_SOURCE_DIR", Path(__file__).resolve().parents[2]))
sys.path.append(str(SOURCE_DIR / "blender_addon" / "dwivedi_bake"))

import normals  # noqa: E402


def cube():
    """A unit cube's 8 corners and 6 quads, counter-clockwise seen from outside, plus a ninth
    vertex no face uses."""
    points = [(x, y, z) for z in (-1.0, 1.0) for y in (-1.0, 1.0) for x in (-1.0, 1.0)] + [(0.0, 3.0, 4.0)]
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    return points, quads


def uv_sphere(segments=12, rings=6):
    """Unit UV sphere: pole triangles and quads, outward."""
    points = [(0.0, 0.0, 1.0)]
    for r in range(1, rings):
        theta = math.pi * r / rings
        points += [(math.sin(theta) * math.cos(2 * math.pi * s / segments),
                    math.sin(theta) * math.sin(2 * math.pi * s / segments), math.cos(theta)) for s in range(segments)]
    points.append((0.0, 0.0, -1.0))
    bottom = len(points) - 1

    def ring(r, s):
        return 1 + (r - 1) * segments + s % segments

    faces = [(0, ring(1, s), ring(1, s + 1)) for s in range(segments)]
    for r in range(1, rings - 1):
        faces += [(ring(r, s), ring(r + 1, s), ring(r + 1, s + 1), ring(r, s + 1)) for s in range(segments)]
    faces += [(bottom, ring(rings - 1, s + 1), ring(rings - 1, s)) for s in range(segments)]
    return points, faces


def polygon_arrays(faces, reverse=False):
    """Blender's loops.vertex_index, polygons.loop_start and loop_total; reverse: the polygons'
    loops stored back to front in the loop array (loop_start not in polygon order)."""
    loops, starts, totals = [], [0] * len(faces), [len(f) for f in faces]
    order = range(len(faces) - 1, -1, -1) if reverse else range(len(faces))
    for p in order:
        starts[p] = len(loops)
        loops += list(faces[p])
    return loops, starts, totals


def flat(points):
    return [c for p in points for c in p]


def without_numpy(function, *args):
    saved, normals.numpy = normals.numpy, None
    try:
        return function(*args)
    finally:
        normals.numpy = saved


class Collection:
    """A bpy collection of `count` items whose foreach_get fills attributes from lists."""

    def __init__(self, count, **attributes):
        self.count, self.attributes = count, attributes

    def __len__(self):
        return self.count

    def foreach_get(self, name, out):
        values = self.attributes[name]
        for i, v in enumerate(values):
            out[i] = v


class FakeMesh:
    """What settle_corner_normals reads of a Blender mesh: vertices, loops, polygons and loop
    triangles (each quad split into two triangles, as calc_loop_triangles does)."""

    def __init__(self, points, faces, auto_smooth=False):
        loops, starts, totals = polygon_arrays(faces, reverse=True)
        self.vertices = Collection(len(points), co=flat(points))
        self.loops = Collection(len(loops), vertex_index=loops)
        self.smooth = [1] * len(faces)
        self.polygons = Collection(len(faces), loop_start=starts, loop_total=totals, use_smooth=self.smooth)
        self.corner_vertices, polygon = [], []
        for p, face in enumerate(faces):
            for k in range(1, len(face) - 1):
                self.corner_vertices += [face[0], face[k], face[k + 1]]
                polygon.append(p)
        self.loop_triangles = Collection(len(polygon), polygon_index=polygon)
        self.use_auto_smooth = auto_smooth
        self.has_custom_normals = False


def jittered(values, rng):
    """Each float32 moved by -1, 0 or +1 unit in the last place."""
    out = array.array("f", values)
    bits = array.array("i", out.tobytes())
    for i in range(len(bits)):
        bits[i] += rng.choice((-1, 0, 1))
    return array.array("f", bits.tobytes())


class VertexNormalsTest(unittest.TestCase):
    def paths(self, *args):
        found = [("standard library", without_numpy(normals.vertex_normals, *args))]
        if normals.numpy is not None:
            found.append(("numpy", normals.vertex_normals(*args)))
        return found

    def test_cube_corners(self):
        points, quads = cube()
        for name, n in self.paths(flat(points), *polygon_arrays(quads)):
            for v, p in enumerate(points[:8]):
                for i in range(3):
                    self.assertAlmostEqual(n[3 * v + i], p[i] / math.sqrt(3.0), delta=1e-7, msg=name)
            lone = (0.0, 0.6, 0.8)
            self.assertEqual([round(x, 6) for x in n[24:27]], list(lone), name)

    def test_sphere_radial_and_paths_agree(self):
        points, faces = uv_sphere()
        found = self.paths(flat(points), *polygon_arrays(faces, reverse=True))
        for name, n in found:
            worst = max(abs(n[3 * v + i] - p[i]) for v, p in enumerate(points) for i in range(3))
            self.assertLess(worst, 0.05, name)
        if len(found) == 2:
            worst = max(abs(a - b) for a, b in zip(found[0][1], found[1][1]))
            self.assertLess(worst, 1e-6, "numpy and standard-library paths")


class SettleCornerNormalsTest(unittest.TestCase):
    def setUp(self):
        points, faces = uv_sphere()
        self.mesh = FakeMesh(points, faces)
        self.smooth = self.mesh.smooth
        self.smooth[3] = 0  # a flat pole triangle keeps its face normal
        self.blender = array.array("f", [c for v in self.mesh.corner_vertices for c in points[v]])
        self.rng = random.Random(5)

    def settle(self, given, version=(3, 4, 1)):
        out = array.array("f", given)
        normals.settle_corner_normals(self.mesh, self.mesh.corner_vertices, out, version)
        return out

    def test_the_same_bits_whatever_the_jitter(self):
        results = [self.settle(jittered(self.blender, self.rng)) for _ in range(4)]
        inputs_differ = len({bytes(jittered(self.blender, self.rng)) for _ in range(4)}) > 1
        self.assertTrue(inputs_differ)
        polygon = self.mesh.loop_triangles.attributes["polygon_index"]
        smooth_corners = [c for c in range(len(self.mesh.corner_vertices)) if self.smooth[polygon[c // 3]]]
        for r in results[1:]:
            for c in smooth_corners:
                self.assertEqual(bytes(r[3 * c:3 * c + 3]), bytes(results[0][3 * c:3 * c + 3]), f"corner {c}")
        for c in range(len(self.mesh.corner_vertices)):
            worst = max(abs(results[0][3 * c + i] - self.blender[3 * c + i]) for i in range(3))
            self.assertLess(worst, 0.05)

    def test_flat_face_keeps_its_normal(self):
        given = jittered(self.blender, self.rng)
        out = self.settle(given)
        self.assertEqual(bytes(out[9 * 3:9 * 3 + 9]), bytes(given[9 * 3:9 * 3 + 9]))
        self.assertNotEqual(bytes(out[:9]), bytes(given[:9]))

    def test_left_alone_from_4_1_and_with_auto_smooth(self):
        given = jittered(self.blender, self.rng)
        self.assertEqual(bytes(self.settle(given, (4, 1, 0))), bytes(given))
        self.mesh.use_auto_smooth = True
        self.assertEqual(bytes(self.settle(given)), bytes(given))


if __name__ == "__main__":
    unittest.main()
