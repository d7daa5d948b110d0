"""Issue 18, assets through the add-on (Blender on the host, small and fast):

- an object with two materials whose Base Colors come from procedural trees (Checker Textures):
  each material is evaluated by Blender into its own image on its own faces (evaluate.py), and
  the bake agrees with the same object of constant colours (means within 2%; a mix-up of the two
  materials' images moves them by tens of percent);
- a Normal input driven by a procedural tree (a Bump node of Distance 0.1 fed by a Wave
  Texture): its height evaluated by Blender (256 x 256) and bound as the library's bump; against
  Cycles, means within 2% (measured 0.3%; figures printed), and the bump moves Cycles' own mean
  by 11%, more than the tolerance (the test can fail). Distance 0.3: test_evaluate.py;
- the farm export's scene file of a scene with evaluated and image textures and an HDRI world
  bakes the same bits as the add-on's scene in memory;
- bad input: an image whose file is not an image (0 x 0 pixels) cancels the bake with a message
  naming it, nothing written; an HDRI of 1 x 1 bakes as the constant world of its colour (to 1e-6
  of each pixel: the operator's bakes vary in the last bits run to run) and one of 100000 x 1 bakes.
"""
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bpy  # noqa: E402

import harness  # noqa: E402
import scenes  # noqa: E402

WORK = harness.install_addon()


def checker(tree, colour):
    node = tree.nodes.new("ShaderNodeTexChecker")
    node.inputs["Color1"].default_value = colour + (1.0,)
    node.inputs["Color2"].default_value = colour + (1.0,)
    coordinates = tree.nodes.new("ShaderNodeTexCoord")
    tree.links.new(coordinates.outputs["UV"], node.inputs["Vector"])
    return node


def two_material_sphere(procedural):
    scene = scenes.sphere_scene(16, 16, shader='DIFFUSE')
    sphere = bpy.data.objects["Sphere"]
    first = sphere.data.materials[0]
    second = first.copy()
    second.name = "Clay Blue"
    sphere.data.materials.append(second)
    for polygon in sphere.data.polygons:
        polygon.material_index = 1 if polygon.center.z > 0.0 else 0
    for material, colour in ((first, (0.8, 0.3, 0.1)), (second, (0.1, 0.3, 0.8))):
        bsdf = material.node_tree.nodes["Principled BSDF"]
        if procedural:
            tree = material.node_tree
            tree.links.new(checker(tree, colour).outputs["Color"], bsdf.inputs["Base Color"])
        else:
            bsdf.inputs["Base Color"].default_value = colour + (1.0,)
    scene.dwivedi_bake.texture_bake_size = 64
    return scene


def means(pixels):
    n = len(pixels) // 4
    return [sum(pixels[c::4]) / n for c in range(3)]


def bumped_sphere(resolution, samples, bump=True):
    scene = scenes.sphere_scene(resolution, samples, shader='DIFFUSE')
    material = bpy.data.objects["Sphere"].data.materials[0]
    tree = material.node_tree
    if bump:
        wave = tree.nodes.new("ShaderNodeTexWave")
        wave.inputs["Scale"].default_value = 2.0
        node = tree.nodes.new("ShaderNodeBump")
        node.inputs["Strength"].default_value = 1.0
        node.inputs["Distance"].default_value = 0.1
        tree.links.new(wave.outputs["Fac"], node.inputs["Height"])
        tree.links.new(node.outputs["Normal"], tree.nodes["Principled BSDF"].inputs["Normal"])
    scene.dwivedi_bake.texture_bake_size = 256
    return scene


