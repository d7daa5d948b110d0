"""Tests of the shim's baker part (python_shim/dwivedi/baker.py): the ctypes mirrors of the capi
structs, scenes from sequences and buffers, errors, images and their zero-copy views, bakes with
progress, cancellation and Ctrl-C, output files, scene files.

Run by ctest with DWIVEDI_LIBRARY set (tests/CMakeLists.txt). Standard library only; numpy is used
where it is installed.
"""
import array
import ctypes
import math
import os
import re
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import textwrap
import unittest
from pathlib import Path

SOURCE_DIR = Path(os.environ.get("DWIVEDI_SOURCE_DIR", Path(__file__).resolve().parents[2]))
sys.path.append(str(SOURCE_DIR / "python_shim"))
sys.path.append(str(SOURCE_DIR / "tools"))

import dwivedi  # noqa: E402
from dwivedi import _buffers, _library  # noqa: E402
import cycles_report as report  # noqa: E402  (its geometry: the report tool is not part of the shim)

try:
    import numpy
except ImportError:  # numpy is optional for the shim
    numpy = None

# A unit cube [-0.5, 0.5]^3: 8 corners, 12 outward-facing triangles (counter-clockwise seen from
# outside), and per-corner UVs laying each face over the whole [0, 1]^2 square's lower triangle
# or upper triangle.
CUBE_POSITIONS = [(x, y, z) for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]
CUBE_TRIANGLES = [
    (0, 1, 3), (0, 3, 2),  # x = -0.5
    (4, 6, 7), (4, 7, 5),  # x = +0.5
    (0, 4, 5), (0, 5, 1),  # y = -0.5
    (2, 3, 7), (2, 7, 6),  # y = +0.5
    (0, 2, 6), (0, 6, 4),  # z = -0.5
    (1, 5, 7), (1, 7, 3),  # z = +0.5
]
CUBE_UVS = [c for i in range(6) for c in ((0.02, 0.02), (0.98, 0.02), (0.98, 0.98),
                                           (0.02, 0.02), (0.98, 0.98), (0.02, 0.98))]


def cube_scene(world=(0.0, 0.0, 0.0), sun=3.0, camera=True, uvs=False, radius=(0.5, 0.25, 0.1)):
    """A lit subsurface cube seen from the front; not committed."""
    scene = dwivedi.Scene()
    material = scene.add_material(dwivedi.Material(subsurface_color=(0.9, 0.6, 0.4), subsurface_radius=radius,
                                                   subsurface_scale=1.0))
    scene.add_mesh(CUBE_POSITIONS, CUBE_TRIANGLES, material, uvs=CUBE_UVS if uvs else None)
    if sun:
        scene.add_light(dwivedi.SunLight(direction=(0.3, 1.0, -0.5), strength=sun))
    scene.set_world(world, 1.0)
    if camera:
        scene.set_camera(dwivedi.Camera.look_at((0.0, -3.0, 0.5), (0.0, 0.0, 0.0)))
    return scene


def luminance_sum(image):
    rgba = image.pixels()
    return sum(rgba[i] + rgba[i + 1] + rgba[i + 2] for i in range(0, len(rgba), 4))


