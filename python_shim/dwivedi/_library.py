"""Finding and loading libdwivedi, and the ctypes declarations of the part of capi the shim uses.

Nothing here runs at import time: the library is looked for on the first call that needs it
(``library()``), so that ``import dwivedi`` works on a machine without it and the error comes with
the list of places that were searched. Every declaration mirrors capi/dwivedi.h, the contract.
"""
from __future__ import annotations

import ctypes
import ctypes.util
import os
import threading
from pathlib import Path
from typing import Dict, Iterator, List, Optional, Sequence, Tuple

# The environment variable naming the library file to load, bypassing the search.
ENV_VARIABLE = "DWIVEDI_LIBRARY"
# The file names of the library, the SONAME (libdwivedi.so.<DWV_ABI_VERSION>) first.
LIBRARY_FILE_NAMES = ("libdwivedi.so.1", "libdwivedi.so")
# A file only dwivedi's source tree has: the directory holding it is the repository root.
SOURCE_TREE_MARKER = Path("capi") / "dwivedi.h"

# dwv_result_t values (capi/dwivedi.h).
DWV_SUCCESS = 0
DWV_ERROR_OUT_OF_RANGE = 3
DWV_ERROR_UNKNOWN_NAME = 5


class Error(ValueError):
    """A call into dwivedi failed, or the library could not be loaded.

    ``str(error)`` and ``error.message`` hold the library's message (dwv_last_error_message) or,
    for a library that could not be loaded, where it was looked for. ``error.code`` is the
    dwv_result_t of the failed call (for instance 3, DWV_ERROR_OUT_OF_RANGE), or None when the
    library could not be loaded.
    """

    def __init__(self, message: str, code: Optional[int] = None) -> None:
        super().__init__(message)
        self.message = message
        self.code = code

    def __reduce__(self) -> Tuple[type, Tuple[str, Optional[int]]]:
        # Keep .code through pickling (ValueError would rebuild from the message alone).
        return (type(self), (self.message, self.code))


# Error is part of the public API: show it where users import it from.
Error.__module__ = "dwivedi"


class _SizedStructure(ctypes.Structure):
    """A capi struct that begins with struct_size, constructed with struct_size set to the size of
    the struct as its DWV_..._INIT macro sets it (the other fields start at 0)."""

    def __init__(self) -> None:
        super().__init__(ctypes.sizeof(type(self)))


class DiffusionLength(_SizedStructure):
    """dwv_diffusion_length_t, with struct_size set as DWV_DIFFUSION_LENGTH_INIT does."""

    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("method", ctypes.c_int32),
        ("albedo", ctypes.c_double),
        ("kappa", ctypes.c_double),
        ("one_minus_kappa", ctypes.c_double),
        ("log_one_minus_kappa", ctypes.c_double),
        ("v0", ctypes.c_double),
        ("log_ratio", ctypes.c_double),
    ]


class Dwivedi(_SizedStructure):
    """dwv_dwivedi_t, with struct_size set as DWV_DWIVEDI_INIT does."""

    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("method", ctypes.c_int32),
        ("albedo", ctypes.c_double),
        ("kappa", ctypes.c_double),
        ("one_minus_kappa", ctypes.c_double),
        ("log_ratio", ctypes.c_double),
        ("albedo_eff", ctypes.c_double),
        ("kappa_f", ctypes.c_float),
        ("one_minus_kappa_f", ctypes.c_float),
        ("log_ratio_f", ctypes.c_float),
        ("albedo_eff_f", ctypes.c_float),
    ]


class DwivediSample(_SizedStructure):
    """dwv_dwivedi_sample_t, with struct_size set as DWV_DWIVEDI_SAMPLE_INIT does."""

    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("cos_theta", ctypes.c_double),
        ("one_minus_cos", ctypes.c_double),
        ("one_plus_cos", ctypes.c_double),
        ("pdf", ctypes.c_double),
        ("stretch", ctypes.c_double),
    ]


_result_t = ctypes.c_int32
_method_t = ctypes.c_int32
_double_p = ctypes.POINTER(ctypes.c_double)
_dwivedi_p = ctypes.POINTER(Dwivedi)

# name -> (restype, argtypes) of every function the shim calls.
_PROTOTYPES: Dict[str, Tuple[object, Sequence[object]]] = {
    "dwv_version_string": (ctypes.c_char_p, ()),
    "dwv_result_string": (ctypes.c_char_p, (_result_t,)),
    "dwv_last_error_message": (ctypes.c_char_p, ()),
    "dwv_v0_method_name": (ctypes.c_char_p, (_method_t,)),
    "dwv_v0_method_from_name": (_result_t, (ctypes.c_char_p, ctypes.POINTER(_method_t))),
    "dwv_diffusion_length": (_result_t, (ctypes.c_double, _method_t, ctypes.POINTER(DiffusionLength))),
    "dwv_dwivedi_init": (_result_t, (_dwivedi_p, ctypes.c_double, _method_t)),
    "dwv_dwivedi_sample": (_result_t, (_dwivedi_p, ctypes.c_double, _double_p)),
    "dwv_dwivedi_pdf": (_result_t, (_dwivedi_p, ctypes.c_double, _double_p)),
    "dwv_dwivedi_sample_pdf": (_result_t, (_dwivedi_p, ctypes.c_double, ctypes.POINTER(DwivediSample))),
    "dwv_dwivedi_stretch": (_result_t, (_dwivedi_p, ctypes.c_double, _double_p)),
}

