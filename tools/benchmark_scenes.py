#!/usr/bin/env python3
"""The benchmark set of issue 20: nine scenes beyond the report's slab, leaf and sphere, made
procedurally (nothing binary is committed) so that the same geometry, materials, lights and
camera reach both renderers:

    python3 tools/benchmark_scenes.py --json DIR [--size 48] [--samples 64]   # scene files for `dwivedi bake`
    python3 tools/cycles_report.py --sections cycles --cycles-scenes torus,head_back,...  # against Cycles

Inside Blender, `build(name, resolution, samples)` empties the file and builds the scene with
tests/blender/scenes.py's Cycles settings (render only what dwivedi bakes); the report exports
it through the add-on, as it does its own scenes. Outside Blender, `scene_json(name, ...)` writes
the same scene as a scene file (docs/scene-format.md), for profiling with `dwivedi bake`.

Materials are the Subsurface Scattering node (Random Walk, Fixed Radius in Blender 3.x: the
plain walk dwivedi bakes) with Lambertian entry and exit; lengths in metres; Cycles' mean free
path is radius x scale / (4 pi). The set covers thick and thin, front-, back- and side-lit,
convex and concave, sun, area, point and world light, high and low albedo, and a subdivided
head-like shape (an icosahedron subdivided four times, displaced into a head with brow, nose,
eye sockets, ears and chin).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
from typing import Dict, List, Sequence, Tuple

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_example_meshes import icosphere  # noqa: E402  (a unit sphere: a subdivided icosahedron)

Vec = Tuple[float, float, float]
Tri = Tuple[int, int, int]


# ---------------------------------------------------------------------------------------------
# Geometry: closed meshes, outward counter-clockwise triangles
# ---------------------------------------------------------------------------------------------

def _normalise(v: Sequence[float]) -> Vec:
    n = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    return (v[0] / n, v[1] / n, v[2] / n)


def _bump(p: Vec, centre: Vec, width: float) -> float:
    d2 = sum((p[i] - centre[i]) ** 2 for i in range(3))
    return math.exp(-d2 / (width * width))


def head(size: float = 0.11) -> Tuple[List[Vec], List[Tri]]:
    """A head-like closed shape about `size` m in radius, facing -y: a subdivided icosphere
    (5,120 triangles) stretched into an egg and displaced along its normals by Gaussian bumps
    (brow, nose, cheeks, ears, chin) and dents (eye sockets). Displacements stay small against
    the radius, so the surface does not fold."""
    points, tris = icosphere(4)
    features = [  # (centre on the unit sphere, width, height)
        ((0.0, -0.93, 0.05), 0.16, 0.20),    # nose
        ((0.0, -0.80, 0.35), 0.35, 0.06),    # brow
        ((-0.35, -0.82, 0.22), 0.16, -0.09),  # eye sockets
        ((0.35, -0.82, 0.22), 0.16, -0.09),
        ((-0.5, -0.75, -0.1), 0.3, 0.04),    # cheeks
        ((0.5, -0.75, -0.1), 0.3, 0.04),
        ((-0.99, 0.0, 0.05), 0.18, 0.14),    # ears: thin lobes, translucent when lit from behind
        ((0.99, 0.0, 0.05), 0.18, 0.14),
        ((0.0, -0.6, -0.75), 0.3, 0.08),     # chin
    ]
    shaped = []
    for p in points:
        r = 1.0 + sum(h * _bump(p, _normalise(c), w) for c, w, h in features)
        shaped.append((size * 0.82 * r * p[0], size * 0.95 * r * p[1], size * 1.1 * r * p[2]))
    return shaped, tris


def torus(major: float, minor: float, segments: int = 64, sides: int = 24) -> Tuple[List[Vec], List[Tri]]:
    """A torus about z: concave (its hole) and convex (its outside)."""
    points = []
    for i in range(segments):
        u = 2 * math.pi * i / segments
        for j in range(sides):
            v = 2 * math.pi * j / sides
            ring = major + minor * math.cos(v)
            points.append((ring * math.cos(u), ring * math.sin(u), minor * math.sin(v)))
    tris = []
    for i in range(segments):
        for j in range(sides):
            a, b = i * sides + j, ((i + 1) % segments) * sides + j
            c, d = ((i + 1) % segments) * sides + (j + 1) % sides, i * sides + (j + 1) % sides
            tris += [(a, b, c), (a, c, d)]
    return points, tris


def _grid_solid(surface, nu: int, nv: int, thickness: float) -> Tuple[List[Vec], List[Tri]]:
    """A closed solid around the surface (u, v) -> (point, unit normal) over [0, 1]^2: its two
    faces offset by +-thickness/2 along the normal, joined at the rim."""
    top, bottom = [], []
    for i in range(nu + 1):
        for j in range(nv + 1):
            p, n = surface(i / nu, j / nv)
            top.append(tuple(p[k] + n[k] * thickness / 2 for k in range(3)))
            bottom.append(tuple(p[k] - n[k] * thickness / 2 for k in range(3)))
    points = top + bottom
    off = len(top)

    def at(i: int, j: int) -> int:
        return i * (nv + 1) + j

    tris = []
    for i in range(nu):
        for j in range(nv):
            a, b, c, d = at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)
            tris += [(a, b, c), (a, c, d), (off + a, off + c, off + b), (off + a, off + d, off + c)]
    rim = [at(i, 0) for i in range(nu)] + [at(nu, j) for j in range(nv)] + \
          [at(i, nv) for i in range(nu, 0, -1)] + [at(0, j) for j in range(nv, 0, -1)]
    for k in range(len(rim)):
        a, b = rim[k], rim[(k + 1) % len(rim)]
        tris += [(a, off + a, off + b), (a, off + b, b)]
    return points, tris


def bent_sheet(width: float, height: float, bend: float, thickness: float) -> Tuple[List[Vec], List[Tri]]:
    """A solidified plane bent about the z axis (a cylinder of radius `bend`), leaf-like: in the
    x-z plane, its convex side toward -y."""
    angle = width / bend

    def surface(u: float, v: float):
        a = (u - 0.5) * angle
        return (bend * math.sin(a), bend * (1.0 - math.cos(a)), (v - 0.5) * height), (-math.sin(a), math.cos(a), 0.0)

    return _grid_solid(surface, 40, 16, thickness)


def lathe(profile: Sequence[Tuple[float, float]], segments: int) -> Tuple[List[Vec], List[Tri]]:
    """The closed solid made by turning the profile (r, z), a path from a point on the z axis to
    another (r = 0 at both ends, r > 0 between), about the z axis."""
    points: List[Vec] = []
    rings: List[List[int]] = []
    for r, z in profile:
        if r == 0.0:
            points.append((0.0, 0.0, z))
            rings.append([len(points) - 1] * segments)
        else:
            rings.append(list(range(len(points), len(points) + segments)))
            points += [(r * math.cos(2 * math.pi * s / segments), r * math.sin(2 * math.pi * s / segments), z)
                       for s in range(segments)]
    tris = []
    for a_ring, b_ring in zip(rings, rings[1:]):
        for s in range(segments):
            a, b = a_ring[s], b_ring[s]
            c, d = b_ring[(s + 1) % segments], a_ring[(s + 1) % segments]
            for t in ((a, b, c), (a, c, d)):
                if len(set(t)) == 3:
                    tris.append(t)
    return points, tris


def bowl(radius: float, thickness: float, segments: int = 64, rings: int = 16) -> Tuple[List[Vec], List[Tri]]:
    """A hemispherical shell open upward (+z), its rim rounded: concave inside, convex outside."""
    inner = radius - thickness
    profile = [(radius * math.sin(a), -radius * math.cos(a))
               for a in (math.pi / 2 * k / rings for k in range(rings + 1))]
    profile += [(radius - thickness / 2 + thickness / 2 * math.cos(a), thickness / 2 * math.sin(a))
                for a in (math.pi * k / 6 for k in range(1, 6))]  # the rounded rim
    profile += [(inner * math.sin(a), -inner * math.cos(a))
                for a in (math.pi / 2 * k / rings for k in range(rings, -1, -1))]
    return lathe(profile, segments)


def box(sx: float, sy: float, sz: float) -> Tuple[List[Vec], List[Tri]]:
    p = [(x * sx / 2, y * sy / 2, z * sz / 2) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    t = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6), (0, 2, 6),
         (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    return p, t


def cylinder(radius: float, height: float, segments: int = 64) -> Tuple[List[Vec], List[Tri]]:
    """A closed cylinder about z with flat caps."""
    return lathe([(0.0, -height / 2), (radius, -height / 2), (radius, height / 2), (0.0, height / 2)], segments)


def uv_sphere(radius: float, segments: int = 48, rings: int = 24) -> Tuple[List[Vec], List[Tri]]:
    points = [(0.0, 0.0, radius)]
    for r in range(1, rings):
        theta = math.pi * r / rings
        for s in range(segments):
            phi = 2 * math.pi * s / segments
            points.append((radius * math.sin(theta) * math.cos(phi), radius * math.sin(theta) * math.sin(phi),
                           radius * math.cos(theta)))
    points.append((0.0, 0.0, -radius))
    south = len(points) - 1

    def at(r: int, s: int) -> int:
        return 1 + (r - 1) * segments + s % segments

    tris = [(0, at(1, s), at(1, s + 1)) for s in range(segments)]
    for r in range(1, rings - 1):
        for s in range(segments):
            tris += [(at(r, s), at(r + 1, s), at(r + 1, s + 1)), (at(r, s), at(r + 1, s + 1), at(r, s + 1))]
    tris += [(south, at(rings - 1, s + 1), at(rings - 1, s)) for s in range(segments)]
    return points, tris


def outward(points: List[Vec], tris: List[Tri]) -> Tuple[List[Vec], List[Tri]]:
    """The closed mesh with its triangles turned counter-clockwise seen from outside: all of them
    reversed if its signed volume (the sum of a . (b x c) / 6) is negative."""
    volume = 0.0
    for a, b, c in tris:
        pa, pb, pc = points[a], points[b], points[c]
        volume += (pa[0] * (pb[1] * pc[2] - pb[2] * pc[1]) - pa[1] * (pb[0] * pc[2] - pb[2] * pc[0]) +
                   pa[2] * (pb[0] * pc[1] - pb[1] * pc[0]))
    return (points, tris) if volume > 0 else (points, [(a, c, b) for a, b, c in tris])


def smooth_normals(points: List[Vec], tris: List[Tri]) -> List[Vec]:
    """Per-vertex normals: the area-weighted mean of the faces' normals (Blender's smooth shading
    weighs by angle; the difference does not matter to a benchmark as both renderers get the
    same mesh from Blender, and scene files get these)."""
    acc = [[0.0, 0.0, 0.0] for _ in points]
    for a, b, c in tris:
        pa, pb, pc = points[a], points[b], points[c]
        e1 = [pb[i] - pa[i] for i in range(3)]
        e2 = [pc[i] - pa[i] for i in range(3)]
        n = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])
        for v in (a, b, c):
            for i in range(3):
                acc[v][i] += n[i]
    return [_normalise(n) if any(n) else (0.0, 0.0, 1.0) for n in acc]


# ---------------------------------------------------------------------------------------------
# The scenes
# ---------------------------------------------------------------------------------------------

def _material(color: Vec, radius: Vec, scale: float) -> Dict:
    return {"color": color, "radius": radius, "scale": scale}


SKIN = _material((0.8, 0.55, 0.45), (1.0, 0.35, 0.2), 0.025)


def _scenes() -> Dict[str, Dict]:
    """Name -> description. Each: a mesh (geometry, smooth or flat, location), a material (the
    Subsurface Scattering node's colour, radius, scale), lights, a world and a camera."""
    return {
        # The torus of pale wax under an area light, dim world: thick, front-lit, concave.
        "torus": {"what": "thick wax torus, area light from the front and above, dim world (concave, high albedo)",
                  "mesh": (lambda: torus(0.3, 0.1), True), "location": (0.0, 0.0, 0.0), "rotate_x": 60.0,
                  "material": _material((0.92, 0.88, 0.78), (1.0, 0.8, 0.6), 0.05),
                  "lights": [{"kind": "area", "strength": 15.0, "size": 0.4, "eye": (0.3, -0.9, 0.9),
                              "target": (0.0, 0.0, 0.0)}],
                  "world": ((1.0, 1.0, 1.0), 0.05), "camera": ((0.0, -1.6, 0.5), (0.0, 0.0, 0.0))},
        # The Suzanne: a subdivided head, skin colours, lit from behind.
        "head_back": {"what": "subdivided head, skin, sun from behind and above (thick, back-lit, ears thin)",
                      "mesh": (lambda: head(), True), "location": (0.0, 0.0, 0.0), "rotate_x": 0.0,
                      "material": SKIN,
                      "lights": [{"kind": "sun", "strength": 6.0, "direction": (0.7, -0.7, -0.3)}],
                      "world": ((1.0, 1.0, 1.0), 0.02), "camera": ((0.0, -0.55, 0.03), (0.0, 0.0, 0.0))},
        "head_point": {"what": "subdivided head, skin, point light front left (thick, front-lit, concave sockets)",
                       "mesh": (lambda: head(), True), "location": (0.0, 0.0, 0.0), "rotate_x": 0.0,
                       "material": SKIN,
                       "lights": [{"kind": "point", "strength": 8.0, "position": (-0.25, -0.35, 0.15),
                                   "radius": 0.02}],
                       "world": ((0.0, 0.0, 0.0), 1.0), "camera": ((0.0, -0.55, 0.03), (0.0, 0.0, 0.0))},
        "sheet": {"what": "bent sheet 4 mm thick, leaf green, sun from behind (thin, back-lit, high albedo)",
                  "mesh": (lambda: bent_sheet(0.3, 0.2, 0.25, 0.004), True), "location": (0.0, 0.0, 0.0),
                  "rotate_x": 0.0, "material": _material((0.5, 0.9, 0.3), (0.5, 0.5, 0.3), 0.02),
                  "lights": [{"kind": "sun", "strength": 3.0, "direction": (-0.3, -1.0, -0.4)}],
                  "world": ((0.0, 0.0, 0.0), 1.0), "camera": ((0.0, -0.7, 0.05), (0.0, 0.0, 0.0))},
        "box_side": {"what": "box of dark clay, sun from the side at grazing incidence (thick, side-lit, low albedo)",
                     "mesh": (lambda: box(0.3, 0.3, 0.3), False), "location": (0.0, 0.0, 0.0), "rotate_x": 0.0,
                     "rotate_z": 35.0, "material": _material((0.3, 0.22, 0.18), (1.0, 0.5, 0.3), 0.1),
                     "lights": [{"kind": "sun", "strength": 4.0, "direction": (-1.0, 0.3, -0.25)}],
                     "world": ((1.0, 1.0, 1.0), 0.02), "camera": ((0.35, -0.9, 0.45), (0.0, 0.0, 0.0))},
        "marble": {"what": "white marble sphere under a uniform world only (thick, lit from everywhere, very high albedo)",
                   "mesh": (lambda: uv_sphere(0.2), True), "location": (0.0, 0.0, 0.0), "rotate_x": 0.0,
                   "material": _material((0.97, 0.97, 0.95), (1.0, 0.9, 0.8), 0.02),
                   "lights": [], "world": ((1.0, 1.0, 1.0), 0.6), "camera": ((0.0, -1.0, 0.0), (0.0, 0.0, 0.0))},
        "disc_back": {"what": "coin-like disc 1 cm thick, area light behind it (thin, back-lit, medium albedo)",
                      "mesh": (lambda: cylinder(0.15, 0.01), False), "location": (0.0, 0.0, 0.0),
                      "rotate_x": 90.0, "material": _material((0.9, 0.6, 0.4), (1.0, 0.5, 0.25), 0.05),
                      "lights": [{"kind": "area", "strength": 12.0, "size": 0.4, "eye": (0.1, 0.5, 0.1),
                                  "target": (0.0, 0.0, 0.0)}],
                      "world": ((0.0, 0.0, 0.0), 1.0), "camera": ((0.0, -0.8, 0.1), (0.0, 0.0, 0.0))},
        "bowl": {"what": "jade bowl, point light above it (concave inside, thin wall 1.5 cm, medium albedo)",
                 "mesh": (lambda: bowl(0.15, 0.015), True), "location": (0.0, 0.0, 0.0), "rotate_x": 0.0,
                 "material": _material((0.45, 0.8, 0.6), (0.6, 0.9, 0.7), 0.03),
                 "lights": [{"kind": "point", "strength": 15.0, "position": (0.05, -0.1, 0.3), "radius": 0.02}],
                 "world": ((1.0, 1.0, 1.0), 0.03), "camera": ((0.0, -0.6, 0.45), (0.0, 0.0, -0.02))},
        "cylinder_front": {"what": "dark blue cylinder, sun from the camera's side (thick, front-lit, low albedo)",
                           "mesh": (lambda: cylinder(0.12, 0.3), False), "location": (0.0, 0.0, 0.0),
                           "rotate_x": 0.0, "material": _material((0.15, 0.25, 0.4), (0.5, 0.5, 0.8), 0.1),
                           "lights": [{"kind": "sun", "strength": 3.0, "direction": (0.3, 1.0, -0.3)}],
                           "world": ((1.0, 1.0, 1.0), 0.05), "camera": ((0.0, -0.9, 0.2), (0.0, 0.0, 0.0))},
    }


SCENES = _scenes()


# ---------------------------------------------------------------------------------------------
# Real-asset scenes (issue 18 item 6): image textures, a normal map, an HDRI world, a spot light
# and a ground that lights the object. Their images are generated when the scene is built (inside
# Blender, into Blender's session folder bpy.app.tempdir, standard library only: Debian's 4.3 and
# 5.2 have no numpy), so they are Blender scenes only; a scene file of one is the add-on's farm
# export's to write.
# ---------------------------------------------------------------------------------------------

def _srgb_byte(linear: float) -> int:
    """A scene-linear value in [0, 1] as an 8-bit sRGB code (IEC 61966-2-1's transfer function)."""
    c = min(max(linear, 0.0), 1.0)
    encoded = 12.92 * c if c <= 0.0031308 else 1.055 * c ** (1.0 / 2.4) - 0.055
    return int(round(255.0 * encoded))


def _texels(width: int, height: int, texel, srgb: bool) -> bytes:
    """8-bit RGB texels, bottom row first (Blender's order), of texel(u, v) -> linear RGB at the
    texel's centre; sRGB-encoded for a colour image, as they are for data (Non-Color)."""
    out = bytearray()
    for row in range(height):
        for column in range(width):
            rgb = texel((column + 0.5) / width, (row + 0.5) / height)
            out += bytes(_srgb_byte(c) if srgb else int(round(255.0 * min(max(c, 0.0), 1.0))) for c in rgb)
    return bytes(out)


def _hash(i: int, j: int, seed: int) -> float:
    """A value in [0, 1) fixed by the integers (i, j, seed): the texture generators' noise, the same
    on every Python (no random module state)."""
    h = (i * 374761393 + j * 668265263 + seed * 2147483647) & 0xFFFFFFFF
    h = ((h ^ (h >> 13)) * 1274126177) & 0xFFFFFFFF
    return ((h ^ (h >> 16)) & 0xFFFFFF) / float(0x1000000)


def _value_noise(u: float, v: float, cells: int, seed: int) -> float:
    """Smooth value noise in [0, 1), periodic in u and v over the unit square (cells x cells)."""
    x, y = u * cells, v * cells
    i, j = int(math.floor(x)), int(math.floor(y))
    fx, fy = x - i, y - j
    sx, sy = fx * fx * (3 - 2 * fx), fy * fy * (3 - 2 * fy)

    def at(a: int, b: int) -> float:
        return _hash(a % cells, b % cells, seed)
    top = at(i, j) + sx * (at(i + 1, j) - at(i, j))
    bottom = at(i, j + 1) + sx * (at(i + 1, j + 1) - at(i, j + 1))
    return top + sy * (bottom - top)


def skin_texel(u: float, v: float) -> Vec:
    """Skin with detail: a mottled tone (two octaves of noise), redder cheeks, freckles."""
    n = 0.6 * _value_noise(u, v, 8, 1) + 0.4 * _value_noise(u, v, 32, 2)
    freckle = 1.0 if _hash(int(u * 96), int(v * 96), 3) > 0.93 and 0.35 < v < 0.7 else 0.0
    cheek = math.exp(-((v - 0.45) / 0.08) ** 2) * (math.exp(-((u - 0.36) / 0.05) ** 2) +
                                                   math.exp(-((u - 0.64) / 0.05) ** 2))
    base = (0.78 + 0.1 * cheek, 0.52 - 0.08 * cheek, 0.42 - 0.06 * cheek)
    shade = 0.85 + 0.3 * n - 0.3 * freckle
    return tuple(c * shade for c in base)


def pore_normal_texel(u: float, v: float) -> Vec:
    """A tangent-space normal map (Non-Color, 0.5 + 0.5 n) of pores and wrinkles: the normal of the
    height h = 0.004 sin(2 pi 40 u) sin(2 pi 30 v) + 0.01 (noise), slopes as the map's x and y."""
    dx = 0.35 * math.cos(2 * math.pi * 40 * u) * math.sin(2 * math.pi * 30 * v)
    dy = 0.3 * math.sin(2 * math.pi * 40 * u) * math.cos(2 * math.pi * 30 * v)
    e = 1.0 / 128
    dx += 8.0 * (_value_noise(u + e, v, 16, 4) - _value_noise(u - e, v, 16, 4))
    dy += 8.0 * (_value_noise(u, v + e, 16, 4) - _value_noise(u, v - e, 16, 4))
    n = _normalise((-dx, -dy, 1.0))
    return tuple(0.5 + 0.5 * c for c in n)


def leaf_texel(u: float, v: float) -> Vec:
    """A leaf: green lamina mottled by noise, a pale midrib along u (v = 0.5) and side veins."""
    vein = _leaf_vein(u, v)
    n = 0.85 + 0.3 * _value_noise(u, v, 12, 5)
    lamina = (0.25 * n, 0.6 * n, 0.12 * n)
    pale = (0.6, 0.8, 0.3)
    return tuple(a + vein * (b - a) for a, b in zip(lamina, pale))


def _leaf_vein(u: float, v: float) -> float:
    """How much of a vein the leaf's texel (u, v) is, in [0, 1]: the midrib (v = 0.5) and side
    veins leaving it at 45 degrees toward the tip (u = 1)."""
    midrib = math.exp(-((v - 0.5) / 0.02) ** 2)
    side = abs(v - 0.5) - (u - 0.08) * 0.8  # lines v - 0.5 = +-0.8 (u - 0.08) + k / 8 toward the tip
    phase = (side * 8.0) % 1.0
    veins = math.exp(-((min(phase, 1.0 - phase)) / 0.06) ** 2) if u > 0.08 else 0.0
    return max(midrib, 0.7 * veins)


def leaf_radius_texel(u: float, v: float) -> Vec:
    """The leaf's Subsurface Radius (Non-Color, times the node's Scale): the lamina scatters far,
    the veins (denser) a third as far."""
    vein = _leaf_vein(u, v)
    lamina, dense = (0.9, 0.9, 0.5), (0.3, 0.3, 0.17)
    return tuple(a + vein * (b - a) for a, b in zip(lamina, dense))


def hdri_texels(width: int, height: int, sun: Vec, spot: float) -> List[float]:
    """An equirectangular HDRI (RGBA floats, bottom row first, Cycles' equirectangular mapping: a
    column's longitude pi (1 - 2 (x + 0.5) / width) from +x toward +y, a row's polar angle from +z
    pi (1 - (y + 0.5) / height)): a blue sky brighter toward the zenith, a brown ground, and a
    sun-like hot spot of `spot` at the direction `sun`, Gaussian of 3 degrees."""
    sun = _normalise(sun)
    out: List[float] = []
    for row in range(height):
        theta = math.pi * (1.0 - (row + 0.5) / height)
        for column in range(width):
            phi = math.pi * (1.0 - 2.0 * (column + 0.5) / width)
            d = (math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta))
            rgb = [c * (0.4 + 0.6 * d[2]) for c in (0.25, 0.35, 0.6)] if d[2] > 0.0 else [0.12, 0.1, 0.08]
            angle = math.acos(max(-1.0, min(1.0, sum(a * b for a, b in zip(d, sun)))))
            hot = spot * math.exp(-(angle / math.radians(3.0)) ** 2)
            out += [rgb[0] + hot, rgb[1] + 0.92 * hot, rgb[2] + 0.8 * hot, 1.0]
    return out


