"""Whole-array gathers for the mesh export, without a Python loop per element: numpy's indexing
where Blender's Python has numpy (the official builds, Debian's 3.4 with python3-numpy), else the
standard library's iterators (map, zip, itertools), which run their loops in C. Both give the
same values in the same order (tests/python/test_gather.py compares them); the numpy form is
about 10x faster on a million triangles.

Results are buffers of float32 ("f") or uint32 ("I") values that the shim passes to the library
without a copy: numpy arrays, or array.array without numpy.
"""
from __future__ import annotations

import array
import itertools
from typing import Any, List, Tuple

try:
    import numpy
except ImportError:  # Blender built against a Python without numpy (Debian's 4.x and 5.x packages)
    numpy = None

def rows(values: Any, width: int, index: Any, typecode: str = "f", use_numpy: bool = True) -> Any:
    """The `width`-wide rows of the flat buffer `values` at the row numbers `index`, one after
    the other: rows(co, 3, corner_vertices) is every corner's position."""
    if numpy is not None and use_numpy:
        # Each row as one opaque item, picked by numpy.take: several times faster than indexing a
        # 2-D array by rows (which steps through the row's values one by one).
        table = numpy.ascontiguousarray(_numpy(values), dtype=typecode)
        items = table.view(numpy.dtype((numpy.void, width * table.itemsize)))
        return numpy.take(items, _numpy(index)).view(typecode)
    # Each row as a bytes object, the picked ones joined: faster than a Python loop or a chain of
    # the values (which makes a Python float of each).
    out = array.array(typecode)
    out.frombytes(b"".join(map(_byte_rows(values, width).__getitem__, index)))
    return out


def groups(keys: Any, use_numpy: bool = True) -> List[Tuple[int, Any]]:
    """(key, the positions that hold it, as uint32) for each distinct value of `keys`, in
    increasing key order; the positions keep their order: groups(material_index) are the
    triangles of each material."""
    if numpy is not None and use_numpy:
        values = _numpy(keys)
        return [(int(key), numpy.flatnonzero(values == key).astype(numpy.uint32)) for key in numpy.unique(values)]
    return [(key, array.array("I", itertools.compress(range(len(keys)), map(key.__eq__, keys))))
            for key in sorted(set(keys))]


def interleave(first: Any, width: int, second: Any, use_numpy: bool = True) -> Any:
    """Rows of `width` values of `first` each followed by one value of `second` (float32): a
    tangent's xyz and its bitangent sign."""
    if numpy is not None and use_numpy:
        a = _numpy(first).astype("f", copy=False).reshape(-1, width)
        b = _numpy(second).astype("f", copy=False).reshape(-1, 1)
        return numpy.hstack((a, b)).reshape(-1)
    out = array.array("f")
    out.frombytes(b"".join(map(bytes.__add__, _byte_rows(first, width), _byte_rows(second, 1))))
    return out


def corner_uvs(mesh: Any, layer: Any, loops: Any) -> Any:
    """A Blender UV map's coordinates at the triangle corners whose loops are `loops` (2 floats
    each)."""
    loop_uv = array.array("f", bytes(8 * len(mesh.loops)))
    layer.data.foreach_get("uv", loop_uv)
    return rows(loop_uv, 2, loops)


def _byte_rows(values: Any, width: int) -> List[bytes]:
    """The rows of a buffer of 4-byte values, `width` values each, as bytes objects."""
    raw = values.tobytes()
    size = 4 * width
    return list(map(raw.__getitem__, map(slice, range(0, len(raw), size), range(size, len(raw) + size, size))))


def _numpy(values: Any) -> Any:
    """A numpy view of a buffer: array.array's type codes are numpy's type characters."""
    if isinstance(values, numpy.ndarray):
        return values
    return numpy.frombuffer(values, dtype=values.typecode)
