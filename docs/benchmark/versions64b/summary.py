#!/usr/bin/env python3
"""The table of docs/speed.md's "Benchmark set against the Cycles of 3.4, 4.3 and 5.2, second run"
from this folder's reports: python3 docs/benchmark/versions64b/summary.py [FOLDER ...]
(default: host, host_assets, trixie, trixie_assets, sid, sid_assets beside this file).

Per scene and Blender: the speed-up at equal RMSE (the report's, whole operator against whole
operator), the variance per sample Cycles / dwivedi at 32 and 128 spp (noise only, as the report's
equal-samples table), the time per sample Cycles / dwivedi at 128 spp (whole operator; in brackets
the renderers' own parts), and the largest per-channel difference of the two converged images'
means (dwivedi against Cycles)."""
import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2] / "tools"))
sys.path.insert(0, str(HERE.parents[2] / "python_shim"))
from cycles_report import noise_only  # noqa: E402


def rows(folder: Path):
    data = json.loads((folder / "report.json").read_text())
    for where, run in data.get("cycles", {}).items():
        for name, entry in run["scenes"].items():
            theirs = {p["samples"]: p for p in noise_only(entry["cycles"], entry["reference_samples"])}
            ours = {p["samples"]: p for p in noise_only(entry["dwivedi"], entry["dwivedi_reference_samples"])}
            speed = entry["speedup_at_rmse"]
            ratio = speed["cycles_seconds"] / speed["dwivedi_seconds"]
            variance = {n: (theirs[n]["rmse"] / ours[n]["rmse"]) ** 2 for n in (32, 128)}
            per_sample = theirs[128]["seconds"] / ours[128]["seconds"]
            own = theirs[128]["own_seconds"] / ours[128]["own_seconds"]
            means = [d / c - 1.0 for c, d in zip(entry["cycles_reference_mean_rgb"], entry["dwivedi_reference_mean_rgb"])]
            yield (name, run["blender"], ratio, variance[32], variance[128], per_sample, own, max(means, key=abs),
                   entry["converged_rmse"])


def main(argv):
    folders = [Path(a) for a in argv] or [HERE / n for n in ("host", "host_assets", "trixie", "trixie_assets", "sid",
                                                             "sid_assets")]
    print("| scene | Blender | speed-up at equal RMSE | variance per sample, Cycles / dwivedi, 32 / 128 spp | "
          "time per sample, Cycles / dwivedi, 128 spp (own parts) | converged means, largest channel difference | "
          "RMSE between converged |")
    print("|---|---|---|---|---|---|---|")
    for folder in folders:
        if not (folder / "report.json").is_file():
            print(f"| ({folder.name}: no report) | | | | | | |")
            continue
        for name, blender, ratio, v32, v128, per_sample, own, mean, converged in rows(folder):
            print(f"| {name} | {blender} | {ratio:.2f}x | {v32:.3g} / {v128:.3g} | {per_sample:.2f} ({own:.2f}) | "
                  f"{100 * mean:+.1f}% | {converged:.3g} |")


if __name__ == "__main__":
    main(sys.argv[1:])