def head_uvs(points: List[Vec], tris: List[Tri]) -> List[Tuple[float, float]]:
    """Per triangle corner: a spherical map of head()'s points, u the longitude about z from the
    face (-y), v the latitude, its seam at the back (+y). A triangle's corners take u within 0.5
    of its first (u + 1 across the seam: the image repeats), so no triangle spans the whole image;
    a corner at a pole, whose longitude is any, takes its triangle's other corners' mean."""
    per_vertex = []
    for p in points:
        d = _normalise((p[0] / 0.82, p[1] / 0.95, p[2] / 1.1))
        pole = abs(d[2]) > 1.0 - 1e-9
        per_vertex.append((None if pole else 0.5 + math.atan2(d[0], -d[1]) / (2 * math.pi),
                           0.5 + math.asin(max(-1.0, min(1.0, d[2]))) / math.pi))
    out = []
    for t in tris:
        us = [per_vertex[i][0] for i in t]
        first = next(u for u in us if u is not None)
        us = [None if u is None else u + round(first - u) for u in us]
        known = [u for u in us if u is not None]
        shift = 1.0 if min(known) < 0.0 else 0.0
        mean = sum(known) / len(known)
        out += [((mean if u is None else u) + shift, per_vertex[i][1]) for u, i in zip(us, t)]
    return out


