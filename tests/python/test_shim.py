"""Tests of the ctypes shim (python_shim/dwivedi): values against the mpmath reference table,
the Dwivedi pdf and sampler against closed forms and quadrature, errors, and library discovery.

Run by ctest (see tests/CMakeLists.txt), which sets DWIVEDI_LIBRARY, DWIVEDI_SOURCE_DIR,
DWIVEDI_BUILD_DIR and PYTHONPATH. Standard library only.
"""
import ctypes
import csv
import json
import math
import os
import random
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path
from typing import Callable, Dict, List, Optional, Tuple

SOURCE_DIR = Path(os.environ.get("DWIVEDI_SOURCE_DIR", Path(__file__).resolve().parents[2]))
# The source tree's shim, unless PYTHONPATH names another copy to test.
sys.path.append(str(SOURCE_DIR / "python_shim"))

import dwivedi  # noqa: E402
from dwivedi import _library  # noqa: E402

V0_REFERENCE = SOURCE_DIR / "tests" / "data" / "v0_reference.csv"
METHODS = ("exact", "case", "deon", "fast")
# Albedos below which the sampling distribution's v is held at 1 + 2^-20 (capi/dwivedi.h).
V_FLOOR = 1.0 + 2.0 ** -20


def read_v0_reference() -> List[Dict[str, float]]:
    """The rows of tests/data/v0_reference.csv (made by tools/gen_v0_reference.py with mpmath), as
    floats keyed by column name."""
    with open(V0_REFERENCE, newline="") as f:
        lines = [line for line in f if not line.startswith("#")]
    return [{key: float(value) for key, value in row.items()} for row in csv.DictReader(lines)]


def relative_error(value: float, reference: float) -> float:
    if value == reference:
        return 0.0
    return abs(value - reference) / abs(reference) if reference != 0.0 else math.inf


def header_version() -> str:
    """major.minor.patch as capi/dwivedi.h defines it (the single source of the version)."""
    text = (SOURCE_DIR / "capi" / "dwivedi.h").read_text()
    parts = [re.search(rf"#define DWV_VERSION_{part} (\d+)", text) for part in ("MAJOR", "MINOR", "PATCH")]
    return ".".join(match.group(1) for match in parts if match)


def simpson(f: Callable[[float], float], a: float, b: float, intervals: int) -> float:
    """Composite Simpson's rule with an even number of intervals."""
    h = (b - a) / intervals
    total = f(a) + f(b)
    for i in range(1, intervals):
        total += (4.0 if i % 2 else 2.0) * f(a + i * h)
    return total * h / 3.0


def cosine_integral(pdf: Callable[[float], float], kappa: float, weight: Callable[[float], float],
                    intervals: int = 2048) -> float:
    """The integral of weight(mu) pdf(mu) over mu in [-1, 1], for a pdf peaked like 1/(v - mu),
    v = 1/kappa: substituting mu = v - (v + 1) exp(-t L), t in [0, 1], L = 2 atanh(kappa) (so
    that dmu = L (v - mu) dt), makes the integrand of a correct Dwivedi pdf constant in t and
    that of any other pdf smooth, whatever the peak."""
    v = 1.0 / kappa
    log_ratio = 2.0 * math.atanh(kappa)

    def integrand(t: float) -> float:
        v_minus_mu = (v + 1.0) * math.exp(-t * log_ratio)
        mu = min(1.0, max(-1.0, v - v_minus_mu))
        return weight(mu) * pdf(mu) * log_ratio * v_minus_mu

    return simpson(integrand, 0.0, 1.0, intervals)


def cosine_moments(dist: "dwivedi.DwivediDistribution") -> Tuple[float, float]:
    """Mean and variance of mu under the library's pdf, by quadrature."""
    mean = cosine_integral(dist.pdf, dist.kappa, lambda mu: mu)
    second = cosine_integral(dist.pdf, dist.kappa, lambda mu: mu * mu)
    return mean, second - mean * mean


def mean_z_score(samples: List[float], mean: float, variance: float) -> float:
    """How many standard errors the sample mean is from `mean` (central limit theorem)."""
    sample_mean = math.fsum(samples) / len(samples)
    return abs(sample_mean - mean) / math.sqrt(variance / len(samples))


