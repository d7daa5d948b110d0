"""The add-on in Blender's real UI (a window on an X server: Xvfb), as an artist uses it, in
whichever Blender runs this; driven by a script through bpy.app.timers and simulated events
(--enable-event-simulate: the X server's own input is ignored, Esc is sent by Window.event_simulate).
Steps, in this order (one Blender process; each timed):

1. install and enable the package (3.x: the legacy zip; 4.2+: the extension), the operator in the
   Render menu (what F3's menu search lists) and the status bar's progress drawer registered;
2. a camera bake started as the Bake button starts it (INVOKE_DEFAULT in the Properties editor):
   running, the status bar and the panel show a progress bar and a cancel button, no Bake button;
   the file is saved during the bake and opened again while it runs: the bake is stopped by the
   load, the file holds no run state and opens ready to bake (the Bake button, no progress);
3. cancel from the status bar's button (dwivedi.bake_cancel) and with Esc: the bake stops and
   writes nothing, the panel says "Bake cancelled" with a warning icon;
4. a camera bake to its end: the result is shown in an Image Editor (the render view Blender opens,
   as F12), its background opaque (Film > Transparent off); saved and opened again, the image
   comes back with its pixels;
5. a UV bake of the active object into the image of its material's active Image Texture node;
6. the add-on disabled during a bake (threads stopped, no crash), enabled again, a bake;
7. an unsaved file: Bake opens a file browser for the output folder (no temporary folder); the
   folder chosen there becomes the Output Folder and the bake writes there.

    xvfb-run -a blender --factory-startup --enable-event-simulate --python tests/blender/test_ui.py
run by tests/blender/run_package_tests.py --ui (host or chroot), which sets the environment of
test_package.py; the verdict is DWIVEDI_TEST_TIMES's "passed" (Blender's exit status is not the
test's: the UI quits through wm.quit_blender).
"""
import faulthandler
import json
import os
import shutil
import sys
import time
import traceback
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bpy  # noqa: E402

import scenes  # noqa: E402

HOME = Path(os.environ["DWIVEDI_TEST_HOME"])
LEGACY_ZIP = Path(os.environ["DWIVEDI_ADDON_ZIP"])
EXTENSION_ZIP = Path(os.environ["DWIVEDI_EXTENSION_ZIP"])
TIMES_FILE = Path(os.environ["DWIVEDI_TEST_TIMES"])
WORK = HOME / "work"
OUT = WORK / "out"
EXTENSIONS = bpy.app.version >= (4, 2, 0)
MODULE = "bl_ext.user_default.dwivedi_bake" if EXTENSIONS else "dwivedi_bake"
TIMES = {}
RESULT = {"blender": bpy.app.version_string, "seconds": TIMES, "passed": False, "steps": []}


class Failure(AssertionError):
    pass


def check(condition, message):
    if not condition:
        raise Failure(message)


def module():
    return sys.modules[MODULE]


def run_state():
    return module()._RUN


class RecordingLayout:
    """Records what a draw function puts in a layout: (kind, text or name, icon)."""

    def __init__(self, sink=None):
        self.items = sink if sink is not None else []
        self.use_property_split = False
        self.use_property_decorate = False
        self.enabled = True
        self.scale_y = 1.0
        self.alignment = 'EXPAND'
        if hasattr(bpy.types.UILayout, "progress"):
            self.progress = self._progress

    def label(self, text="", icon='NONE', **_):
        self.items.append(("label", text, icon))

    def prop(self, data, name, **_):
        self.items.append(("prop", name, ""))

    def _progress(self, text="", factor=0.0, **_):
        self.items.append(("progress", text, factor))

    def operator(self, idname, text="", icon='NONE', **_):
        self.items.append(("operator", idname, icon))
        return type("Properties", (), {})()

    def separator(self, **_):
        pass

    def column(self, **_):
        return RecordingLayout(self.items)

    row = box = column


