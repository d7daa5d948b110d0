"""Issue 17: the add-on's bake against this Blender's own Cycles, for every subsurface method of
this Blender's Principled BSDF with its default specular layer (3.x: Principled v1's Specular 0.5
over the walk; 4.x+: the dielectric layer, IOR 1.5, Multiscatter GGX), scenes of
tests/blender/scenes.py:

- default_sphere_<method>: a front-lit smooth sphere (1 m, a sun), the default subsurface
  material, 48 x 48 (in 4.0-4.3 its blue channel falls under Cycles' quarter-pixel rule);
- thin_slab_<method>: a back-lit slab 3 cm thick (Subsurface 0.3, colour 0.9 / 0.7 / 0.5, a sun
  from straight below), orthographic, 32 x 32;
- cube_<method>: a small (0.3 m) flat-shaded cube, Roughness 0.3, a point light and a grey world
  (the specular layer reflects both), perspective, 48 x 48;
- on demand only (DWIVEDI_FIDELITY_ONLY), slab_<method>: the issue's 0.2 m slab, 48 x 48.

Each is rendered by Cycles and baked by the installed add-on with seeds 1 and 2 (Cycles 2 x 256
spp, slabs 2 x 512; dwivedi 2 x 128; the bake with Cycles' cap of 256 events per walk, the
add-on's Walk Event Cap: without it dwivedi keeps the light Cycles loses on the 0.2 m slab,
DWIVEDI_FIDELITY_EVENT_CAP=0), and must agree (harness.compare_two_seeds):
- mean per channel within 2% where the channel has signal (5% of the brightest channel's mean),
  and there the standard error of the difference below 0.67% (a third of the tolerance: else the
  test could not tell 2%);
- per-pixel differences consistent with noise: the noise ratio R = sum (ours - cycles)^2 /
  sum (var_ours + var_cycles) (each two-seed mean's variance from its two seeds) below 1.5 in
  every channel (1 in expectation when the two differ by noise only);
- no NaN, and no warning that a method is not mapped.
Figures: DWIVEDI_TEST_HOME/fidelity_figures.json (with bpy.app.version), and stdout; seconds per
scene in DWIVEDI_TEST_TIMES. Run by tests/blender/run_package_tests.py --script test_fidelity.py
in the host's Blender (3.4) and those of the trixie (4.3) and sid (5.2) chroots (ctest
blender.fidelity.host, .trixie, .sid); DWIVEDI_FIDELITY_RESOLUTION, _CYCLES_SPP, _DWIVEDI_SPP and
_ONLY (test names without test_, comma-separated) change the settings for a diagnosis run.
"""
import json
import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bpy  # noqa: E402

import harness  # noqa: E402
import scenes  # noqa: E402

WORK = harness.install_addon()
RESOLUTION = int(os.environ.get("DWIVEDI_FIDELITY_RESOLUTION", "48"))
SLAB_RESOLUTION = RESOLUTION * 2 // 3
CYCLES_SAMPLES = int(os.environ.get("DWIVEDI_FIDELITY_CYCLES_SPP", "256"))    # per seed; two seeds
DWIVEDI_SAMPLES = int(os.environ.get("DWIVEDI_FIDELITY_DWIVEDI_SPP", "128"))  # per seed; two seeds
MEAN_TOLERANCE = 0.02
SIGNAL_SHARE = 0.05
NOISE_RATIO_LIMIT = 1.5
CYCLES_EVENT_CAP = int(os.environ.get("DWIVEDI_FIDELITY_EVENT_CAP", "256"))
FIGURES = {"blender_version": list(bpy.app.version)}
SECONDS = {}  # per scene: Cycles' two renders and the two bakes


def bake_warnings():
    """The warnings the add-on's export gives for this scene's materials (its own function)."""
    export, dwivedi = harness.addon_module("export"), harness.addon_module("dwivedi")
    warnings = []
    for material in bpy.data.materials:
        export.material_from_blender(material, dwivedi, warnings)
    return warnings


def compare(name, scene, cycles_samples, dwivedi_samples):
    cycles = [harness.cycles_render(scene, seed, cycles_samples, WORK / f"{name}_cycles_{seed}.exr")
              for seed in (1, 2)]
    # Cycles' own cap of 256 events per walk (BSSRDF_MAX_BOUNCES): at the same settings as its render.
    ours = [harness.dwivedi_bake(scene, seed, dwivedi_samples, WORK / f"{name}_dwivedi_{seed}", CYCLES_EVENT_CAP)
            for seed in (1, 2)]
    figures = harness.compare_two_seeds([p for p, _ in cycles], [p for p, _ in ours])
    figures.update({
        "cycles_seconds": sum(t for _, t in cycles), "cycles_samples": 2 * cycles_samples,
        "dwivedi_seconds": sum(t for _, t in ours), "dwivedi_samples": 2 * dwivedi_samples,
        "walk_event_cap": CYCLES_EVENT_CAP, "resolution": scene.render.resolution_x, "warnings": bake_warnings(),
    })
    FIGURES[name] = figures
    print(f"\n{name}: " + json.dumps(figures, indent=1), flush=True)
    (harness.HOME / "fidelity_figures.json").write_text(json.dumps(FIGURES, indent=2))
    SECONDS[name] = round(figures["cycles_seconds"] + figures["dwivedi_seconds"], 1)
    if os.environ.get("DWIVEDI_TEST_TIMES"):
        Path(os.environ["DWIVEDI_TEST_TIMES"]).write_text(json.dumps({"blender": bpy.app.version_string,
                                                                       "seconds": SECONDS}, indent=1))
    return figures


