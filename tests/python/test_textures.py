"""Textures through the shim (Scene.add_texture, bind_texture, add_mesh's UV layers) and scene
files (docs/scene-format.md "Textures"): a diffuse quad under a sun of irradiance pi, seen straight
on, bakes to its albedo, so a texture's mean and its texels per pixel are the answer; refused
inputs raise dwivedi.Error with the library's message.

Run by ctest with DWIVEDI_LIBRARY set (tests/CMakeLists.txt). Standard library only.
"""
import json
import math
import os
import struct
import sys
import tempfile
import unittest
import zlib
from pathlib import Path

SOURCE_DIR = Path(os.environ.get("DWIVEDI_SOURCE_DIR", Path(__file__).resolve().parents[2]))
sys.path.append(str(SOURCE_DIR / "python_shim"))

import dwivedi  # noqa: E402

QUAD = dict(positions=[-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0], indices=[0, 1, 2, 0, 2, 3])
QUAD_UVS = [0, 0, 1, 0, 1, 1, 0, 0, 1, 1, 0, 1]
# A second layer mirrored in u: what a binding to it must see.
QUAD_UVS_MIRRORED = [1 - x if k % 2 == 0 else x for k, x in enumerate(QUAD_UVS)]
# 2 x 2 texels, row 0 at v = 0: (0.2, 0.4) bottom, (0.6, 0.8) top, in red; green 0.1.
GRID = [0.2, 0.1, 0.0, 0.4, 0.1, 0.0, 0.6, 0.1, 0.0, 0.8, 0.1, 0.0]


def quad_scene(layer=None):
    scene = dwivedi.Scene()
    material = scene.add_material(dwivedi.Material.diffuse((0.8, 0.8, 0.8)))
    texture = scene.add_texture(GRID, 2, 2, 3, interpolation="closest")
    scene.bind_texture(material, "base_color", texture, uv_layer=layer)
    scene.add_mesh(QUAD["positions"], QUAD["indices"], material, uvs=QUAD_UVS, uv_name="UVMap",
                   uv_layers=[("Mirrored", QUAD_UVS_MIRRORED)])
    scene.add_light(dwivedi.SunLight(direction=(0, 0, -1), strength=math.pi))
    scene.set_camera(dwivedi.Camera(kind="orthographic", transform=[1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 5],
                                    ortho_scale=2.0))
    return scene.commit()



def png_rgb8(path, width, height, rows):
    """Writes an 8-bit RGB PNG (rows top first) with zlib only."""
    raw = b"".join(b"\x00" + bytes(row) for row in rows)

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    Path(path).write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw))
                           + chunk(b"IEND", b""))


