"""The add-on's packages in whichever Blender runs this: Blender 3.x installs the legacy zip
(bpy.ops.preferences.addon_install), 4.2+ the extension (bpy.ops.extensions.package_install_files),
each through Blender's own operators; then, in this order (the process keeps what it loaded):

1. every bad library file where the add-on looks for its bundled library (a missing dependency
   first, while nothing is loaded; then missing, another CPU, truncated, not ELF, ABI too old,
   too new, functions missing): enabling works, the panel shows the problem with an ERROR icon,
   the bake reports it as an error and writes nothing;
2. the real library back: a camera bake and a UV bake of a Principled-subsurface scene, with
   no "not mapped" warning in any version (every method is mapped: test_fidelity);
3. a bake cancelled (a KeyboardInterrupt in the main thread during the bake, as Python's Ctrl-C;
   Esc belongs to the UI's modal path, which headless Blender has not), then a bake;
4. a bad file named in the preferences (a different path: the loader's message), then none; the
   loaded file replaced under Blender ("restart Blender");
5. a read-only add-on folder (a read-only bind mount in the private mount namespace the runner
   gives us as root; chmod otherwise): it enables and bakes, and nothing in it changes;
6. a second copy enabled at once (the legacy add-on beside the extension on 4.2+; a second
   folder on 3.x): it refuses with a message, the first keeps baking; on 4.2+ the other order too;
7. disable and enable again, and bake.

    blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_package.py
run by tests/blender/run_package_tests.py (host or chroot), which sets:
DWIVEDI_TEST_HOME (emptied, the user folders inside), DWIVEDI_ADDON_ZIP, DWIVEDI_EXTENSION_ZIP,
DWIVEDI_FIXTURES (tests/blender/fixtures.py's output), DWIVEDI_TEST_TIMES (a JSON file of seconds
per step), optionally DWIVEDI_TEST_PRELOAD (a scratch folder of the library's own dependencies,
loaded first: only while the bundled library is not yet self-contained) and
DWIVEDI_PRIVATE_MOUNTS=1 (this process has a mount namespace of its own).
"""
import ctypes
import json
import os
import shutil
import sys
import threading
import time
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bpy  # noqa: E402

import harness  # noqa: E402  (beside this file: run_package_tests.py copies it)
import scenes  # noqa: E402

HOME = Path(os.environ["DWIVEDI_TEST_HOME"])
LEGACY_ZIP = Path(os.environ["DWIVEDI_ADDON_ZIP"])
EXTENSION_ZIP = Path(os.environ["DWIVEDI_EXTENSION_ZIP"])
FIXTURES = Path(os.environ["DWIVEDI_FIXTURES"])
TIMES_FILE = os.environ.get("DWIVEDI_TEST_TIMES")
WORK = HOME / "work"
OUT = WORK / "out"
EXTENSIONS = harness.EXTENSIONS  # 4.2+: the extension package, else the legacy zip
MODULE = harness.MODULE
TIMES = {}


def timed(name):
    def wrap(function):
        def run(*args, **kwargs):
            start = time.monotonic()
            try:
                return function(*args, **kwargs)
            finally:
                TIMES[name] = round(time.monotonic() - start, 3)
        run.__name__ = function.__name__
        return run
    return wrap


def check_home():
    scripts = os.environ.get("BLENDER_USER_SCRIPTS", "")
    if not scripts or not Path(scripts).resolve().is_relative_to(HOME.resolve()):
        raise SystemExit("test_package: BLENDER_USER_SCRIPTS must point inside DWIVEDI_TEST_HOME (run it through "
                         "tests/blender/run_package_tests.py) so nothing lands in a real user's folder")
    for path in (LEGACY_ZIP, EXTENSION_ZIP, FIXTURES):
        if not path.exists():
            raise SystemExit(f"test_package: {path} is missing")
    if WORK.exists():
        shutil.rmtree(WORK)
    OUT.mkdir(parents=True)


def module():
    return sys.modules[MODULE]


