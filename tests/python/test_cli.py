"""Tests of the `dwivedi` command (src/cli): help, the v0 verb's output against the shim and the
mpmath reference table, and the usage-error contract (exit 2, nothing on stdout, one line on stderr
starting with "dwivedi").

Run by ctest (see tests/CMakeLists.txt), which sets DWIVEDI_CLI, DWIVEDI_LIBRARY,
DWIVEDI_SOURCE_DIR and PYTHONPATH. Standard library only.
"""
import math
import unittest
from typing import Dict, List, Optional

from cli_helpers import assert_bad_usage, listed_verbs, run_cli, run_json
from test_shim import header_version, read_v0_reference, relative_error

import dwivedi

JSON_KEYS = {"albedo", "method", "v0", "kappa", "one_minus_kappa", "log_one_minus_kappa"}

def json_number(value: float) -> Optional[float]:
    """How the CLI writes a double in JSON: itself, or null where it is not finite."""
    return value if math.isfinite(value) else None


class HelpTest(unittest.TestCase):
    def test_help_lists_the_verbs(self) -> None:
        for flag in ("--help", "-h"):
            with self.subTest(flag=flag):
                done = run_cli(flag)
                self.assertEqual(done.returncode, 0)
                self.assertEqual(done.stderr, "")
                self.assertIn("usage: dwivedi", done.stdout)
                verbs = listed_verbs(done.stdout)
                self.assertIn("v0", verbs)
                self.assertIn("bench", verbs)

    def test_version(self) -> None:
        done = run_cli("--version")
        self.assertEqual(done.returncode, 0)
        self.assertEqual(done.stdout, f"dwivedi {header_version()}\n")

    def test_v0_help(self) -> None:
        for args in (["v0", "--help"], ["v0", "-h"], ["v0", "--albedo", "0.5", "--help"]):
            with self.subTest(args=args):
                done = run_cli(*args)
                self.assertEqual(done.returncode, 0)
                self.assertEqual(done.stderr, "")
                self.assertIn("usage: dwivedi v0", done.stdout)
                for word in ("--albedo", "--method", "--json") + dwivedi.methods():
                    self.assertIn(word, done.stdout)


class V0Test(unittest.TestCase):
    def v0_json(self, *args: str) -> Dict[str, object]:
        return run_json(self, JSON_KEYS, "v0", *args)

    def assert_matches_shim(self, result: Dict[str, object], albedo: float, method: str) -> None:
        # %.17g round-trips a double, so the CLI's numbers equal the library's exactly.
        c = dwivedi.diffusion_constants(albedo, method)
        self.assertEqual(result["albedo"], albedo)
        self.assertEqual(result["method"], method)
        for key in ("v0", "kappa", "one_minus_kappa", "log_one_minus_kappa"):
            self.assertEqual(result[key], json_number(getattr(c, key)), key)

    def test_json_at_half(self) -> None:
        result = self.v0_json("--albedo", "0.5")
        self.assert_matches_shim(result, 0.5, "exact")
        row = next(row for row in read_v0_reference() if row["albedo"] == 0.5)
        self.assertLess(relative_error(float(result["v0"]), 1.0 / row["kappa"]), 1e-12)
        self.assertLess(relative_error(float(result["kappa"]), row["kappa"]), 1e-12)
        self.assertLess(relative_error(float(result["one_minus_kappa"]), row["one_minus_kappa"]), 1e-12)
        self.assertLess(relative_error(float(result["log_one_minus_kappa"]), row["log_one_minus_kappa"]), 1e-12)

    def test_every_method(self) -> None:
        self.assertEqual(dwivedi.methods(), ("exact", "case", "deon", "fast"))
        for method in dwivedi.methods():
            for albedo in ("0.3", "0.7", "0.99"):
                with self.subTest(method=method, albedo=albedo):
                    result = self.v0_json("--albedo", albedo, "--method", method)
                    self.assert_matches_shim(result, float(albedo), method)

    def test_default_method_is_exact(self) -> None:
        self.assertEqual(self.v0_json("--albedo", "0.8"), self.v0_json("--albedo", "0.8", "--method", "exact"))

    def test_endpoints(self) -> None:
        for method in ("exact", "deon", "fast"):
            with self.subTest(method=method):
                result = self.v0_json("--albedo", "1", "--method", method)
                self.assertIsNone(result["v0"])
                self.assertEqual((result["kappa"], result["one_minus_kappa"], result["log_one_minus_kappa"]),
                                 (0, 1, 0))
        self.assertIsNotNone(self.v0_json("--albedo", "1", "--method", "case")["v0"])
        zero = self.v0_json("--albedo", "0")
        self.assertEqual((zero["v0"], zero["kappa"], zero["one_minus_kappa"]), (1, 1, 0))
        self.assertIsNone(zero["log_one_minus_kappa"])  # log(0) = -infinity is not JSON

    def test_text_output(self) -> None:
        done = run_cli("v0", "--albedo", "0.9", "--method", "deon")
        self.assertEqual(done.returncode, 0)
        self.assertEqual(done.stderr, "")
        fields = dict(line.rsplit(None, 1) for line in done.stdout.splitlines())
        c = dwivedi.diffusion_constants(0.9, "deon")
        self.assertEqual(fields["method"], "deon")
        for key in ("albedo", "v0", "kappa", "one_minus_kappa", "log_one_minus_kappa"):
            self.assertEqual(float(fields[key]), getattr(c, key), key)


class UsageErrorTest(unittest.TestCase):
    """Bad usage: exit 2, empty stdout, one line on stderr that begins with "dwivedi" and names the
    problem."""

    CASES: List[List[str]] = [
        # arguments, then words the message must contain
        [["v0", "--albedo", "-0.1"], ["--albedo", "-0.1", "[0, 1]"]],
        [["v0", "--albedo", "1.5"], ["--albedo", "1.5", "[0, 1]"]],
        [["v0", "--albedo", "1.0000000000000002"], ["--albedo", "[0, 1]"]],
        [["v0", "--albedo", "nan"], ["--albedo", "NaN"]],
        [["v0", "--albedo", "inf"], ["--albedo", "infinite"]],
        [["v0", "--albedo", "-inf"], ["--albedo", "infinite"]],
        [["v0", "--albedo", "1e999"], ["--albedo", "1e999"]],
        [["v0", "--albedo", "abc"], ["--albedo", "'abc'"]],
        [["v0", "--albedo", "0.5x"], ["--albedo", "'0.5x'"]],
        [["v0", "--albedo", ""], ["--albedo"]],
        [["v0", "--albedo"], ["--albedo", "value"]],
        [["v0"], ["--albedo", "required"]],
        [["v0", "--json"], ["--albedo", "required"]],
        [["v0", "--albedo", "0.5", "--method", "foo"], ["--method", "'foo'"]],
        [["v0", "--albedo", "0.5", "--method", "Exact"], ["--method", "'Exact'"]],
        [["v0", "--albedo", "0.5", "--method"], ["--method", "value"]],
        [["v0", "--albedo", "0.5", "--frobnicate"], ["'--frobnicate'"]],
        [["v0", "0.5"], ["'0.5'"]],
        [["frobnicate"], ["'frobnicate'"]],
        [["--frobnicate"], ["'--frobnicate'"]],
    ]

    def test_bad_usage(self) -> None:
        for args, words in self.CASES:
            with self.subTest(args=args):
                expected_start = "dwivedi v0: " if args[0] == "v0" else "dwivedi: "
                assert_bad_usage(self, args, expected_start, words)


if __name__ == "__main__":
    unittest.main()
