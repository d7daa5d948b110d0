"""Issue 18 item 4: indirect light against Cycles, with the scene's Light Paths (Blender's defaults
12 / 4 / 4 / 12 here, passed by the add-on from scene.cycles). Scenes built here:

- torus: a concave torus of pale wax (Principled BSDF, subsurface, 3.x Fixed Radius / 4.x+
  Random Walk as scenes.principled_material) under an area light with a dim world, seen from
  above at an angle: the inside of the ring lights itself (one bounce was 3.0-3.4% dark);
- thick_torus: tools/benchmark_scenes.py's torus (major radius 0.3, minor 0.1, 64 x 24 segments,
  smooth, turned 60 degrees about x; the Subsurface Scattering node of colour 0.92 / 0.88 / 0.78,
  radius 1 / 0.8 / 0.6 x 0.05; a disc area light of 15 W, 0.4 m, from the front and above; world
  0.05; Light Paths 4 / 4, as scenes._reset): 25-42 mean free paths thick at single-scattering
  albedo 0.9987 / 0.9969 / 0.9883, so that some walks (3-7%, `dwivedi estimate` on a sphere and a
  slab of its thickness) outlast Cycles' 256 events; the bakes end them there as Cycles does
  (harness.render_and_bake's event cap). Uncapped, the benchmark report found it 2.8% / 1.6% /
  0.2% brighter than Cycles 3.4 in R / G / B (capped: 0.06% / 0.27% / 0.16%, 32 x 32, 1024 / 512 spp);
- ground: the wax sphere (Subsurface Scattering node) resting on a diffuse ground plane under a
  sun: the ground lights the sphere's underside and the sphere the ground;
- mirror: a wax sphere (Principled subsurface) above a mirror-sharp plane (Principled, Roughness
  0, black base: the specular layer alone, 3.x Specular 1 / 4.x+ IOR 2.5) under a sun and a
  coloured world: the camera sees the world and the lit sphere in the mirror (Cycles' singular
  reflection), and the mirror lights the sphere's underside with the world. Reflective caustics
  on (Blender's default; scenes._reset turns them off), once with Filter Glossy 0 (the mirror
  stays a mirror at every bounce) and once with Blender's default 1.0 (after the sphere's exit,
  a bounce of pdf cos / pi, the mirror is GGX of alpha >= 0.41: Cycles is +0.80 / +0.32 / +0.04%
  brighter, and without the blur dwivedi's noise ratio against it was 4.5 in red, 3.4).

Each is rendered by Cycles and baked by the add-on with two seeds at 24 x 24 (the mirror scenes
four seeds at 48 x 48, see their tests) and must agree as tests/blender/test_fidelity.py
requires: mean per channel within 2% where the channel has at least 5% of the brightest
channel's mean, with the standard error of that difference below 0.67% (so that 2% is
decidable, 3 sigma), and the noise ratio R (harness.compare_seeds) below 1.5 in every channel;
no NaN. Figures: DWIVEDI_TEST_HOME/indirect_figures.json, with each channel's effective pixels
(R's spread). DWIVEDI_INDIRECT_SEEDS (comma-separated) replaces every test's seeds for a diagnosis
run (run_package_tests.py --keep-scratch keeps the images).

Planted error (to show the comparison catches what indirect light changes):
DWIVEDI_INDIRECT_PLANTED=one_bounce makes the add-on pass max_bounces 0 (the one-bounce image)
while Cycles keeps its Light Paths; the test must then fail. DWIVEDI_INDIRECT_PLANTED=no_blur makes
it pass blur_glossy 0 while Cycles blurs: test_mirror_at_default_filter_glossy must then fail.
DWIVEDI_INDIRECT_PLANTED=uncapped bakes the thick torus with the add-on's default Walk Event Cap
(10^6) while Cycles stops at 256: test_thick_torus_at_cycles_event_cap must then fail (red).
DWIVEDI_INDIRECT_ONLY (test names, comma-separated) runs only those, for a diagnosis run.
"""
import json
import math
import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bpy  # noqa: E402

