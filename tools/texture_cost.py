#!/usr/bin/env python3
"""The cost of textured material inputs: one scene baked with a constant subsurface colour, with
the same colour from a 1 x 1 texture (the same image bit for bit, the texels being exact in float:
a texture changes what is computed per hit, not what comes out), and with a 64 x 64 colour
texture; seconds of each, alternated, and their ratio within this run (ratios from one run only).

    DWIVEDI_LIBRARY=build/libdwivedi.so.1 python3 tools/texture_cost.py [--rounds 3]
"""
import argparse
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python_shim"))
import dwivedi  # noqa: E402


def sphere(rings=24, segments=48):
    """A UV sphere of radius 1 (split corners, smooth normals, UVs and analytic tangents)."""
    positions, normals, uvs = [], [], []

    def point(r, s):
        theta, phi = math.pi * r / rings, 2 * math.pi * s / segments
        return (math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta)), \
            (s / segments, 1 - r / rings)
    for r in range(rings):
        for s in range(segments):
            quad = [(r, s), (r + 1, s), (r + 1, s + 1), (r, s + 1)]
            for tri in ((0, 1, 2), (0, 2, 3)):
                for k in tri:
                    p, uv = point(*quad[k])
                    positions += p
                    normals += p
                    uvs += uv
    return positions, list(range(len(positions) // 3)), normals, uvs


def scene(mesh, texture):
    positions, indices, normals, uvs = mesh
    s = dwivedi.Scene()
    m = s.add_material(dwivedi.Material(subsurface_color=(0.875, 0.625, 0.375), subsurface_radius=(0.5, 0.25, 0.1),
                                        subsurface_scale=0.3))
    if texture == "1x1":
        s.bind_texture(m, "subsurface_color", s.add_texture([0.875, 0.625, 0.375], 1, 1, 3))
    elif texture == "64x64":
        texels = [v for y in range(64) for x in range(64) for v in (0.875, 0.375 + 0.25 * ((x // 8 + y // 8) % 2), 0.375)]
        s.bind_texture(m, "subsurface_color", s.add_texture(texels, 64, 64, 3))
    s.add_mesh(positions, indices, m, normals=normals, uvs=uvs)
    s.add_light(dwivedi.SunLight(direction=(0.3, 1, -0.5), strength=3))
    s.set_camera(dwivedi.Camera(kind="orthographic", transform=[1, 0, 0, 0, 0, 0, -1, -5, 0, 1, 0, 0],
                                ortho_scale=2.2))
    return s.commit()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--size", type=int, default=48)
    parser.add_argument("--samples", type=int, default=16)
    args = parser.parse_args()
    mesh = sphere()
    scenes = {name: scene(mesh, name) for name in ("constant", "1x1", "64x64")}
    seconds = {name: 0.0 for name in scenes}
    images = {}
    for _ in range(args.rounds):
        for name, s in scenes.items():
            start = time.perf_counter()
            images[name] = s.bake(width=args.size, height=args.size, samples=args.samples, threads=2, seed=3)
            seconds[name] += time.perf_counter() - start
    same = bytes(images["constant"].pixels()) == bytes(images["1x1"].pixels())
    for name in scenes:
        print(f"{name:9s} {seconds[name] / args.rounds:7.3f} s per bake, x{seconds[name] / seconds['constant']:.3f} "
              f"of the constant colour, mean {tuple(round(v, 4) for v in images[name].stats.mean_rgb)}")
    print(f"1x1 texture bit-identical to the constant: {same}")
    memory, texels = scenes["64x64"].texture_memory()
    print(f"texture memory: {memory} bytes for {texels} texels, {memory / texels:g} bytes per texel (float RGB)")


if __name__ == "__main__":
    main()