def drawn(draw):
    """What `draw` puts in a layout, drawn in the Properties editor's context."""
    layout = RecordingLayout()
    owner = type("Owner", (), {"layout": layout})()
    with in_editor('PROPERTIES'):
        draw(owner, bpy.context)
    return layout.items


def panel():
    return drawn(bpy.types.DWIVEDI_PT_bake.draw)


def shows_progress(items):
    """A progress bar (layout.progress, or the read-only percentage) and the cancel button."""
    bar = any(kind == "progress" or (kind == "prop" and text == "dwivedi_bake_progress") for kind, text, _ in items)
    cancel = ("operator", "dwivedi.bake_cancel", 'CANCEL') in items
    return bar and cancel


def window():
    return bpy.context.window_manager.windows[0]


def area(kind):
    for win in bpy.context.window_manager.windows:
        for a in win.screen.areas:
            if a.type == kind:
                return win, a
    return None, None


def in_editor(area_type='VIEW_3D'):
    """The context of a click in an editor of `area_type` (a timer runs with no window)."""
    win, where = area(area_type)
    check(where is not None, f"no {area_type} editor on the screen")
    region = next(r for r in where.regions if r.type == 'WINDOW')
    return bpy.context.temp_override(window=win, screen=win.screen, area=where, region=region)


def ui_call(operator, area_type='PROPERTIES', **properties):
    """Calls an operator as a click in an editor of `area_type` would (INVOKE_DEFAULT)."""
    with in_editor(area_type):
        return operator('INVOKE_DEFAULT', **properties)


def slab(samples=4, resolution=24):
    """The test scene, with the Properties editor on its Render tab (where the panel is)."""
    # scenes' builders start with read_homefile, which replaces the screen a context override
    # holds: the reset in one override, the building (with the reset made a no-op) in another.
    reset = scenes._reset
    with bpy.context.temp_override(window=window()):
        reset()
    scenes._reset = lambda: bpy.context.scene
    try:
        with bpy.context.temp_override(window=window()):
            scene = scenes.slab_scene(resolution=resolution, samples=samples)
    finally:
        scenes._reset = reset
    props = scene.dwivedi_bake
    props.samples = samples
    props.threads = 2
    props.output_dir = str(OUT)
    props.target = 'CAMERA'
    _, properties = area('PROPERTIES')
    if properties is not None:
        properties.spaces.active.context = 'RENDER'
    return scene


def wait_until(condition, timeout, what):
    """Yields (to Blender's event loop) until condition() holds; Failure after `timeout` s."""
    start = time.monotonic()
    while not condition():
        if time.monotonic() - start > timeout:
            raise Failure(f"{what}: not after {timeout} s")
        yield 0.05


def files(folder):
    return sorted(p.name for p in Path(folder).iterdir()) if Path(folder).is_dir() else []


# ---------------------------------------------------------------------------------------------

def step_install():
    if EXTENSIONS:
        result = bpy.ops.extensions.package_install_files(filepath=str(EXTENSION_ZIP), repo='user_default',
                                                          enable_on_install=False)
    else:
        result = bpy.ops.preferences.addon_install(filepath=str(LEGACY_ZIP), overwrite=True)
    check(result == {'FINISHED'}, f"install: {result}")
    check(bpy.ops.preferences.addon_enable(module=MODULE) == {'FINISHED'}, "enable")
    check(module().library_status().ok, module().library_status().message)
    # The menu search (F3) lists what the menus hold: the operator is in the Render menu.
    menu = bpy.types.TOPBAR_MT_render._dyn_ui_initialize()
    check(module().draw_render_menu in menu, "the bake is in the Render menu")
    check(("operator", "dwivedi.bake", 'RENDER_STILL') in drawn(module().draw_render_menu), "menu item")
    check(module().draw_status_bar in bpy.types.STATUSBAR_HT_header._dyn_ui_initialize(), "status bar drawer")
    yield 0.1


