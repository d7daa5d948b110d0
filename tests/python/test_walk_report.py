"""tools/walk_report.py --quick end to end: every file written, every case and technique measured.

Run by ctest with DWIVEDI_CLI, DWIVEDI_SOURCE_DIR and DWIVEDI_BUILD_DIR set. The report always runs
under Debian's interpreter (/usr/bin/python3, which has matplotlib and numpy once scripts/setup.sh
has run); this module itself needs only the standard library. Quick mode runs each measurement for
a few milliseconds, so its figures are noise: this checks the plumbing, never a timing or a ratio
(speed belongs to the benchmark's full run, not to a unit test).
"""

import csv
import json
import math
import os
import shutil
import subprocess
import tempfile
import unittest

DEBIAN_PYTHON = "/usr/bin/python3"
# The case set and techniques, spelled out here so that a report that drops one fails.
CASES = ("halfspace_a0.5", "halfspace_a0.9", "halfspace_a0.99", "halfspace_a0.999", "slab_d1", "slab_d4",
         "slab_d16", "sphere_r4")
HALFSPACE_ALBEDOS = {"halfspace_a0.5": 0.5, "halfspace_a0.9": 0.9, "halfspace_a0.99": 0.99,
                     "halfspace_a0.999": 0.999}
TECHNIQUES = ("classical", "poe", "closest", "incident", "backward", "cycles", "auto")
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
# Targets of the section "Efficiency and speed": 2 poe/classical, incident/poe and auto/poe
# on the thick slab, auto/best per case, throughput on two half-space albedos.
TARGET_COUNT = 2 + 2 + len(CASES) + 2


def environment(name):
    value = os.environ.get(name)
    if not value:
        raise AssertionError("%s is not set: run this test through ctest" % name)
    return value


def script():
    return os.path.join(environment("DWIVEDI_SOURCE_DIR"), "tools", "walk_report.py")


def finite(x):
    return isinstance(x, (int, float)) and math.isfinite(x)


