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
from typing import Callable, Dict, Iterator, List, Optional, Sequence, Tuple

# The environment variable naming the library file to load, bypassing the search.
ENV_VARIABLE = "DWIVEDI_LIBRARY"
# DWV_ABI_VERSION of capi/dwivedi.h: the ABI generation these declarations are written for (the
# library's SONAME is libdwivedi.so.<ABI_VERSION>).
ABI_VERSION = 1
# The file names of the library, the SONAME (libdwivedi.so.<DWV_ABI_VERSION>) first.
LIBRARY_FILE_NAMES = ("libdwivedi.so.1", "libdwivedi.so")
# A file only dwivedi's source tree has: the directory holding it is the repository root.
SOURCE_TREE_MARKER = Path("capi") / "dwivedi.h"

# dwv_result_t values (capi/dwivedi.h).
DWV_SUCCESS = 0
DWV_ERROR_NULL_POINTER = 1
DWV_ERROR_INVALID_ARGUMENT = 2
DWV_ERROR_OUT_OF_RANGE = 3
DWV_ERROR_STRUCT_SIZE = 4
DWV_ERROR_UNKNOWN_NAME = 5
DWV_ERROR_OUT_OF_MEMORY = 6
DWV_ERROR_INTERNAL = 7
DWV_ERROR_INVALID_STATE = 8
DWV_ERROR_CANCELLED = 9
DWV_ERROR_IO = 10
DWV_ERROR_FORMAT = 11


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


# ---- The baker API (scenes, bakes, images, output, scene files): capi/dwivedi.h's last part. ----

_Vec3 = ctypes.c_double * 3
_Transform = ctypes.c_double * 12


class Material(_SizedStructure):
    """dwv_material_t."""

    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("kind", ctypes.c_int32),
        ("base_color", _Vec3),
        ("subsurface_weight", ctypes.c_double),
        ("subsurface_color", _Vec3),
        ("subsurface_radius", _Vec3),
        ("subsurface_scale", ctypes.c_double),
        ("subsurface_anisotropy", ctypes.c_double),
        ("subsurface_ior", ctypes.c_double),
        ("subsurface_exit", ctypes.c_int32),
        ("reserved", ctypes.c_uint32),
        ("roughness", ctypes.c_double),
        ("subsurface_model", ctypes.c_int32),
        ("specular_model", ctypes.c_int32),
        ("ior", ctypes.c_double),
        ("specular", ctypes.c_double),
        ("specular_tint", _Vec3),
        ("specular_multiscatter", ctypes.c_int32),
        ("reserved2", ctypes.c_uint32),
        ("subsurface_min_footprint", ctypes.c_double),
    ]


class Mesh(_SizedStructure):
    """dwv_mesh_t (the pointers borrow the caller's buffers for the duration of one call)."""

    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("vertex_count", ctypes.c_uint32),
        ("triangle_count", ctypes.c_uint32),
        ("material_id", ctypes.c_uint32),
        ("positions", ctypes.c_void_p),
        ("indices", ctypes.c_void_p),
        ("normals", ctypes.c_void_p),
        ("uvs", ctypes.c_void_p),
        ("transform", _Transform),
        ("shadow_terminator_geometry_offset", ctypes.c_double),
        ("uv_layer_count", ctypes.c_uint32),
        ("reserved_uv", ctypes.c_uint32),
        ("uv_layers", ctypes.c_void_p),
        ("uv_layer_names", ctypes.c_void_p),
        ("tangents", ctypes.c_void_p),
    ]


class TextureDesc(_SizedStructure):
    """dwv_texture_desc_t (texels borrowed for one call)."""

    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("width", ctypes.c_uint32),
        ("height", ctypes.c_uint32),
        ("channels", ctypes.c_uint32),
        ("format", ctypes.c_int32),
        ("extension", ctypes.c_int32),
        ("interpolation", ctypes.c_int32),
        ("reserved", ctypes.c_uint32),
        ("texels", ctypes.c_void_p),
    ]


class TextureBinding(_SizedStructure):
    """dwv_texture_binding_t."""

    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("input", ctypes.c_int32),
        ("texture_id", ctypes.c_uint32),
        ("invert", ctypes.c_int32),
        ("uv_layer", ctypes.c_char_p),
        ("blend", ctypes.c_double),
        ("strength", ctypes.c_double),
        ("distance", ctypes.c_double),
        ("bump_shadowing", ctypes.c_int32),
        ("reserved", ctypes.c_uint32),
    ]