_lock = threading.Lock()
_loaded: Optional[Tuple[ctypes.CDLL, str]] = None


def _open(name: str) -> ctypes.CDLL:
    """dlopen `name` and declare every prototype; OSError or AttributeError if either fails."""
    lib = ctypes.CDLL(name)
    for function_name, (restype, argtypes) in _PROTOTYPES.items():
        function = getattr(lib, function_name)
        function.restype = restype
        function.argtypes = list(argtypes)
    return lib


def _package_dirs() -> List[Path]:
    """The package's directory as imported and with symbolic links resolved (an add-on may link
    to the source tree), without repeats."""
    here = Path(__file__).absolute().parent
    dirs = [here, here.resolve()]
    return [d for i, d in enumerate(dirs) if d not in dirs[:i]]


def _build_dirs(root: Path) -> List[Path]:
    """root/build first, then root's other build*/ directories holding the library, the most
    recently built first."""
    others = []
    for d in root.glob("build*"):
        library_file = d / LIBRARY_FILE_NAMES[0]
        if d.name != "build" and library_file.is_file():
            others.append((-library_file.stat().st_mtime, d.name, d))
    return [root / "build"] + [d for _, _, d in sorted(others)]


def _file_candidates(notes: List[str]) -> Iterator[Path]:
    """Library files to try, in order: beside the package (its directory, then its parent), then
    the build directories of the source tree the package sits in. Appends to `notes` what was
    not a candidate (no source tree above the package)."""
    for package_dir in _package_dirs():
        for d in (package_dir, package_dir.parent):
            for file_name in LIBRARY_FILE_NAMES:
                yield d / file_name
    for package_dir in _package_dirs():
        root = next((a for a in package_dir.parents if (a / SOURCE_TREE_MARKER).is_file()), None)
        if root is None:
            notes.append(f"no source tree (a directory with {SOURCE_TREE_MARKER}) above {package_dir}")
            continue
        for d in _build_dirs(root):
            yield d / LIBRARY_FILE_NAMES[0]


def _system_names() -> List[str]:
    """Names for the dynamic linker's own search (LD_LIBRARY_PATH, ld.so.cache, system dirs)."""
    names: List[str] = []
    for name in (ctypes.util.find_library("dwivedi"), LIBRARY_FILE_NAMES[0]):
        if name and name not in names:
            names.append(name)
    return names


def _load() -> Tuple[ctypes.CDLL, str]:
    """Finds and opens the library; Error listing every place tried if there is none."""
    configured = os.environ.get(ENV_VARIABLE, "")
    if configured:
        # An explicit choice: never fall back to another library behind the user's back.
        # Opened by absolute path, because dlopen searches the system for a name without a slash.
        path = os.path.abspath(configured)
        shown = f"{ENV_VARIABLE}={configured}" + (f" ({path})" if path != configured else "")
        if not Path(path).is_file():
            raise Error(f"{shown} is not a file (unset {ENV_VARIABLE} to search for libdwivedi instead)")
        try:
            return _open(path), path
        except (OSError, AttributeError) as error:
            raise Error(f"{shown} cannot be loaded as libdwivedi: {error}") from None

    looked: List[str] = [f"{ENV_VARIABLE} (not set)"]
    notes: List[str] = []
    seen: List[Path] = []
    for candidate in _file_candidates(notes):
        if candidate in seen:
            continue
        seen.append(candidate)
        if not candidate.is_file():
            looked.append(f"{candidate} (no such file)")
            continue
        try:
            return _open(str(candidate)), str(candidate)
        except (OSError, AttributeError) as error:
            looked.append(f"{candidate} (cannot be loaded: {error})")
    for name in _system_names():
        try:
            return _open(name), name
        except (OSError, AttributeError) as error:
            looked.append(f"{name} by the system's library search ({error})")
    raise Error("libdwivedi was not found. Looked at:\n  " + "\n  ".join(looked + notes) +
                f"\nBuild it (cmake --build build) or set {ENV_VARIABLE} to the path of libdwivedi.so.1.")


def _loaded_library() -> Tuple[ctypes.CDLL, str]:
    """The library and where it came from, found and opened on the first call (thread-safe)."""
    global _loaded
    with _lock:
        if _loaded is None:
            _loaded = _load()
        return _loaded


def library() -> ctypes.CDLL:
    """The loaded library; Error if there is none."""
    return _loaded_library()[0]


def library_path() -> str:
    """The file the library was loaded from, or for a library found by the system's search the
    name it was found by (loading it first if needed); Error if there is none."""
    return _loaded_library()[1]


def check(result: int) -> None:
    """Raises Error with the calling thread's library message unless `result` is DWV_SUCCESS."""
    if result == DWV_SUCCESS:
        return
    lib = library()
    message = (lib.dwv_last_error_message() or b"").decode("utf-8", "replace")
    if not message:
        message = (lib.dwv_result_string(result) or b"").decode("utf-8", "replace")
    raise Error(message, result)
