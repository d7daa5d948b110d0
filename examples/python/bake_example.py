#!/usr/bin/env python3
"""Bake a small subsurface scene with the dwivedi Python shim and write EXR + PNG.

    PYTHONPATH=python_shim python3 examples/python/bake_example.py --out /tmp/dwivedi-example

A wax-like sphere (an icosphere built here) on a diffuse floor, lit by a sun from behind and a
dim grey world, seen by a perspective camera. Ctrl-C cancels the bake cleanly. The shim finds
libdwivedi in the build tree or through DWIVEDI_LIBRARY.
"""
import argparse
import math
import sys
import time
from pathlib import Path

import dwivedi


def icosphere(subdivisions):
    """Positions and triangles of a unit icosphere (each subdivision splits a triangle into 4)."""
    t = (1.0 + math.sqrt(5.0)) / 2.0
    points = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
              (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    points = [tuple(c / math.sqrt(1 + t * t) for c in p) for p in points]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
             (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        midpoint = {}

        def middle(a, b):
            key = (min(a, b), max(a, b))
            if key not in midpoint:
                m = [(x + y) / 2 for x, y in zip(points[a], points[b])]
                n = math.sqrt(sum(c * c for c in m))
                points.append(tuple(c / n for c in m))
                midpoint[key] = len(points) - 1
            return midpoint[key]

        faces = [f for a, b, c in faces
                 for ab, bc, ca in [(middle(a, b), middle(b, c), middle(c, a))]
                 for f in ((a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca))]
    return points, faces


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("dwivedi-example"))
    parser.add_argument("--size", type=int, default=256, help="image width and height")
    parser.add_argument("--samples", type=int, default=64)
    parser.add_argument("--technique", default="auto", choices=dwivedi.techniques())
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    points, faces = icosphere(3)
    with dwivedi.Scene() as scene:
        wax = scene.add_material(dwivedi.Material(subsurface_color=(0.9, 0.6, 0.4),
                                                  subsurface_radius=(1.0, 0.5, 0.25), subsurface_scale=0.5))
        floor = scene.add_material(dwivedi.Material.diffuse((0.5, 0.5, 0.5)))
        # Smooth shading: on a unit sphere the normal is the position.
        scene.add_mesh(points, faces, wax, normals=points, transform=[1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 1])
        scene.add_mesh([(-4, -4, 0), (4, -4, 0), (4, 4, 0), (-4, 4, 0)], [(0, 1, 2), (0, 2, 3)], floor)
        scene.add_light(dwivedi.SunLight(direction=(0.2, -1.0, -0.6), strength=4.0, angle=math.radians(5)))
        scene.set_world((0.05, 0.06, 0.08))
        scene.set_camera(dwivedi.Camera.look_at((0.0, -5.0, 2.0), (0.0, 0.0, 0.9), focal_length=45.0))
        scene.commit()

        last = [0.0]

        def report(progress):
            if progress.done or time.monotonic() - last[0] > 1.0:
                last[0] = time.monotonic()
                print(f"  {progress.fraction:6.1%}  {progress.samples_per_pixel} spp  "
                      f"error {progress.estimated_relative_error:.3g}", file=sys.stderr)

        try:
            image = dwivedi.bake(scene, width=args.size, height=args.size, samples=args.samples,
                                 technique=args.technique, progress=report)
        except KeyboardInterrupt:
            print("cancelled", file=sys.stderr)
            return 130
    stats = image.stats
    image.write_exr(args.out / "example.exr")
    image.write_png(args.out / "example.png", view="Standard")
    print(f"{image.width} x {image.height}, {stats.samples_per_pixel} spp, {stats.seconds:.2f} s, technique "
          f"{stats.technique}, estimated error {stats.estimated_relative_error:.3%}, mean "
          f"{', '.join(f'{c:.4f}' for c in stats.mean_rgb)} -> {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
