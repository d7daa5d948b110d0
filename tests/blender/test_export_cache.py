"""The add-on's export cache (export.ExportCache, issue 20): a bake after a change follows the
change, and reuses only what did not change.

For each change (a mesh edit, a modifier, a material and a material slot, a transform, a light's
strength and direction, the world, the camera, an object hidden, a light hidden, a mesh shared by two objects
edited, the bake's export settings) the scene is exported through the cache and without it: the
two must hand the library the same scene (every call that builds it, arrays within 1e-6), which
differs from the one before the change (so the change is seen), and the meshes read again are
those the change touched. The Bake operator bakes twice, the second time from the kept scene and
to the same image, and once more after a light changed. Also the mesh export's variants (n-gons, loose edges, a mesh without faces, several
UV maps, several materials, flat / smooth / auto-smooth shading) against a plain per-corner
reading of the same mesh.

    blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_export_cache.py
(through ctest, which sets the user folders and the zip's path: see harness.py)
"""
import array
import hashlib
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bpy  # noqa: E402

import harness  # noqa: E402

WORK = harness.install_addon()


def world_color(world, color):
    if world.use_nodes:
        world.node_tree.nodes["Background"].inputs["Color"].default_value = (*color, 1.0)
    else:
        world.color = color


def build_scene():
    """Two Suzannes (the second subdivided, with two materials), a linked duplicate of a third,
    a sun, a camera, a grey world; 16 x 16 pixels."""
    for collection in (bpy.data.objects, bpy.data.meshes, bpy.data.lights, bpy.data.cameras):
        for block in list(collection):
            collection.remove(block)
    scene = bpy.context.scene
    materials = []
    for name, color in (("skin", (0.9, 0.6, 0.5)), ("lips", (0.8, 0.2, 0.2))):
        material = bpy.data.materials.get(name) or bpy.data.materials.new(name)
        material.use_nodes = True
        node = material.node_tree.nodes["Principled BSDF"]
        node.inputs["Base Color"].default_value = (*color, 1.0)
        weight = node.inputs.get("Subsurface Weight") or node.inputs["Subsurface"]
        weight.default_value = 1.0 if weight.name == "Subsurface Weight" else 0.5
        materials.append(material)
    for k, x in enumerate((-0.7, 0.7)):
        bpy.ops.mesh.primitive_monkey_add(size=0.6, location=(x, 0.0, 0.0))
        obj = bpy.context.active_object
        obj.name = f"monkey{k}"
        bpy.ops.object.shade_smooth()
        obj.data.materials.append(materials[0])
        if k == 1:
            obj.data.materials.append(materials[1])
            obj.data.polygons.foreach_set("material_index", [i % 2 for i in range(len(obj.data.polygons))])
            obj.data.update()
            modifier = obj.modifiers.new("subdivision", 'SUBSURF')
            modifier.levels = modifier.render_levels = 1
    bpy.ops.mesh.primitive_ico_sphere_add(radius=0.25, location=(0.0, 0.0, 0.7))
    shared = bpy.context.active_object
    shared.name = "shared0"
    shared.data.materials.append(materials[0])
    twin = shared.copy()  # a linked duplicate: the same mesh data
    twin.name = "shared1"
    twin.location = (0.0, 0.0, -0.7)
    scene.collection.objects.link(twin)
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", 'SUN'))
    sun.rotation_euler = (0.5, 0.2, 0.3)
    scene.collection.objects.link(sun)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.location = (0.0, -5.0, 0.0)
    camera.rotation_euler = (math.pi / 2, 0.0, 0.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    world = bpy.data.worlds.get("grey") or bpy.data.worlds.new("grey")
    world.use_nodes = False  # Blender 5.x: worlds always use their nodes
    world_color(world, (0.1, 0.1, 0.1))
    scene.world = world
    scene.render.resolution_x = scene.render.resolution_y = 16
    scene.render.resolution_percentage = 100
    props = scene.dwivedi_bake
    props.samples, props.threads, props.seed = 4, 2, 1
    props.output_dir = str(WORK / "out")
    return scene


# What an export hands the library, recorded call by call (the shim's Scene methods that build a
# scene), to compare a cached export with a fresh one.
RECORDED = ("add_material", "add_mesh", "add_light", "set_world", "set_world_environment", "set_camera",
            "add_texture", "bind_texture")


def plain(value):
    """A comparable copy of a call's argument: buffers as lists, objects as their fields."""
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    if hasattr(value, "tolist"):  # array.array, numpy arrays and numbers
        return value.tolist()
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if isinstance(value, dict):
        return {k: plain(v) for k, v in value.items()}
    if hasattr(value, "__dict__") and not hasattr(value, "__len__"):
        return {k: plain(v) for k, v in vars(value).items()}
    return [plain(v) for v in list(value)]


def close(a, b):
    """Equal, floats within 1e-6: Blender's vertex normals of an unchanged evaluated mesh move by
    a unit in the last place when other objects are evaluated again."""
    if isinstance(a, float) and isinstance(b, (int, float)) or isinstance(b, float) and isinstance(a, int):
        return abs(a - b) <= 1e-6 * max(1.0, abs(a), abs(b))
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(close(x, y) for x, y in zip(a, b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(close(a[k], b[k]) for k in a)
    return a == b


def difference(a, b, where="calls"):
    """Where two recordings first differ (for the failure message), else None."""
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        return next((d for d in (difference(x, y, f"{where}[{k}]") for k, (x, y) in enumerate(zip(a, b))) if d), None)
    if isinstance(a, dict) and isinstance(b, dict) and a.keys() == b.keys():
        return next((d for d in (difference(a[k], b[k], f"{where}.{k}") for k in a) if d), None)
    return None if close(a, b) else f"{where}: {str(a)[:200]} != {str(b)[:200]}"


class CacheTest(harness.unittest.TestCase):
    def setUp(self):
        self.export = harness.addon_module("export")
        self.shim = harness.addon_module().shim()
        self.export.CACHE.clear()
        self.scene = build_scene()
        self.read = []  # the objects whose meshes the export read from Blender
        self.calls = []  # what the export handed the library
        self.saved = [(self.export, "_mesh_arrays", self.export._mesh_arrays)]
        self.saved += [(self.shim.Scene, name, getattr(self.shim.Scene, name)) for name in RECORDED]
        owner = self

        def counted(mesh, *args, **kwargs):
            owner.read.append(mesh.name)
            return owner.saved[0][2](mesh, *args, **kwargs)
        self.export._mesh_arrays = counted
        for _, name, method in self.saved[1:]:
            def recorded(scene, *args, _name=name, _method=method, **kwargs):
                owner.calls.append([_name, plain(args), plain(kwargs)])
                return _method(scene, *args, **kwargs)
            setattr(self.shim.Scene, name, recorded)

    def tearDown(self):
        for owner, name, original in self.saved:
            setattr(owner, name, original)
        self.export.CACHE.clear()

    def cached(self):
        """(what the export through the cache handed the library, whether the whole scene was
        the kept one, how many meshes it read)."""
        self.read.clear()
        self.calls.clear()
        exported = self.export.export_scene(bpy.context, self.scene.dwivedi_bake, self.shim, self.export.CACHE)
        self.assertFalse(exported.owned)
        return list(self.calls), exported.reused, len(self.read)

    def fresh(self):
        self.calls.clear()
        self.export.export_scene(bpy.context, self.scene.dwivedi_bake, self.shim).scene.close()
        return list(self.calls)

    def check_change(self, change, meshes_read):
        """After `change`, the export through the cache hands the library what a fresh export
        does, which differs from before the change; `meshes_read` meshes (of the 4 objects)
        were read again, and an unchanged scene is the kept one."""
        before = self.fresh()
        first, _, first_reads = self.cached()
        self.assertEqual(first_reads, 4)
        self.assertIsNone(difference(first, before))
        again, reused, reads = self.cached()
        self.assertEqual((again, reused, reads), ([], True, 0))
        change()
        after, reused, reads = self.cached()
        self.assertFalse(reused)
        self.assertEqual(reads, meshes_read)
        expected = self.fresh()
        self.assertFalse(close(expected, before), "the change did not change the export")
        self.assertIsNone(difference(after, expected), "the cached export differs from a fresh one")
        again, reused, reads = self.cached()
        self.assertEqual((again, reused, reads), ([], True, 0))

    def test_mesh_edit(self):
        def edit():
            self.scene.objects["monkey0"].data.vertices[0].co.z += 0.3
            self.scene.objects["monkey0"].data.transform(__import__("mathutils").Matrix.Scale(1.2, 4))
        self.check_change(edit, 1)

    def test_modifier(self):
        self.check_change(lambda: setattr(self.scene.objects["monkey1"].modifiers[0], "levels", 2), 1)

    def test_material(self):
        node = bpy.data.materials["skin"].node_tree.nodes["Principled BSDF"]
        self.check_change(lambda: setattr(node.inputs["Base Color"], "default_value", (0.2, 0.9, 0.3, 1.0)), 0)

    def test_material_slot(self):
        # The slot belongs to the mesh (its materials): Blender updates the mesh, which is read again.
        def assign():
            self.scene.objects["monkey0"].material_slots[0].material = bpy.data.materials["lips"]
        self.check_change(assign, 1)

    def test_transform(self):
        self.check_change(lambda: setattr(self.scene.objects["monkey0"], "location", (-0.5, 0.0, 0.3)), 0)

    def test_light(self):
        self.check_change(lambda: setattr(self.scene.objects["sun"].data, "energy", 3.0), 0)

    def test_light_direction(self):
        self.check_change(lambda: setattr(self.scene.objects["sun"], "rotation_euler", (1.2, 0.0, 0.0)), 0)

    def test_world(self):
        self.check_change(lambda: world_color(self.scene.world, (0.6, 0.6, 0.8)), 0)

    def test_camera(self):
        self.check_change(lambda: setattr(self.scene.camera.data, "lens", 35.0), 0)

    def test_hidden_object(self):
        self.check_change(lambda: setattr(self.scene.objects["monkey1"], "hide_render", True), 0)

    def test_hidden_light(self):
        # A light disabled in renders is out of Cycles' render: it was exported all the same.
        self.check_change(lambda: setattr(self.scene.objects["sun"], "hide_render", True), 0)

    def test_shared_mesh(self):
        # Both objects of the linked duplicate read their (one) mesh again.
        self.check_change(lambda: self.scene.objects["shared0"].data.transform(
            __import__("mathutils").Matrix.Translation((0.1, 0.0, 0.2))), 2)

    def test_export_settings(self):
        # Not a depsgraph update: the bake's export settings are part of what the kept scene is for.
        self.cached()
        self.scene.dwivedi_bake.world_resolution = 64
        self.assertFalse(self.cached()[1])
        self.scene.render.resolution_x = 12
        calls, reused, _ = self.cached()
        self.assertFalse(reused)
        self.assertIsNone(difference(calls, self.fresh()))

    def test_operator_reuses_the_scene(self):
        calls = []
        original = self.export._export

        def counted(*args, **kwargs):
            calls.append(1)
            return original(*args, **kwargs)
        self.export._export = counted
        try:
            pixels = []
            for _ in range(2):
                result, error = harness.call_operator()
                self.assertEqual(result, {'FINISHED'}, error)
                pixels.append(hashlib.sha256(bytes(array.array("f", harness.image_pixels("Dwivedi Camera")[2])))
                              .hexdigest())
            self.scene.objects["sun"].data.energy = 2.0
            result, error = harness.call_operator()
            self.assertEqual(result, {'FINISHED'}, error)
        finally:
            self.export._export = original
        self.assertEqual(len(calls), 2, "the second bake exported again, or the third did not")
        self.assertEqual(pixels[0], pixels[1], "the same scene and seed baked another image")

    def test_handlers(self):
        module = harness.addon_module()
        for name, handler in module._CACHE_HANDLERS:
            self.assertIn(handler, getattr(bpy.app.handlers, name))
            self.assertIn("_bpy_persistent", handler.__dict__, f"{name} handler is not persistent")


def corner_reference(mesh):
    """Every triangle corner's position and normal, read one by one from Blender's API."""
    mesh.calc_loop_triangles()
    if hasattr(mesh, "calc_normals_split"):
        mesh.calc_normals_split()
    positions, normals = [], []
    for tri in mesh.loop_triangles:
        for k in range(3):
            positions.append(tuple(mesh.vertices[tri.vertices[k]].co))
            normals.append(tuple(tri.split_normals[k]))
    return positions, normals


def unpack(arrays):
    """The corners' positions and normals (or None: flat) of an _mesh_arrays result."""
    p, i = list(arrays["positions"]), list(arrays["indices"])
    n = None if arrays["normals"] is None else list(arrays["normals"])
    positions = [tuple(p[3 * v:3 * v + 3]) for v in i]
    normals = None if n is None else [tuple(n[3 * v:3 * v + 3]) for v in i]
    return positions, normals


class MeshVariantsTest(harness.unittest.TestCase):
    def setUp(self):
        self.export = harness.addon_module("export")
        self.gather = harness.addon_module("gather")

    def mesh(self, vertices, edges, faces, smooth=True):
        mesh = bpy.data.meshes.new("variant")
        mesh.from_pydata(vertices, edges, faces)
        mesh.polygons.foreach_set("use_smooth", [smooth] * len(mesh.polygons))
        mesh.update()
        return mesh

    def check(self, mesh, want_uvs=False):
        for use_numpy in ((True, False) if self.gather.numpy is not None else (False,)):
            rows, groups = self.gather.rows, self.gather.groups
            try:
                if not use_numpy:  # the standard-library path, also where numpy is present
                    self.gather.rows = lambda *a, **k: rows(*a, **{**k, "use_numpy": False})
                    self.gather.groups = lambda *a, **k: groups(*a, **{**k, "use_numpy": False})
                arrays = self.export._mesh_arrays(mesh, want_uvs=want_uvs)
            finally:
                self.gather.rows, self.gather.groups = rows, groups
            positions, normals = unpack(arrays)
            reference_positions, reference_normals = corner_reference(mesh)
            self.assertEqual(positions, reference_positions)
            if normals is not None:
                for got, want in zip(normals, reference_normals):
                    self.assertTrue(all(abs(a - b) < 1e-6 for a, b in zip(got, want)), (got, want))
            else:  # flat: every face flat
                self.assertFalse(any(p.use_smooth for p in mesh.polygons))
            material = list(arrays["material_index"])
            self.assertEqual(material, [t.material_index for t in mesh.loop_triangles])
            if want_uvs:
                layer = mesh.uv_layers.active.data
                expected = [c for t in mesh.loop_triangles for k in range(3) for c in layer[t.loops[k]].uv]
                self.assertEqual(list(arrays["uvs"]), expected)
        return arrays

    def test_ngons_and_loose_edges(self):
        ring = [(math.cos(a), math.sin(a), 0.0) for a in (2 * math.pi * k / 7 for k in range(7))]
        mesh = self.mesh(ring + [(0.0, 0.0, 1.0), (2.0, 0.0, 0.0), (3.0, 0.0, 0.0)], [(8, 9)],
                         [tuple(range(7))] + [(k, (k + 1) % 7, 7) for k in range(7)])
        arrays = self.check(mesh)
        self.assertEqual(arrays["triangles"], 5 + 7)

    def test_no_faces(self):
        mesh = self.mesh([(0, 0, 0), (1, 0, 0), (1, 1, 0)], [(0, 1), (1, 2)], [])
        arrays = self.export._mesh_arrays(mesh, want_uvs=False)
        self.assertEqual(arrays["triangles"], 0)

    def test_flat_mixed_and_auto_smooth(self):
        bpy.ops.mesh.primitive_cube_add()
        cube = bpy.context.active_object.data
        self.check(cube)  # flat
        cube.polygons[0].use_smooth = True
        cube.update()
        self.check(cube)  # mixed: corner normals
        for polygon in cube.polygons:
            polygon.use_smooth = True
        cube.update()
        self.check(cube)  # smooth: vertex normals shared
        if hasattr(cube, "use_auto_smooth"):  # Blender < 4.1
            cube.use_auto_smooth = True
            cube.update()
            self.check(cube)

    def test_uv_layers_and_materials(self):
        bpy.ops.mesh.primitive_monkey_add()
        mesh = bpy.context.active_object.data
        mesh.uv_layers.new(name="second")
        data = mesh.uv_layers["second"].data
        data.foreach_set("uv", [v * 0.5 for v in range(2 * len(data))])
        mesh.uv_layers.active = mesh.uv_layers["second"]
        mesh.polygons.foreach_set("material_index", [i % 3 for i in range(len(mesh.polygons))])
        mesh.update()
        arrays = self.check(mesh, want_uvs=True)
        keep = [t for t, m in enumerate(arrays["material_index"]) if m == 2]
        part = self.export._subset(arrays, array.array("I", keep))
        self.assertEqual(list(part["indices"]), [v for t in keep for v in arrays["indices"][3 * t:3 * t + 3]])
        self.assertEqual(list(part["uvs"]), [v for t in keep for v in arrays["uvs"][6 * t:6 * t + 6]])


if __name__ == "__main__":
    harness.run(CacheTest, MeshVariantsTest)