def leaf(length: float, width: float, thickness: float) -> Tuple[List[Vec], List[Tri], List[Tuple[float, float]]]:
    """A leaf-like closed sheet `thickness` thick in the x-z plane, its convex side toward -y: an
    outline of half-width width/2 sin(pi u)^0.7 (u along x), folded along its midrib (y = 0.6 z^2
    / width) and curled along its length; its per-vertex UVs (u along, v across)."""
    nu, nv = 40, 12

    def point(u: float, v: float) -> Vec:
        half = max(width / 2 * math.sin(math.pi * u) ** 0.7, 0.003)
        x, z = (u - 0.5) * length, (2 * v - 1) * half
        return (x, 0.6 * z * z / width + 0.4 * x * x / length, z)

    def surface(u: float, v: float):
        e = 1e-4
        pu = [a - b for a, b in zip(point(min(u + e, 1), v), point(max(u - e, 0), v))]
        pv = [a - b for a, b in zip(point(u, min(v + e, 1)), point(u, max(v - e, 0)))]
        n = (pu[1] * pv[2] - pu[2] * pv[1], pu[2] * pv[0] - pu[0] * pv[2], pu[0] * pv[1] - pu[1] * pv[0])
        return point(u, v), _normalise(n)

    points, tris = _grid_solid(surface, nu, nv, thickness)
    uv = [(i / nu, j / nv) for i in range(nu + 1) for j in range(nv + 1)]
    return points, tris, uv + uv  # both faces: the grid's (u, v)