class RecordingLayout:
    """Records what a panel's draw() puts in its layout (headless Blender has no region to draw
    into): (kind, text, icon) per label."""

    def __init__(self, sink=None):
        self.items = sink if sink is not None else []
        self.use_property_split = False
        self.use_property_decorate = False
        self.enabled = True

    def label(self, text="", icon='NONE', **_):
        self.items.append(("label", text, icon))

    def prop(self, data, name, **_):
        self.items.append(("prop", name, ""))

    def operator(self, idname, **_):
        self.items.append(("operator", idname, ""))

    def column(self, **_):
        return RecordingLayout(self.items)

    row = box = column


def panel_labels():
    layout = RecordingLayout()
    panel = type("Panel", (), {"layout": layout})()
    bpy.types.DWIVEDI_PT_bake.draw(panel, bpy.context)
    return layout.items


def bundled_library():
    return Path(module().BUNDLED_LIBRARY)


def put(source, target):
    """Replaces `target` by a copy of `source` through a rename (a new file, as an installer does:
    a library Blender has mapped is never overwritten in place)."""
    temporary = target.with_name(target.name + ".new")
    shutil.copyfile(source, temporary)
    os.replace(temporary, target)


def snapshot(folder):
    return sorted((str(p.relative_to(folder)), p.stat().st_size, p.stat().st_mtime_ns)
                  for p in Path(folder).rglob("*"))


def slab():
    scene = scenes.slab_scene(resolution=16, samples=4)
    props = scene.dwivedi_bake
    props.samples = 4
    props.threads = 2
    props.output_dir = str(OUT)
    props.target = 'CAMERA'
    props.time_limit = 0.0
    return scene


