#!/usr/bin/env python3
"""Scattering events per second of `dwivedi estimate`, two builds compared in one run.

The machine these figures come from is shared, so wall-clock times move with other work. This
runs the two builds alternately (A, B, A, B, ...), keeps the best (least disturbed) run of each,
and prints their ratio beside the load average before and after. Each run is one
`dwivedi estimate --json`; events per second = events / seconds (wall clock, all threads). The
CPU time of the run (user + system, all threads) per event is printed too: other programs that
hold the cores inflate it much less than the wall clock.

    tools/walk_throughput.py --a OLD/dwivedi --b build/dwivedi --albedo 0.99 --rounds 6

`--technique all` runs every technique of the estimator in turn (each with its A and B runs
alternating) and ends with a table of CPU nanoseconds per event per core (CPU time of all
threads / events) and wall nanoseconds per event, one row per technique; without --a only B runs.

A build directory's `dwivedi` finds its own libdwivedi through its RUNPATH; --a-lib DIR puts DIR
first on LD_LIBRARY_PATH for build A (a copy of an older build, say)."""
import argparse
import json
import os
import resource
import subprocess
import sys

TECHNIQUES = ("classical", "poe", "closest", "incident", "backward", "cycles", "sheet", "auto")


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
    p.add_argument("--a", default="", help="the first dwivedi executable (the old build); none: B alone")
    p.add_argument("--a-lib", default="", help="directory put first on LD_LIBRARY_PATH for --a")
    p.add_argument("--b", required=True, help="the second dwivedi executable (the new build)")
    p.add_argument("--scene", default="halfspace")
    p.add_argument("--albedo", default="0.99")
    p.add_argument("--technique", default="poe", help="a technique, or `all` (every one, a table at the end)")
    p.add_argument("--walks", default="1500000")
    p.add_argument("--threads", default="2")
    p.add_argument("--rounds", type=int, default=6)
    o, extra = p.parse_known_args()  # any other option goes to `dwivedi estimate` (--thickness, --light, ...)
    if o.rounds < 1:
        sys.exit("walk_throughput.py: --rounds must be at least 1")
    techniques = TECHNIQUES if o.technique == "all" else (o.technique,)
    builds = ((("a", o.a, o.a_lib),) if o.a else ()) + (("b", o.b, ""),)
    table = []
    for technique in techniques:
        args = ["--scene", o.scene, "--albedo", o.albedo, "--technique", technique, "--walks", o.walks,
                "--threads", o.threads, *extra]
        table.append((technique, compare(o, builds, args)))
    if len(techniques) > 1:
        names = [k.upper() for k, _, _ in builds]
        print(f"ns per scattering event, best of {o.rounds}: CPU time of all threads / events (per core), "
              f"wall time / events on {o.threads} thread(s)")
        print("| technique | " + " | ".join(f"{n} CPU per core | {n} wall" for n in names) + " |")
        print("|---|" + "---|---|" * len(names))
        for technique, best in table:
            cells = " | ".join(f"{1e9 / best[k][1]:.1f} | {1e9 / best[k][0]:.1f}" for k, _, _ in builds)
            print(f"| {technique} | {cells} |")


def compare(o, builds, args):
    """Runs the builds alternately for o.rounds rounds, prints their best rates; returns
    {build: (best events per wall second, best events per CPU second)}."""
    load_before = loadavg()
    rates = {k: [] for k, _, _ in builds}
    cpu_rates = {k: [] for k, _, _ in builds}
    means = {}
    for _ in range(o.rounds):
        for name, cli, lib in builds:
            rate, cpu_rate, mean = run(cli, lib, args)
            rates[name].append(rate)
            cpu_rates[name].append(cpu_rate)
            means[name] = mean
    load_after = loadavg()
    best = {k: max(v) for k, v in rates.items()}
    best_cpu = {k: max(v) for k, v in cpu_rates.items()}
    print(f"{' '.join(args)}, {o.rounds} rounds" + (", A and B alternately" if len(builds) > 1 else ""))
    for k, label, _ in builds:
        r = sorted(rates[k], reverse=True)
        print(f"  {k.upper()} {label}: best {best[k] / 1e6:.1f} M events/s ({1e9 / best[k]:.1f} ns per event), "
              f"all {', '.join(f'{x / 1e6:.1f}' for x in r)}; CPU time (all threads) "
              f"{1e9 / best_cpu[k]:.1f} ns per event at best; mean {means[k]:.10g}")
    if len(builds) > 1:
        print(f"  B / A (best of each): {best['b'] / best['a']:.2f} by the wall clock, "
              f"{best_cpu['b'] / best_cpu['a']:.2f} by CPU time")
    print(f"  load average (1, 5, 15 min) before: {load_before}; after: {load_after}")
    return {k: (best[k], best_cpu[k]) for k in best}


if __name__ == "__main__":
    main()
