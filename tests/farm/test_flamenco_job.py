"""The Flamenco 3 job type farm/flamenco/dwivedi-bake.js (docs/farm.md), its compileJob run by node
with Flamenco's job-compiler globals reduced to recorders (tests/farm/flamenco_compile.js; not a
real Flamenco Manager): its chunk tasks are the same commands as dwivedi.farm's chunks.txt (same
ranges, same flags), the merge task depends on every chunk, and running the authored `exec`
commands with the real dwivedi gives the one-machine bake's pixels bit for bit. Its JOB_TYPE uses
Flamenco's setting types and names properties the add-on has. Bad settings are refused.

ctest sets DWIVEDI_CLI and PYTHONPATH (the shim); node is Debian's nodejs (scripts/setup.sh).
Standard library only.
"""
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from exr_blocks import exr_pixel_blocks, read  # noqa: E402

from dwivedi import farm  # noqa: E402

SOURCE = os.environ.get("DWIVEDI_SOURCE_DIR", os.path.join(HERE, "..", ".."))
JOB_SCRIPT = os.path.join(SOURCE, "farm", "flamenco", "dwivedi-bake.js")
SCENE = os.path.join(SOURCE, "examples", "scenes", "frontlit_sphere.json")
ADDON = os.path.join(SOURCE, "blender_addon", "dwivedi_bake")
SETTING_TYPES = {"string", "int32", "float", "bool"}  # Flamenco 3's job setting types
VISIBILITY = {"visible", "hidden", "submission", "web"}


def compile_job(settings: dict) -> subprocess.CompletedProcess:
    node = shutil.which("node") or shutil.which("nodejs")
    if node is None:
        raise AssertionError("node is not installed (scripts/setup.sh: nodejs)")
    return subprocess.run([node, os.path.join(HERE, "flamenco_compile.js"), JOB_SCRIPT, json.dumps(settings)],
                          capture_output=True, text=True, timeout=60)


class FlamencoJobTypeTest(unittest.TestCase):
    def setUp(self) -> None:
        self.temporary = tempfile.TemporaryDirectory(prefix="dwivedi-flamenco-")
        self.folder = os.path.join(self.temporary.name, "job")
        os.mkdir(self.folder)
        self.scene = os.path.join(self.folder, "dwivedi_scene.json")
        shutil.copy(SCENE, self.scene)
        shutil.copy(os.path.join(os.path.dirname(SCENE), "sphere.ply"), self.folder)
        self.cli = os.environ["DWIVEDI_CLI"]
        self.settings = {"folder": self.folder, "scene_file": "dwivedi_scene.json", "samples": 11, "chunks": 4,
                         "seed": 9, "threads": 1, "output_name": "shot", "dwivedi": self.cli}

    def tearDown(self) -> None:
        self.temporary.cleanup()

    def test_job_type_settings(self) -> None:
        done = compile_job(self.settings)
        self.assertEqual(done.returncode, 0, done.stderr)
        job_type = json.loads(done.stdout)["job_type"]
        self.assertTrue(job_type["label"])
        keys = [s["key"] for s in job_type["settings"]]
        self.assertEqual(sorted(keys), sorted(self.settings))
        addon = "".join(read(os.path.join(ADDON, name)).decode() for name in ("__init__.py", "farm.py"))
        for setting in job_type["settings"]:
            self.assertIn(setting["type"], SETTING_TYPES, setting)
            self.assertIn(setting.get("visible", "visible"), VISIBILITY, setting)
            self.assertTrue(setting.get("description"), setting)
            for group, prop in re.findall(r"C\.scene\.(dwivedi_bake|dwivedi_farm)\.(\w+)", setting.get("eval", "")):
                self.assertRegex(addon, rf"\n    {prop}: \w+Property\(", f"{setting['key']}: no {group}.{prop}")

    def test_tasks_are_the_plans_commands_and_merge_to_the_bake(self) -> None:
        done = compile_job(self.settings)
        self.assertEqual(done.returncode, 0, done.stderr)
        tasks = json.loads(done.stdout)["tasks"]
        chunks, merge = tasks[:-1], tasks[-1]
        self.assertEqual(len(chunks), 4)
        self.assertEqual(merge["dependencies"], [t["name"] for t in chunks])
        for task in tasks:
            self.assertEqual(task["type"], "misc")
            self.assertEqual([c["name"] for c in task["commands"]], ["exec"])
            self.assertEqual(set(task["commands"][0]["parameters"]), {"exe", "args"})

        plan = farm.plan(self.scene, 11, 4, self.folder, name="shot", seed=9, dwivedi=self.cli,
                         bake_args=["--threads", "1"])
        self.assertEqual([c.samples for c in plan.chunks], ["0:3", "3:3", "6:3", "9:2"])
        farm.write_plan(plan, self.folder)  # the folder as Export for a Farm leaves it (parts/ made)

        def absolute(argv):  # the plan's commands run in the folder; Flamenco's have absolute paths
            return [os.path.join(self.folder, a) if a == plan.scene or a.startswith("parts/") or a == "shot" else a
                    for a in argv]
        for task, chunk in zip(chunks, plan.chunks):
            command = task["commands"][0]["parameters"]
            self.assertEqual([command["exe"]] + command["args"], absolute(plan.chunk_args(chunk)))
        command = merge["commands"][0]["parameters"]
        self.assertEqual([command["exe"]] + command["args"], absolute(plan.merge_argv()))

        for task in list(reversed(chunks)) + [merge]:  # chunks in any order, then the merge
            command = task["commands"][0]["parameters"]
            ran = subprocess.run([command["exe"]] + command["args"], capture_output=True, text=True, timeout=120,
                                 cwd=self.temporary.name)
            self.assertEqual(ran.returncode, 0, task["name"] + ": " + ran.stderr)
        whole = os.path.join(self.temporary.name, "whole")
        ran = subprocess.run([self.cli, "bake", self.scene, "--spp", "11", "--seed", "9", "--quiet", "--out", whole],
                             capture_output=True, text=True, timeout=120)
        self.assertEqual(ran.returncode, 0, ran.stderr)
        merged = os.path.join(self.folder, "shot")
        self.assertEqual(exr_pixel_blocks(whole + ".exr"), exr_pixel_blocks(merged + ".exr"))
        self.assertEqual(read(whole + ".png"), read(merged + ".png"))
        self.assertEqual(json.loads(read(whole + ".json"))["estimated_relative_error"],
                         json.loads(read(merged + ".json"))["estimated_relative_error"])

    def test_bad_settings_are_refused(self) -> None:
        for change, word in ((dict(chunks=12), "chunks"), (dict(samples=0), "samples"), (dict(chunks=2.5), "chunks"),
                             (dict(output_name="../x"), "output_name"), (dict(folder=""), "folder")):
            settings = dict(self.settings, **change)
            done = compile_job(settings)
            self.assertEqual(done.returncode, 1, change)
            self.assertIn(word, done.stderr, change)


if __name__ == "__main__":
    unittest.main()
