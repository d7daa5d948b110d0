"""Where Cycles loses energy, side by side: a thick back-lit high-albedo slab rendered by Cycles
and baked by dwivedi, against an independent Monte Carlo of the infinite slab.

    blender -b --factory-startup --python tools/cycles_energy_loss.py -- --out docs [--size 32]

(with the shim importable: PYTHONPATH=python_shim, and DWIVEDI_LIBRARY=build/libdwivedi.so.1 or a
build tree the shim finds). Writes DIR/cycles_energy_loss.png (Cycles | dwivedi, Standard view,
+3 stops so the dim transmission shows) and DIR/cycles_energy_loss.md with the figures.

The scene (tests/blender/scenes.py slab_scene): 20 x 20 m, 2 m thick, colour 0.99 (alpha 0.999999
after Cycles' fit), radius 1 m (mean free path 1/(4 pi) m: 25 mean free paths thick), a sun of
3 W/m^2 from below. Cycles stops each walk after 256 events and loses the light of the walks that
need more; dwivedi's cap is 10^6. The reference is an analog walk in the infinite slab (numpy,
cosine entry, isotropic scattering, exits counted), without a cap and with Cycles' 256.
"""
import argparse
import json
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT / "tests" / "blender"), str(ROOT / "blender_addon"), str(ROOT / "python_shim")]

import bpy  # noqa: E402

import dwivedi  # noqa: E402
import scenes  # noqa: E402
from dwivedi_bake import export  # noqa: E402

THICKNESS = 2.0
COLOR = 0.99
RADIUS = 1.0
SUN = 3.0


def cycles_alpha(albedo):
    """Cycles' single-scattering albedo for a multiple-scattering albedo, g = 0 (Wrenninge et al.)."""
    blend = albedo ** 0.25
    a = ((1 - blend) * 1.8260523782 * math.atan((4.98511194385 + 0.127355959438) * albedo) ** 1.09686102424 +
         blend * 0.496310210422 * math.atan((4.23190299701 + 0.00310603949088) * albedo) ** 2.40602999408)
    return min(max(a, 0.0), 0.999999)


def slab_transmission(tau, alpha, walks, cap, seed):
    """Mean and standard error of the transmission of an infinite slab of optical thickness tau:
    cosine-weighted entry, exponential flights, isotropic scattering, weight alpha per event."""
    import numpy
    rng = numpy.random.default_rng(seed)
    mu = numpy.sqrt(rng.random(walks))
    z = numpy.zeros(walks)
    weight = numpy.ones(walks)
    alive = numpy.ones(walks, bool)
    out = numpy.zeros(walks)
    for _ in range(cap):
        z = z + mu * -numpy.log1p(-rng.random(walks))
        through = alive & (z >= tau)
        out[through] = weight[through]
        alive &= (z > 0) & (z < tau)
        if not alive.any():
            break
        weight *= alpha
        mu = 2 * rng.random(walks) - 1
    return float(out.mean()), float(out.std() / math.sqrt(walks))


