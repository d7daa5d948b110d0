"""`dwivedi bench v0` (error against run time of the v0 methods) and tools/v0_report.py.

Run by ctest with DWIVEDI_CLI and DWIVEDI_SOURCE_DIR set. Needs only the standard library; the
report test runs tools/v0_report.py with /usr/bin/python3, which has matplotlib, numpy and mpmath
once scripts/setup.sh has run. Times are only checked to be positive numbers, never judged.
"""

import decimal
import json
import os
import subprocess
import tempfile
import unittest

METHODS = {"exact", "case", "deon", "fast"}
FAST_DOMAIN = (0.01, 1 - 1e-6)
CALLS = "20000"  # enough to time, short enough for a unit test
DEBIAN_PYTHON = "/usr/bin/python3"


def environment(name):
    value = os.environ.get(name)
    if not value:
        raise AssertionError("%s is not set: run this test through ctest" % name)
    return value


def run_cli(*arguments):
    return subprocess.run([environment("DWIVEDI_CLI")] + list(arguments), capture_output=True, text=True,
                          timeout=300)


def reference_path():
    return os.path.join(environment("DWIVEDI_SOURCE_DIR"), "tests", "data", "v0_reference.csv")


def read_reference():
    """(header, rows) of the committed table, every field a string."""
    with open(reference_path(), encoding="ascii") as table:
        lines = [line.strip() for line in table if line.strip() and not line.lstrip().startswith("#")]
    header = lines[0].split(",")
    return header, [dict(zip(header, line.split(","))) for line in lines[1:]]