import harness  # noqa: E402
import scenes  # noqa: E402

harness.preload_scratch_dependencies()  # run_package_tests.py's scratch set-up, if any
WORK = harness.install_addon()
RESOLUTION = int(os.environ.get("DWIVEDI_INDIRECT_RESOLUTION", "24"))
CYCLES_SAMPLES = int(os.environ.get("DWIVEDI_INDIRECT_CYCLES_SPP", "256"))    # per seed
DWIVEDI_SAMPLES = int(os.environ.get("DWIVEDI_INDIRECT_DWIVEDI_SPP", "128"))  # per seed
SEEDS = tuple(int(seed) for seed in os.environ.get("DWIVEDI_INDIRECT_SEEDS", "").split(",") if seed)
MEAN_TOLERANCE = 0.02
ERROR_LIMIT = MEAN_TOLERANCE / 3.0
NOISE_RATIO_LIMIT = 1.5
SIGNAL_FRACTION = 0.05
FIGURES = {"blender_version": list(bpy.app.version)}

if os.environ.get("DWIVEDI_INDIRECT_PLANTED") == "one_bounce":
    export = harness.addon_module("export")
    real_light_paths = export.light_paths

    def one_bounce(scene, version=None):
        return {**real_light_paths(scene, version), "max_bounces": 0}

    export.light_paths = one_bounce
elif os.environ.get("DWIVEDI_INDIRECT_PLANTED") == "no_blur":
    export = harness.addon_module("export")
    real_light_paths = export.light_paths

    def no_blur(scene, version=None):
        return {**real_light_paths(scene, version), "blur_glossy": 0.0}

    export.light_paths = no_blur


def empty_scene(resolution, samples):
    """scenes._reset's Cycles settings with Blender's default Light Paths (it sets fewer for its
    one-object scenes)."""
    scene = scenes._reset()
    scene.cycles.max_bounces = 12
    scene.cycles.diffuse_bounces = 4
    scene.cycles.glossy_bounces = 4
    scene.cycles.transmission_bounces = 12
    scene.cycles.min_light_bounces = 0
    scene.render.resolution_x = scene.render.resolution_y = resolution
    scene.cycles.samples = samples
    return scene


def torus_scene(resolution, samples):
    scene = empty_scene(resolution, samples)
    material = scenes.principled_material("Pale wax", (0.9, 0.85, 0.75), (0.3, 0.2, 0.12), scale=0.1)
    bpy.ops.mesh.primitive_torus_add(major_radius=1.0, minor_radius=0.45, major_segments=48, minor_segments=16)
    torus = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    torus.data.materials.append(material)
    data = bpy.data.lights.new("Area", 'AREA')
    data.energy = 300.0
    data.size = 1.0
    area = bpy.data.objects.new("Area", data)
    area.location = (0.6, -0.4, 2.5)
    scene.collection.objects.link(area)
    scenes.set_world(scene, (0.05, 0.05, 0.06), 1.0)
    scenes._camera(scene, (0.0, -3.2, 3.0), (math.radians(47.0), 0.0, 0.0), lens=40.0)
    return scene