class StructLayoutTest(unittest.TestCase):
    """The ctypes mirrors have the C structs' sizes and offsets (a C compiler checks, if any)."""

    STRUCTS = {
        "dwv_material_t": _library.Material, "dwv_mesh_t": _library.Mesh, "dwv_light_desc_t": _library.LightDesc,
        "dwv_camera_t": _library.CameraDesc, "dwv_bake_progress_t": _library.BakeProgress,
        "dwv_bake_options_t": _library.BakeOptions, "dwv_image_info_t": _library.ImageInfo,
        "dwv_bake_stats_t": _library.BakeStats, "dwv_error_point_t": _library.ErrorPoint,
        "dwv_display_options_t": _library.DisplayOptions, "dwv_environment_t": _library.EnvironmentDesc,
        "dwv_texture_desc_t": _library.TextureDesc, "dwv_texture_binding_t": _library.TextureBinding,
    }

    def test_sizes_on_lp64(self):
        if ctypes.sizeof(ctypes.c_void_p) != 8:
            self.skipTest("the sizes below are those of an LP64 ABI")
        sizes = {"dwv_material_t": 192, "dwv_mesh_t": 184, "dwv_light_desc_t": 248, "dwv_camera_t": 128,
                 "dwv_bake_progress_t": 48, "dwv_bake_options_t": 184, "dwv_image_info_t": 40,
                 "dwv_bake_stats_t": 136, "dwv_error_point_t": 24, "dwv_display_options_t": 56,
                 "dwv_environment_t": 104, "dwv_texture_desc_t": 40, "dwv_texture_binding_t": 56}
        for name, size in sizes.items():
            self.assertEqual(ctypes.sizeof(self.STRUCTS[name]), size, name)

    def test_offsets_match_a_c_compiler(self):
        cc = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
        # setup.sh installs build-essential: a missing compiler is a broken setup, not a skip
        self.assertIsNotNone(cc, "no C compiler (cc, gcc or clang) on PATH to compare the layouts with")
        lines = []
        for c_name, py in self.STRUCTS.items():
            lines.append(f'printf("{c_name} %zu\\n", sizeof({c_name}));')
            for field_name, *_ in py._fields_:
                lines.append(f'printf("{c_name}.{field_name} %zu\\n", offsetof({c_name}, {field_name}));')
        source = "#include <stdio.h>\n#include <stddef.h>\n#include \"dwivedi.h\"\nint main(void){\n" + \
                 "\n".join(lines) + "\nreturn 0;}\n"
        with tempfile.TemporaryDirectory() as tmp:
            (Path(tmp) / "layout.c").write_text(source)
            exe = Path(tmp) / "layout"
            subprocess.run([cc, "-I", str(SOURCE_DIR / "capi"), str(Path(tmp) / "layout.c"), "-o", str(exe)],
                           check=True)
            out = subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout
        for line in out.splitlines():
            key, value = line.rsplit(" ", 1)
            if "." in key:
                struct_name, field_name = key.split(".")
                actual = getattr(self.STRUCTS[struct_name], field_name).offset
            else:
                actual = ctypes.sizeof(self.STRUCTS[key])
            self.assertEqual(actual, int(value), key)

    def test_defaults_are_the_init_macros(self):
        options = _library.BakeOptions()
        self.assertEqual((options.struct_size, options.width, options.height, options.uv_margin, options.samples),
                         (184, 256, 256, 16, 64))
        # Issue 18's light paths: Blender's defaults, as DWV_BAKE_OPTIONS_INIT (Filter Glossy 1).
        self.assertEqual((options.max_bounces, options.diffuse_bounces, options.glossy_bounces,
                          options.transmission_bounces, options.min_light_bounces, options.subsurface_after_diffuse,
                          options.blur_glossy),
                         (12, 4, 4, 12, 0, 0, 1.0))
        self.assertEqual(dwivedi.BakeSettings().blur_glossy, 1.0)
        # The pixel filter: the box of one pixel, as DWV_BAKE_OPTIONS_INIT.
        self.assertEqual((options.pixel_filter, options.reserved3, options.filter_width), (0, 0, 1.0))
        self.assertEqual((dwivedi.BakeSettings().pixel_filter, dwivedi.BakeSettings().filter_width), ("box", 1.0))
        filtered = dwivedi.BakeSettings(pixel_filter="blackman_harris", filter_width=1.5)
        self.assertEqual((filtered._to_c().pixel_filter, filtered._to_c().filter_width), (2, 1.5))
        self.assertEqual(dwivedi.BakeSettings._from_c(filtered._to_c()), filtered)
        with self.assertRaises((ValueError, TypeError)):
            dwivedi.BakeSettings(pixel_filter="mitchell")._to_c()
        # UV samples in their texel: Cycles 3.5+'s retries by default, as DWV_BAKE_OPTIONS_INIT.
        self.assertEqual((options.uv_jitter, options.reserved4, dwivedi.BakeSettings().uv_jitter), (0, 0, "retry"))
        folded = dwivedi.BakeSettings(uv_jitter="mirror")
        self.assertEqual(folded._to_c().uv_jitter, 1)
        self.assertEqual(dwivedi.BakeSettings._from_c(folded._to_c()), folded)
        with self.assertRaises((ValueError, TypeError)):
            dwivedi.BakeSettings(uv_jitter="clamp")._to_c()
        settings = dwivedi.BakeSettings()
        self.assertEqual(dwivedi.BakeSettings._from_c(settings._to_c()), settings)
        self.assertEqual((settings.width, settings.height, settings.uv_margin, settings.samples, settings.technique),
                         (256, 256, 16, 64, "auto"))
        material = dwivedi.Material()._to_c()
        self.assertEqual(tuple(material.subsurface_radius), (1.0, 0.2, 0.1))
        self.assertEqual((material.subsurface_scale, material.subsurface_ior), (0.05, 1.4))
        self.assertEqual((material.struct_size, material.subsurface_exit, material.roughness), (192, 0, 0.5))
        # Issue 17's fields: the same defaults as DWV_MATERIAL_INIT (fixed radius, no specular).
        self.assertEqual((material.subsurface_model, material.specular_model, material.ior, material.specular,
                          tuple(material.specular_tint), material.specular_multiscatter,
                          material.subsurface_min_footprint),
                         (0, 0, 1.5, 0.5, (1.0, 1.0, 1.0), 0, 0.0))
        self.assertEqual(_library.DisplayOptions().gamma, 1.0)

    def test_pixel_filter_names_are_the_librarys(self):
        """BakeSettings.pixel_filter takes the names of dwv_pixel_filter_name (any case) or their
        codes, turns each code back into its name, and refuses anything else with the names listed."""
        name_of = _library.function("dwv_pixel_filter_name")
        names = []
        while name_of(len(names)) is not None:
            names.append(name_of(len(names)).decode("ascii"))
        self.assertEqual(names, ["box", "gaussian", "blackman_harris"])  # as docs/scene-format.md
        for code, name in enumerate(names):
            for given in (name, name.upper(), code):
                settings = dwivedi.BakeSettings(pixel_filter=given)
                self.assertEqual(settings._to_c().pixel_filter, code, given)
                self.assertEqual(dwivedi.BakeSettings._from_c(settings._to_c()).pixel_filter, name)
        for bad in ("mitchell", "", "box\0", 3, -1, 1 << 32):
            with self.assertRaises(dwivedi.Error) as caught:
                dwivedi.BakeSettings(pixel_filter=bad)._to_c()
            self.assertIn("pixel filter", str(caught.exception))
        with self.assertRaises(dwivedi.Error) as caught:
            dwivedi.BakeSettings(pixel_filter="Mitchell")._to_c()
        self.assertIn("'mitchell' (box, gaussian or blackman_harris)", str(caught.exception))
        for bad in (None, 1.0, True):
            with self.assertRaises(TypeError):
                dwivedi.BakeSettings(pixel_filter=bad)._to_c()


