"""Turning Python data into C arrays for the library, without copies where the layout allows.

A buffer (bytes, bytearray, array.array, memoryview, a numpy array: anything with the buffer
protocol) that is C-contiguous and already holds the C type the library wants (or raw bytes,
read as native values of that type) is passed by address; anything else (a sequence of numbers or of tuples, a float64 array, a strided view) is
converted once into an array.array of the right type. Values are checked for count here; the
library itself checks the values (finite, in range) and says which one is wrong.
"""
from __future__ import annotations

import array
import ctypes
import numbers
import struct
import sys
from typing import Any, List, Optional, Sequence, Tuple

from ._library import DWV_ERROR_INVALID_ARGUMENT, Error

# struct-module format characters (with byte-order prefixes stripped) that are the C types here.
_FLOAT32_FORMATS = {"f"}
_UINT32_FORMATS = {c for c in "IiLl" if struct.calcsize(c) == 4}


class CArray:
    """A C array borrowed for one call: .address (an int for a void * argument), .count values.
    Keeps the Python object that owns the memory alive while it lives."""

    __slots__ = ("address", "count", "_owner")

    def __init__(self, address: int, count: int, owner: object) -> None:
        self.address = address
        self.count = count
        self._owner = owner


def _buffer_format(view: memoryview) -> str:
    """The format without a prefix that means native byte order ('@', '=', or '<' on a
    little-endian machine, as numpy and ctypes write it)."""
    fmt = view.format
    native = "<" if sys.byteorder == "little" else ">"
    return fmt[1:] if fmt[:1] in ("@", "=", native) else fmt


def _address_of(view: memoryview, owner: object) -> Optional[CArray]:
    """The address of a C-contiguous buffer: ctypes can take it from a writable buffer directly;
    a read-only one (bytes, a read-only numpy array) is wrapped through its memoryview's object
    when possible, else None (the caller copies)."""
    nbytes = view.nbytes
    if nbytes == 0:
        return CArray(0, 0, owner)
    if not view.readonly:
        holder = (ctypes.c_char * nbytes).from_buffer(view)
        return CArray(ctypes.addressof(holder), 0, (holder, view, owner))
    return None


def _flatten(values: Any, name: str) -> List[Any]:
    """A flat list from numbers or (nested) sequences of numbers, such as [(x, y, z), ...]."""
    flat: List[Any] = []

    def visit(item: Any) -> None:
        if isinstance(item, (str, bytes)):
            raise TypeError(f"{name} must hold numbers, not {type(item).__name__}")
        if isinstance(item, numbers.Number) and not isinstance(item, bool):
            flat.append(item)
            return
        if isinstance(item, bool):
            raise TypeError(f"{name} must hold numbers, not bool")
        try:
            iterator = iter(item)
        except TypeError:
            raise TypeError(f"{name} must hold numbers or sequences of numbers, not {type(item).__name__}") from None
        for sub in iterator:
            visit(sub)

    visit(values)
    return flat


def as_c_array(values: Any, kind: str, name: str, group: int) -> CArray:
    """`values` as a C array of `kind` ('f': float, 'I': uint32), a multiple of `group` values.

    Zero-copy for C-contiguous buffers of exactly that type; a copy otherwise."""
    view: Optional[memoryview] = None
    try:
        view = memoryview(values)
    except TypeError:
        view = None
    if view is not None:
        fmt = _buffer_format(view)
        wanted = _FLOAT32_FORMATS if kind == "f" else _UINT32_FORMATS
        raw = fmt in ("B", "b", "c")  # raw bytes (bytes, struct.pack output): native C values
        if view.c_contiguous and ((fmt in wanted and view.itemsize == 4) or (raw and view.nbytes % 4 == 0)):
            count = view.nbytes // 4
            _check_group(count, name, group)
            found = _address_of(view, values)
            if found is not None:
                found.count = count
                return found
            # Read-only and of the right type: one copy into a writable array.
            copied = array.array(kind if kind == "f" else _uint32_code())
            copied.frombytes(view.tobytes())
            return _from_array(copied, name, group)
        try:
            items = view.tolist()
        except (NotImplementedError, TypeError, ValueError):
            raise TypeError(f"{name}: a buffer of format {view.format!r} cannot be read as numbers") from None
        return _from_list(_flatten(items, name), kind, name, group)
    return _from_list(_flatten(values, name), kind, name, group)