def thick_torus_scene(resolution, samples):
    """tools/benchmark_scenes.py's torus (built here with Blender's own torus: the test scripts
    run without the tools folder), scenes._reset's Light Paths (4 total, 4 diffuse) as there."""
    from mathutils import Vector
    scene = scenes._reset()
    scene.render.resolution_x = scene.render.resolution_y = resolution
    scene.cycles.samples = samples
    material = scenes.sss_node_material("Thick wax", (0.92, 0.88, 0.78), (1.0, 0.8, 0.6), scale=0.05)
    bpy.ops.mesh.primitive_torus_add(major_radius=0.3, minor_radius=0.1, major_segments=64, minor_segments=24,
                                     rotation=(math.radians(60.0), 0.0, 0.0))
    torus = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    torus.data.materials.append(material)

    def aim(obj, eye):  # -z toward the origin, as benchmark_scenes._aim
        obj.location = eye
        obj.rotation_euler = (-Vector(eye)).to_track_quat('-Z', 'Y').to_euler()

    data = bpy.data.lights.new("Area", 'AREA')
    data.shape = 'DISK'
    data.size = 0.4
    data.energy = 15.0
    area = bpy.data.objects.new("Area", data)
    aim(area, (0.3, -0.9, 0.9))
    scene.collection.objects.link(area)
    scenes.set_world(scene, (1.0, 1.0, 1.0), 0.05)
    camera = scenes._camera(scene, (0.0, -1.6, 0.5), (0.0, 0.0, 0.0), lens=50.0)
    aim(camera, (0.0, -1.6, 0.5))
    return scene


def ground_scene(resolution, samples):
    scene = empty_scene(resolution, samples)
    wax = scenes.sss_node_material("Wax", (0.9, 0.6, 0.4), (0.5, 0.25, 0.1), scale=0.3)
    bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=0.6, location=(0.0, 0.0, 0.6))
    sphere = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    sphere.data.materials.append(wax)
    bpy.ops.mesh.primitive_plane_add(size=6.0)
    bpy.context.active_object.data.materials.append(scenes.diffuse_material("Ground", (0.8, 0.8, 0.8)))
    scenes._sun(scene, (math.radians(35.0), 0.0, math.radians(30.0)), 3.0)
    scenes.set_world(scene, (0.02, 0.02, 0.03), 1.0)
    scenes._camera(scene, (0.0, -3.0, 1.2), (math.radians(78.0), 0.0, 0.0), lens=45.0)
    return scene


def mirror_material():
    """Principled BSDF of Roughness 0 with a black base: only its specular layer, singular."""
    material = bpy.data.materials.new("Mirror")
    material.use_nodes = True
    inputs = material.node_tree.nodes["Principled BSDF"].inputs
    inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    inputs["Roughness"].default_value = 0.0
    inputs["Metallic"].default_value = 0.0
    if "Specular IOR Level" in inputs:  # Blender 4.x+
        inputs["IOR"].default_value = 2.5
        inputs["Specular IOR Level"].default_value = 0.5
    else:
        inputs["Specular"].default_value = 1.0
        inputs["Subsurface"].default_value = 0.0
        inputs["Sheen"].default_value = 0.0
        inputs["Clearcoat"].default_value = 0.0
    return material


def mirror_scene(resolution, samples, blur_glossy=0.0):
    scene = empty_scene(resolution, samples)
    scene.cycles.caustics_reflective = True
    scene.cycles.blur_glossy = blur_glossy  # the add-on passes it on (export.light_paths)
    # Radii well above a quarter of the pixel's footprint (Cycles 4.0-4.3 turn smaller channels
    # Lambertian, by ray differentials that grow through the mirror): at (0.4, 0.2, 0.1) x 0.2,
    # 4.3's blue differed per pixel (noise ratio 1.96) while the means agreed, measured while
    # dwivedi applied the rule at the camera's hit only (it follows the path's differentials now).
    wax = scenes.principled_material("Wax", (0.9, 0.7, 0.5), (0.6, 0.4, 0.25), scale=0.5)
    bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=0.5, location=(0.0, 0.6, 0.7))
    sphere = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    sphere.data.materials.append(wax)
    bpy.ops.mesh.primitive_plane_add(size=8.0)
    bpy.context.active_object.data.materials.append(mirror_material())
    scenes._sun(scene, (math.radians(40.0), 0.0, math.radians(-30.0)), 3.0)
    scenes.set_world(scene, (0.25, 0.4, 0.7), 1.0)
    scenes._camera(scene, (0.0, -2.6, 1.1), (math.radians(80.0), 0.0, 0.0), lens=32.0)
    return scene