class FidelityTest(harness.unittest.TestCase):
    def check(self, figures):
        self.assertEqual(figures["nan_pixels"], 0)
        self.assertFalse([w for w in figures["warnings"] if "not mapped" in w or "not known" in w],
                         figures["warnings"])
        # Means are compared where a channel has signal: at least SIGNAL_SHARE of the brightest
        # channel's mean (the slabs' deep channels, e.g. the 0.2 m slab's green and blue after 25
        # mean free paths, 4e-4 and 1e-6 against red's 0.02, are judged by the noise ratio alone).
        brightest = max(figures["cycles_mean_rgb"])
        bright = [c for c in range(3) if figures["cycles_mean_rgb"][c] > max(SIGNAL_SHARE * brightest, 1e-3)]
        self.assertTrue(bright, "no channel has signal in Cycles")
        for c in range(3):
            cm = figures["cycles_mean_rgb"][c]
            om = figures["dwivedi_mean_rgb"][c]
            if c in bright:
                # The test's power: the two means' own noise well below the tolerance (3 sigma).
                self.assertLess(figures["relative_standard_error_rgb"][c], MEAN_TOLERANCE / 3,
                                f"channel {'RGB'[c]}: too noisy to judge a {MEAN_TOLERANCE:.0%} difference")
                self.assertLess(abs(om / cm - 1.0), MEAN_TOLERANCE,
                                f"channel {'RGB'[c]}: dwivedi {om:.5f} vs Cycles {cm:.5f}")
            self.assertLess(figures["noise_ratio_rgb"][c], NOISE_RATIO_LIMIT,
                            f"channel {'RGB'[c]}: per-pixel differences exceed the noise")


# Per scene: how it is built for a method, and Cycles' and dwivedi's samples per seed. The slabs
# are uniform images: fewer pixels (SLAB_RESOLUTION), more samples per pixel.
SCENES = {
    "default_sphere": (lambda method: scenes.default_sphere_scene(RESOLUTION, method), CYCLES_SAMPLES,
                       DWIVEDI_SAMPLES),
    "thin_slab": (lambda method: scenes.backlit_slab_scene(SLAB_RESOLUTION, method, thickness=0.03),
                  2 * CYCLES_SAMPLES, DWIVEDI_SAMPLES),
    "cube": (lambda method: scenes.glossy_cube_scene(RESOLUTION, method), CYCLES_SAMPLES, DWIVEDI_SAMPLES),
    # The 0.2 m slab (its 3.4 reproduction, 6.7x too bright in red before, and where
    # Cycles' 256-event cap matters): on demand only (DWIVEDI_FIDELITY_ONLY=slab_random_walk, ...),
    # its walks take minutes to judge 2% (docs/blender-compatibility.md has its figures).
    "slab": (lambda method: scenes.backlit_slab_scene(RESOLUTION, method), 2 * CYCLES_SAMPLES,
             DWIVEDI_SAMPLES),
}


def _make(kind, method):
    def test(self):
        build, cycles_samples, dwivedi_samples = SCENES[kind]
        self.check(compare(f"{kind}_{method.lower()}", build(method), cycles_samples, dwivedi_samples))
    return test


ONLY = os.environ.get("DWIVEDI_FIDELITY_ONLY", "")
for _kind in SCENES:
    for _method in scenes.methods():
        _name = f"test_{_kind}_{_method.lower()}"
        if _name[5:] in ONLY.split(",") or not ONLY and _kind != "slab":
            setattr(FidelityTest, _name, _make(_kind, _method))


class MappingTest(harness.unittest.TestCase):
    """The add-on's table of methods per Blender version (export.subsurface_model, footprint_rule),
    for every release, whichever Blender runs it."""

    def test_methods_per_version(self):
        export = harness.addon_module("export")
        cases = [((3, 4, 1), 'RANDOM_WALK_FIXED_RADIUS', "fixed_radius"),
                 ((3, 6, 0), 'RANDOM_WALK', "blender3_random_walk"),
                 ((4, 2, 0), 'RANDOM_WALK', "blender4_random_walk"),
                 ((4, 3, 2), 'RANDOM_WALK_SKIN', "blender4_skin"),
                 ((5, 1, 0), 'RANDOM_WALK', "blender4_random_walk"),
                 ((5, 2, 2), 'RANDOM_WALK', "blender52_random_walk"),
                 ((5, 2, 2), 'RANDOM_WALK_LEGACY', "blender52_legacy"),
                 ((5, 2, 2), 'RANDOM_WALK_SKIN', "blender52_skin")]
        for version, method, model in cases:
            self.assertEqual(export.subsurface_model(version, method), (model, None), (version, method))
        model, note = export.subsurface_model((4, 3, 0), 'BURLEY')
        self.assertEqual(model, "fixed_radius")
        self.assertIn("Christensen-Burley", note)
        self.assertEqual([export.footprint_rule(v) for v in ((3, 4, 1), (4, 0, 0), (4, 3, 2), (4, 4, 0), (4, 5, 0),
                                                             (5, 2, 2))],
                         [0.0, 0.25, 0.25, 0.0, 0.0, 0.0])


harness.run(FidelityTest, MappingTest)
