"""dwivedi.farm's plans without a farm manager (docs/farm.md): chunks.txt's commands run one by one in
the plan's folder and merge.txt's merge give the one-machine bake's PNG and stats; the sample
ranges cover the total in order; bad requests are refused with a message. (The Slurm scripts run
on a real Slurm in tests/farm/test_farm_slurm.py.) Standard library only."""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

from dwivedi import farm

SOURCE = os.environ.get("DWIVEDI_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
SCENE = os.path.join(SOURCE, "examples", "scenes", "backlit_slab.json")


def read(path: str) -> bytes:
    with open(path, "rb") as f:
        return f.read()


class FarmPlanTest(unittest.TestCase):
    def test_ranges_cover_the_total_in_order(self) -> None:
        for spp, chunks in ((1, 1), (10, 3), (64, 64), (1000, 7)):
            made = farm.split_samples(spp, chunks)
            self.assertEqual(len(made), chunks)
            self.assertEqual(made[0].first, 0)
            for a, b in zip(made, made[1:]):
                self.assertEqual(a.first + a.count, b.first)
            self.assertEqual(made[-1].first + made[-1].count, spp)
            self.assertLessEqual(max(c.count for c in made) - min(c.count for c in made), 1)

    def test_bad_requests_are_refused(self) -> None:
        with tempfile.TemporaryDirectory() as folder:
            cases = [(dict(scene=os.path.join(folder, "absent.json")), "no scene file"),
                     (dict(spp=0), "--spp"), (dict(chunks=0), "--chunks"), (dict(chunks=9), "--chunks"),
                     (dict(name="../x"), "output name"), (dict(name="a b"), "output name"),
                     (dict(seed=-1), "--seed"), (dict(bake_args=["--samples", "0:1"]), "not one of"),
                     (dict(bake_args=["--width"]), "no value"), (dict(merge_args=["--spp", "3"]), "not one of"),
                     (dict(partition="a b"), "--partition")]
            for change, word in cases:
                args = dict(scene=SCENE, spp=8, chunks=2, folder=folder)
                args.update(change)
                with self.assertRaises(farm.PlanError, msg=change) as caught:
                    farm.plan(args.pop("scene"), args.pop("spp"), args.pop("chunks"), args.pop("folder"), **args)
                self.assertIn(word, str(caught.exception))
            inside = os.path.join(folder, "shot.json")
            shutil.copy(SCENE, inside)
            with self.assertRaises(farm.PlanError) as caught:
                farm.plan(inside, 8, 2, folder, name="shot")
            self.assertIn("would replace the scene file", str(caught.exception))
            self.assertEqual(farm.plan(inside, 8, 2, folder).name, "shot_merged")

    def test_the_command(self) -> None:
        with tempfile.TemporaryDirectory() as folder:
            job = os.path.join(folder, "job")
            done = subprocess.run([sys.executable, "-m", "dwivedi.farm", SCENE, "--spp", "10", "--chunks", "4", "--out",
                                   job, "--width", "30", "--view", "Standard"], capture_output=True, text=True)
            self.assertEqual(done.returncode, 0, done.stderr)
            self.assertIn("4 chunks (0:3, 3:3, 6:2, 8:2) of 10 spp", done.stdout)
            with open(os.path.join(job, "chunks.txt"), encoding="utf-8") as f:
                self.assertIn("--width 30 --samples 6:2 --out parts/chunk-2", f.read().splitlines()[2])
            with open(os.path.join(job, "merge.txt"), encoding="utf-8") as f:
                self.assertTrue(f.read().rstrip().endswith("--out backlit_slab --view Standard"))
            done = subprocess.run([sys.executable, "-m", "dwivedi.farm", SCENE, "--spp", "3", "--chunks", "4", "--out",
                                   job], capture_output=True, text=True)
            self.assertEqual(done.returncode, 1)
            self.assertEqual(done.stdout, "")
            self.assertIn("--chunks must be a whole number from 1 to the samples per pixel (3)", done.stderr)

    def test_chunk_commands_merge_to_the_one_machine_bake(self) -> None:
        cli = os.environ["DWIVEDI_CLI"]
        settings = ["--width", "24", "--height", "14", "--threads", "2"]
        with tempfile.TemporaryDirectory() as folder:
            job = os.path.join(folder, "job")
            os.mkdir(job)
            shutil.copy(SCENE, job)
            shutil.copy(os.path.join(os.path.dirname(SCENE), "slab.obj"), job)
            scene = os.path.join(job, os.path.basename(SCENE))
            done = subprocess.run([cli, "bake", scene, "--spp", "10", "--seed", "3", *settings, "--quiet",
                                   "--out", os.path.join(folder, "whole")], capture_output=True, text=True)
            self.assertEqual(done.returncode, 0, done.stderr)
            made = farm.plan(scene, 10, 3, job, name="shot", seed=3, dwivedi=cli, bake_args=settings)
            self.assertEqual(made.scene, os.path.basename(SCENE))  # inside the folder: named relative to it
            farm.write_plan(made, job)
            moved = os.path.join(folder, "moved")
            os.rename(job, moved)  # the folder goes anywhere as a whole
            with open(os.path.join(moved, "chunks.txt"), encoding="utf-8") as f:
                commands = f.read().splitlines()
            self.assertEqual(len(commands), 3)
            done = subprocess.run(["bash", "-c", commands[2]], cwd=moved, capture_output=True, text=True)
            self.assertEqual(done.returncode, 0, commands[2] + "\n" + done.stderr)
            for number in ("1", "0"):  # a farm's task number, from any working directory
                done = subprocess.run([os.path.join(moved, "run-chunk.sh"), number], cwd=folder, capture_output=True,
                                      text=True)
                self.assertEqual(done.returncode, 0, done.stderr)
            for bad in ("3", "-1", "x", ""):
                done = subprocess.run([os.path.join(moved, "run-chunk.sh"), bad], capture_output=True, text=True)
                self.assertEqual(done.returncode, 2, bad)
                self.assertIn("chunk", done.stderr)
            with open(os.path.join(moved, "merge.txt"), encoding="utf-8") as f:
                done = subprocess.run(["bash", "-c", f.read()], cwd=moved, capture_output=True, text=True)
            self.assertEqual(done.returncode, 0, done.stderr)
            self.assertEqual(read(os.path.join(folder, "whole.png")), read(os.path.join(moved, "shot.png")))
            whole = json.loads(read(os.path.join(folder, "whole.json")))
            merged = json.loads(read(os.path.join(moved, "shot.json")))
            for key in ("spp", "samples", "estimated_relative_error", "mean_rgb"):
                self.assertEqual(whole[key], merged[key], key)
            parts, name = farm.read_plan_parts(moved)
            self.assertEqual((len(parts), name), (3, "shot"))
            self.assertTrue(all(os.path.isfile(p) for p in parts))


if __name__ == "__main__":
    unittest.main()
