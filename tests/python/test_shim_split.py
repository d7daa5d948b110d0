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


if __name__ == "__main__":
    unittest.main()
