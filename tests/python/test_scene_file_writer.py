"""dwivedi.scene_file.SceneFileWriter (the add-on's "Export for a farm"): a scene built through the
shim's calls, written as a scene file and loaded back, bakes the same bits as the scene built in
memory; every material field, every light kind and the camera survive. A planted change of one
material field in the file changes the image (the comparison can fail). Standard library only."""
import dataclasses
import hashlib
import json
import math
import os
import struct
import tempfile
import unittest

import dwivedi
from dwivedi import scene_file
from dwivedi.scene_file import LIGHT_PATH_KEYS, SceneFileWriter, degrees_for, light_path_keys

CUBE = [-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1]
CUBE_TRIANGLES = [0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4, 1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6,
                  3, 0, 4, 3, 4, 7]


def build(scene) -> None:
    """The same calls on a dwivedi.Scene or a SceneFileWriter."""
    wax = scene.add_material(dwivedi.Material(
        base_color=(0.7, 0.6, 0.5), subsurface_color=(0.9, 0.7, 0.5), subsurface_radius=(1.0, 0.5, 0.25),
        subsurface_scale=0.07, subsurface_anisotropy=0.3, subsurface_ior=1.33, roughness=0.35,
        subsurface_model="blender4_random_walk", specular_model="principled_v2", ior=1.45, specular=0.6,
        specular_tint=(1.0, 0.9, 0.8), specular_multiscatter=True, subsurface_min_footprint=0.25))
    floor = scene.add_material(dwivedi.Material.diffuse((0.4, 0.45, 0.5)))
    normals = [c / math.sqrt(3.0) for c in CUBE]
    scene.add_mesh(CUBE, CUBE_TRIANGLES, wax, normals=normals,
                   transform=[0.03, 0, 0, 0, 0, 0.03, 0, 0, 0, 0, 0.03, 0.031], shadow_terminator_geometry_offset=0.2)
    scene.add_mesh([-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0], [0, 1, 2, 0, 2, 3], floor)
    scene.add_light(dwivedi.SunLight(direction=(0.3, 0.5, -1.0), strength=2.5, angle=0.1234567, color=(1, 0.95, 0.9)))
    scene.add_light(dwivedi.PointLight(position=(0.1, -0.1, 0.2), power=3.0, radius=0.01))
    area = dwivedi.Camera.look_at((-0.2, -0.1, 0.15), (0, 0, 0.03)).transform
    scene.add_light(dwivedi.AreaLight(transform=area, size_x=0.05, size_y=0.08, power=4.0, shape="disk"))
    scene.add_light(dwivedi.SpotLight(position=(-0.1, 0.05, 0.3), direction=(0.2, 0.1, -1.0), power=5.0, radius=0.02,
                                      spot_size=0.7, spot_blend=0.3, falloff="cycles4"))
    scene.set_world((0.6, 0.7, 1.0), 0.05)
    scene.set_camera(dwivedi.Camera.look_at((0.05, -0.3, 0.12), (0, 0, 0.03), focal_length=40.0))