def _asset_scenes() -> Dict[str, str]:
    """Name -> what: the real-asset scenes, built by build() (_build_asset)."""
    return {
        "head_asset": "subdivided head, skin from a generated colour image with detail, a generated normal map "
                      "(pores, wrinkles), an HDRI world (equirectangular, a sun-like hot spot front left)",
        "candle": "wax cylinder (a candle) on a diffuse ground, a spot light from the front right; the ground "
                  "lights the candle (indirect light, the scene's Light Paths)",
        "leaf_textured": "leaf-like sheet 3 mm thick, colour and Subsurface Radius from generated images (veins "
                         "scatter a third as far), sun from behind",
    }


ASSET_SCENES = _asset_scenes()
NAMES = tuple(SCENES) + tuple(ASSET_SCENES)


def _rotation(rx: float, rz: float):
    """Blender's XYZ Euler rotation (degrees) about x then z, as a function on points."""
    cx, sx, cz, sz = math.cos(math.radians(rx)), math.sin(math.radians(rx)), math.cos(math.radians(rz)), \
        math.sin(math.radians(rz))

    def apply(p: Vec) -> Vec:
        x, y, z = p[0], cx * p[1] - sx * p[2], sx * p[1] + cx * p[2]
        return (cz * x - sz * y, sz * x + cz * y, z)
    return apply


