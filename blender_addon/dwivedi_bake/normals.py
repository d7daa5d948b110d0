"""Vertex normals computed in a fixed order, so that one mesh always exports the same bits.

Blender before 4.1 accumulates each face's angle-weighted normal into its vertices' normals from
several threads at once with atomic float additions (mesh_calc_normals_poly_and_vertex), so the
order of the additions, and the last bits of a vertex normal where many faces meet (a UV
sphere's poles), change from one evaluation to the next whenever the threads are scheduled
differently: measured in Blender 3.4.1 on a 48 x 24 UV sphere, 240 to 459 of its 3456 corner
normal components changed between two evaluations while two other processes kept the cores busy
(none on an idle machine, none in 4.3 and 5.2). The bake then differs in the last bits of the
pixels that see those corners, from one bake to the next and between the add-on's bake and a
farm chunk of the same scene (blender.test_farm's intermittent 1-ulp difference).

The same normals are computed here from the positions, in one pass in loop order and in double
precision, by Blender's definition: a face's normal by Newell's method (its vector area,
normalised; +z where it vanishes), weighted at each corner by the corner's angle between its two
edges (Thurmer and Wuthrich 1998, "Computing vertex normals from polygonal facets"), summed per
vertex and normalised; a vertex whose sum vanishes takes its normalised position, as Blender's
does. They agree with Blender's within 3e-6 on a 48 x 24 UV sphere (Blender sums in float, and
its Newell sums lose that much on the poles' thin triangles; tests/blender/test_export_normals.py
bounds it by 1e-5) and are the same bits every time (tests/python/test_normals.py).

numpy where Blender has it (whole-array operations; np.bincount adds in index order), the standard
library otherwise, with the same result up to rounding and each path deterministic.
"""
from __future__ import annotations

import array
import math
from typing import Any, Sequence

try:
    import numpy
except ImportError:  # Debian's Blender 3.4 may run without it
    numpy = None


def vertex_normals(positions: Sequence[float], loop_vertices: Sequence[int], loop_starts: Sequence[int],
                   loop_totals: Sequence[int]) -> "array.array[float]":
    """The angle-weighted vertex normals (array('f') of 3 per vertex) of a polygon mesh:
    positions (3 per vertex), each loop's (face corner's) vertex, and each polygon's first loop
    and loop count (Blender's Mesh.vertices.co, loops.vertex_index, polygons.loop_start and
    loop_total)."""
    if numpy is not None:
        return _vertex_normals_numpy(positions, loop_vertices, loop_starts, loop_totals)
    return _vertex_normals_python(positions, loop_vertices, loop_starts, loop_totals)


def _vertex_normals_numpy(positions: Any, loop_vertices: Any, loop_starts: Any, loop_totals: Any) -> Any:
    np = numpy
    co = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    vertex = np.asarray(loop_vertices, dtype=np.int64)
    start = np.asarray(loop_starts, dtype=np.int64)
    total = np.asarray(loop_totals, dtype=np.int64)
    polygons = len(start)
    normals = np.zeros_like(co)
    if polygons and len(vertex):
        polygon = np.repeat(np.arange(polygons), total)  # polygon by polygon, each of its loops
        first = np.repeat(np.cumsum(total) - total, total)
        offset = np.arange(len(polygon)) - first  # the loop's place in its polygon
        loops = start[polygon] + offset
        next_loop = start[polygon] + (offset + 1) % total[polygon]
        prev_loop = start[polygon] + (offset - 1) % total[polygon]
        here, after, before = co[vertex[loops]], co[vertex[next_loop]], co[vertex[prev_loop]]
        face = _sums(polygon, _cross(here, after), polygons)  # Newell: the vector area, twice
        face = _normalised(face, fallback=np.array([0.0, 0.0, 1.0]))
        angle = np.arccos(np.clip(np.einsum("ij,ij->i", _normalised(before - here), _normalised(after - here)),
                                  -1.0, 1.0))
        normals = _sums(vertex[loops], face[polygon] * angle[:, None], len(co))
    length = np.sqrt(np.einsum("ij,ij->i", normals, normals))
    lost = length == 0.0
    normals[~lost] /= length[~lost, None]
    normals[lost] = _normalised(co[lost])
    return array.array("f", normals.astype(np.float32).tobytes())


def _cross(a: Any, b: Any) -> Any:
    """Row-wise a x b (numpy.cross, without its axis juggling: 19x faster on 640,000 rows in numpy 1.24)."""
    return numpy.stack([a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1], a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
                        a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]], axis=1)


def _sums(index: Any, rows: Any, count: Any) -> Any:
    """count x 3 sums of `rows` by `index`, each added in row order (bincount's loop)."""
    return numpy.stack([numpy.bincount(index, weights=rows[:, i], minlength=count) for i in range(3)], axis=1)


