"""The error-against-run-time report: python3 tools/cycles_report.py --out DIR [--quick] [--no-cycles]
[--sections v0,techniques,cycles] [--cycles-scenes slab,leaf,sphere] [--repeats N]
[--cycles-blenders host,trixie,sid] [--walk-event-cap N] [--library PATH]

Runs benchmark scenes through the shim and writes DIR/report.md, DIR/report.json and plots
(matplotlib, Debian python3-matplotlib; without it the report has tables only):

1. v0 methods: the relative error of kappa0 = 1/v0 of every method against the exact root over
   albedos 0.01 to 0.999999 (v0_methods.png).
2. Walk techniques, image level: each technique bakes each benchmark scene at growing sample
   counts on 2 threads; the RMSE of the image against a reference (the auto technique at 16x the
   largest count, another seed) is plotted against the bake's own seconds
   (rmse_<scene>.png). Scenes: the default scene, a thin back-lit slab and a thick front-lit
   sphere (both built here from triangles, with Cycles-compatible materials).
3. Cycles (where Blender is installed and the source tree is at hand): the Blender test scenes of
   tests/blender/scenes.py (the slab with a Principled BSDF, the sphere with the Subsurface
   Scattering node, whose walk is the one dwivedi bakes: see docs/cycles-conventions.md), rendered by Cycles and baked by dwivedi (through the add-on's export)
   at growing sample counts inside one headless Blender; the RMSE of each against a converged
   reference of its own (each renderer at its largest count x 4, another seed) is plotted against
   seconds, the time each needs to reach the same RMSE is compared (cycles_<scene>.png), and the
   two converged images are compared with each other. Scenes: the slab, a leaf-like thin sheet
   (high albedo, back-lit) and the sphere. Cycles' time is its
   render time minus that of a 1-sample render (scene sync), dwivedi's the bake's own seconds.
   The two take turns over N timing rounds (--repeats, default 3) and each sample count keeps its
   fastest time; at the counts both ran, the variance ratio per sample is reported apart, since
   it does not depend on the machine's load. --cycles-blenders runs this in each Blender named:
   the host's (3.4) and those of the trixie (4.3) and sid (5.2) chroots (root; the chroots as the
   tests make and enter them, tests/blender/run_package_tests.py), with the same scene script and
   the add-on's export for that version; --library names the library the bakes use (the chroots
   need the self-contained one). One Blender per run is fine too (a report per version).
   dwivedi's bakes end walks after Cycles' 256 events (--walk-event-cap, default 256: the same
   image as Cycles'; 0 for the add-on's default 10^6, which keeps the light Cycles loses).

Timings are measured on whatever else runs on the machine: ratios within one run are fair,
absolute seconds are not. Exit status 1 with a message on failure.
"""
from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Tuple

SOURCE_DIR = Path(__file__).resolve().parent.parent  # tools/ -> the source tree
SHIM_DIR = SOURCE_DIR / "python_shim"
# A tool of the source tree, not part of `import dwivedi` (nor of the add-on's packages): it uses
# the shim of its own tree unless PYTHONPATH already names one.
if str(SHIM_DIR) not in sys.path:
    sys.path.append(str(SHIM_DIR))

import dwivedi  # noqa: E402

sys.path.append(str(SOURCE_DIR / "tools"))
# The benchmark set of issue 20 (tools/benchmark_scenes.py): its scenes can be compared with Cycles
# by name, or all of them as `--cycles-scenes benchmark`.
from benchmark_scenes import NAMES as BENCHMARK_SCENES  # noqa: E402


# ---------------------------------------------------------------------------------------------
# Scenes built from triangles (no files, no Blender)
# ---------------------------------------------------------------------------------------------

def box(sx: float, sy: float, sz: float) -> Tuple[List[Tuple[float, float, float]], List[Tuple[int, int, int]]]:
    """An axis-aligned box centred at the origin, outward triangles."""
    p = [(x * sx / 2, y * sy / 2, z * sz / 2) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    t = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4),
         (1, 5, 7), (1, 7, 3)]
    return p, t


def uv_sphere(segments: int = 48, rings: int = 24) -> Tuple[list, list]:
    """A unit UV sphere (as Blender's primitive: poles on z), outward triangles; its positions
    are its smooth normals."""
    points = [(0.0, 0.0, 1.0)]
    for r in range(1, rings):
        theta = math.pi * r / rings
        for s in range(segments):
            phi = 2 * math.pi * s / segments
            points.append((math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta)))
    points.append((0.0, 0.0, -1.0))
    south = len(points) - 1

    def ring(r: int, s: int) -> int:
        return 1 + (r - 1) * segments + s % segments

    tris = []
    for s in range(segments):
        tris.append((0, ring(1, s), ring(1, s + 1)))
        tris.append((south, ring(rings - 1, s + 1), ring(rings - 1, s)))
    for r in range(1, rings - 1):
        for s in range(segments):
            a, b, c, d = ring(r, s), ring(r, s + 1), ring(r + 1, s), ring(r + 1, s + 1)
            tris.append((a, c, d))
            tris.append((a, d, b))
    return points, tris


def slab_scene() -> dwivedi.Scene:
    """The back-lit slab of tests/blender/scenes.py: 4 x 4 x 0.1 m, radius (1, 0.5, 0.25), colour
    0.8 (1.3 / 2.5 / 5 mean free paths thick), a sun of 3 W/m^2 from below, orthographic camera."""
    scene = dwivedi.Scene()
    material = scene.add_material(dwivedi.Material(base_color=(0.8, 0.8, 0.8), subsurface_color=(0.8, 0.8, 0.8),
                                                   subsurface_radius=(1.0, 0.5, 0.25), subsurface_scale=1.0))
    p, t = box(4.0, 4.0, 0.1)
    scene.add_mesh(p, t, material)
    scene.add_light(dwivedi.SunLight(direction=(0.0, 0.0, 1.0), strength=3.0))
    scene.set_camera(dwivedi.Camera(transform=[1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 3], kind="orthographic",
                                    ortho_scale=1.0))
    return scene.commit()