def uniform_numbers(seed: int, count: int) -> List[float]:
    generator = random.Random(seed)
    return [generator.random() for _ in range(count)]


class VersionTest(unittest.TestCase):
    def test_version_matches_header(self) -> None:
        self.assertRegex(header_version(), r"^\d+\.\d+\.\d+$")
        self.assertEqual(dwivedi.version(), header_version())

    def test_library_path_is_the_configured_library(self) -> None:
        configured = os.environ.get("DWIVEDI_LIBRARY")
        self.assertTrue(configured, "ctest sets DWIVEDI_LIBRARY; run these tests through ctest")
        self.assertTrue(os.path.samefile(dwivedi.library_path(), configured))

    def test_methods_are_the_headers_names_in_order(self) -> None:
        self.assertEqual(dwivedi.methods(), METHODS)


class StructLayoutTest(unittest.TestCase):
    """The ctypes structures mirror capi/dwivedi.h: sizes from the header's field lists, and every
    field read back where the library wrote it (a shifted field breaks these identities)."""

    def test_sizes(self) -> None:
        # uint32 + int32 + 6 doubles; uint32 + int32 + 5 doubles + 4 floats; 2 uint32 + 5 doubles.
        self.assertEqual(ctypes.sizeof(_library.DiffusionLength), 56)
        self.assertEqual(ctypes.sizeof(_library.Dwivedi), 64)
        self.assertEqual(ctypes.sizeof(_library.DwivediSample), 48)
        self.assertEqual(_library.DiffusionLength().struct_size, 56)
        self.assertEqual(_library.Dwivedi().struct_size, 64)
        self.assertEqual(_library.DwivediSample().struct_size, 48)

    def test_diffusion_constants_fields_agree(self) -> None:
        for method in METHODS:
            for albedo in (0.3, 0.7, 0.95):
                with self.subTest(method=method, albedo=albedo):
                    c = dwivedi.diffusion_constants(albedo, method)
                    # `fast` approximates kappa, 1 - kappa and its log each on its own, to ~1e-10
                    # (its promise is 1e-6 and 1e-4); the other methods derive them from one value.
                    tolerance = 1e-9 if method == "fast" else 1e-14
                    self.assertEqual(c.albedo, albedo)
                    self.assertEqual(c.method, method)
                    self.assertAlmostEqual(c.kappa + c.one_minus_kappa, 1.0, delta=max(4e-16, tolerance / 10))
                    self.assertLess(relative_error(c.log_one_minus_kappa, math.log(c.one_minus_kappa)), tolerance)
                    self.assertLess(relative_error(c.v0, 1.0 / c.kappa), 1e-15)
                    self.assertLess(relative_error(c.log_ratio, 2.0 * math.atanh(c.kappa)), tolerance)

    def test_dwivedi_fields_agree(self) -> None:
        for method in METHODS:
            dist = dwivedi.DwivediDistribution(0.8, method)
            raw = dist._dist
            with self.subTest(method=method):
                self.assertEqual(raw.method, METHODS.index(method))
                self.assertEqual(raw.albedo, 0.8)
                self.assertAlmostEqual(raw.kappa + raw.one_minus_kappa, 1.0, delta=4e-16)
                self.assertLess(relative_error(raw.log_ratio, 2.0 * math.atanh(raw.kappa)), 1e-14)
                self.assertLess(relative_error(raw.albedo_eff, 2.0 * raw.kappa / raw.log_ratio), 1e-14)
                for double_name in ("kappa", "one_minus_kappa", "log_ratio", "albedo_eff"):
                    rounded = struct.unpack("f", struct.pack("f", getattr(raw, double_name)))[0]
                    self.assertEqual(getattr(raw, double_name + "_f"), rounded, double_name)


