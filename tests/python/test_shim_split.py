"""The shim's split bakes: BakeSettings.sample_first/sample_count, Image.write_partial and
dwivedi.merge_partials give the whole bake's pixels; a missing range raises Error naming the file."""
import dataclasses
import os
import tempfile
import unittest

import dwivedi


class ShimSplitTest(unittest.TestCase):
    def test_chunks_merge_to_the_whole_bake(self) -> None:
        scene = dwivedi.Scene.default()
        settings = dataclasses.replace(scene.settings, width=20, height=12, samples=10, threads=2,
                                       time_limit=0.0, target_error=0.0)
        whole = scene.bake(settings)
        with tempfile.TemporaryDirectory() as folder:
            paths = []
            for first, count in ((0, 3), (3, 7)):
                chunk = scene.bake(dataclasses.replace(settings, sample_first=first, sample_count=count))
                paths.append(os.path.join(folder, f"c{first}.dwvpart"))
                chunk.write_partial(paths[-1])
            merged = dwivedi.merge_partials(list(reversed(paths)))
            self.assertEqual(bytes(merged.rgba), bytes(whole.rgba))
            self.assertEqual(bytes(merged.variance), bytes(whole.variance))
            self.assertEqual(merged.stats.estimated_relative_error, whole.stats.estimated_relative_error)
            with self.assertRaises(dwivedi.Error) as caught:
                dwivedi.merge_partials(paths[1:])
            self.assertIn("c3.dwvpart", str(caught.exception))
            self.assertIn("missing", str(caught.exception))
            with self.assertRaises(dwivedi.Error):
                whole.write_partial(os.path.join(folder, "whole.dwvpart"))

    def test_chunks_of_differently_textured_scenes_do_not_merge(self) -> None:
        """The chunks' scene hash covers textures, their bindings and the UV layers they read: a
        chunk of a scene whose texture differs in one texel is another scene's."""
        def textured_scene(corner_texel: float, uv_layer_name: str = "UVMap") -> dwivedi.Scene:
            scene = dwivedi.Scene()
            material = scene.add_material(dwivedi.Material(subsurface_scale=0.2))
            positions = [-1.0, -1.0, 0.0, 1.0, -1.0, 0.0, 1.0, 1.0, 0.0, -1.0, 1.0, 0.0]
            uvs = [0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 1.0]
            scene.add_mesh(positions, [0, 1, 2, 0, 2, 3], material, uvs=uvs, uv_name=uv_layer_name)
            texels = [0.8, 0.5, 0.3] * 4
            texels[0] = corner_texel
            texture = scene.add_texture(texels, 2, 2, 3)
            scene.bind_texture(material, "base_color", texture, uv_layer=uv_layer_name)
            scene.add_light(dwivedi.SunLight(direction=(0.2, 0.3, -1.0), strength=3.0))
            scene.set_camera(dwivedi.Camera.look_at((0.0, -0.5, 3.0), (0.0, 0.0, 0.0)))
            scene.commit()
            return scene
        settings = dwivedi.BakeSettings(width=8, height=8, samples=4, threads=2)
        with tempfile.TemporaryDirectory() as folder:
            def chunk(scene: dwivedi.Scene, first: int, name: str) -> str:
                path = os.path.join(folder, name)
                scene.bake(dataclasses.replace(settings, sample_first=first, sample_count=2)).write_partial(path)
                scene.close()
                return path
            same = [chunk(textured_scene(0.8), 0, "a.dwvpart"), chunk(textured_scene(0.8), 2, "b.dwvpart")]
            dwivedi.merge_partials(same).close()
            for other in (textured_scene(0.7), textured_scene(0.8, "Other")):
                foreign = chunk(other, 2, "c.dwvpart")
                with self.assertRaises(dwivedi.Error) as caught:
                    dwivedi.merge_partials([same[0], foreign])
                self.assertIn("another scene", str(caught.exception))


if __name__ == "__main__":
    unittest.main()
