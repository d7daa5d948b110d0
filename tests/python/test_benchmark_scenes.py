"""The benchmark set of tools/benchmark_scenes.py (issue 20): every scene's mesh is closed and
turned outward, its scene file loads and bakes to a lit image, and tools/cycles_report.py takes
the set's names (one by one or as `benchmark`) and refuses others."""
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

    def test_meshes_closed_and_outward(self):
        for name in benchmark_scenes.NAMES:
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
            for name in benchmark_scenes.NAMES:
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


if __name__ == "__main__":
    unittest.main()
