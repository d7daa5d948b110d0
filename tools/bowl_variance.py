#!/usr/bin/env python3
"""Where the benchmark bowl's variance lives (tools/benchmark_scenes.py "bowl", issue 20 item 2):
for each technique, its bakes at seeds 1-4 with the DiffDir / DiffInd / DiffCol passes, and

- the variance per sample of the combined image, of its direct part (the walks' exits' and the
  surface's next-event estimates, DiffDir x DiffCol) and of its indirect part (the paths after
  the exits and the surface, DiffInd x DiffCol; the specular layer's glossy light, under 1% of the
  bowl's, is in the combined image only), per region of the image (inside the bowl, its
  outside, the rim; the background left out): the mean over pixels and RGB of (a - b)^2 / 2
  between seeds 1 and 2 and between 3 and 4, times the samples per pixel (unbiased estimators
  with independent seeds: no reference needed);
- the bake's time per sample and its counts (walks, events, path rays per sample), and with
  max_bounces 0 (no path after the first scattering) for the paths' share of the time;
- with --single K: K bakes of one sample per pixel (each pixel value one sample), for the
  distribution of one sample's value (its mean over RGB): the share of zero samples, quantiles,
  and the share of the sum of squares the largest 1% carry (a heavy tail).

    PYTHONPATH=python_shim python3 tools/bowl_variance.py [--size 32] [--samples 32] \
        [--techniques incident:shared,auto:auto] [--single 8]
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
from typing import Dict, List, Sequence, Tuple

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_scenes  # noqa: E402

import dwivedi  # noqa: E402

# The bowl's shell (benchmark_scenes.bowl(0.15, 0.015)): the points within half the wall of an
# arc of radius 0.1425 about the origin, from the bottom up to the opening at z = 0.
ARC, HALF_WALL = 0.1425, 0.0075


def shell_distance(p: Tuple[float, float, float]) -> float:
    """Signed distance to the shell: to the arc (its lower quarter, or its end at z = 0) less half the wall."""
    r, z = math.hypot(p[0], p[1]), p[2]
    to_arc = abs(math.hypot(r, z) - ARC) if z <= 0.0 else math.hypot(r - ARC, z)
    return to_arc - HALF_WALL


def regions(size: int) -> List[str]:
    """Per pixel (rows from the top) what the camera sees there: inside, outside, rim or background
    (sphere tracing of shell_distance along the pixel centre's ray; the scene file's camera)."""
    eye, target = benchmark_scenes.SCENES["bowl"]["camera"]
    forward = [t - e for t, e in zip(target, eye)]
    norm = math.sqrt(sum(c * c for c in forward))
    forward = [c / norm for c in forward]
    right = [forward[1], -forward[0], 0.0]  # forward x up (z)
    norm = math.sqrt(sum(c * c for c in right))
    right = [c / norm for c in right]
    up = [right[1] * forward[2] - right[2] * forward[1], right[2] * forward[0] - right[0] * forward[2],
          right[0] * forward[1] - right[1] * forward[0]]
    half = 18.0 / 50.0  # sensor width 36 mm, focal length 50 mm
    out = []
    for i in range(size):
        for j in range(size):
            sx, sy = ((j + 0.5) / size * 2.0 - 1.0) * half, (1.0 - (i + 0.5) / size * 2.0) * half
            d = [f + sx * a + sy * b for f, a, b in zip(forward, right, up)]
            norm = math.sqrt(sum(c * c for c in d))
            d = [c / norm for c in d]
            t, kind = 0.0, "background"
            for _ in range(400):
                p = tuple(e + t * c for e, c in zip(eye, d))
                step = shell_distance(p)
                if step < 1e-6:
                    r2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2]
                    kind = "rim" if p[2] > -0.01 else ("outside" if r2 > ARC * ARC else "inside")
                    break
                t += step
                if t > 2.0:
                    break
            out.append(kind)
    return out


def rgb_of(image) -> List[float]:
    """An image's RGB values (its alpha left out), pixel by pixel."""
    return [v for k, v in enumerate(image.pixels()) if k % 4 != 3]


def bake(scene, size: int, samples: int, seed: int, technique: str, walks: str, paths: Dict) -> Dict:
    image = dwivedi.bake(scene, width=size, height=size, samples=samples, threads=2, seed=seed, technique=technique,
                         channel_walks=walks, passes=("DiffDir", "DiffInd", "DiffCol"), **paths)
    color = rgb_of(image.pass_image("DiffCol"))
    direct = [v * c for v, c in zip(rgb_of(image.pass_image("DiffDir")), color)]
    indirect = [v * c for v, c in zip(rgb_of(image.pass_image("DiffInd")), color)]
    s = image.stats
    return {"combined": rgb_of(image), "color": color, "direct": direct, "indirect": indirect, "seconds": s.seconds,
            "walks": s.walks, "events": s.events, "path_rays": s.path_rays, "samples": s.samples}