class DiffusionLengthTest(unittest.TestCase):
    def test_against_mpmath_reference(self) -> None:
        # That the values cross the shim intact, at the table's albedos in [0.05, 0.9999], where
        # every method matches its own formula to double precision (near 1, 1 - alpha^p in the
        # d'Eon fit loses digits by design). The methods over the whole table are the C tests'.
        rows = [row for row in read_v0_reference() if 0.05 <= row["albedo"] <= 0.9999]
        self.assertGreater(len(rows), 20)
        for row in rows:
            for method, prefix in (("exact", ""), ("case", "case_"), ("deon", "deon_")):
                albedo = row["albedo"]
                with self.subTest(albedo=albedo, method=method):
                    c = dwivedi.diffusion_constants(albedo, method)
                    self.assertLess(relative_error(c.kappa, row[prefix + "kappa"]), 1e-12)
                    self.assertLess(relative_error(dwivedi.diffusion_length(albedo, method),
                                                   1.0 / row[prefix + "kappa"]), 1e-12)
                    self.assertLess(relative_error(c.one_minus_kappa, row[prefix + "one_minus_kappa"]), 1e-12)
                    self.assertLess(relative_error(c.log_one_minus_kappa, row[prefix + "log_one_minus_kappa"]),
                                    1e-12)

    def test_endpoints(self) -> None:
        for method in METHODS:
            with self.subTest(method=method):
                self.assertEqual(dwivedi.diffusion_length(0.0, method), 1.0)
                self.assertEqual(dwivedi.diffusion_length(0, method), 1.0)
                zero = dwivedi.diffusion_constants(0, method)
                self.assertEqual((zero.kappa, zero.one_minus_kappa, zero.log_one_minus_kappa),
                                 (1.0, 0.0, -math.inf))
        for method in ("exact", "deon", "fast"):
            with self.subTest(method=method):
                self.assertEqual(dwivedi.diffusion_length(1.0, method), math.inf)
                self.assertEqual(dwivedi.diffusion_length(1, method), math.inf)
                one = dwivedi.diffusion_constants(1.0, method)
                self.assertEqual((one.kappa, one.one_minus_kappa, one.log_one_minus_kappa, one.log_ratio),
                                 (0.0, 1.0, 0.0, 0.0))
        # The case series is used as written: v0(0.9999) for every albedo from 0.9999 on.
        self.assertEqual(dwivedi.diffusion_length(1.0, "case"), dwivedi.diffusion_length(0.9999, "case"))

    def test_constants_are_frozen(self) -> None:
        c = dwivedi.diffusion_constants(0.5)
        with self.assertRaises(AttributeError):
            c.v0 = 2.0  # type: ignore[misc]