class BufferTest(unittest.TestCase):
    """Arrays reach the library without a copy where their layout allows it."""

    def test_float32_buffers_are_not_copied(self):
        data = array.array("f", range(9))
        passed = _buffers.as_c_array(data, "f", "positions", 3)
        self.assertEqual(passed.address, data.buffer_info()[0])
        view = memoryview(data)
        self.assertEqual(_buffers.as_c_array(view, "f", "positions", 3).address, data.buffer_info()[0])
        if numpy is not None:
            a = numpy.arange(9, dtype=numpy.float32).reshape(3, 3)
            self.assertEqual(_buffers.as_c_array(a, "f", "positions", 3).address, a.ctypes.data)
            i = numpy.arange(6, dtype=numpy.uint32)
            self.assertEqual(_buffers.as_c_array(i, "I", "indices", 3).address, i.ctypes.data)

    def test_other_layouts_are_converted(self):
        for values in ([(0, 1, 2), (3, 4, 5)], [0, 1, 2, 3, 4, 5], array.array("d", range(6)),
                       memoryview(array.array("d", range(6)))):
            passed = _buffers.as_c_array(values, "f", "positions", 3)
            self.assertEqual(passed.count, 6)
            self.assertEqual(list((ctypes.c_float * 6).from_address(passed.address)), [0, 1, 2, 3, 4, 5])
        if numpy is not None:
            a = numpy.arange(12, dtype=numpy.float64).reshape(4, 3)[::2]  # strided float64
            passed = _buffers.as_c_array(a, "f", "positions", 3)
            self.assertEqual(list((ctypes.c_float * 6).from_address(passed.address)), [0, 1, 2, 6, 7, 8])
            ints = numpy.array([[0, 1, 2]], dtype=numpy.int64)
            passed = _buffers.as_c_array(ints, "I", "indices", 3)
            self.assertEqual(list((ctypes.c_uint32 * 3).from_address(passed.address)), [0, 1, 2])

    def test_bad_arrays(self):
        with self.assertRaises(dwivedi.Error) as caught:
            _buffers.as_c_array([0, 1, 2, 3], "f", "positions", 3)
        self.assertIn("not a multiple of 3", str(caught.exception))
        with self.assertRaises(TypeError):
            _buffers.as_c_array(["a", "b", "c"], "f", "positions", 3)
        with self.assertRaises(TypeError):
            _buffers.as_c_array([0.5, 1, 2], "I", "indices", 3)
        with self.assertRaises(dwivedi.Error):
            _buffers.as_c_array([-1, 1, 2], "I", "indices", 3)
        with self.assertRaises(dwivedi.Error):
            _buffers.transform12([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]])