class PackageTest(unittest.TestCase):
    maxDiff = None

    def assertRefused(self, fragment):
        """The panel shows `fragment` with an ERROR icon, a bake reports it and writes nothing."""
        labels = panel_labels()
        self.assertIn(("label", "dwivedi library not usable:", 'ERROR'), labels)
        shown = " ".join(text for kind, text, _ in labels if kind == "label")
        self.assertIn(fragment, shown.replace("  ", " "))
        self.assertIn(("operator", "dwivedi.bake", ""), labels, "the panel stays usable")
        before = snapshot(OUT)
        result, error = harness.call_operator()
        self.assertEqual(result, {'CANCELLED'})
        self.assertIsNotNone(error, "the bake reports an error")
        self.assertIn("the dwivedi library cannot be used", error)
        self.assertIn(fragment, error)
        self.assertEqual(snapshot(OUT), before, "nothing is written")

    @timed("install")
    def test_01_install(self):
        if EXTENSIONS:
            result = bpy.ops.extensions.package_install_files(filepath=str(EXTENSION_ZIP), repo='user_default',
                                                              enable_on_install=False)
        else:
            result = bpy.ops.preferences.addon_install(filepath=str(LEGACY_ZIP), overwrite=True)
        self.assertEqual(result, {'FINISHED'})
        import addon_utils
        names = [m.__name__ for m in addon_utils.modules(refresh=True)]
        self.assertIn(MODULE, names)

    @timed("missing dependency")
    def test_02_missing_dependency_at_enable(self):
        import addon_utils
        folder = Path(next(m.__file__ for m in addon_utils.modules() if m.__name__ == MODULE)).parent
        library = folder / "dwivedi" / "libdwivedi.so.1"
        self.assertTrue(library.is_file(), "the package carries the library")
        shutil.copyfile(library, WORK / "good-libdwivedi.so.1")
        put(FIXTURES / "needs" / "libdwivedi.so.1", library)
        self.assertEqual(bpy.ops.preferences.addon_enable(module=MODULE), {'FINISHED'})
        self.assertTrue(hasattr(bpy.types.Scene, "dwivedi_bake"), "registered all the same")
        self.assertEqual(str(bundled_library()), str(library))
        slab()
        self.assertRefused("libdwivedi_test_missing.so.7: cannot open shared object file")
        status = module().library_status()
        self.assertFalse(status.ok)

    @timed("bad bundled files")
    def test_03_bad_bundled_files(self):
        library = bundled_library()
        cases = [
            ("aarch64", "is built for aarch64, this Blender runs on x86_64"),
            ("i386", "is built for x86 (i386) (32-bit), this Blender runs on x86_64"),
            ("truncated", "is damaged: truncated"),
            ("garbage", "is damaged or not a library: it is not an ELF file"),
            ("abi0", "is too old: libdwivedi ABI 0"),
            ("abi2", "is too new: libdwivedi ABI 2"),
            ("old", "is too old for this add-on: it lacks"),
        ]
        for case, fragment in cases:
            with self.subTest(case=case):
                put(FIXTURES / case / "libdwivedi.so.1", library)
                self.assertRefused(fragment)
        library.unlink()
        self.assertRefused("is missing (the add-on package is incomplete")
        # Disabled and enabled again with a bad file: the check at enable finds it too.
        put(FIXTURES / "aarch64" / "libdwivedi.so.1", library)
        bpy.ops.preferences.addon_disable(module=MODULE)
        self.assertEqual(bpy.ops.preferences.addon_enable(module=MODULE), {'FINISHED'})
        self.assertFalse(module().library_status().ok)
        self.assertIn("built for aarch64", module().library_status().message)

    @timed("camera and UV bakes")
    def test_04_bakes(self):
        put(WORK / "good-libdwivedi.so.1", bundled_library())
        harness.preload_scratch_dependencies()
        scene = slab()
        result, error = harness.call_operator()
        self.assertEqual(result, {'FINISHED'}, error)
        self.assertTrue(module().library_status().ok)
        shim = module().shim()
        self.assertEqual(shim.loaded_library_path(), str(bundled_library()))
        self.assertTrue((OUT / f"{scene.name}_camera.exr").is_file())
        self.assertTrue((OUT / f"{scene.name}_camera.png").is_file())
        image = bpy.data.images.get("Dwivedi Camera")
        self.assertIsNotNone(image)
        pixels = [0.0] * (4 * 16 * 16)
        image.pixels.foreach_get(pixels)
        self.assertGreater(sum(pixels[0::4]), 0.0, "light comes through the slab")
        warnings = module()._RUN.warnings
        # Every subsurface method of every version is mapped to its own Cycles model (test_fidelity).
        self.assertFalse([w for w in warnings if "not mapped" in w], warnings)
        # Nothing about the run is scene data (a .blend saved during a bake would keep it).
        self.assertFalse(set(scene.dwivedi_bake.keys()) & {"running", "progress", "last_result", "last_warnings"})
        target = scenes.bake_image(bpy.data.objects["Slab"], (32, 32))
        result, error = harness.call_operator(target='UV', uv_margin=2)
        self.assertEqual(result, {'FINISHED'}, error)
        self.assertTrue((OUT / f"{scene.name}_uv_Slab.exr").is_file())
        self.assertEqual(bpy.path.abspath(target.filepath), str(OUT / f"{scene.name}_uv_Slab.exr"))
        pixels = [0.0] * (4 * 32 * 32)
        target.pixels.foreach_get(pixels)
        self.assertGreater(sum(pixels[0::4]), 0.0, "the active image holds the bake")

    @timed("cancel")
    def test_05_cancel(self):
        scene = slab()
        for name in os.listdir(OUT):
            os.unlink(OUT / name)
        # A KeyboardInterrupt raised in Blender's main thread 1 s into the bake, as Python's Ctrl-C
        # would be (Blender keeps SIGINT for itself, and Esc belongs to the UI's modal path).
        main = threading.main_thread().ident
        interrupt = lambda: ctypes.pythonapi.PyThreadState_SetAsyncExc(ctypes.c_ulong(main),
                                                                         ctypes.py_object(KeyboardInterrupt))
        timer = threading.Timer(1.0, interrupt)
        try:
            start = time.monotonic()
            timer.start()
            result, error = harness.call_operator(samples=1 << 22)
            seconds = time.monotonic() - start
        finally:
            timer.cancel()
        self.assertEqual(result, {'CANCELLED'}, error)
        self.assertIsNone(error, "a cancel is a warning, not an error")
        self.assertLess(seconds, 30.0, "it stopped soon after the signal")
        self.assertEqual(os.listdir(OUT), [], "a cancelled bake writes nothing")
        result, error = harness.call_operator(samples=4)
        self.assertEqual(result, {'FINISHED'}, error)
        self.assertTrue((OUT / f"{scene.name}_camera.exr").is_file())

    @timed("preferences library")
    def test_06_preferences_library(self):
        slab()
        prefs = bpy.context.preferences.addons[MODULE].preferences
        copy = WORK / "elsewhere" / "libdwivedi.so.1"
        copy.parent.mkdir()
        shutil.copyfile(FIXTURES / "needs" / "libdwivedi.so.1", copy)
        prefs.library_path = str(copy)
        self.assertRefused("libdwivedi_test_missing.so.7")
        self.assertIn("the library named in the add-on preferences", module().library_status().message)
        prefs.library_path = ""
        result, error = harness.call_operator()
        self.assertEqual(result, {'FINISHED'}, error)
        # The loaded file replaced under Blender (an update while it runs): restart, it says.
        library = bundled_library()
        keep = WORK / "loaded-libdwivedi.so.1"
        os.link(library, keep)  # the loaded file itself, to put back
        put(WORK / "good-libdwivedi.so.1", library)
        self.assertRefused("was replaced since Blender loaded it: restart Blender")
        os.replace(keep, library)
        result, error = harness.call_operator()
        self.assertEqual(result, {'FINISHED'}, error)

    @timed("read-only folder")
    def test_07_read_only_folder(self):
        folder = Path(module().PACKAGE_DIR)
        before = snapshot(folder)
        undo = make_read_only(folder)
        try:
            with self.assertRaises(OSError, msg="the add-on folder is really read-only"):
                (folder / "probe").write_text("x")
            bpy.ops.preferences.addon_disable(module=MODULE)
            self.assertEqual(bpy.ops.preferences.addon_enable(module=MODULE), {'FINISHED'})
            self.assertTrue(module().library_status().ok, module().library_status().message)
            scene = slab()
            result, error = harness.call_operator()
            self.assertEqual(result, {'FINISHED'}, error)
            # An unsaved file's "//" is nowhere: a script is told to name a folder (the UI asks for
            # one), and nothing goes to the package folder or a temporary folder.
            result, error = harness.call_operator(output_dir="//dwivedi_bake/")
            self.assertEqual(result, {'CANCELLED'})
            self.assertIn("the .blend is not saved", error or "")
            self.assertTrue((OUT / f"{scene.name}_camera.exr").is_file())
        finally:
            undo()
        self.assertEqual(snapshot(folder), before, "nothing in the add-on folder changed")

    @timed("second copy")
    def test_08_second_copy(self):
        import addon_utils
        if EXTENSIONS:
            other = "dwivedi_bake"
            result = bpy.ops.preferences.addon_install(filepath=str(LEGACY_ZIP), overwrite=True)
            self.assertEqual(result, {'FINISHED'})
        else:
            other = "dwivedi_bake_copy"
            source = Path(module().PACKAGE_DIR)
            shutil.copytree(source, source.parent / other)
            addon_utils.modules(refresh=True)
        try:
            with self.assertRaises(RuntimeError) as caught:
                bpy.ops.preferences.addon_enable(module=other)
            self.assertIn(f"Dwivedi Subsurface Bake is already enabled as '{MODULE}'", str(caught.exception))
            self.assertFalse(addon_utils.check(other)[1], "the second copy is not enabled")
            self.assertNotIn(other, sys.modules)
            self.assertTrue(addon_utils.check(MODULE)[1], "the first copy still is")
            slab()
            result, error = harness.call_operator()
            self.assertEqual(result, {'FINISHED'}, error)
            if EXTENSIONS:
                # The other order: the legacy add-on enabled first, then the extension refused.
                self.assertEqual(bpy.ops.preferences.addon_disable(module=MODULE), {'FINISHED'})
                self.assertEqual(bpy.ops.preferences.addon_enable(module=other), {'FINISHED'})
                with self.assertRaises(RuntimeError) as caught:
                    bpy.ops.preferences.addon_enable(module=MODULE)
                self.assertIn(f"Dwivedi Subsurface Bake is already enabled as '{other}'", str(caught.exception))
                self.assertTrue(addon_utils.check(other)[1])
                self.assertEqual(bpy.ops.preferences.addon_disable(module=other), {'FINISHED'})
                self.assertEqual(bpy.ops.preferences.addon_enable(module=MODULE), {'FINISHED'})
                result, error = harness.call_operator()
                self.assertEqual(result, {'FINISHED'}, error)
        finally:
            # (Not addon_remove: in background mode it fails in Blender's own code, on context.area.)
            folder = next((Path(m.__file__).parent for m in addon_utils.modules(refresh=True) if m.__name__ == other),
                          None)
            if folder is not None:
                shutil.rmtree(folder)
            addon_utils.modules(refresh=True)

    @timed("disable and enable")
    def test_09_disable_enable(self):
        self.assertEqual(bpy.ops.preferences.addon_disable(module=MODULE), {'FINISHED'})
        self.assertFalse(hasattr(bpy.types.Scene, "dwivedi_bake"))
        self.assertFalse(hasattr(bpy.types, "DWIVEDI_OT_bake"))
        self.assertEqual(bpy.ops.preferences.addon_enable(module=MODULE), {'FINISHED'})
        slab()
        result, error = harness.call_operator()
        self.assertEqual(result, {'FINISHED'}, error)


