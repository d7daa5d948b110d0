"""Image textures against Cycles, headless (the host's Blender 3.4, and through
tests/blender/run_package_tests.py --script test_textures.py the chroots' 4.3 and 5.2: ctest
blender.test_textures, blender.textures.trixie, .sid): a smooth UV sphere whose
Principled BSDF takes its Base Color from a generated colour-grid Image Texture (8-bit sRGB, the
sphere's UV map) and its Normal from a Normal Map node fed by a generated tangent-space normal
map (8-bit Non-Color, through a UV Map node), lit by a sun; once as wax (Blender 3.x Subsurface
0.5: the walk's colour is mix(Base Color, Subsurface Color, 0.5) per entry point; 4.x+ Subsurface
Weight 0.5: half Lambertian, half a walk of the Base Color) and once as diffuse (Subsurface 0). Rendered by Cycles and baked by the add-on (with Cycles' cap of 256
events per walk) twice with different seeds at 32 x 32 (the normal-mapped glossy sphere eight
times), then (harness.compare_seeds):

- mean radiance per channel within 2%;
- per-pixel differences consistent with noise: R = sum (ours - cycles)^2 / sum (var_ours +
  var_cycles), each variance from the seeds, below 1.5 (1 in expectation);
- the texture memory per texel of the exported scene is printed (3 bytes: two 8-bit RGB images).

A Checker Texture on Base Color is evaluated by Blender (an emission bake into a 256 x 256
image, with a warning stating it): means within 2% (its pixels on the checker's edges differ by
the image's blur). And bad input: an Image Texture whose file is missing, a UV Map node naming a UV map the mesh
lacks, a textured object without UV maps, and a float image with a NaN texel each cancel the
bake with a message naming the problem, and nothing is written.
"""
import json
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bpy  # noqa: E402

import harness  # noqa: E402
import scenes  # noqa: E402

WORK = harness.install_addon()
RESOLUTION = 32
CYCLES_SAMPLES = 256       # per seed; two seeds
DWIVEDI_SAMPLES = 128      # per seed; two seeds
MEAN_TOLERANCE = 0.02
NOISE_RATIO_LIMIT = 1.5
CYCLES_EVENT_CAP = 256
FIGURES = {"blender_version": list(bpy.app.version)}


def colour_grid():
    image = bpy.data.images.new("Grid", 64, 64, alpha=False)
    image.generated_type = 'COLOR_GRID'
    image.colorspace_settings.name = 'sRGB'
    return image


def normal_map_image():
    """A tangent-space normal map of bumps: n = normalize(0.35 sin(2 pi 6 u), 0.35 sin(2 pi 3 v), 1)."""
    size = 64
    image = bpy.data.images.new("Bumps", size, size, alpha=False)
    image.colorspace_settings.name = 'Non-Color'
    pixels = []
    for y in range(size):
        for x in range(size):
            u, v = (x + 0.5) / size, (y + 0.5) / size
            n = (0.35 * math.sin(2 * math.pi * 6 * u), 0.35 * math.sin(2 * math.pi * 3 * v), 1.0)
            length = math.sqrt(sum(c * c for c in n))
            pixels.extend([0.5 + 0.5 * c / length for c in n] + [1.0])
    image.pixels.foreach_set(pixels)
    image.pack()
    return image


def textured_sphere(resolution, samples, subsurface, base=True, normal=True):
    scene = scenes.sphere_scene(resolution, samples, shader='PRINCIPLED' if subsurface > 0 else 'DIFFUSE')
    material = bpy.data.objects["Sphere"].data.materials[0]
    tree = material.node_tree
    bsdf = tree.nodes["Principled BSDF"]
    if subsurface > 0:
        # 3.x: Subsurface mixes Subsurface Color into the walk's colour and scales the radius;
        # 4.x+: Subsurface Weight mixes diffuse and subsurface, the walk's colour being Base Color.
        key = "Subsurface Weight" if "Subsurface Weight" in bsdf.inputs else "Subsurface"
        bsdf.inputs[key].default_value = subsurface
    grid = tree.nodes.new("ShaderNodeTexImage")
    grid.image = colour_grid()
    grid.interpolation = 'Linear'
    if base:
        tree.links.new(grid.outputs["Color"], bsdf.inputs["Base Color"])
    bumps = tree.nodes.new("ShaderNodeTexImage")
    bumps.image = normal_map_image()
    bumps.interpolation = 'Closest'
    uv = tree.nodes.new("ShaderNodeUVMap")
    uv.uv_map = bpy.data.objects["Sphere"].data.uv_layers[0].name
    tree.links.new(uv.outputs["UV"], bumps.inputs["Vector"])
    normal_map = tree.nodes.new("ShaderNodeNormalMap")
    normal_map.space = 'TANGENT'
    normal_map.uv_map = uv.uv_map
    tree.links.new(bumps.outputs["Color"], normal_map.inputs["Color"])
    if normal:
        tree.links.new(normal_map.outputs["Normal"], bsdf.inputs["Normal"])
    return scene


