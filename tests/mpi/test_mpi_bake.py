"""`mpirun -n N dwivedi bake ... --mpi` (docs/farm.md, "MPI"): 1, 2 and 3 ranks write the one-process
bake's EXR pixels (RGBA, variance, sample counts), PNG bytes and JSON stats, also with uneven shares
of ranges; a rank with another scene file, another seed, killed or stopped ends all ranks with a
non-zero exit and a message, no output and no leftover files, within the test's timeout; the build
without MPI says so. Standard library only.

Environment (tests/CMakeLists.txt): DWIVEDI_CLI, DWIVEDI_MPIRUN (unset where MPI was not found),
DWIVEDI_CLI_WITHOUT_MPI (the command built without MPI)."""
import json
import os
import signal
import struct
import subprocess
import tempfile
import time
import unittest
import uuid
from typing import Dict, List, Tuple

SMALL = ["--width", "24", "--height", "20", "--spp", "13", "--quiet"]
# A bake long enough (tens of seconds) that a rank is still baking when the test kills or stops it.
LONG = ["--width", "64", "--height", "48", "--spp", "4000", "--quiet"]
RUN_TIMEOUT = 60  # seconds: a run that hangs fails here


def mpirun_prefix(ranks: int) -> List[str]:
    prefix = [os.environ["DWIVEDI_MPIRUN"], "--oversubscribe"]
    if os.geteuid() == 0:
        prefix.append("--allow-run-as-root")
    return prefix + ["-n", str(ranks)]


def read(path: str) -> bytes:
    with open(path, "rb") as f:
        return f.read()