def mesh_of(name: str) -> Tuple[List[Vec], List[Tri], bool]:
    """The scene's mesh in world space (rotated and placed), and whether it is smooth shaded."""
    s = SCENES[name]
    make, smooth = s["mesh"]
    points, tris = outward(*make())
    turn = _rotation(s.get("rotate_x", 0.0), s.get("rotate_z", 0.0))
    loc = s["location"]
    points = [tuple(a + b for a, b in zip(turn(p), loc)) for p in points]
    return points, tris, smooth


# The light paths of build()'s Blender scenes (tests/blender/scenes.py's _reset), for the scene files.
LIGHT_PATHS = {"max_bounces": 4, "diffuse_bounces": 4, "glossy_bounces": 0, "transmission_bounces": 0}


def scene_json(name: str, size: int, samples: int) -> Dict:
    """The scene as a scene file (docs/scene-format.md)."""
    s = SCENES[name]
    points, tris, smooth = mesh_of(name)
    m = s["material"]
    mesh = {"name": name, "material": "sss", "positions": [c for p in points for c in p],
            "indices": [i for t in tris for i in t]}
    if smooth:
        mesh["normals"] = [round(c, 7) for n in smooth_normals(points, tris) for c in n]
    lights = []
    for light in s["lights"]:
        if light["kind"] == "sun":
            lights.append({"kind": "sun", "strength": light["strength"], "direction": list(light["direction"])})
        elif light["kind"] == "point":
            lights.append({"kind": "point", "strength": light["strength"], "position": list(light["position"]),
                           "radius": light["radius"]})
        else:
            lights.append({"kind": "area", "shape": "disk", "strength": light["strength"], "size_x": light["size"],
                           "transform": {"look_at": {"eye": list(light["eye"]), "target": list(light["target"])}}})
    color, strength = s["world"]
    eye, target = s["camera"]
    return {"version": 1, "description": s["what"],
            "materials": {"sss": {"base_color": list(m["color"]), "subsurface_color": list(m["color"]),
                                  "subsurface_radius": list(m["radius"]), "subsurface_scale": m["scale"]}},
            "meshes": [mesh], "lights": lights, "world": {"color": list(color), "strength": strength},
            "camera": {"kind": "perspective", "focal_length": 50.0, "sensor_width": 36.0,
                       "transform": {"look_at": {"eye": list(eye), "target": list(target)}}},
            "bake": {"width": size, "height": size, "samples": samples, **LIGHT_PATHS}}