def sphere_scene() -> dwivedi.Scene:
    """The front-lit wax sphere of tests/blender/scenes.py."""
    scene = dwivedi.Scene()
    material = scene.add_material(dwivedi.Material(base_color=(0.9, 0.6, 0.4), subsurface_color=(0.9, 0.6, 0.4),
                                                   subsurface_radius=(0.5, 0.25, 0.1), subsurface_scale=1.0))
    p, t = uv_sphere()
    scene.add_mesh(p, t, material, normals=p)
    c, s = math.cos(math.radians(45)), math.sin(math.radians(45))
    cz, sz = math.cos(math.radians(-30)), math.sin(math.radians(-30))
    # The sun's local -z after Blender's XYZ Euler (45, 0, -30) degrees: Rz Rx (0, 0, -1).
    d = (0.0, s, -c)
    d = (cz * d[0] - sz * d[1], sz * d[0] + cz * d[1], d[2])
    scene.add_light(dwivedi.SunLight(direction=d, strength=2.0))
    scene.set_camera(dwivedi.Camera(transform=[1, 0, 0, 0, 0, 0, -1, -3.5, 0, 1, 0, 0], focal_length=50.0))
    return scene.commit()


def default_scene() -> dwivedi.Scene:
    return dwivedi.Scene.default()


SCENES = {"default": default_scene, "slab": slab_scene, "sphere": sphere_scene}
SECTIONS = ("v0", "techniques", "cycles")
CYCLES_SCENES = ("slab", "leaf", "sphere")
BLENDERS = ("host", "trixie", "sid")
# Cycles ends a subsurface walk after 256 scattering events (BSSRDF_MAX_BOUNCES, every version
# here) and drops its light; dwivedi's bakes against it end theirs there too (the add-on's Walk
# Event Cap, as tests/blender/harness.py), so that the two converged images estimate the same
# image: uncapped (the add-on's default, 10^6), the thick, bright benchmark torus came out 2.8% /
# 1.6% / 0.2% brighter than Cycles 3.4 in R / G / B, at the cap 0.06% / 0.27% / 0.16%.
CYCLES_EVENT_CAP = 256


# ---------------------------------------------------------------------------------------------
# Measurements
# ---------------------------------------------------------------------------------------------

def rmse(a: Sequence[float], b: Sequence[float]) -> float:
    """Root mean square difference over the RGB channels of two RGBA arrays."""
    total = 0.0
    n = 0
    for i in range(0, len(a), 4):
        for c in range(3):
            total += (a[i + c] - b[i + c]) ** 2
            n += 1
    return math.sqrt(total / n)


def v0_section(quick: bool) -> Dict[str, Any]:
    albedos = [1 - 10 ** (-k / 4) for k in range(1, 25)] + [0.01, 0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7]
    albedos = sorted(a for a in albedos if 0 < a < 1)
    out: Dict[str, Any] = {"albedo": albedos}
    for method in dwivedi.methods():
        errors = []
        for a in albedos:
            exact = dwivedi.diffusion_constants(a, "exact").kappa
            value = dwivedi.diffusion_constants(a, method).kappa
            errors.append(abs(value - exact) / exact if exact > 0 else 0.0)
        out[method] = errors
    return out


def technique_section(quick: bool, size: int) -> Dict[str, Any]:
    counts = [2, 8, 32] if quick else [4, 16, 64, 256]
    result: Dict[str, Any] = {}
    for name, build in SCENES.items():
        with build() as scene:
            reference = dwivedi.bake(scene, width=size, height=size, samples=16 * counts[-1], threads=2, seed=99)
            ref_pixels = reference.pixels()
            entry: Dict[str, Any] = {"reference_samples": 16 * counts[-1],
                                     "reference_seconds": reference.stats.seconds,
                                     "reference_mean_rgb": list(reference.stats.mean_rgb), "techniques": {}}
            for technique in dwivedi.techniques():
                points = []
                for samples in counts:
                    image = dwivedi.bake(scene, width=size, height=size, samples=samples, threads=2, seed=1,
                                         technique=technique)
                    points.append({"samples": samples, "seconds": image.stats.seconds,
                                   "rmse": rmse(image.pixels(), ref_pixels),
                                   "estimated_relative_error": image.stats.estimated_relative_error})
                entry["techniques"][technique] = points
                print(f"  {name:8s} {technique:10s} " + "  ".join(f"{p['seconds']:.3f}s:{p['rmse']:.4g}"
                                                               for p in points), file=sys.stderr, flush=True)
            result[name] = entry
    return result