def _uint32_code() -> str:
    for code in "IL":
        if array.array(code).itemsize == 4:
            return code
    raise RuntimeError("this Python has no 32-bit unsigned array type")  # pragma: no cover


def _from_list(flat: Sequence[Any], kind: str, name: str, group: int) -> CArray:
    if kind == "f":
        for v in flat:
            if not isinstance(v, numbers.Real):
                raise TypeError(f"{name} must hold real numbers, not {type(v).__name__}")
        try:
            made = array.array("f", [float(v) for v in flat])
        except OverflowError:
            raise Error(f"{name} holds a number too large for a float", DWV_ERROR_INVALID_ARGUMENT) from None
    else:
        ints = []
        for v in flat:
            if not isinstance(v, numbers.Integral):
                raise TypeError(f"{name} must hold integers, not {type(v).__name__}")
            if not 0 <= int(v) <= 0xFFFFFFFF:
                raise Error(f"{name} holds {int(v)}, outside 0 to 2^32 - 1", DWV_ERROR_INVALID_ARGUMENT)
            ints.append(int(v))
        made = array.array(_uint32_code(), ints)
    return _from_array(made, name, group)


def _from_array(made: array.array, name: str, group: int) -> CArray:
    _check_group(len(made), name, group)
    address, count = made.buffer_info()
    return CArray(address if count else 0, count, made)


def _check_group(count: int, name: str, group: int) -> None:
    if count % group:
        raise Error(f"{name} holds {count} values, not a multiple of {group}", DWV_ERROR_INVALID_ARGUMENT)


def real_tuple(values: Any, name: str, length: int) -> Tuple[float, ...]:
    """A tuple of `length` reals from any sequence (a colour, a vector)."""
    if isinstance(values, (str, bytes)):
        raise TypeError(f"{name} must be a sequence of {length} numbers, not {type(values).__name__}")
    try:
        items = list(values)
    except TypeError:
        raise TypeError(f"{name} must be a sequence of {length} numbers, not {type(values).__name__}") from None
    if len(items) != length:
        raise Error(f"{name} must have {length} values, not {len(items)}", DWV_ERROR_INVALID_ARGUMENT)
    out = []
    for v in items:
        if isinstance(v, bool) or not isinstance(v, numbers.Real):
            raise TypeError(f"{name} must hold real numbers, not {type(v).__name__}")
        out.append(float(v))
    return tuple(out)


def transform12(values: Any, name: str = "transform") -> Tuple[float, ...]:
    """A row-major 3 x 4 transform from 12 numbers, 16 (4 x 4 with the last row 0 0 0 1), or
    nested rows of either (a Blender mathutils.Matrix, a numpy 4 x 4 array, lists of lists)."""
    if values is None:
        return (1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0)
    flat = _flatten(values, name)
    for v in flat:
        if not isinstance(v, numbers.Real):
            raise TypeError(f"{name} must hold real numbers, not {type(v).__name__}")
    flat = [float(v) for v in flat]
    if len(flat) == 16:
        if flat[12:] != [0.0, 0.0, 0.0, 1.0]:
            raise Error(f"{name}: a 4 x 4 matrix must end in the row 0 0 0 1 (an affine transform), not "
                        f"{flat[12:]}", DWV_ERROR_INVALID_ARGUMENT)
        flat = flat[:12]
    if len(flat) != 12:
        raise Error(f"{name} must be 3 x 4 or 4 x 4 numbers, not {len(flat)}", DWV_ERROR_INVALID_ARGUMENT)
    return tuple(flat)
