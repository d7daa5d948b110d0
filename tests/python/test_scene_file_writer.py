"""dwivedi.scene_file.SceneFileWriter (the add-on's "Export for a farm"): a scene built through the
shim's calls, written as a scene file and loaded back, bakes the same bits as the scene built in
memory; every material field, every light kind and the camera survive. A planted change of one
material field in the file changes the image (the comparison can fail). Standard library only."""
import dataclasses
import json
import math
import os
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


class SceneFileWriterTest(unittest.TestCase):
    def test_written_scene_bakes_the_same_bits(self) -> None:
        memory = dwivedi.Scene()
        build(memory)
        memory.commit()
        writer = SceneFileWriter()
        build(writer)
        settings = dict(width=24, height=16, samples=8, technique="auto", seed=5)
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "scene.json")
            writer.write(path, bake=settings)
            loaded = dwivedi.Scene.load(path)
            self.assertEqual((loaded.settings.width, loaded.settings.samples, loaded.settings.seed), (24, 8, 5))
            options = dataclasses.replace(loaded.settings, threads=2)
            a, b = memory.bake(options), loaded.bake(options)
            self.assertEqual(bytes(a.rgba), bytes(b.rgba))
            self.assertEqual(bytes(a.variance), bytes(b.variance))
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

    def test_what_a_file_cannot_hold_is_refused(self) -> None:
        writer = scene_file.SceneFileWriter()
        for call in (lambda: writer.add_texture([0.5] * 3, 1, 1, 3), lambda: writer.bind_texture(0, "base_color", 0),
                     lambda: writer.set_world_environment([0.5] * 3, 1, 1)):
            with self.assertRaises(dwivedi.Error) as caught:
                call()
            self.assertIn("bake this scene on one machine", str(caught.exception))

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