class SceneTest(unittest.TestCase):
    def test_ids_and_states(self):
        with dwivedi.Scene() as scene:
            self.assertEqual(scene.add_material(dwivedi.Material()), 0)
            self.assertEqual(scene.add_material(dwivedi.Material.diffuse((0.5, 0.5, 0.5))), 1)
            self.assertEqual(scene.add_mesh(CUBE_POSITIONS, CUBE_TRIANGLES, 1), 0)
            flat = array.array("f", [c for p in CUBE_POSITIONS for c in p])
            self.assertEqual(scene.add_mesh(memoryview(flat), array.array("I", [i for t in CUBE_TRIANGLES for i in t]),
                                            0, transform=[[1, 0, 0, 2], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]),
                             1)
            self.assertFalse(scene.committed)
            scene.commit()
            self.assertTrue(scene.committed)
            with self.assertRaises(dwivedi.Error) as caught:
                scene.add_material(dwivedi.Material())
            self.assertEqual(caught.exception.code, _library.DWV_ERROR_INVALID_STATE)
        with self.assertRaises(dwivedi.Error):
            scene.commit()  # closed

    def test_library_errors_carry_codes(self):
        with dwivedi.Scene() as scene:
            material = scene.add_material(dwivedi.Material())
            cases = [
                (lambda: scene.add_mesh(CUBE_POSITIONS, [(0, 1, 8)], material), _library.DWV_ERROR_OUT_OF_RANGE),
                (lambda: scene.add_mesh(CUBE_POSITIONS, CUBE_TRIANGLES, 5), _library.DWV_ERROR_OUT_OF_RANGE),
                (lambda: scene.add_mesh([(math.nan, 0, 0)] + CUBE_POSITIONS[1:], CUBE_TRIANGLES, material), None),
                (lambda: scene.add_material(dwivedi.Material(subsurface_color=(2.0, 0.5, 0.5))), None),
                (lambda: scene.add_material(dwivedi.Material(kind="glass")), _library.DWV_ERROR_UNKNOWN_NAME),
                (lambda: scene.add_light(dwivedi.SunLight(strength=-1.0)), _library.DWV_ERROR_OUT_OF_RANGE),
                (lambda: scene.add_light(dwivedi.AreaLight(size_x=0.0)), _library.DWV_ERROR_OUT_OF_RANGE),
                (lambda: scene.set_world((0.1, 0.1, math.inf)), None),
                (lambda: scene.set_camera(dwivedi.Camera(focal_length=0.0)), _library.DWV_ERROR_OUT_OF_RANGE),
                (lambda: scene.add_mesh(CUBE_POSITIONS, CUBE_TRIANGLES, material, uvs=[0.0] * 6), 2),
                (lambda: scene.add_mesh(CUBE_POSITIONS, CUBE_TRIANGLES, material,
                                        shadow_terminator_geometry_offset=-0.1), _library.DWV_ERROR_OUT_OF_RANGE),
                (lambda: scene.add_mesh(CUBE_POSITIONS, CUBE_TRIANGLES, material,
                                        shadow_terminator_geometry_offset=math.nan), None),
            ]
            for call, code in cases:
                with self.assertRaises(dwivedi.Error) as caught:
                    call()
                self.assertTrue(caught.exception.message, "an error has a message")
                self.assertIsInstance(caught.exception.code, int)
                if code is not None:
                    self.assertEqual(caught.exception.code, code, caught.exception.message)
            with self.assertRaises(TypeError):
                scene.add_light("sun")
            with self.assertRaises(TypeError):
                scene.add_mesh(CUBE_POSITIONS, CUBE_TRIANGLES, "wax")

    def test_camera_look_at(self):
        camera = dwivedi.Camera.look_at((0.0, -3.0, 0.0), (0.0, 0.0, 0.0))
        t = camera.transform
        # Looks along its local -z: the third column is the direction from target to eye.
        self.assertAlmostEqual(t[2], 0.0)
        self.assertAlmostEqual(t[6], -1.0)
        self.assertAlmostEqual(t[10], 0.0)
        self.assertAlmostEqual(t[9], 1.0)  # local +y is world +z (up)
        self.assertEqual((t[3], t[7], t[11]), (0.0, -3.0, 0.0))
        with self.assertRaises(dwivedi.Error):
            dwivedi.Camera.look_at((0, 0, 0), (0, 0, 0))

    def test_subsurface_and_specular_models(self):
        """Issue 17's fields reach the library by name, and bad values are refused with codes."""
        from dwivedi import baker
        self.assertEqual(len(baker.SUBSURFACE_MODELS), 7)
        for name, code in baker.SUBSURFACE_MODELS.items():
            self.assertEqual(dwivedi.Material(subsurface_model=name)._to_c().subsurface_model, code)
        m = dwivedi.Material(specular_model="principled_v2", ior=1.45, specular=0.7, specular_tint=(1, 0.5, 0.25),
                             specular_multiscatter=True)._to_c()
        self.assertEqual((m.specular_model, m.ior, m.specular, tuple(m.specular_tint), m.specular_multiscatter),
                         (2, 1.45, 0.7, (1.0, 0.5, 0.25), 1))
        with dwivedi.Scene() as scene:
            scene.add_material(dwivedi.Material(subsurface_model="blender52_random_walk", specular_model="principled_v2"))
            with self.assertRaises(dwivedi.Error) as caught:
                scene.add_material(dwivedi.Material(subsurface_model="blender6"))
            self.assertEqual(caught.exception.code, _library.DWV_ERROR_UNKNOWN_NAME)
            with self.assertRaises(dwivedi.Error) as caught:
                scene.add_material(dwivedi.Material(specular_model="principled_v2", ior=0.5))
            self.assertEqual(caught.exception.code, _library.DWV_ERROR_OUT_OF_RANGE)
            with self.assertRaises(dwivedi.Error) as caught:
                scene.add_material(dwivedi.Material(specular_model="principled_v1", specular_multiscatter=True))
            self.assertEqual(caught.exception.code, _library.DWV_ERROR_INVALID_ARGUMENT)
            with self.assertRaises(dwivedi.Error):
                scene.add_material(dwivedi.Material(specular_tint=(1.0, 2.0, 1.0)))
            with self.assertRaises(ValueError):
                dwivedi.Material(specular_multiscatter=2)._to_c()

    def test_blender_3x_material_mapping(self):
        m = dwivedi.Material.from_blender_3x((1.0, 0.0, 0.0), 0.25, (0.0, 1.0, 0.0), (1.0, 0.5, 0.25))
        self.assertEqual(m.subsurface_weight, 1.0)
        self.assertEqual(m.subsurface_scale, 0.25)
        self.assertEqual(m.subsurface_color, (0.75, 0.25, 0.0))
        self.assertEqual(dwivedi.Material.from_blender_3x((1, 1, 1), 0.0, (0, 0, 0), (1, 1, 1)).subsurface_weight, 0.0)
        # Blender 3.x's Principled exit (retro-reflection by Roughness, weighted exit).
        self.assertEqual((m.subsurface_exit, m.roughness), ("principled_v1", 0.5))
        c = dwivedi.Material.from_blender_3x((1, 1, 1), 0.5, (1, 1, 1), (1, 1, 1), roughness=0.2)._to_c()
        self.assertEqual((c.subsurface_exit, c.roughness), (1, 0.2))
        with dwivedi.Scene() as scene:
            with self.assertRaises(dwivedi.Error) as caught:
                scene.add_material(dwivedi.Material(subsurface_exit="fresnel"))
            self.assertEqual(caught.exception.code, _library.DWV_ERROR_UNKNOWN_NAME)
            with self.assertRaises(dwivedi.Error) as caught:
                scene.add_material(dwivedi.Material(subsurface_exit="principled_v1", roughness=1.5))
            self.assertEqual(caught.exception.code, _library.DWV_ERROR_OUT_OF_RANGE)