class LightDesc(_SizedStructure):
    """dwv_light_desc_t."""

    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("kind", ctypes.c_int32),
        ("color", _Vec3),
        ("strength", ctypes.c_double),
        ("direction", _Vec3),
        ("angle", ctypes.c_double),
        ("position", _Vec3),
        ("radius", ctypes.c_double),
        ("transform", _Transform),
        ("size_x", ctypes.c_double),
        ("size_y", ctypes.c_double),
        ("spot_size", ctypes.c_double),
        ("spot_blend", ctypes.c_double),
        ("spot_falloff", ctypes.c_int32),
        ("reserved", ctypes.c_uint32),
        ("point_shape", ctypes.c_int32),
        ("reserved_shape", ctypes.c_uint32),
    ]


class EnvironmentDesc(_SizedStructure):
    """dwv_environment_t."""

    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("width", ctypes.c_uint32),
        ("height", ctypes.c_uint32),
        ("interpolation", ctypes.c_int32),
        ("texels", ctypes.c_void_p),
        ("strength", ctypes.c_double),
        ("rotation", ctypes.c_double * 9),
    ]


class CameraDesc(_SizedStructure):
    """dwv_camera_t."""

    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("kind", ctypes.c_int32),
        ("transform", _Transform),
        ("focal_length", ctypes.c_double),
        ("sensor_width", ctypes.c_double),
        ("ortho_scale", ctypes.c_double),
    ]


class BakeProgress(_SizedStructure):
    """dwv_bake_progress_t."""

    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("done", ctypes.c_uint32),
        ("fraction", ctypes.c_double),
        ("seconds", ctypes.c_double),
        ("estimated_relative_error", ctypes.c_double),
        ("samples_per_pixel", ctypes.c_uint64),
        ("events", ctypes.c_uint64),
    ]


# dwv_progress_callback_t. The shim polls progress on the caller's thread instead of passing a
# callback (Python callbacks on the library's threads would run user code, Blender's API among
# it, off the main thread), so the field stays NULL.
ProgressCallback = ctypes.CFUNCTYPE(ctypes.c_int32, ctypes.c_void_p, ctypes.POINTER(BakeProgress))


class BakeOptions(_SizedStructure):
    """dwv_bake_options_t, with the defaults of DWV_BAKE_OPTIONS_INIT."""

    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("target", ctypes.c_int32),
        ("width", ctypes.c_uint32),
        ("height", ctypes.c_uint32),
        ("uv_mesh", ctypes.c_uint32),
        ("uv_margin", ctypes.c_uint32),
        ("technique", ctypes.c_int32),
        ("samples", ctypes.c_uint64),
        ("time_limit", ctypes.c_double),
        ("target_error", ctypes.c_double),
        ("threads", ctypes.c_uint32),
        ("max_events", ctypes.c_uint32),
        ("seed", ctypes.c_uint64),
        ("tile_size", ctypes.c_uint32),
        ("channel_walks", ctypes.c_uint32),
        ("progress", ProgressCallback),
        ("progress_user", ctypes.c_void_p),
        ("sample_first", ctypes.c_uint64),
        ("sample_count", ctypes.c_uint64),
        ("transparent_background", ctypes.c_int32),
        ("reserved", ctypes.c_uint32),
        ("passes", ctypes.c_uint32),
        ("reserved2", ctypes.c_uint32),
        ("max_bounces", ctypes.c_uint32),
        ("diffuse_bounces", ctypes.c_uint32),
        ("glossy_bounces", ctypes.c_uint32),
        ("transmission_bounces", ctypes.c_uint32),
        ("min_light_bounces", ctypes.c_uint32),
        ("subsurface_after_diffuse", ctypes.c_int32),
        ("blur_glossy", ctypes.c_double),
        ("pixel_filter", ctypes.c_int32),
        ("reserved3", ctypes.c_uint32),
        ("filter_width", ctypes.c_double),
        ("uv_jitter", ctypes.c_int32),
        ("reserved4", ctypes.c_uint32),
    ]

    def __init__(self) -> None:
        super().__init__()
        self.width = 256
        self.height = 256
        self.uv_margin = 16
        self.samples = 64
        self.max_bounces = 12
        self.diffuse_bounces = 4
        self.glossy_bounces = 4
        self.transmission_bounces = 12
        self.blur_glossy = 1.0
        self.filter_width = 1.0


class ImageInfo(_SizedStructure):
    """dwv_image_info_t."""

    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("width", ctypes.c_uint32),
        ("height", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("rgba", ctypes.c_void_p),
        ("variance", ctypes.c_void_p),
        ("samples", ctypes.c_void_p),
    ]


class BakeStats(_SizedStructure):
    """dwv_bake_stats_t."""

    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("technique", ctypes.c_int32),
        ("samples_per_pixel", ctypes.c_uint64),
        ("samples", ctypes.c_uint64),
        ("events", ctypes.c_uint64),
        ("walks", ctypes.c_uint64),
        ("seconds", ctypes.c_double),
        ("estimated_relative_error", ctypes.c_double),
        ("mean_rgb", _Vec3),
        ("truncated_weight", _Vec3),
        ("features", ctypes.c_uint32),
        ("threads", ctypes.c_uint32),
        ("warnings", ctypes.c_uint64),
        ("error_vs_time_count", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("path_rays", ctypes.c_uint64),
    ]


