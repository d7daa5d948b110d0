#!/usr/bin/env python3
"""Refits the cost model of auto's pilot (PILOT_COST_* in src/bake/pilot.c).

The pilot prices a sample as
    cost = c_sample + c_walk x walks + c_event x events + c_guided x guided events + c_ray x rays
           + c_query x closest-point queries + c_term x mixture terms
where walks are one per sample that walks when the channels walk together and one per walking
channel when they walk apart (TECHNIQUE/separate: dwv_channel_walks_t), guided events are the events of walks with a guided component (every technique but
classical: their events sample and weigh a Dwivedi direction, which a classical event does not)
and keeps, per mesh, the candidate technique with the least variance x cost. This tool bakes
scenes x techniques on one thread with build/dwivedi_bake_counts (which prints those counts; the
C API does not), measures each bake's cost, and fits the six coefficients by least squares on
relative residuals (each bake weighs alike, whatever its size), with every coefficient >= 0
(all subsets of the columns are tried: exact non-negative least squares for seven unknowns).

Costs, by --measure:
  instructions  callgrind's instruction count inside bake.c's `worker` (the bake's samples,
                not the commit or the pilot): deterministic, so the default on a shared
                machine, but blind to memory stalls and to slow instructions (divisions, exp)
  time          wall seconds of the bake (ns), the fastest of --repeats rounds; each round
                bakes every scene x technique once, so that a spell of load from other jobs
                slows one round of all of them rather than all repeats of one. Only on an
                idle machine: under load the fit's residuals show it (rms 32% against 5% for
                instructions, 2 cores shared by four jobs)

Scenes: the report's sphere (thick, front-lit), slab (thin, back-lit), the leaf-like sheet of
the report's Cycles section (cycles_report's geometry, written as scene files) and the built-in
default scene. Prints the counts per sample, the fit with its residuals, and the #define lines
(all but PILOT_COST_PATH_RAY, which these scenes cannot fit: HELD).
Only the coefficients' ratios matter to the pilot. Standard library only (the report's meshes
come from tools/cycles_report.py, which needs no library to import).

usage: tools/fit_pilot_cost.py [--build build] [--measure instructions|time] [--repeats 5]
                               [--size 32] [--spp 16] [--scenes sphere,slab,leaf,default]
                               [--techniques classical,poe,backward,incident,closest,cycles,
                                             classical/separate,backward/separate,incident/separate]
"""
from __future__ import annotations

import argparse
import itertools
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "python_shim"))
sys.path.insert(0, str(ROOT / "tools"))
import cycles_report as report  # noqa: E402  (geometry only: loads no library)

COUNTS = ("samples", "walks", "events", "guided_events", "rays", "point_queries", "mixture_terms")
NAMES = ("SAMPLE", "WALK", "EVENT", "GUIDED_EVENT", "RAY", "QUERY", "TERM")
# pilot.c's constants this tool does not fit: PATH_RAY prices a ray of indirect light's paths,
# which none of these scenes trace; it was fitted alone with the others held (pilot.c says how).
HELD = ("PATH_RAY",)
TECHNIQUES = ("classical", "poe", "backward", "incident", "closest", "cycles", "classical/separate",
              "backward/separate", "incident/separate")


def _mesh(points, triangles, material, normals=False):
    mesh = {"name": "object", "material": material,
            "positions": [c for p in points for c in p], "indices": [i for t in triangles for i in t]}
    if normals:
        mesh["normals"] = mesh["positions"]
    return mesh


def _material(color, radius):
    return {"kind": "subsurface", "base_color": list(color), "subsurface_weight": 1.0,
            "subsurface_color": list(color), "subsurface_radius": list(radius), "subsurface_scale": 1.0,
            "subsurface_anisotropy": 0.0, "subsurface_ior": 1.4}