class QuickReport(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if not os.access(DEBIAN_PYTHON, os.X_OK):
            raise AssertionError("%s is missing: run scripts/setup.sh (it installs python3-matplotlib)"
                                 % DEBIAN_PYTHON)
        probe = subprocess.run([DEBIAN_PYTHON, "-c", "import matplotlib, numpy"], capture_output=True, text=True)
        if probe.returncode != 0:
            raise AssertionError("%s lacks matplotlib or numpy (%s): run scripts/setup.sh, which installs "
                                 "python3-matplotlib python3-numpy" % (DEBIAN_PYTHON, probe.stderr.strip()[-200:]))
        cls.directory = tempfile.mkdtemp(prefix="walk_report_")
        cls.out = os.path.join(cls.directory, "report")
        archive = os.path.join(environment("DWIVEDI_BUILD_DIR"), "libdwivedi_internal.a")
        cls.done = subprocess.run([DEBIAN_PYTHON, script(), "--cli", environment("DWIVEDI_CLI"), "--out", cls.out,
                                   "--quick", "--internal-lib", archive], capture_output=True, text=True, timeout=300)
        cls.report = None
        if cls.done.returncode == 0:
            with open(os.path.join(cls.out, "walk_efficiency.json"), encoding="utf-8") as text:
                cls.report = json.load(text)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.directory, ignore_errors=True)

    def setUp(self):
        self.assertEqual(self.done.returncode, 0, self.done.stderr)

    def test_every_file_is_written(self):
        for case in CASES:
            path = os.path.join(self.out, "rmse_%s.png" % case)
            with open(path, "rb") as image:
                self.assertEqual(image.read(8), PNG_MAGIC, path)
            self.assertGreater(os.path.getsize(path), 10000, path)
        with open(os.path.join(self.out, "walk_efficiency.md"), encoding="utf-8") as text:
            markdown = text.read()
        self.assertIn("## Targets", markdown)
        verdicts = [line for line in markdown.splitlines()
                    if line.startswith("| ") and (line.endswith("| PASS |") or line.endswith("| FAIL |"))]
        self.assertEqual(len(verdicts), TARGET_COUNT, verdicts)
        for case in CASES:
            self.assertIn("(rmse_%s.png)" % case, markdown)

    def test_every_case_and_technique_is_measured(self):
        self.assertEqual([c["name"] for c in self.report["cases"]], list(CASES))
        self.assertEqual(self.report["techniques"], list(TECHNIQUES))
        for case in CASES:
            measured = self.report["efficiency"][case]
            self.assertEqual(set(measured), set(TECHNIQUES), case)
            for technique in TECHNIQUES:
                r = measured[technique]
                where = "%s/%s" % (case, technique)
                self.assertTrue(finite(r["mean"]) and finite(r["stderr"]), where)
                self.assertTrue(finite(r["variance"]) and r["variance"] >= 0.0, where)
                self.assertGreater(r["walks"], 0, where)
                self.assertTrue(finite(r["ns_per_event"]) and r["ns_per_event"] > 0.0, where)
                self.assertTrue(finite(r["seconds_per_walk"]) and r["seconds_per_walk"] > 0.0, where)
                self.assertTrue(r["runs"], where)

    def test_every_case_has_a_reference_and_rmse_curves(self):
        for case in CASES:
            self.assertTrue(finite(self.report["references"][case]["value"]), case)
            for technique in TECHNIQUES:
                points = self.report["rmse"][case][technique]
                self.assertGreaterEqual(len(points), 2, (case, technique))
                walks = [p["walks"] for p in points]
                self.assertEqual(walks, sorted(set(walks)), (case, technique))
                for point in points:
                    self.assertTrue(finite(point["rmse"]) and point["rmse"] >= 0.0, (case, technique))
                    self.assertTrue(all(finite(m) for m in point["means"]), (case, technique))

    def test_half_space_references_are_the_committed_table(self):
        # Read here independently of the report's own reader: quantity,shape,incidence,cosine,albedo,...
        path = os.path.join(environment("DWIVEDI_SOURCE_DIR"), "tests", "data", "walk_reference.csv")
        if not os.path.exists(path):
            self.fail("%s is missing (tools/gen_walk_reference.py writes it)" % path)
        with open(path, encoding="utf-8") as table:
            rows = list(csv.DictReader(line for line in table if line.strip() and not line.startswith("#")))
        for case, albedo in HALFSPACE_ALBEDOS.items():
            value = [float(r["value"]) for r in rows if r["quantity"] == "reflectance" and r["shape"] == "halfspace"
                     and r["incidence"] == "cosine" and float(r["cosine"]) == 1.0 and float(r["albedo"]) == albedo]
            self.assertEqual(len(value), 1, case)
            reference = self.report["references"][case]
            self.assertEqual(reference["value"], value[0], case)
            self.assertTrue(reference["source"].startswith("Chandrasekhar"), reference["source"])

    def test_targets_are_evaluated(self):
        targets = self.report["targets"]
        self.assertEqual(len(targets), TARGET_COUNT)
        for target in targets:
            self.assertTrue(finite(target["measured"]) and target["measured"] > 0.0, target["target"])
            self.assertIs(target["pass"], target["measured"] >= target["threshold"], target["target"])

    def test_mixture_program_reproduces_the_cli(self):
        checks = self.report["mixture_validation"]
        self.assertEqual({c["technique"] for c in checks}, set(TECHNIQUES))
        for check in checks:
            self.assertTrue(check["identical"], check)
            self.assertEqual(check["program_mean"], check["cli_mean"], check)
        for case in CASES:
            labels = [row["label"] for row in self.report["mixtures"][case]]
            self.assertIn("auto (as built)", labels, case)
            self.assertIn("proposed auto", labels, case)
            for row in self.report["mixtures"][case]:
                self.assertAlmostEqual(sum(row["weights"]), 1.0, delta=1e-12, msg=(case, row["label"]))
                self.assertTrue(finite(row["mean"]), (case, row["label"]))


class Failures(unittest.TestCase):
    def test_a_missing_cli_fails_in_one_line(self):
        with tempfile.TemporaryDirectory() as directory:
            missing = os.path.join(directory, "no-dwivedi")
            done = subprocess.run([DEBIAN_PYTHON, script(), "--cli", missing, "--out", directory, "--quick"],
                                  capture_output=True, text=True, timeout=60)
        self.assertEqual(done.returncode, 1)
        self.assertIn(missing, done.stderr)
        self.assertEqual(len(done.stderr.strip().splitlines()), 1, done.stderr)


if __name__ == "__main__":
    unittest.main()
