"""Shared set-up of the headless Blender tests (run by ctest: see tests/CMakeLists.txt).

Each test script starts Blender with --factory-startup and user folders of its own under
DWIVEDI_TEST_HOME (emptied here first, so nothing is cached between runs), installs the add-on
from the zip the build made (DWIVEDI_ADDON_ZIP), enables it, runs its unittest cases and exits
with 0 only if all passed.
"""
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
WORK = HOME / "work"


def preload_scratch_dependencies():
    """run_fidelity_chroot.sh's scratch set-up for a library that is not self-contained
    (DWIVEDI_PRELOAD: a wrapper needing this Blender's malloc, then the library; the host
    dependencies beside it): one dlopen with RTLD_DEEPBIND, so that the library binds to its own
    Embree 3 and OpenEXR rather than the Embree 4 / OpenEXR this Blender loaded under the same
    symbol names (without it every ray misses). The add-on's shim then opens the same file
    (DWIVEDI_LIBRARY): the same handle. Branch native's self-contained library needs none of it."""
    wrapper = os.environ.get("DWIVEDI_PRELOAD")
    if not wrapper or not Path(wrapper).is_file():
        return
    import ctypes
    ctypes.CDLL(wrapper, mode=ctypes.RTLD_LOCAL | getattr(os, "RTLD_DEEPBIND", 8))
    print(f"harness: scratch set-up: {wrapper} (the library and its host dependencies) loaded with "
          "RTLD_DEEPBIND", flush=True)


def install_addon():
    """A fresh home, the add-on installed from the zip and enabled; returns the work folder."""
    scripts = os.environ.get("BLENDER_USER_SCRIPTS")
    if not scripts or not Path(scripts).resolve().is_relative_to(HOME.resolve()):
        raise SystemExit("harness: BLENDER_USER_SCRIPTS must point inside DWIVEDI_TEST_HOME (run these through "
                         "ctest, which sets both), so that the add-on never lands in a real user's folder")
    if WORK.exists():
        shutil.rmtree(WORK)
    WORK.mkdir(parents=True)
    if not ZIP.is_file():
        raise SystemExit(f"harness: no add-on zip at {ZIP} (build the dwivedi_bake_addon target)")
    result = bpy.ops.preferences.addon_install(filepath=str(ZIP), overwrite=True)
    assert result == {'FINISHED'}, result
    result = bpy.ops.preferences.addon_enable(module="dwivedi_bake")
    assert result == {'FINISHED'}, result
    return WORK


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


def cycles_render(scene, seed, path, samples):
    """The scene rendered by Cycles with `seed` and `samples` into the EXR `path`: its RGBA
    pixels (rows from the bottom) and the seconds it took."""
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


def dwivedi_bake(scene, seed, output_dir, samples, walk_event_cap=0):
    """The add-on's camera bake of the scene (technique auto, 2 threads) into `output_dir`: its
    RGBA pixels and the seconds it took; AssertionError if it failed."""
    props = scene.dwivedi_bake
    props.samples = samples
    props.walk_event_cap = walk_event_cap
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


def agreement(c1, c2, o1, o2):
    """Cycles' two seeds c1, c2 against dwivedi's o1, o2 (RGBA pixel lists): the two-seed means'
    channel means, their relative difference, and the noise ratio per channel
    R = sum (ours - cycles)^2 / sum (var_ours + var_cycles), each side's per-pixel variance of
    its two-seed mean estimated from its seeds as (a1 - a2)^2 / 4: 1 in expectation when both
    estimate the same image."""
    cycles = [(a + b) / 2 for a, b in zip(c1, c2)]
    ours = [(a + b) / 2 for a, b in zip(o1, o2)]
    n = len(ours) // 4
    cm = [sum(cycles[c::4]) / n for c in range(3)]
    om = [sum(ours[c::4]) / n for c in range(3)]
    ratios = []
    for c in range(3):
        num = sum((ours[i] - cycles[i]) ** 2 for i in range(c, len(ours), 4))
        den = sum(((o1[i] - o2[i]) ** 2 + (c1[i] - c2[i]) ** 2) / 4 for i in range(c, len(ours), 4))
        ratios.append(num / den if den > 0 else (0.0 if num == 0 else math.inf))
    return {"cycles_mean_rgb": cm, "dwivedi_mean_rgb": om,
            "relative_difference_rgb": [(o - c) / c if c > 0 else None for o, c in zip(om, cm)],
            "noise_ratio_rgb": ratios, "nan_pixels": sum(1 for v in ours if v != v)}
