"""Issue 18 item 4: indirect light against Cycles, with the scene's Light Paths (Blender's defaults
12 / 4 / 4 / 12 here, passed by the add-on from scene.cycles). Scenes built here:

- torus: a concave torus of pale wax (Principled BSDF, subsurface, 3.x Fixed Radius / 4.x+
  Random Walk as scenes.principled_material) under an area light with a dim world, seen from
  above at an angle: the inside of the ring lights itself (one bounce was 3.0-3.4% dark);
- ground: the wax sphere (Subsurface Scattering node) resting on a diffuse ground plane under a
  sun: the ground lights the sphere's underside and the sphere the ground.

Each is rendered by Cycles and baked by the add-on with two seeds at 24 x 24 and must agree as
tests/blender/test_fidelity.py requires: mean per channel within 2% where the channel has at
least 5% of the brightest channel's mean, with the standard error of that difference below
0.67% (so that 2% is decidable, 3 sigma), and the noise ratio R (harness.compare_two_seeds) below
1.5 in every channel; no NaN. Figures: DWIVEDI_TEST_HOME/indirect_figures.json.

Planted error (to show the comparison catches what indirect light changes):
DWIVEDI_INDIRECT_PLANTED=one_bounce makes the add-on pass max_bounces 0 (the one-bounce image)
while Cycles keeps its Light Paths; the test must then fail.
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
CYCLES_SAMPLES = int(os.environ.get("DWIVEDI_INDIRECT_CYCLES_SPP", "256"))    # per seed; two seeds
DWIVEDI_SAMPLES = int(os.environ.get("DWIVEDI_INDIRECT_DWIVEDI_SPP", "128"))  # per seed; two seeds
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


def compare(name, build):
    scene = build(RESOLUTION, CYCLES_SAMPLES)
    figures = {**harness.render_and_bake(name, scene, CYCLES_SAMPLES, DWIVEDI_SAMPLES, WORK),
               "resolution": RESOLUTION, "planted": os.environ.get("DWIVEDI_INDIRECT_PLANTED", "")}
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

    def test_subsurface_sphere_on_ground(self):
        self.check(compare("ground", ground_scene))


harness.run(IndirectLightTest)