class WorldEnvironmentTest(unittest.TestCase):
    """Scene.set_world_environment and SpotLight (issue 18)."""

    def test_environment_and_spot_bake(self):
        w, h = 16, 8
        texels = array.array("f", [0.2] * (3 * w * h))
        texels[3 * (6 * w + 3):3 * (6 * w + 3) + 3] = array.array("f", [50.0, 40.0, 30.0])  # a hot spot up high
        scene = cube_scene(sun=0.0)
        scene.set_world_environment(texels, w, h, strength=1.5, rotation=((0.0, -1.0, 0.0), (1.0, 0.0, 0.0),
                                                                          (0.0, 0.0, 1.0)), interpolation="cubic")
        scene.add_light(dwivedi.SpotLight(position=(0.0, -2.0, 1.0), direction=(0.0, 1.0, -0.5), power=200.0,
                                          spot_size=math.radians(40.0), spot_blend=0.2, falloff="cycles4"))
        scene.commit()
        image = dwivedi.bake(scene, dwivedi.BakeSettings(width=16, height=16, samples=4, threads=2))
        self.assertTrue(math.isfinite(luminance_sum(image)))
        self.assertGreater(luminance_sum(image), 0.0)
        self.assertIn("world_light", image.stats.features)

    def test_bad_environments(self):
        scene = dwivedi.Scene()
        with self.assertRaises(dwivedi.Error) as caught:
            scene.set_world_environment([0.5, -1.0, 0.5], 1, 1)
        self.assertEqual(caught.exception.code, _library.DWV_ERROR_INVALID_ARGUMENT)
        self.assertIn("texel (0, 0)", str(caught.exception))
        with self.assertRaises(dwivedi.Error):
            scene.set_world_environment([0.5] * 9, 2, 2)  # 3 texels for 4
        with self.assertRaises(dwivedi.Error):
            scene.set_world_environment([0.5] * 3, 1, 1, interpolation="smart")
        with self.assertRaises(dwivedi.Error) as caught:
            scene.set_world_environment([0.5] * 3, 1, 1, rotation=(2, 0, 0, 0, 1, 0, 0, 0, 1))
        self.assertIn("not a rotation", str(caught.exception))
        with self.assertRaises(dwivedi.Error):
            scene.add_light(dwivedi.SpotLight(spot_blend=2.0))
        with self.assertRaises(dwivedi.Error):
            scene.add_light(dwivedi.SpotLight(falloff="cycles5"))
        scene.close()

    @unittest.skipIf(numpy is None, "numpy is not installed")
    def test_numpy_texels(self):
        scene = dwivedi.Scene()
        scene.set_world_environment(numpy.full((4, 8, 3), 0.25, dtype=numpy.float32), 8, 4)
        scene.set_world_environment(numpy.full((4, 8, 3), 0.25), 8, 4)  # float64: converted
        scene.close()


class TransparentBackgroundTest(unittest.TestCase):
    """BakeSettings.transparent_background (Cycles' Film > Transparent): where the camera sees no
    surface, RGBA 0 instead of the world; a pixel wholly on the surface is the same as in the
    opaque bake (the world still lights it); a partly covered one is its surface share only."""

    def test_background_left_out_and_surface_kept(self):
        world = (0.3, 0.5, 0.7)
        images = {}
        for transparent in (False, True):
            scene = cube_scene(world=world)
            scene.commit()
            images[transparent] = dwivedi.bake(scene, dwivedi.BakeSettings(
                width=24, height=24, samples=8, threads=2, seed=3, transparent_background=transparent)).pixels()
            scene.close()
        opaque, transparent = images[False], images[True]
        seen = {"background": 0, "surface": 0, "edge": 0}
        for i in range(0, len(opaque), 4):
            coverage = opaque[i + 3]
            self.assertEqual(transparent[i + 3], coverage)
            if coverage == 0.0:
                seen["background"] += 1
                for c in range(3):
                    self.assertAlmostEqual(opaque[i + c], world[c], places=6)
                    self.assertEqual(transparent[i + c], 0.0)
            elif coverage == 1.0:
                seen["surface"] += 1
                self.assertEqual(transparent[i:i + 3], opaque[i:i + 3])
            else:
                seen["edge"] += 1
                for c in range(3):  # the opaque pixel adds the world over the uncovered share
                    self.assertAlmostEqual(opaque[i + c] - transparent[i + c], (1.0 - coverage) * world[c], places=4)
        self.assertTrue(all(seen.values()), seen)

    def test_bad_values(self):
        with self.assertRaises(TypeError):
            dwivedi.BakeSettings(transparent_background=1)._to_c()
        scene = cube_scene()
        scene.commit()
        for field, value, message in (("transparent_background", 2, "neither 0 nor 1"), ("reserved", 1, "must be 0")):
            bad = dwivedi.BakeSettings(width=4, height=4, samples=1)._to_c()
            setattr(bad, field, value)
            bake = ctypes.c_void_p()
            code = _library.library().dwv_bake_start(scene._handle, ctypes.byref(bad), ctypes.byref(bake))
            self.assertEqual(code, _library.DWV_ERROR_INVALID_ARGUMENT)
            self.assertIn(message, _library.library().dwv_last_error_message().decode())
        scene.close()