def compare(name, build, seeds=(1, 2)):
    scene = build(RESOLUTION, CYCLES_SAMPLES)
    cycles = [harness.cycles_render(scene, seed, CYCLES_SAMPLES, WORK / f"{name}_cycles_{seed}.exr") for seed in seeds]
    # Cycles' own cap of 256 events per walk (BSSRDF_MAX_BOUNCES), as test_fidelity.py.
    ours = [harness.dwivedi_bake(scene, seed, DWIVEDI_SAMPLES, WORK / f"{name}_dwivedi_{seed}", CYCLES_EVENT_CAP)
            for seed in seeds]
    figures = harness.compare_seeds([p for p, _ in cycles], [p for p, _ in ours])
    # The exported scene's texture memory, as the add-on builds it (its own modules and shim).
    addon = harness.addon_module()
    exported = addon.export.export_scene(bpy.context, scene.dwivedi_bake, addon.shim())
    size, texels = exported.scene.texture_memory()
    exported.scene.close()
    figures.update({
        "cycles_seconds": sum(t for _, t in cycles), "dwivedi_seconds": sum(t for _, t in ours),
        "texture_bytes_per_texel": size / texels if texels else None,
        "warnings": [w for w in exported.warnings if "material" in w],
    })
    FIGURES[name] = figures
    print(f"\n{name}: " + json.dumps(figures, indent=1), flush=True)
    (harness.HOME / "texture_figures.json").write_text(json.dumps(FIGURES, indent=2))
    return figures


