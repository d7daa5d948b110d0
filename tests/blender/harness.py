"""Shared set-up of the headless Blender tests (run by ctest: see tests/CMakeLists.txt).

Each test script starts Blender with --factory-startup and user folders of its own under
DWIVEDI_TEST_HOME (emptied here first, so nothing is cached between runs), installs the add-on
from the package the build made for this Blender (3.x: the legacy zip DWIVEDI_ADDON_ZIP; 4.2+:
the extension DWIVEDI_EXTENSION_ZIP), enables it, runs its unittest cases and exits with 0 only
if all passed. The scripts run by tests/blender/run_package_tests.py (host or chroot) get this
file beside them.
"""
import ctypes
import math
import os
import shutil
import sys
import time
import unittest
from pathlib import Path

import bpy

HERE = Path(__file__).resolve().parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

HOME = Path(os.environ.get("DWIVEDI_TEST_HOME", "/tmp/dwivedi-blender-test"))
ZIP = Path(os.environ.get("DWIVEDI_ADDON_ZIP", HERE.parents[1] / "build" / "dwivedi_bake.zip"))
EXTENSION_ZIP = os.environ.get("DWIVEDI_EXTENSION_ZIP")
EXTENSIONS = bpy.app.version >= (4, 2, 0)
MODULE = "bl_ext.user_default.dwivedi_bake" if EXTENSIONS else "dwivedi_bake"
WORK = HOME / "work"


def preload_scratch_dependencies():
    """Only for a bundled library that still links its dependencies dynamically (the scratch set-up
    of run_package_tests.py, DWIVEDI_TEST_PRELOAD, never the package): loads them first so the
    loader finds them."""
    folder = os.environ.get("DWIVEDI_TEST_PRELOAD")
    if not folder:
        return
    pending = sorted(str(p) for p in Path(folder).iterdir())
    while pending:
        left = []
        for path in pending:
            try:
                ctypes.CDLL(path, mode=ctypes.RTLD_GLOBAL)
            except OSError:
                left.append(path)
        if len(left) == len(pending):
            raise SystemExit(f"harness: cannot preload {left}")
        pending = left


def install_addon():
    """A fresh home, the add-on installed from this Blender's package and enabled; returns the
    work folder."""
    scripts = os.environ.get("BLENDER_USER_SCRIPTS")
    if not scripts or not Path(scripts).resolve().is_relative_to(HOME.resolve()):
        raise SystemExit("harness: BLENDER_USER_SCRIPTS must point inside DWIVEDI_TEST_HOME (run these through "
                         "ctest, which sets both), so that the add-on never lands in a real user's folder")
    if WORK.exists():
        shutil.rmtree(WORK)
    WORK.mkdir(parents=True)
    preload_scratch_dependencies()
    if EXTENSIONS:
        if not EXTENSION_ZIP or not Path(EXTENSION_ZIP).is_file():
            raise SystemExit(f"harness: Blender {bpy.app.version_string} installs the extension package: "
                             f"DWIVEDI_EXTENSION_ZIP={EXTENSION_ZIP} is not a file (run_package_tests.py sets it)")
        result = bpy.ops.extensions.package_install_files(filepath=EXTENSION_ZIP, repo='user_default',
                                                          enable_on_install=False)
    else:
        if not ZIP.is_file():
            raise SystemExit(f"harness: no add-on zip at {ZIP} (build the dwivedi_bake_addon target)")
        result = bpy.ops.preferences.addon_install(filepath=str(ZIP), overwrite=True)
    assert result == {'FINISHED'}, result
    result = bpy.ops.preferences.addon_enable(module=MODULE)
    assert result == {'FINISHED'}, result
    return WORK


def addon_module(part=None):
    """The loaded add-on package, or its submodule `part` ("export", "dwivedi")."""
    return sys.modules[MODULE if part is None else f"{MODULE}.{part}"]


def run(*cases):
    """Runs the TestCase classes and exits Blender with 0 (all passed) or 1."""
    suite = unittest.TestSuite()
    loader = unittest.TestLoader()
    for case in cases:
        suite.addTests(loader.loadTestsFromTestCase(case))
    outcome = unittest.TextTestRunner(stream=sys.stdout, verbosity=2).run(suite)
    sys.stdout.flush()
    sys.exit(0 if outcome.wasSuccessful() else 1)


