"""Shared set-up of the headless Blender tests (run by ctest: see tests/CMakeLists.txt).

Each test script starts Blender with --factory-startup and user folders of its own under
DWIVEDI_TEST_HOME (emptied here first, so nothing is cached between runs), installs the add-on
from the zip the build made (DWIVEDI_ADDON_ZIP), enables it, runs its unittest cases and exits
with 0 only if all passed.
"""
import os
import shutil
import sys
import unittest
from pathlib import Path

import bpy

HERE = Path(__file__).resolve().parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

HOME = Path(os.environ.get("DWIVEDI_TEST_HOME", "/tmp/dwivedi-blender-test"))
ZIP = Path(os.environ.get("DWIVEDI_ADDON_ZIP", HERE.parents[1] / "build" / "dwivedi_bake.zip"))
WORK = HOME / "work"


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


def cycles_render(scene, seed, samples, path):
    """Renders `scene` with Cycles (seed, samples) into the float EXR `path`; (pixels, seconds)."""
    import time
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


def dwivedi_bake(scene, seed, samples, output_dir):
    """Bakes `scene` with the add-on (technique auto, 2 threads) into `output_dir`; (pixels of the
    loaded result, seconds)."""
    import time
    props = scene.dwivedi_bake
    props.samples = samples
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