def step_save_and_reopen_during_bake():
    scene = slab(samples=1 << 22, resolution=32)
    check(("operator", "dwivedi.bake", 'RENDER_STILL') in panel(), "the Bake button before the bake")
    check(ui_call(bpy.ops.dwivedi.bake) == {'RUNNING_MODAL'}, "the bake starts as a modal operator")
    yield from wait_until(lambda: run_state().fraction > 0.0, 20.0, "progress")
    check(run_state().running, "running")
    check(shows_progress(drawn(module().draw_status_bar)), "the status bar shows the progress and a cancel button")
    if os.environ.get("DWIVEDI_UI_SCREENSHOT"):  # for a person to look at (not compared)
        with in_editor('PROPERTIES'):  # down to the panel, below Cycles' own
            for _ in range(40):
                bpy.ops.view2d.scroll_down()
        yield 1.0
        with in_editor():
            bpy.ops.screen.screenshot(filepath=os.environ["DWIVEDI_UI_SCREENSHOT"])
    items = panel()
    check(shows_progress(items), f"the panel shows the progress and a cancel button: {items}")
    check(("operator", "dwivedi.bake", 'RENDER_STILL') not in items, "no Bake button while baking")
    saved = WORK / "saved-during-bake.blend"
    with in_editor():
        check(bpy.ops.wm.save_as_mainfile(filepath=str(saved), copy=True) == {'FINISHED'}, "save")
    yield 0.3
    check(run_state().running, "saving does not stop the bake")
    stored = set(scene.dwivedi_bake.keys())
    check(not stored & {"running", "progress", "last_result", "last_warnings"}, f"run state in the scene: {stored}")
    # Opened again while the bake runs: the load stops it (its scene goes) and the file opens ready.
    with bpy.context.temp_override(window=window()):
        bpy.ops.wm.open_mainfile(filepath=str(saved))
    yield 0.3
    check(not run_state().running, "the load stopped the bake")
    check(bpy.data.filepath == str(saved), bpy.data.filepath)
    items = panel()
    check(("operator", "dwivedi.bake", 'RENDER_STILL') in items, f"ready to bake after reopening: {items}")
    check(not shows_progress(items), "no progress after reopening")
    check(not shows_progress(drawn(module().draw_status_bar)), "no progress in the status bar")
    check(files(OUT) == [], f"a stopped bake writes nothing: {files(OUT)}")
    bpy.context.scene.dwivedi_bake.samples = 4
    check(ui_call(bpy.ops.dwivedi.bake) == {'RUNNING_MODAL'}, "a bake in the reopened file")
    yield from wait_until(lambda: not run_state().running, 60.0, "the bake in the reopened file")
    check(run_state().level == 'INFO' and "spp" in run_state().message, run_state().message)


def step_cancel():
    for name in files(OUT):
        os.unlink(OUT / name)
    for how in ("status bar", "Esc"):
        slab(samples=1 << 22, resolution=32)
        check(ui_call(bpy.ops.dwivedi.bake) == {'RUNNING_MODAL'}, "start")
        yield from wait_until(lambda: run_state().fraction > 0.0, 20.0, "progress")
        if how == "status bar":
            check(ui_call(bpy.ops.dwivedi.bake_cancel) == {'FINISHED'}, "the status bar's cancel button")
        else:
            window().event_simulate(type='ESC', value='PRESS')
            window().event_simulate(type='ESC', value='RELEASE')
        yield from wait_until(lambda: not run_state().running, 5.0, f"cancel by {how}")
        check(run_state().level == 'WARNING' and run_state().message == "Bake cancelled",
              f"{how}: {run_state().level} {run_state().message}")
        items = panel()
        check(("label", "Bake cancelled", 'ERROR') in items, f"the panel says it with a warning icon: {items}")
        check(files(OUT) == [], f"a cancelled bake writes nothing: {files(OUT)}")
        # The message is about this scene and target: another target's panel does not show it.
        bpy.context.scene.dwivedi_bake.target = 'UV'
        check(not [i for i in panel() if i[1] == "Bake cancelled"], "the message is cleared in another context")
        bpy.context.scene.dwivedi_bake.target = 'CAMERA'