BLENDER_SCRIPT = r'''
import json, os, sys, time, math
args = json.loads(sys.argv[sys.argv.index("--") + 1])
sys.path[:0] = [args["shim"], args["addon"], args["scenes"], args["tools"]]
import bpy, dwivedi, scenes, benchmark_scenes
import dwivedi_bake
import dwivedi_bake.export as export

# dwivedi's bakes run through the add-on's operator (bpy.ops.dwivedi.bake), as an artist runs them:
# export, scene commit, bake, EXR + PNG written and loaded as a Blender image. Its parts are timed
# on the way through: the export (with the library's scene commit) and the library's bake.
dwivedi_bake.register()
parts = {}
_export_scene, _bake = export.export_scene, dwivedi.bake

def timed_export(*a, **k):
    t = time.monotonic(); out = _export_scene(*a, **k); parts["export"] = time.monotonic() - t; return out

def timed_bake(*a, **k):
    image = _bake(*a, **k); parts["bake"] = image.stats.seconds; return image

export.export_scene, dwivedi.bake = timed_export, timed_bake

class Props:  # what export_scene reads of scene.dwivedi_bake
    target = 'CAMERA'; uv_object = None; uv_size = 0

def operator_bake(scene, spp, seed, folder):
    """The whole bake from the operator; (wall seconds, its parts, RGBA rows from the bottom)."""
    props = scene.dwivedi_bake
    props.target = 'CAMERA'; props.samples = spp; props.seed = seed; props.threads = 2
    props.output_dir = folder; props.load_result = False; props.walk_event_cap = args["event_cap"]
    parts.clear()
    # Cold, as Cycles renders without Persistent Data: the add-on's export cache (which would make
    # a bake of the unchanged scene reuse the last one's export and commit) is emptied first.
    export.CACHE.clear()
    t = time.monotonic()
    result = bpy.ops.dwivedi.bake()
    seconds = time.monotonic() - t
    if result != {'FINISHED'} or "bake" not in parts:
        raise RuntimeError(f"the dwivedi operator returned {result}")
    image = bpy.data.images["Dwivedi Camera"]
    px = [0.0] * (4 * image.size[0] * image.size[1]); image.pixels.foreach_get(px)
    return seconds, dict(parts), px

def pixels_of(path):
    image = bpy.data.images.load(path, check_existing=False)
    px = [0.0] * (4 * image.size[0] * image.size[1]); image.pixels.foreach_get(px)
    bpy.data.images.remove(image)
    return px

def flip(rgba, w, h):  # dwivedi's rows from the top -> Blender's from the bottom
    out = []
    for y in range(h - 1, -1, -1):
        out.extend(rgba[4 * w * y: 4 * w * (y + 1)])
    return out

def rmse(a, b):
    return math.sqrt(sum((a[i + c] - b[i + c]) ** 2 for i in range(0, len(a), 4) for c in range(3)) / (3 * len(a) // 4))

def cycles(scene, spp, seed, path):
    scene.cycles.samples = spp; scene.cycles.seed = seed
    scene.render.image_settings.file_format = 'OPEN_EXR'; scene.render.image_settings.color_depth = '32'
    scene.render.filepath = path
    t = time.monotonic(); bpy.ops.render.render(write_still=True); return time.monotonic() - t

out = {}
not_run = []

def write_result():
    # After every scene, so that a run cut short (the machine's load, --budget-minutes) keeps the
    # scenes it finished: written beside and renamed, never half-written.
    with open(args["result"] + ".part", "w") as f:
        json.dump({"blender": bpy.app.version_string, "scenes": out, "not_run": not_run}, f)
    os.replace(args["result"] + ".part", args["result"])

for index, name in enumerate(args["scenes_list"]):
    if args["deadline"] is not None and time.time() > args["deadline"]:
        not_run[:] = args["scenes_list"][index:]
        print("time budget spent: not run", ", ".join(not_run), file=sys.stderr, flush=True)
        break
    builders = {"slab": scenes.slab_scene,
                # A leaf-like sheet: 2 cm thick, the same radius in every channel (mean free path
                # 0.1 / (4 pi) = 8 mm, 2.5 of them across), a high green albedo, lit from behind.
                "leaf": lambda r, s: scenes.slab_scene(r, s, thickness=0.02, color=(0.6, 0.95, 0.4),
                                                       radius=(0.1, 0.1, 0.1)),
                # The Subsurface Scattering node: the plain walk, which Blender 3.x's Principled is not.
                "sphere": lambda r, s: scenes.sphere_scene(r, s, shader='SSS')}
    scene = builders[name](args["size"], 16) if name in builders else benchmark_scenes.build(name, args["size"], 16)
    # The same media in every Blender: 5.2's new Random Walk reads the radius as the mean free path
    # (4 pi longer than before); its Legacy method is the model the other versions' scenes use.
    for material in bpy.data.materials:
        for node in (material.node_tree.nodes if material.use_nodes else ()):
            if getattr(node, "subsurface_method", None) == 'RANDOM_WALK' and 'RANDOM_WALK_LEGACY' in [
                    item.identifier for item in node.bl_rna.properties["subsurface_method"].enum_items]:
                node.subsurface_method = 'RANDOM_WALK_LEGACY'
    work = args["work"]
    overhead = cycles(scene, 1, 0, f"{work}/{name}_c1.exr")
    ref_spp = 4 * args["cycles_counts"][-1]
    ref_seconds = cycles(scene, ref_spp, 1234, f"{work}/{name}_ref.exr")
    ref = pixels_of(f"{work}/{name}_ref.exr")
    entry = {"reference_samples": ref_spp, "reference_seconds": ref_seconds, "sync_seconds": overhead,
             "repeats": args["repeats"], "cycles": [], "dwivedi": []}
    exported = export.export_scene(bpy.context, Props, dwivedi)
    # Both renderers with the scene's Light Paths (indirect light, issue 18).
    paths = export.light_paths(scene)
    # dwivedi's own converged image (4x its largest count, another seed): its noise is measured
    # against it, as Cycles' is against Cycles' own; the two converged images are compared apart.
    own_spp = 4 * args["dwivedi_counts"][-1]
    own = dwivedi.bake(exported.scene, width=exported.width, height=exported.height, samples=own_spp, threads=2,
                       seed=1234, max_events=args["event_cap"], **paths)
    exported.scene.close()
    own_ref = flip(list(own.pixels()), own.width, own.height)
    entry["dwivedi_reference_samples"] = own_spp
    entry["dwivedi_reference_seconds"] = own.stats.seconds
    entry["converged_rmse"] = rmse(own_ref, ref)
    entry["dwivedi_reference_mean_rgb"] = [sum(own_ref[c::4]) / (len(own_ref) // 4) for c in range(3)]
    # Timings: both renderers take turns, `repeats` rounds, and each count keeps its fastest time
    # (other load on the machine only ever adds time). Seeds are fixed, so every round makes the
    # same images: the RMSE is taken from the first. Both sides are timed the same way, as the
    # whole operator an artist runs (seconds): Cycles' F12 (bpy.ops.render.render with the EXR
    # written: scene sync, render, file) and dwivedi's Bake (export, commit, bake, EXR + PNG, the
    # image loaded); each renderer's own part is kept beside it (own_seconds: Cycles' render less a
    # 1-sample render's time, the scene sync; dwivedi's bake without the export and the files).
    for turn in range(args["repeats"]):
        if turn > 0:
            overhead = min(overhead, cycles(scene, 1, 0, f"{work}/{name}_c1.exr"))
        for i, spp in enumerate(args["cycles_counts"]):
            seconds = cycles(scene, spp, 7, f"{work}/{name}_c.exr")
            if turn == 0:
                entry["cycles"].append({"samples": spp, "render_seconds": seconds,
                                        "rmse": rmse(pixels_of(f"{work}/{name}_c.exr"), ref)})
            else:
                entry["cycles"][i]["render_seconds"] = min(entry["cycles"][i]["render_seconds"], seconds)
        for i, spp in enumerate(args["dwivedi_counts"]):
            seconds, timed, ours = operator_bake(scene, spp, 7, f"{work}/{name}_out")
            if turn == 0:
                n = len(ours) // 4
                entry["dwivedi"].append({"samples": spp, "seconds": seconds, "own_seconds": timed["bake"],
                                         "export_seconds": timed["export"], "rmse": rmse(ours, own_ref),
                                         "rmse_against_cycles": rmse(ours, ref),
                                         "mean_rgb": [sum(ours[c::4]) / n for c in range(3)]})
            else:
                point = entry["dwivedi"][i]
                point["seconds"] = min(point["seconds"], seconds)
                point["own_seconds"] = min(point["own_seconds"], timed["bake"])
                point["export_seconds"] = min(point["export_seconds"], timed["export"])
    entry["sync_seconds"] = overhead
    for point in entry["cycles"]:
        point["seconds"] = point["render_seconds"]
        point["own_seconds"] = max(point["render_seconds"] - overhead, 1e-3)
    n = len(ref) // 4
    entry["cycles_reference_mean_rgb"] = [sum(ref[c::4]) / n for c in range(3)]
    out[name] = entry
    print("scene", name, "done", file=sys.stderr, flush=True)
    write_result()
write_result()
'''


