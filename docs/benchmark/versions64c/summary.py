#!/usr/bin/env python3
"""The tables of docs/speed.md's "Third run against the Cycles of 3.4, 4.3 and 5.2" from this
folder's reports and the second run's (../versions64b): python3 docs/benchmark/versions64c/summary.py

Per scene and Blender, as ../versions64b/summary.py: the speed-up at equal RMSE (the report's,
whole operator against whole operator), the variance per sample Cycles / dwivedi at 32 and 128 spp
(noise only, as the report's equal-samples table), the time per sample Cycles / dwivedi at 128 spp
(whole operator; in brackets the renderers' own parts), the largest per-channel difference of the
two converged images' means (dwivedi against Cycles) and the RMSE between them. Then the table of
docs/speed.md (speed-up second run -> this run per Blender, variance and time per sample at
128 spp), the scenes whose converged means differ by more than 2% in a channel, and issue 20's
target per scene and Blender: 5x at equal RMSE and at least as fast per sample (time ratio >= 1);
where it is missed, which of the two factors of the speed-up (variance per sample x time per
sample = speed-up at equal RMSE, roughly) falls short of the 5x that a time ratio of 1 would need."""
import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2] / "tools"))
sys.path.insert(0, str(HERE.parents[2] / "python_shim"))
from cycles_report import noise_only  # noqa: E402

FOLDERS = ("host", "host_assets", "trixie", "trixie_assets", "sid", "sid_assets")
WHERE = ("host", "trixie", "sid")
TARGET = 5.0
MEANS_LIMIT = 0.02


def rows(folder: Path):
    """(scene, where, Blender, figures) of one report folder; nothing if it has no report.json."""
    if not (folder / "report.json").is_file():
        return
    data = json.loads((folder / "report.json").read_text())
    for where, run in data.get("cycles", {}).items():
        for name, entry in run["scenes"].items():
            theirs = {p["samples"]: p for p in noise_only(entry["cycles"], entry["reference_samples"])}
            ours = {p["samples"]: p for p in noise_only(entry["dwivedi"], entry["dwivedi_reference_samples"])}
            speed = entry["speedup_at_rmse"]
            means = [d / c - 1.0 for c, d in zip(entry["cycles_reference_mean_rgb"], entry["dwivedi_reference_mean_rgb"])]
            yield name, where, run["blender"], {
                "speedup": speed["cycles_seconds"] / speed["dwivedi_seconds"],
                "v32": (theirs[32]["rmse"] / ours[32]["rmse"]) ** 2,
                "v128": (theirs[128]["rmse"] / ours[128]["rmse"]) ** 2,
                "time": theirs[128]["seconds"] / ours[128]["seconds"],
                # Cycles' own part is its render less its 1-sample render (the scene sync), floored
                # at 1 ms by the report: where that floor is hit the 1-sample render took longer
                # than the 128-sample one (head_asset: the first render loads the images), no ratio.
                "own": (theirs[128]["own_seconds"] / ours[128]["own_seconds"]
                        if theirs[128]["own_seconds"] > 1e-3 else None),
                "mean": max(means, key=abs), "converged": entry["converged_rmse"]}


def collect(base: Path):
    """{scene: {where: (Blender, figures)}} in the order the scenes first appear."""
    table = {}
    for folder in FOLDERS:
        for name, where, blender, figures in rows(base / folder):
            table.setdefault(name, {})[where] = (blender, figures)
    return table


def three(per_where, key, form):
    return " / ".join(form(per_where[w][1][key]) if w in per_where else "-" for w in WHERE)


def speed(value):
    return f"{value:.2f}x" if value < 10 else f"{value:.1f}x"


def ratio(value):
    return f"{value:.2g}" if value < 10 else f"{value:.0f}"


def main():
    now, before = collect(HERE), collect(HERE.parent / "versions64b")
    missing = [f for f in FOLDERS if not (HERE / f / "report.json").is_file()]
    print("## Every figure\n")
    print("| scene | Blender | speed-up at equal RMSE | variance per sample, Cycles / dwivedi, 32 / 128 spp | "
          "time per sample, Cycles / dwivedi, 128 spp (own parts) | converged means, largest channel difference | "
          "RMSE between converged |")
    print("|---|---|---|---|---|---|---|")
    for where in WHERE:
        for name, per_where in now.items():
            if where in per_where:
                blender, f = per_where[where]
                print(f"| {name} | {blender} | {f['speedup']:.2f}x | {f['v32']:.3g} / {f['v128']:.3g} | "
                      f"{f['time']:.2f} ({'-' if f['own'] is None else format(f['own'], '.2f')}) | {100 * f['mean']:+.1f}% | {f['converged']:.3g} |")
    if missing:
        print(f"\nNo report (not finished): {', '.join(missing)}")
    print("\n## docs/speed.md's table\n")
    print("| scene | speed-up before (bench18) 3.4 / 4.3 / 5.2 | speed-up now 3.4 / 4.3 / 5.2 | variance per sample "
          "Cycles / dwivedi at 128 spp, 3.4 / 4.3 / 5.2 | time per sample Cycles / dwivedi at 128 spp (whole "
          "operator), 3.4 / 4.3 / 5.2 |")
    print("|---|---|---|---|---|")
    for name, per_where in now.items():
        print(f"| {name} | {three(before.get(name, {}), 'speedup', speed)} | {three(per_where, 'speedup', speed)} | "
              f"{three(per_where, 'v128', ratio)} | {three(per_where, 'time', lambda v: f'{v:.2f}')} |")
    print(f"\n## Converged means differing by more than {100 * MEANS_LIMIT:.0f}% in a channel\n")
    for name, per_where in now.items():
        for where, (blender, f) in per_where.items():
            if abs(f["mean"]) > MEANS_LIMIT:
                print(f"- {name} on {blender}: {100 * f['mean']:+.1f}% (RMSE between converged {f['converged']:.3g})")
    print(f"\n## Issue 20's target: {TARGET:g}x at equal RMSE and time per sample >= 1\n")
    for name, per_where in now.items():
        verdicts = []
        for where in WHERE:
            if where not in per_where:
                continue
            blender, f = per_where[where]
            short = []
            if f["v128"] < TARGET:
                short.append(f"variance {f['v128']:.2g}")
            if f["time"] < 1.0:
                short.append(f"time {f['time']:.2f}")
            verdict = "meets" if f["speedup"] >= TARGET and f["time"] >= 1.0 else "short: " + ", ".join(short or
                                                                                                       ["(one round's noise)"])
            verdicts.append(f"{blender.split()[0]} {speed(f['speedup'])} {verdict}")
        print(f"- {name}: " + "; ".join(verdicts))


if __name__ == "__main__":
    main()
