"""The add-on's farm sub-panel in headless Blender (docs/farm.md): "Export for a Farm" writes the
scene file and the chunk commands for the bake settings; the chunks are baked from the exported
folder; "Merge Farm Chunks" loads the merged result as a Blender image whose pixels are the
add-on's own one-machine bake's, bit for bit. A missing chunk is refused naming it and keeps the
earlier merged EXR; a UV target is refused.

On the host (ctest blender.test_farm: the legacy zip, Blender 3.4) the chunks run as chunks.txt's
commands with the real `dwivedi` (build/dwivedi, beside the zip). In the Blender 4.3 and 5.2
chroots (tests/blender/run_package_tests.py --script test_farm.py: the extension, 4.2+) there is
no `dwivedi` command built for them, so each chunk is baked through the add-on's own library
(the shim: Scene.load of the exported file, BakeSettings.sample_first/sample_count,
Image.write_partial), which is what the command does (tests/python/test_cli_split.py and
test_farm_plan.py check the command against the one-machine bake).

    blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_farm.py
(through ctest, which sets the user folders and the zip's path: see harness.py)
"""
import dataclasses
import json
import os
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bpy  # noqa: E402

import harness  # noqa: E402
import scenes  # noqa: E402

EXTENSION_ZIP = os.environ.get("DWIVEDI_EXTENSION_ZIP")
if EXTENSION_ZIP and bpy.app.version >= (4, 2, 0):
    MODULE = "bl_ext.user_default.dwivedi_bake"
    WORK = harness.HOME / "work"
    WORK.mkdir(parents=True, exist_ok=True)
    assert bpy.ops.extensions.package_install_files(filepath=EXTENSION_ZIP, repo='user_default',
                                                    enable_on_install=False) == {'FINISHED'}
    assert bpy.ops.preferences.addon_enable(module=MODULE) == {'FINISHED'}
else:
    MODULE = "dwivedi_bake"
    WORK = harness.install_addon()
CLI = harness.ZIP.parent / "dwivedi"


def read(path):
    with open(path, "rb") as f:
        return f.read()


def bake_chunks(folder):
    """Bakes every chunk of the plan in `folder`: chunks.txt's commands where the dwivedi command
    is there, else the same bakes through the add-on's library."""
    if CLI.is_file():
        for command in read(folder / "chunks.txt").decode().splitlines():
            done = subprocess.run(["bash", "-c", command], cwd=folder, capture_output=True, text=True)
            assert done.returncode == 0, command + "\n" + done.stderr
        return
    dwivedi = sys.modules[MODULE].shim()
    plan = json.loads(read(folder / "farm.json"))
    for chunk in plan["chunks"]:
        scene = dwivedi.Scene.load(str(folder / plan["scene"]))
        try:  # as `dwivedi bake SCENE --spp N --seed S --samples F:C`: the file's settings, the range's
            settings = dataclasses.replace(scene.settings, samples=plan["spp"], seed=plan["seed"], time_limit=0.0,
                                           target_error=0.0, sample_first=chunk["first"], sample_count=chunk["count"])
            image = scene.bake(settings)
            image.write_partial(str(folder / chunk["part"]))
            image.close()
        finally:
            scene.close()


class FarmTest(harness.unittest.TestCase):
    def setUp(self):
        scene = scenes.sphere_scene(resolution=16, samples=6)
        scene.render.resolution_x = 20
        props = scene.dwivedi_bake
        props.samples = 6
        props.seed = 4
        props.threads = 2
        props.output_dir = str(WORK / "bake")
        self.folder = WORK / "farm"
        farm = scene.dwivedi_farm
        farm.folder = str(self.folder)
        farm.chunks = 3
        farm.program = str(CLI)

    def test_panel_is_a_closed_sub_panel(self):
        panel = bpy.types.DWIVEDI_PT_farm
        self.assertEqual(panel.bl_parent_id, "DWIVEDI_PT_bake")
        self.assertIn('DEFAULT_CLOSED', panel.bl_options)

    def test_export_run_chunks_merge_equals_the_bake(self):
        if MODULE == "dwivedi_bake" and bpy.app.version < (4, 2, 0):
            self.assertTrue(CLI.is_file(), f"no dwivedi command at {CLI}")  # the host's run uses it
        self.assertEqual(bpy.ops.dwivedi.bake(), {'FINISHED'})
        width, height, baked = harness.image_pixels("Dwivedi Camera")
        self.assertEqual((width, height), (20, 16))

        self.assertEqual(bpy.ops.dwivedi.farm_export(), {'FINISHED'})
        for name in ("dwivedi_scene.json", "farm.json", "chunks.txt", "merge.txt", "bake.sbatch", "merge.sbatch",
                     "submit.sh"):
            self.assertTrue((self.folder / name).is_file(), name)
        plan = json.loads(read(self.folder / "farm.json"))
        self.assertEqual([(c["first"], c["count"]) for c in plan["chunks"]], [(0, 2), (2, 2), (4, 2)])
        self.assertEqual((plan["spp"], plan["seed"], plan["name"]), (6, 4, "Scene_camera"))
        self.assertEqual(len(read(self.folder / "chunks.txt").decode().splitlines()), 3)
        bake_chunks(self.folder)

        self.assertEqual(bpy.ops.dwivedi.farm_merge(), {'FINISHED'})
        self.assertEqual(harness.image_pixels("Dwivedi Farm"), (width, height, baked))
        exr = self.folder / "Scene_camera.exr"
        self.assertTrue(exr.is_file())
        self.assertTrue((self.folder / "Scene_camera.png").is_file())
        good = read(exr)

        (self.folder / "parts" / "chunk-1.dwvpart").unlink()
        with self.assertRaises(RuntimeError) as caught:
            bpy.ops.dwivedi.farm_merge()
        self.assertIn("chunk-1.dwvpart", str(caught.exception))
        self.assertEqual(read(exr), good, "a failed merge changed the merged EXR")

    def test_uv_target_is_refused(self):
        props = bpy.context.scene.dwivedi_bake
        props.target = 'UV'
        props.uv_object = bpy.data.objects["Sphere"]
        bpy.context.scene.dwivedi_farm.folder = str(WORK / "farm_uv")
        with self.assertRaises(RuntimeError) as caught:
            bpy.ops.dwivedi.farm_export()
        self.assertIn("camera bakes", str(caught.exception))
        self.assertFalse((WORK / "farm_uv" / "farm.json").exists())


harness.run(FarmTest)