def step_result_shown():
    scene = slab(samples=4)
    check(ui_call(bpy.ops.dwivedi.bake) == {'RUNNING_MODAL'}, "start")
    yield from wait_until(lambda: not run_state().running, 60.0, "the camera bake")
    check(run_state().level == 'INFO', run_state().message)
    yield 0.5  # the render view opens
    shown = [a.spaces.active.image.name for w in bpy.context.window_manager.windows for a in w.screen.areas
             if a.type == 'IMAGE_EDITOR' and a.spaces.active.image is not None]
    check("Dwivedi Camera" in shown, f"the result is shown in an Image Editor: {shown}")
    image = bpy.data.images["Dwivedi Camera"]
    pixels = [0.0] * (4 * 24 * 24)
    image.pixels.foreach_get(pixels)
    check(sum(pixels[0::4]) > 0.0, "lit")
    check(min(pixels[3::4]) == 1.0, "opaque background (Film > Transparent off)")
    saved = WORK / "with-result.blend"
    with in_editor():
        check(bpy.ops.wm.save_as_mainfile(filepath=str(saved)) == {'FINISHED'}, "save")
    with bpy.context.temp_override(window=window()):
        bpy.ops.wm.open_mainfile(filepath=str(saved))
    yield 0.3
    image = bpy.data.images.get("Dwivedi Camera")
    check(image is not None, "the result survives save and reopen")
    again = [0.0] * (4 * 24 * 24)
    image.pixels.foreach_get(again)
    check(again == pixels, "with its pixels")
    del scene


def step_uv_bake():
    scene = slab(samples=4)
    with in_editor():
        image = scenes.bake_image(bpy.data.objects["Slab"], (32, 32))
    scene.dwivedi_bake.target = 'UV'
    check(any(kind == "label" and "into 'Baked' (32 x 32)" in text for kind, text, _ in panel()),
          f"the panel names the image: {panel()}")
    check(ui_call(bpy.ops.dwivedi.bake) == {'RUNNING_MODAL'}, "start")
    yield from wait_until(lambda: not run_state().running, 60.0, "the UV bake")
    check(run_state().level == 'INFO', run_state().message)
    pixels = [0.0] * (4 * 32 * 32)
    image.pixels.foreach_get(pixels)
    check(sum(pixels[0::4]) > 0.0, "the active image holds the bake")
    check(image.source == 'FILE' and Path(bpy.path.abspath(image.filepath)).is_file(), "saved as a file")


def step_disable_during_bake():
    slab(samples=1 << 22, resolution=32)
    check(ui_call(bpy.ops.dwivedi.bake) == {'RUNNING_MODAL'}, "start")
    yield from wait_until(lambda: run_state().fraction > 0.0, 20.0, "progress")
    old = module()
    job = old._RUN.job
    check(bpy.ops.preferences.addon_disable(module=MODULE) == {'FINISHED'}, "disable")
    check(old._RUN.job is None and job.bake is None and job.exported.scene is None,
          "the bake was cancelled and released (its threads joined) at disable")
    yield 0.5  # events and timers go on: nothing of the add-on is left to run
    check(bpy.ops.preferences.addon_enable(module=MODULE) == {'FINISHED'}, "enable again")
    slab(samples=4)
    check(ui_call(bpy.ops.dwivedi.bake) == {'RUNNING_MODAL'}, "start after enabling again")
    yield from wait_until(lambda: not run_state().running, 60.0, "the bake after enabling again")
    check(run_state().level == 'INFO', run_state().message)