def make_read_only(folder):
    """Makes `folder` read-only and returns the function that undoes it: a read-only bind mount
    where this process may (root, in a mount namespace of its own), else chmod a-w (enough for a
    user other than root)."""
    if os.geteuid() == 0:
        if os.environ.get("DWIVEDI_PRIVATE_MOUNTS") != "1":
            raise AssertionError("as root the runner must give this process a mount namespace of its own")
        libc = ctypes.CDLL(None, use_errno=True)
        libc.mount.argtypes = [ctypes.c_char_p, ctypes.c_char_p, ctypes.c_char_p, ctypes.c_ulong, ctypes.c_void_p]
        ms_rdonly, ms_remount, ms_bind = 1, 32, 4096
        target = str(folder).encode()
        if libc.mount(target, target, None, ms_bind, None) != 0:
            raise OSError(ctypes.get_errno(), f"bind mount of {folder}")
        if libc.mount(None, target, None, ms_remount | ms_bind | ms_rdonly, None) != 0:
            error = ctypes.get_errno()
            libc.umount2(target, 0)
            raise OSError(error, f"read-only remount of {folder}")
        return lambda: libc.umount2(target, 0)
    modes = {}
    for path in [folder, *folder.rglob("*")]:
        modes[path] = path.stat().st_mode
        path.chmod(modes[path] & ~0o222)

    def undo():
        for path, mode in modes.items():
            path.chmod(mode)
    return undo


def main():
    check_home()
    if os.geteuid() == 0 and os.environ.get("DWIVEDI_PRIVATE_MOUNTS") != "1":
        raise SystemExit("test_package: as root, run it in a mount namespace of its own (run_package_tests.py "
                         "does, with unshare -m) and set DWIVEDI_PRIVATE_MOUNTS=1")
    print(f"test_package: Blender {bpy.app.version_string}, module {MODULE}")
    suite = unittest.TestLoader().loadTestsFromTestCase(PackageTest)
    # Stop at the first failure: later steps build on earlier ones.
    failfast = os.environ.get("DWIVEDI_TEST_KEEP_GOING") != "1"
    outcome = unittest.TextTestRunner(stream=sys.stdout, verbosity=2, failfast=failfast).run(suite)
    if TIMES_FILE:
        Path(TIMES_FILE).write_text(json.dumps({"blender": bpy.app.version_string, "seconds": TIMES}, indent=1))
    sys.stdout.flush()
    sys.exit(0 if outcome.wasSuccessful() and outcome.testsRun == 9 else 1)


main()
