"""The benchmark set of tools/benchmark_scenes.py (issue 20): every scene's mesh is closed and
turned outward, its scene file loads and bakes to a lit image, and tools/cycles_report.py takes
the set's names (one by one or as `benchmark`) and refuses others. The real-asset scenes (issue
18, built in Blender only): their meshes closed and outward, their UVs without a triangle across
the image, their generated images in range and the HDRI's hot spot where its sun is."""
import math
import os
import subprocess
import sys
import tempfile
import unittest
from collections import Counter
from pathlib import Path

SOURCE_DIR = Path(os.environ.get("DWIVEDI_SOURCE_DIR", Path(__file__).resolve().parents[2]))
sys.path.append(str(SOURCE_DIR / "python_shim"))
sys.path.append(str(SOURCE_DIR / "tools"))

import benchmark_scenes  # noqa: E402
import dwivedi  # noqa: E402


def signed_volume(points, tris):
    total = 0.0
    for a, b, c in tris:
        pa, pb, pc = points[a], points[b], points[c]
        total += (pa[0] * (pb[1] * pc[2] - pb[2] * pc[1]) - pa[1] * (pb[0] * pc[2] - pb[2] * pc[0]) +
                  pa[2] * (pb[0] * pc[1] - pb[1] * pc[0])) / 6.0
    return total


class BenchmarkScenesTest(unittest.TestCase):
    def test_set_covers_the_issue(self):
        self.assertGreaterEqual(len(benchmark_scenes.NAMES), 8)
        kinds = {light["kind"] for s in benchmark_scenes.SCENES.values() for light in s["lights"]}
        self.assertEqual(kinds, {"sun", "area", "point"})
        self.assertTrue(any(not s["lights"] and s["world"][1] > 0 for s in benchmark_scenes.SCENES.values()),
                        "a scene lit by the world alone")

    def assert_closed_outward(self, name, points, tris):
        edges = Counter((t[i], t[(i + 1) % 3]) for t in tris for i in range(3))
        bad = [e for e, n in edges.items() if n != 1 or edges.get((e[1], e[0])) != 1]
        self.assertEqual(bad, [], f"{name}: {len(bad)} edges not shared by two opposite triangles")
        self.assertGreater(signed_volume(points, tris), 0.0, f"{name}: turned inward")

    def test_asset_meshes_and_images(self):
        b = benchmark_scenes
        self.assertEqual(set(b.NAMES), set(b.SCENES) | set(b.ASSET_SCENES))
        points, tris = b.outward(*b.head())
        self.assert_closed_outward("head_asset", points, tris)
        uvs = b.head_uvs(points, tris)
        self.assertEqual(len(uvs), 3 * len(tris))
        spans = [max(u for u, _ in uvs[k:k + 3]) - min(u for u, _ in uvs[k:k + 3]) for k in range(0, len(uvs), 3)]
        # The pole's fans span a fifth of the longitudes; a triangle across the seam would span it all.
        self.assertLess(max(spans), 0.25, "a head triangle spans the image (the seam not wrapped)")
        self.assert_closed_outward("candle", *b.outward(*b.cylinder(0.04, 0.16)))
        points, tris, uv = b.leaf(0.3, 0.14, 0.003)
        self.assertEqual(len(uv), len(points))
        self.assert_closed_outward("leaf_textured", *b.outward(points, tris))
        for texel in (b.skin_texel, b.pore_normal_texel, b.leaf_texel, b.leaf_radius_texel):
            values = [c for i in range(16) for j in range(16) for c in texel((i + 0.5) / 16, (j + 0.5) / 16)]
            self.assertTrue(all(0.0 <= c <= 1.0 for c in values), texel.__name__)
            self.assertGreater(max(values) - min(values), 0.05, f"{texel.__name__}: no detail")
        width, height, sun = 64, 32, (-0.6, -0.6, 0.5)
        hdri = b.hdri_texels(width, height, sun, 600.0)
        self.assertEqual(len(hdri), 4 * width * height)
        brightest = max(range(width * height), key=lambda k: hdri[4 * k])
        theta = math.pi * (1.0 - (brightest // width + 0.5) / height)
        phi = math.pi * (1.0 - 2.0 * (brightest % width + 0.5) / width)
        d = (math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta))
        s = b._normalise(sun)
        self.assertLess(math.degrees(math.acos(sum(x * y for x, y in zip(d, s)))), 6.0, "the hot spot is not at the sun")
        with tempfile.TemporaryDirectory() as tmp:
            self.assertEqual(b.main(["--json", tmp, "--scenes", "candle"]), 1)

    def test_meshes_closed_and_outward(self):
        for name in benchmark_scenes.SCENES:
            points, tris, _ = benchmark_scenes.mesh_of(name)
            edges = Counter((t[i], t[(i + 1) % 3]) for t in tris for i in range(3))
            # Closed and consistently turned: every directed edge once, its reverse once.
            bad = [e for e, n in edges.items() if n != 1 or edges.get((e[1], e[0])) != 1]
            self.assertEqual(bad, [], f"{name}: {len(bad)} edges not shared by two opposite triangles")
            self.assertGreater(signed_volume(points, tris), 0.0, f"{name}: turned inward")
            self.assertTrue(all(math.isfinite(c) for p in points for c in p), name)

    def test_scene_files_bake(self):
        with tempfile.TemporaryDirectory() as tmp:
            self.assertEqual(benchmark_scenes.main(["--json", tmp, "--size", "8", "--samples", "2"]), 0)
            for name in benchmark_scenes.SCENES:
                with dwivedi.Scene.load(os.path.join(tmp, name + ".json")) as scene:
                    with dwivedi.bake(scene, width=8, height=8, samples=2, threads=1, seed=1) as image:
                        pixels = list(image.pixels())
                rgb = [v for i, v in enumerate(pixels) if i % 4 != 3]
                self.assertTrue(all(math.isfinite(v) and v >= 0.0 for v in rgb), name)
                self.assertGreater(sum(rgb), 0.0, f"{name}: a black image")
            self.assertEqual(benchmark_scenes.main(["--json", tmp, "--scenes", "nosuch"]), 1)

    def test_report_takes_the_names(self):
        report = SOURCE_DIR / "tools" / "cycles_report.py"
        env = {**os.environ, "PYTHONPATH": str(SOURCE_DIR / "python_shim")}
        with tempfile.TemporaryDirectory() as tmp:
            ok = subprocess.run([sys.executable, str(report), "--sections", "cycles", "--no-cycles", "--cycles-scenes",
                                 "benchmark,torus", "--out", tmp], capture_output=True, text=True, env=env, timeout=120)
            self.assertEqual(ok.returncode, 0, ok.stderr[-2000:])
            self.assertIn("Not run: --no-cycles", (Path(tmp) / "report.md").read_text())
            bad = subprocess.run([sys.executable, str(report), "--sections", "cycles", "--no-cycles", "--cycles-scenes",
                                  "nosuch", "--out", tmp], capture_output=True, text=True, env=env, timeout=120)
            self.assertEqual(bad.returncode, 1)
            self.assertIn("unknown section, scene or Blender 'nosuch'", bad.stderr)
            for budget in ("0", "-3", "nan"):
                bad = subprocess.run([sys.executable, str(report), "--sections", "cycles", "--no-cycles",
                                      "--budget-minutes", budget, "--out", tmp], capture_output=True, text=True,
                                     env=env, timeout=120)
                self.assertEqual(bad.returncode, 1, budget)
                self.assertIn("is not a positive number of minutes", bad.stderr)


if __name__ == "__main__":
    unittest.main()