def _backlit_sheet(thickness, color, radius):
    """report.slab_scene's layout: a 4 x 4 m box, a sun of 3 W/m^2 from below, orthographic camera above."""
    points, triangles = report.box(4.0, 4.0, thickness)
    return {"version": 1, "materials": {"m": _material(color, radius)},
            "meshes": [_mesh(points, triangles, "m")],
            "lights": [{"kind": "sun", "strength": 3.0, "direction": [0.0, 0.0, 1.0]}],
            "camera": {"kind": "orthographic", "ortho_scale": 1.0,
                       "transform": {"matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 3]}}}


def _sphere():
    """report.sphere_scene: the front-lit wax sphere."""
    points, triangles = report.uv_sphere()
    c, s = math.cos(math.radians(45)), math.sin(math.radians(45))
    cz, sz = math.cos(math.radians(-30)), math.sin(math.radians(-30))
    d = (0.0, s, -c)
    d = (cz * d[0] - sz * d[1], sz * d[0] + cz * d[1], d[2])
    return {"version": 1, "materials": {"wax": _material((0.9, 0.6, 0.4), (0.5, 0.25, 0.1))},
            "meshes": [_mesh(points, triangles, "wax", normals=True)],
            "lights": [{"kind": "sun", "strength": 2.0, "direction": list(d)}],
            "camera": {"kind": "perspective", "focal_length": 50.0,
                       "transform": {"matrix": [1, 0, 0, 0, 0, 0, -1, -3.5, 0, 1, 0, 0]}}}


SCENES = {
    "sphere": _sphere,
    "slab": lambda: _backlit_sheet(0.1, (0.8, 0.8, 0.8), (1.0, 0.5, 0.25)),
    "leaf": lambda: _backlit_sheet(0.02, (0.6, 0.95, 0.4), (0.1, 0.1, 0.1)),
    "default": None,  # built into the library
}


def _instructions(out_prefix: str) -> int:
    total = 0
    for path in Path(out_prefix).parent.glob(Path(out_prefix).name + "*"):
        for line in path.read_text().splitlines():
            m = re.match(r"(?:summary|totals):\s+(\d+)", line)
            if m:
                total += int(m.group(1))
                break
    return total


def measure(tool: Path, scene: str, technique: str, args, workdir: str) -> dict:
    command = [str(tool), scene, technique, str(args.size), str(args.size), str(args.spp), str(args.seed)]
    if args.measure == "time":
        out = subprocess.run(command + ["1"], check=True, capture_output=True, text=True).stdout
        row = json.loads(out)
        row["cost"] = row["seconds"][0] * 1e9
        return row
    prefix = os.path.join(workdir, f"cg.{Path(scene).stem}.{technique.replace('/', '-')}")
    out = subprocess.run(["valgrind", "--tool=callgrind", "--toggle-collect=worker",
                          f"--callgrind-out-file={prefix}.%p"] + command + ["1"],
                         check=True, capture_output=True, text=True).stdout
    row = json.loads(out)
    row["cost"] = float(_instructions(prefix))
    return row


def _solve(rows, columns):
    """Least squares of rows (x, y) on the given columns of x, relative residuals; None if singular."""
    n = len(columns)
    a = [[0.0] * n for _ in range(n)]
    b = [0.0] * n
    for x, y in rows:
        w = 1.0 / (y * y)
        for i, ci in enumerate(columns):
            b[i] += w * x[ci] * y
            for j, cj in enumerate(columns):
                a[i][j] += w * x[ci] * x[cj]
    # Gaussian elimination with partial pivoting.
    for k in range(n):
        p = max(range(k, n), key=lambda r: abs(a[r][k]))
        if abs(a[p][k]) < 1e-300:
            return None
        a[k], a[p], b[k], b[p] = a[p], a[k], b[p], b[k]
        for r in range(k + 1, n):
            f = a[r][k] / a[k][k]
            for c in range(k, n):
                a[r][c] -= f * a[k][c]
            b[r] -= f * b[k]
    coef = [0.0] * n
    for k in reversed(range(n)):
        coef[k] = (b[k] - sum(a[k][c] * coef[c] for c in range(k + 1, n))) / a[k][k]
    return coef


def fit(rows):
    """Non-negative least squares on relative residuals: the best of every subset's unconstrained fit
    whose coefficients are all >= 0. Returns (coefficients, rms relative residual)."""
    best = None
    for size in range(1, len(COUNTS) + 1):
        for columns in itertools.combinations(range(len(COUNTS)), size):
            coef = _solve(rows, columns)
            if coef is None or min(coef) < 0.0:
                continue
            full = [0.0] * len(COUNTS)
            for c, v in zip(columns, coef):
                full[c] = v
            rms = math.sqrt(sum((sum(f * xi for f, xi in zip(full, x)) / y - 1.0) ** 2 for x, y in rows) / len(rows))
            if best is None or rms < best[1]:
                best = (full, rms)
    return best


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    parser.add_argument("--build", default=str(ROOT / "build"), help="the build directory (default: build)")
    parser.add_argument("--measure", choices=("instructions", "time"), default="instructions")
    parser.add_argument("--repeats", type=int, default=5, help="time: rounds, the fastest bake of each point kept")
    parser.add_argument("--size", type=int, default=32, help="image width and height (default 32)")
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--scenes", default=",".join(SCENES))
    parser.add_argument("--techniques", default=",".join(TECHNIQUES))
    parser.add_argument("--json", help="also write the rows and the fit to this file")
    args = parser.parse_args(argv)
    tool = Path(args.build) / "dwivedi_bake_counts"
    if not tool.exists():
        parser.error(f"{tool} not found: build the project first")
    scenes = args.scenes.split(",")
    techniques = args.techniques.split(",")
    unknown = [s for s in scenes if s not in SCENES]
    if unknown:
        parser.error(f"unknown scenes {unknown} (known: {', '.join(SCENES)})")
    unknown = [t for t in techniques if t not in TECHNIQUES]
    if unknown:
        parser.error(f"unknown techniques {unknown} (known: {', '.join(TECHNIQUES)})")
    for name in ("repeats", "size", "spp"):
        if getattr(args, name) < 1:
            parser.error(f"--{name} must be at least 1, not {getattr(args, name)}")
    if args.seed < 0:
        parser.error(f"--seed must be at least 0, not {args.seed}")
    if args.measure == "instructions" and shutil.which("valgrind") is None:
        parser.error("--measure instructions needs valgrind (apt-get install valgrind)")
    unit = "ns" if args.measure == "time" else "instructions"
    results = {}
    rounds = args.repeats if args.measure == "time" else 1
    with tempfile.TemporaryDirectory() as workdir:
        paths = {}
        for name in scenes:
            if SCENES[name] is None:
                paths[name] = name
            else:
                paths[name] = os.path.join(workdir, name + ".json")
                Path(paths[name]).write_text(json.dumps(SCENES[name]()))
        for _ in range(rounds):
            for name in scenes:
                for technique in techniques:
                    try:
                        row = measure(tool, paths[name], technique, args, workdir)
                    except subprocess.CalledProcessError as error:
                        print(f"fit_pilot_cost: {name} {technique}: {error.stderr.strip() or error}", file=sys.stderr)
                        return 1
                    key = (name, technique)
                    if key in results and results[key]["cost"] <= row["cost"]:
                        continue
                    row["scene"], row["technique"] = name, technique
                    row["guided_events"] = 0 if technique.split("/")[0] == "classical" else row["events"]
                    results[key] = row
        results = list(results.values())
        for row in results:
            name, technique, per = row["scene"], row["technique"], row["samples"]
            print(f"{name:8s} {technique:18s} per sample: {unit} {row['cost'] / per:10.0f}  walks {row['walks'] / per:6.3f}"
                  f"  events {row['events'] / per:7.3f}"
                  f"  guided {row['guided_events'] / per:7.3f}"
                  f"  rays {row['rays'] / per:7.3f}  queries {row['point_queries'] / per:7.3f}"
                  f"  terms {row['mixture_terms'] / per:8.2f}")
    rows = [([float(r[c]) for c in COUNTS], r["cost"]) for r in results]
    coef, rms = fit(rows)
    print(f"\nfit ({unit}, relative least squares, coefficients >= 0): rms relative residual {rms:.3f}")
    for r, (x, y) in zip(results, rows):
        model = sum(f * xi for f, xi in zip(coef, x))
        print(f"  {r['scene']:8s} {r['technique']:18s} measured {y / x[0]:10.0f}  model {model / x[0]:10.0f}"
              f"  residual {model / y - 1.0:+.3f}")
    print(f"\n/* PILOT_COST_*: {unit} per count, fitted by tools/fit_pilot_cost.py --measure {args.measure}"
          f" (rms {rms:.1%}); only ratios matter */")
    for name, value in zip(NAMES, coef):
        print(f"#define PILOT_COST_{name} {value:.4g}")
    for name in HELD:
        print(f"/* PILOT_COST_{name}: not fitted here (these scenes trace no paths): keep pilot.c's */")
    if args.json:
        Path(args.json).write_text(json.dumps({"rows": results, "unit": unit, "rms": rms,
                                               "coefficients": dict(zip(NAMES, coef))}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
