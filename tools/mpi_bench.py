#!/usr/bin/env python3
"""Figures of `dwivedi bake --mpi` and `dwivedi merge` (docs/farm.md, "MPI" and "Time to an error on
many nodes"): prints

  1. the 1 -> 2 ranks speed-up on this machine (one thread per rank; runs alternated 1, 2, 1, 2 in
     this one run; the load average before and after, since the machine may be shared),
  2. the merge's cost against image size and chunk count (dwivedi merge of chunks baked here),
  3. the pieces of the node model, each timed here: the cost of a sample, the fixed cost of a
     range, the bytes and time of a range's transfer, the merge's cost per chunk and pixel, and the
     error constant K = error * sqrt(spp),
  4. the model's time to a given error on 10, 100 and 1000 nodes.

Usage: tools/mpi_bench.py [--cli build/dwivedi] [--mpirun mpirun] [--quick] [--pairs N]
       [--speedup-only | --skip-speedup] [--model-pixels N]
       [--model-error E] [--model-cores C] [--model-bandwidth BYTES_PER_S]
Standard library only; any Python 3.8+.
"""
import argparse
import json
import math
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from typing import Dict, List, Sequence, Tuple

PARTIAL_BYTES_PER_PIXEL = 4 + 10 * 16  # src/api/partial_api.c: a count and ten 128-bit sums
PARTIAL_FIXED_BYTES = 216 + 16         # the header and the checksum with the end mark


def children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def timed(command: Sequence[str]) -> Tuple[float, float, str]:
    """Runs `command`; its wall seconds, CPU seconds (user + system of it and its children) and stdout."""
    cpu, start = children_cpu(), time.monotonic()
    done = subprocess.run(list(command), capture_output=True, text=True)
    wall = time.monotonic() - start
    if done.returncode != 0:
        sys.exit(f"mpi_bench: {' '.join(command)} failed ({done.returncode}):\n{done.stderr}")
    return wall, children_cpu() - cpu, done.stdout