def _normalised(vectors: Any, fallback: Any = None) -> Any:
    """Rows scaled to unit length; a zero row stays zero, or becomes `fallback`."""
    np = numpy
    length = np.sqrt(np.einsum("ij,ij->i", vectors, vectors))
    out = np.zeros_like(vectors)
    keep = length > 0.0
    out[keep] = vectors[keep] / length[keep, None]
    if fallback is not None:
        out[~keep] = fallback
    return out


def _unit(v: Sequence[float]) -> Sequence[float]:
    length = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    return (v[0] / length, v[1] / length, v[2] / length) if length > 0.0 else (0.0, 0.0, 0.0)


def _vertex_normals_python(positions: Sequence[float], loop_vertices: Sequence[int], loop_starts: Sequence[int],
                           loop_totals: Sequence[int]) -> "array.array[float]":
    count = len(positions) // 3
    sums = [0.0] * (3 * count)
    for start, total in zip(loop_starts, loop_totals):
        corners = [loop_vertices[start + k] for k in range(total)]
        points = [positions[3 * v:3 * v + 3] for v in corners]
        area = [0.0, 0.0, 0.0]
        for k, p in enumerate(points):
            q = points[(k + 1) % total]
            area[0] += p[1] * q[2] - p[2] * q[1]
            area[1] += p[2] * q[0] - p[0] * q[2]
            area[2] += p[0] * q[1] - p[1] * q[0]
        face = _unit(area)
        if face == (0.0, 0.0, 0.0):
            face = (0.0, 0.0, 1.0)
        for k, p in enumerate(points):
            a = _unit([points[k - 1][i] - p[i] for i in range(3)])
            b = _unit([points[(k + 1) % total][i] - p[i] for i in range(3)])
            angle = math.acos(max(-1.0, min(1.0, a[0] * b[0] + a[1] * b[1] + a[2] * b[2])))
            v = corners[k]
            for i in range(3):
                sums[3 * v + i] += face[i] * angle
    out = array.array("f", bytes(12 * count))
    for v in range(count):
        n = _unit(sums[3 * v:3 * v + 3])
        if n == (0.0, 0.0, 0.0):
            n = _unit(positions[3 * v:3 * v + 3])
        out[3 * v:3 * v + 3] = array.array("f", n)
    return out


def mesh_vertex_normals(mesh: Any) -> "array.array[float]":
    """vertex_normals of a Blender mesh (its vertices' co, loops' vertex_index, polygons'
    loop_start and loop_total)."""
    positions = array.array("f", bytes(12 * len(mesh.vertices)))
    mesh.vertices.foreach_get("co", positions)
    loop_vertices = array.array("i", bytes(4 * len(mesh.loops)))
    mesh.loops.foreach_get("vertex_index", loop_vertices)
    starts = array.array("i", bytes(4 * len(mesh.polygons)))
    totals = array.array("i", bytes(4 * len(mesh.polygons)))
    mesh.polygons.foreach_get("loop_start", starts)
    mesh.polygons.foreach_get("loop_total", totals)
    return vertex_normals(positions, loop_vertices, starts, totals)


def settle_corner_normals(mesh: Any, corner_vertices: Sequence[int], corner_normals: Any,
                          version: Sequence[int]) -> None:
    """Replaces, in place, the corner normals (3 per loop-triangle corner, from
    MeshLoopTriangle.split_normals) of a Blender `mesh` of `version` before 4.1 by vertex_normals
    where they are their vertices' normals: the corners of smooth faces of a mesh without Auto
    Smooth and custom normals. Flat faces keep their face normal (one face's, no accumulation),
    and Auto Smooth's or custom corner normals stay Blender's. 4.1 on gathers each vertex's faces
    in one thread, in a fixed order, and is left alone."""
    if tuple(version) >= (4, 1, 0) or getattr(mesh, "use_auto_smooth", False) or mesh.has_custom_normals:
        return
    smooth = array.array("b", bytes(len(mesh.polygons)))
    mesh.polygons.foreach_get("use_smooth", smooth)
    tris = mesh.loop_triangles
    polygon = array.array("i", bytes(4 * len(tris)))
    tris.foreach_get("polygon_index", polygon)
    normals = mesh_vertex_normals(mesh)
    if numpy is not None:
        corner_smooth = numpy.repeat(numpy.asarray(smooth, dtype=bool)[numpy.asarray(polygon)], 3)
        out = numpy.frombuffer(corner_normals, dtype=numpy.float32).reshape(-1, 3)
        chosen = numpy.asarray(corner_vertices, dtype=numpy.int64)[corner_smooth]
        out[corner_smooth] = numpy.frombuffer(normals, dtype=numpy.float32).reshape(-1, 3)[chosen]
        return
    for c, v in enumerate(corner_vertices):
        if smooth[polygon[c // 3]]:
            corner_normals[3 * c:3 * c + 3] = normals[3 * v:3 * v + 3]
