"""`dwivedi bake --samples FIRST:COUNT` and `dwivedi merge` (docs/farm.md): merged chunks give the
single bake's display image and stats; foreign, missing, truncated chunks are refused naming the
file; a failed merge leaves earlier outputs as they were; a chunk killed mid-way leaves no file
that looks complete. Standard library only."""
import json
import os
import signal
import struct
import subprocess
import tempfile
import time
import unittest

from cli_helpers import run_cli

SMALL = ["--width", "24", "--height", "14", "--spp", "12", "--threads", "2", "--quiet"]
HEADER_BYTES = 216  # src/api/partial_api.c: the fixed header


def read(path: str) -> bytes:
    with open(path, "rb") as f:
        return f.read()


def write(path: str, data: bytes) -> None:
    with open(path, "wb") as f:
        f.write(data)


def fnv1a64(data: bytes) -> int:
    h = 0xcbf29ce484222325
    for b in data:
        h = ((h ^ b) * 0x100000001b3) & 0xFFFFFFFFFFFFFFFF
    return h


class SplitMergeTest(unittest.TestCase):
    def setUp(self) -> None:
        self.folder = tempfile.TemporaryDirectory()
        self.dir = self.folder.name

    def tearDown(self) -> None:
        self.folder.cleanup()

    def path(self, name: str) -> str:
        return os.path.join(self.dir, name)

    def chunk(self, name: str, first: int, count: int, *extra: str) -> str:
        done = run_cli("bake", *SMALL, "--samples", f"{first}:{count}", "--out", self.path(name), *extra)
        self.assertEqual(done.returncode, 0, done.stderr)
        return self.path(name) + ".dwvpart"

    def test_merge_equals_single_bake(self) -> None:
        done = run_cli("bake", *SMALL, "--out", self.path("whole"))
        self.assertEqual(done.returncode, 0, done.stderr)
        parts = [self.chunk("c", 7, 5), self.chunk("a", 0, 4), self.chunk("b", 4, 3, "--threads", "1")]
        done = run_cli("merge", *parts, "--out", self.path("merged"))
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertEqual(read(self.path("whole.png")), read(self.path("merged.png")))
        whole = json.loads(read(self.path("whole.json")))
        merged = json.loads(read(self.path("merged.json")))
        for key in ("spp", "samples", "estimated_relative_error", "mean_rgb", "technique", "features", "width"):
            self.assertEqual(whole[key], merged[key], key)
        self.assertEqual([p["spp"] for p in merged["error_vs_time"]], [4, 7, 12])
        self.assertEqual(merged["error_vs_time"][-1]["estimated_relative_error"], whole["estimated_relative_error"])

    def test_faults_are_refused_naming_the_file(self) -> None:
        a, b = self.chunk("a", 0, 6), self.chunk("b", 6, 6)
        done = run_cli("merge", a, b, "--out", self.path("good"))
        self.assertEqual(done.returncode, 0, done.stderr)
        good = {s: read(self.path("good" + s)) for s in (".exr", ".png", ".json")}
        seed = self.chunk("seed", 6, 6, "--seed", "9")
        overlap = self.chunk("overlap", 3, 6)
        data = bytearray(read(b))
        cut = self.path("cut.dwvpart")
        write(cut, bytes(data[: len(data) // 2]))
        version = bytearray(data)
        version[16:48] = b"9.9.9".ljust(32, b"\0")
        version[-16:-8] = struct.pack("<Q", fnv1a64(bytes(version[:-16])))
        other = self.path("version.dwvpart")
        write(other, bytes(version))
        cases = [([a], b"missing", a), ([a, a, b], b"duplicates", a), ([a, b, overlap], b"overlaps", overlap),
                 ([a, seed], b"another seed", seed), ([a, cut], b"truncated", cut),
                 ([a, other], b"another library version", other), ([a, self.path("absent.dwvpart")], b"cannot open", "absent")]
        for parts, word, named in cases:
            done = run_cli("merge", *parts, "--out", self.path("good"))
            self.assertEqual(done.returncode, 1, (parts, done.stderr))
            self.assertIn(word.decode(), done.stderr)
            self.assertIn(os.path.basename(named), done.stderr)
            self.assertEqual(len(done.stderr.splitlines()), 1, done.stderr)
            for s, content in good.items():
                self.assertEqual(read(self.path("good" + s)), content, f"{s} kept after {word}")
        done = run_cli("bake", *SMALL, "--samples", "10:5", "--out", self.path("x"))
        self.assertNotEqual(done.returncode, 0)
        self.assertIn("does not lie within", done.stderr)
        done = run_cli("bake", *SMALL, "--samples", "3", "--out", self.path("x"))
        self.assertEqual(done.returncode, 2)
        done = run_cli("bake", *SMALL, "--samples", "0:4", "--time", "5", "--out", self.path("x"))
        self.assertEqual(done.returncode, 2)

    def test_killed_chunk_leaves_no_complete_file(self) -> None:
        cli = os.environ["DWIVEDI_CLI"]
        prefix = self.path("killed")
        for sig in (signal.SIGKILL, signal.SIGTERM):
            process = subprocess.Popen([cli, "bake", "--width", "64", "--height", "48", "--spp", "100000", "--threads",
                                        "1", "--quiet", "--samples", "0:100000", "--out", prefix],
                                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            time.sleep(1.0)
            self.assertIsNone(process.poll(), "the chunk was still baking when killed")
            process.send_signal(sig)
            process.wait(timeout=30)
            self.assertNotEqual(process.returncode, 0)
            self.assertFalse(os.path.exists(prefix + ".dwvpart"), sig)
            for name in os.listdir(self.dir):
                self.assertFalse(name.endswith(".dwvpart"), name)


if __name__ == "__main__":
    unittest.main()
