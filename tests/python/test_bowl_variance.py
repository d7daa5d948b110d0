"""tools/bowl_variance.py: its shell distance at known points of the bowl, its regions against the
bake's own coverage, the tail statistics of a known list, and one small run end to end (the
figures of a 12 x 12, 2-spp run are noise: this checks the plumbing, not a ratio).

Run by ctest with DWIVEDI_LIBRARY, DWIVEDI_SOURCE_DIR and PYTHONPATH (the shim) set; standard
library only.
"""

import contextlib
import io
import json
import os
import sys
import unittest

SOURCE = os.environ.get("DWIVEDI_SOURCE_DIR", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
sys.path.insert(0, os.path.join(SOURCE, "tools"))
import bowl_variance  # noqa: E402


class ShellDistance(unittest.TestCase):
    def test_known_points(self):
        # The wall's middle at the bottom, the inner and outer surfaces there, the rim's top.
        self.assertAlmostEqual(bowl_variance.shell_distance((0.0, 0.0, -0.1425)), -0.0075, places=12)
        self.assertAlmostEqual(bowl_variance.shell_distance((0.0, 0.0, -0.135)), 0.0, places=12)
        self.assertAlmostEqual(bowl_variance.shell_distance((0.15, 0.0, 0.0)), 0.0, places=12)
        self.assertAlmostEqual(bowl_variance.shell_distance((0.0, 0.1425, 0.0075)), 0.0, places=12)
        # The centre of the opening is the arc's radius less half the wall away.
        self.assertAlmostEqual(bowl_variance.shell_distance((0.0, 0.0, 0.0)), 0.135, places=12)

    def test_tail(self):
        t = bowl_variance.tail([0.0] * 98 + [1.0, 9.0])
        self.assertAlmostEqual(t["zero"], 0.98)
        self.assertAlmostEqual(t["mean"], 0.1)
        self.assertAlmostEqual(t["max_over_mean"], 90.0)
        self.assertAlmostEqual(t["top1_square_share"], 81.0 / 82.0)


class EndToEnd(unittest.TestCase):
    def test_small_run(self):
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            self.assertEqual(bowl_variance.main(["--size", "12", "--samples", "2", "--techniques", "classical:shared",
                                                 "--single", "1"]), 0)
        text = out.getvalue()
        row = json.loads(text[text.index("\n{") + 1:])["classical:shared"]
        for region in ("all", "inside", "outside", "rim"):
            for part in ("combined", "direct", "indirect"):
                self.assertGreaterEqual(row[region][part]["variance"], 0.0)
        # The bowl is lit inside: its inside is brighter than its outside, and it has indirect light.
        self.assertGreater(row["inside"]["combined"]["mean"], row["outside"]["combined"]["mean"])
        self.assertGreater(row["all"]["indirect"]["mean"], 0.0)
        # Inside (no background in those pixels) combined is direct + indirect (DiffDir and DiffInd
        # times DiffCol) and the specular layer's glossy light, under 1% of it on the bowl.
        total = row["inside"]["direct"]["mean"] + row["inside"]["indirect"]["mean"]
        self.assertGreaterEqual(row["inside"]["combined"]["mean"], total * (1.0 - 1e-6))
        self.assertLess(row["inside"]["combined"]["mean"], total * 1.01)
        self.assertGreater(row["path_rays_per_sample"], 0.0)
        self.assertIn("single_indirect", row)


if __name__ == "__main__":
    unittest.main()
