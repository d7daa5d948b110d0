"""Scene files with image files (issue 18): textures and environment worlds from OpenEXR files
(written by dwivedi.image_files, and patched here into bad ones), extra UV layers and tangents.
`dwivedi bake` of each bad scene exits non-zero with a message that names the place in the file
and the reason, and writes nothing: a missing image file, an EXR of 0 x 0, oversized, truncated,
with a NaN texel, a binding's absent UV layer, UV layers of the wrong size, an sRGB colour space
for an EXR, a file whose SHA-256 differs from the scene's. A 1 x 1 environment file bakes as the
constant world of its colour (bit for bit) and a 100000 x 1 one bakes. Standard library only."""
import hashlib
import json
import math
import os
import shutil
import struct
import tempfile
import unittest

from cli_helpers import run_cli
import dwivedi
from dwivedi import image_files

SMALL = ["--width", "12", "--height", "8", "--spp", "2", "--quiet", "--threads", "2"]


def patched_data_window(data: bytes, max_x: int) -> bytes:
    """`data` (an EXR) with its dataWindow's max.x replaced."""
    at = data.index(b"dataWindow\0box2i\0") + len(b"dataWindow\0box2i\0") + 4 + 8
    return data[:at] + struct.pack("<i", max_x) + data[at + 4:]


