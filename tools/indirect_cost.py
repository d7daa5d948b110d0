#!/usr/bin/env python3
"""The cost of indirect light per sample on the benchmark scenes (tools/benchmark_scenes.py):
each scene baked with max_bounces 0 (the one-bounce image) and with light paths on (the
benchmark's own, 4 total / 4 diffuse, and Blender's defaults 12 / 4 / 4 / 12), the same seed,
samples and threads, turn by turn `--repeats` times (each keeps its fastest: other load on the
machine only adds time); prints seconds per sample, their ratio to one bounce, and the image's
mean (how much light the paths add).

    PYTHONPATH=python_shim python3 tools/indirect_cost.py [--size 32] [--samples 16] [--repeats 2]
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
from typing import Sequence

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_scenes  # noqa: E402

import dwivedi  # noqa: E402

SETTINGS = {"one bounce": {"max_bounces": 0},
            "benchmark 4/4/0": dict(benchmark_scenes.LIGHT_PATHS),
            "Blender 12/4/4": {"max_bounces": 12, "diffuse_bounces": 4, "glossy_bounces": 4,
                               "transmission_bounces": 12}}


def main(argv: Sequence[str] = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", type=int, default=32)
    parser.add_argument("--samples", type=int, default=16)
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--scenes", default=",".join(benchmark_scenes.NAMES))
    args = parser.parse_args(argv)
    results = {}
    with tempfile.TemporaryDirectory() as folder:
        for name in [n for n in args.scenes.split(",") if n]:
            path = os.path.join(folder, f"{name}.json")
            with open(path, "w", encoding="utf-8") as f:
                json.dump(benchmark_scenes.scene_json(name, args.size, args.samples), f)
            scene = dwivedi.Scene.load(path)
            row = {}
            for _ in range(args.repeats):
                for label, paths in SETTINGS.items():
                    image = dwivedi.bake(scene, width=args.size, height=args.size, samples=args.samples,
                                         threads=args.threads, seed=3, technique="classical", **paths)
                    seconds = image.stats.seconds / args.samples
                    mean = sum(image.stats.mean_rgb) / 3.0
                    best = row.get(label)
                    row[label] = {"seconds_per_sample": min(seconds, best["seconds_per_sample"]) if best else seconds,
                                  "mean": mean}
            scene.close()
            base = row["one bounce"]
            print(f"{name:12s}" + "".join(
                f"  {label}: {r['seconds_per_sample'] * 1e3:7.2f} ms/spp x{r['seconds_per_sample'] / base['seconds_per_sample']:5.2f}"
                f" mean {r['mean'] / base['mean']:5.3f}x" for label, r in row.items()), flush=True)
            results[name] = row
    print(json.dumps(results, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
