"""Compatibility with Cycles, headless: for the same scene, the add-on's camera bake and a Cycles
render (Principled BSDF, subsurface "Random Walk (Fixed Radius)", specular 0) agree, and the
add-on's display PNG is Blender's own view transform of the same linear pixels.

Scenes (tests/blender/scenes.py, built by script): a back-lit slab 1.3 / 2.5 / 5 mean free paths
thick in R / G / B, and a front-lit thick wax sphere. Each is rendered by Cycles and baked by the
add-on twice with different seeds at 32 x 32 (nothing is cached between runs), then:

- mean radiance per channel within 3% (on channels bright enough to measure);
- per-pixel differences consistent with noise: with each side's per-pixel variance of its
  two-seed mean estimated from the two seeds, (a1 - a2)^2 / 4, the ratio
  R = sum (ours - cycles)^2 / sum (var_ours + var_cycles) is 1 in expectation when both estimate
  the same image; it must stay below 1.5 (a 3% bias on these images makes it several times that);
- the display PNG (Filmic, a look, exposure and gamma) equals Image.save_render of our EXR with
  the scene's view settings within 1/255 per channel.

The figures are printed, and written to DWIVEDI_TEST_HOME/cycles_figures.json.
"""
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bpy  # noqa: E402

import harness  # noqa: E402
import scenes  # noqa: E402

WORK = harness.install_addon()
RESOLUTION = 32
CYCLES_SAMPLES = 512       # per seed; two seeds
DWIVEDI_SAMPLES = 256      # per seed; two seeds
MEAN_TOLERANCE = 0.03
NOISE_RATIO_LIMIT = 1.5
FIGURES = {}


def compare(name, build):
    scene = build(RESOLUTION, CYCLES_SAMPLES)
    cycles = [harness.cycles_render(scene, seed, CYCLES_SAMPLES, WORK / f"{name}_cycles_{seed}.exr") for seed in (1, 2)]
    ours = [harness.dwivedi_bake(scene, seed, DWIVEDI_SAMPLES, WORK / f"{name}_dwivedi_{seed}") for seed in (1, 2)]
    figures = harness.compare_two_seeds([p for p, _ in cycles], [p for p, _ in ours])
    figures.update({
        "cycles_seconds": sum(t for _, t in cycles), "cycles_samples": 2 * CYCLES_SAMPLES,
        "dwivedi_seconds": sum(t for _, t in ours), "dwivedi_samples": 2 * DWIVEDI_SAMPLES,
        "resolution": RESOLUTION,
    })
    FIGURES[name] = figures
    print(f"\n{name}: " + json.dumps(figures, indent=1), flush=True)
    (harness.HOME / "cycles_figures.json").write_text(json.dumps(FIGURES, indent=2))
    return figures