class Textures(unittest.TestCase):
    def bake_mean(self, scene, size=16):
        image = scene.bake(width=size, height=size, samples=2, threads=2)
        return image.stats.mean_rgb, image

    def test_texture_mean_and_layers(self):
        mean, image = self.bake_mean(quad_scene())
        self.assertAlmostEqual(mean[0], 0.5, delta=1e-4)
        self.assertAlmostEqual(mean[1], 0.1, delta=1e-4)
        with quad_scene("Mirrored") as scene:
            mean_m, image_m = self.bake_mean(scene)
        self.assertAlmostEqual(mean_m[0], 0.5, delta=1e-4)
        first, mirrored = image.pixels(), image_m.pixels()
        # Bottom-left pixel (row 15): texel (0, 0) = 0.2 plainly, texel (1, 0) = 0.4 mirrored in u.
        corner = 4 * (16 * 15)
        self.assertAlmostEqual(first[corner], 0.2, delta=1e-4)
        self.assertAlmostEqual(mirrored[corner], 0.4, delta=1e-4)

    def test_texture_memory_per_texel(self):
        with dwivedi.Scene() as scene:
            scene.add_texture(GRID, 2, 2, 3)
            scene.add_texture(bytes(range(16)), 2, 2, 4, format="srgb8")
            size, texels = scene.texture_memory()
        self.assertEqual((size, texels), (2 * 2 * 12 + 2 * 2 * 4, 8))

    def test_refusals(self):
        with dwivedi.Scene() as scene:
            with self.assertRaisesRegex(dwivedi.Error, "0 x 0"):
                scene.add_texture([], 0, 0, 3)
            with self.assertRaisesRegex(dwivedi.Error, "NaN"):
                scene.add_texture([0.5, float("nan"), 0.5], 1, 1, 3)
            with self.assertRaisesRegex(dwivedi.Error, "needs 12"):
                scene.add_texture([0.5] * 11, 2, 2, 3)
            with self.assertRaisesRegex(dwivedi.Error, "format"):
                scene.add_texture(GRID, 2, 2, 3, format="half")
            material = scene.add_material(dwivedi.Material.diffuse((0.5, 0.5, 0.5)))
            grey = scene.add_texture([0.5] * 4, 2, 2, 1)
            with self.assertRaisesRegex(dwivedi.Error, "1 channel"):
                scene.bind_texture(material, "base_color", grey)
            with self.assertRaisesRegex(dwivedi.Error, "texture_id = 7"):
                scene.bind_texture(material, "roughness", 7)
            scene.bind_texture(material, "roughness", grey, uv_layer="Missing")
            scene.add_mesh(QUAD["positions"], QUAD["indices"], material, uvs=QUAD_UVS, uv_name="UVMap")
            with self.assertRaisesRegex(dwivedi.Error, 'no UV layer "Missing"'):
                scene.commit()

    def test_scene_file(self):
        with tempfile.TemporaryDirectory() as folder:
            # The same grid as 8-bit sRGB in a PNG (rows top first) and inline in JSON.
            png_rgb8(Path(folder) / "grid.png", 2, 2, [[153, 26, 0, 204, 26, 0], [26, 26, 0, 102, 26, 0]])
            scene = {
                "version": 1,
                "textures": {
                    "grid": {"file": "grid.png", "colorspace": "srgb", "interpolation": "closest"},
                    "inline": {"width": 2, "height": 2, "channels": 3, "texels": GRID, "interpolation": "closest"},
                },
                "materials": {"a": {"kind": "diffuse", "textures": [{"input": "base_color", "texture": "inline"}]},
                              "b": {"kind": "diffuse", "textures": [{"input": "base_color", "texture": "grid",
                                                                    "uv_layer": "UVMap"}]}},
                "meshes": [{"material": "a", "uvs": QUAD_UVS, "uv_name": "UVMap", **QUAD}],
                "lights": [{"kind": "sun", "strength": math.pi, "direction": [0, 0, -1]}],
                "camera": {"kind": "orthographic", "ortho_scale": 2,
                           "transform": {"translate": [0, 0, 5]}},
                "bake": {"width": 16, "height": 16, "samples": 2},
            }
            path = Path(folder) / "scene.json"
            path.write_text(json.dumps(scene))
            loaded = dwivedi.Scene.load(path)
            mean, _ = self.bake_mean(loaded)
            self.assertAlmostEqual(mean[0], 0.5, delta=1e-4)
            scene["meshes"][0]["material"] = "b"
            path.write_text(json.dumps(scene))
            loaded = dwivedi.Scene.load(path)
            mean, image = self.bake_mean(loaded)
            srgb = [((c / 255 + 0.055) / 1.055) ** 2.4 for c in (26, 102, 153, 204)]
            self.assertAlmostEqual(mean[0], sum(srgb) / 4, delta=1e-4)
            # The PNG's bottom row (its last) is v = 0: the bottom-left pixel reads 26.
            self.assertAlmostEqual(image.pixels()[4 * 16 * 15], srgb[0], delta=1e-4)
            # A missing image file: the message names it; no scene.
            scene["textures"]["grid"]["file"] = "absent.png"
            path.write_text(json.dumps(scene))
            with self.assertRaisesRegex(dwivedi.Error, "absent.png"):
                dwivedi.Scene.load(path)


if __name__ == "__main__":
    unittest.main()