def cycles_section(quick: bool, blender: str, size: int, scenes: Sequence[str], repeats: int,
                   where: str = "host", library: Optional[str] = None,
                   deadline: Optional[float] = None, event_cap: int = CYCLES_EVENT_CAP) -> Dict[str, Any]:
    """The Cycles comparison in one Blender: `blender` on the host (where = "host"), or the Blender
    of the trixie / sid chroot (scripts/blender-chroots.sh, run the way the tests run it:
    tests/blender/run_package_tests.py's make_chroot and blender_command; root). `library`: the
    dwivedi library the bakes use (default the shim's; a chroot needs the self-contained one,
    build/portable/libdwivedi.so.1). `deadline` (time.time() seconds): scenes not begun by then
    are left out and listed. `event_cap`: every dwivedi bake's cap on scattering events per walk
    (the add-on's Walk Event Cap; 0: the library's 10^6). Returns {"blender": version, "scenes":
    {name: entry}, "not_run": [names], "where": where, "walk_event_cap": event_cap}."""
    scenes_dir = SOURCE_DIR / "tests" / "blender"
    addon_dir = SOURCE_DIR / "blender_addon"
    shim_dir = Path(dwivedi.__file__).resolve().parent.parent
    if not (scenes_dir / "scenes.py").is_file() or not (addon_dir / "dwivedi_bake").is_dir():
        raise RuntimeError(f"the Cycles comparison needs the source tree (tests/blender, blender_addon) at {SOURCE_DIR}")
    library = library or dwivedi.library_path()
    if library and not os.path.isfile(library) and (where != "host" or os.path.isabs(library)):
        raise RuntimeError(f"the dwivedi library {library!r} is not a file (--library)")
    chroot = None
    if where != "host":
        sys.path.insert(0, str(scenes_dir))
        import run_package_tests as runner  # the tests' chroot machinery, standard library only
        chroot = runner.make_chroot(where)
        blender = "/usr/bin/blender"
        holder = tempfile.TemporaryDirectory(dir=chroot / "tmp", prefix="dwivedi-report-")
    else:
        holder = tempfile.TemporaryDirectory()
    with holder as work:
        stage = Path(work)

        def inside(path: Path) -> str:
            return "/" + str(Path(path).relative_to(chroot)) if chroot is not None else str(path)

        if chroot is not None:
            # Copies of the shim, the add-on's source, the scenes and the library inside the chroot.
            shutil.copytree(shim_dir / "dwivedi", stage / "shim" / "dwivedi")
            shutil.copytree(addon_dir / "dwivedi_bake", stage / "addon" / "dwivedi_bake")
            (stage / "scenes").mkdir()
            shutil.copy2(scenes_dir / "scenes.py", stage / "scenes" / "scenes.py")
            (stage / "tools").mkdir()
            for tool in ("benchmark_scenes.py", "make_example_meshes.py"):  # the second makes the first's spheres
                shutil.copy2(SOURCE_DIR / "tools" / tool, stage / "tools" / tool)
            shutil.copy2(library, stage / "libdwivedi.so.1")
            paths = {"shim": stage / "shim", "addon": stage / "addon", "scenes": stage / "scenes",
                     "tools": stage / "tools"}
            library_seen = inside(stage / "libdwivedi.so.1")
        else:
            paths = {"shim": shim_dir, "addon": addon_dir, "scenes": scenes_dir, "tools": SOURCE_DIR / "tools"}
            library_seen = library
        result_path = stage / "result.json"
        args = {**{key: inside(value) for key, value in paths.items()}, "work": inside(stage),
                "result": inside(result_path), "size": size, "scenes_list": list(scenes), "repeats": repeats,
                "deadline": deadline, "event_cap": event_cap,
                # Counts large enough that Cycles' render time, not its per-render overhead, is
                # what is measured.
                "cycles_counts": [32, 128, 512] if quick else [64, 256, 1024],
                "dwivedi_counts": [8, 32, 128] if quick else [16, 64, 256, 1024]}
        script = stage / "bench.py"
        script.write_text(BLENDER_SCRIPT)
        command = [blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python", inside(script), "--",
                   json.dumps(args)]
        if chroot is not None:
            home = stage / "home"
            home.mkdir()
            env = {"HOME": inside(home), "PATH": "/usr/local/bin:/usr/bin:/bin", "LANG": "C.UTF-8",
                   "TMPDIR": inside(stage), "DWIVEDI_LIBRARY": library_seen, "PYTHONDONTWRITEBYTECODE": "1",
                   "BLENDER_USER_SCRIPTS": inside(home / "scripts"), "BLENDER_USER_CONFIG": inside(home / "config")}
            command = runner.blender_command(command, env, chroot)
            completed = subprocess.run(command, capture_output=True, text=True)
        else:
            env = dict(os.environ)
            # A bare name (the loader's search) stays with what the environment already says.
            env["DWIVEDI_LIBRARY"] = library_seen if os.path.isabs(library_seen) else env.get("DWIVEDI_LIBRARY", "")
            completed = subprocess.run(command, env=env, capture_output=True, text=True)
        if completed.returncode != 0 or not result_path.is_file():
            tail = "\n".join((completed.stdout + completed.stderr).splitlines()[-15:])
            raise RuntimeError(f"the Blender benchmark ({where}) failed:\n{tail}")
        result = json.loads(result_path.read_text())
        result["where"] = where
        result["walk_event_cap"] = event_cap
        return result


