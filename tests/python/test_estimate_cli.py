"""Tests of `dwivedi estimate` (src/cli/estimate.c): help, the JSON output's keys and values, RGB
output, results that do not depend on --threads, and the usage-error contract (exit 2, nothing on
stdout, one line on stderr starting with "dwivedi").

Run by ctest (see tests/CMakeLists.txt), which sets DWIVEDI_CLI. Standard library only.
"""
import math
import unittest
from typing import Dict, List

from cli_helpers import assert_bad_usage, listed_verbs, run_cli, run_json

JSON_KEYS = {"technique", "channels", "mean", "stderr", "variance", "walks", "events", "seconds", "efficiency",
             "truncated_weight", "truncated_walks"}
PER_CHANNEL_KEYS = ("mean", "stderr", "variance", "truncated_weight")
# A small valid run; the bad-argument cases below change or drop one thing of it.
SMALL_RUN = ["--scene", "halfspace", "--albedo", "0.5", "--technique", "auto", "--walks", "20000", "--seed", "7",
             "--threads", "1"]


def without(args: List[str], flag: str) -> List[str]:
    """args with flag and its value removed."""
    i = args.index(flag)
    return args[:i] + args[i + 2:]


def replaced(args: List[str], flag: str, value: str) -> List[str]:
    """args with flag's value set to value (appended if flag is absent)."""
    if flag not in args:
        return args + [flag, value]
    i = args.index(flag)
    return args[:i + 1] + [value] + args[i + 2:]


class EstimateHelpTest(unittest.TestCase):
    def test_help(self) -> None:
        for args in (["estimate", "--help"], ["estimate", "-h"], ["estimate", *SMALL_RUN, "--help"]):
            with self.subTest(args=args):
                done = run_cli(*args)
                self.assertEqual(done.returncode, 0, done.stderr)
                self.assertEqual(done.stderr, "")
                self.assertIn("usage: dwivedi estimate", done.stdout)
                for word in ("--scene", "--albedo", "--technique", "--walks", "--threads", "--json", "auto",
                             "classical", "poe", "closest", "incident", "backward", "cycles", "sheet"):
                    self.assertIn(word, done.stdout)

    def test_listed_by_dwivedi_help(self) -> None:
        done = run_cli("--help")
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertIn("estimate", listed_verbs(done.stdout))


class EstimateJsonTest(unittest.TestCase):
    def estimate_json(self, *args: str) -> Dict[str, object]:
        return run_json(self, JSON_KEYS, "estimate", *args)

    def assert_channel_sane(self, mean: float, stderr: float, variance: float, truncated: float,
                            walks: int) -> None:
        for value in (mean, stderr, variance, truncated):
            # %.17g writes a whole number without a point (0 for no truncated weight): a JSON number.
            self.assertIsInstance(value, (int, float))
            self.assertNotIsInstance(value, bool)
            self.assertTrue(math.isfinite(value), value)
        # A front-lit half-space reflects a fraction of the light: strictly between 0 and 1, and
        # known to several standard errors from 20000 walks.
        self.assertGreater(mean, 0.0)
        self.assertLess(mean, 1.0)
        self.assertGreater(variance, 0.0)
        self.assertLess(stderr, 0.1 * mean)
        self.assertAlmostEqual(stderr, math.sqrt(variance / walks), delta=1e-12 * stderr)
        self.assertEqual(truncated, 0.0)

    def test_small_run(self) -> None:
        result = self.estimate_json(*SMALL_RUN)
        self.assertEqual(result["technique"], "auto")
        self.assertEqual(result["channels"], 1)
        self.assertEqual(result["walks"], 20000)
        self.assertIsInstance(result["walks"], int)
        self.assertIsInstance(result["events"], int)
        # Normal incidence into a half-space: the first step cannot leave, so every walk scatters.
        self.assertGreaterEqual(result["events"], result["walks"])
        self.assertEqual(result["truncated_walks"], 0)
        self.assert_channel_sane(result["mean"], result["stderr"], result["variance"], result["truncated_weight"],
                                 result["walks"])
        self.assertIsInstance(result["seconds"], (int, float))
        self.assertGreaterEqual(result["seconds"], 0.0)
        # 1 / (variance x seconds per walk): positive, or null where the run took no measurable time.
        if result["efficiency"] is not None:
            self.assertGreater(result["efficiency"], 0.0)

    def test_technique_is_echoed(self) -> None:
        for technique in ("classical", "poe", "closest", "incident", "backward", "cycles", "sheet"):
            with self.subTest(technique=technique):
                result = self.estimate_json(*replaced(replaced(SMALL_RUN, "--technique", technique), "--walks", "200"))
                self.assertEqual(result["technique"], technique)
                self.assertEqual(result["walks"], 200)

    def test_rgb(self) -> None:
        result = self.estimate_json(*replaced(SMALL_RUN, "--albedo", "0.3,0.6,0.9"))
        self.assertEqual(result["channels"], 3)
        for key in PER_CHANNEL_KEYS:
            self.assertIsInstance(result[key], list, key)
            self.assertEqual(len(result[key]), 3, key)
        for c in range(3):
            with self.subTest(channel=c):
                self.assert_channel_sane(result["mean"][c], result["stderr"][c], result["variance"][c],
                                         result["truncated_weight"][c], result["walks"])
        # More scattering, more light back out: ordered as the albedos, far beyond the errors.
        for c in range(2):
            self.assertGreater(result["mean"][c + 1] - result["mean"][c],
                               5.0 * (result["stderr"][c] + result["stderr"][c + 1]))

    def test_three_extinctions_make_three_channels(self) -> None:
        result = self.estimate_json(*(SMALL_RUN + ["--sigma-t", "1,2,3"]))
        self.assertEqual(result["channels"], 3)
        for key in PER_CHANNEL_KEYS:
            self.assertEqual(len(result[key]), 3, key)
        # One albedo for all: the reflectance of a half-space does not depend on the length unit,
        # so the three channels estimate the same number (fixed seed; 5 standard errors).
        for c in (1, 2):
            self.assertLess(abs(result["mean"][c] - result["mean"][0]),
                            5.0 * (result["stderr"][c] + result["stderr"][0]))

    def test_threads_do_not_change_the_result(self) -> None:
        for scene in (["--scene", "halfspace"], ["--scene", "slab", "--thickness", "2", "--light", "both"]):
            with self.subTest(scene=scene):
                base = replaced(replaced(SMALL_RUN, "--seed", "12345"), "--walks", "5000") + scene[2:]
                base = replaced(base, "--scene", scene[1])
                one = self.estimate_json(*replaced(base, "--threads", "1"))
                two = self.estimate_json(*replaced(base, "--threads", "2"))
                # %.17g round-trips a double: the same walks summed in the same blocks give the
                # same bits.
                for key in ("mean", "stderr", "variance", "events", "walks", "truncated_weight", "truncated_walks"):
                    self.assertEqual(one[key], two[key], key)
                other_seed = self.estimate_json(*replaced(replaced(base, "--threads", "2"), "--seed", "12346"))
                self.assertNotEqual(one["mean"], other_seed["mean"])