class DwivediDistributionTest(unittest.TestCase):
    ALBEDOS = (0.05, 0.5, 0.9, 0.99)

    def reference_v(self, albedo: float) -> float:
        """v of the sampling distribution from the mpmath table: v0, held at 1 + 2^-20."""
        row = next(row for row in read_v0_reference() if row["albedo"] == albedo)
        return max(V_FLOOR, 1.0 / row["kappa"])

    def test_v_is_v0_held_at_the_floor(self) -> None:
        for albedo in self.ALBEDOS:
            with self.subTest(albedo=albedo):
                dist = dwivedi.DwivediDistribution(albedo)
                self.assertLess(relative_error(1.0 / dist.kappa, self.reference_v(albedo)), 1e-12)
                self.assertEqual(dist.albedo, albedo)
                self.assertEqual(dist.method, "exact")
        self.assertEqual(1.0 / dwivedi.DwivediDistribution(0.05).kappa, V_FLOOR)

    def test_pdf_is_the_closed_form(self) -> None:
        # p(mu) = 1 / (L (v - mu)), L = log((v + 1)/(v - 1)) (supplemental Eq. 7, normalised).
        for albedo in self.ALBEDOS:
            v = self.reference_v(albedo)
            log_ratio = math.log((v + 1.0) / (v - 1.0))
            dist = dwivedi.DwivediDistribution(albedo)
            for mu in (-1.0, -0.5, 0.0, 0.3, 0.9, 1.0):
                with self.subTest(albedo=albedo, mu=mu):
                    expected = 1.0 / (log_ratio * (v - mu))
                    self.assertLess(relative_error(dist.pdf(mu), expected), 1e-13)
                    self.assertEqual(dwivedi.dwivedi_pdf(albedo, mu), dist.pdf(mu))

    def test_pdf_integrates_to_one(self) -> None:
        for albedo in self.ALBEDOS:
            dist = dwivedi.DwivediDistribution(albedo)
            with self.subTest(albedo=albedo):
                self.assertAlmostEqual(cosine_integral(dist.pdf, dist.kappa, lambda mu: 1.0), 1.0, delta=1e-12)

    def test_normalisation_check_catches_a_wrong_pdf(self) -> None:
        # Planted error: the pdf tilted by 2% toward the normal, p(mu) (1 + 0.02 mu).
        dist = dwivedi.DwivediDistribution(0.9)
        integral = cosine_integral(dist.pdf, dist.kappa, lambda mu: 1.0 + 0.02 * mu)
        self.assertGreater(abs(integral - 1.0), 1e-4)

    def test_sample_mean_matches_pdf_mean(self) -> None:
        # 5 standard errors of the mean over 50000 samples; seeds fixed so that a pass is final.
        for seed, albedo in enumerate((0.5, 0.9, 0.99)):
            dist = dwivedi.DwivediDistribution(albedo)
            mean, variance = cosine_moments(dist)
            # The first moment in closed form: E[mu] = v - 2/L.
            self.assertAlmostEqual(mean, 1.0 / dist.kappa - 2.0 / dist.log_ratio, delta=1e-10)
            samples = [dist.sample(u) for u in uniform_numbers(seed, 50000)]
            with self.subTest(albedo=albedo):
                self.assertLess(mean_z_score(samples, mean, variance), 5.0)

    def test_mean_check_catches_a_mismatched_pdf(self) -> None:
        # Planted error: directions sampled for albedo 0.9, weighted with the pdf of albedo 0.95
        # (two media or spectral channels mixed up); the 5-sigma check must reject it.
        sampled = dwivedi.DwivediDistribution(0.9)
        mean, variance = cosine_moments(dwivedi.DwivediDistribution(0.95))
        samples = [sampled.sample(u) for u in uniform_numbers(1, 50000)]
        self.assertGreater(mean_z_score(samples, mean, variance), 5.0)

    def test_sampler_inverts_the_cdf(self) -> None:
        # CDF(mu) = log((v + 1)/(v - mu)) / L, so CDF(sample(u)) = u; v - mu = (v - 1) + (1 - mu)
        # is formed from one_minus_cos so that nothing cancels.
        for albedo in self.ALBEDOS:
            dist = dwivedi.DwivediDistribution(albedo)
            v_minus_one = dist.one_minus_kappa / dist.kappa
            for u in [i / 16 for i in range(17)]:
                with self.subTest(albedo=albedo, u=u):
                    s = dist.sample_pdf(u)
                    cdf = math.log((v_minus_one + 2.0) / (v_minus_one + s.one_minus_cos)) / dist.log_ratio
                    self.assertAlmostEqual(cdf, u, delta=1e-12)

    def test_sample_pdf_agrees_with_the_single_calls(self) -> None:
        # 1 -+ mu are computed by the library without forming mu first, so they may differ from
        # 1 -+ cos_theta by a few rounding errors of numbers up to 2: at most 2e-15.
        for albedo in self.ALBEDOS:
            dist = dwivedi.DwivediDistribution(albedo)
            v_minus_one = dist.one_minus_kappa / dist.kappa
            for u in (0.0, 0.1, 0.5, 0.77, 1.0):
                with self.subTest(albedo=albedo, u=u):
                    s = dist.sample_pdf(u)
                    self.assertIsInstance(s, dwivedi.DwivediSample)
                    self.assertEqual(s.cos_theta, dist.sample(u))
                    self.assertEqual(s.cos_theta, dwivedi.dwivedi_sample(albedo, u))
                    self.assertTrue(-1.0 <= s.cos_theta <= 1.0)
                    self.assertLess(relative_error(s.pdf, dist.pdf(s.cos_theta)), 1e-12)
                    self.assertAlmostEqual(s.one_minus_cos, 1.0 - s.cos_theta, delta=2e-15)
                    self.assertAlmostEqual(s.one_plus_cos, 1.0 + s.cos_theta, delta=2e-15)
                    # 1 - mu/v = kappa (v - mu) = kappa ((v - 1) + (1 - mu)), free of cancellation.
                    stretch = dist.kappa * (v_minus_one + s.one_minus_cos)
                    self.assertLess(relative_error(s.stretch, stretch), 1e-12)
                    self.assertLess(relative_error(dist.stretch(s.cos_theta), s.stretch), 1e-12)
        # The endpoints of the inverse CDF: u = 0 gives mu = -1, u = 1 gives mu = +1.
        dist = dwivedi.DwivediDistribution(0.9)
        self.assertAlmostEqual(dist.sample(0.0), -1.0, delta=4e-16)
        self.assertAlmostEqual(dist.sample(1.0), 1.0, delta=4e-16)

    def test_every_method_builds_a_distribution(self) -> None:
        for method in METHODS:
            with self.subTest(method=method):
                dist = dwivedi.DwivediDistribution(0.9, method)
                self.assertEqual(dist.method, method)
                self.assertAlmostEqual(cosine_integral(dist.pdf, dist.kappa, lambda mu: 1.0), 1.0, delta=1e-12)
                self.assertIn("0.9", repr(dist))