def noise_only(points: List[Dict[str, float]], reference_samples: int) -> List[Dict[str, float]]:
    """The points with the RMSE each has against the converged image itself. Each was measured
    against a reference of the same renderer at `reference_samples` spp, whose own noise is
    independent of the point's: with per-sample variance s^2, RMSE^2 = s^2 / spp + s^2 / reference,
    so the noise alone is RMSE x sqrt(reference / (spp + reference)). Without this, a point at a
    quarter of the reference's samples carries 25% more variance than it has, and a renderer whose
    curve must be extrapolated from it (the target lies below its last point) looks slower."""
    return [{**p, "rmse": p["rmse"] * math.sqrt(reference_samples / (p["samples"] + reference_samples))}
            for p in points]


def time_to_rmse(points: List[Dict[str, float]], target: float) -> Optional[float]:
    """Seconds to reach `target` RMSE, interpolated log-log between measured points (RMSE falls
    as 1/sqrt(time)); extrapolated along that slope beyond the last point."""
    pts = sorted((p["seconds"], p["rmse"]) for p in points if p["rmse"] > 0 and p["seconds"] > 0)
    if not pts:
        return None
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if e0 >= target >= e1 and e0 != e1:
            f = math.log(e0 / target) / math.log(e0 / e1)
            return math.exp(math.log(t0) + f * math.log(t1 / t0))
    t, e = pts[-1] if target < pts[-1][1] else pts[0]
    return t * (e / target) ** 2


# ---------------------------------------------------------------------------------------------
# Output
# ---------------------------------------------------------------------------------------------

def event_cap_words(cap: Optional[int]) -> str:
    """What the report says of dwivedi's walk event cap against Cycles' 256 (None: a report.json
    from before the cap was recorded, whose bakes ran uncapped)."""
    if cap == CYCLES_EVENT_CAP:
        return (f"dwivedi's walks end after {cap} scattering events, as Cycles' do (BSSRDF_MAX_BOUNCES): both lose "
                "the same light on thick, bright objects, docs/cycles_energy_loss.md")
    events = f"{cap}" if cap else "10^6"
    return (f"dwivedi's walks end after {events} scattering events, Cycles' after 256: where their counts differ, "
            "on thick, bright objects, the two converged images differ by the light one of them loses, "
            "docs/cycles_energy_loss.md")


def cycles_entries(data: Dict[str, Any]) -> List[Tuple[str, str, Dict[str, Any]]]:
    """(where, scene, entry) of every Cycles comparison of the report, per Blender in run order."""
    return [(where, name, entry) for where, run in data.get("cycles", {}).items()
            for name, entry in run["scenes"].items()]


