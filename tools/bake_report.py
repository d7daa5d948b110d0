#!/usr/bin/python3
"""Baker report: throughput, thread scaling, memory per triangle and image RMSE against run time
per technique on a scene (the built-in default scene unless one is given).

    /usr/bin/python3 tools/bake_report.py --cli build/dwivedi --out docs [--scene FILE] [--quick]

It runs `dwivedi bench bake --json` once (every figure of one run, so ratios are fair on a shared
machine) and writes into --out: bake_report.md (tables, one PASS/FAIL line for the 1 -> 2 thread
scaling target of the baker issue), bake_report.json (the raw figures) and bake_rmse.png
(relative RMSE against seconds, log-log, per technique, with the 1/sqrt(time) slope for reference).
Needs matplotlib (Debian: python3-matplotlib, which /usr/bin/python3 sees). Exits 1 with a
one-line message if the CLI fails.
"""

import argparse
import datetime
import json
import os
import platform
import subprocess
import sys

COLORS = {"classical": "black", "poe": "tab:blue", "closest": "tab:orange", "incident": "tab:green",
          "backward": "tab:purple", "cycles": "tab:brown", "auto": "tab:red"}
SCALING_TARGET = 1.9
MODES = {
    "full": ["--width", "160", "--height", "90", "--spp", "32", "--reference-spp", "1024", "--max-spp", "64"],
    "quick": ["--width", "32", "--height", "18", "--spp", "2", "--reference-spp", "16", "--max-spp", "4"],
}


def fail(message):
    print(f"bake_report: {message}", file=sys.stderr)
    sys.exit(1)


def run_bench(cli, scene, mode):
    command = [cli, "bench", "bake", *([scene] if scene else []), *MODES[mode], "--json"]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        fail(f"{' '.join(command)} failed: {done.stderr.strip()}")
    try:
        return json.loads(done.stdout)
    except json.JSONDecodeError as error:
        fail(f"bench bake printed no JSON ({error})")


def plot(figures, path):
    import matplotlib
    matplotlib.use("Agg")
    from matplotlib import pyplot
    figure, axes = pyplot.subplots(figsize=(6.4, 4.4))
    for technique, points in figures["rmse"].items():
        seconds = [p["seconds"] for p in points if p["relative_rmse"] is not None]
        rmse = [p["relative_rmse"] for p in points if p["relative_rmse"] is not None]
        axes.loglog(seconds, rmse, "o-", color=COLORS.get(technique), label=technique)
    best = min((p for points in figures["rmse"].values() for p in points if p["relative_rmse"]),
               key=lambda p: p["relative_rmse"])
    ts = [best["seconds"] / 16, best["seconds"]]
    axes.loglog(ts, [best["relative_rmse"] * 4, best["relative_rmse"]], ":", color="grey",
                label="slope 1/sqrt(time)")
    axes.set_xlabel("seconds (2 threads)")
    axes.set_ylabel("relative RMSE against the reference")
    axes.set_title(f"{figures['scene']} scene, {figures['width']} x {figures['height']}")
    axes.grid(True, which="both", alpha=0.3)
    axes.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(path)
    pyplot.close(figure)


def efficiency_at_end(points):
    """1 / (relative RMSE^2 x seconds) of the largest run: higher is better."""
    last = points[-1]
    if not last["relative_rmse"] or not last["seconds"]:
        return None
    return 1.0 / (last["relative_rmse"] ** 2 * last["seconds"])


def write_markdown(path, figures, meta):
    t = figures["throughput"]
    scaling = figures["thread_scaling"]
    lines = [
        "# Baker report", "",
        f"Made by `tools/bake_report.py` ({meta['mode']}) on {meta['date']}, {meta['machine']}: "
        f"`dwivedi bench bake` on the {figures['scene']} scene at {figures['width']} x {figures['height']}.", "",
        "## Throughput and thread scaling", "",
        "| threads | seconds | samples/s | scattering events/s |", "|---|---|---|---|",
    ]
    for row in t:
        lines.append(f"| {row['threads']} | {row['seconds']:.3f} | {row['samples_per_second']:.4g} | "
                     f"{row['events_per_second']:.4g} |")
    verdict = "PASS" if scaling >= SCALING_TARGET else "FAIL"
    lines += ["", f"{verdict}: 1 -> 2 thread speed-up {scaling:.2f}x (target >= {SCALING_TARGET}x). "
              f"Images bit-identical across thread counts: {'yes' if figures['threads_bit_identical'] else 'NO'}.",
              "", "## Memory", "",
              f"{figures['memory']['bytes_per_triangle']:.0f} bytes per triangle: resident memory of a committed "
              f"scene of {figures['memory']['triangles'][1]} triangles minus one of "
              f"{figures['memory']['triangles'][0]} triangles.", "",
              "## Relative RMSE against run time", "",
              f"Against a {figures['reference_spp']} spp reference baked by `auto` with another seed "
              "(its own noise is included, so the curves flatten at its level). Efficiency is "
              "1 / (relative RMSE^2 x seconds) of each technique's largest run. The relative RMSE is "
              "over the R, G and B values of every pixel; the estimated error is the bake's own "
              "estimate from its pixel variances (luminance of the covered pixels, no reference), so "
              "it runs lower where the noise is coloured. `auto` picks per mesh, by a pilot, the "
              "candidate of least variance x cost (docs/bake-engine.md).", "",
              "![relative RMSE against seconds](bake_rmse.png)", "",
              "| technique | spp | seconds | relative RMSE | estimated error | efficiency |",
              "|---|---|---|---|---|---|"]
    for technique, points in figures["rmse"].items():
        last = points[-1]
        eff = efficiency_at_end(points)
        lines.append(f"| {technique} | {last['spp']} | {last['seconds']:.3f} | {last['relative_rmse']:.4g} | "
                     f"{last['estimated_relative_error']:.4g} | {eff:.4g} |" if eff else
                     f"| {technique} | {last['spp']} | {last['seconds']:.3f} | - | - | - |")
    with open(path, "w") as handle:
        handle.write("\n".join(lines) + "\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cli", required=True, help="the dwivedi command")
    parser.add_argument("--out", required=True, help="folder for the report")
    parser.add_argument("--scene", help="a scene file (default: the built-in default scene)")
    parser.add_argument("--quick", action="store_true", help="tiny sizes, for tests")
    args = parser.parse_args()
    mode = "quick" if args.quick else "full"
    os.makedirs(args.out, exist_ok=True)
    figures = run_bench(args.cli, args.scene, mode)
    meta = {"mode": mode, "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
            "machine": f"{platform.machine()}, {os.cpu_count()} cores"}
    with open(os.path.join(args.out, "bake_report.json"), "w") as handle:
        json.dump({"meta": meta, **figures}, handle, indent=1)
    plot(figures, os.path.join(args.out, "bake_rmse.png"))
    write_markdown(os.path.join(args.out, "bake_report.md"), figures, meta)
    print(f"bake_report: wrote bake_report.md, bake_report.json and bake_rmse.png into {args.out}")


if __name__ == "__main__":
    main()
