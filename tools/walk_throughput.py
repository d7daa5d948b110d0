#!/usr/bin/env python3
"""Scattering events per second of `dwivedi estimate`, two builds compared in one run.

The machine these figures come from is shared, so wall-clock times move with other work. This
runs the two builds alternately (A, B, A, B, ...), keeps the best (least disturbed) run of each,
and prints their ratio beside the load average before and after. Each run is one
`dwivedi estimate --json`; events per second = events / seconds (wall clock, all threads).

    tools/walk_throughput.py --a OLD/dwivedi --b build/dwivedi --albedo 0.99 --rounds 6

A build directory's `dwivedi` finds its own libdwivedi through its RUNPATH; --a-lib DIR puts DIR
first on LD_LIBRARY_PATH for build A (a copy of an older build, say)."""
import argparse
import json
import os
import subprocess
import sys


def run(cli, lib, args):
    env = dict(os.environ)
    if lib:
        env["LD_LIBRARY_PATH"] = lib + (":" + env["LD_LIBRARY_PATH"] if env.get("LD_LIBRARY_PATH") else "")
    out = subprocess.run([cli, "estimate", *args, "--json"], env=env, check=True, capture_output=True, text=True)
    result = json.loads(out.stdout)
    return result["events"] / result["seconds"], result["mean"]


def loadavg():
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--a", required=True, help="the first dwivedi executable (the old build)")
    p.add_argument("--a-lib", default="", help="directory put first on LD_LIBRARY_PATH for --a")
    p.add_argument("--b", required=True, help="the second dwivedi executable (the new build)")
    p.add_argument("--scene", default="halfspace")
    p.add_argument("--albedo", default="0.99")
    p.add_argument("--technique", default="poe")
    p.add_argument("--walks", default="1500000")
    p.add_argument("--threads", default="2")
    p.add_argument("--rounds", type=int, default=6)
    o = p.parse_args()
    if o.rounds < 1:
        sys.exit("walk_throughput.py: --rounds must be at least 1")
    args = ["--scene", o.scene, "--albedo", o.albedo, "--technique", o.technique, "--walks", o.walks,
            "--threads", o.threads]
    load_before = loadavg()
    rates = {"a": [], "b": []}
    means = {}
    for _ in range(o.rounds):
        for name, cli, lib in (("a", o.a, o.a_lib), ("b", o.b, "")):
            rate, mean = run(cli, lib, args)
            rates[name].append(rate)
            means[name] = mean
    load_after = loadavg()
    best = {k: max(v) for k, v in rates.items()}
    print(f"{' '.join(args)}, {o.rounds} rounds, A and B alternately")
    for k, label in (("a", o.a), ("b", o.b)):
        r = sorted(rates[k], reverse=True)
        print(f"  {k.upper()} {label}: best {best[k] / 1e6:.1f} M events/s ({1e9 / best[k]:.1f} ns per event), "
              f"all {', '.join(f'{x / 1e6:.1f}' for x in r)}; mean {means[k]:.10g}")
    print(f"  B / A (best of each): {best['b'] / best['a']:.2f}")
    print(f"  load average (1, 5, 15 min) before: {load_before}; after: {load_after}")


if __name__ == "__main__":
    main()
