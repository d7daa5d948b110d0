"""Faults of split bakes beyond tests/python/test_cli_split.py (docs/farm.md, issue 21 item 5):

- a chunk of another scene that differs only in a material field added after the partial format
  (subsurface model, specular layer, IOR, specular, tint, distribution, minimum footprint) is
  refused as another scene's, naming the file (it was merged silently before they were hashed);
- a chunk cut at any length (empty, inside the header, at its end, one byte short, one too many)
  is refused naming the file, and the earlier merged outputs stay as they were;
- a merge killed (SIGKILL) at moments spread over its run never leaves a partial output: every
  output file is either the earlier one or the complete new one, byte for byte.

ctest sets DWIVEDI_CLI, DWIVEDI_LIBRARY and PYTHONPATH (the shim). Standard library only.
"""
import dataclasses
import os
import signal
import subprocess
import sys
import tempfile
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from exr_blocks import read  # noqa: E402

import dwivedi  # noqa: E402

OUTPUTS = (".exr", ".png", ".json")
HEADER_BYTES = 224  # src/api/partial_api.c: the fixed header


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([os.environ["DWIVEDI_CLI"], *args], capture_output=True, text=True, timeout=120)


class FarmFaultsTest(unittest.TestCase):
    def setUp(self) -> None:
        self.temporary = tempfile.TemporaryDirectory(prefix="dwivedi-faults-")
        self.dir = self.temporary.name

    def tearDown(self) -> None:
        self.temporary.cleanup()

    def path(self, name: str) -> str:
        return os.path.join(self.dir, name)

    def test_a_scene_differing_in_any_material_field_is_foreign(self) -> None:
        base = dwivedi.Material(subsurface_color=(0.9, 0.7, 0.5), subsurface_radius=(1.0, 0.5, 0.25),
                                subsurface_scale=0.05, specular_model="principled_v2")
        changes = {"subsurface_model": "blender4_random_walk", "specular_model": "principled_v1", "ior": 1.45,
                   "specular": 0.7, "specular_tint": (1.0, 0.9, 0.8), "specular_multiscatter": True,
                   "subsurface_min_footprint": 0.25}

        def chunk(material, first: int, name: str) -> str:
            built = dwivedi.Scene()
            built.add_material(material)
            built.add_mesh([-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0], [0, 1, 2, 0, 2, 3], 0)
            built.add_light(dwivedi.SunLight(direction=(0.2, 0.3, -1.0), strength=2.0))
            built.set_camera(dwivedi.Camera.look_at((0, -1.5, 1.5), (0, 0, 0)))
            built.commit()
            settings = dwivedi.BakeSettings(width=8, height=6, samples=4, threads=1, sample_first=first, sample_count=2)
            image = built.bake(settings)
            path = self.path(name + ".dwvpart")
            image.write_partial(path)
            image.close()
            built.close()
            return path

        first = chunk(base, 0, "base")
        dwivedi.merge_partials([first, chunk(base, 2, "same")]).close()  # the same scene merges
        for field, value in changes.items():
            other = chunk(dataclasses.replace(base, **{field: value}), 2, "other-" + field)
            with self.assertRaises(dwivedi.Error, msg=field) as caught:
                dwivedi.merge_partials([first, other])
            self.assertIn("another scene", str(caught.exception), field)
            self.assertIn(os.path.basename(other), str(caught.exception), field)

    def test_chunks_cut_at_any_length_are_refused(self) -> None:
        small = ["--width", "12", "--height", "8", "--spp", "6", "--threads", "1", "--quiet"]
        parts = []
        for first, name in ((0, "a"), (3, "b")):
            done = run("bake", *small, "--samples", f"{first}:3", "--out", self.path(name))
            self.assertEqual(done.returncode, 0, done.stderr)
            parts.append(self.path(name + ".dwvpart"))
        done = run("merge", *parts, "--out", self.path("good"))
        self.assertEqual(done.returncode, 0, done.stderr)
        good = {s: read(self.path("good" + s)) for s in OUTPUTS}
        data = read(parts[1])
        for length in (0, 1, 7, HEADER_BYTES - 1, HEADER_BYTES, len(data) // 3, len(data) - 16, len(data) - 1,
                       len(data) + 1):
            cut = self.path(f"cut-{length}.dwvpart")
            with open(cut, "wb") as f:
                f.write(data[:length] if length <= len(data) else data + b"\0")
            done = run("merge", parts[0], cut, "--out", self.path("good"))
            self.assertEqual(done.returncode, 1, (length, done.stderr))
            self.assertIn(os.path.basename(cut), done.stderr, length)
            self.assertEqual(len(done.stderr.splitlines()), 1, done.stderr)
            for s, content in good.items():
                self.assertEqual(read(self.path("good" + s)), content, f"good{s} changed by a chunk cut at {length}")

    def test_a_killed_merge_leaves_no_partial_output(self) -> None:
        size = ["--width", "480", "--height", "360", "--threads", "2", "--quiet"]
        parts = {}
        for seed in ("1", "2"):
            parts[seed] = []
            for first in (0, 1):
                prefix = self.path(f"s{seed}-{first}")
                done = run("bake", *size, "--spp", "2", "--seed", seed, "--samples", f"{first}:1", "--out", prefix)
                self.assertEqual(done.returncode, 0, done.stderr)
                parts[seed].append(prefix + ".dwvpart")
        done = run("merge", *parts["2"], "--out", self.path("new"))  # the complete outputs of seed 2
        self.assertEqual(done.returncode, 0, done.stderr)
        new = {s: read(self.path("new" + s)) for s in OUTPUTS}
        done = run("merge", *parts["1"], "--out", self.path("shot"))
        self.assertEqual(done.returncode, 0, done.stderr)
        old = {s: read(self.path("shot" + s)) for s in OUTPUTS}
        self.assertNotEqual(old[".exr"], new[".exr"])

        started = time.monotonic()
        run("merge", *parts["2"], "--out", self.path("timed"))
        whole = time.monotonic() - started  # how long a merge takes here now (spreads the kills)
        killed = 0
        for step in range(1, 8):
            merge = subprocess.Popen([os.environ["DWIVEDI_CLI"], "merge", *parts["2"], "--out", self.path("shot")],
                                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            time.sleep(whole * step / 8.0)
            merge.send_signal(signal.SIGKILL)
            merge.wait(timeout=60)
            killed += merge.returncode == -signal.SIGKILL
            for s in OUTPUTS:
                now = read(self.path("shot" + s))
                self.assertIn(now, (old[s], new[s]), f"shot{s} is partial after a kill at step {step}")
            visible = {n for n in os.listdir(self.dir) if n.startswith("shot") and not n.startswith(".")}
            self.assertEqual(visible, {"shot" + s for s in OUTPUTS})
            for s in OUTPUTS:  # the next kill starts from the earlier outputs again
                with open(self.path("shot" + s), "wb") as f:
                    f.write(old[s])
        self.assertGreater(killed, 0, "no merge was still running when killed")


if __name__ == "__main__":
    unittest.main()