def build_textured(scene) -> None:
    """Textures of every kind the add-on passes (float RGB, 8-bit sRGB and non-colour, a normal
    map on a second UV layer with given tangents, a bump), and an environment world with a
    rotation that Euler degrees would not give back exactly."""
    wax = scene.add_material(dwivedi.Material(subsurface_color=(0.9, 0.7, 0.5), subsurface_radius=(1.0, 0.5, 0.25),
                                              subsurface_scale=0.07, subsurface_exit="principled_v1",
                                              specular_model="principled_v1"))
    floor = scene.add_material(dwivedi.Material.diffuse((0.4, 0.45, 0.5)))
    colour = scene.add_texture([((k * 37) % 11) / 10.0 for k in range(4 * 3 * 3)], 4, 3, 3, interpolation="cubic")
    rough = scene.add_texture(bytes([20, 200, 90, 255]), 2, 2, 1, format="linear8", extension="extend")
    normal = scene.add_texture([x for t in range(9) for x in (0.5 + 0.2 * math.sin(t), 0.5 + 0.2 * math.cos(t), 0.9)],
                               3, 3, 3, interpolation="closest")
    bump = scene.add_texture(bytes((k * 53) % 256 for k in range(5 * 4 * 4)), 5, 4, 4, format="srgb8",
                             extension="mirror")
    scene.bind_texture(wax, "subsurface_color", colour, blend=0.75)
    scene.bind_texture(wax, "roughness", rough)
    scene.bind_texture(wax, "normal_map", normal, uv_layer="Detail", strength=0.8)
    scene.bind_texture(floor, "bump", bump, distance=0.02, strength=0.5, invert=True, bump_shadowing="conty2019")
    normals = [c / math.sqrt(3.0) for c in CUBE]
    triangles = len(CUBE_TRIANGLES) // 3
    uvs = [((k * 0.37) % 1.0) for k in range(6 * triangles)]
    detail = [((k * 0.61 + 0.2) % 1.0) for k in range(6 * triangles)]
    tangents = []
    for v in CUBE_TRIANGLES:
        n = normals[3 * v:3 * v + 3]
        t = (-n[1], n[0], 0.0)
        length = math.hypot(t[0], t[1])
        tangents += [t[0] / length, t[1] / length, 0.0, -1.0 if v % 2 else 1.0]
    scene.add_mesh(CUBE, CUBE_TRIANGLES, wax, normals=normals, uvs=uvs, uv_name="UVMap",
                   uv_layers=[("Detail", detail)], tangents={"Detail": tangents},
                   transform=[0.03, 0, 0, 0, 0, 0.03, 0, 0, 0, 0, 0.03, 0.031])
    scene.add_mesh([-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0], [0, 1, 2, 0, 2, 3], floor,
                   uvs=[0, 0, 1, 0, 1, 1, 0, 0, 1, 1, 0, 1])
    scene.add_light(dwivedi.SunLight(direction=(0.3, 0.5, -1.0), strength=2.5, angle=0.05))
    a, b = 0.3, 1.1  # Rz(b) Rx(a), rounded as doubles are
    rotation = [math.cos(b), -math.sin(b) * math.cos(a), math.sin(b) * math.sin(a),
                math.sin(b), math.cos(b) * math.cos(a), -math.cos(b) * math.sin(a),
                0.0, math.sin(a), math.cos(a)]
    sky = [v for k in range(8 * 4) for v in (0.2 + 0.1 * (k % 8), 0.3, 3.0 if k == 21 else 0.5)]
    scene.set_world_environment(sky, 8, 4, strength=0.7, rotation=rotation, interpolation="linear")
    scene.set_camera(dwivedi.Camera.look_at((0.05, -0.3, 0.12), (0, 0, 0.03), focal_length=40.0))


def bake_memory_and_file(test, builder, folder, name, settings):
    """The scene `builder` makes, baked in memory and from the file SceneFileWriter writes of the
    same calls: the two bakes must be the same bits. Returns (the in-memory image, the loaded
    scene, the bake options, the file's path)."""
    memory = dwivedi.Scene()
    builder(memory)
    memory.commit()
    writer = SceneFileWriter()
    builder(writer)
    path = os.path.join(folder, name)
    writer.write(path, bake=settings)
    loaded = dwivedi.Scene.load(path)
    options = dataclasses.replace(loaded.settings, threads=2)
    a, b = memory.bake(options), loaded.bake(options)
    test.assertEqual(bytes(a.rgba), bytes(b.rgba))
    test.assertEqual(bytes(a.variance), bytes(b.variance))
    test.assertEqual(memory.texture_memory(), loaded.texture_memory())
    return a, loaded, options, path


