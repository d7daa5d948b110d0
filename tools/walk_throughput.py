#!/usr/bin/env python3
"""Scattering events per second of `dwivedi estimate`, two builds compared in one run.

The machine these figures come from is shared, so wall-clock times move with other work. This
runs the two builds alternately (A, B, A, B, ...), keeps the best (least disturbed) run of each,
and prints their ratio beside the load average before and after. Each run is one
`dwivedi estimate --json`; events per second = events / seconds (wall clock, all threads). The
CPU time of the run (user + system, all threads) per event is printed too: other programs that
hold the cores inflate it much less than the wall clock.

    tools/walk_throughput.py --a OLD/dwivedi --b build/dwivedi --albedo 0.99 --rounds 6

A build directory's `dwivedi` finds its own libdwivedi through its RUNPATH; --a-lib DIR puts DIR
first on LD_LIBRARY_PATH for build A (a copy of an older build, say)."""
import argparse
import json
import os
import resource
import subprocess
import sys


def run(cli, lib, args):
    env = dict(os.environ)
    if lib:
        env["LD_LIBRARY_PATH"] = lib + (":" + env["LD_LIBRARY_PATH"] if env.get("LD_LIBRARY_PATH") else "")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = subprocess.run([cli, "estimate", *args, "--json"], env=env, check=True, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    result = json.loads(out.stdout)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return result["events"] / result["seconds"], result["events"] / cpu, result["mean"]


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
    o, extra = p.parse_known_args()  # any other option goes to `dwivedi estimate` (--thickness, --light, ...)
    if o.rounds < 1:
        sys.exit("walk_throughput.py: --rounds must be at least 1")
    args = ["--scene", o.scene, "--albedo", o.albedo, "--technique", o.technique, "--walks", o.walks,
            "--threads", o.threads, *extra]
    load_before = loadavg()
    rates = {"a": [], "b": []}
    cpu_rates = {"a": [], "b": []}
    means = {}
    for _ in range(o.rounds):
        for name, cli, lib in (("a", o.a, o.a_lib), ("b", o.b, "")):
            rate, cpu_rate, mean = run(cli, lib, args)
            rates[name].append(rate)
            cpu_rates[name].append(cpu_rate)
            means[name] = mean
    load_after = loadavg()
    best = {k: max(v) for k, v in rates.items()}
    best_cpu = {k: max(v) for k, v in cpu_rates.items()}
    print(f"{' '.join(args)}, {o.rounds} rounds, A and B alternately")
    for k, label in (("a", o.a), ("b", o.b)):
        r = sorted(rates[k], reverse=True)
        print(f"  {k.upper()} {label}: best {best[k] / 1e6:.1f} M events/s ({1e9 / best[k]:.1f} ns per event), "
              f"all {', '.join(f'{x / 1e6:.1f}' for x in r)}; CPU time (all threads) "
              f"{1e9 / best_cpu[k]:.1f} ns per event at best; mean {means[k]:.10g}")
    print(f"  B / A (best of each): {best['b'] / best['a']:.2f} by the wall clock, "
          f"{best_cpu['b'] / best_cpu['a']:.2f} by CPU time")
    print(f"  load average (1, 5, 15 min) before: {load_before}; after: {load_after}")


if __name__ == "__main__":
    main()
