"""The add-on's farm sub-panel in headless Blender (docs/farm.md): "Export for a Farm" writes the
scene file and the chunk commands for the bake settings; the chunks run with the real `dwivedi`
command (build/dwivedi, beside the add-on zip); "Merge Farm Chunks" loads the merged result as a
Blender image whose pixels are the add-on's own one-machine bake's, bit for bit. A missing chunk
is refused naming it and keeps the earlier merged EXR; a UV target is refused.

    blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_farm.py
(through ctest, which sets the user folders and the zip's path: see harness.py)
"""
import json
import os
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bpy  # noqa: E402

import harness  # noqa: E402
import scenes  # noqa: E402

WORK = harness.install_addon()
CLI = harness.ZIP.parent / "dwivedi"


def read(path):
    with open(path, "rb") as f:
        return f.read()


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
        self.assertTrue(CLI.is_file(), f"no dwivedi command at {CLI}")
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
        commands = read(self.folder / "chunks.txt").decode().splitlines()
        self.assertEqual(len(commands), 3)
        for command in commands:  # what a farm's task runs, in the folder
            done = subprocess.run(["bash", "-c", command], cwd=self.folder, capture_output=True, text=True)
            self.assertEqual(done.returncode, 0, command + "\n" + done.stderr)

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