class ImageTest(unittest.TestCase):
    def test_views_share_the_library_memory(self):
        pixels = [float(i) / 10 for i in range(4 * 3 * 2)]
        image = dwivedi.Image(3, 2, pixels)
        self.assertEqual((image.width, image.height), (3, 2))
        rgba = image.rgba
        self.assertEqual(rgba.shape, (2, 3, 4))
        self.assertEqual(rgba.format, "f")
        self.assertEqual([round(v, 6) for v in image.pixels()], [round(v, 6) for v in pixels])
        rgba[1, 2, 3] = 42.0
        self.assertEqual(image.pixels()[-1], 42.0)  # a view, not a copy
        self.assertEqual(image.samples.shape, (2, 3))
        self.assertEqual(image.variance.shape, (2, 3, 3))
        image.close()
        del image
        # The view keeps its own reference: the pixels are still there.
        self.assertEqual(rgba[1, 2, 3], 42.0)
        self.assertAlmostEqual(rgba[0, 0, 1], 0.1, places=6)

    def test_numpy_without_copy(self):
        """ctest runs this with /usr/bin/python3 (Debian's numpy) and with the PATH python3, which
        may have no numpy: there numpy() must raise ImportError, as documented, and the image stays
        usable through its memoryviews."""
        image = dwivedi.Image(4, 2, [0.5] * 32)
        if numpy is None:
            with self.assertRaises(ImportError):
                image.numpy()
            image.rgba[0, 0, 0] = 7.0
            self.assertEqual(image.pixels()[0], 7.0)
            return
        rgba, variance, samples = image.numpy()
        self.assertEqual(rgba.shape, (2, 4, 4))
        self.assertEqual(rgba.dtype, numpy.float32)
        rgba[0, 0, 0] = 7.0
        self.assertEqual(image.pixels()[0], 7.0)
        del image
        self.assertEqual(float(rgba.sum()), 0.5 * 31 + 7.0)

    def test_bad_images(self):
        with self.assertRaises(dwivedi.Error):
            dwivedi.Image(2, 2, [0.0] * 15)
        with self.assertRaises(dwivedi.Error):
            dwivedi.Image(0, 2, [])
        with self.assertRaises(dwivedi.Error):
            dwivedi.Image(1, 1, [0.0, math.nan, 0.0, 1.0])

    def test_exr_and_png_files(self):
        image = dwivedi.Image(2, 2, [0.0, 0.0, 0.0, 1.0, 0.18, 0.18, 0.18, 1.0, 1.0, 0.5, 0.25, 1.0, 4.0, 4.0, 4.0, 1.0])
        with tempfile.TemporaryDirectory() as tmp:
            exr = Path(tmp) / "a.exr"
            png = Path(tmp) / "a.png"
            image.write_exr(exr)
            self.assertEqual(exr.read_bytes()[:4], b"\x76\x2f\x31\x01")  # OpenEXR magic
            image.write_png(png, view="Standard")
            self.assertEqual(png.read_bytes()[:8], b"\x89PNG\r\n\x1a\n")
            shown = image.to_display(view="Standard")
            self.assertEqual(len(shown), 16)
            self.assertEqual(tuple(shown[0:4]), (0, 0, 0, 255))
            self.assertEqual(tuple(shown[12:16]), (255, 255, 255, 255))  # clipped by the Standard view
            brighter = image.to_display(view="Standard", exposure=1.0)
            self.assertGreater(brighter[4], shown[4])
            with self.assertRaises(dwivedi.Error) as caught:
                image.write_exr(Path(tmp) / "missing" / "a.exr")
            self.assertEqual(caught.exception.code, _library.DWV_ERROR_IO)
            with self.assertRaises(dwivedi.Error):
                image.write_png(png, view="No Such View")
            self.assertEqual(sorted(os.listdir(tmp)), ["a.exr", "a.png"])  # nothing partial left