def plots(out: Path, data: Dict[str, Any]) -> List[str]:
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as pyplot
    except ImportError:
        return []
    made = []
    if "v0" in data:
        v0 = data["v0"]
        fig, ax = pyplot.subplots(figsize=(6, 4))
        for method in dwivedi.methods():
            if method == "exact":
                continue
            ax.loglog([1 - a for a in v0["albedo"]], [max(e, 1e-17) for e in v0[method]], marker=".", label=method)
        ax.set_xlabel("1 - albedo")
        ax.set_ylabel("relative error of kappa0")
        ax.legend()
        ax.grid(True, which="both", alpha=0.3)
        fig.tight_layout()
        fig.savefig(out / "v0_methods.png", dpi=100)
        pyplot.close(fig)
        made.append("v0_methods.png")
    for name, entry in data.get("techniques", {}).items():
        fig, ax = pyplot.subplots(figsize=(6, 4))
        for technique, points in entry["techniques"].items():
            ax.loglog([p["seconds"] for p in points], [p["rmse"] for p in points], marker="o", label=technique)
        ax.set_xlabel("bake seconds (2 threads)")
        ax.set_ylabel("image RMSE")
        ax.set_title(f"{name}: RMSE against time")
        ax.legend(fontsize="small")
        ax.grid(True, which="both", alpha=0.3)
        fig.tight_layout()
        fig.savefig(out / f"rmse_{name}.png", dpi=100)
        pyplot.close(fig)
        made.append(f"rmse_{name}.png")
    for where, name, entry in cycles_entries(data):
        fig, ax = pyplot.subplots(figsize=(6, 4))
        for who, reference in (("cycles", entry["reference_samples"]), ("dwivedi", entry["dwivedi_reference_samples"])):
            points = noise_only(entry[who], reference)
            ax.loglog([p["seconds"] for p in points], [p["rmse"] for p in points], marker="o", label=who)
        ax.set_xlabel("seconds (2 threads)")
        ax.set_ylabel("RMSE against the converged image (noise only)")
        ax.set_title(f"{name}: dwivedi against Cycles of Blender {data['cycles'][where]['blender']}")
        ax.legend()
        ax.grid(True, which="both", alpha=0.3)
        fig.tight_layout()
        fig.savefig(out / f"cycles_{where}_{name}.png", dpi=100)
        pyplot.close(fig)
        made.append(f"cycles_{where}_{name}.png")
    return made


