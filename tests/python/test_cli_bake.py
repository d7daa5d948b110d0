"""`dwivedi bake` end to end: the default scene and a scene file bake into PREFIX.exr/.png/.json;
bad scenes and flags fail with a message and leave earlier outputs alone; Ctrl-C (SIGINT) cancels
cleanly, also leaving earlier outputs alone; the time budget stops a bake. Standard library only.
"""
import json
import os
import shutil
import signal
import subprocess
import tempfile
import time
import unittest

from cli_helpers import USAGE, assert_bad_usage, run_cli

SMALL = ["--width", "48", "--height", "27", "--spp", "4", "--quiet"]
JSON_KEYS = {"spp", "seconds", "estimated_relative_error", "mean_rgb", "events", "path_rays", "features", "error_vs_time"}


def outputs(prefix):
    return [prefix + suffix for suffix in (".exr", ".png", ".json")]


def snapshot(folder):
    """Every file in folder with its bytes."""
    result = {}
    for name in sorted(os.listdir(folder)):
        with open(os.path.join(folder, name), "rb") as handle:
            result[name] = handle.read()
    return result


class BakeCli(unittest.TestCase):
    def setUp(self):
        self.folder = tempfile.mkdtemp(prefix="dwivedi-bake-")
        self.prefix = os.path.join(self.folder, "out")

    def tearDown(self):
        shutil.rmtree(self.folder, ignore_errors=True)

    def bake(self, *args):
        done = run_cli("bake", "--out", self.prefix, *SMALL, *args)
        self.assertEqual(done.returncode, 0, done.stderr)
        with open(self.prefix + ".json") as handle:
            return json.load(handle)

    def test_default_scene_writes_three_outputs(self):
        stats = self.bake("--threads", "2")
        self.assertLessEqual(JSON_KEYS, set(stats))
        self.assertEqual(stats["spp"], 4)
        self.assertGreater(stats["events"], 0, "the default scene has subsurface materials")
        self.assertTrue(all(value > 0 for value in stats["mean_rgb"]), stats["mean_rgb"])
        self.assertIn("subsurface", stats["features"])
        self.assertGreaterEqual(len(stats["error_vs_time"]), 1)
        for path in outputs(self.prefix):
            self.assertGreater(os.path.getsize(path), 0, path)
        with open(self.prefix + ".png", "rb") as handle:
            self.assertEqual(handle.read(8), b"\x89PNG\r\n\x1a\n")
        with open(self.prefix + ".exr", "rb") as handle:
            self.assertEqual(handle.read(4), b"\x76\x2f\x31\x01")  # OpenEXR magic number
        self.assertEqual([name for name in os.listdir(self.folder) if "partial" in name], [])

    def test_same_seed_same_image_for_any_thread_count(self):
        # the EXR also holds the bake's seconds, so compare the display image and the mean
        results = []
        for threads in ("1", "2"):
            stats = self.bake("--threads", threads, "--seed", "7")
            with open(self.prefix + ".png", "rb") as handle:
                results.append((handle.read(), stats["mean_rgb"], stats["events"]))
        self.assertEqual(results[0], results[1])

    def test_bad_scene_fails_and_keeps_earlier_outputs(self):
        self.bake()
        before = snapshot(self.folder)
        bad = os.path.join(self.folder, "bad.json")
        with open(bad, "w") as handle:
            handle.write('{"version": 1, "meshes": [')
        done = run_cli("bake", bad, "--out", self.prefix, *SMALL)
        self.assertEqual(done.returncode, 1, done.stderr)
        self.assertIn("bad.json", done.stderr)
        os.remove(bad)
        self.assertEqual(snapshot(self.folder), before)
        done = run_cli("bake", os.path.join(self.folder, "missing.json"), "--out", self.prefix, *SMALL)
        self.assertEqual(done.returncode, 1, done.stderr)
        self.assertIn("missing.json", done.stderr)
        self.assertEqual(snapshot(self.folder), before)

    def test_bad_flags(self):
        assert_bad_usage(self, ["bake"], "dwivedi bake:", ["--out"])
        assert_bad_usage(self, ["bake", "--out", self.prefix, "--spp", "many"], "dwivedi bake:", ["--spp"])
        assert_bad_usage(self, ["bake", "--out", self.prefix, "--technique", "magic"], "dwivedi bake:", ["magic"])
        assert_bad_usage(self, ["bake", "--out", self.prefix, "--frobnicate"], "dwivedi bake:", ["--frobnicate"])
        for blur in ("-1", "inf", "nan", "soft"):
            assert_bad_usage(self, ["bake", "--out", self.prefix, "--blur-glossy", blur], "dwivedi bake:",
                             ["--blur-glossy", blur])
        assert_bad_usage(self, ["bake", "--out", self.prefix, "--uv-jitter", "clamp"], "dwivedi bake:",
                         ["--uv-jitter", "clamp"])
        done = run_cli("bake", "--out", self.prefix, "--spp", "0", "--quiet")
        self.assertEqual(done.returncode, USAGE, done.stderr)
        self.assertIn("samples", done.stderr)
        done = run_cli("bake", "--out", self.prefix, *SMALL, "--view", "No Such View")
        self.assertEqual(done.returncode, 1, done.stderr)
        self.assertIn("No Such View", done.stderr)
        self.assertEqual(os.listdir(self.folder), [])

    def write_box_scene(self, **bake):
        """A 1 m box whose radii differ per channel (so its channels can walk apart), lit by a sun
        and seen by a camera, with `bake` as the scene's "bake" object; returns the file's path."""
        positions = [x for corner in range(8) for x in ((corner & 1) - 0.5, (corner >> 1 & 1) - 0.5,
                                                         (corner >> 2 & 1) - 0.5)]
        indices = [0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                   2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5]
        scene = {"version": 1,
                 "materials": {"wax": {"subsurface_radius": [1.0, 0.5, 0.25], "subsurface_scale": 0.2}},
                 "meshes": [{"material": "wax", "positions": positions, "indices": indices}],
                 "lights": [{"kind": "sun", "strength": 3.0, "direction": [0.3, 0.5, -1.0]}],
                 "camera": {"transform": {"look_at": {"eye": [1.5, -3.0, 2.0], "target": [0.0, 0.0, 0.0]}}},
                 "bake": bake}
        path = os.path.join(self.folder, "box.json")
        with open(path, "w") as handle:
            json.dump(scene, handle)
        return path

    def test_channel_walks_from_the_scene_and_the_flag(self):
        """The scene's bake.channel_walks is used, --channel-walks overrides it, and a bad value in
        either is refused with its name and where it was written."""
        scene = self.write_box_scene(technique="classical", channel_walks="separate")
        stats = self.bake(scene, "--threads", "2")
        self.assertIn("channel_walks", stats["features"])
        self.assertNotIn("rgb_walks", stats["features"])
        stats = self.bake(scene, "--threads", "2", "--channel-walks", "shared")
        self.assertNotIn("channel_walks", stats["features"])
        self.assertIn("rgb_walks", stats["features"])
        assert_bad_usage(self, ["bake", scene, "--out", self.prefix, "--channel-walks", "apart"], "dwivedi bake:",
                         ["--channel-walks", "apart"])
        bad = self.write_box_scene(channel_walks="apart")
        done = run_cli("bake", bad, "--out", self.prefix, *SMALL)
        self.assertEqual(done.returncode, 1, done.stderr)
        self.assertIn("bake.channel_walks", done.stderr)
        self.assertIn("apart", done.stderr)

    def test_pixel_filter_from_the_scene_and_the_flag(self):
        """The scene's bake.pixel_filter / filter_width are used and --pixel-filter / --filter-width
        override them: same seed, same image for the same filter wherever it is written, another
        image for another filter."""
        def png(*args):
            self.bake(*args, "--seed", "3")
            with open(self.prefix + ".png", "rb") as handle:
                return handle.read()
        box = png(self.write_box_scene())
        gaussian = png(self.write_box_scene(pixel_filter="gaussian", filter_width=2.0))
        self.assertNotEqual(gaussian, box)
        self.assertEqual(png(self.write_box_scene(), "--pixel-filter", "gaussian", "--filter-width", "2"), gaussian)
        self.assertEqual(png(self.write_box_scene(pixel_filter="gaussian", filter_width=2.0),
                             "--pixel-filter", "box", "--filter-width", "1"), box)

    def test_bad_pixel_filter_flags_and_keys(self):
        """A pixel filter that is no name and a width outside Blender's 0.01 to 10, as flags (usage,
        exit 2) or in the scene file (exit 1, the key named), are refused before the bake, and the
        folder is as it was: an earlier bake's outputs kept, nothing new written."""
        for filter_flags, words in ((["--pixel-filter", "mitchell"],
                                     ["--pixel-filter", "'mitchell'", "box, gaussian or blackman_harris"]),
                                    (["--pixel-filter", "BOX"], ["--pixel-filter", "'BOX'"]),
                                    (["--filter-width", "0"], ["--filter-width", "'0'", "[0.01, 10]"]),
                                    (["--filter-width", "10.5"], ["--filter-width", "'10.5'", "[0.01, 10]"]),
                                    (["--filter-width", "nan"], ["--filter-width", "'nan'"]),
                                    (["--filter-width", "abc"], ["--filter-width", "'abc'", "not a number"])):
            assert_bad_usage(self, ["bake", "--out", self.prefix, *SMALL, *filter_flags], "dwivedi bake:", words)
            self.assertEqual(os.listdir(self.folder), [], filter_flags)
        self.bake()
        cases = [("pixel_filter", '"mitchell"', "'mitchell' (box, gaussian or blackman_harris)"),
                 ("pixel_filter", "2", "expected a string, found a number"),
                 ("pixel_filter", "null", "expected a string, found null"),
                 ("filter_width", "0.005", "[0.01, 10]"),
                 ("filter_width", "-1", "-1 pixels"),
                 ("filter_width", "11", "11 pixels"),
                 ("filter_width", '"1.5"', "expected a number, found a string"),
                 ("filter_width", "null", "expected a number, found null"),
                 ("filter_width", "1e400", "too large")]  # JSON has no NaN; 1e400 is beyond a double
        for key, value, message in cases:
            scene = self.write_box_scene(**{key: "@value@"})
            with open(scene) as handle:
                text = handle.read().replace('"@value@"', value)
            with open(scene, "w") as handle:
                handle.write(text)
            before = snapshot(self.folder)
            done = run_cli("bake", scene, "--out", self.prefix, *SMALL)
            self.assertEqual(done.returncode, 1, (key, value, done.stderr))
            self.assertEqual(done.stdout, "", (key, value))
            for said in ("box.json", "bake." + key, message):
                self.assertIn(said, done.stderr, (key, value))
            self.assertEqual(snapshot(self.folder), before, (key, value))

    def test_look_none_is_blenders_no_look(self):
        """Blender's look menu calls "no look" None: `--look None` bakes what no --look does."""
        images = []
        for extra in ([], ["--look", "None"]):
            self.bake("--seed", "3", *extra)
            with open(self.prefix + ".png", "rb") as handle:
                images.append(handle.read())
        self.assertEqual(images[0], images[1])
        done = run_cli("bake", "--out", self.prefix, *SMALL, "--look", "none")  # names are case-sensitive
        self.assertEqual(done.returncode, 1, done.stderr)
        self.assertIn("none", done.stderr)

    def test_unwritable_folder_fails_cleanly(self):
        done = run_cli("bake", "--out", os.path.join(self.folder, "no", "such", "dir", "x"), *SMALL)
        self.assertEqual(done.returncode, 1, done.stderr)
        self.assertIn("no/such/dir", done.stderr)
        self.assertEqual(os.listdir(self.folder), [])

    def test_outputs_are_checked_before_the_bake(self):
        """A bake of 10^9 samples per pixel would outlast run_cli's 60 s timeout: each of these must
        be refused before it starts, not after."""
        endless = ["--spp", "1000000000", "--quiet"]
        cases = [
            (["--out", os.path.join(self.folder, "missing", "x")], "missing"),
            (["--out", os.path.join(self.folder, "file", "x")], "Not a directory"),
            (["--out", self.prefix, "--view", "No Such View"], "No Such View"),
            (["--out", self.prefix, "--look", "No Such Look"], "No Such Look"),
            (["--out", self.prefix, "--ocio", os.path.join(self.folder, "none.ocio")], "none.ocio"),
        ]
        with open(os.path.join(self.folder, "file"), "w") as handle:
            handle.write("a file where a folder should be")
        before = snapshot(self.folder)
        for args, message in cases:
            done = run_cli("bake", *args, *endless)
            self.assertEqual(done.returncode, 1, done.stderr)
            self.assertIn(message, done.stderr)
            self.assertEqual(snapshot(self.folder), before)

    def test_interrupt_cancels_and_keeps_earlier_outputs(self):
        self.bake()
        before = snapshot(self.folder)
        cli = os.environ["DWIVEDI_CLI"]
        process = subprocess.Popen([cli, "bake", "--out", self.prefix, "--spp", "100000", "--quiet"],
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        time.sleep(1.5)
        sent = time.monotonic()
        process.send_signal(signal.SIGINT)
        stdout, stderr = process.communicate(timeout=30)
        waited = time.monotonic() - sent
        self.assertNotEqual(process.returncode, 0, stderr)
        self.assertIn("cancelled", stderr)
        self.assertEqual(snapshot(self.folder), before)
        print(f"SIGINT to exit: {waited:.3f} s")

    def test_time_budget_stops_the_bake(self):
        started = time.monotonic()
        stats = self.bake("--spp", "1000000", "--time", "1.5")
        elapsed = time.monotonic() - started
        self.assertLess(stats["spp"], 1000000)
        self.assertGreater(stats["spp"], 0)
        print(f"--time 1.5: bake {stats['seconds']:.2f} s, command {elapsed:.2f} s, {stats['spp']} spp")


class BakeReport(unittest.TestCase):
    """tools/bake_report.py --quick end to end (Debian's interpreter has matplotlib)."""

    def test_report_writes_every_file(self):
        folder = tempfile.mkdtemp(prefix="dwivedi-bake-report-")
        try:
            script = os.path.join(os.environ["DWIVEDI_SOURCE_DIR"], "tools", "bake_report.py")
            done = subprocess.run(["/usr/bin/python3", script, "--cli", os.environ["DWIVEDI_CLI"], "--out", folder,
                                   "--quick"], capture_output=True, text=True, timeout=300)
            self.assertEqual(done.returncode, 0, done.stderr)
            self.assertEqual(sorted(os.listdir(folder)), ["bake_report.json", "bake_report.md", "bake_rmse.png"])
            with open(os.path.join(folder, "bake_report.json")) as handle:
                figures = json.load(handle)
            self.assertTrue(figures["threads_bit_identical"])
            self.assertGreater(figures["memory"]["bytes_per_triangle"], 0)
            self.assertEqual(set(figures["rmse"]), {"classical", "poe", "closest", "incident", "backward",
                                                    "cycles", "auto"})
        finally:
            shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    unittest.main()
