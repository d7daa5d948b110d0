"""Bake passes through the shim, the scene file and the CLI (issue 18 item 5): BakeSettings.passes
by Blender's names, Image.passes / pass_image / bake_type / write_exr_layers, bake_type_passes and
its refusals, a scene file's bake.passes (and its bad values), `dwivedi bake --passes` writing
PREFIX.layers.exr, and a split bake's chunk refusing passes. Standard library only; about 2 s.
Run by ctest, which sets DWIVEDI_LIBRARY, DWIVEDI_CLI, DWIVEDI_SOURCE_DIR and PYTHONPATH."""
import json
import os
import sys
import tempfile
import unittest
from pathlib import Path

SOURCE_DIR = Path(os.environ.get("DWIVEDI_SOURCE_DIR", Path(__file__).resolve().parents[2]))
sys.path.append(str(SOURCE_DIR / "python_shim"))

import dwivedi  # noqa: E402
from cli_helpers import run_cli  # noqa: E402

SMALL = dict(width=12, height=10, samples=4, threads=2, seed=3)


class ShimPasses(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.scene = dwivedi.Scene.default()
        cls.image = cls.scene.bake(dwivedi.BakeSettings(passes=("DiffDir", "GlossDir", "Env"), **SMALL))

    @classmethod
    def tearDownClass(cls):
        cls.image.close()
        cls.scene.close()

    def test_names_and_colours_held(self):
        self.assertEqual(self.image.passes, ("Combined", "DiffDir", "DiffCol", "GlossDir", "GlossCol", "Env"))
        self.assertEqual(dwivedi.PASS_NAMES[0], "Combined")

    def test_diffuse_type_is_direct_times_colour(self):
        light = self.image.bake_type("DIFFUSE", {"direct", "color"})
        direct, colour = self.image.pass_image("DiffDir"), self.image.pass_image("DiffCol")
        for i, (a, d, k) in enumerate(zip(light.pixels(), direct.pixels(), colour.pixels())):
            if i % 4 == 3:
                self.assertEqual(a, d)  # the combined image's alpha in both
            elif k > 0.0:
                self.assertAlmostEqual(a, d * k, delta=1e-5 * max(abs(a), 1e-3))
        for img in (light, direct, colour):
            img.close()

    def test_layers_file(self):
        with tempfile.TemporaryDirectory() as folder:
            path = Path(folder) / "layers.exr"
            self.image.write_exr_layers(path)
            data = path.read_bytes()
            for name in (b"Combined.R", b"DiffDir.G", b"GlossCol.B", b"Env.R"):
                self.assertIn(name, data)

    def test_refusals(self):
        with self.assertRaisesRegex(ValueError, "unknown pass 'Diffuse'"):
            dwivedi.BakeSettings(passes=("Diffuse",))._to_c()
        with self.assertRaises(TypeError):
            dwivedi.BakeSettings(passes="DiffDir")._to_c()
        with self.assertRaisesRegex(dwivedi.Error, "selects nothing"):
            dwivedi.bake_type_passes("GLOSSY", set())
        with self.assertRaisesRegex(ValueError, "unknown bake type"):
            dwivedi.bake_type_passes("NORMAL", {"direct"})
        with self.assertRaisesRegex(dwivedi.Error, "holds no TransDir"):
            self.image.pass_image("TransDir")
        with self.assertRaisesRegex(dwivedi.Error, "split bake"):
            self.scene.bake(dwivedi.BakeSettings(passes=("DiffCol",), sample_count=2, **SMALL))

    def test_bake_type_passes(self):
        self.assertEqual(dwivedi.bake_type_passes("COMBINED", {"direct", "diffuse", "emit"}), ("DiffDir", "Emit"))
        self.assertEqual(dwivedi.bake_type_passes("DIFFUSE", {"color"}), ("DiffCol",))


class SceneFilePasses(unittest.TestCase):
    def test_json_passes(self):
        scene_path = SOURCE_DIR / "examples" / "scenes" / "uv_tile.json"
        document = json.loads(scene_path.read_text())
        document["bake"]["passes"] = ["DiffDir", "Emit"]
        dwivedi.Scene.from_json(json.dumps(document), base_dir=scene_path.parent).close()
        for bad, message in ((["DiffDir", "DiffDir"], "listed twice"), (["Shadow"], "unknown pass"),
                             ("DiffDir", "array")):
            document["bake"]["passes"] = bad
            with self.assertRaisesRegex(dwivedi.Error, message):
                dwivedi.Scene.from_json(json.dumps(document), base_dir=scene_path.parent)

    def test_cli_layers(self):
        # run_cli fails (never skips) where ctest did not set DWIVEDI_CLI.
        with tempfile.TemporaryDirectory() as folder:
            prefix = Path(folder) / "out"
            run = run_cli("bake", "--out", str(prefix), "--spp", "2", "--width", "8", "--height", "8",
                          "--passes", "DiffDir,Env", "--quiet")
            self.assertEqual(run.returncode, 0, run.stderr)
            self.assertIn("out.layers.exr", run.stdout)
            self.assertIn(b"DiffCol.R", (Path(folder) / "out.layers.exr").read_bytes())
            bad = run_cli("bake", "--out", str(prefix), "--passes", "DiffDir,,Env")
            self.assertNotEqual(bad.returncode, 0)
            self.assertIn("--passes", bad.stderr)


if __name__ == "__main__":
    unittest.main()
