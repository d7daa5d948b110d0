"""`python3 -m dwivedi.farm` against a real Slurm (docs/farm.md): a single-node cluster started for
the test (tests/farm/slurm_cluster.py), a bake split into a job array of 3 chunks plus the
dependent merge, submitted with the plan's submit.sh; the merged image is the one-machine bake's
(display PNG bytes, every float of the EXR's layers, the stats). Then a plan whose second chunk
fails: the merge never runs (it is cancelled, not left pending), submit.sh --wait exits 1 naming
the chunk, and the earlier merged outputs in the folder are kept byte for byte. No daemon or job
outlives the test.

Needs root (label "root" in ctest); not root: skipped (exit 77). As root, a missing Slurm or munge
is a failure. ctest sets DWIVEDI_CLI and PYTHONPATH (the shim). Standard library only.
"""
import json
import os
import subprocess
import sys
import tempfile
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from exr_blocks import exr_pixel_blocks, read  # noqa: E402
from slurm_cluster import SlurmCluster  # noqa: E402

from dwivedi import farm  # noqa: E402

SOURCE = os.environ.get("DWIVEDI_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
SCENE = os.path.join(SOURCE, "examples", "scenes", "frontlit_sphere.json")
SETTINGS = ["--width", "40", "--height", "24"]
SPP, SEED = 24, 11


class SlurmFarmTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        cls.cli = os.environ["DWIVEDI_CLI"]
        cls.cluster = SlurmCluster().__enter__()

    @classmethod
    def tearDownClass(cls) -> None:
        cluster_env = dict(cls.cluster.env)
        cls.cluster.stop()
        probe = SlurmCluster()
        probe.env = cluster_env
        leftover = probe.processes()
        assert not leftover, f"processes of the test cluster outlived it: {leftover}"

    def setUp(self) -> None:
        self.folder = tempfile.TemporaryDirectory(prefix="dwivedi-farm-")
        self.dir = self.folder.name

    def tearDown(self) -> None:
        self.folder.cleanup()

    def path(self, *names: str) -> str:
        return os.path.join(self.dir, *names)

    def submit(self, job: str) -> subprocess.CompletedProcess:
        return subprocess.run([os.path.join(job, "submit.sh"), "--wait"], capture_output=True, text=True,
                              env=self.cluster.env, timeout=120)

    def test_job_array_merge_equals_one_machine_bake(self) -> None:
        done = subprocess.run([self.cli, "bake", SCENE, "--spp", str(SPP), "--seed", str(SEED), *SETTINGS,
                               "--threads", "2", "--quiet", "--out", self.path("whole")], capture_output=True, text=True)
        self.assertEqual(done.returncode, 0, done.stderr)
        job = self.path("job")
        made = farm.plan(SCENE, SPP, 3, job, name="shot", seed=SEED, dwivedi=self.cli,
                         bake_args=SETTINGS, cpus_per_task=1)
        farm.write_plan(made, job)
        self.assertEqual([c.samples for c in made.chunks], ["0:8", "8:8", "16:8"])
        done = self.submit(job)
        self.assertEqual(done.returncode, 0, done.stdout + done.stderr)
        self.assertIn("merged: shot.exr", done.stdout)
        self.assertEqual(read(self.path("whole.png")), read(os.path.join(job, "shot.png")))
        whole = json.loads(read(self.path("whole.json")))
        merged = json.loads(read(os.path.join(job, "shot.json")))
        for key in ("spp", "samples", "estimated_relative_error", "mean_rgb", "technique", "features", "width",
                    "height", "events", "walks"):
            self.assertEqual(whole[key], merged[key], key)
        self.assertEqual([p["spp"] for p in merged["error_vs_time"]], [8, 16, 24])
        blocks = exr_pixel_blocks(self.path("whole.exr"))
        self.assertEqual(len(blocks), 2)  # 24 rows, ZIP's 16 a block
        self.assertEqual(blocks, exr_pixel_blocks(os.path.join(job, "shot.exr")))
        self.assertEqual(self.cluster.queue(), [])

        # The same folder, a plan whose chunk 1 fails: the merge must not run, the good outputs stay.
        good = {s: read(os.path.join(job, "shot" + s)) for s in (".exr", ".png", ".json")}
        flaky = self.path("flaky-dwivedi")
        with open(flaky, "w", encoding="utf-8") as f:
            f.write('#!/bin/sh\ncase " $* " in *" 8:8 "*) echo "planted failure" >&2; exit 3 ;; esac\n'
                    f'exec {self.cli} "$@"\n')
        os.chmod(flaky, 0o755)
        failing = farm.plan(SCENE, SPP, 3, job, name="shot", seed=SEED + 1, dwivedi=flaky, bake_args=SETTINGS)
        farm.write_plan(failing, job)
        done = self.submit(job)
        self.assertEqual(done.returncode, 1, done.stdout + done.stderr)
        self.assertIn("the merge did not run", done.stderr)
        self.assertIn("chunk 1 (", done.stderr)
        self.assertIn("exit status 3", done.stderr)
        self.assertIn("planted failure", read(os.path.join(job, "logs", "chunk-1.err")).decode())
        self.assertFalse(os.path.exists(os.path.join(job, "logs", "merge.status")), "the merge ran")
        self.assertEqual(self.cluster.queue(), [], "the merge was left pending")
        for s, content in good.items():
            self.assertEqual(read(os.path.join(job, "shot" + s)), content, f"shot{s} changed")

    def test_cancelled_chunks_leave_no_part_and_no_merge(self) -> None:
        job = self.path("long")
        # Chunks of about a minute each (25000 spp of 40 x 24 px on one thread), cancelled (scancel:
        # SIGTERM, then SIGKILL) while baking; bounded, should the test itself be killed first.
        made = farm.plan(SCENE, 50000, 2, job, name="long", seed=SEED, dwivedi=self.cli, bake_args=SETTINGS)
        farm.write_plan(made, job)
        submit = subprocess.Popen([os.path.join(job, "submit.sh"), "--wait"], stdout=subprocess.PIPE,
                                  stderr=subprocess.PIPE, text=True, env=self.cluster.env)
        try:
            deadline = time.monotonic() + 60
            running = []
            while time.monotonic() < deadline and len(running) < 2:
                running = [line for line in self.cluster.queue() if " RUNNING " in line and "_" in line.split()[0]]
                time.sleep(0.3)
            self.assertEqual(len(running), 2, self.cluster.queue())
            time.sleep(1.0)  # both chunks are baking
            array = running[0].split()[0].split("_")[0]
            done = subprocess.run(["scancel", array], capture_output=True, text=True, env=self.cluster.env)
            self.assertEqual(done.returncode, 0, done.stderr)
            out, err = submit.communicate(timeout=120)
        finally:
            if submit.poll() is None:
                submit.kill()
                submit.wait()
        self.assertEqual(submit.returncode, 1, out + err)
        self.assertIn("the merge did not run", err)
        for chunk in made.chunks:
            self.assertIn(f"{chunk.part} was not written", err)
        self.assertEqual([n for n in os.listdir(os.path.join(job, "parts")) if not n.startswith(".")], [])
        self.assertFalse(os.path.exists(os.path.join(job, "logs", "merge.status")), "the merge ran")
        self.assertEqual(self.cluster.queue(), [], "the merge was left pending")


if __name__ == "__main__":
    if os.geteuid() != 0:
        print("test_farm_slurm: needs root (a Slurm cluster of its own); skipped", file=sys.stderr)
        sys.exit(77)
    unittest.main()