class AssetsTest(harness.unittest.TestCase):
    def test_two_materials_evaluated_each(self):
        constant, _ = harness.dwivedi_bake(two_material_sphere(False), 3, 32, WORK / "two_constant")
        scene = two_material_sphere(True)
        addon = harness.addon_module()
        exported = addon.export.export_scene(bpy.context, scene.dwivedi_bake, addon.shim())
        exported.scene.close()
        warned = " ".join(exported.warnings)
        self.assertIn("'Clay'", warned)
        self.assertIn("'Clay Blue'", warned)
        self.assertNotIn("could not be evaluated", warned)
        evaluated, _ = harness.dwivedi_bake(scene, 3, 32, WORK / "two_evaluated")
        a, b = means(constant), means(evaluated)
        print(f"two materials: constant {a}, evaluated {b}", flush=True)
        for c in range(3):
            self.assertLess(abs(b[c] / a[c] - 1.0), 0.02, f"channel {'RGB'[c]}: {b[c]:.5f} vs {a[c]:.5f}")

    def test_procedural_normal(self):
        flat_cycles = means(harness.cycles_render(bumped_sphere(24, 128, bump=False), 1, 128, WORK / "flat_c.exr")[0])
        scene = bumped_sphere(24, 128)
        c = [harness.cycles_render(scene, s, 128, WORK / f"bump_c{s}.exr")[0] for s in (1, 2)]
        addon = harness.addon_module()
        exported = addon.export.export_scene(bpy.context, scene.dwivedi_bake, addon.shim())
        exported.scene.close()
        self.assertTrue(any("the Height of Bump node" in w for w in exported.warnings), exported.warnings)
        o = [harness.dwivedi_bake(scene, s, 64, WORK / f"bump_o{s}")[0] for s in (1, 2)]
        cycles = means([(x + y) / 2 for x, y in zip(*c)])
        ours = means([(x + y) / 2 for x, y in zip(*o)])
        print(f"procedural normal: Cycles {cycles}, dwivedi {ours}, Cycles without the bump {flat_cycles}", flush=True)
        self.assertGreater(max(abs(f / b - 1.0) for f, b in zip(flat_cycles, cycles)), 0.02,
                           "the bump should move the mean by more than the tolerance")
        for ch in range(3):
            self.assertLess(abs(ours[ch] / cycles[ch] - 1.0), 0.02, f"channel {'RGB'[ch]}")

    def test_unreadable_image(self):
        scene = scenes.sphere_scene(8, 2, shader='DIFFUSE')
        broken = WORK / "broken.png"
        broken.write_bytes(b"not a PNG at all")
        tree = bpy.data.objects["Sphere"].data.materials[0].node_tree
        node = tree.nodes.new("ShaderNodeTexImage")
        node.image = bpy.data.images.load(str(broken))
        tree.links.new(node.outputs["Color"], tree.nodes["Principled BSDF"].inputs["Base Color"])
        folder = WORK / "refused_broken"
        result, error = harness.call_operator(samples=2, output_dir=str(folder))
        self.assertEqual(result, {'CANCELLED'})
        self.assertIn("broken.png", error or "")
        self.assertIn("no pixels", error or "")
        self.assertEqual(list(folder.glob("*")) if folder.exists() else [], [])

    def hdri(self, width, height, colour):
        scene = scenes.sphere_scene(8, 4, shader='DIFFUSE')
        image = bpy.data.images.new(f"sky {width}", width, height, float_buffer=True)
        image.pixels.foreach_set(list(colour + (1.0,)) * (width * height))
        tree = scene.world.node_tree
        texture = tree.nodes.new("ShaderNodeTexEnvironment")
        texture.image = image
        background = tree.nodes["Background"]
        background.inputs["Strength"].default_value = 0.5
        tree.links.new(texture.outputs["Color"], background.inputs["Color"])
        return scene

    def test_hdri_sizes(self):
        one, _ = harness.dwivedi_bake(self.hdri(1, 1, (0.25, 0.5, 0.75)), 4, 4, WORK / "hdri_1x1")
        scene = scenes.sphere_scene(8, 4, shader='DIFFUSE')
        scenes.set_world(scene, (0.25, 0.5, 0.75), 0.5)
        constant, _ = harness.dwivedi_bake(scene, 4, 4, WORK / "hdri_constant")
        # The library stores a 1 x 1 map as exactly the constant world (bit for bit in
        # unit.test_image_files); the add-on's operator bakes of one scene differ in the last bits
        # of a few pixels from run to run (seen: the same constant-world scene baked twice in one
        # session), so the bound here is 1e-6 of each pixel.
        worst = max(abs(a - b) / max(abs(b), 1e-6) for a, b in zip(one, constant))
        print(f"1 x 1 HDRI vs constant world: largest relative pixel difference {worst:.2g}", flush=True)
        self.assertLess(worst, 1e-6, "a 1 x 1 HDRI is the constant world of its colour")
        wide, _ = harness.dwivedi_bake(self.hdri(100000, 1, (0.3, 0.3, 0.3)), 4, 2, WORK / "hdri_wide")
        self.assertGreater(max(wide), 0.0)

    def test_farm_scene_file_of_a_textured_scene(self):
        """The farm export's scene file (SceneFileWriter) of a scene with evaluated textures, an
        image texture and an HDRI world bakes the same bits as the add-on's scene in memory."""
        scene = two_material_sphere(True)
        grid = bpy.data.images.new("Grid", 16, 16, alpha=False)
        grid.generated_type = 'COLOR_GRID'
        tree = bpy.data.objects["Sphere"].data.materials[0].node_tree
        node = tree.nodes.new("ShaderNodeTexImage")
        node.image = grid
        tree.links.new(node.outputs["Color"], tree.nodes["Principled BSDF"].inputs["Roughness"])
        sky = bpy.data.images.new("sky", 8, 4, float_buffer=True)
        sky.pixels.foreach_set([0.1 + 0.05 * (k % 7) for k in range(4 * 8 * 4)])
        world = scene.world.node_tree
        texture = world.nodes.new("ShaderNodeTexEnvironment")
        texture.image = sky
        world.links.new(texture.outputs["Color"], world.nodes["Background"].inputs["Color"])
        addon = harness.addon_module()
        dwivedi = addon.shim()
        memory = addon.export.export_scene(bpy.context, scene.dwivedi_bake, dwivedi)
        written = addon.export.export_scene(bpy.context, scene.dwivedi_bake, addon.farm._writer_module(dwivedi))
        path = WORK / "farm" / "dwivedi_scene.json"
        path.parent.mkdir(parents=True, exist_ok=True)
        written.scene.write(str(path))
        self.assertTrue((WORK / "farm" / "dwivedi_scene_files").is_dir())
        loaded = dwivedi.Scene.load(str(path))
        import dataclasses
        # Technique Auto's trial picks walk engines by timing (which round differently in the last
        # bits): a named technique and channel walks make the comparison exact.
        options = dataclasses.replace(loaded.settings, width=12, height=12, samples=4, threads=2, seed=9,
                                      technique="classical", channel_walks="shared")
        a, b = memory.scene.bake(options), loaded.bake(options)
        self.assertEqual(bytes(a.rgba), bytes(b.rgba))
        self.assertGreater(a.stats.mean_rgb[0], 0.0)
        memory.scene.close()
        loaded.close()


harness.run(AssetsTest)
