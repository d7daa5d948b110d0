"""The add-on in headless Blender: it installs and enables from the zip, its settings and panel
register, the operator bakes small scenes (camera and UV) into EXR + PNG and loads the result,
and every failure is reported as an error with CANCELLED, never a crash.

    blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_addon.py
(through ctest, which sets the user folders and the zip's path: see harness.py)
"""
import math
import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bpy  # noqa: E402

import harness  # noqa: E402
import scenes  # noqa: E402

WORK = harness.install_addon()


def small_slab():
    scene = scenes.slab_scene(resolution=16, samples=4)
    props = scene.dwivedi_bake
    props.samples = 4
    props.threads = 2
    props.output_dir = str(WORK / "out")
    return scene


def last_message():
    return sys.modules["dwivedi_bake"]._RUN.message


def last_warnings():
    return sys.modules["dwivedi_bake"]._RUN.warnings


class AddonTest(harness.unittest.TestCase):
    def setUp(self):
        prefs = bpy.context.preferences.addons["dwivedi_bake"].preferences
        prefs.library_path = ""

    def test_registered(self):
        import addon_utils
        self.assertTrue(addon_utils.check("dwivedi_bake")[1], "the add-on is enabled")
        self.assertTrue(hasattr(bpy.types, "DWIVEDI_PT_bake"))
        self.assertEqual(bpy.types.DWIVEDI_PT_bake.bl_context, "render")
        props = bpy.context.scene.dwivedi_bake
        for name in ("target", "technique", "channel_walks", "samples", "time_limit", "threads", "seed", "output_dir",
                     "uv_margin", "load_result"):
            self.assertTrue(hasattr(props, name), name)
        # Nothing about a running bake is scene data (a .blend saved mid-bake would keep it).
        for name in ("running", "progress", "last_result", "last_warnings", "uv_object", "uv_size"):
            self.assertFalse(hasattr(props, name), name)
        self.assertEqual(props.target, 'CAMERA')
        self.assertEqual(props.channel_walks, 'AUTO')
        items = props.bl_rna.properties["channel_walks"].enum_items
        self.assertEqual([item.identifier for item in items], ['AUTO', 'SHARED', 'SEPARATE'])
        for item in items:
            self.assertTrue(item.name and item.description, item.identifier)
        self.assertIn("Dwivedi", bpy.ops.dwivedi.bake.get_rna_type().name)
        module = sys.modules["dwivedi_bake"]
        self.assertEqual(module.bl_info["blender"][:2], (3, 4))
        # The bundled library is the one in use.
        shim = module.shim()
        self.assertTrue(shim.library_path().startswith(str(Path(os.environ["BLENDER_USER_SCRIPTS"]).resolve()))
                        or shim.library_path().startswith(os.environ["BLENDER_USER_SCRIPTS"]), shim.library_path())

    def test_camera_bake(self):
        scene = small_slab()
        result, error = harness.call_operator()
        self.assertEqual(result, {'FINISHED'}, error)
        exr = WORK / "out" / f"{scene.name}_camera.exr"
        png = WORK / "out" / f"{scene.name}_camera.png"
        self.assertTrue(exr.is_file())
        self.assertTrue(png.is_file())
        image = bpy.data.images.get("Dwivedi Camera")
        self.assertIsNotNone(image, "the result is loaded as a Blender image")
        self.assertEqual(tuple(image.size), (16, 16))
        self.assertEqual(exr.read_bytes()[:4], b"\x76\x2f\x31\x01")  # OpenEXR magic
        width, height, pixels = harness.image_pixels("Dwivedi Camera")
        self.assertEqual((width, height), (16, 16))
        self.assertTrue(all(math.isfinite(v) for v in pixels))
        mean_r = sum(pixels[0::4]) / (width * height)
        self.assertGreater(mean_r, 0.0, "light comes through the slab")
        self.assertIn("spp", last_message())
        # The image is the EXR itself (it comes back after save and reopen) and is kept by saving.
        self.assertEqual(image.source, 'FILE')
        self.assertEqual(bpy.path.abspath(image.filepath), str(exr))
        self.assertTrue(image.use_fake_user)
        # Film > Transparent off (scenes' default): the background is opaque, as Cycles'.
        self.assertEqual(min(pixels[3::4]), 1.0)

    def test_every_technique_bakes(self):
        """The Technique items are the library's techniques, in its order, and each bakes the back-lit
        slab (the sheet walk among them) to finite, lit pixels with the technique it names."""
        module = sys.modules["dwivedi_bake"]
        props_items = bpy.context.scene.dwivedi_bake.bl_rna.properties["technique"].enum_items
        self.assertEqual([item.identifier.lower() for item in props_items], list(module.shim().techniques()))
        for item in props_items:
            with self.subTest(technique=item.identifier):
                scene = small_slab()
                scene.dwivedi_bake.technique = item.identifier
                result, error = harness.call_operator()
                self.assertEqual(result, {'FINISHED'}, error)
                width, height, pixels = harness.image_pixels("Dwivedi Camera")
                self.assertTrue(all(math.isfinite(v) for v in pixels))
                self.assertGreater(sum(pixels[0::4]), 0.0, item.identifier)
                if item.identifier != 'AUTO':
                    self.assertIn(item.identifier.lower(), last_message())

    def test_panel_shows_channel_walks_after_technique(self):
        small_slab()

        class Layout:
            """Records the properties a panel draws, in order."""

            def __init__(self):
                self.props = []

            def prop(self, data, name, **options):
                self.props.append(name)

            def column(self, **options):
                return self

            def label(self, **options):
                pass

            def operator(self, *args, **options):
                pass

        layout = Layout()
        sys.modules["dwivedi_bake"].DWIVEDI_PT_bake_advanced.draw_settings(None, layout, bpy.context.scene.dwivedi_bake)
        drawn = layout.props
        self.assertIn("channel_walks", drawn)
        self.assertEqual(drawn.index("channel_walks"), drawn.index("technique") + 1, drawn)

    def test_panel_conventions(self):
        """The Render tab's conventions: the Bake button first, sub-panels closed by default under
        the main one (whose bl_idname other modules name), every setting and technique with a
        tooltip of its own, no raw identifiers as names."""
        module = sys.modules["dwivedi_bake"]
        small_slab()
        items = []

        class Layout:
            scale_y = 1.0
            use_property_split = use_property_decorate = False

            def prop(self, data, name, **options):
                items.append(("prop", name))

            def label(self, text="", icon='NONE', **options):
                items.append(("label", text))

            def operator(self, idname, **options):
                items.append(("operator", idname))

            def row(self, **options):
                return self

            column = box = row

        module.DWIVEDI_PT_bake.draw(type("Panel", (), {"layout": Layout()})(), bpy.context)
        self.assertEqual(items[0], ("operator", "dwivedi.bake"), items)
        self.assertEqual(module.DWIVEDI_PT_bake.bl_idname, "DWIVEDI_PT_bake")
        for panel in (module.DWIVEDI_PT_bake_sampling, module.DWIVEDI_PT_bake_output, module.DWIVEDI_PT_bake_advanced):
            self.assertEqual(panel.bl_parent_id, "DWIVEDI_PT_bake")
            self.assertIn('DEFAULT_CLOSED', panel.bl_options)
        properties = bpy.context.scene.dwivedi_bake.bl_rna.properties
        for prop in properties:
            if prop.identifier == "rna_type" or prop.identifier == "name":
                continue
            self.assertTrue(prop.description and prop.description != prop.name, prop.identifier)
        for enum in ("technique", "channel_walks", "target"):
            for item in properties[enum].enum_items:
                self.assertTrue(item.description, item.identifier)
                self.assertNotIn("_", item.name, item.identifier)

    def test_channel_walks_reach_the_bake(self):
        """The slab's radii differ per channel: Separate walks each channel on its own (the bake
        reports the channel_walks feature), Shared and Auto with an explicit technique walk them
        together. The job is made as the operator makes it; then the operator bakes Separate."""
        scene = small_slab()
        module = sys.modules["dwivedi_bake"]
        props = scene.dwivedi_bake
        props.technique = 'CLASSICAL'
        for choice, separate in (('SEPARATE', True), ('SHARED', False), ('AUTO', False)):
            props.channel_walks = choice
            job = module._Job(bpy.context, props)
            try:
                self.assertEqual(job.bake_settings.channel_walks, choice.lower())
                image = job.dwivedi.bake(job.exported.scene, job.bake_settings)
                try:
                    features = image.stats.features
                    self.assertTrue(all(math.isfinite(v) for v in image.pixels()), choice)
                finally:
                    image.close()
            finally:
                job.close()
            self.assertEqual("channel_walks" in features, separate, (choice, features))
            self.assertEqual("rgb_walks" in features, not separate, (choice, features))
            # The operator's one-line summary says whether the channels walked apart.
            job = module._Job(bpy.context, props)
            try:
                job.start()
                summary = job.finish()
            finally:
                job.close()
            self.assertIn(", classical", summary)
            self.assertEqual("with channel walks" in summary, separate, summary)
        result, error = harness.call_operator(channel_walks='SEPARATE')
        self.assertEqual(result, {'FINISHED'}, error)
        _, _, pixels = harness.image_pixels("Dwivedi Camera")
        self.assertTrue(all(math.isfinite(v) for v in pixels))
        self.assertGreater(max(pixels[0::4]), 0.0, "light comes through the slab")

    # Blender 3.4 takes an EXR with any layered channel name ("x.R") as multilayer and then gives
    # bpy.data.images.load no pixels (size 0 x 0); the library's channel names have no dots.
    def test_exr_opens_in_blender(self):
        scene = small_slab()
        result, error = harness.call_operator()
        self.assertEqual(result, {'FINISHED'}, error)
        width, height, pixels = harness.read_pixels(WORK / "out" / f"{scene.name}_camera.exr")
        self.assertEqual((width, height), (16, 16))
        _, _, ours = harness.image_pixels("Dwivedi Camera")
        self.assertEqual(pixels, ours)
        self.assertGreater(max(pixels[0::4]), 0.0, "the image is not empty")

    def test_render_percentage(self):
        scene = small_slab()
        scene.render.resolution_x = 40
        scene.render.resolution_y = 20
        scene.render.resolution_percentage = 50
        result, error = harness.call_operator()
        self.assertEqual(result, {'FINISHED'}, error)
        width, height, _ = harness.image_pixels("Dwivedi Camera")
        self.assertEqual((width, height), (20, 10))

    def test_uv_bake(self):
        scene = small_slab()
        slab = bpy.data.objects["Slab"]  # the cube primitive comes with a UV map
        image = scenes.bake_image(slab, (32, 24))
        result, error = harness.call_operator(target='UV', uv_margin=2)
        self.assertEqual(result, {'FINISHED'}, error)
        # Into the active Image Texture node's image, at its size, saved as a float EXR.
        exr = WORK / "out" / f"{scene.name}_uv_Slab.exr"
        self.assertTrue(exr.is_file())
        self.assertEqual(image.source, 'FILE')
        self.assertTrue(image.is_float)
        self.assertEqual(bpy.path.abspath(image.filepath), str(exr))
        width, height, pixels = harness.image_pixels(image.name)
        self.assertEqual((width, height), (32, 24))
        covered = sum(1 for a in pixels[3::4] if a > 0.0)
        self.assertGreater(covered, 32 * 24 // 4)
        self.assertGreater(sum(pixels[0::4]), 0.0)
        self.assertIsNone(bpy.data.images.get("Dwivedi UV"), "no image of its own: the user's image")
        width, height, on_disk = harness.read_pixels(exr)
        self.assertEqual((width, height), (32, 24))
        self.assertEqual(on_disk, pixels)

    def test_uv_bake_into_an_8_bit_file_image(self):
        """An 8-bit sRGB image from a file: the baked texels sRGB-encoded, the others kept; saved
        to its own file."""
        small_slab()
        slab = bpy.data.objects["Slab"]
        image = scenes.bake_image(slab, (16, 16), name="Byte", float_buffer=False)
        image.generated_color = (0.0, 0.0, 1.0, 1.0)
        png = WORK / "byte.png"
        image.filepath_raw = str(png)
        image.file_format = 'PNG'
        image.save()
        self.assertEqual(image.source, 'FILE')
        result, error = harness.call_operator(target='UV', uv_margin=0)
        self.assertEqual(result, {'FINISHED'}, error)
        _, _, pixels = harness.read_pixels(png)
        kept = sum(1 for i in range(0, len(pixels), 4) if pixels[i + 2] == 1.0 and pixels[i] == 0.0)
        baked = sum(1 for i in range(0, len(pixels), 4) if pixels[i] > 0.0)
        self.assertGreater(kept, 0, "texels outside the UV islands keep their colour")
        self.assertGreater(baked, 0, "the islands are baked")

    def test_modifiers_are_evaluated(self):
        """A subdivision modifier changes what is baked (the evaluated mesh, not the original)."""
        scenes.sphere_scene(resolution=16, samples=4)
        scene = bpy.context.scene
        module = sys.modules["dwivedi_bake"]
        props = scene.dwivedi_bake
        plain = module.export.export_scene(bpy.context, props, module.shim())
        sphere = bpy.data.objects["Sphere"]
        sphere.modifiers.new("Subdivision", 'SUBSURF').levels = 1
        subdivided = module.export.export_scene(bpy.context, props, module.shim())
        # Quads become 4 quads (8 triangles), the poles' triangles 3 quads (6 triangles).
        self.assertGreater(subdivided.triangle_count, 3 * plain.triangle_count)
        plain.scene.close()
        subdivided.scene.close()

    def test_principled_exit_by_version(self):
        """Blender 3.x's Principled BSDF exports the Principled v1 exit (retro-reflection by its
        Roughness, 1 - (1 - cos)^5 / 2 exit weight); the Subsurface Scattering node, like 4.x's
        Principled, the Lambertian exit."""
        module = sys.modules["dwivedi_bake"]
        shim = module.shim()
        material = scenes.principled_material("Exit", (0.9, 0.6, 0.4), (0.5, 0.25, 0.1))
        material.node_tree.nodes["Principled BSDF"].inputs["Roughness"].default_value = 0.3
        warnings = []
        exported = module.export.material_from_blender(material, shim, warnings)
        if bpy.app.version < (4, 0, 0):
            self.assertEqual(exported.subsurface_exit, "principled_v1")
            self.assertAlmostEqual(exported.roughness, 0.3, places=6)
        else:
            self.assertEqual(exported.subsurface_exit, "lambert")
        node = module.export.material_from_blender(scenes.sss_node_material("Node", (0.9, 0.6, 0.4), (1, 1, 1)),
                                                   shim, warnings)
        self.assertEqual(node.subsurface_exit, "lambert")

    def assertFails(self, pattern, **settings):
        result, error = harness.call_operator(**settings)
        self.assertEqual(result, {'CANCELLED'})
        self.assertIsNotNone(error, "an error is reported")
        self.assertIn(pattern.lower(), error.lower())
        return error

    def test_no_camera(self):
        scene = small_slab()
        scene.camera = None
        self.assertFails("no active camera")

    def test_no_uvs(self):
        small_slab()
        slab = bpy.data.objects["Slab"]
        while slab.data.uv_layers:
            slab.data.uv_layers.remove(slab.data.uv_layers[0])
        scenes.bake_image(slab, (8, 8))
        self.assertFails("no UV map", target='UV')

    def test_uv_target_missing(self):
        """No mesh selected, no image node, a node without an image: each says what to do."""
        small_slab()
        slab = bpy.data.objects["Slab"]
        for obj in bpy.context.view_layer.objects:
            obj.select_set(False)
        bpy.context.view_layer.objects.active = bpy.data.objects["Camera"]
        self.assertFails("select the mesh to bake", target='UV')
        bpy.context.view_layer.objects.active = slab
        self.assertFails("has no active Image Texture node", target='UV')
        image = scenes.bake_image(slab, (8, 8))
        slab.active_material.node_tree.nodes.active.image = None
        self.assertFails("has no image", target='UV')
        slab.active_material.node_tree.nodes.active.image = image
        self.assertEqual(harness.call_operator(target='UV')[0], {'FINISHED'})

    def test_unsaved_file_needs_a_folder(self):
        """An unsaved file has no folder for "//": a script is told so (the UI asks for a folder)."""
        small_slab()
        self.assertFalse(bpy.data.filepath)
        self.assertFails("the .blend is not saved", output_dir="//dwivedi_bake/")

    def test_temporary_folder_warns(self):
        small_slab()
        result, error = harness.call_operator(output_dir=bpy.app.tempdir)
        self.assertEqual(result, {'FINISHED'}, error)
        self.assertTrue([w for w in last_warnings() if "deletes at quit" in w], last_warnings())

    def test_transparent_film(self):
        """Film > Transparent: the background's alpha is 0 and the world is taken out of its colour
        (Cycles' premultiplied alpha); the slab covers the whole view here, so a wider view is used."""
        scene = small_slab()
        scenes.set_world(scene, (0.2, 0.4, 0.6), 1.0)
        bpy.data.objects["Slab"].scale = (0.4, 0.4, 0.1)
        scene.render.film_transparent = True
        result, error = harness.call_operator()
        self.assertEqual(result, {'FINISHED'}, error)
        _, _, pixels = harness.image_pixels("Dwivedi Camera")
        background = [i for i in range(0, len(pixels), 4) if pixels[i + 3] == 0.0]
        self.assertGreater(len(background), 0)
        self.assertTrue(all(max(pixels[i:i + 3]) < 1e-6 for i in background))
        scene.render.film_transparent = False
        result, error = harness.call_operator()
        _, _, pixels = harness.image_pixels("Dwivedi Camera")
        self.assertEqual(min(pixels[3::4]), 1.0)
        self.assertAlmostEqual(pixels[background[0] + 2], 0.6, places=5)

    def test_menu_and_status_bar(self):
        """The operator is in the Render menu (F3's menu search finds it there) and the status bar
        has the progress drawer; method identifiers in messages read as Blender names them."""
        module = sys.modules["dwivedi_bake"]
        self.assertIn(module.draw_render_menu, bpy.types.TOPBAR_MT_render._dyn_ui_initialize())
        self.assertIn(module.draw_status_bar, bpy.types.STATUSBAR_HT_header._dyn_ui_initialize())
        self.assertIn("Random Walk", module.readable("subsurface method RANDOM_WALK is not modelled"))
        self.assertNotIn("RANDOM_WALK", module.readable("subsurface method RANDOM_WALK is not modelled"))
        self.assertIn("OCIO", module.readable("the OCIO config"))

    def test_unwritable_folder(self):
        small_slab()
        blocker = WORK / "a_file"
        blocker.write_text("not a folder")
        self.assertFails("output folder", output_dir=str(blocker / "sub"))
        if os.geteuid() != 0:  # root writes anywhere
            locked = WORK / "locked"
            locked.mkdir()
            locked.chmod(0o500)
            try:
                self.assertFails("not writable", output_dir=str(locked))
            finally:
                locked.chmod(0o700)

    def test_missing_library(self):
        small_slab()
        prefs = bpy.context.preferences.addons["dwivedi_bake"].preferences
        prefs.library_path = str(WORK / "no_such" / "libdwivedi.so.1")
        try:
            self.assertFails("libdwivedi.so.1")
        finally:
            prefs.library_path = ""

    def test_zero_samples(self):
        small_slab()
        self.assertFails("at least 1 sample", samples=0)

    def test_bad_values_from_the_library(self):
        scene = small_slab()
        node = bpy.data.materials["Slab"].node_tree.nodes["Principled BSDF"]
        node.inputs["Subsurface Radius"].default_value = (-1.0, 0.5, 0.25)
        self.assertFails("radius")

    def test_no_meshes(self):
        scene = small_slab()
        bpy.data.objects.remove(bpy.data.objects["Slab"])
        self.assertFails("no visible mesh")

    def test_non_mesh_geometry_is_converted(self):
        """Text and curves are geometry: they are baked through their evaluated mesh."""
        scene = small_slab()
        bpy.ops.object.text_add(location=(0.0, 0.0, 0.06))
        result, error = harness.call_operator()
        self.assertEqual(result, {'FINISHED'}, error)

    def test_output_dir_is_a_file(self):
        small_slab()
        existing = WORK / "not_a_folder.txt"
        existing.write_text("a file where the output folder should be")
        self.assertFails("output folder", output_dir=str(existing))
        self.assertEqual(existing.read_text(), "a file where the output folder should be")

    def test_library_path_not_a_library(self):
        """A text file, and a folder, given as the library: refused with a message."""
        small_slab()
        prefs = bpy.context.preferences.addons["dwivedi_bake"].preferences
        text = WORK / "libdwivedi.so.1"
        text.write_text("not a shared object")
        try:
            for path, said in ((text, "is damaged or not a library: it is not an ELF file"),
                               (WORK, "is a folder, not a library file")):
                prefs.library_path = str(path)
                error = self.assertFails(str(path))
                self.assertIn(said, error)
        finally:
            prefs.library_path = ""

    def test_non_mesh_objects_in_the_scene(self):
        """Objects that are not geometry (an empty, a lattice, an armature, a speaker, a light
        probe, a grease pencil, a volume, a curve without bevel, a second camera) are left out,
        with a warning for those that would render; the bake finishes."""
        scene = small_slab()
        collection = scene.collection

        def add(name, data):
            obj = bpy.data.objects.new(name, data)
            collection.objects.link(obj)
            return obj

        add("Empty", None)
        add("Lattice", bpy.data.lattices.new("Lattice"))
        add("Armature", bpy.data.armatures.new("Armature"))
        add("Speaker", bpy.data.speakers.new("Speaker"))
        add("Probe", bpy.data.lightprobes.new("Probe", 'CUBE'))
        add("Pencil", bpy.data.grease_pencils.new("Pencil"))
        add("Volume", bpy.data.volumes.new("Volume"))
        curve = bpy.data.curves.new("Wire", 'CURVE')
        spline = curve.splines.new('POLY')
        spline.points.add(1)
        spline.points[1].co = (1.0, 0.0, 0.0, 1.0)
        add("Wire", curve)
        add("Camera 2", bpy.data.cameras.new("Camera 2"))
        module = sys.modules["dwivedi_bake"]
        exported = module.export.export_scene(bpy.context, scene.dwivedi_bake, module.shim())
        try:
            self.assertEqual(exported.mesh_count, 1, "only the slab is geometry")
            left_out = [w for w in exported.warnings if "not geometry" in w]
            self.assertEqual(len(left_out), 1, exported.warnings)
            for name in ("Pencil", "Volume"):
                self.assertIn(name, left_out[0])
        finally:
            exported.scene.close()
        result, error = harness.call_operator()
        self.assertEqual(result, {'FINISHED'}, error)
        _, _, pixels = harness.image_pixels("Dwivedi Camera")
        self.assertTrue(all(math.isfinite(v) for v in pixels))

    def test_non_finite_vertex(self):
        """A NaN vertex (Python can write one into a mesh) is refused with the library's message;
        the same scene bakes again once it is fixed: Blender keeps running."""
        small_slab()
        mesh = bpy.data.objects["Slab"].data
        kept = tuple(mesh.vertices[0].co)
        mesh.vertices[0].co = (float("nan"), 0.0, 0.0)
        mesh.update()
        try:
            self.assertFails("not finite")
        finally:
            mesh.vertices[0].co = kept
            mesh.update()
        result, error = harness.call_operator()
        self.assertEqual(result, {'FINISHED'}, error)

    def test_huge_coordinates(self):
        """A slab scaled beyond what Embree intersects in float (2^40): left out by the library
        (counted as warnings), the camera sees the world; the bake finishes with finite pixels."""
        scene = small_slab()
        slab = bpy.data.objects["Slab"]
        slab.scale = (1e13, 1e13, 1e13)
        result, error = harness.call_operator()
        self.assertEqual(result, {'FINISHED'}, error)
        _, _, pixels = harness.image_pixels("Dwivedi Camera")
        self.assertTrue(all(math.isfinite(v) for v in pixels))
        self.assertIn("geometry warnings", last_message())
        slab.scale = (1.0, 1.0, 1.0)
        result, error = harness.call_operator()
        self.assertEqual(result, {'FINISHED'}, error)
        self.assertNotIn("geometry warnings", last_message())

    def test_failures_in_a_row_then_a_bake(self):
        """Every refusal leaves Blender and the add-on usable: after each, a good bake finishes."""
        scene = small_slab()
        good = scene.dwivedi_bake.output_dir
        self.assertFails("at least 1 sample", samples=0)
        self.assertEqual(harness.call_operator(samples=4)[0], {'FINISHED'})
        blocker = WORK / "a_file_again"
        blocker.write_text("x")
        self.assertFails("output folder", output_dir=str(blocker / "sub"))
        self.assertEqual(harness.call_operator(output_dir=good)[0], {'FINISHED'})
        bpy.context.view_layer.objects.active = None
        for obj in bpy.context.view_layer.objects:
            obj.select_set(False)
        self.assertFails("select the mesh", target='UV')
        self.assertEqual(harness.call_operator(target='CAMERA')[0], {'FINISHED'})

    def test_unregister_and_register(self):
        bpy.ops.preferences.addon_disable(module="dwivedi_bake")
        self.assertFalse(hasattr(bpy.types.Scene, "dwivedi_bake"))
        bpy.ops.preferences.addon_enable(module="dwivedi_bake")
        self.assertTrue(hasattr(bpy.types.Scene, "dwivedi_bake"))


harness.run(AddonTest)