class ErrorPoint(ctypes.Structure):
    """dwv_error_point_t (no struct_size: an element of an array)."""

    _fields_ = [
        ("seconds", ctypes.c_double),
        ("estimated_relative_error", ctypes.c_double),
        ("samples_per_pixel", ctypes.c_uint64),
    ]


class DisplayOptions(_SizedStructure):
    """dwv_display_options_t, with the defaults of DWV_DISPLAY_OPTIONS_INIT."""

    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("config_path", ctypes.c_char_p),
        ("display", ctypes.c_char_p),
        ("view", ctypes.c_char_p),
        ("look", ctypes.c_char_p),
        ("exposure", ctypes.c_double),
        ("gamma", ctypes.c_double),
    ]

    def __init__(self) -> None:
        super().__init__()
        self.gamma = 1.0


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

_p = ctypes.POINTER
_handle_p = ctypes.c_void_p  # dwv_scene_t *, dwv_bake_t *, dwv_image_t * (opaque)
_handle_pp = ctypes.POINTER(ctypes.c_void_p)

# The baker API: a library built before it lacks these, and the kernel functions must keep working
# with such a library; a missing one raises Error when called (see function()).
_BAKER_PROTOTYPES: Dict[str, Tuple[object, Sequence[object]]] = {
    "dwv_technique_name": (ctypes.c_char_p, (ctypes.c_int32,)),
    "dwv_technique_from_name": (_result_t, (ctypes.c_char_p, _p(ctypes.c_int32))),
    "dwv_channel_walks_name": (ctypes.c_char_p, (ctypes.c_uint32,)),
    "dwv_channel_walks_from_name": (_result_t, (ctypes.c_char_p, _p(ctypes.c_uint32))),
    "dwv_pixel_filter_name": (ctypes.c_char_p, (ctypes.c_int32,)),
    "dwv_pixel_filter_from_name": (_result_t, (ctypes.c_char_p, _p(ctypes.c_int32))),
    "dwv_feature_name": (ctypes.c_char_p, (ctypes.c_uint32,)),
    "dwv_scene_create": (_result_t, (_handle_pp,)),
    "dwv_scene_retain": (_result_t, (_handle_p,)),
    "dwv_scene_release": (None, (_handle_p,)),
    "dwv_scene_add_material": (_result_t, (_handle_p, _p(Material), _p(ctypes.c_uint32))),
    "dwv_scene_add_mesh": (_result_t, (_handle_p, _p(Mesh), _p(ctypes.c_uint32))),
    "dwv_scene_add_light": (_result_t, (_handle_p, _p(LightDesc))),
    "dwv_scene_add_texture": (_result_t, (_handle_p, _p(TextureDesc), _p(ctypes.c_uint32))),
    "dwv_scene_add_texture_file": (_result_t, (_handle_p, ctypes.c_char_p, _p(TextureDesc), _p(ctypes.c_uint32))),
    "dwv_scene_bind_texture": (_result_t, (_handle_p, ctypes.c_uint32, _p(TextureBinding))),
    "dwv_scene_texture_memory": (_result_t, (_handle_p, _p(ctypes.c_uint64), _p(ctypes.c_uint64))),
    "dwv_scene_set_world": (_result_t, (_handle_p, _p(ctypes.c_double), ctypes.c_double)),
    "dwv_scene_set_world_environment": (_result_t, (_handle_p, _p(EnvironmentDesc))),
    "dwv_scene_set_world_environment_file": (_result_t, (_handle_p, ctypes.c_char_p, _p(EnvironmentDesc))),
    "dwv_scene_set_camera": (_result_t, (_handle_p, _p(CameraDesc))),
    "dwv_scene_commit": (_result_t, (_handle_p,)),
    "dwv_bake_start": (_result_t, (_handle_p, _p(BakeOptions), _handle_pp)),
    "dwv_bake_wait": (_result_t, (_handle_p, ctypes.c_double, _p(ctypes.c_int32))),
    "dwv_bake_progress": (_result_t, (_handle_p, _p(BakeProgress))),
    "dwv_bake_cancel": (_result_t, (_handle_p,)),
    "dwv_bake_finish": (_result_t, (_handle_p, _handle_pp)),
    "dwv_bake_release": (None, (_handle_p,)),
    "dwv_bake": (_result_t, (_handle_p, _p(BakeOptions), _handle_pp)),
    "dwv_image_info": (_result_t, (_handle_p, _p(ImageInfo))),
    "dwv_image_stats": (_result_t, (_handle_p, _p(BakeStats))),
    "dwv_image_error_vs_time": (_result_t, (_handle_p, _p(ErrorPoint), ctypes.c_uint32, _p(ctypes.c_uint32))),
    "dwv_image_retain": (_result_t, (_handle_p,)),
    "dwv_image_release": (None, (_handle_p,)),
    "dwv_image_create": (_result_t, (ctypes.c_uint32, ctypes.c_uint32, ctypes.c_void_p, _handle_pp)),
    "dwv_image_write_exr": (_result_t, (_handle_p, ctypes.c_char_p)),
    "dwv_image_write_partial": (_result_t, (_handle_p, ctypes.c_char_p)),
    "dwv_pass_name": (ctypes.c_char_p, (ctypes.c_int32,)),
    "dwv_bake_type_passes": (_result_t, (ctypes.c_int32, ctypes.c_uint32, _p(ctypes.c_uint32))),
    "dwv_image_passes": (_result_t, (_handle_p, _p(ctypes.c_uint32))),
    "dwv_image_pass": (_result_t, (_handle_p, ctypes.c_int32, _handle_pp)),
    "dwv_image_bake_type": (_result_t, (_handle_p, ctypes.c_int32, ctypes.c_uint32, _handle_pp)),
    "dwv_image_write_exr_layers": (_result_t, (_handle_p, ctypes.c_char_p)),
    "dwv_merge_partials": (_result_t, (ctypes.POINTER(ctypes.c_char_p), ctypes.c_uint32, ctypes.POINTER(_handle_p))),
    "dwv_image_write_display_png": (_result_t, (_handle_p, ctypes.c_char_p, _p(DisplayOptions))),
    "dwv_image_to_display": (_result_t, (_handle_p, _p(DisplayOptions), ctypes.c_void_p, ctypes.c_uint64)),
    "dwv_scene_load": (_result_t, (ctypes.c_char_p, _handle_pp, _p(BakeOptions))),
    "dwv_scene_load_json": (_result_t, (ctypes.c_char_p, ctypes.c_uint64, ctypes.c_char_p, _handle_pp,
                                        _p(BakeOptions))),
    "dwv_scene_create_default": (_result_t, (_handle_pp, _p(BakeOptions))),
}

