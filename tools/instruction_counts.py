#!/usr/bin/env python3
"""Instructions per walk and per sample, counted by callgrind, for changes that must not slow the walks.

Runs `dwivedi estimate` on the walk report's cases (tools/walk_report.py CASES) with each of its
techniques, and `dwivedi bake` on the default scene and the example scenes, one thread each,
under `valgrind --tool=callgrind`, and prints the whole process's instructions per walk (estimate)
or per sample (bake). Instruction counts are repeatable for the same binary and inputs whatever
else the machine does, so a before/after pair can be compared line by line:

    python3 tools/instruction_counts.py --cli build/dwivedi > before.txt
    ... change, rebuild ...
    python3 tools/instruction_counts.py --cli build/dwivedi --compare before.txt

With --compare it prints each case's change and exits 1 when one got slower by more than
--tolerance percent (default 2); speed-ups pass. Start-up (loading the library, writing the outputs) is in every count; the
cases run enough walks that it is a small, equal part of before and after.
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

SOURCE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(SOURCE, "tools"))
from walk_report import CASES  # noqa: E402

ESTIMATE_TECHNIQUES = ("classical", "poe", "closest", "incident", "backward", "cycles", "sheet", "auto")
WALKS = 20000
BAKE_SPP = 8


def callgrind_instructions(command):
    with tempfile.TemporaryDirectory() as work:
        out = os.path.join(work, "callgrind.out")
        subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=" + out] + command, check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=work)
        with open(out) as f:
            for line in f:
                match = re.match(r"(?:summary|totals): (\d+)", line)
                if match:
                    return int(match.group(1))
    raise RuntimeError("callgrind wrote no total for " + " ".join(command))


def cases(cli):
    for case in CASES:
        for technique in ESTIMATE_TECHNIQUES:
            command = [cli, "estimate"] + case.arguments() + ["--technique", technique, "--walks", str(WALKS),
                                                              "--seed", "3", "--threads", "1", "--json"]
            yield f"estimate {case.name} {technique}", command, WALKS
    scenes = [("default", [])]
    folder = os.path.join(SOURCE, "examples", "scenes")
    scenes += [(name[:-5], [os.path.join(folder, name)]) for name in sorted(os.listdir(folder)) if name.endswith(".json")]
    for name, scene in scenes:
        width, height = 48, 32
        command = [cli, "bake"] + scene + ["--out", "out", "--spp", str(BAKE_SPP), "--threads", "1", "--seed", "1",
                                           "--width", str(width), "--height", str(height), "--quiet"]
        yield f"bake {name} auto", command, width * height * BAKE_SPP


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cli", required=True, help="the dwivedi command")
    parser.add_argument("--compare", help="a file this tool printed before: report the change per case")
    parser.add_argument("--tolerance", type=float, default=2.0, help="percent (default 2)")
    args = parser.parse_args()
    cli = os.path.abspath(args.cli)
    before = {}
    if args.compare:
        with open(args.compare) as f:
            for line in f:
                name, _, value = line.rstrip("\n").rpartition(" ")
                before[name] = float(value)
    worst = 0.0  # the largest slowdown, percent
    for name, command, units in cases(cli):
        per_unit = callgrind_instructions(command) / units
        if name in before:
            change = 100.0 * (per_unit / before[name] - 1.0)
            worst = max(worst, change)
            print(f"{name} {before[name]:.1f} -> {per_unit:.1f} ({change:+.2f}%)", flush=True)
        else:
            print(f"{name} {per_unit:.1f}", flush=True)
    if args.compare:
        print(f"largest slowdown {worst:+.2f}% (tolerance {args.tolerance}%)")
        return 1 if worst > args.tolerance else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