class ErrorTest(unittest.TestCase):
    def assert_library_error(self, call: Callable[[], object], code: int, *words: str) -> None:
        with self.assertRaises(dwivedi.Error) as caught:
            call()
        error = caught.exception
        self.assertIsInstance(error, ValueError)
        self.assertEqual(error.code, code)
        self.assertTrue(str(error))
        self.assertEqual(str(error), error.message)
        for word in words:
            self.assertIn(word, str(error))

    def test_bad_albedo_values(self) -> None:
        invalid, out_of_range = 2, 3  # DWV_ERROR_INVALID_ARGUMENT, DWV_ERROR_OUT_OF_RANGE
        for call in (dwivedi.diffusion_length, dwivedi.diffusion_constants, dwivedi.DwivediDistribution,
                     lambda a: dwivedi.dwivedi_pdf(a, 0.0), lambda a: dwivedi.dwivedi_sample(a, 0.5)):
            with self.subTest(call=call):
                self.assert_library_error(lambda: call(math.nan), invalid, "albedo", "NaN")
                self.assert_library_error(lambda: call(math.inf), invalid, "albedo", "infinite")
                self.assert_library_error(lambda: call(-1), out_of_range, "albedo", "-1")
                self.assert_library_error(lambda: call(2), out_of_range, "albedo", "2")
                self.assert_library_error(lambda: call(1.0000000000000002), out_of_range, "albedo")
                self.assert_library_error(lambda: call(10 ** 400), out_of_range, "albedo")

    def test_wrong_types_raise_type_error(self) -> None:
        for value in ("abc", "0.5", True, None, [0.5], 1j):
            with self.subTest(value=value):
                with self.assertRaises(TypeError):
                    dwivedi.diffusion_length(value)  # type: ignore[arg-type]
                with self.assertRaises(TypeError):
                    dwivedi.DwivediDistribution(0.5).sample(value)  # type: ignore[arg-type]
        with self.assertRaises(TypeError):
            dwivedi.diffusion_length(0.5, 0)  # type: ignore[arg-type]

    def test_unknown_method(self) -> None:
        unknown_name = 5  # DWV_ERROR_UNKNOWN_NAME
        for method in ("foo", "Exact", "", "exact ", "exact\0"):
            with self.subTest(method=method):
                self.assert_library_error(lambda: dwivedi.diffusion_length(0.5, method), unknown_name, "method")
                self.assert_library_error(lambda: dwivedi.DwivediDistribution(0.5, method), unknown_name)
        self.assert_library_error(lambda: dwivedi.diffusion_length(0.5, "foo"), unknown_name, "'foo'")

    def test_bad_u_and_cosine(self) -> None:
        dist = dwivedi.DwivediDistribution(0.9)
        for call, name in ((dist.sample, "u"), (dist.sample_pdf, "u"), (dist.pdf, "cos_theta"),
                           (dist.stretch, "cos_theta")):
            with self.subTest(call=call):
                self.assert_library_error(lambda: call(1.5), 3, name, "1.5")
                self.assert_library_error(lambda: call(-1.5), 3, name)
                self.assert_library_error(lambda: call(math.nan), 2, name, "NaN")
        self.assert_library_error(lambda: dist.sample(-0.1), 3, "u")
        self.assert_library_error(lambda: dwivedi.dwivedi_sample(0.9, 1.5), 3, "u")
        self.assert_library_error(lambda: dwivedi.dwivedi_pdf(0.9, 1.5), 3, "cos_theta")

    def test_a_failure_does_not_spoil_the_next_call(self) -> None:
        with self.assertRaises(dwivedi.Error):
            dwivedi.diffusion_length(2.0)
        self.assertEqual(dwivedi.diffusion_length(0.0), 1.0)