class EstimateUsageErrorTest(unittest.TestCase):
    def assert_usage_error(self, args: List[str], names: str) -> None:
        """Exit 2, nothing on stdout, one line on stderr that starts with "dwivedi" and names the
        offending flag or value (`names`)."""
        assert_bad_usage(self, ["estimate", *args], "dwivedi", [names])

    def test_the_small_run_itself_is_valid(self) -> None:
        # Each case below differs from SMALL_RUN in one thing, so its failure is that thing's doing.
        done = run_cli("estimate", *replaced(SMALL_RUN, "--walks", "100"))
        self.assertEqual(done.returncode, 0, done.stderr)

    def test_missing_required_flags(self) -> None:
        for flag in ("--scene", "--albedo", "--technique", "--walks"):
            with self.subTest(missing=flag):
                self.assert_usage_error(without(SMALL_RUN, flag), flag)

    def test_unknown_names(self) -> None:
        cases = [(replaced(SMALL_RUN, "--scene", "cube"), "cube"),
                 (replaced(SMALL_RUN, "--technique", "magic"), "magic"),
                 (replaced(SMALL_RUN, "--technique", "Auto"), "Auto"),
                 (replaced(SMALL_RUN, "--scene", "slab") + ["--light", "sideways"], "sideways"),
                 (SMALL_RUN + ["--colour", "red"], "--colour"),
                 (SMALL_RUN + ["--fast"], "--fast"),
                 (SMALL_RUN + ["stray"], "stray")]
        for args, names in cases:
            with self.subTest(args=args):
                self.assert_usage_error(args, names)

    def test_bad_values(self) -> None:
        cases = {
            "albedo 1.5": (replaced(SMALL_RUN, "--albedo", "1.5"), "albedo"),
            "albedo nan": (replaced(SMALL_RUN, "--albedo", "nan"), "albedo"),
            "albedo two values": (replaced(SMALL_RUN, "--albedo", "0.1,0.2"), "--albedo"),
            "albedo four values": (replaced(SMALL_RUN, "--albedo", "0.1,0.2,0.3,0.4"), "--albedo"),
            "albedo not a number": (replaced(SMALL_RUN, "--albedo", "half"), "half"),
            "sigma-t 0": (SMALL_RUN + ["--sigma-t", "0"], "sigma"),
            "anisotropy 1": (SMALL_RUN + ["--anisotropy", "1"], "anisotropy"),
            "incidence 0": (SMALL_RUN + ["--incidence", "0"], "incidence"),
            "incidence 2": (SMALL_RUN + ["--incidence", "2"], "incidence"),
            "walks 1": (replaced(SMALL_RUN, "--walks", "1"), "walks"),
            "walks -5": (replaced(SMALL_RUN, "--walks", "-5"), "walks"),
            "walks 1e3": (replaced(SMALL_RUN, "--walks", "1e3"), "walks"),
            "walks 10^13": (replaced(SMALL_RUN, "--walks", "10000000000000"), "walks"),
            "threads 1000": (replaced(SMALL_RUN, "--threads", "1000"), "threads"),
            "slab thickness 0": (replaced(SMALL_RUN, "--scene", "slab") + ["--thickness", "0"], "thickness"),
            "halfspace lit from the back": (SMALL_RUN + ["--light", "back"], "back"),
            "a flag without its value": (SMALL_RUN + ["--seed"], "--seed"),
        }
        for name, (args, names) in cases.items():
            with self.subTest(case=name):
                self.assert_usage_error(args, names)


if __name__ == "__main__":
    unittest.main()