class CyclesTest(harness.unittest.TestCase):
    def check(self, figures, channels):
        for c in channels:
            cm = figures["cycles_mean_rgb"][c]
            om = figures["dwivedi_mean_rgb"][c]
            self.assertGreater(cm, 1e-3, f"channel {c} has signal in Cycles")
            self.assertLess(abs(om / cm - 1.0), MEAN_TOLERANCE,
                            f"channel {'RGB'[c]}: dwivedi {om:.5f} vs Cycles {cm:.5f}")
            self.assertLess(figures["noise_ratio_rgb"][c], NOISE_RATIO_LIMIT,
                            f"channel {'RGB'[c]}: per-pixel differences exceed the noise")

    def test_back_lit_slab(self):
        self.check(compare("slab", scenes.slab_scene), (0, 1, 2))

    def test_front_lit_sphere(self):
        """The Subsurface Scattering node (Random Walk, Fixed Radius): the walk with a Lambertian
        exit that dwv_material_t describes, front-lit at every angle of incidence."""
        self.check(compare("sphere_sss_node", lambda r, s: scenes.sphere_scene(r, s, shader='SSS')), (0, 1, 2))

    # Blender 3.x's Principled BSDF (v1) adds a retro-reflection lobe and weights the walk's exit
    # by 1 - (1 - cos)^5 / 2: the add-on exports it with DWV_SUBSURFACE_EXIT_PRINCIPLED_V1 (in 4.x
    # the Principled walk has the plain Lambertian exit, which the add-on exports there).
    def test_front_lit_sphere_principled(self):
        self.check(compare("sphere_principled", scenes.sphere_scene), (0, 1, 2))

    # Its diffuse without subsurface (Subsurface = 0) is Cycles' PRINCIPLED_DIFFUSE_FULL in 3.x:
    # Fresnel-weighted Lambertian plus retro-reflection; at roughness 1 on this sphere it is 8%
    # brighter than a plain Lambertian surface, so the 3% test on the means tells them apart.
    # Pixel by pixel, a nearly noise-free diffuse surface also shows the shadow terminator of the
    # smooth-shaded low-poly sphere: it matches only because dwivedi, as Cycles, moves the shadow
    # rays of smooth-shaded triangles near the terminator onto a smooth surface (Cycles' "Shadow
    # Terminator > Geometry Offset"; without it the ratio is 6.1, docs/cycles-conventions.md).
    def test_front_lit_sphere_principled_diffuse(self):
        self.check(compare("sphere_diffuse", lambda r, s: scenes.sphere_scene(r, s, shader='DIFFUSE')), (0, 1, 2))

    # The same with the object's geometry offset at 0: Cycles' shadow rays then leave from the flat
    # triangles, and the add-on exports the setting (dwv_mesh_t.shadow_terminator_geometry_offset).
    def test_front_lit_sphere_principled_diffuse_without_terminator_offset(self):
        def build(resolution, samples):
            scene = scenes.sphere_scene(resolution, samples, shader='DIFFUSE')
            bpy.data.objects["Sphere"].cycles.shadow_terminator_geometry_offset = 0.0
            return scene
        self.check(compare("sphere_diffuse_offset_0", build), (0, 1, 2))

    def display_pngs(self):
        """Our display PNG and Blender's save_render of the same linear pixels (the add-on's float
        image), Filmic with a look, exposure and gamma; returns both as RGBA lists (0..1)."""
        if "display" in self.__class__.__dict__.get("_cache", {}):
            return self.__class__._cache["display"]
        scene = scenes.sphere_scene(16, 4)
        view = scene.view_settings
        view.view_transform = 'Filmic'
        view.look = 'Medium High Contrast'  # named as in Blender's OCIO config; passed on as is
        view.exposure = 1.5
        view.gamma = 1.3
        scene.display_settings.display_device = 'sRGB'
        scene.render.dither_intensity = 0.0
        # Film > Transparent: the sphere's edge pixels keep their coverage as alpha (opaque film
        # makes every pixel's alpha 1, as Cycles').
        scene.render.film_transparent = True
        scene.render.image_settings.file_format = 'PNG'
        scene.render.image_settings.color_mode = 'RGBA'
        scene.render.image_settings.color_depth = '8'
        props = scene.dwivedi_bake
        props.samples = 16
        props.output_dir = str(WORK / "display")
        result, error = harness.call_operator()
        self.assertEqual(result, {'FINISHED'}, error)
        ours_png = WORK / "display" / f"{scene.name}_camera.png"
        # The same linear pixels as the EXR, loaded by the add-on into a float image.
        image = bpy.data.images["Dwivedi Camera"]
        blender_png = WORK / "display" / "blender_save_render.png"
        image.save_render(str(blender_png), scene=scene)
        w1, h1, ours = harness.read_pixels(ours_png)
        w2, h2, theirs = harness.read_pixels(blender_png)
        self.assertEqual((w1, h1), (w2, h2))
        self.__class__._cache = {"display": (ours, theirs)}
        return ours, theirs

    def worst(self, ours, theirs, opaque):
        """The largest difference of the colour channels over the (opaque or partly covered)
        pixels, and how many of them there are."""
        worst, count = 0.0, 0
        for p in range(0, len(ours), 4):
            alpha = theirs[p + 3]
            if (alpha >= 1.0) != opaque or alpha <= 0.0:
                continue
            count += 1
            worst = max(worst, *(abs(ours[p + c] - theirs[p + c]) for c in range(3)))
        return worst, count

    def test_display_png_is_blenders_view_transform(self):
        ours, theirs = self.display_pngs()
        worst, count = self.worst(ours, theirs, opaque=True)
        FIGURES["display_png_opaque_max_difference_255"] = worst * 255
        print(f"display PNG, {count} opaque pixels: largest difference {worst * 255:.2f}/255", flush=True)
        self.assertGreater(count, 50, "the comparison sees the object")
        self.assertLessEqual(worst, 1.0 / 255 + 1e-6)

    # PNG colour is not premultiplied: Blender divides by alpha before the view transform, and so
    # does the library (src/output/display.cpp, docs/output.md).
    def test_display_png_partly_covered_pixels(self):
        ours, theirs = self.display_pngs()
        worst, count = self.worst(ours, theirs, opaque=False)
        FIGURES["display_png_partial_max_difference_255"] = worst * 255
        print(f"display PNG, {count} partly covered pixels: largest difference {worst * 255:.2f}/255", flush=True)
        self.assertGreater(count, 0)
        self.assertLessEqual(worst, 1.0 / 255 + 1e-6)


harness.run(CyclesTest)