def run_child(env: Dict[str, str], cwd: str) -> Dict[str, object]:
    """Imports dwivedi in a fresh interpreter (so the library state of this one cannot leak in or
    out) and reports what library it found, or the error it raised."""
    code = (
        "import json, dwivedi\n"
        "report = {'imported': True}\n"
        "try:\n"
        "    report['version'] = dwivedi.version()\n"
        "    report['path'] = dwivedi.library_path()\n"
        "except dwivedi.Error as error:\n"
        "    report['error'] = str(error)\n"
        "    report['code'] = error.code\n"
        "print(json.dumps(report))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], env=env, cwd=cwd, capture_output=True, text=True,
                          timeout=60)
    if done.returncode != 0:
        raise AssertionError(f"child failed ({done.returncode}): {done.stderr}")
    return json.loads(done.stdout)


def child_env(python_path: Path, library: Optional[str]) -> Dict[str, str]:
    env = dict(os.environ)
    env.pop("DWIVEDI_LIBRARY", None)
    if library is not None:
        env["DWIVEDI_LIBRARY"] = library
    env["PYTHONPATH"] = str(python_path)
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    return env


class LoadedLibraryPathTest(unittest.TestCase):
    """dwivedi.loaded_library_path(): None before the first load (and it never loads one), the
    file in use after; dwivedi.ABI_VERSION is the header's DWV_ABI_VERSION."""

    def test_none_before_a_load_then_the_file(self) -> None:
        code = ("import json, dwivedi\n"
                "before = dwivedi.loaded_library_path()\n"
                "again = dwivedi.loaded_library_path()\n"
                "version = dwivedi.version()\n"
                "print(json.dumps([before, again, dwivedi.loaded_library_path(), dwivedi.library_path()]))\n")
        env = child_env(Path(dwivedi.__file__).parent.parent, os.environ["DWIVEDI_LIBRARY"])
        done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=60)
        self.assertEqual(done.returncode, 0, done.stderr)
        before, again, after, path = json.loads(done.stdout)
        self.assertIsNone(before)
        self.assertIsNone(again, "asking does not load the library")
        self.assertEqual(after, path)
        self.assertEqual(Path(after).resolve(), Path(os.environ["DWIVEDI_LIBRARY"]).resolve())

    def test_abi_version_is_the_headers(self) -> None:
        header = (SOURCE_DIR / "capi" / "dwivedi.h").read_text()
        found = re.search(r"#define DWV_ABI_VERSION (\d+)", header)
        self.assertIsNotNone(found)
        self.assertEqual(dwivedi.ABI_VERSION, int(found.group(1)))
        self.assertIn("loaded_library_path", dwivedi.__all__)
        self.assertIn("loaded_library_path", dwivedi.__doc__)


