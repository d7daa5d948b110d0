#!/usr/bin/env python3
"""What technique auto picks on the benchmark scenes (tools/benchmark_scenes.py), and its
efficiency against each fixed technique, without Blender:

    PYTHONPATH=python_shim python3 tools/auto_pick_report.py --size 48 --spp 32 --seeds 4 [--scenes a,b]
        [--scene-files DIR] [--json OUT.json] [--fixed-from EARLIER.json] [--before EARLIER.json]

Every scene is baked (one thread, through the shim) with auto and with each fixed technique the
pilot chooses among (classical, backward, incident, sheet; channel walks shared and separate), at
seeds 1..N. The variance per sample is the mean over pixels and RGB of (a - b)^2 / 2 between the
images of seeds 2k-1 and 2k (independent and unbiased, so that is twice the variance of one
image's pixel), times the samples per pixel; the cost is the CPU time of the bake (the process's,
around Scene.bake on one thread: the pilot and the passes, not the scene's load), averaged over
the seeds, so efficiency = 1 / (variance per sample x seconds per sample). Printed: per scene the features of auto's bakes
(which technique it walked with), each configuration's variance, seconds and efficiency relative
to the best fixed configuration, as a Markdown table; before it a summary, one row per scene: every
configuration's efficiency relative to the best, what auto walked in each seed, its efficiency and ms
per sample (the pilot included), and where it walked one configuration in every seed, its time over
that configuration's forced bake (the pilot's and the extra channel walks' share); with --before,
an earlier run's auto (another library) beside it. The real-asset scenes are Blender-built: their
scene files come from the add-on's farm export of benchmark_scenes.build(NAME) (--scene-files). CPU time moves less with the machine's load
than wall time, but still some (caches and memory shared with other processes).
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "python_shim"))

import benchmark_scenes  # noqa: E402
import dwivedi  # noqa: E402

FIXED = [(t, c) for c in ("shared", "separate") for t in ("classical", "backward", "incident", "sheet")]


def walked(features):
    """The technique a bake's features say it walked with (one subsurface mesh)."""
    names = set(features)
    kind = ("sheet" if "sheet" in names else "mixture" if {"incident_patches", "closest_point"} <= names
            else "incident" if "incident_patches" in names
            else "closest" if "closest_point" in names else "backward" if "guided" in names else "classical")
    return kind + (" separate" if "channel_walks" in names else " shared")


def measure(scene, base, technique, channel_walks, seeds):
    images, seconds, features = [], 0.0, []
    for seed in range(1, seeds + 1):
        settings = dataclasses.replace(base, technique=technique, channel_walks=channel_walks, seed=seed, threads=1,
                                       time_limit=0.0, target_error=0.0)
        start = time.process_time()
        image = scene.bake(settings)
        seconds += time.process_time() - start
        try:
            rgba = image.pixels()
            images.append([v for i, v in enumerate(rgba) if i % 4 != 3])
            features.append(walked(image.stats.features))
        finally:
            image.close()
    pairs = [(images[k], images[k + 1]) for k in range(0, len(images) - 1, 2)]
    variance = sum(sum((a - b) ** 2 for a, b in zip(x, y)) / (2.0 * len(x)) for x, y in pairs) / len(pairs)
    return variance * base.samples, seconds / seeds / base.samples, features


def efficiency(figure):
    return 1.0 / (figure["variance_per_sample"] * figure["seconds_per_sample"])


