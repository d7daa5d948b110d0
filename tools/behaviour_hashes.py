#!/usr/bin/env python3
"""Fingerprints of what the library computes, for refactors that must not change it.

Bakes a set of scenes (the default scene and examples/scenes/*.json) with every technique and
both channel-walk modes, and runs `dwivedi estimate` on the half-space, slab and sphere with every
technique, then prints one SHA-256 per case: of a bake's RGBA, variance and sample counts and of
its stats but its times; of an estimate's JSON less its times. Everything is seeded, and neither
depends on the thread count, so two trees that compute the same numbers print the same lines:

    python3 tools/behaviour_hashes.py --library build/libdwivedi.so.1 --cli build/dwivedi > before.txt
    ... change the code, rebuild ...
    python3 tools/behaviour_hashes.py --library build/libdwivedi.so.1 --cli build/dwivedi > after.txt
    diff before.txt after.txt

Exit status 0 when every case ran, 1 when one failed (its line says why).
"""
import argparse
import hashlib
import json
import os
import subprocess
import sys

SOURCE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(SOURCE, "python_shim"))

TECHNIQUES = ("auto", "classical", "poe", "closest", "incident", "backward", "cycles", "sheet")
# Keys of `dwivedi estimate --json` that are times (or derived from them) and so differ run to run.
TIMED_KEYS = ("seconds", "efficiency", "walks_per_second", "ns_per_event", "ns_per_walk")


def bake_cases():
    scenes = [("default", None)]
    folder = os.path.join(SOURCE, "examples", "scenes")
    scenes += [(name[:-5], os.path.join(folder, name)) for name in sorted(os.listdir(folder)) if name.endswith(".json")]
    for scene_name, path in scenes:
        for technique in TECHNIQUES:
            for channel_walks in ("shared", "separate"):
                if technique != "auto" and channel_walks == "separate" and technique not in ("classical", "incident"):
                    continue
                yield scene_name, path, technique, channel_walks


def bake_hash(dwivedi, path, technique, channel_walks, seed):
    scene = dwivedi.Scene.load(path) if path else dwivedi.Scene.default()
    with scene:
        settings = dwivedi.BakeSettings(**{**scene.settings.__dict__, "technique": technique,
                                           "channel_walks": channel_walks, "samples": 8, "seed": seed,
                                           "threads": 2, "time_limit": 0.0, "target_error": 0.0})
        if settings.target == "camera":
            settings = dwivedi.BakeSettings(**{**settings.__dict__, "width": 40, "height": 30})
        else:
            settings = dwivedi.BakeSettings(**{**settings.__dict__, "width": 32, "height": 32})
        with dwivedi.bake(scene, settings) as image:
            digest = hashlib.sha256()
            for view in (image.rgba, image.variance, image.samples):
                digest.update(view.tobytes())
            stats = image.stats
            digest.update(repr((stats.technique, stats.samples_per_pixel, stats.samples, stats.events, stats.walks,
                                stats.estimated_relative_error, stats.mean_rgb, stats.truncated_weight,
                                stats.features, stats.warnings)).encode())
            digest.update(repr([(p.estimated_relative_error, p.samples_per_pixel) for p in image.error_vs_time]).encode())
            return digest.hexdigest()


def estimate_cases():
    for shape, extra in (("halfspace", ["--light", "front"]), ("slab", ["--thickness", "4", "--light", "back"]),
                         ("slab", ["--thickness", "1", "--light", "front"]), ("sphere", ["--radius", "3", "--light", "front"])):
        for technique in TECHNIQUES:
            for albedo in ("0.99", "0.6"):
                yield [shape] + extra + ["--technique", technique, "--albedo", albedo]
    yield ["halfspace", "--light", "front", "--technique", "poe", "--albedo", "0.9", "--anisotropy", "0.7"]
    yield ["slab", "--thickness", "2", "--light", "back", "--technique", "auto", "--albedo", "0.95,0.8,0.5", "--anisotropy", "-0.3"]


def estimate_hash(cli, args):
    command = [cli, "estimate", "--scene"] + args + ["--walks", "20000", "--seed", "7", "--threads", "2", "--json"]
    out = subprocess.run(command, check=True, capture_output=True, text=True).stdout
    data = json.loads(out)
    for key in TIMED_KEYS:
        data.pop(key, None)
    return hashlib.sha256(json.dumps(data, sort_keys=True).encode()).hexdigest()


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--library", required=True, help="libdwivedi.so.1 to bake with")
    parser.add_argument("--cli", required=True, help="the dwivedi command to estimate with")
    parser.add_argument("--seeds", type=int, default=2, help="seeds per bake case (default 2)")
    args = parser.parse_args()
    os.environ["DWIVEDI_LIBRARY"] = os.path.abspath(args.library)
    import dwivedi

    failures = 0
    for scene_name, path, technique, channel_walks in bake_cases():
        for seed in range(args.seeds):
            name = f"bake {scene_name} {technique} {channel_walks} seed {seed}"
            try:
                print(name, bake_hash(dwivedi, path, technique, channel_walks, seed), flush=True)
            except (dwivedi.Error, OSError) as error:
                failures += 1
                print(name, "FAILED", error, flush=True)
    for case in estimate_cases():
        name = "estimate " + " ".join(case)
        try:
            print(name, estimate_hash(args.cli, case), flush=True)
        except (subprocess.CalledProcessError, ValueError) as error:
            failures += 1
            print(name, "FAILED", getattr(error, "stderr", error), flush=True)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