class DiscoveryTest(unittest.TestCase):
    def setUp(self) -> None:
        self.work = Path(tempfile.mkdtemp(prefix="dwivedi-shim-test-"))
        self.library_file = Path(os.environ["DWIVEDI_LIBRARY"]).resolve()
        # The directory holding the package under test.
        self.shim = Path(dwivedi.__file__).parent.parent

    def tearDown(self) -> None:
        shutil.rmtree(self.work)

    def test_missing_configured_library_is_an_error_naming_it(self) -> None:
        missing = str(self.work / "nowhere" / "libdwivedi.so.1")
        report = run_child(child_env(self.shim, missing), str(self.work))
        self.assertTrue(report["imported"])  # loading is lazy: import never fails
        self.assertIn(missing, report["error"])
        self.assertIn("DWIVEDI_LIBRARY", report["error"])
        self.assertIsNone(report["code"])
        self.assertNotIn("path", report)

    def test_unloadable_configured_library_does_not_fall_back(self) -> None:
        not_a_library = str(SOURCE_DIR / "capi" / "dwivedi.h")
        report = run_child(child_env(self.shim, not_a_library), str(self.work))
        self.assertIn(not_a_library, report["error"])
        self.assertNotIn("path", report)

    def test_found_in_the_build_tree_without_configuration(self) -> None:
        # The source tree's own layout: the shim in python_shim/, libraries in build*/ (ctest's
        # build directory is one of them). An out-of-tree build (cmake -B /elsewhere) gets that
        # layout made around it: a source tree whose build/ is that build directory.
        build_dir = Path(os.environ["DWIVEDI_BUILD_DIR"]).resolve()
        root = SOURCE_DIR.resolve()
        if build_dir.parent != root or not build_dir.name.startswith("build"):
            root = self.make_tree()
            (root / "build").symlink_to(build_dir, target_is_directory=True)
        report = run_child(child_env(root / "python_shim", None), str(self.work))
        self.assertEqual(report.get("version"), header_version(), report)
        found = Path(os.path.abspath(str(report["path"])))
        self.assertEqual(found.name, "libdwivedi.so.1")
        self.assertEqual(found.parent.parent, root)
        self.assertTrue(found.parent.name.startswith("build"))

    def make_tree(self) -> Path:
        """A copy of the shim in a minimal source tree: <tree>/capi/dwivedi.h marks the root."""
        tree = self.work / "tree"
        (tree / "capi").mkdir(parents=True)
        (tree / "capi" / "dwivedi.h").write_text("/* marker */\n")
        shutil.copytree(Path(dwivedi.__file__).parent, tree / "python_shim" / "dwivedi",
                        ignore=shutil.ignore_patterns("__pycache__"))
        return tree

    def place_library(self, directory: Path, name: str = "libdwivedi.so.1", mtime: Optional[float] = None) -> Path:
        directory.mkdir(parents=True, exist_ok=True)
        target = directory / name
        shutil.copyfile(self.library_file, target)
        if mtime is not None:
            os.utime(target, (mtime, mtime))
        return target

    def found_in(self, tree: Path, library: Optional[str] = None) -> Path:
        report = run_child(child_env(tree / "python_shim", library), str(self.work))
        self.assertIn("path", report, report)
        return Path(str(report["path"]))

    def test_search_order(self) -> None:
        tree = self.make_tree()
        # Among build*/ other than build/, the most recently built first.
        self.place_library(tree / "build-old", mtime=1_000_000_000)
        newest = self.place_library(tree / "build-new", mtime=1_500_000_000)
        self.assertEqual(self.found_in(tree), newest)
        # An empty DWIVEDI_LIBRARY counts as unset.
        self.assertEqual(self.found_in(tree, library=""), newest)
        # build/ before the other build directories.
        in_build = self.place_library(tree / "build", mtime=1_000_000_000)
        self.assertEqual(self.found_in(tree), in_build)
        # Beside the package (its parent directory) before the build tree.
        beside = self.place_library(tree / "python_shim")
        self.assertEqual(self.found_in(tree), beside)
        # Inside the package before its parent, libdwivedi.so accepted too.
        inside = self.place_library(tree / "python_shim" / "dwivedi", name="libdwivedi.so")
        self.assertEqual(self.found_in(tree), inside)
        # DWIVEDI_LIBRARY before everything.
        configured = self.place_library(self.work / "elsewhere")
        self.assertEqual(self.found_in(tree, library=str(configured)), configured)

    def test_nothing_found_lists_where_it_looked(self) -> None:
        tree = self.make_tree()
        report = run_child(child_env(tree / "python_shim", None), str(self.work))
        self.assertTrue(report["imported"])
        if "path" in report:
            # Only a library installed on the system may be found, never one from elsewhere.
            self.assertFalse(str(report["path"]).startswith(str(self.work)), report)
            self.assertNotIn("/", str(report["path"]), report)
        else:
            message = str(report["error"])
            for place in (tree / "python_shim" / "dwivedi" / "libdwivedi.so.1",
                          tree / "python_shim" / "libdwivedi.so.1", tree / "build" / "libdwivedi.so.1"):
                self.assertIn(str(place), message)
            self.assertIn("DWIVEDI_LIBRARY", message)
            self.assertIn("system", message)


if __name__ == "__main__":
    unittest.main()