def exr_parts(path: str) -> Tuple[Dict[str, bytes], List[Tuple[int, bytes]]]:
    """A single-part scanline OpenEXR file's header attributes (name -> raw value) and its pixel
    blocks (first line, compressed bytes), read by the file layout of the OpenEXR specification
    ("The OpenEXR File Layout"): magic, version, attributes up to an empty name, the offset table,
    then per block its y and byte count. Equal blocks under the same compression are equal pixels."""
    data = read(path)
    if data[:4] != b"\x76\x2f\x31\x01":
        raise AssertionError(f"{path} is not an OpenEXR file")
    flags = struct.unpack_from("<I", data, 4)[0]
    if flags & 0x1A00:  # tiled (0x200), deep (0x800) or multi-part (0x1000): not what dwivedi writes
        raise AssertionError(f"{path}: not a single-part scanline file (flags {flags:#x})")
    at, attributes = 8, {}
    while data[at] != 0:
        name_end = data.index(b"\0", at)
        type_end = data.index(b"\0", name_end + 1)
        size = struct.unpack_from("<i", data, type_end + 1)[0]
        value_at = type_end + 5
        attributes[data[at:name_end].decode()] = data[value_at:value_at + size]
        at = value_at + size
    at += 1
    x0, y0, x1, y1 = struct.unpack("<4i", attributes["dataWindow"])
    lines_per_block = {0: 1, 1: 1, 2: 1, 3: 16, 4: 32, 5: 16}[attributes["compression"][0]]
    blocks = -(-(y1 - y0 + 1) // lines_per_block)
    offsets = struct.unpack_from(f"<{blocks}Q", data, at)
    pixels = []
    for offset in offsets:
        y, size = struct.unpack_from("<ii", data, offset)
        pixels.append((y, data[offset + 8:offset + 8 + size]))
    return attributes, pixels


# EXR attributes and JSON fields that a merged bake has of its own: the time (the chunks' seconds
# added up), the error series (a point per range instead of per pass) and the thread count.
OWN_EXR = {"dwivedi:seconds", "dwivedi:error_vs_time"}
OWN_JSON = {"seconds", "error_vs_time", "threads"}


@unittest.skipUnless(os.environ.get("DWIVEDI_MPIRUN"), "built without MPI")
class MpiBakeTest(unittest.TestCase):
    def setUp(self) -> None:
        self.folder = tempfile.TemporaryDirectory()
        self.dir = self.folder.name
        self.tmp = os.path.join(self.dir, "tmp")  # the ranks' TMPDIR: nothing may be left in it
        os.mkdir(self.tmp)
        self.env = dict(os.environ, TMPDIR=self.tmp, DWV_TEST_RUN=uuid.uuid4().hex)

    def tearDown(self) -> None:
        self.folder.cleanup()

    def path(self, name: str) -> str:
        return os.path.join(self.dir, name)

    def mpirun(self, ranks: int, *args: str) -> subprocess.CompletedProcess:
        return subprocess.run([*mpirun_prefix(ranks), os.environ["DWIVEDI_CLI"], "bake", *args], capture_output=True,
                              text=True, timeout=RUN_TIMEOUT, env=self.env)

    def leftovers(self) -> List[str]:
        """dwivedi's files in the ranks' TMPDIR (Open MPI keeps its session folder there too)."""
        return [n for n in os.listdir(self.tmp) if n.startswith("dwivedi-mpi")]

    def assert_nothing_written(self, prefix: str) -> None:
        self.assertEqual([n for n in os.listdir(self.dir) if n.startswith(prefix)], [])
        self.assertEqual(self.leftovers(), [])

    def test_ranks_write_the_one_process_bake(self) -> None:
        done = subprocess.run([os.environ["DWIVEDI_CLI"], "bake", *SMALL, "--threads", "2", "--out", self.path("one")],
                              capture_output=True, text=True, timeout=RUN_TIMEOUT)
        self.assertEqual(done.returncode, 0, done.stderr)
        one_attributes, one_pixels = exr_parts(self.path("one.exr"))
        one_json = json.loads(read(self.path("one.json")))
        # 13 spp: 1 rank in its default 2 ranges; 2 ranks in ranges of 5 (5 + 5 + 3); 3 ranks of one
        # thread in ranges of 2, so that the ranks' shares differ
        for ranks, extra in ((1, []), (2, ["--mpi-chunk", "5"]), (3, ["--mpi-chunk", "2", "--threads", "1"])):
            with self.subTest(ranks=ranks):
                prefix = self.path(f"ranks{ranks}")
                done = self.mpirun(ranks, *SMALL, *extra, "--mpi", "--out", prefix)
                self.assertEqual(done.returncode, 0, done.stderr)
                self.assertIn(f"on {ranks} rank(s)", done.stdout)
                attributes, pixels = exr_parts(prefix + ".exr")
                self.assertEqual(len(pixels), len(one_pixels))
                self.assertEqual(pixels, one_pixels, "EXR pixels, variance or sample counts differ")
                self.assertEqual(set(attributes), set(one_attributes))
                for name in set(attributes) - OWN_EXR:
                    self.assertEqual(attributes[name], one_attributes[name], name)
                self.assertEqual(read(prefix + ".png"), read(self.path("one.png")))
                merged_json = json.loads(read(prefix + ".json"))
                self.assertEqual(set(merged_json), set(one_json))
                for key in set(one_json) - OWN_JSON:
                    self.assertEqual(merged_json[key], one_json[key], key)
                self.assertEqual(merged_json["error_vs_time"][-1]["estimated_relative_error"],
                                 one_json["estimated_relative_error"])
                self.assertEqual(self.leftovers(), [])
        # the harness catches a planted difference: another seed's pixels are not the bake's
        done = self.mpirun(2, *SMALL, "--seed", "1", "--mpi", "--out", self.path("planted"))
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertNotEqual(exr_parts(self.path("planted.exr"))[1], one_pixels)

    def mpmd(self, first: List[str], second: List[str]) -> subprocess.CompletedProcess:
        """Rank 0 with arguments `first`, rank 1 with `second` (mpirun's colon syntax)."""
        cli = os.environ["DWIVEDI_CLI"]
        command = [*mpirun_prefix(1), cli, "bake", *first, ":", "-n", "1", cli, "bake", *second]
        return subprocess.run(command, capture_output=True, text=True, timeout=RUN_TIMEOUT, env=self.env)

    def test_a_rank_that_cannot_start_ends_all(self) -> None:
        missing = self.path("missing.json")
        out = self.path("out")
        done = self.mpmd([*SMALL, "--mpi", "--out", out], [missing, *SMALL, "--mpi", "--out", out])
        self.assertNotEqual(done.returncode, 0)
        self.assertIn("missing.json: cannot open it", done.stderr)
        self.assertIn("another rank could not start", done.stderr)
        self.assert_nothing_written("out")

    def test_a_rank_with_another_seed_is_refused_naming_it(self) -> None:
        done = self.mpmd([*SMALL, "--mpi", "--out", self.path("out")],
                         [*SMALL, "--seed", "5", "--mpi", "--out", self.path("out")])
        self.assertNotEqual(done.returncode, 0)
        self.assertRegex(done.stderr, r"rank-1\.dwvpart' is foreign: another seed")
        self.assert_nothing_written("out")

    def test_a_rank_whose_range_fails_ends_all(self) -> None:
        # rank 1 cannot write its range's file (its TMPDIR does not exist): its message, from rank 0
        cli, out = os.environ["DWIVEDI_CLI"], self.path("out")
        command = [*mpirun_prefix(1), cli, "bake", *SMALL, "--mpi", "--out", out, ":", "-n", "1", "env",
                   "TMPDIR=" + self.path("absent"), cli, "bake", *SMALL, "--mpi", "--out", out]
        done = subprocess.run(command, capture_output=True, text=True, timeout=RUN_TIMEOUT, env=self.env)
        self.assertNotEqual(done.returncode, 0)
        self.assertRegex(done.stderr, r"rank 1 of 2: samples \d+:\d+: dwv_image_write_partial: cannot write .*absent")
        self.assertEqual(done.stderr.count("dwv_image_write_partial"), 1, done.stderr)
        self.assert_nothing_written("out")

    def is_ours(self, pid: int) -> bool:
        try:
            with open(f"/proc/{pid}/environ", "rb") as f:
                return f"DWV_TEST_RUN={self.env['DWV_TEST_RUN']}".encode() in f.read().split(b"\0")
        except OSError:
            return False

    def rank_process(self, rank: int, deadline: float) -> int:
        """The pid of this test's `dwivedi` of MPI rank `rank` (found by its environment)."""
        wanted = {f"DWV_TEST_RUN={self.env['DWV_TEST_RUN']}".encode(), f"OMPI_COMM_WORLD_RANK={rank}".encode()}
        while time.monotonic() < deadline:
            for pid in filter(str.isdigit, os.listdir("/proc")):
                try:
                    with open(f"/proc/{pid}/comm", "rb") as f:
                        if f.read().strip() != b"dwivedi":
                            continue
                    with open(f"/proc/{pid}/environ", "rb") as f:
                        if wanted <= set(f.read().split(b"\0")):
                            return int(pid)
                except OSError:
                    continue
            time.sleep(0.05)
        raise AssertionError(f"rank {rank} did not start")

    def signal_rank_mid_bake(self, signal_number: int, *extra: str,
                             rank: int = 1) -> Tuple[subprocess.CompletedProcess, float]:
        """Runs a long bake on 2 ranks, sends rank `rank` `signal_number` once it is baking, and
        returns the run and the seconds from the signal to mpirun's exit."""
        # When mpirun ends a job it sends the ranks SIGTERM, and SIGKILL 1 s later: on a loaded
        # machine a rank (a stopped one just continued) may not have run by then to remove its
        # files. 20 s here (mpirun waits that long at most: a rank that ends sooner ends the
        # wait), so that the check of no leftovers tests dwivedi, not the scheduler: 3 s once, and
        # 8 s once more (the ASan build beside another build's tests, load ~4 on 2 cores), left a
        # stopped rank 0's folder.
        command = [*mpirun_prefix(2), "--mca", "odls_base_sigkill_timeout", "20", os.environ["DWIVEDI_CLI"], "bake",
                   *LONG, *extra, "--mpi", "--out", self.path("out")]
        run = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=self.env)
        pid = 0
        try:
            pid = self.rank_process(rank, time.monotonic() + RUN_TIMEOUT)
            time.sleep(1.0)  # past the start: baking its first range
            os.kill(pid, signal_number)
            signalled = time.monotonic()
            stdout, stderr = run.communicate(timeout=RUN_TIMEOUT)
            return subprocess.CompletedProcess(command, run.returncode, stdout, stderr), time.monotonic() - signalled
        finally:
            if run.poll() is None:
                run.kill()
                run.communicate()
            if pid and self.is_ours(pid):  # a failed test leaves no stopped rank behind
                os.kill(pid, signal.SIGKILL)

    def test_a_killed_rank_ends_all(self) -> None:
        done, _ = self.signal_rank_mid_bake(signal.SIGKILL)
        self.assertNotEqual(done.returncode, 0)
        self.assertIn("rank 1", done.stderr)
        self.assert_nothing_written("out")

    def test_a_stopped_rank_times_out(self) -> None:
        done, seconds = self.signal_rank_mid_bake(signal.SIGSTOP, "--mpi-timeout", "2")
        self.assertNotEqual(done.returncode, 0)
        self.assertIn("rank 1 has not been heard from in 2 s", done.stderr)
        self.assertLess(seconds, RUN_TIMEOUT)
        self.assert_nothing_written("out")

    def test_a_stopped_rank_0_times_out(self) -> None:
        # short ranges: rank 1 soon needs rank 0 (to take a range, or to give it the next)
        done, seconds = self.signal_rank_mid_bake(signal.SIGSTOP, "--mpi-timeout", "2", "--mpi-chunk", "20", rank=0)
        self.assertNotEqual(done.returncode, 0)
        self.assertRegex(done.stderr, r"rank 1 of 2: no .* from rank 0 in 2 s \(--mpi-timeout\)")
        self.assertLess(seconds, RUN_TIMEOUT)
        self.assert_nothing_written("out")

    def test_what_mpi_does_not_do_is_refused(self) -> None:
        for extra, message in ((["--time", "5"], "no --time or --error"), (["--samples", "0:4"], "no --samples"),
                               (["--spp", "0"], "--spp must be at least 1")):
            with self.subTest(extra=extra):
                done = self.mpirun(1, *SMALL, *extra, "--mpi", "--out", self.path("out"))
                self.assertEqual(done.returncode, 2, done.stderr)
                self.assertIn(message, done.stderr)
                self.assert_nothing_written("out")


class WithoutMpiTest(unittest.TestCase):
    def test_the_build_without_mpi_says_so(self) -> None:
        with tempfile.TemporaryDirectory() as folder:
            prefix = os.path.join(folder, "out")
            done = subprocess.run([os.environ["DWIVEDI_CLI_WITHOUT_MPI"], "bake", *SMALL, "--mpi", "--out", prefix],
                                  capture_output=True, text=True, timeout=RUN_TIMEOUT)
            self.assertEqual(done.returncode, 1)
            self.assertIn("built without MPI", done.stderr)
            self.assertEqual(os.listdir(folder), [])

    def test_mpi_flags_need_mpi(self) -> None:
        done = subprocess.run([os.environ["DWIVEDI_CLI"], "bake", *SMALL, "--mpi-chunk", "3", "--out", "unused"],
                              capture_output=True, text=True, timeout=RUN_TIMEOUT)
        self.assertEqual(done.returncode, 2)
        self.assertIn("need --mpi", done.stderr)


if __name__ == "__main__":
    unittest.main()