class SceneFileWriterTest(unittest.TestCase):
    def test_written_scene_bakes_the_same_bits(self) -> None:
        settings = dict(width=24, height=16, samples=8, technique="auto", seed=5)
        with tempfile.TemporaryDirectory() as folder:
            a, loaded, options, path = bake_memory_and_file(self, build, folder, "scene.json", settings)
            self.assertEqual((loaded.settings.width, loaded.settings.samples, loaded.settings.seed), (24, 8, 5))
            self.assertGreater(a.stats.mean_rgb[0], 0.0)

            with open(path, encoding="utf-8") as f:
                document = json.load(f)
            document["materials"]["material0"]["ior"] = 1.5  # planted: one field off
            with open(path, "w", encoding="utf-8") as f:
                json.dump(document, f)
            planted = dwivedi.Scene.load(path).bake(options)
            self.assertNotEqual(bytes(planted.rgba), bytes(a.rgba))

    def test_light_paths_written_and_read_back(self) -> None:
        writer = SceneFileWriter()
        build(writer)
        paths = dwivedi.BakeSettings(max_bounces=7, diffuse_bounces=3, glossy_bounces=2, transmission_bounces=1,
                                     min_light_bounces=4, subsurface_after_diffuse="walk")
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "scene.json")
            writer.write(path, bake=dict(width=8, height=8, samples=2, **light_path_keys(paths)))
            loaded = dwivedi.Scene.load(path).settings
            for key in LIGHT_PATH_KEYS:
                self.assertEqual(getattr(loaded, key), getattr(paths, key), key)
            absent = os.path.join(folder, "absent.json")
            writer.write(absent, bake=dict(width=8, height=8, samples=2))
            defaults = dwivedi.Scene.load(absent).settings  # Blender's Light Paths
            self.assertEqual((defaults.max_bounces, defaults.diffuse_bounces, defaults.glossy_bounces,
                              defaults.transmission_bounces, defaults.subsurface_after_diffuse), (12, 4, 4, 12, "by_model"))
        with self.assertRaises(dwivedi.Error):
            light_path_keys(dwivedi.BakeSettings(subsurface_after_diffuse="sometimes"))

    def test_sun_angle_degrees_map_back_exactly(self) -> None:
        per_degree = 3.14159265358979323846 / 180.0
        for radians in (0.0, 0.1234567, 0.009250245035569947, 1.0, math.pi / 7):
            self.assertEqual(degrees_for(radians) * per_degree, radians, radians)

    def test_textured_scene_with_an_environment_bakes_the_same_bits(self) -> None:
        settings = dict(width=20, height=14, samples=6, technique="auto", seed=3)
        with tempfile.TemporaryDirectory() as folder:
            a, loaded, options, path = bake_memory_and_file(self, build_textured, folder, "shot.json", settings)
            self.assertEqual(sorted(os.listdir(os.path.join(folder, "shot_files"))),
                             ["environment.exr", "texture0.exr", "texture1.png", "texture2.exr", "texture3.png"])
            with open(path, encoding="utf-8") as f:
                document = json.load(f)
            self.assertEqual(len(document["world"]["environment"]["rotation"]), 9)
            # Planted: one texel of the colour texture off (the file's hash updated, so it loads)
            # changes the image; the comparison can fail.
            texture = os.path.join(folder, "shot_files", "texture0.exr")
            with open(texture, "rb") as f:
                data = bytearray(f.read())
            data[-4:] = struct.pack("<f", 0.01)
            with open(texture, "wb") as f:
                f.write(data)
            document["textures"]["texture0"]["sha256"] = hashlib.sha256(data).hexdigest()
            with open(path, "w", encoding="utf-8") as f:
                json.dump(document, f)
            self.assertNotEqual(bytes(dwivedi.Scene.load(path).bake(options).rgba), bytes(a.rgba))
            # A farm node whose file differs from the one the scene was written with refuses it.
            document["textures"]["texture0"]["sha256"] = "0" * 64
            with open(path, "w", encoding="utf-8") as f:
                json.dump(document, f)
            with self.assertRaises(dwivedi.Error) as caught:
                dwivedi.Scene.load(path)
            self.assertIn("not the file the scene was written with", str(caught.exception))
            self.assertIn("textures.texture0.file", str(caught.exception))

    def test_too_many_values_are_refused(self) -> None:
        writer = SceneFileWriter()
        writer.add_material(dwivedi.Material())
        writer.add_mesh(CUBE, CUBE_TRIANGLES, 0)  # 60 numbers and the mesh's own keys
        limit = scene_file.MAX_JSON_VALUES
        scene_file.MAX_JSON_VALUES = 60  # the real limit (2^22) would take a mesh of millions of numbers
        try:
            with tempfile.TemporaryDirectory() as folder:
                with self.assertRaises(ValueError) as caught:
                    writer.write(os.path.join(folder, "big.json"))
                self.assertIn("inline", str(caught.exception))
                self.assertEqual(os.listdir(folder), [])
        finally:
            scene_file.MAX_JSON_VALUES = limit


if __name__ == "__main__":
    unittest.main()