def _aim(obj, eye, target):
    """Inside Blender: place `obj` at `eye` with its -z toward `target` (a camera's or light's view)."""
    from mathutils import Vector
    obj.location = eye
    obj.rotation_euler = (Vector(target) - Vector(eye)).to_track_quat('-Z', 'Y').to_euler()


def _mesh_object(scene, name: str, points, tris, smooth: bool, material, corner_uvs=None):
    """Inside Blender: a mesh object of the triangles (with a UV map "UVMap" of one (u, v) per
    corner, in the triangles' order: from_pydata makes loop 3 t + k of corner k of triangle t)."""
    import bpy
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(points, [], tris)
    if corner_uvs is not None:
        layer = mesh.uv_layers.new(name="UVMap")
        layer.data.foreach_set("uv", [c for uv in corner_uvs for c in uv])
    mesh.update()
    for polygon in mesh.polygons:
        polygon.use_smooth = smooth
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)
    obj.data.materials.append(material)
    return obj


def _image(name: str, width: int, height: int, texel, colorspace: str):
    """Inside Blender: a generated 8-bit RGB image written as a PNG file into Blender's session
    folder and loaded from it, in `colorspace` ('sRGB' for colour, 'Non-Color' for data)."""
    import bpy
    from dwivedi import image_files  # the shim's PNG writer (standard library only)
    path = os.path.join(bpy.app.tempdir, f"benchmark_{name}.png")
    with open(path, "wb") as f:
        f.write(image_files.png_bytes(_texels(width, height, texel, colorspace == 'sRGB'), width, height, 3))
    image = bpy.data.images.load(path, check_existing=False)
    image.colorspace_settings.name = colorspace
    return image