class BakeTest(unittest.TestCase):
    def test_camera_bake(self):
        with cube_scene(world=(0.05, 0.05, 0.05)).commit() as scene:
            seen = []
            image = dwivedi.bake(scene, width=24, height=16, samples=8, threads=2, seed=3, progress=seen.append)
            self.assertEqual((image.width, image.height), (24, 16))
            pixels = image.pixels()
            self.assertTrue(all(math.isfinite(v) for v in pixels))
            self.assertGreater(luminance_sum(image), 0.0)
            stats = image.stats
            self.assertEqual(stats.samples_per_pixel, 8)
            self.assertGreater(stats.walks, 0)
            self.assertIn("subsurface", stats.features)
            self.assertTrue(seen and seen[-1].done)
            self.assertEqual(sorted(p.fraction for p in seen), [p.fraction for p in seen])
            points = image.error_vs_time
            self.assertTrue(points)
            self.assertEqual([p.seconds for p in points], sorted(p.seconds for p in points))
            # Deterministic for any thread count.
            again = dwivedi.bake(scene, width=24, height=16, samples=8, threads=1, seed=3)
            self.assertEqual(again.pixels().tobytes(), pixels.tobytes())
            other = dwivedi.bake(scene, width=24, height=16, samples=8, threads=2, seed=4)
            self.assertNotEqual(other.pixels().tobytes(), pixels.tobytes())

    def test_shadow_terminator_geometry_offset(self):
        """A smooth-shaded low-poly sphere lit from the side: with Cycles' default geometry offset
        (0.1, also add_mesh's default) the points whose shading normal faces the sun but whose
        flat triangle does not are lit from the smooth surface, so the image is brighter than
        with 0 (shadow rays from the flat triangle), and only near the terminator."""
        points, triangles = report.uv_sphere(segments=12, rings=6)
        # Light travelling along -(cos 15, sin 15, 0) degrees: the terminator, at azimuth 105 and -75
        # degrees, crosses the middle of the 30-degree facets (on their edges the flat and the
        # smooth terminator coincide).
        travel = (-math.cos(math.radians(15.0)), -math.sin(math.radians(15.0)), 0.0)

        def bake(**offset):
            scene = dwivedi.Scene()
            material = scene.add_material(dwivedi.Material(kind="diffuse", base_color=(0.8, 0.8, 0.8)))
            scene.add_mesh(points, triangles, material, normals=points, **offset)
            scene.add_light(dwivedi.SunLight(direction=travel, strength=3.0))
            scene.set_camera(dwivedi.Camera.look_at((0.0, -4.0, 0.0), (0.0, 0.0, 0.0)))
            with scene.commit() as committed:
                return dwivedi.bake(committed, width=32, height=32, samples=4, threads=2, seed=1).pixels()

        default, cycles, flat = bake(), bake(shadow_terminator_geometry_offset=0.1), bake(
            shadow_terminator_geometry_offset=0.0)
        self.assertEqual(default.tobytes(), cycles.tobytes())
        brighter = [i for i in range(0, len(flat), 4) if cycles[i] > flat[i]]
        darker = [i for i in range(0, len(flat), 4) if cycles[i] < flat[i]]
        self.assertFalse(darker, "the offset only lights points the flat triangle shadows")
        self.assertTrue(brighter, "the offset lights points past the flat triangles' terminator")
        # The camera looks along +y from -y: the seen terminator is at x = cos 75 degrees = 0.26 m,
        # right of the middle column.
        columns = {(i // 4) % 32 for i in brighter}
        self.assertTrue(all(16 <= c < 26 for c in columns), sorted(columns))

    def test_uv_bake(self):
        with cube_scene(uvs=True, camera=False).commit() as scene:
            image = scene.bake(target="uv", uv_mesh=0, width=32, height=32, samples=4, uv_margin=2)
            alpha = image.rgba.tolist()
            covered = sum(1 for row in alpha for px in row if px[3] > 0.0)
            self.assertGreater(covered, 32 * 32 // 2)
            with self.assertRaises(dwivedi.Error):
                scene.bake(target="uv", uv_mesh=7, width=8, height=8, samples=1)

    def test_channel_walks(self):
        with cube_scene().commit() as scene:
            features = {}
            for channel_walks in ("shared", "separate", "auto"):
                image = dwivedi.bake(scene, width=8, height=8, samples=4, threads=2, seed=5, technique="classical",
                                     channel_walks=channel_walks)
                features[channel_walks] = image.stats.features
                self.assertTrue(all(math.isfinite(v) for v in image.pixels()))
            self.assertIn("channel_walks", features["separate"])
            self.assertNotIn("rgb_walks", features["separate"])
            # An explicit technique walks the channels together unless told otherwise.
            for name in ("shared", "auto"):
                self.assertIn("rgb_walks", features[name])
                self.assertNotIn("channel_walks", features[name])
            self.assertEqual(dwivedi.BakeSettings(channel_walks="separate")._to_c().channel_walks, 2)
            for bad in ("apart", "", 3):
                with self.assertRaises(dwivedi.Error, msg=repr(bad)):
                    dwivedi.bake(scene, width=8, height=8, samples=1, channel_walks=bad)
            for bad in (None, 1.0, True):
                with self.assertRaises(TypeError, msg=repr(bad)):
                    dwivedi.bake(scene, width=8, height=8, samples=1, channel_walks=bad)

    def test_bad_settings(self):
        with cube_scene().commit() as scene:
            for overrides in ({"samples": 0}, {"width": 0}, {"time_limit": -1.0}, {"technique": "magic"},
                              {"target": "screen"}, {"channel_walks": "magic"}):
                with self.assertRaises(dwivedi.Error, msg=str(overrides)):
                    dwivedi.bake(scene, **{"width": 8, "height": 8, "samples": 1, **overrides})
            with self.assertRaises(TypeError):
                dwivedi.bake(scene, colour=1)
        with cube_scene(camera=False).commit() as scene:
            with self.assertRaises(dwivedi.Error):  # a camera bake needs a camera
                dwivedi.bake(scene, width=8, height=8, samples=1)
        with cube_scene() as scene:
            with self.assertRaises(dwivedi.Error):  # not committed
                dwivedi.bake(scene, width=8, height=8, samples=1)

    def test_progress_callback_cancels(self):
        with cube_scene().commit() as scene:
            calls = []

            def stop(progress):
                calls.append(progress)
                return True

            with self.assertRaises(dwivedi.Cancelled) as caught:
                dwivedi.bake(scene, width=64, height=64, samples=1 << 20, progress=stop, interval=0.01)
            self.assertEqual(caught.exception.code, _library.DWV_ERROR_CANCELLED)
            self.assertGreaterEqual(len(calls), 1)

    def test_keyboard_interrupt_in_the_wait_cancels(self):
        with cube_scene().commit() as scene:
            def interrupt(progress):
                raise KeyboardInterrupt

            with self.assertRaises(KeyboardInterrupt):
                dwivedi.bake(scene, width=64, height=64, samples=1 << 20, progress=interrupt, interval=0.01)
            # The scene is usable again at once: the bake's threads have stopped.
            image = dwivedi.bake(scene, width=4, height=4, samples=1)
            self.assertEqual(image.width, 4)

    def test_ctrl_c_in_a_process(self):
        """A real SIGINT while bake() waits stops the bake and raises KeyboardInterrupt."""
        script = textwrap.dedent(f"""
            import sys, time
            sys.path.insert(0, {str(SOURCE_DIR / 'python_shim')!r})
            sys.path.insert(0, {str(Path(__file__).resolve().parent)!r})
            import dwivedi
            from test_baker_shim import cube_scene
            scene = cube_scene().commit()
            def started(progress):
                if not getattr(started, "said", False):
                    started.said = True
                    print("started", flush=True)
            try:
                dwivedi.bake(scene, width=64, height=64, samples=1 << 24, progress=started)
            except KeyboardInterrupt:
                print("interrupted", flush=True)
                sys.exit(3)
            print("finished", flush=True)
        """)
        process = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True,
                                   env={**os.environ, "PYTHONDONTWRITEBYTECODE": "1"})
        try:
            self.assertEqual(process.stdout.readline().strip(), "started")
            process.send_signal(signal.SIGINT)
            out, _ = process.communicate(timeout=60)
        finally:
            if process.poll() is None:
                process.kill()
                process.wait()
        self.assertEqual(out.strip(), "interrupted")
        self.assertEqual(process.returncode, 3)

    def test_start_bake_handle(self):
        with cube_scene().commit() as scene:
            with dwivedi.start_bake(scene, width=16, height=16, samples=4) as job:
                self.assertTrue(job.wait(None))
                self.assertTrue(job.progress().done)
                image = job.finish()
            self.assertEqual(image.stats.samples_per_pixel, 4)
            with self.assertRaises(dwivedi.Error):
                job.finish()  # already finished
            job = dwivedi.start_bake(scene, width=64, height=64, samples=1 << 20)
            job.cancel()
            with self.assertRaises(dwivedi.Cancelled):
                job.finish()


class SceneFileTest(unittest.TestCase):
    def test_default_scene(self):
        with dwivedi.Scene.default() as scene:
            self.assertTrue(scene.committed)
            settings = scene.settings
            self.assertGreater(settings.width, 0)
            image = dwivedi.bake(scene, width=16, height=12, samples=2)
            self.assertEqual((image.width, image.height), (16, 12))
            self.assertGreater(luminance_sum(image), 0.0)

    def test_scene_file_errors(self):
        with self.assertRaises(dwivedi.Error) as caught:
            dwivedi.Scene.from_json("{ not json")
        self.assertEqual(caught.exception.code, _library.DWV_ERROR_FORMAT)
        with self.assertRaises(dwivedi.Error) as caught:
            dwivedi.Scene.load("/nonexistent/scene.json")
        self.assertEqual(caught.exception.code, _library.DWV_ERROR_IO)

    def test_example_scenes_load(self):
        scenes = sorted((SOURCE_DIR / "examples" / "scenes").glob("*.json"))
        self.assertTrue(scenes, "examples/scenes/ holds no scene files")
        for path in scenes:
            with dwivedi.Scene.load(path) as scene:
                self.assertTrue(scene.committed, path.name)


class ExampleScriptTest(unittest.TestCase):
    def test_bake_example_runs(self):
        script = SOURCE_DIR / "examples" / "python" / "bake_example.py"
        with tempfile.TemporaryDirectory() as tmp:
            result = subprocess.run([sys.executable, str(script), "--out", tmp, "--size", "24", "--samples", "2"],
                                    capture_output=True, text=True, timeout=120,
                                    env={**os.environ, "PYTHONPATH": str(SOURCE_DIR / "python_shim")})
            self.assertEqual(result.returncode, 0, result.stderr)
            self.assertTrue((Path(tmp) / "example.exr").is_file())
            self.assertTrue((Path(tmp) / "example.png").is_file())


if __name__ == "__main__":
    unittest.main()