class TexturesTest(harness.unittest.TestCase):
    def check(self, figures, bytes_per_texel=3.0, per_pixel=True):
        for c in range(3):
            cm, om = figures["cycles_mean_rgb"][c], figures["dwivedi_mean_rgb"][c]
            self.assertGreater(cm, 1e-3, f"channel {c} has signal in Cycles")
            self.assertLess(abs(om / cm - 1.0), MEAN_TOLERANCE, f"channel {'RGB'[c]}: dwivedi {om:.5f} vs Cycles {cm:.5f}")
            if per_pixel:
                self.assertLess(figures["noise_ratio_rgb"][c], NOISE_RATIO_LIMIT,
                                f"channel {'RGB'[c]}: per-pixel differences exceed the noise")
        # Grid (3 bytes a texel, sRGB) and bumps (3 bytes, Non-Color): 3 bytes a texel; an
        # evaluated input is a float RGB image (12 bytes).
        self.assertEqual(figures["texture_bytes_per_texel"], bytes_per_texel)

    def test_textured_diffuse(self):
        self.check(compare("textured_diffuse", lambda r, s: textured_sphere(r, s, 0.0)))

    def test_blackman_harris_pixel_filter(self):
        """Blender's default pixel filter (Film > Pixel Filter: Blackman-Harris, 1.5 px; the
        other scenes here set the box of one pixel) in both renderers: the add-on passes the
        scene's filter, and camera samples are placed by it as Cycles' camera rays are, so the
        colour grid's edges and the silhouette are softened alike."""
        def build(resolution, samples):
            scene = textured_sphere(resolution, samples, 0.0)
            scene.cycles.pixel_filter_type = 'BLACKMAN_HARRIS'
            scene.cycles.filter_width = 1.5
            return scene
        self.check(compare("blackman_harris_filter", build))

    def test_textured_wax(self):
        self.check(compare("textured_wax", lambda r, s: textured_sphere(r, s, 0.5)))

    def test_normal_mapped_glossy(self):
        """A black-based glossy sphere (Roughness 0.35) with the normal map, lit from behind and
        the side: its rim highlight lies where the view is grazing, so 4.x+'s specular normal (kept
        valid for reflection) differs from the mapped one, and the sun lies between their horizons
        at some pixels: each lobe takes its light about its own normal (Strength 1.5, beyond 1:
        each release's strength rule, 3.x's world-space extrapolation, 4.0+'s tangent-space
        scaling). Past the smooth terminator the mapped normal faces the sun: Cycles' shadow ray
        leaves from under the triangle there (its side is the smooth normal's) and the sphere
        shadows it (3.4 was +2.0% with the side taken from the mapped normal)."""
        def build(resolution, samples):
            scene = textured_sphere(resolution, samples, 0.0, base=False)
            tree = bpy.data.objects["Sphere"].data.materials[0].node_tree
            bsdf = tree.nodes["Principled BSDF"]
            bsdf.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
            bsdf.inputs["Roughness"].default_value = 0.35
            # The scenes' materials have no specular layer: Blender's default level here.
            key = "Specular IOR Level" if "Specular IOR Level" in bsdf.inputs else "Specular"
            bsdf.inputs[key].default_value = 0.5
            tree.nodes["Normal Map"].inputs["Strength"].default_value = 1.5
            sun = next(o for o in scene.objects if o.type == 'LIGHT')
            sun.rotation_euler = (math.radians(70.0), 0.0, math.radians(135.0))
            sun.data.energy = 8.0
            return scene
        # Eight seeds: a few highlight pixels hold most of the variance, so a two-seed estimate
        # of it (one degree of freedom a pixel) makes R spread widely on an image that agrees
        # (3.4: 0.34 to 2.36 over four seed pairs; 0.53 from twelve seeds, their pixels' means
        # within 1.4 standard errors of Cycles').
        self.check(compare("normal_mapped_glossy", build, seeds=tuple(range(1, 9))))

    def test_procedural_base_color(self):
        """A Checker Texture on Base Color: evaluated by Blender into an image (an emission bake
        at Texture Bake Size), with a warning that states the size."""
        def build(resolution, samples):
            scene = textured_sphere(resolution, samples, 0.0, base=False, normal=False)
            tree = bpy.data.materials[0].node_tree
            checker = tree.nodes.new("ShaderNodeTexChecker")
            checker.inputs["Scale"].default_value = 6.0
            checker.inputs["Color1"].default_value = (0.9, 0.3, 0.1, 1.0)
            checker.inputs["Color2"].default_value = (0.1, 0.5, 0.8, 1.0)
            coordinates = tree.nodes.new("ShaderNodeTexCoord")
            tree.links.new(coordinates.outputs["UV"], checker.inputs["Vector"])
            tree.links.new(checker.outputs["Color"], tree.nodes["Principled BSDF"].inputs["Base Color"])
            scene.dwivedi_bake.texture_bake_size = 256
            return scene
        figures = compare("procedural_base_color", build)
        # Means only: the pixels on the checker's edges differ by what the 256 x 256 image's
        # bilinear lookup blurs (10 to 30% on those pixels of a nearly noise-free diffuse image).
        self.check(figures, bytes_per_texel=12.0, per_pixel=False)
        self.assertTrue(any("256 x 256" in w for w in figures["warnings"]), figures["warnings"])

    def refused(self, scene, words, name):
        folder = WORK / f"refused_{name}"
        result, error = harness.call_operator(samples=2, output_dir=str(folder))
        self.assertEqual(result, {'CANCELLED'}, f"{name}: the bake should be refused")
        for word in words:
            self.assertIn(word, error or "", f"{name}: the message names the problem")
        written = list(folder.glob("*")) if folder.exists() else []
        self.assertEqual(written, [], f"{name}: nothing is written")
        print(f"{name}: {error.strip().splitlines()[-1] if error else ''}", flush=True)

    def test_missing_image_file(self):
        scene = textured_sphere(8, 2, 0.0)
        grid = bpy.data.materials[0].node_tree.nodes["Image Texture"]
        # An image whose file has gone (as a .blend opened elsewhere has it).
        image = bpy.data.images.new("Gone", 8, 8)
        image.source = 'FILE'
        image.filepath = str(WORK / "no_such_grid.png")
        grid.image = image
        self.refused(scene, ["no_such_grid.png", "missing", "Gone"], "missing_image")

    def test_absent_uv_map(self):
        scene = textured_sphere(8, 2, 0.0)
        tree = bpy.data.materials[0].node_tree
        uv = next(node for node in tree.nodes if node.type == 'UVMAP')
        uv.uv_map = "NoSuchMap"
        tree.nodes["Normal Map"].uv_map = "NoSuchMap"
        self.refused(scene, ["NoSuchMap"], "absent_uv_map")

    def test_object_without_uv_map(self):
        scene = textured_sphere(8, 2, 0.0)
        mesh = bpy.data.objects["Sphere"].data
        while len(mesh.uv_layers):
            mesh.uv_layers.remove(mesh.uv_layers[0])
        self.refused(scene, ["no UV map", "Sphere"], "no_uv_map")

    def test_nan_texel(self):
        scene = textured_sphere(8, 2, 0.0)
        image = bpy.data.images.new("NaN", 4, 4, float_buffer=True)
        pixels = [0.5] * 64
        pixels[5] = float("nan")
        image.pixels.foreach_set(pixels)
        bpy.data.materials[0].node_tree.nodes["Image Texture"].image = image
        self.refused(scene, ["NaN", "image 'NaN'"], "nan_texel")


harness.run(TexturesTest)