def compare(name, build, samples_scale=1.0, event_cap=256, seeds=(1, 2), resolution_scale=1):
    cycles_samples = round(samples_scale * CYCLES_SAMPLES)
    dwivedi_samples = round(samples_scale * DWIVEDI_SAMPLES)
    seeds = SEEDS or seeds
    scene = build(resolution_scale * RESOLUTION, cycles_samples)
    figures = {**harness.render_and_bake(name, scene, cycles_samples, dwivedi_samples, WORK, event_cap, seeds),
               "event_cap": event_cap, "seeds": list(seeds),
               "resolution": resolution_scale * RESOLUTION, "planted": os.environ.get("DWIVEDI_INDIRECT_PLANTED", "")}
    FIGURES[name] = figures
    print(f"\n{name}: " + json.dumps(figures, indent=1), flush=True)
    (harness.HOME / "indirect_figures.json").write_text(json.dumps(FIGURES, indent=2))
    return figures


class IndirectLightTest(harness.unittest.TestCase):
    def check(self, figures):
        self.assertEqual(figures["nan_pixels"], 0)
        brightest = max(figures["cycles_mean_rgb"])
        for c in range(3):
            cm, om = figures["cycles_mean_rgb"][c], figures["dwivedi_mean_rgb"][c]
            self.assertLess(figures["noise_ratio_rgb"][c], NOISE_RATIO_LIMIT,
                            f"channel {'RGB'[c]}: per-pixel differences exceed the noise")
            if cm < SIGNAL_FRACTION * brightest:
                continue
            self.assertLess(figures["relative_standard_error_rgb"][c], ERROR_LIMIT,
                            f"channel {'RGB'[c]}: too noisy to decide 2%")
            self.assertLess(abs(om / cm - 1.0), MEAN_TOLERANCE, f"channel {'RGB'[c]}: dwivedi {om:.5f} vs Cycles {cm:.5f}")

    def test_concave_wax_torus(self):
        self.check(compare("torus", torus_scene))

    def test_thick_torus_at_cycles_event_cap(self):
        uncapped = os.environ.get("DWIVEDI_INDIRECT_PLANTED") == "uncapped"
        self.check(compare("thick_torus", thick_torus_scene, event_cap=0 if uncapped else 256))

    def test_subsurface_sphere_on_ground(self):
        self.check(compare("ground", ground_scene))

    # The mirror scenes at twice the resolution with four seeds of half the samples (the same
    # samples in all): the world and its reflection are nearly noise-free, so at 24 x 24 the
    # sphere's ~20 pixels held the noise ratio's variance (effective_pixels 15-20) and R's spread
    # where the images agree was about 0.49 with two seeds, 1.5 one standard deviation away:
    # Cycles 4.3 against itself (seeds 5-6 against 7-8) gave 2.07, and CI failed twice on 5.2
    # (blue 1.58, 1.52) with means within 0.07%. At 48 x 48, effective_pixels 100-130 and k = 4
    # (harness.compare_seeds): a spread of about 0.15, 1.5 three of them above 1; 4.3 with 8
    # seeds there: 1.06 / 1.09 / 1.19 and 1.03 / 1.05 / 1.20 (Filter Glossy 1).
    def test_mirror_reflects_world_and_sphere(self):
        self.check(compare("mirror", mirror_scene, samples_scale=0.5, seeds=(1, 2, 3, 4), resolution_scale=2))

    def test_mirror_at_default_filter_glossy(self):
        # Blender's default Filter Glossy 1.0: the mirror seen after the sphere's exit is blurred.
        self.check(compare("mirror_blur", lambda r, s: mirror_scene(r, s, blur_glossy=1.0), samples_scale=0.5,
                           seeds=(1, 2, 3, 4), resolution_scale=2))


ONLY = [name for name in os.environ.get("DWIVEDI_INDIRECT_ONLY", "").split(",") if name]
for _name in [name for name in vars(IndirectLightTest) if name.startswith("test_")]:
    if ONLY and _name not in ONLY:
        delattr(IndirectLightTest, _name)
harness.run(IndirectLightTest)