def call_operator(**settings):
    """Sets scene.dwivedi_bake fields and runs bpy.ops.dwivedi.bake(); returns (result, error
    message or None). In background mode an operator that reports an ERROR raises RuntimeError
    carrying the report, and returns CANCELLED."""
    props = bpy.context.scene.dwivedi_bake
    for key, value in settings.items():
        setattr(props, key, value)
    try:
        return bpy.ops.dwivedi.bake(), None
    except RuntimeError as error:
        return {'CANCELLED'}, str(error)


def image_pixels(name):
    """The float RGBA pixels of the Blender image `name` (rows from the bottom), with its size."""
    image = bpy.data.images[name]
    width, height = image.size
    pixels = [0.0] * (4 * width * height)
    image.pixels.foreach_get(pixels)
    return width, height, pixels


def read_pixels(path):
    """The float RGBA pixels of an image file as Blender loads it (rows from the bottom), with
    its size; EXR gives scene-linear floats, PNG the stored bytes / 255."""
    image = bpy.data.images.load(str(path), check_existing=False)
    try:
        width, height = image.size
        pixels = [0.0] * (4 * width * height)
        image.pixels.foreach_get(pixels)
        return width, height, pixels
    finally:
        bpy.data.images.remove(image)


def cycles_render(scene, seed, samples, path):
    """Cycles' render of `scene` with `seed` and `samples` into the 32-bit EXR `path`: (float
    RGBA pixels, seconds)."""
    scene.cycles.seed = seed
    scene.cycles.samples = samples
    scene.render.image_settings.file_format = 'OPEN_EXR'
    scene.render.image_settings.color_depth = '32'
    scene.render.filepath = str(path)
    start = time.monotonic()
    bpy.ops.render.render(write_still=True)
    seconds = time.monotonic() - start
    _, _, pixels = read_pixels(path)
    return pixels, seconds


def dwivedi_bake(scene, seed, samples, output_dir, event_cap=None):
    """The add-on's camera bake of `scene` (technique auto, 2 threads) into `output_dir`: (float
    RGBA pixels, seconds). `event_cap`: the Walk Event Cap (None: the add-on's default)."""
    props = scene.dwivedi_bake
    props.samples = samples
    if event_cap is not None:
        props.walk_event_cap = event_cap
    props.threads = 2
    props.seed = seed
    props.technique = 'AUTO'
    props.output_dir = str(output_dir)
    start = time.monotonic()
    result, error = call_operator()
    seconds = time.monotonic() - start
    if result != {'FINISHED'}:
        raise AssertionError(f"the bake failed: {error}")
    _, _, pixels = image_pixels("Dwivedi Camera")
    return pixels, seconds


def render_and_bake(name, scene, cycles_samples, dwivedi_samples, work, event_cap=256, seeds=(1, 2)):
    """Cycles' renders and the add-on's bakes of `scene` with each of `seeds` (files `name`_* in
    `work`), compared (compare_seeds) with their times and samples. The event cap defaults to
    Cycles' own 256 events per walk (BSSRDF_MAX_BOUNCES), as test_fidelity.py."""
    cycles, ours, cycles_seconds, ours_seconds = [], [], 0.0, 0.0
    for seed in seeds:
        pixels, seconds = cycles_render(scene, seed, cycles_samples, work / f"{name}_cycles_{seed}.exr")
        cycles.append(pixels)
        cycles_seconds += seconds
    for seed in seeds:
        pixels, seconds = dwivedi_bake(scene, seed, dwivedi_samples, work / f"{name}_dwivedi_{seed}", event_cap)
        ours.append(pixels)
        ours_seconds += seconds
    return {**compare_seeds(cycles, ours), "cycles_seconds": cycles_seconds,
            "cycles_samples": len(seeds) * cycles_samples, "dwivedi_seconds": ours_seconds,
            "dwivedi_samples": len(seeds) * dwivedi_samples}