def _image_node(tree, image, interpolation: str = 'Linear'):
    node = tree.nodes.new("ShaderNodeTexImage")
    node.image = image
    node.interpolation = interpolation
    return node


def _build_asset(name: str, scene):
    """Inside Blender: the real-asset scene `name` into the emptied `scene`."""
    import bpy
    import scenes as test_scenes
    if name == "head_asset":
        points, tris = outward(*head())
        material = test_scenes.sss_node_material(name, SKIN["color"], SKIN["radius"], SKIN["scale"])
        tree = material.node_tree
        sss = next(n for n in tree.nodes if n.type == 'SUBSURFACE_SCATTERING')
        colour = _image_node(tree, _image("skin", 128, 128, skin_texel, 'sRGB'))
        tree.links.new(colour.outputs["Color"], sss.inputs["Color"])
        pores = _image_node(tree, _image("pores", 128, 128, pore_normal_texel, 'Non-Color'))
        normal_map = tree.nodes.new("ShaderNodeNormalMap")
        normal_map.space = 'TANGENT'
        normal_map.uv_map = "UVMap"
        tree.links.new(pores.outputs["Color"], normal_map.inputs["Color"])
        tree.links.new(normal_map.outputs["Normal"], sss.inputs["Normal"])
        _mesh_object(scene, name, points, tris, True, material, head_uvs(points, tris))
        # The HDRI: an EXR of float texels (the shim's writer: Blender's Image.save would pass a
        # float image through the colour management), the hot spot front left and above.
        from dwivedi import image_files
        width, height = 256, 128
        path = os.path.join(bpy.app.tempdir, "benchmark_hdri.exr")
        with open(path, "wb") as f:
            f.write(image_files.exr_bytes(hdri_texels(width, height, (-0.6, -0.6, 0.5), 600.0), width, height, 4))
        world = scene.world.node_tree
        texture = world.nodes.new("ShaderNodeTexEnvironment")
        texture.image = bpy.data.images.load(path, check_existing=False)
        background = world.nodes["Background"]
        background.inputs["Strength"].default_value = 1.0
        world.links.new(texture.outputs["Color"], background.inputs["Color"])
        camera = ((0.0, -0.55, 0.03), (0.0, 0.0, 0.0))
    elif name == "candle":
        points, tris = outward(*cylinder(0.04, 0.16))
        # Standing 1 mm above the ground: no coplanar faces for the two renderers to split differently.
        points = [(x, y, z + 0.081) for x, y, z in points]
        _mesh_object(scene, name, points, tris, False,
                     test_scenes.sss_node_material(name, (0.93, 0.82, 0.6), (1.0, 0.6, 0.3), 0.05))
        ground = [(-0.75, -0.75, 0.0), (0.75, -0.75, 0.0), (0.75, 0.75, 0.0), (-0.75, 0.75, 0.0)]
        _mesh_object(scene, "Ground", ground, [(0, 1, 2), (0, 2, 3)], False,
                     test_scenes.diffuse_material("Ground", (0.6, 0.6, 0.6)))
        data = bpy.data.lights.new("Spot", 'SPOT')
        data.energy = 12.0
        data.spot_size = math.radians(40.0)
        data.spot_blend = 0.3
        data.shadow_soft_size = 0.02
        spot = bpy.data.objects.new("Spot", data)
        _aim(spot, (0.3, -0.35, 0.45), (0.0, 0.0, 0.06))
        scene.collection.objects.link(spot)
        test_scenes.set_world(scene, (1.0, 1.0, 1.0), 0.02)
        camera = ((0.0, -0.55, 0.22), (0.0, 0.0, 0.07))
    else:  # leaf_textured
        points, tris, uv = leaf(0.3, 0.14, 0.003)
        points, tris = outward(points, tris)
        material = test_scenes.sss_node_material(name, (0.3, 0.6, 0.15), (0.9, 0.9, 0.5), 0.02)
        tree = material.node_tree
        sss = next(n for n in tree.nodes if n.type == 'SUBSURFACE_SCATTERING')
        colour = _image_node(tree, _image("leaf", 128, 128, leaf_texel, 'sRGB'))
        tree.links.new(colour.outputs["Color"], sss.inputs["Color"])
        radius = _image_node(tree, _image("leaf_radius", 64, 64, leaf_radius_texel, 'Non-Color'))
        tree.links.new(radius.outputs["Color"], sss.inputs["Radius"])
        _mesh_object(scene, name, points, tris, True, material, [uv[i] for t in tris for i in t])
        data = bpy.data.lights.new("Sun", 'SUN')
        data.energy = 3.0
        data.angle = 0.0
        sun = bpy.data.objects.new("Sun", data)
        from mathutils import Vector
        sun.rotation_euler = Vector((-0.3, -1.0, -0.4)).to_track_quat('-Z', 'Y').to_euler()
        scene.collection.objects.link(sun)
        test_scenes.set_world(scene, (1.0, 1.0, 1.0), 0.02)
        camera = ((0.0, -0.6, 0.05), (0.0, 0.0, 0.0))
    data = bpy.data.cameras.new("Camera")
    data.lens = 50.0
    data.sensor_width = 36.0
    obj = bpy.data.objects.new("Camera", data)
    _aim(obj, *camera)
    scene.collection.objects.link(obj)
    scene.camera = obj
    return scene