class SceneFileImages(unittest.TestCase):
    def setUp(self):
        self.folder = tempfile.mkdtemp(prefix="dwivedi-images-")

    def tearDown(self):
        shutil.rmtree(self.folder, ignore_errors=True)

    def write(self, name: str, data: bytes) -> str:
        with open(os.path.join(self.folder, name), "wb") as f:
            f.write(data)
        return name

    def scene(self, textures=None, bindings=(), world=None, mesh_extra=None) -> str:
        mesh = {"material": "m", "positions": [-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0], "indices": [0, 1, 2, 0, 2, 3],
                "uvs": [0, 0, 1, 0, 1, 1, 0, 0, 1, 1, 0, 1], "uv_name": "UVMap"}
        mesh.update(mesh_extra or {})
        document = {"version": 1, "materials": {"m": {"kind": "diffuse", "textures": list(bindings)}},
                    "meshes": [mesh], "lights": [{"kind": "sun", "strength": 3}],
                    "camera": {"kind": "orthographic", "ortho_scale": 2.5,
                               "transform": {"translate": [0, 0, 5]}}}
        if textures:
            document["textures"] = textures
        if world:
            document["world"] = world
        path = os.path.join(self.folder, "scene.json")
        with open(path, "w", encoding="utf-8") as f:
            json.dump(document, f)
        return path

    def assert_refused(self, path: str, *words: str) -> None:
        prefix = os.path.join(self.folder, "out")
        result = run_cli("bake", path, "--out", prefix, *SMALL)
        self.assertNotEqual(result.returncode, 0, result.stderr)
        for word in words:
            self.assertIn(word, result.stderr)
        for suffix in (".exr", ".png", ".json"):
            self.assertFalse(os.path.exists(prefix + suffix), suffix)

    def bake(self, path: str, prefix: str) -> bytes:
        result = run_cli("bake", path, "--out", os.path.join(self.folder, prefix), *SMALL)
        self.assertEqual(result.returncode, 0, result.stderr)
        with open(os.path.join(self.folder, prefix + ".exr"), "rb") as f:
            return f.read()

    def test_bad_textures_are_refused_and_nothing_written(self):
        texels = [0.25 + 0.05 * k for k in range(3 * 4 * 2)]
        good = image_files.exr_bytes(texels, 4, 2, 3)
        bind = {"input": "base_color", "texture": "t"}
        self.assert_refused(self.scene({"t": {"file": "missing.exr"}}, [bind]),
                            "textures.t.file", "missing.exr", "No such file")
        self.write("zero.exr", patched_data_window(good, -1))
        self.assert_refused(self.scene({"t": {"file": "zero.exr"}}, [bind]), "textures.t.file", "zero.exr")
        self.write("huge.exr", patched_data_window(good, 99999))
        self.assert_refused(self.scene({"t": {"file": "huge.exr"}}, [bind]), "textures.t.file", "100000 x 2")
        self.write("cut.exr", good[:len(good) - 20])
        self.assert_refused(self.scene({"t": {"file": "cut.exr"}}, [bind]), "textures.t.file", "cannot read EXR")
        bad = list(texels)
        bad[3 * 5 + 2] = math.nan
        self.write("nan.exr", image_files.exr_bytes(bad, 4, 2, 3))
        self.assert_refused(self.scene({"t": {"file": "nan.exr"}}, [bind]), "nan.exr", "texel (1, 1) channel 2 is NaN")
        self.write("good.exr", good)
        self.assert_refused(self.scene({"t": {"file": "good.exr", "colorspace": "srgb"}}, [bind]),
                            "textures.t", "scene-linear floats")
        self.assert_refused(self.scene({"t": {"file": "good.exr", "sha256": "ab" * 32}}, [bind]),
                            "textures.t.file", "not the file the scene was written with")
        self.assert_refused(self.scene({"t": {"file": "good.exr"}}, [dict(bind, uv_layer="Detail")]),
                            "no UV layer", "Detail")
        self.assert_refused(self.scene({"t": {"file": "good.exr"}}, [bind],
                                       mesh_extra={"uv_layers": [{"name": "Detail", "uvs": [0.5] * 18}]}),
                            "meshes[0].uv_layers[0].uvs", "one (u, v) per triangle corner")
        self.assert_refused(self.scene({"t": {"file": "good.exr"}}, [bind], mesh_extra={"tangents": [1, 0, 0, 1] * 5}),
                            "meshes[0].tangents")
        # The good file with its right hash and an extra UV layer with tangents bakes.
        digest = hashlib.sha256(good).hexdigest()
        layer = {"name": "Detail", "uvs": [0.2] * 12, "tangents": [1, 0, 0, -1] * 6}
        self.bake(self.scene({"t": {"file": "good.exr", "sha256": digest}}, [dict(bind, uv_layer="Detail")],
                             mesh_extra={"uv_layers": [layer], "tangents": [0, 1, 0, 1] * 6}), "good")

    def test_environment_files(self):
        one = self.write("one.exr", image_files.exr_bytes([0.25, 0.5, 0.75], 1, 1, 3))
        settings = dict(width=12, height=8, samples=2, threads=2)
        constant = dwivedi.Scene.load(self.scene(world={"color": [0.25, 0.5, 0.75], "strength": 0.5})).bake(**settings)
        from_file = dwivedi.Scene.load(self.scene(world={"environment": {"file": one, "strength": 0.5}})).bake(**settings)
        self.assertEqual(bytes(constant.rgba), bytes(from_file.rgba))
        self.assertGreater(constant.stats.mean_rgb[2], 0.0)
        wide = self.write("wide.exr", image_files.exr_bytes([0.1 + (k % 7) * 0.05 for k in range(300000)], 100000, 1, 3,
                                                            half=True))
        self.bake(self.scene(world={"environment": {"file": wide, "rotation": [0, -1, 0, 1, 0, 0, 0, 0, 1]}}), "wide")
        sky = image_files.exr_bytes([0.5] * 24, 4, 2, 3)
        self.write("cut.exr", sky[:-10])
        self.assert_refused(self.scene(world={"environment": {"file": "cut.exr"}}), "world.environment.file",
                            "cannot read EXR")
        self.assert_refused(self.scene(world={"environment": {"file": "none.hdr"}}), "world.environment.file",
                            "none.hdr")
        self.write("sky.exr", sky)
        self.assert_refused(self.scene(world={"environment": {"file": "sky.exr", "rotate": [0, 0, 90],
                                                              "rotation": [1, 0, 0, 0, 1, 0, 0, 0, 1]}}),
                            "world.environment", "either 'rotate'")
        self.assert_refused(self.scene(world={"environment": {"file": "sky.exr", "width": 4}}), "world.environment",
                            "either 'file'")
        self.assert_refused(self.scene(world={"environment": {"file": "sky.exr", "rotation": [1, 0, 0, 0, 1, 0, 0, 0, -1]}}),
                            "world.environment.file", "mirrors")

    def test_shim_file_calls(self):
        """Scene.add_texture_file and set_world_environment_file: the same bits as in memory."""
        texels = [((k * 5) % 9) / 8.0 for k in range(3 * 5 * 4)]
        sky = [0.2 + ((k * 7) % 11) / 10.0 for k in range(3 * 8 * 4)]
        tex = self.write("tex.exr", image_files.exr_bytes(texels, 5, 4, 3, half=True))
        env = self.write("env.exr", image_files.exr_bytes(sky, 8, 4, 3))
        rotation = [0, -1, 0, 1, 0, 0, 0, 0, 1]

        def build(from_files):
            scene = dwivedi.Scene()
            material = scene.add_material(dwivedi.Material.diffuse((0.5, 0.5, 0.5)))
            if from_files:
                texture = scene.add_texture_file(os.path.join(self.folder, tex), interpolation="closest")
                scene.set_world_environment_file(os.path.join(self.folder, env), strength=0.7, rotation=rotation)
            else:
                texture = scene.add_texture(texels, 5, 4, 3, interpolation="closest")
                scene.set_world_environment(sky, 8, 4, strength=0.7, rotation=rotation)
            scene.bind_texture(material, "base_color", texture)
            scene.add_mesh([-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0], [0, 1, 2, 0, 2, 3], material,
                           uvs=[0, 0, 1, 0, 1, 1, 0, 0, 1, 1, 0, 1])
            scene.add_light(dwivedi.SunLight(strength=2.0))
            scene.set_camera(dwivedi.Camera.look_at((0.3, -2.0, 1.5), (0, 0, 0)))
            return scene.commit()

        settings = dict(width=12, height=8, samples=2, threads=2)
        a, b = build(True).bake(**settings), build(False).bake(**settings)
        self.assertEqual(bytes(a.rgba), bytes(b.rgba))
        with self.assertRaises(dwivedi.Error) as caught:
            dwivedi.Scene().add_texture_file(os.path.join(self.folder, tex), format="srgb8")
        self.assertIn("scene-linear floats", str(caught.exception))


if __name__ == "__main__":
    unittest.main()