def compare_two_seeds(cycles_pair, ours_pair):
    """Cycles' and dwivedi's two-seed images of one scene (RGBA lists) compared: compare_seeds
    with two seeds each."""
    return compare_seeds(cycles_pair, ours_pair)


def compare_seeds(cycles_images, ours_images):
    """Cycles' and dwivedi's images of one scene from k >= 2 seeds each (RGBA lists) compared:
    means per channel of the k-seed means, their relative difference, and per channel the noise
    ratio R = sum (ours - cycles)^2 / sum (var_ours + var_cycles), each side's per-pixel variance
    of its k-seed mean estimated from the k seeds, sum (a_j - mean)^2 / (k (k - 1)) (with two
    seeds (a1 - a2)^2 / 4): 1 in expectation when both estimate the same image, larger with any
    bias; and the standard error of the difference of the means from the same variances,
    sqrt(sum (var_ours + var_cycles)) / pixels, relative to Cycles' mean (what the mean test's
    tolerance must stand well above). More seeds steady R's denominator (each pixel's variance
    estimate has k - 1 degrees of freedom); its numerator is steadied only by more pixels with
    comparable variance: `effective_pixels_rgb`, N = (sum v_i)^2 / sum v_i^2 of the per-pixel
    variances v_i (from the seeds, so rather low), gives R's spread where the images agree: a
    standard deviation of about sqrt(2 k / (N (k - 1))) for Gaussian pixel means (a chi-square
    of N degrees over one of N (k - 1)), so that a bound of 1.5 is 3 of them above 1 only from
    N = 96 with k = 4 seeds, 144 with 2. A scene whose variance sits on a few pixels needs more
    pixels, not more samples."""
    def mean_and_variance(images):
        k = len(images)
        mean = [sum(values) / k for values in zip(*images)]
        variance = [sum((a - m) ** 2 for a in values) / (k * (k - 1)) for values, m in zip(zip(*images), mean)]
        return mean, variance
    cycles, var_cycles = mean_and_variance(cycles_images)
    ours, var_ours = mean_and_variance(ours_images)
    n = len(ours) // 4
    cm = [sum(cycles[c::4]) / n for c in range(3)]
    om = [sum(ours[c::4]) / n for c in range(3)]
    ratios, errors, effective = [], [], []
    for c in range(3):
        num = sum((ours[i] - cycles[i]) ** 2 for i in range(c, len(ours), 4))
        variances = [var_ours[i] + var_cycles[i] for i in range(c, len(ours), 4)]
        den = sum(variances)
        squares = sum(v * v for v in variances)
        ratios.append(num / den if den > 0 else (0.0 if num == 0 else math.inf))
        errors.append(math.sqrt(den) / n / cm[c] if cm[c] > 0 else None)
        effective.append(den * den / squares if squares > 0 else 0.0)
    return {
        "cycles_mean_rgb": cm, "dwivedi_mean_rgb": om,
        "relative_difference_rgb": [(o - c) / c if c > 0 else None for o, c in zip(om, cm)],
        "noise_ratio_rgb": ratios, "relative_standard_error_rgb": errors, "effective_pixels_rgb": effective,
        "nan_pixels": sum(1 for v in ours if v != v),
    }


def assert_agreement(test, figures, mean_tolerance=0.02, noise_ratio_limit=1.5):
    """The bounds of the Cycles comparisons (compare_two_seeds' figures) on unittest case `test`:
    every channel has signal in Cycles, its mean within `mean_tolerance` of Cycles' and its noise
    ratio below `noise_ratio_limit`."""
    for c in range(3):
        cm, om = figures["cycles_mean_rgb"][c], figures["dwivedi_mean_rgb"][c]
        test.assertGreater(cm, 1e-3, f"channel {c} has signal in Cycles")
        test.assertLess(abs(om / cm - 1.0), mean_tolerance, f"channel {'RGB'[c]}: dwivedi {om:.5f} vs Cycles {cm:.5f}")
        test.assertLess(figures["noise_ratio_rgb"][c], noise_ratio_limit,
                        f"channel {'RGB'[c]}: per-pixel differences exceed the noise")
