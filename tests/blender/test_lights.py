"""Issue 18: point and spot lights of radius > 0 near a small object against Cycles (the host's
Blender 3.4: a disc facing the shaded point; 4.3 and 5.2 through run_package_tests.py
--script test_lights.py: a disc with Soft Falloff, Blender's default, and a sphere without it;
ctest blender.test_lights, blender.lights.trixie, .sid). A diffuse sphere of radius 0.1 m, a
light of Blender's default lamp (1000 W, radius 0.1 m) 0.37 m from its surface (where disc and
sphere differ by 7%), a black world, 24 x 24 pixels; Cycles 2 x 128 spp, dwivedi 2 x 64 spp.
Bounds (harness.compare_two_seeds): mean per channel within 2%, noise ratio below 1.5.
Figures: DWIVEDI_TEST_HOME/lights_figures.json.
"""
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bpy  # noqa: E402

import harness  # noqa: E402
import scenes  # noqa: E402

WORK = harness.install_addon()
RESOLUTION = 24
CYCLES_SAMPLES = 128   # per seed; two seeds
DWIVEDI_SAMPLES = 64   # per seed; two seeds
MEAN_TOLERANCE = 0.02
NOISE_RATIO_LIMIT = 1.5
FIGURES = {"blender_version": list(bpy.app.version)}
BLENDER4 = bpy.app.version >= (4, 0, 0)


def near_light_scene(kind, soft_falloff):
    scene = scenes._reset()
    scene.render.resolution_x = scene.render.resolution_y = RESOLUTION
    bpy.ops.mesh.primitive_uv_sphere_add(segments=32, ring_count=16, radius=0.1)
    sphere = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    sphere.data.materials.append(scenes.diffuse_material("Clay", (0.8, 0.6, 0.5)))
    scenes._camera(scene, (0.0, -1.0, 0.0), (1.5707963267948966, 0.0, 0.0), lens=100.0)
    data = bpy.data.lights.new("Lamp", kind)
    data.energy = 1000.0
    data.shadow_soft_size = 0.1
    if kind == 'SPOT':
        data.spot_size = 1.2
        data.spot_blend = 0.3
    if hasattr(data, "use_soft_falloff"):
        data.use_soft_falloff = soft_falloff
    lamp = bpy.data.objects.new("Lamp", data)
    lamp.location = (0.3, -0.3, 0.2)
    if kind == 'SPOT':
        from mathutils import Vector
        lamp.rotation_euler = (Vector((0.0, 0.0, 0.0)) - lamp.location).to_track_quat('-Z', 'Y').to_euler()
    scene.collection.objects.link(lamp)
    return scene


def compare(name, scene):
    cycles = [harness.cycles_render(scene, seed, CYCLES_SAMPLES, WORK / f"{name}_cycles_{seed}.exr") for seed in (1, 2)]
    ours = [harness.dwivedi_bake(scene, seed, DWIVEDI_SAMPLES, WORK / f"{name}_dwivedi_{seed}") for seed in (1, 2)]
    figures = harness.compare_two_seeds([p for p, _ in cycles], [p for p, _ in ours])
    figures["seconds"] = sum(t for _, t in cycles) + sum(t for _, t in ours)
    FIGURES[name] = figures
    print(f"\n{name}: " + json.dumps(figures, indent=1), flush=True)
    (harness.HOME / "lights_figures.json").write_text(json.dumps(FIGURES, indent=2))
    return figures


class LightsTest(harness.unittest.TestCase):
    def check(self, figures):
        harness.assert_agreement(self, figures, MEAN_TOLERANCE, NOISE_RATIO_LIMIT)
        self.assertEqual(figures["nan_pixels"], 0)

    def test_point_soft_falloff(self):
        """Blender's default lamp: the disc (3.x; 4.0+ with Soft Falloff)."""
        self.check(compare("point_disc", near_light_scene('POINT', True)))

    @harness.unittest.skipUnless(BLENDER4, "Blender 3.x has no sphere lights")
    def test_point_sphere(self):
        self.check(compare("point_sphere", near_light_scene('POINT', False)))

    @harness.unittest.skipUnless(BLENDER4, "Blender 3.x has no sphere lights")
    def test_spot_sphere(self):
        self.check(compare("spot_sphere", near_light_scene('SPOT', False)))


harness.run(LightsTest)