class BenchJson(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        done = run_cli("bench", "v0", "--json", "--calls", CALLS)
        if done.returncode != 0:
            raise AssertionError("dwivedi bench v0 --json failed (%d): %s" % (done.returncode, done.stderr))
        cls.report = json.loads(done.stdout)
        cls.methods = {m["name"]: m for m in cls.report["methods"]}

    def error(self, container, key, method):
        value = container[key]
        self.assertIsNotNone(value, "%s: %s is null (a NaN or infinite result, at albedo %r)"
                             % (method, key, container[key + "_at_albedo"]))
        return value

    def test_every_method_is_measured(self):
        self.assertEqual(set(self.methods), METHODS)
        self.assertEqual(len(self.report["methods"]), len(METHODS))
        self.assertEqual(self.report["calls"], int(CALLS))

    def test_the_embedded_table_is_the_committed_one(self):
        header, rows = read_reference()
        for column in ("albedo", "kappa", "one_minus_kappa"):
            self.assertIn(column, header)
        reference = self.report["reference"]
        self.assertTrue(reference["embedded"])
        self.assertEqual(reference["rows"], len(rows))
        albedos = [float(row["albedo"]) for row in rows]
        self.assertEqual(reference["albedo_min"], min(albedos))
        self.assertEqual(reference["albedo_max"], max(albedos))
        in_domain = [a for a in albedos if FAST_DOMAIN[0] <= a <= FAST_DOMAIN[1]]
        self.assertEqual(self.report["fast_domain"]["rows"], len(in_domain))
        self.assertGreater(len(in_domain), 10)

    def test_exact_is_exact_to_double_precision(self):
        exact = self.methods["exact"]
        for where in (exact, exact["fast_domain"]):
            self.assertLessEqual(self.error(where, "max_rel_err_kappa", "exact"), 1e-14)
            self.assertLessEqual(self.error(where, "max_rel_err_one_minus_kappa", "exact"), 1e-12)

    def test_case_is_measured_to_be_poor(self):
        # The supplemental's series are poor near the switch at 0.56 and above the clamp at
        # 0.9999: a bench that measured nothing would report 0 here.
        case = self.methods["case"]
        for where in (case, case["fast_domain"]):
            self.assertGreater(self.error(where, "max_rel_err_kappa", "case"), 1e-4)
            self.assertGreater(self.error(where, "max_rel_err_one_minus_kappa", "case"), 1e-4)
        at = case["fast_domain"]["max_rel_err_kappa_at_albedo"]
        self.assertTrue(FAST_DOMAIN[0] <= at <= FAST_DOMAIN[1], at)

    def test_where_the_worst_errors_are_lies_in_the_table(self):
        _, rows = read_reference()
        albedos = {float(row["albedo"]) for row in rows}
        for name, method in self.methods.items():
            for where in (method, method["fast_domain"]):
                for key in ("max_rel_err_kappa", "max_rel_err_one_minus_kappa"):
                    self.assertIn(where[key + "_at_albedo"], albedos, (name, key))

    def test_run_times_are_positive(self):
        for name, method in self.methods.items():
            self.assertGreater(method["ns_per_call"], 0.0, name)
        self.assertEqual(self.report["sampler"]["function"], "dwv_dwivedi_sample_pdf_f")
        self.assertGreater(self.report["sampler"]["ns_per_call"], 0.0)


class BenchMeasures(unittest.TestCase):
    """A planted error in a --reference table is found where it was planted and with its size."""

    def test_planted_errors_are_found(self):
        _, rows = read_reference()
        kappa_row = min(rows, key=lambda row: abs(float(row["albedo"]) - 0.7))
        complement_row = min(rows, key=lambda row: abs(float(row["albedo"]) - 0.3))
        kappa_factor, complement_factor = decimal.Decimal("1.000001"), decimal.Decimal("0.99999")
        # Columns in another order than the committed table's, and a comment: found by name.
        lines = ["# planted errors", "one_minus_kappa,albedo,kappa"]
        for row in rows:
            kappa, complement = row["kappa"], row["one_minus_kappa"]
            if row is kappa_row:
                kappa = str(decimal.Decimal(kappa) * kappa_factor)
            if row is complement_row:
                complement = str(decimal.Decimal(complement) * complement_factor)
            lines.append("%s,%s,%s" % (complement, row["albedo"], kappa))
        with tempfile.TemporaryDirectory() as directory:
            path = os.path.join(directory, "planted.csv")
            with open(path, "w", encoding="ascii") as table:
                table.write("\n".join(lines) + "\n")
            done = run_cli("bench", "v0", "--reference", path, "--json", "--calls", "1000")
        self.assertEqual(done.returncode, 0, done.stderr)
        report = json.loads(done.stdout)
        self.assertFalse(report["reference"]["embedded"])
        self.assertEqual(report["reference"]["source"], path)
        exact = {m["name"]: m for m in report["methods"]}["exact"]["fast_domain"]
        # |k - k (1 + d)| / (k (1 + d)) = d / (1 + d), to within the method's own ~1e-15.
        self.assertAlmostEqual(exact["max_rel_err_kappa"] / (1e-6 / (1 + 1e-6)), 1.0, delta=1e-6)
        self.assertEqual(exact["max_rel_err_kappa_at_albedo"], float(kappa_row["albedo"]))
        self.assertAlmostEqual(exact["max_rel_err_one_minus_kappa"] / (1e-5 / (1 - 1e-5)), 1.0, delta=1e-6)
        self.assertEqual(exact["max_rel_err_one_minus_kappa_at_albedo"], float(complement_row["albedo"]))

    def test_text_output_names_every_method(self):
        done = run_cli("bench", "v0", "--calls", "1000")
        self.assertEqual(done.returncode, 0, done.stderr)
        for name in METHODS:
            self.assertIn("dwv_diffusion_length %s" % name, done.stdout)
        self.assertIn("fast domain", done.stdout)
        self.assertIn("dwv_dwivedi_sample_pdf_f", done.stdout)


class BenchUsage(unittest.TestCase):
    def assert_usage_error(self, arguments, mention=None):
        done = run_cli(*arguments)
        self.assertEqual(done.returncode, 2, (arguments, done.stdout, done.stderr))
        self.assertEqual(done.stdout, "", arguments)
        self.assertEqual(len(done.stderr.strip().splitlines()), 1, (arguments, done.stderr))
        self.assertTrue(done.stderr.startswith("dwivedi bench"), done.stderr)
        if mention:
            self.assertIn(mention, done.stderr)

    def test_bad_arguments_exit_2_with_one_line(self):
        for arguments in (["bench"], ["bench", "v1"], ["bench", "v0", "v0"], ["bench", "v0", "--calls"],
                          ["bench", "v0", "--calls", "0"], ["bench", "v0", "--calls", "-5"],
                          ["bench", "v0", "--calls", "ten"], ["bench", "v0", "--frobnicate"],
                          ["bench", "--json"], ["bench", "v0", "--reference"]):
            self.assert_usage_error(arguments)

    def test_unreadable_reference_names_the_file(self):
        with tempfile.TemporaryDirectory() as directory:
            missing = os.path.join(directory, "no-such-table.csv")
            self.assert_usage_error(["bench", "v0", "--reference", missing], missing)
            self.assert_usage_error(["bench", "v0", "--reference", directory], directory)

    def test_malformed_reference_names_the_file_and_line(self):
        tables = {"no_column.csv": "albedo,kappa\n0.5,0.9575\n",
                  "not_a_number.csv": "albedo,kappa,one_minus_kappa\n0.5,x,0.0425\n",
                  "out_of_range.csv": "albedo,kappa,one_minus_kappa\n1.5,0.9,0.1\n",
                  "short_line.csv": "albedo,kappa,one_minus_kappa\n0.5,0.9575\n",
                  "header_only.csv": "# nothing\nalbedo,kappa,one_minus_kappa\n"}
        with tempfile.TemporaryDirectory() as directory:
            for name, text in tables.items():
                path = os.path.join(directory, name)
                with open(path, "w", encoding="ascii") as table:
                    table.write(text)
                self.assert_usage_error(["bench", "v0", "--reference", path], path)

    def test_help(self):
        done = run_cli("bench", "--help")
        self.assertEqual(done.returncode, 0)
        self.assertIn("dwivedi bench v0", done.stdout)


class Report(unittest.TestCase):
    """tools/v0_report.py end to end, always with Debian's interpreter (which setup.sh equips)."""

    def script(self):
        return os.path.join(environment("DWIVEDI_SOURCE_DIR"), "tools", "v0_report.py")

    def test_report_writes_every_file(self):
        if not os.access(DEBIAN_PYTHON, os.X_OK):
            self.fail("%s is missing: run scripts/setup.sh (it installs python3 and python3-matplotlib)"
                      % DEBIAN_PYTHON)
        probe = subprocess.run([DEBIAN_PYTHON, "-c", "import matplotlib, numpy, mpmath"], capture_output=True,
                               text=True)
        if probe.returncode != 0:
            self.fail("%s lacks matplotlib, numpy or mpmath (%s): run scripts/setup.sh, which installs "
                      "python3-matplotlib python3-numpy python3-mpmath"
                      % (DEBIAN_PYTHON, probe.stderr.strip().splitlines()[-1:]))
        with tempfile.TemporaryDirectory() as directory:
            out = os.path.join(directory, "report")
            done = subprocess.run([DEBIAN_PYTHON, self.script(), "--cli", environment("DWIVEDI_CLI"), "--out", out,
                                   "--points", "40", "--calls", CALLS], capture_output=True, text=True, timeout=600)
            self.assertEqual(done.returncode, 0, done.stderr)
            for name in ("v0_error_vs_albedo.png", "figure1.png", "error_vs_time.png"):
                with open(os.path.join(out, name), "rb") as image:
                    self.assertEqual(image.read(8), b"\x89PNG\r\n\x1a\n", name)
                self.assertGreater(os.path.getsize(os.path.join(out, name)), 10000, name)
            with open(os.path.join(out, "v0_methods.md"), encoding="utf-8") as table:
                text = table.read()
        self.assertIn("| method | worst rel. error kappa0 | worst rel. error 1-kappa0 | ns per call", text)
        for name in METHODS:
            self.assertRegex(text, r"\n\| %s \| [^|]+ \| [^|]+ \| [0-9.]+ \|" % name)

    def test_report_without_the_cli_fails_clearly(self):
        with tempfile.TemporaryDirectory() as directory:
            missing = os.path.join(directory, "no-dwivedi")
            done = subprocess.run([DEBIAN_PYTHON, self.script(), "--cli", missing, "--out", directory],
                                  capture_output=True, text=True, timeout=60)
        self.assertNotEqual(done.returncode, 0)
        self.assertIn(missing, done.stderr)
        self.assertEqual(len(done.stderr.strip().splitlines()), 1, done.stderr)


if __name__ == "__main__":
    unittest.main()