def variance_per_sample(images: List[Dict], part: str, kinds: List[str], region: str, samples: int) -> float:
    total, count = 0.0, 0
    for a, b in ((images[0], images[1]), (images[2], images[3])):
        for k, (x, y) in enumerate(zip(a[part], b[part])):
            if kinds[k // 3] == region or (region == "all" and kinds[k // 3] != "background"):
                total += (x - y) ** 2 / 2.0
                count += 1
    return total / max(count, 1) * samples


def mean_of(images: List[Dict], part: str, kinds: List[str], region: str) -> float:
    values = [v for image in images for k, v in enumerate(image[part])
              if kinds[k // 3] == region or (region == "all" and kinds[k // 3] != "background")]
    return sum(values) / max(len(values), 1)


def tail(values: List[float]) -> Dict:
    ordered = sorted(values)
    n = len(ordered)
    squares = sum(v * v for v in ordered)
    top = ordered[n - max(n // 100, 1):]
    mean = sum(ordered) / n
    return {"zero": sum(1 for v in ordered if v == 0.0) / n, "mean": mean,
            "q50": ordered[n // 2], "q90": ordered[int(0.9 * n)], "q99": ordered[int(0.99 * n)], "max": ordered[-1],
            "top1_square_share": sum(v * v for v in top) / squares if squares > 0 else 0.0,
            "max_over_mean": ordered[-1] / mean if mean > 0 else 0.0}


def main(argv: Sequence[str] = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", type=int, default=32)
    parser.add_argument("--samples", type=int, default=32)
    parser.add_argument("--techniques", default="incident:shared",
                        help="technique:channel_walks pairs, comma-separated")
    parser.add_argument("--single", type=int, default=0, help="bakes of one sample per pixel for the distribution")
    args = parser.parse_args(argv)
    kinds = regions(args.size)
    results = {}
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "bowl.json")
        with open(path, "w", encoding="utf-8") as f:
            json.dump(benchmark_scenes.scene_json("bowl", args.size, args.samples), f)
        scene = dwivedi.Scene.load(path)
        for pair in args.techniques.split(","):
            technique, walks = pair.split(":")
            images = [bake(scene, args.size, args.samples, seed, technique, walks, benchmark_scenes.LIGHT_PATHS)
                      for seed in (1, 2, 3, 4)]
            # The traced silhouette is a pixel short of the renderer's here and there: pixels it
            # misses that the bake covers (a colour) are edges, counted with the rim.
            kinds = [("rim" if kind == "background" and images[0]["color"][3 * p] > 0.0 else kind)
                     for p, kind in enumerate(kinds)]
            print("pixels: " + ", ".join(f"{r} {kinds.count(r)}" for r in ("inside", "outside", "rim", "background")))
            one = [bake(scene, args.size, args.samples, seed, technique, walks, {"max_bounces": 0})
                   for seed in (1, 2)]
            samples = sum(i["samples"] for i in images)
            row = {"ms_per_spp": 1e3 * sum(i["seconds"] for i in images) / (4 * args.samples),
                   "ms_per_spp_one_bounce": 1e3 * sum(i["seconds"] for i in one) / (2 * args.samples),
                   "walks_per_sample": sum(i["walks"] for i in images) / samples,
                   "events_per_sample": sum(i["events"] for i in images) / samples,
                   "path_rays_per_sample": sum(i["path_rays"] for i in images) / samples}
            for region in ("all", "inside", "outside", "rim"):
                row[region] = {part: {"variance": variance_per_sample(images, part, kinds, region, args.samples),
                                      "mean": mean_of(images, part, kinds, region)}
                               for part in ("combined", "direct", "indirect")}
            if args.single:
                singles = [bake(scene, args.size, 1, 100 + s, technique, walks, benchmark_scenes.LIGHT_PATHS)
                           for s in range(args.single)]
                for part in ("combined", "direct", "indirect"):
                    values = [sum(image[part][3 * p:3 * p + 3]) / 3.0 for image in singles for p in range(len(kinds))
                              if kinds[p] != "background"]
                    row["single_" + part] = tail(values)
            results[pair] = row
            v = row["all"]
            print(f"{pair}: {row['ms_per_spp']:.3f} ms/spp (one bounce {row['ms_per_spp_one_bounce']:.3f}), "
                  f"variance per sample {v['combined']['variance']:.5f} = direct {v['direct']['variance']:.5f} "
                  f"+ indirect {v['indirect']['variance']:.5f} (+ covariance), mean {v['combined']['mean']:.4f} "
                  f"(direct {v['direct']['mean']:.4f}, indirect {v['indirect']['mean']:.4f})", flush=True)
        scene.close()
    print(json.dumps(results, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