def build(name: str, resolution: int = 48, samples: int = 64):
    """Inside Blender: the scene `name` as the current file (tests/blender/scenes.py's Cycles
    settings), returned. The real-asset scenes import the shim (`dwivedi`, for its image
    writers), as the report's Blender has it on sys.path."""
    import bpy  # only inside Blender
    from mathutils import Vector
    import scenes as test_scenes  # tests/blender/scenes.py, on sys.path inside the report's Blender

    scene = test_scenes._reset()
    scene.render.resolution_x = resolution
    scene.render.resolution_y = resolution
    scene.cycles.samples = samples
    if name in ASSET_SCENES:
        return _build_asset(name, scene)
    s = SCENES[name]
    # Light paths: tests/blender/scenes.py's (4 total, 4 diffuse, no glossy or transmission), which
    # the add-on passes to dwivedi too (export.light_paths): on the concave scenes (bowl, torus)
    # both renderers bake the light one part of the surface reflects onto another (indirect light,
    # issue 18; before it Cycles ran with diffuse_bounces 0 here, the bowl being 17% brighter with 4).
    points, tris, smooth = mesh_of(name)
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(points, [], tris)
    mesh.update()
    for polygon in mesh.polygons:
        polygon.use_smooth = smooth
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)
    m = s["material"]
    obj.data.materials.append(test_scenes.sss_node_material(name, m["color"], m["radius"], m["scale"]))

    for i, light in enumerate(s["lights"]):
        kind = {"sun": 'SUN', "point": 'POINT', "area": 'AREA'}[light["kind"]]
        data = bpy.data.lights.new(f"Light{i}", kind)
        data.energy = light["strength"]
        lobj = bpy.data.objects.new(f"Light{i}", data)
        if kind == 'SUN':
            data.angle = 0.0
            lobj.rotation_euler = Vector(light["direction"]).to_track_quat('-Z', 'Y').to_euler()
        elif kind == 'POINT':
            data.shadow_soft_size = light["radius"]
            lobj.location = light["position"]
        else:
            data.shape = 'DISK'
            data.size = light["size"]
            _aim(lobj, light["eye"], light["target"])
        scene.collection.objects.link(lobj)
    color, strength = s["world"]
    test_scenes.set_world(scene, color, strength)
    data = bpy.data.cameras.new("Camera")
    data.lens = 50.0
    data.sensor_width = 36.0
    camera = bpy.data.objects.new("Camera", data)
    _aim(camera, *s["camera"])
    scene.collection.objects.link(camera)
    scene.camera = camera
    return scene


def main(argv: Sequence[str] = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--json", required=True, metavar="DIR", help="write one scene file per scene here")
    parser.add_argument("--size", type=int, default=48, help="image width and height (default 48)")
    parser.add_argument("--samples", type=int, default=64)
    parser.add_argument("--scenes", default=",".join(SCENES),
                        help="comma-separated (default: all but the real-asset scenes, which are Blender's only)")
    args = parser.parse_args(argv)
    names = [n for n in args.scenes.split(",") if n]
    unknown = [n for n in names if n not in SCENES]
    assets = [n for n in unknown if n in ASSET_SCENES]
    if assets:
        print(f"benchmark_scenes: {', '.join(assets)}: built in Blender only (generated images); the add-on's farm "
              "export writes a scene file of one", file=sys.stderr)
        return 1
    if unknown:
        print(f"benchmark_scenes: unknown scene(s) {', '.join(unknown)} (known: {', '.join(NAMES)})", file=sys.stderr)
        return 1
    if args.size < 1 or args.samples < 1:
        print("benchmark_scenes: --size and --samples must be at least 1", file=sys.stderr)
        return 1
    os.makedirs(args.json, exist_ok=True)
    for name in names:
        path = os.path.join(args.json, name + ".json")
        with open(path, "w") as f:
            json.dump(scene_json(name, args.size, args.samples), f)
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
