"""Inputs Blender evaluates into images (blender_addon/dwivedi_bake/evaluate.py), headless: the
host's Blender 3.4 (ctest blender.test_evaluate) and through tests/blender/run_package_tests.py
--script test_evaluate.py the chroots' 4.3 and 5.2 (blender.evaluate.trixie, .sid):

- a material shared by two objects whose UV layouts differ (one sphere's UVs in the lower left
  quarter of the unit square, the other's in the upper right), its Base Color a Checker Texture
  on the UV map: each object is evaluated on its own UVs and bound to its own image. Against
  Cycles (two seeds each, harness.compare_two_seeds): means within 2% per channel, per-pixel
  noise ratio below 1.5 (1 in expectation). With one evaluation for both (the add-on before
  this test) the second sphere read the first one's image where it has no faces: its colour
  was black, the means 53-55% low (noise ratio 7000-12000);
- which inputs are evaluated once for every object: reads_only_mesh on UV, generated and
  attribute trees (also through a node group) is true, on the world position, a Bump and
  another object's coordinates false; linked duplicates (one mesh, no modifiers) share one
  evaluation, a modifier or a world-position tree makes one per object; an Object Info's
  Random (the copy's, evaluated) is warned about;
- a strong procedural bump (Bump of Distance 0.3 over a Wave Texture, tilts past the 45 degrees
  Blender's normal bake keeps), evaluated by its height at the default settings, and one twice
  as fine: means within 1% of Cycles' (the bump moves them by more than 4%; the normal bake at
  Distance / 16 this replaced was 1.1-2.9% off), and a bump whose height cannot be taken (its
  Strength linked: normal-baked) past that limit is warned about with its share;
- nothing the user had is changed by an evaluation (node trees, links, active and selected
  nodes, slots, selection, active object, render and bake settings, the data-blocks there are),
  and the bake works, with: another slot whose material does not use nodes (5.x: has none), an
  empty slot, a material linked from a library (on another slot, and the evaluated one itself),
  and the scene's bake settings set to what would break the bake (Selected to Active, save to
  files, vertex colours as the target) and a render engine other than Cycles;
- bad input: a material without an output and an object whose bake Blender refuses (no UV map)
  give a clear message, no crash, nothing left behind.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bpy  # noqa: E402

import harness  # noqa: E402
import scenes  # noqa: E402

WORK = harness.install_addon()
COLOURS = ((0.8, 0.3, 0.1), (0.1, 0.3, 0.8))
# The evaluated image's size for the Cycles comparison: its texels hold the checker at their
# centres, so a checker edge is placed to half a texel; at 256 that shift, 1/6 of a pixel here,
# is far above Cycles' noise at the edges (noise ratio 3.4 in red and blue, 0.7 in green where
# the two colours are equal; means within 0.07%).
BAKE_SIZE = 1024


def checker(tree, scale=8.0, coordinates="UV"):
    node = tree.nodes.new("ShaderNodeTexChecker")
    node.inputs["Color1"].default_value = COLOURS[0] + (1.0,)
    node.inputs["Color2"].default_value = COLOURS[1] + (1.0,)
    node.inputs["Scale"].default_value = scale
    source = tree.nodes.new("ShaderNodeTexCoord")
    tree.links.new(source.outputs[coordinates], node.inputs["Vector"])
    return node


def move_uvs(obj, scale, offset):
    for datum in obj.data.uv_layers.active.data:
        datum.uv = (offset[0] + scale * datum.uv[0], offset[1] + scale * datum.uv[1])


def two_spheres(resolution=(48, 24), samples=128):
    """Two spheres of radius 0.6 side by side, separate meshes of one shape whose UV maps are
    moved apart (lower left and upper right quarters), sharing a diffuse material whose Base
    Color is a Checker Texture on the UV map."""
    scene = scenes.sphere_scene(resolution[0], samples, shader='DIFFUSE')
    scene.render.resolution_y = resolution[1]
    first = bpy.data.objects["Sphere"]
    first.scale = (0.6, 0.6, 0.6)
    first.location = (-0.65, 0.0, 0.0)
    second = bpy.data.objects.new("Sphere B", first.data.copy())
    second.scale, second.location = first.scale, (0.65, 0.0, 0.0)
    scene.collection.objects.link(second)
    move_uvs(first, 0.5, (0.0, 0.0))
    move_uvs(second, 0.5, (0.5, 0.5))
    tree = first.data.materials[0].node_tree
    tree.links.new(checker(tree).outputs["Color"], tree.nodes["Principled BSDF"].inputs["Base Color"])
    scene.dwivedi_bake.texture_bake_size = BAKE_SIZE
    return scene


def export(scene):
    addon = harness.addon_module()
    exported = addon.export.export_scene(bpy.context, scene.dwivedi_bake, addon.shim())
    exported.scene.close()
    return exported.warnings


def evaluation_warning(warnings, material):
    found = [w for w in warnings if w.startswith(f"material '{material}'") and "evaluated by Blender" in w]
    return found[0] if found else ""


class SharedMaterialTest(harness.unittest.TestCase):
    def test_two_uv_layouts_against_cycles(self):
        scene = two_spheres()
        warned = evaluation_warning(export(scene), "Clay")
        self.assertIn("2 times", warned)
        figures = harness.render_and_bake("shared", scene, 128, 64, WORK)
        print(f"shared material, two UV layouts: {figures}", flush=True)
        harness.assert_agreement(self, figures)

    def test_reads_only_mesh(self):
        evaluate = harness.addon_module("evaluate")
        scene = scenes.sphere_scene(8, 2, shader='DIFFUSE')
        tree = bpy.data.objects["Sphere"].data.materials[0].node_tree
        base = tree.nodes["Principled BSDF"].inputs["Base Color"]

        def reads_only_mesh(output):
            tree.links.new(output, base)
            return evaluate.reads_only_mesh(base)

        for coordinates in ("UV", "Generated", "Object", "Normal"):
            self.assertTrue(reads_only_mesh(checker(tree, coordinates=coordinates).outputs["Color"]), coordinates)
        for coordinates in ("Camera", "Window", "Reflection"):
            self.assertFalse(reads_only_mesh(checker(tree, coordinates=coordinates).outputs["Color"]), coordinates)
        other = checker(tree, coordinates="Object")
        other.inputs["Vector"].links[0].from_node.object = scene.camera
        self.assertFalse(reads_only_mesh(other.outputs["Color"]), "another object's space")
        noise = tree.nodes.new("ShaderNodeTexNoise")  # its unlinked Vector: generated coordinates
        mix = tree.nodes.new("ShaderNodeMixRGB")
        tree.links.new(noise.outputs["Color"], mix.inputs["Color1"])
        self.assertTrue(reads_only_mesh(mix.outputs["Color"]))
        position = tree.nodes.new("ShaderNodeNewGeometry")
        tree.links.new(position.outputs["Position"], mix.inputs["Color2"])
        self.assertFalse(reads_only_mesh(mix.outputs["Color"]), "the world position")
        attribute = tree.nodes.new("ShaderNodeAttribute")
        attribute.attribute_name = "Col"
        self.assertTrue(reads_only_mesh(attribute.outputs["Color"]))
        attribute.attribute_type = 'OBJECT'
        self.assertFalse(reads_only_mesh(attribute.outputs["Color"]), "an object's property")
        bump = tree.nodes.new("ShaderNodeBump")
        tree.links.new(noise.outputs["Fac"], bump.inputs["Height"])
        normal = tree.nodes["Principled BSDF"].inputs["Normal"]
        tree.links.new(bump.outputs["Normal"], normal)
        self.assertFalse(evaluate.reads_only_mesh(normal), "a Bump's world-space gradient")
        # Through a node group: its output's tree, and its input's link outside.
        group = bpy.data.node_groups.new("Pattern", "ShaderNodeTree")
        inputs = group.nodes.new("NodeGroupInput")
        outputs = group.nodes.new("NodeGroupOutput")
        if hasattr(group, "interface"):
            group.interface.new_socket("Vector", in_out='INPUT', socket_type='NodeSocketVector')
            group.interface.new_socket("Color", in_out='OUTPUT', socket_type='NodeSocketColor')
        else:
            group.inputs.new("NodeSocketVector", "Vector")
            group.outputs.new("NodeSocketColor", "Color")
        inner = group.nodes.new("ShaderNodeTexChecker")
        group.links.new(inputs.outputs[0], inner.inputs["Vector"])
        group.links.new(inner.outputs["Color"], outputs.inputs[0])
        node = tree.nodes.new("ShaderNodeGroup")
        node.node_tree = group
        source = tree.nodes.new("ShaderNodeTexCoord")
        tree.links.new(source.outputs["UV"], node.inputs[0])
        self.assertTrue(reads_only_mesh(node.outputs[0]), "a group of a UV checker")
        tree.links.new(source.outputs["Camera"], node.inputs[0])
        self.assertFalse(reads_only_mesh(node.outputs[0]), "a group fed the camera's coordinates")

    def test_who_shares_an_evaluation(self):
        scene = scenes.sphere_scene(8, 2, shader='DIFFUSE')
        first = bpy.data.objects["Sphere"]
        tree = first.data.materials[0].node_tree
        base = tree.nodes["Principled BSDF"].inputs["Base Color"]
        tree.links.new(checker(tree).outputs["Color"], base)
        twin = first.copy()  # a linked duplicate: the same mesh
        twin.location.x = 2.0
        scene.collection.objects.link(twin)
        scene.dwivedi_bake.texture_bake_size = 32
        self.assertIn("once for its 2 objects", evaluation_warning(export(scene), "Clay"))
        twin.modifiers.new("Wave", 'WAVE')
        self.assertIn("2 times", evaluation_warning(export(scene), "Clay"))
        twin.modifiers.clear()
        tree.links.new(tree.nodes.new("ShaderNodeNewGeometry").outputs["Position"], base)
        warnings = export(scene)
        self.assertIn("2 times", evaluation_warning(warnings, "Clay"))
        self.assertFalse([w for w in warnings if "Object Info" in w], warnings)
        tree.links.new(tree.nodes.new("ShaderNodeObjectInfo").outputs["Random"], base)
        self.assertTrue([w for w in export(scene) if "Object Info node's Random" in w])


# The bound on a bump's mean against Cycles' (issue 18's figures for a Bump-driven normal: 1%).
BUMP_TOLERANCE = 0.01


def bumped_sphere(distance, resolution=24, samples=128, strength_linked=False, size=256, scale=2.0):
    """The diffuse sphere with a Bump node of `distance` fed by a Wave Texture of `scale` on its
    Normal (tilts up to tangents of about 5 x scale x distance); the Bump's Strength from a Value
    node (1) if `strength_linked` (a bump whose height the evaluation cannot take: normal-baked).
    `size`: the Texture Bake Size (256: the add-on's default)."""
    scene = scenes.sphere_scene(resolution, samples, shader='DIFFUSE')
    tree = bpy.data.objects["Sphere"].data.materials[0].node_tree
    wave = tree.nodes.new("ShaderNodeTexWave")
    wave.inputs["Scale"].default_value = scale
    bump = tree.nodes.new("ShaderNodeBump")
    bump.inputs["Distance"].default_value = distance
    if strength_linked:
        value = tree.nodes.new("ShaderNodeValue")
        value.outputs[0].default_value = 1.0
        tree.links.new(value.outputs[0], bump.inputs["Strength"])
    tree.links.new(wave.outputs["Fac"], bump.inputs["Height"])
    tree.links.new(bump.outputs["Normal"], tree.nodes["Principled BSDF"].inputs["Normal"])
    scene.dwivedi_bake.texture_bake_size = size
    return scene


class StrongBumpTest(harness.unittest.TestCase):
    def assert_bump_agrees(self, name, **sphere):
        """bumped_sphere(0.3, **sphere) against Cycles: the bump's mean within BUMP_TOLERANCE of
        Cycles' per channel at the add-on's default Texture Bake Size, and the bump moves Cycles' own mean by more than 4% (the test can
        fail). Means only: per pixel, Cycles' bump takes its finite differences over the pixel's
        footprint (ray differentials), the evaluated height over a texel's, and at these
        resolutions they differ far beyond the noise."""
        flat = harness.cycles_render(bumped_sphere(0.0, **sphere), 1, 128, WORK / f"{name}_flat.exr")[0]
        figures = harness.render_and_bake(name, bumped_sphere(0.3, **sphere), 128, 64, WORK)
        flat_mean = [sum(flat[c::4]) / (len(flat) // 4) for c in range(3)]
        print(f"{name}: {figures}; Cycles without the bump {flat_mean}", flush=True)
        for c in range(3):
            cycles, ours = figures["cycles_mean_rgb"][c], figures["dwivedi_mean_rgb"][c]
            self.assertGreater(abs(flat_mean[c] / cycles - 1.0), 0.04, "the bump moves the mean")
            self.assertLess(abs(ours / cycles - 1.0), BUMP_TOLERANCE, f"channel {'RGB'[c]}: {ours:.5f} vs {cycles:.5f}")

    def test_strong_bump_against_cycles(self):
        """A Bump of Distance 0.3 over a Wave Texture (tilts beyond Blender's normal bake's 45
        degrees), evaluated by its height (at 512 x 512, twice the default Texture Bake Size):
        measured +0.60% (3.4), -0.08% (4.3), +0.35% (5.2). The Distance / 16 normal bake before it
        gave +1.1% / +1.7% / +2.9% at the default 256 x 256 (fails BUMP_TOLERANCE on every
        version); the normal bake as it is, 3.4 +3.8%."""
        self.assert_bump_agrees("bump")

    def test_finer_bump_against_cycles(self):
        """Twice as fine a Wave (tilts up to 80 degrees, 15 texels a period at 512 x 512, the
        height's evaluated size at the default 256), at 64 x 64 pixels: at 24 x 24, 4.3's Cycles
        renders this bump smoother by its pixels' footprints (-2.6% at 24 pixels). Measured +0.12%
        (3.4), +0.37% (4.3), +0.06% (5.2); with the height at 256 x 256 +0.15% / +0.99% / +1.30%
        (fails BUMP_TOLERANCE on 5.2)."""
        self.assert_bump_agrees("fine_bump", resolution=64, scale=4.0)

    def test_bump_at_the_limit_warned(self):
        """The strong bump scaled: no texel at the limit, the warning gives the measured
        differences per size; one the evaluation cannot scale (its Strength linked) tilted past
        the limit: the warning gives the share of texels at the limit; a weak one: none."""
        warnings = export(bumped_sphere(0.3, 8, 2, size=64))
        self.assertFalse([w for w in warnings if "limit" in w], warnings)
        self.assertIn("the Height of Bump node 'Bump' driven by node trees", evaluation_warning(warnings, "Clay"))
        self.assertIn("a strong bump's height evaluated", evaluation_warning(warnings, "Clay"))
        warnings = [w for w in export(bumped_sphere(0.3, 8, 2, strength_linked=True, size=64)) if "limit" in w]
        print(f"unscaled bump: {warnings}", flush=True)
        self.assertEqual(len(warnings), 1, warnings)
        self.assertRegex(warnings[0], r"material 'Clay': [0-9.]+% of the texels of its Normal on object 'Sphere' "
                                      r"are at Blender's normal bake's limit")
        self.assertFalse([w for w in export(bumped_sphere(0.03, 8, 2, strength_linked=True, size=64)) if "limit" in w])


def snapshot():
    """What an evaluation must leave as it was: every material's nodes (names, types, selection,
    locations), links and active node, every object's slots and selection, the active object,
    the render engine, Cycles' samples and bake type and the scene's bake settings, and the
    names of the data-blocks there are."""
    scene, view_layer = bpy.context.scene, bpy.context.view_layer
    state = {"active": view_layer.objects.active.name if view_layer.objects.active else None,
             "engine": scene.render.engine, "samples": scene.cycles.samples, "bake_type": scene.cycles.bake_type}
    bake = scene.render.bake
    state["bake"] = {p.identifier: getattr(bake, p.identifier) for p in bake.bl_rna.properties
                     if not p.is_readonly and p.type != 'POINTER'}
    for kind in ("materials", "images", "objects", "meshes", "node_groups"):
        state[kind] = sorted(i.name_full for i in getattr(bpy.data, kind))
    for material in bpy.data.materials:
        tree = material.node_tree
        state[f"material {material.name_full}"] = (material.use_nodes, None if tree is None else (
            sorted((n.name, n.bl_idname, n.select, tuple(n.location)) for n in tree.nodes),
            sorted((l.from_node.name, l.from_socket.identifier, l.to_node.name, l.to_socket.identifier)
                   for l in tree.links),
            tree.nodes.active.name if tree.nodes.active else None))
    for obj in bpy.data.objects:
        state[f"object {obj.name_full}"] = ([(s.link, s.material.name_full if s.material else None)
                                            for s in obj.material_slots], obj.select_get())
    return state


def library_material(name):
    """A material linked from a library file written here (a node tree that cannot be edited)."""
    material = scenes.diffuse_material(name, (0.2, 0.6, 0.3))
    tree = material.node_tree
    tree.links.new(checker(tree, 4.0).outputs["Color"], tree.nodes["Principled BSDF"].inputs["Base Color"])
    path = WORK / f"{name}.blend"
    bpy.data.libraries.write(str(path), {material})
    bpy.data.materials.remove(material)
    with bpy.data.libraries.load(str(path), link=True) as (_, into):
        into.materials = [name]
    linked = bpy.data.materials[name, str(path)] if bpy.app.version >= (3, 0, 0) else bpy.data.materials[name]
    assert linked.library is not None
    return linked


class UntouchedTest(harness.unittest.TestCase):
    def sphere(self, *make_slots):
        """The sphere with a procedural Base Color on slot 0 and the materials `make_slots` make
        after it, each slot with a band of the sphere's faces."""
        scene = scenes.sphere_scene(8, 2, shader='DIFFUSE')
        slots = [make() for make in make_slots]
        sphere = bpy.data.objects["Sphere"]
        tree = sphere.data.materials[0].node_tree
        tree.links.new(checker(tree).outputs["Color"], tree.nodes["Principled BSDF"].inputs["Base Color"])
        for material in slots:
            sphere.data.materials.append(material)
        count = len(slots) + 1
        for polygon in sphere.data.polygons:
            polygon.material_index = min(count - 1, int((polygon.center.z + 1.0) / 2.0 * count))
        scene.dwivedi_bake.texture_bake_size = 32
        return scene, sphere

    def assert_untouched(self, scene, *materials):
        before = snapshot()
        warnings = export(scene)
        self.assertEqual(snapshot(), before)
        for material in materials:
            self.assertIn("evaluated by Blender into 32 x 32", evaluation_warning(warnings, material), warnings)
        return warnings

    def test_slot_without_nodes(self):
        def plain():
            material = bpy.data.materials.new("Plain")
            material.use_nodes = True  # it has a node tree, which it does not use
            if bpy.app.version >= (5, 0, 0):
                material.node_tree.nodes.clear()  # 5.x materials always use their nodes: none here
            else:
                material.use_nodes = False
            return material

        scene, _ = self.sphere(plain)
        self.assert_untouched(scene, "Clay")

    def test_empty_slot(self):
        scene, _ = self.sphere(lambda: None)
        self.assert_untouched(scene, "Clay")

    def test_library_materials(self):
        scene, sphere = self.sphere(lambda: library_material("Library Green"))
        # Both are evaluated: the local one with the linked one on another slot, and the linked one.
        self.assert_untouched(scene, "Clay", "Library Green")

    def test_object_slots_and_scene_settings(self):
        scene, sphere = self.sphere()
        sphere.material_slots[0].link = 'OBJECT'
        sphere.material_slots[0].material = sphere.data.materials[0]
        bake = scene.render.bake
        bake.use_selected_to_active, bake.save_mode, bake.target, bake.margin = True, 'EXTERNAL', 'VERTEX_COLORS', 17
        scene.render.engine = 'BLENDER_WORKBENCH'
        scene.cycles.samples = 7
        scene.cycles.bake_type = 'AO'
        sphere.select_set(False)
        bpy.context.view_layer.objects.active = scene.camera
        scene.camera.select_set(True)
        self.assert_untouched(scene, "Clay")

    def test_refused_bake(self):
        """An input Blender cannot evaluate: a material without an output, and an object without
        a UV map (Blender's bake refuses it): a clear message, nothing left behind."""
        scene, sphere = self.sphere()
        evaluate = harness.addon_module("evaluate")
        material = sphere.data.materials[0]
        socket = material.node_tree.nodes["Principled BSDF"].inputs["Base Color"]
        before = snapshot()
        material.node_tree.nodes.remove(material.node_tree.nodes["Material Output"])
        with self.assertRaises(evaluate.EvaluationError) as caught:
            evaluate._bake_socket(sphere, material, socket, 16)
        self.assertIn("material 'Clay' has no material output", str(caught.exception))
        material.node_tree.nodes.new("ShaderNodeOutputMaterial").name = "Material Output"
        sphere.data.uv_layers.remove(sphere.data.uv_layers[0])
        with self.assertRaises(evaluate.EvaluationError) as caught:
            evaluate._bake_socket(sphere, material, socket, 16)
        print(f"refused: {caught.exception}", flush=True)
        self.assertIn("Blender could not evaluate 'Base Color' of material 'Clay' on object 'Sphere'",
                      str(caught.exception))
        for kind in ("images", "materials", "objects"):
            self.assertEqual(sorted(i.name_full for i in getattr(bpy.data, kind)), before[kind])

harness.run(SharedMaterialTest, StrongBumpTest, UntouchedTest)
