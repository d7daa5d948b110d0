"""The add-on's whole-array gathers (blender_addon/dwivedi_bake/gather.py), without Blender:
numpy's and the standard library's forms against a plain loop per element, on random meshes'
arrays (positions by corner, UVs by loop, tangents with their signs, triangles by material).
Numpy's form only where this interpreter has numpy."""
import array
import importlib.util
import os
import random
import unittest
from pathlib import Path

SOURCE = Path(os.environ.get("DWIVEDI_SOURCE_DIR", Path(__file__).resolve().parents[2]))
SPEC = importlib.util.spec_from_file_location("gather", SOURCE / "blender_addon" / "dwivedi_bake" / "gather.py")
gather = importlib.util.module_from_spec(SPEC)
SPEC.loader.exec_module(gather)


def forms():
    return (False, True) if gather.numpy is not None else (False,)


class GatherTest(unittest.TestCase):
    def setUp(self):
        self.random = random.Random(20)

    def floats(self, n):
        return array.array("f", (self.random.uniform(-2.0, 2.0) for _ in range(n)))

    def test_rows(self):
        for width, rows_in, picks in ((3, 500, 3000), (2, 40, 7), (1, 9, 100), (6, 1, 5), (4, 300, 0)):
            values = self.floats(width * rows_in)
            index = array.array("I", (self.random.randrange(rows_in) for _ in range(picks)))
            expected = [v for i in index for v in values[width * i:width * i + width]]
            for use_numpy in forms():
                got = gather.rows(values, width, index, use_numpy=use_numpy)
                self.assertEqual(list(got), expected, (width, use_numpy))
                self.assertEqual(bytes(memoryview(got).cast("B")), array.array("f", expected).tobytes())

    def test_rows_of_indices(self):
        indices = array.array("I", (self.random.randrange(1 << 31) for _ in range(3 * 200)))
        keep = array.array("I", (self.random.randrange(200) for _ in range(50)))
        expected = [v for t in keep for v in indices[3 * t:3 * t + 3]]
        for use_numpy in forms():
            got = gather.rows(indices, 3, keep, "I", use_numpy=use_numpy)
            self.assertEqual(list(got), expected)
            self.assertEqual(memoryview(got).format in ("I", "<I", "=I"), True)

    def test_loop_index_types(self):
        # Blender's loop numbers come as signed ints ("i"); a numpy result may be the index too.
        values = self.floats(2 * 30)
        loops = array.array("i", (self.random.randrange(30) for _ in range(90)))
        expected = [v for i in loops for v in values[2 * i:2 * i + 2]]
        for use_numpy in forms():
            self.assertEqual(list(gather.rows(values, 2, loops, use_numpy=use_numpy)), expected)

    def test_groups(self):
        for keys in (array.array("i", (self.random.choice((0, 2, 5)) for _ in range(1000))), array.array("i", [3] * 7),
                     array.array("i")):
            expected = [(k, [t for t, m in enumerate(keys) if m == k]) for k in sorted(set(keys))]
            for use_numpy in forms():
                got = [(k, list(p)) for k, p in gather.groups(keys, use_numpy=use_numpy)]
                self.assertEqual(got, expected)
                self.assertTrue(all(type(k) is int for k, _ in got))

    def test_interleave(self):
        first = self.floats(3 * 100)
        second = array.array("f", (self.random.choice((1.0, -1.0)) for _ in range(100)))
        expected = [v for k in range(100) for v in list(first[3 * k:3 * k + 3]) + [second[k]]]
        for use_numpy in forms():
            self.assertEqual(list(gather.interleave(first, 3, second, use_numpy=use_numpy)), expected)

    def test_corner_uvs(self):
        class Loops(list):
            pass

        class Layer:
            def __init__(self, uv):
                self.data = self
                self.uv = uv

            def foreach_get(self, name, out):
                out[:] = self.uv

        uv = self.floats(2 * 12)
        mesh = type("Mesh", (), {"loops": Loops(range(12))})()
        loops = array.array("i", [0, 5, 11, 3, 3, 7])
        expected = [v for i in loops for v in uv[2 * i:2 * i + 2]]
        self.assertEqual(list(gather.corner_uvs(mesh, Layer(uv), loops)), expected)


if __name__ == "__main__":
    unittest.main()