def markdown(data: Dict[str, Any], made: List[str]) -> str:
    lines = ["# dwivedi: error against run time", "",
             f"Made by `python3 tools/cycles_report.py` on {data['date']} ({data['machine']}), library "
             f"{data['version']} ({data['library']}). Timings are ratios within this run; other load on the "
             "machine moves the absolute seconds.", ""]
    if "v0" in data:
        lines += ["## v0 methods", "", "Largest relative error of kappa0 = 1/v0 against the exact root, albedo 0.01 "
                  "to 1 - 10^-6:", "", "| method | largest relative error |", "|---|---|"]
        for method in dwivedi.methods():
            lines.append(f"| {method} | {max(data['v0'][method]):.3g} |")
        if "v0_methods.png" in made:
            lines += ["", "![v0 methods](v0_methods.png)"]
    if data.get("techniques"):
        lines += ["", "## Walk techniques, image RMSE against time", "",
                  "Each technique at growing samples per pixel (2 threads, seed 1); RMSE over the RGB pixels "
                  "against the auto technique at 16x the largest count (seed 99).", ""]
        for name, entry in data["techniques"].items():
            lines += [f"### {name}", "", f"Reference: {entry['reference_samples']} spp in "
                      f"{entry['reference_seconds']:.2f} s, mean RGB "
                      + ", ".join(f"{v:.4f}" for v in entry["reference_mean_rgb"]), "",
                      "| technique | " + " | ".join(f"{p['samples']} spp" for p in
                                                      next(iter(entry["techniques"].values()))) + " |",
                      "|---|" + "---|" * len(next(iter(entry["techniques"].values())))]
            for technique, points in entry["techniques"].items():
                lines.append(f"| {technique} | " + " | ".join(f"{p['rmse']:.4g} ({p['seconds']:.3f} s)"
                                                             for p in points) + " |")
            if f"rmse_{name}.png" in made:
                lines += ["", f"![{name}](rmse_{name}.png)"]
            lines.append("")
    if data.get("cycles"):
        first = next(iter(data["cycles"].values()))
        lines += ["## Against Cycles", "",
                  f"dwivedi's bakes here use {data.get('cycles_library', data['library'])}. "
                  "Same Blender scene, same 2 threads, in each Blender named (the host's, and those of the "
                  "trixie and sid chroots: the same scene script, that Blender's Cycles and the add-on's "
                  "export for that version; 5.2's Principled and Subsurface Scattering nodes with its Legacy "
                  "method, the medium of the other versions). Each renderer's RMSE is measured against its own "
                  "converged image (Cycles and dwivedi each at 4x their largest count, other seeds), so that "
                  "noise is compared with noise; how far the two converged images lie apart is its own column "
                  f"({event_cap_words(first.get('walk_event_cap'))}). Both sides are timed the same way, as "
                  "the whole operator an artist runs: Cycles' F12 (bpy.ops.render.render writing the EXR: "
                  "scene sync, render, file) "
                  "and dwivedi's Bake (bpy.ops.dwivedi.bake: the add-on's export and the library's scene commit, "
                  "the bake with its auto pilot, EXR + PNG written and loaded as a Blender image; the add-on's "
                  "export cache emptied before each, as Cycles syncs every render without Persistent Data); the speed-up "
                  "of the renderers' own parts (Cycles' render less a 1-sample render's time, the scene sync; "
                  "dwivedi's bake without export and files) is the last column. Both take turns over "
                  f"{next(iter(first['scenes'].values())).get('repeats', 1)} timing round(s) and each count "
                  "keeps its fastest time. RMSEs here are the noise alone: the reference's own noise, 1 / (4x) "
                  "of a point's variance at its largest count, is taken out of each (noise_only). Speed-up = "
                  "Cycles' time / dwivedi's time to reach the RMSE of dwivedi's second-largest bake (log-log "
                  "interpolation, and beyond the last point along RMSE ~ 1/sqrt(time)): the ratio of the two "
                  "efficiencies 1 / (RMSE^2 x seconds) at that RMSE.", ""]
        clean = {(where, name): (noise_only(entry["cycles"], entry["reference_samples"]),
                                 noise_only(entry["dwivedi"], entry["dwivedi_reference_samples"]))
                 for where, name, entry in cycles_entries(data)}
        for where, name, entry in cycles_entries(data):
            theirs_clean, ours_clean = clean[where, name]
            target = ours_clean[-2]["rmse"]
            entry["speedup_at_rmse"] = {"rmse": target, "cycles_seconds": time_to_rmse(theirs_clean, target),
                                        "dwivedi_seconds": time_to_rmse(ours_clean, target)}
            if all("own_seconds" in p for p in theirs_clean + ours_clean):  # reports made before it lack it
                own = [[{**p, "seconds": p["own_seconds"]} for p in side] for side in (theirs_clean, ours_clean)]
                entry["speedup_at_rmse"]["cycles_own_seconds"] = time_to_rmse(own[0], target)
                entry["speedup_at_rmse"]["dwivedi_own_seconds"] = time_to_rmse(own[1], target)
        names = list(dict.fromkeys(name for _, name, _ in cycles_entries(data)))
        lines += ["| scene | " + " | ".join(f"Blender {run['blender']} ({where})" for where, run in
                                             data["cycles"].items()) + " |",
                  "|---|" + "---|" * len(data["cycles"])]
        for name in names:
            cells = []
            for where, run in data["cycles"].items():
                speed = run["scenes"].get(name, {}).get("speedup_at_rmse", {})
                tc, td = speed.get("cycles_seconds"), speed.get("dwivedi_seconds")
                cells.append(f"{tc / td:.2f}x" if tc and td else "n/a")
            lines.append(f"| {name} | " + " | ".join(cells) + " |")
        for where, run in data["cycles"].items():
            lines += ["", f"### Blender {run['blender']} ({where})", "",
                      "| scene | converged Cycles mean RGB | converged dwivedi mean RGB | RMSE between converged | "
                      "target RMSE | Cycles s | dwivedi s | speed-up | speed-up, own parts |",
                      "|---|---|---|---|---|---|---|---|---|"]
            for name, entry in run["scenes"].items():
                speed = entry["speedup_at_rmse"]
                tc, td = speed["cycles_seconds"], speed["dwivedi_seconds"]
                oc, od = speed.get("cycles_own_seconds"), speed.get("dwivedi_own_seconds")
                lines.append(f"| {name} | " + ", ".join(f"{v:.4f}" for v in entry["cycles_reference_mean_rgb"])
                             + " | " + ", ".join(f"{v:.4f}" for v in entry["dwivedi_reference_mean_rgb"]) +
                             f" | {entry['converged_rmse']:.3g} | {speed['rmse']:.4g} | {tc or math.nan:.3g} | "
                             f"{td or math.nan:.3g} | " + (f"{tc / td:.2f}x" if tc and td else "n/a") + " | "
                             + (f"{oc / od:.2f}x" if oc and od else "n/a") + " |")
            lines += ["", "At equal samples per pixel the speed-up splits into variance per sample (independent of "
                      "the machine's load) and time per sample (whole operator; in brackets the renderer's own "
                      "part, and dwivedi's export with the scene commit):", "",
                      "| scene | spp | Cycles RMSE | dwivedi RMSE | variance ratio Cycles / dwivedi | Cycles s | "
                      "dwivedi s | dwivedi export s |", "|---|---|---|---|---|---|---|---|"]

            def own(point):
                return f" ({point['own_seconds']:.3g})" if "own_seconds" in point else ""
            for name in run["scenes"]:
                ours = {p["samples"]: p for p in clean[where, name][1]}
                for theirs in clean[where, name][0]:
                    if theirs["samples"] in ours:
                        mine = ours[theirs["samples"]]
                        lines.append(f"| {name} | {theirs['samples']} | {theirs['rmse']:.4g} | {mine['rmse']:.4g} | "
                                     f"{(theirs['rmse'] / mine['rmse']) ** 2:.3g} | {theirs['seconds']:.3g}"
                                     f"{own(theirs)} | {mine['seconds']:.3g}{own(mine)} | "
                                     f"{mine.get('export_seconds', math.nan):.3g} |")
            if run.get("not_run"):
                lines += ["", "Not run (--budget-minutes spent before they began): " + ", ".join(run["not_run"]) + "."]
            for name in run["scenes"]:
                if f"cycles_{where}_{name}.png" in made:
                    lines += ["", f"![{name} against Blender {run['blender']}'s Cycles](cycles_{where}_{name}.png)"]
    for where, error in data.get("cycles_failed", {}).items():
        lines += ["", f"Against Cycles in {where}: failed ({error.splitlines()[0]})."]
    if data.get("cycles_skipped"):
        lines += ["", "## Against Cycles", "", f"Not run: {data['cycles_skipped']}"]
    return "\n".join(lines) + "\n"


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="tools/cycles_report.py", description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, type=Path, help="folder for report.md, report.json and plots")
    parser.add_argument("--quick", action="store_true", help="fewer and smaller bakes (a smoke run)")
    parser.add_argument("--size", type=int, default=None,
                        help="image width and height (default 32, quick 16; the Cycles part 48, quick 32)")
    parser.add_argument("--no-cycles", action="store_true", help="skip the comparison with Cycles")
    parser.add_argument("--blender", default=shutil.which("blender"), help="the Blender executable")
    parser.add_argument("--sections", default=",".join(SECTIONS),
                        help=f"which parts to run, comma-separated (default: {','.join(SECTIONS)})")
    parser.add_argument("--cycles-scenes", default=",".join(CYCLES_SCENES),
                        help=f"the scenes compared with Cycles, comma-separated (default: {','.join(CYCLES_SCENES)}; "
                        f"also {','.join(BENCHMARK_SCENES)} of tools/benchmark_scenes.py, or `benchmark` for all of those)")
    parser.add_argument("--repeats", type=int, default=None,
                        help="timing rounds against Cycles, each count keeping its fastest time (default 3, quick 1)")
    parser.add_argument("--cycles-blenders", default="host",
                        help="the Blenders whose Cycles is compared, comma-separated, in this order: host (--blender), "
                             "trixie (4.3), sid (5.2) (the chroots of scripts/blender-chroots.sh; root). Default host")
    parser.add_argument("--budget-minutes", type=float, default=None,
                        help="against Cycles: scenes not begun this many minutes after the start are left out "
                             "(listed as not run in the report); the scenes finished are kept. Default: no limit")
    parser.add_argument("--walk-event-cap", type=int, default=CYCLES_EVENT_CAP,
                        help=f"against Cycles: every dwivedi bake's cap on scattering events per walk (default "
                             f"{CYCLES_EVENT_CAP}, Cycles' own, so that both estimate the same image; 0: the add-on's "
                             "default 10^6, which keeps the light Cycles loses on thick, bright objects)")
    parser.add_argument("--library", default=None,
                        help="the dwivedi library the Cycles part bakes with (default the shim's; the chroots need "
                             "the self-contained build/portable/libdwivedi.so.1)")
    args = parser.parse_args(argv)
    blenders = [name for name in args.cycles_blenders.split(",") if name]
    size = args.size or (16 if args.quick else 32)
    sections = [part for part in args.sections.split(",") if part]
    cycles_scenes = [part for name in args.cycles_scenes.split(",") if name
                     for part in (BENCHMARK_SCENES if name == "benchmark" else (name,))]
    repeats = args.repeats if args.repeats is not None else (1 if args.quick else 3)
    unknown = ([part for part in sections if part not in SECTIONS]
               + [n for n in cycles_scenes if n not in CYCLES_SCENES + BENCHMARK_SCENES]
               + [n for n in blenders if n not in BLENDERS])
    budget_bad = args.budget_minutes is not None and not (math.isfinite(args.budget_minutes) and args.budget_minutes > 0)
    cap_bad = not 0 <= args.walk_event_cap <= 2 ** 31 - 1  # the add-on's IntProperty
    if unknown or not sections or not cycles_scenes or not blenders or not 1 <= repeats <= 100 or budget_bad or cap_bad:
        problem = (f"unknown section, scene or Blender {unknown[0]!r}" if unknown else "no section, scene or Blender "
                   "given" if not sections or not cycles_scenes or not blenders else
                   f"--budget-minutes {args.budget_minutes} is not a positive number of minutes" if budget_bad else
                   f"--walk-event-cap {args.walk_event_cap} is outside 0 to {2 ** 31 - 1}" if cap_bad else
                   f"--repeats {repeats} is outside 1 to 100")
        print(f"cycles_report: {problem} (sections: {', '.join(SECTIONS)}; scenes: {', '.join(CYCLES_SCENES)}; "
              f"Blenders: {', '.join(BLENDERS)})", file=sys.stderr)
        return 1
    try:
        args.out.mkdir(parents=True, exist_ok=True)
        data: Dict[str, Any] = {"date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
                                "machine": f"{platform.machine()}, {os.cpu_count()} cores",
                                "version": dwivedi.version(), "library": dwivedi.library_path(), "size": size}
        if "v0" in sections:
            print("v0 methods", file=sys.stderr, flush=True)
            data["v0"] = v0_section(args.quick)
        if "techniques" in sections:
            print("walk techniques", file=sys.stderr, flush=True)
            data["techniques"] = technique_section(args.quick, size)
        if "cycles" not in sections:
            pass
        elif args.no_cycles:
            data["cycles_skipped"] = "--no-cycles"
        elif not args.blender and "host" in blenders:
            data["cycles_skipped"] = "Blender was not found"
        else:
            data["cycles"] = {}
            data["cycles_library"] = args.library or dwivedi.library_path()
            cycles_size = args.size or (32 if args.quick else 48)
            deadline = None if args.budget_minutes is None else time.time() + 60.0 * args.budget_minutes
            for where in blenders:
                print(f"Cycles ({where})", file=sys.stderr, flush=True)
                try:
                    data["cycles"][where] = cycles_section(args.quick, args.blender, cycles_size, cycles_scenes,
                                                           repeats, where, args.library, deadline,
                                                           args.walk_event_cap)
                except RuntimeError as error:  # the other Blenders' figures are still written
                    data.setdefault("cycles_failed", {})[where] = str(error)
                    print(f"cycles_report: {error}", file=sys.stderr, flush=True)
        made = plots(args.out, data)
        text = markdown(data, made)
        (args.out / "report.md").write_text(text)
        (args.out / "report.json").write_text(json.dumps(data, indent=1))
    except (dwivedi.Error, RuntimeError, OSError) as error:
        print(f"cycles_report: {error}", file=sys.stderr)
        return 1
    print(f"cycles_report: wrote {args.out / 'report.md'} and {len(made)} plot(s)", file=sys.stderr)
    return 1 if data.get("cycles_failed") else 0


if __name__ == "__main__":
    sys.exit(main())