# Every function the shim declares: a library that lacks one is older than this shim.
LIBRARY_FUNCTIONS: Tuple[str, ...] = tuple(_PROTOTYPES) + tuple(_BAKER_PROTOTYPES)

_lock = threading.Lock()
_loaded: Optional[Tuple[ctypes.CDLL, str]] = None


def _open(name: str) -> ctypes.CDLL:
    """dlopen `name` and declare every prototype; OSError or AttributeError if either fails."""
    lib = ctypes.CDLL(name)
    for function_name, (restype, argtypes) in _PROTOTYPES.items():
        function = getattr(lib, function_name)
        function.restype = restype
        function.argtypes = list(argtypes)
    for function_name, (restype, argtypes) in _BAKER_PROTOTYPES.items():
        function = getattr(lib, function_name, None)
        if function is not None:
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


def loaded_library_path() -> Optional[str]:
    """Where the library in use came from: the file it was loaded from, or for a library found by
    the system's search the name it was found by; None if none was loaded yet. Never loads one
    (``library_path()`` does). Public as ``dwivedi.loaded_library_path()``."""
    with _lock:
        return None if _loaded is None else _loaded[1]


# The earlier, private name (kept for scripts that used it).
loaded_path = loaded_library_path


def use_library(path: Optional[str]) -> Optional[str]:
    """Loads the library from `path` (a file) in place of the one found by the search, for every
    later call; returns the absolute path. Objects made with the previous library keep using it.
    Error if the file is missing or is not libdwivedi (the previous choice then stays).
    use_library(None) forgets the choice: the next call searches again (see library_path)."""
    global _loaded
    if path is None:
        with _lock:
            _loaded = None
        return None
    absolute = os.path.abspath(os.fspath(path))
    if not Path(absolute).is_file():
        raise Error(f"the library {absolute} is not a file")
    try:
        lib = _open(absolute)
    except (OSError, AttributeError) as error:
        raise Error(f"{absolute} cannot be loaded as libdwivedi: {error}") from None
    with _lock:
        _loaded = (lib, absolute)
    return absolute


def function(name: str) -> Callable[..., object]:
    """The library's function `name`, declared; Error if this library predates it."""
    lib = library()
    found = getattr(lib, name, None) if name in _BAKER_PROTOTYPES or name in _PROTOTYPES else None
    if found is None:
        raise Error(f"{name} is missing from {library_path()}: that libdwivedi was built without this part "
                    "of the baker API (rebuild it, or point DWIVEDI_LIBRARY at a newer one)", DWV_ERROR_INVALID_STATE)
    return found


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