class Bench:
    def __init__(self, args: argparse.Namespace, folder: str) -> None:
        self.cli, self.folder, self.quick, self.pairs = args.cli, folder, args.quick, args.pairs
        self.mpirun = [args.mpirun, "--oversubscribe"] + (["--allow-run-as-root"] if os.geteuid() == 0 else [])

    def path(self, name: str) -> str:
        return os.path.join(self.folder, name)

    def mpi_bake(self, ranks: int, bake: List[str], name: str) -> Tuple[float, float, str]:
        return timed([*self.mpirun, "--bind-to", "none", "-n", str(ranks), self.cli, "bake", *bake, "--threads", "1",
                      "--mpi", "--quiet", "--out", self.path(name)])

    def speedup(self) -> None:
        spp = 256 if self.quick else 2048
        bake = ["--width", "64", "--height", "48", "--spp", str(spp)]
        print(f"== 1 -> 2 ranks: default scene, 64 x 48, {spp} spp, one thread per rank, mpirun --bind-to none")
        print(f"cores: {os.cpu_count()}; nice {os.nice(0)}; {autogroup()}; load average before: "
              f"{' '.join(f'{x:.2f}' for x in os.getloadavg())}")
        walls: Dict[int, List[float]] = {1: [], 2: []}
        inner: Dict[int, List[float]] = {1: [], 2: []}  # from MPI_Init to the outputs written (its own print)
        cpus: Dict[int, List[float]] = {1: [], 2: []}
        for ranks in (1, 2) * self.pairs:
            wall, cpu, out = self.mpi_bake(ranks, bake, f"speed{ranks}")
            walls[ranks].append(wall)
            inner[ranks].append(float(re.search(r"([0-9.]+) s wall", out).group(1)))
            cpus[ranks].append(cpu)
            print(f"  {ranks} rank(s): {wall:7.2f} s mpirun wall, {inner[ranks][-1]:7.2f} s in dwivedi, "
                  f"{cpu:7.2f} s CPU  | {out.splitlines()[1]}")
        for name in ("speed1", "speed2"):
            if open(self.path(name + ".png"), "rb").read() != open(self.path("speed1.png"), "rb").read():
                sys.exit("mpi_bench: the 1- and 2-rank images differ")
        print(f"load average after: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
        pairs = [a / b for a, b in zip(walls[1], walls[2])]
        best = min(walls[1]) / min(walls[2])
        print(f"speed-up 1 -> 2 ranks, mpirun's wall: {best:.2f}x (best runs; per alternated pair "
              f"{', '.join(f'{p:.2f}x' for p in pairs)}); inside dwivedi (without mpirun's start): "
              f"{min(inner[1]) / min(inner[2]):.2f}x; CPU 2 ranks / 1 rank: {min(cpus[2]) / min(cpus[1]):.2f}")
        # The control, without MPI: the same bake as one plain process, and as two plain processes at
        # once (twice the work): how much this session gets from a second core at all.
        plain = [self.cli, "bake", *bake, "--threads", "1", "--quiet"]
        alone, together = [], []
        for k in range(self.pairs):
            start = time.monotonic()
            subprocess.run([*plain, "--out", self.path("plain")], check=True, capture_output=True)
            alone.append(time.monotonic() - start)
            start = time.monotonic()
            both = [subprocess.Popen([*plain, "--out", self.path(f"plain{i}")], stdout=subprocess.DEVNULL)
                    for i in range(2)]
            if any(run.wait() != 0 for run in both):
                sys.exit("mpi_bench: a plain bake failed")
            together.append(time.monotonic() - start)
        machine = 2 * min(alone) / min(together)
        print(f"control without MPI: one plain bake {', '.join(f'{t:.2f}' for t in alone)} s; two at once "
              f"{', '.join(f'{t:.2f}' for t in together)} s: two processes do {machine:.2f}x the work of one per "
              f"wall second here; the ranks' speed-up / that: {best / machine:.2f}")
        # What the ranks got of the machine: a rank that had a core to itself would use 1 CPU second
        # per wall second; on a shared machine it gets less, and the wall ratio shows the others' load.
        share = [sum(cpus[r]) / sum(walls[r]) / r for r in (1, 2)]
        print(f"CPU per rank per wall second: 1 rank {share[0]:.2f}, 2 ranks {share[1]:.2f} (1.00 on an idle machine); "
              f"the speed-up with a core per rank, 2 x CPU(1 rank) / CPU(2 ranks): "
              f"{2 * sum(cpus[1]) / sum(cpus[2]):.2f}x")

    def sample_cost(self) -> Dict[str, float]:
        """Seconds per sample and pixel on one thread, and the fixed cost of a range inside an MPI run
        (a bake's start, auto's pilot, the partial file written and read): one rank baking the same
        samples in 1 range and in 16."""
        spp = 128 if self.quick else 256
        bake = ["--width", "64", "--height", "48", "--spp", str(spp)]
        print(f"\n== model pieces: default scene, 64 x 48, {spp} spp, one thread")
        wall, _, _ = timed([self.cli, "bake", *bake, "--threads", "1", "--quiet", "--out", self.path("single")])
        single = json.load(open(self.path("single.json")))
        per_sample = single["seconds"] / (spp * 64 * 48)
        print(f"per-sample cost a = {per_sample * 1e6:.3f} us per sample and pixel "
              f"(one process: {single['seconds']:.2f} s baking, {wall:.2f} s wall)")
        few, many = [], []
        for _ in range(2):
            few.append(self.mpi_bake(1, [*bake, "--mpi-chunk", str(spp)], "ranges1")[0])
            many.append(self.mpi_bake(1, [*bake, "--mpi-chunk", str(spp // 16)], "ranges16")[0])
        per_range = (min(many) - min(few)) / 15.0
        print(f"per-range fixed cost b = {per_range:.3f} s (1 rank: 1 range {min(few):.2f} s, 16 ranges "
              f"{min(many):.2f} s wall, best of 2)")
        # the transfer: 2 ranks, ranges of one sample of a 384 x 216 image (13.6 MB each)
        _, _, out = self.mpi_bake(2, ["--width", "384", "--height", "216", "--spp", "8", "--technique", "classical",
                                      "--mpi-chunk", "1"], "transfer")
        received = re.search(r"received ([0-9.]+) MB in ([0-9.]+) s", out)
        transfer = float(received.group(1)) * 1e6 / max(float(received.group(2)), 1e-9)
        print(f"transfer into rank 0 (shared memory, rank 0 writing the ranges to its disk): {received.group(1)} MB "
              f"in {received.group(2)} s = {transfer / 1e9:.2f} GB/s")
        k = single["estimated_relative_error"] * math.sqrt(spp)
        points = single["error_vs_time"]
        slope = (math.log(points[-1]["estimated_relative_error"]) - math.log(points[1]["estimated_relative_error"])) / (
            math.log(points[-1]["spp"]) - math.log(points[1]["spp"]))
        print(f"error constant K = error * sqrt(spp) = {k:.4f} (log-log slope of its error_vs_time "
              f"from {points[1]['spp']} to {points[-1]['spp']} spp: {slope:.3f}; 1/sqrt(spp) is -0.5)")
        return {"a": per_sample, "b": per_range, "K": k, "transfer": transfer}

    def merge_cost(self) -> Dict[str, float]:
        sizes = [(96, 54), (192, 108)] if self.quick else [(96, 54), (192, 108), (384, 216)]
        counts = [2, 4, 8] if self.quick else [2, 4, 8, 16]
        total = max(counts)
        print(f"\n== merge cost: `dwivedi merge` (chunks, EXR, PNG, JSON), {total} spp in equal chunks, "
              "best of 3")
        print(f"{'pixels':>8} {'chunks':>6} {'MB/chunk':>9} {'wall s':>8} {'CPU s':>7} {'CPU ns/chunk-pixel':>19}")
        rows = []
        for width, height in sizes:
            pixels = width * height
            for count in counts:
                step = total // count
                parts = []
                for k in range(count):
                    name = self.path(f"m{width}_{count}_{k}")
                    timed([self.cli, "bake", "--width", str(width), "--height", str(height), "--spp", str(total),
                           "--technique", "classical", "--samples", f"{k * step}:{step}", "--quiet", "--out", name])
                    parts.append(name + ".dwvpart")
                best_wall, best_cpu = math.inf, math.inf
                for _ in range(3):
                    wall, cpu, _ = timed([self.cli, "merge", *parts, "--out", self.path("merged")])
                    best_wall, best_cpu = min(best_wall, wall), min(best_cpu, cpu)
                size = os.path.getsize(parts[0])
                rows.append((pixels, count, best_wall, best_cpu))
                print(f"{pixels:8d} {count:6d} {size / 1e6:9.2f} {best_wall:8.3f} {best_cpu:7.3f} "
                      f"{1e9 * best_cpu / (pixels * count):19.1f}")
                for part in parts:
                    os.remove(part)
        # least squares of time = c0 + c1 * pixels + c2 * pixels * chunks (the outputs, the chunks), of
        # the CPU seconds: the merge runs on one thread, and its wall here grows with the others' load
        c0, c1, c2 = least_squares([(1.0, p, p * c) for p, c, _, _ in rows], [u for _, _, _, u in rows])
        print(f"fit: merge CPU = {c0:.3f} s + {c1 * 1e9:.1f} ns x pixels + {c2 * 1e9:.1f} ns x pixels x chunks")
        return {"m0": c0, "m_pixel": c1, "m_chunk_pixel": c2}


def autogroup() -> str:
    """Whether Linux shares the CPU per session (autogroup): then a second rank started from the same
    session competes with the first for that session's share, however many cores are idle of it."""
    try:
        with open("/proc/sys/kernel/sched_autogroup_enabled") as f:
            enabled = f.read().strip() == "1"
    except OSError:
        return "autogroup unknown"
    return "autogroup on (the CPU is shared per session)" if enabled else "autogroup off"


def least_squares(rows: List[Tuple[float, float, float]], values: List[float]) -> Tuple[float, float, float]:
    """The x of min |A x - y| for a 3-column A, by the normal equations (Cramer's rule)."""
    ata = [[sum(r[i] * r[j] for r in rows) for j in range(3)] for i in range(3)]
    aty = [sum(r[i] * v for r, v in zip(rows, values)) for i in range(3)]

    def det(m: List[List[float]]) -> float:
        return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))

    d = det(ata)
    out = []
    for i in range(3):
        m = [row[:] for row in ata]
        for r in range(3):
            m[r][i] = aty[r]
        out.append(det(m) / d)
    return out[0], out[1], out[2]


def model(pieces: Dict[str, float], args: argparse.Namespace) -> None:
    """Time to relative error E of an image of n pixels on P nodes of c cores, k ranges per rank:
         spp    = (K / E)^2                                   (error ~ 1 / sqrt(spp))
         bake   = a * n * spp / (P * c)                       (the samples, shared by P * c cores)
         ranges = k * (b + R / D)                             (each rank's cost per range: its start and
                                                               pilot, b, and its file written and read
                                                               back at D, the rate measured here)
         send   = P * R / B_net + max(0, (k - 1) * P * R / B_net - bake)
                                                              (R = n * 164 B a range: rank 0 takes the
                                                               last wave one after another; the earlier
                                                               ones while the others bake)
         merge  = k * P * n * m_cp                            (rank 0 adds every range at the end)
         out    = m0 + m_pixel * n                            (EXR, PNG, JSON)
    A rank is a node here (one rank per node, c threads): a per-node rank keeps the ranges few."""
    a, b, k_err = pieces["a"], pieces["b"], pieces["K"]
    n, error, cores, bandwidth = args.model_pixels, args.model_error, args.model_cores, args.model_bandwidth
    spp = math.ceil((k_err / error) ** 2)
    range_bytes = n * PARTIAL_BYTES_PER_PIXEL + PARTIAL_FIXED_BYTES
    print(f"\n== model: time to error {error:g} (spp = (K/E)^2 = {spp}) for {n} pixels, {cores} cores per node, "
          f"{bandwidth / 1e9:g} GB/s into rank 0 (measured here: {pieces['transfer'] / 1e9:.2f} GB/s); a range is "
          f"{range_bytes / 1e6:.0f} MB")
    print(f"{'nodes':>6} {'k':>2} {'bake s':>9} {'ranges s':>9} {'send s':>9} {'merge s':>9} {'out s':>6} "
          f"{'total s':>9} {'efficiency':>10}")
    serial = a * n * spp / cores
    for nodes in (10, 100, 1000):
        for per_rank in (1, 2):
            bake = serial / nodes
            ranges = per_rank * (b + range_bytes / pieces["transfer"])
            send = nodes * range_bytes / bandwidth + max(0.0, (per_rank - 1) * nodes * range_bytes / bandwidth - bake)
            merge = per_rank * nodes * n * pieces["m_chunk_pixel"]
            out = pieces["m0"] + pieces["m_pixel"] * n
            total = bake + ranges + send + merge + out
            print(f"{nodes:6d} {per_rank:2d} {bake:9.1f} {ranges:9.2f} {send:9.1f} {merge:9.1f} {out:6.1f} "
                  f"{total:9.1f} {serial / nodes / total:10.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cli", default=os.path.join(os.path.dirname(__file__), "..", "build", "dwivedi"))
    parser.add_argument("--mpirun", default=shutil.which("mpirun") or "mpirun")
    parser.add_argument("--quick", action="store_true", help="smaller runs (a check that the script works)")
    parser.add_argument("--pairs", type=int, default=2, help="alternated 1-rank / 2-rank runs (default 2)")
    parser.add_argument("--speedup-only", action="store_true", help="part 1 only")
    parser.add_argument("--skip-speedup", action="store_true", help="parts 2 to 4 only")
    parser.add_argument("--model-pixels", type=int, default=2048 * 2048)
    parser.add_argument("--model-error", type=float, default=0.001)
    parser.add_argument("--model-cores", type=int, default=32)
    parser.add_argument("--model-bandwidth", type=float, default=10e9, help="bytes per second into rank 0")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="mpi_bench-") as folder:
        bench = Bench(args, folder)
        if not args.skip_speedup:
            bench.speedup()
        if args.speedup_only:
            return
        pieces = bench.sample_cost()
        pieces.update(bench.merge_cost())
        model(pieces, args)


if __name__ == "__main__":
    main()