def step_unsaved_asks_for_folder():
    slab(samples=4)  # a new file (read_homefile): never saved
    yield 0.2
    check(not bpy.data.filepath, "an unsaved file")
    bpy.context.scene.dwivedi_bake.output_dir = "//dwivedi_bake/"
    check(ui_call(bpy.ops.dwivedi.bake, area_type='VIEW_3D') == {'RUNNING_MODAL'}, "asks")
    yield from wait_until(lambda: area('FILE_BROWSER')[1] is not None, 10.0, "a file browser for the folder")
    check(not run_state().running, "no bake before a folder is chosen")
    # A folder chosen in it: the bake runs and writes there.
    chosen = WORK / "chosen"
    chosen.mkdir()
    # What the browser's Accept does: the operator's exec with its directory set. (file.execute
    # under a context override of the browser's window crashes Blender 3.4 as that window closes,
    # and a simulated Return does not reach a temporary window.)
    ui_call_exec = bpy.ops.dwivedi.bake
    with in_editor('PROPERTIES'):
        check(ui_call_exec('EXEC_DEFAULT', asked_folder=True, directory=str(chosen) + os.sep) == {'RUNNING_MODAL'},
              "the bake starts from the browser")
    yield from wait_until(lambda: not run_state().running and (chosen / "Scene_camera.exr").is_file(), 60.0,
                          "the bake into the chosen folder")
    check(Path(bpy.path.abspath(bpy.context.scene.dwivedi_bake.output_dir)).resolve() == chosen.resolve(),
          f"the chosen folder is the output folder: {bpy.context.scene.dwivedi_bake.output_dir}")


STEPS = [("install, menu", step_install), ("save and reopen during a bake", step_save_and_reopen_during_bake),
         ("cancel: status bar, Esc", step_cancel), ("result shown, survives reopen", step_result_shown),
         ("UV bake into the active image", step_uv_bake), ("disable during a bake", step_disable_during_bake),
         ("unsaved file asks for a folder", step_unsaved_asks_for_folder)]


def driver():
    """All steps as one generator: each yields the seconds until Blender should call it again."""
    for name, function in STEPS:
        if os.environ.get("DWIVEDI_UI_ONLY") and name not in ("install, menu", os.environ["DWIVEDI_UI_ONLY"]):
            continue
        start = time.monotonic()
        try:
            yield from function()
        except Exception as error:
            RESULT["steps"].append({"name": name, "passed": False, "error": f"{type(error).__name__}: {error}"})
            print(f"test_ui: FAILED: {name}: {error}")
            traceback.print_exc()
            return
        finally:
            TIMES[name] = round(time.monotonic() - start, 3)
        RESULT["steps"].append({"name": name, "passed": True})
        print(f"test_ui: passed: {name} ({TIMES[name]} s)")
    RESULT["passed"] = True


_RUNNING = driver()


def _tick():
    try:
        return next(_RUNNING)
    except StopIteration:
        pass
    except Exception:
        traceback.print_exc()
    TIMES_FILE.write_text(json.dumps(RESULT, indent=1))
    print(f"test_ui: Blender {bpy.app.version_string}: {'passed' if RESULT['passed'] else 'FAILED'}")
    sys.stdout.flush()
    with in_editor():
        bpy.ops.wm.quit_blender()
    return None


def main():
    scripts = os.environ.get("BLENDER_USER_SCRIPTS", "")
    if not scripts or not Path(scripts).resolve().is_relative_to(HOME.resolve()):
        raise SystemExit("test_ui: BLENDER_USER_SCRIPTS must point inside DWIVEDI_TEST_HOME (run it through "
                         "tests/blender/run_package_tests.py --ui)")
    faulthandler.enable()  # a crash prints the Python stack
    if bpy.app.background:
        raise SystemExit("test_ui: needs Blender's UI (run it under Xvfb, not with -b)")
    if WORK.exists():
        shutil.rmtree(WORK)
    OUT.mkdir(parents=True)
    TIMES_FILE.write_text(json.dumps(RESULT, indent=1))
    print(f"test_ui: Blender {bpy.app.version_string}, module {MODULE}")
    bpy.app.timers.register(_tick, first_interval=0.5, persistent=True)


main()