def summary(figures, before=None):
    """One row per scene: every fixed configuration's efficiency relative to the best one, what auto
    walked (per seed), its efficiency and ms per sample (pilot included), and where it walked one
    configuration in every seed, its time over that configuration's forced bake's (what the pilot
    and the channel-walk counts it gave cost on top); with `before`, the same of an earlier run's auto."""
    keys = [f"{t} {c}" for t, c in FIXED]
    head = ["scene"] + [k.replace(" shared", " sh").replace(" separate", " sep") for k in keys]
    head += ["auto walked (seeds)", "auto eff.", "auto ms/spp", "auto time / pick's"]
    if before:
        head += ["before: walked", "before: eff.", "before: ms/spp", "before: time / pick's"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]

    def auto_cells(scene, figure):
        fixed = {k: v for k, v in scene.items() if k != "auto"}
        best = max(efficiency(v) for v in fixed.values())
        walked_seeds = figure["walked"]
        picks = sorted(set(walked_seeds))
        pick = picks[0] if len(picks) == 1 and picks[0] in fixed else None
        ratio = f"{figure['seconds_per_sample'] / fixed[pick]['seconds_per_sample']:.2f}" if pick else "-"
        return [", ".join(walked_seeds), f"{efficiency(figure) / best:.2f}", f"{1e3 * figure['seconds_per_sample']:.3g}",
                ratio]

    for name, scene in figures.items():
        fixed = {k: v for k, v in scene.items() if k != "auto"}
        best = max(efficiency(v) for v in fixed.values())
        cells = [name] + [f"{efficiency(fixed[k]) / best:.2f}" if k in fixed else "-" for k in keys]
        cells += auto_cells(scene, scene["auto"])
        if before and name in before:
            cells += auto_cells({**fixed, "auto": before[name]["auto"]}, before[name]["auto"])
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=48)
    parser.add_argument("--spp", type=int, default=32)
    parser.add_argument("--seeds", type=int, default=4, help="an even number: seed pairs (1, 2), (3, 4), ...")
    parser.add_argument("--scenes", default=",".join(n for n in benchmark_scenes.NAMES if n in benchmark_scenes.SCENES),
                        help="comma-separated (default: the set but its real-asset scenes, which need --scene-files)")
    parser.add_argument("--scene-files", type=Path, metavar="DIR",
                        help="scenes not made by benchmark_scenes.scene_json (the real-asset ones) come from "
                             "DIR/NAME/dwivedi_scene.json: the add-on's farm export of benchmark_scenes.build(NAME)")
    parser.add_argument("--json", type=Path, help="also write the figures here")
    parser.add_argument("--fixed-from", type=Path, metavar="JSON",
                        help="take the fixed techniques' figures from an earlier run's --json (bake auto only)")
    parser.add_argument("--before", type=Path, metavar="JSON",
                        help="an earlier run's --json (another library): its auto beside this one's in the summary")
    args = parser.parse_args(argv)
    if args.seeds < 2 or args.seeds % 2:
        parser.error("--seeds must be even and at least 2")
    rows, figures = [], {}
    with tempfile.TemporaryDirectory() as folder:
        for name in args.scenes.split(","):
            if name in benchmark_scenes.SCENES:
                path = Path(folder) / f"{name}.json"
                path.write_text(json.dumps(benchmark_scenes.scene_json(name, args.size, args.spp)))
            elif args.scene_files:
                path = args.scene_files / name / "dwivedi_scene.json"
            else:
                parser.error(f"{name}: no scene file made without Blender (give --scene-files)")
            scene = dwivedi.Scene.load(str(path))
            try:
                base = dataclasses.replace(scene.settings, width=args.size, height=args.size, samples=args.spp)
                if args.fixed_from:
                    earlier = json.loads(args.fixed_from.read_text())[name]
                    found = {key: (f["variance_per_sample"], f["seconds_per_sample"], f["walked"])
                             for key, f in earlier.items() if key != "auto"}
                else:
                    found = {f"{t} {c}": measure(scene, base, t, c, args.seeds) for t, c in FIXED}
                found["auto"] = measure(scene, base, "auto", "auto", args.seeds)
            finally:
                scene.close()
            best = max((1.0 / (v * s), key) for key, (v, s, _) in found.items() if key != "auto")
            figures[name] = {key: {"variance_per_sample": v, "seconds_per_sample": s, "walked": f}
                             for key, (v, s, f) in found.items()}
            for key, (v, s, f) in found.items():
                rows.append(f"| {name} | {key} | {', '.join(sorted(set(f)))} | {v:.4g} | {1e3 * s:.3g} | "
                            f"{1.0 / (v * s) / best[0]:.2f} |")
            print(f"{name}: best fixed {best[1]}; auto walked {', '.join(found['auto'][2])} (seeds 1-{args.seeds}), efficiency "
                  f"{1.0 / (found['auto'][0] * found['auto'][1]) / best[0]:.2f} of it", flush=True)
            if args.json:  # after every scene, so that a long run keeps what it measured
                args.json.write_text(json.dumps(figures, indent=1))
    print(summary(figures, json.loads(args.before.read_text()) if args.before else None))
    print("\n| scene | configuration | walked | variance per sample | ms per sample | efficiency / best fixed |")
    print("|---|---|---|---|---|---|")
    print("\n".join(rows))
    if args.json:
        args.json.write_text(json.dumps(figures, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