class Props:
    target = 'CAMERA'
    uv_object = None
    uv_size = 0


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser()
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--size", type=int, default=32)
    parser.add_argument("--samples", type=int, default=512)
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)

    scene = scenes.slab_scene(args.size, args.samples, thickness=THICKNESS, color=(COLOR,) * 3,
                              radius=(RADIUS,) * 3, width=20.0)
    scene.render.image_settings.file_format = 'OPEN_EXR'
    scene.render.image_settings.color_depth = '32'
    cycles_exr = args.out / "cycles_energy_loss_cycles.exr"
    scene.render.filepath = str(cycles_exr)
    start = time.monotonic()
    bpy.ops.render.render(write_still=True)
    cycles_seconds = time.monotonic() - start
    image = bpy.data.images.load(str(cycles_exr))
    cycles = [0.0] * (4 * args.size * args.size)
    image.pixels.foreach_get(cycles)
    bpy.data.images.remove(image)
    cycles_exr.unlink()

    exported = export.export_scene(bpy.context, Props, dwivedi)
    baked = dwivedi.bake(exported.scene, width=args.size, height=args.size, samples=args.samples, threads=2, seed=1)
    ours_top_down = list(baked.pixels())
    ours = []
    for y in range(args.size - 1, -1, -1):
        ours.extend(ours_top_down[4 * args.size * y:4 * args.size * (y + 1)])

    def mean_t(pixels):
        return sum(pixels[0::4]) / (len(pixels) // 4) * math.pi / SUN

    figures = {"cycles_T": mean_t(cycles), "dwivedi_T": mean_t(ours), "cycles_seconds": cycles_seconds,
               "dwivedi_seconds": baked.stats.seconds, "samples": args.samples,
               "dwivedi_truncated_weight": list(baked.stats.truncated_weight)}
    tau = THICKNESS * 4 * math.pi / RADIUS
    alpha = cycles_alpha(COLOR)
    try:
        figures["reference_T"], figures["reference_se"] = slab_transmission(tau, alpha, 100000, 200000, 1)
        figures["reference_T_cap256"], figures["reference_cap256_se"] = slab_transmission(tau, alpha, 100000, 256, 2)
    except ImportError:
        figures["reference_T"] = None

    # Side by side: Cycles | dwivedi, through the Standard view at +3 stops.
    w, h = args.size, args.size
    both = bpy.data.images.new("side_by_side", 2 * w + 2, h, float_buffer=True)
    pixels = [0.0] * (4 * (2 * w + 2) * h)
    for y in range(h):
        for x in range(w):
            for c in range(4):
                pixels[4 * ((2 * w + 2) * y + x) + c] = cycles[4 * (w * y + x) + c]
                pixels[4 * ((2 * w + 2) * y + x + w + 2) + c] = ours[4 * (w * y + x) + c]
        for x in (w, w + 1):
            pixels[4 * ((2 * w + 2) * y + x) + 3] = 1.0
    both.pixels.foreach_set(pixels)
    scene.view_settings.view_transform = 'Standard'
    scene.view_settings.exposure = 3.0
    scene.render.image_settings.file_format = 'PNG'
    scene.render.dither_intensity = 0.0
    both.save_render(str(args.out / "cycles_energy_loss.png"), scene=scene)

    ref = figures["reference_T"]
    lines = ["# Where Cycles loses energy: a thick back-lit slab", "",
             f"A {THICKNESS:g} m slab (20 x 20 m) of colour {COLOR} (single-scattering albedo {alpha}), radius "
             f"{RADIUS:g} m: {tau:.1f} mean free paths thick; a sun of {SUN:g} W/m^2 from below, seen from above "
             f"(orthographic, {w} x {h}, {args.samples} spp each, 2 threads). T = mean radiance x pi / irradiance.", "",
             "| | transmission T | relative to the reference |", "|---|---|---|"]
    for label, key in (("Cycles 3.4 (walks end after 256 events)", "cycles_T"),
                       ("dwivedi (event cap 10^6)", "dwivedi_T")):
        rel = f"{figures[key] / ref:.3f}" if ref else "n/a"
        lines.append(f"| {label} | {figures[key]:.5f} | {rel} |")
    if ref:
        lines.append(f"| reference: analog walks, infinite slab, no cap | {ref:.5f} +- {figures['reference_se']:.5f} | 1 |")
        lines.append(f"| reference with Cycles' cap of 256 events | {figures['reference_T_cap256']:.5f} +- "
                     f"{figures['reference_cap256_se']:.5f} | {figures['reference_T_cap256'] / ref:.3f} |")
    lines += ["", "![Cycles (left) and dwivedi (right), Standard view +3 stops](cycles_energy_loss.png)", "",
              "Left Cycles, right dwivedi. Made by `tools/cycles_energy_loss.py`; figures in "
              "cycles_energy_loss.json.", ""]
    (args.out / "cycles_energy_loss.md").write_text("\n".join(lines))
    (args.out / "cycles_energy_loss.json").write_text(json.dumps(figures, indent=1))
    print(json.dumps(figures, indent=1))
    exported.scene.close()


main()
