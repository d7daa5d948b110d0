"""Scenes, bakes and images: the baker part of capi/dwivedi.h, the Pythonic way.

    import dwivedi
    with dwivedi.Scene() as scene:
        wax = scene.add_material(dwivedi.Material(subsurface_color=(0.9, 0.6, 0.4),
                                                  subsurface_radius=(1.0, 0.5, 0.25), subsurface_scale=0.1))
        scene.add_mesh(positions, indices, material=wax)           # sequences or buffers
        scene.add_light(dwivedi.SunLight(direction=(0, 0, -1), strength=3.0))
        scene.set_camera(dwivedi.Camera.look_at((0, -4, 1), (0, 0, 0)))
        scene.commit()
        image = dwivedi.bake(scene, width=128, height=128, samples=64,
                             progress=lambda p: print(f"{p.fraction:.0%}"))
    image.write_exr("wax.exr")
    image.write_png("wax.png", view="Standard")

Units and conventions are Blender's (metres, sun irradiance in W/m^2, point and area power in W,
cameras looking along their local -z), see capi/dwivedi.h. A bake runs on the library's threads;
`bake()` waits for it on the calling thread in short slices, so Ctrl-C (KeyboardInterrupt)
cancels it within about 0.1 s and is raised again once the bake has stopped, and the progress
callback runs on the calling thread (safe for Blender's API).
"""
from __future__ import annotations

import ctypes
import math
import numbers
import os
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

from . import _library
from ._buffers import as_c_array, real_tuple, transform12
from ._library import Error

Color = Tuple[float, float, float]
Vector = Tuple[float, float, float]
PathLike = Union[str, "os.PathLike[str]"]

__all__ = [
    "Cancelled", "Material", "SunLight", "PointLight", "AreaLight", "SpotLight", "Camera", "Scene", "BakeSettings",
    "Progress", "Bake", "bake", "start_bake", "Image", "BakeStats", "ErrorPoint", "DisplaySettings",
    "techniques", "feature_names", "PASS_NAMES", "BAKE_TYPES", "BAKE_FILTERS", "bake_type_passes",
]


class Cancelled(Error):
    """The bake was cancelled (by cancel(), a progress callback returning True, or Ctrl-C); code 9."""

    def __init__(self, message: str = "the bake was cancelled", code: Optional[int] = _library.DWV_ERROR_CANCELLED
                 ) -> None:
        super().__init__(message, code)


Cancelled.__module__ = "dwivedi"


def _call(name: str, *args: Any) -> None:
    """Calls the library's `name` and turns a failure into Error (Cancelled for code 9)."""
    result = _library.function(name)(*args)
    if result == _library.DWV_ERROR_CANCELLED:
        message = (_library.library().dwv_last_error_message() or b"").decode("utf-8", "replace")
        raise Cancelled(message or "the bake was cancelled")
    _library.check(result)


def _environment_settings(c: Any, strength: float, rotation: Any, interpolation: str) -> None:
    """An EnvironmentDesc's strength, interpolation and rotation (3 x 3 nested or 9 numbers, None:
    none) from set_world_environment's arguments."""
    c.strength = _real("strength", strength)
    c.interpolation = _name_code("interpolation", interpolation, {"linear": 0, "closest": 1, "cubic": 2})
    values = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0] if rotation is None else list(rotation)
    if len(values) == 3:  # rows
        values = [x for row in values for x in row]
    c.rotation[:] = real_tuple(values, "rotation", 9)


def _real(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a real number, not {type(value).__name__}")
    return float(value)


def _uint(name: str, value: Any, bits: int = 32) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an int, not {type(value).__name__}")
    if not 0 <= int(value) < (1 << bits):
        raise Error(f"{name} = {int(value)} is outside 0 to 2^{bits} - 1", _library.DWV_ERROR_OUT_OF_RANGE)
    return int(value)


def _name_code(kind: str, value: Any, names: Dict[str, int]) -> int:
    if isinstance(value, bool) or not isinstance(value, (str, int)):
        raise TypeError(f"{kind} must be a str ({', '.join(names)}), not {type(value).__name__}")
    if isinstance(value, int):
        if value not in names.values():
            raise Error(f"unknown {kind} {value}", _library.DWV_ERROR_UNKNOWN_NAME)
        return value
    key = value.lower()
    if key not in names:
        raise Error(f"unknown {kind} {value!r} ({', '.join(names)})", _library.DWV_ERROR_UNKNOWN_NAME)
    return names[key]


def techniques() -> Tuple[str, ...]:
    """The walk techniques' names in dwv_technique_t order ("auto", "classical", ...)."""
    name_of = _library.function("dwv_technique_name")
    names: List[str] = []
    while True:
        name = name_of(len(names))
        if name is None:
            return tuple(names)
        names.append(name.decode("ascii"))


def _technique_code(technique: Any) -> int:
    if isinstance(technique, bool) or not isinstance(technique, str):
        raise TypeError(f"technique must be a str such as 'auto' (see techniques()), not {type(technique).__name__}")
    if "\0" in technique:
        raise Error(f"unknown technique {technique!r} (it contains a NUL character)", _library.DWV_ERROR_UNKNOWN_NAME)
    code = ctypes.c_int32()
    _call("dwv_technique_from_name", technique.encode("utf-8", "replace"), ctypes.byref(code))
    return code.value


def _technique_name(code: int) -> str:
    name = _library.function("dwv_technique_name")(code)
    return name.decode("ascii") if name else str(code)


def _pixel_filter_code(pixel_filter: Any) -> int:
    """DWV_PIXEL_FILTER_* of a name the library knows (any case) or of a code it names."""
    if isinstance(pixel_filter, bool) or not isinstance(pixel_filter, (str, int)):
        raise TypeError(f"pixel_filter must be a str such as 'box', not {type(pixel_filter).__name__}")
    if isinstance(pixel_filter, int):  # ctypes would wrap a value beyond int32_t around
        named = -(1 << 31) <= pixel_filter < (1 << 31) and _library.function("dwv_pixel_filter_name")(pixel_filter)
        if not named:
            raise Error(f"unknown pixel filter {pixel_filter}", _library.DWV_ERROR_UNKNOWN_NAME)
        return pixel_filter
    if "\0" in pixel_filter:
        raise Error(f"unknown pixel filter {pixel_filter!r} (it contains a NUL)", _library.DWV_ERROR_UNKNOWN_NAME)
    code = ctypes.c_int32()
    _call("dwv_pixel_filter_from_name", pixel_filter.lower().encode("utf-8", "replace"), ctypes.byref(code))
    return code.value


def _pixel_filter_name(code: int) -> str:
    name = _library.function("dwv_pixel_filter_name")(code)
    return name.decode("ascii") if name else str(code)


def feature_names(features: int) -> Tuple[str, ...]:
    """The names of the DWV_FEATURE_* bits set in `features` ("embree", "subsurface"...)."""
    name_of = _library.function("dwv_feature_name")
    names = []
    for bit in range(32):
        if features & (1 << bit):
            name = name_of(1 << bit)
            names.append(name.decode("ascii") if name else f"bit{bit}")
    return tuple(names)


# ---------------------------------------------------------------------------------------------
# Scene description
# ---------------------------------------------------------------------------------------------

_MATERIAL_KINDS = {"subsurface": 0, "diffuse": 1}
_SUBSURFACE_EXITS = {"lambert": 0, "principled_v1": 1}
# dwv_subsurface_model_t (capi/dwivedi.h): which Cycles release's walk, by Blender version and method.
SUBSURFACE_MODELS = {"fixed_radius": 0, "blender3_random_walk": 1, "blender4_random_walk": 2, "blender4_skin": 3,
                     "blender52_random_walk": 4, "blender52_legacy": 5, "blender52_skin": 6}
# dwv_specular_model_t: the Principled BSDF's dielectric specular layer.
SPECULAR_MODELS = {"none": 0, "principled_v1": 1, "principled_v2": 2}


@dataclass
class Material:
    """A Principled BSDF with random-walk subsurface (Blender 4.x names; dwv_material_t).

    The surface is (1 - subsurface_weight) Lambertian diffuse of base_color plus subsurface_weight
    random-walk subsurface whose multiple-scattering albedo is subsurface_color and whose radius per
    channel is subsurface_radius x subsurface_scale (scene units), as Cycles' "Random Walk (Fixed
    Radius)". kind "diffuse" is a plain Lambertian surface of base_color. For Blender 3.x inputs
    use Material.from_blender_3x.

    subsurface_exit: "lambert" (a Lambertian exit: the Subsurface Scattering node, Blender 4.x's
    Principled) or "principled_v1" (Blender 3.x's Principled: the exit weighted by
    1 - (1 - cos)^5 / 2 and a retro-reflection lobe of this roughness; see capi/dwivedi.h).

    subsurface_model: one of SUBSURFACE_MODELS ("fixed_radius", "blender3_random_walk",
    "blender4_random_walk", "blender4_skin", "blender52_random_walk", "blender52_legacy",
    "blender52_skin"): the radius scaling, albedo mapping, anisotropy clamp and entry of that Cycles
    (dwv_subsurface_model_t). specular_model: "none", "principled_v1" (3.x: Specular, Specular
    Tint as specular_tint[0], Roughness) or "principled_v2" (4.x+: ior, Specular IOR Level as
    `specular`, the Specular Tint colour, Roughness, specular_multiscatter for Multiscatter GGX).
    subsurface_min_footprint: Cycles 4.0-4.3 turn a channel whose radius is below a quarter of the
    ray's footprint (a camera pixel's, a UV bake texel's) into diffuse (0.25; 0: never). The add-on sets all of these from
    bpy.app.version and the node (blender_addon/dwivedi_bake/export.py).
    """

    base_color: Color = (0.8, 0.8, 0.8)
    subsurface_weight: float = 1.0
    subsurface_color: Color = (0.8, 0.8, 0.8)
    subsurface_radius: Color = (1.0, 0.2, 0.1)
    subsurface_scale: float = 0.05
    subsurface_anisotropy: float = 0.0
    subsurface_ior: float = 1.4
    kind: str = "subsurface"
    subsurface_exit: str = "lambert"
    roughness: float = 0.5
    subsurface_model: str = "fixed_radius"
    specular_model: str = "none"
    ior: float = 1.5
    specular: float = 0.5
    specular_tint: Color = (1.0, 1.0, 1.0)
    specular_multiscatter: bool = False
    subsurface_min_footprint: float = 0.0

    @classmethod
    def diffuse(cls, color: Color) -> "Material":
        """A Lambertian surface of `color`."""
        c = real_tuple(color, "color", 3)
        return cls(base_color=c, subsurface_weight=0.0, subsurface_color=c, kind="diffuse")

    @classmethod
    def from_blender_3x(cls, base_color: Color, subsurface: float, subsurface_color: Color,
                        subsurface_radius: Color, anisotropy: float = 0.0, ior: float = 1.4,
                        roughness: float = 0.5) -> "Material":
        """The material of Blender 3.x's Principled inputs, mapped as Cycles 3.x does: the walk's
        albedo is mix(Base Color, Subsurface Color, Subsurface), its radius Subsurface Radius x
        Subsurface, its exit "principled_v1" with Roughness; Subsurface = 0 is Base Color with
        Blender 3.x's Principled diffuse (Fresnel-weighted Lambertian plus retro-reflection)."""
        s = _real("subsurface", subsurface)
        base = real_tuple(base_color, "base_color", 3)
        sss = real_tuple(subsurface_color, "subsurface_color", 3)
        mixed = tuple(b * (1.0 - s) + c * s for b, c in zip(base, sss))
        return cls(base_color=base, subsurface_weight=1.0 if s > 0.0 else 0.0, subsurface_color=mixed,
                   subsurface_radius=real_tuple(subsurface_radius, "subsurface_radius", 3), subsurface_scale=s,
                   subsurface_anisotropy=anisotropy, subsurface_ior=ior, subsurface_exit="principled_v1",
                   roughness=_real("roughness", roughness))

    def _to_c(self) -> _library.Material:
        out = _library.Material()
        out.kind = _name_code("material kind", self.kind, _MATERIAL_KINDS)
        out.base_color[:] = real_tuple(self.base_color, "base_color", 3)
        out.subsurface_weight = _real("subsurface_weight", self.subsurface_weight)
        out.subsurface_color[:] = real_tuple(self.subsurface_color, "subsurface_color", 3)
        out.subsurface_radius[:] = real_tuple(self.subsurface_radius, "subsurface_radius", 3)
        out.subsurface_scale = _real("subsurface_scale", self.subsurface_scale)
        out.subsurface_anisotropy = _real("subsurface_anisotropy", self.subsurface_anisotropy)
        out.subsurface_ior = _real("subsurface_ior", self.subsurface_ior)
        out.subsurface_exit = _name_code("subsurface exit", self.subsurface_exit, _SUBSURFACE_EXITS)
        out.roughness = _real("roughness", self.roughness)
        out.subsurface_model = _name_code("subsurface model", self.subsurface_model, SUBSURFACE_MODELS)
        out.specular_model = _name_code("specular model", self.specular_model, SPECULAR_MODELS)
        out.ior = _real("ior", self.ior)
        out.specular = _real("specular", self.specular)
        out.specular_tint[:] = real_tuple(self.specular_tint, "specular_tint", 3)
        if not isinstance(self.specular_multiscatter, (bool, int)) or int(self.specular_multiscatter) not in (0, 1):
            raise ValueError(f"specular_multiscatter must be True or False, not {self.specular_multiscatter!r}")
        out.specular_multiscatter = int(self.specular_multiscatter)
        out.subsurface_min_footprint = _real("subsurface_min_footprint", self.subsurface_min_footprint)
        return out


@dataclass
class SunLight:
    """A distant light: `direction` is the way the light travels; strength is the irradiance
    (W/m^2) on a surface facing it, as Blender's sun "Strength"; angle its angular diameter."""

    direction: Vector = (0.0, 0.0, -1.0)
    strength: float = 1.0
    color: Color = (1.0, 1.0, 1.0)
    angle: float = 0.0

    def _to_c(self) -> _library.LightDesc:
        out = _light_base(0, self.color, _real("strength", self.strength))
        out.direction[:] = real_tuple(self.direction, "direction", 3)
        out.angle = _real("angle", self.angle)
        return out


@dataclass
class PointLight:
    """A point light of `power` watts, Blender's convention (radiant intensity power / (4 pi)
    W/sr), of `radius`: `shape` "disc" (a disc facing the shaded point: Blender 3.x, and 4.0
    onward with Soft Falloff) or "sphere" (4.0 onward without Soft Falloff); dwv_point_shape_t."""

    position: Vector = (0.0, 0.0, 0.0)
    power: float = 100.0
    color: Color = (1.0, 1.0, 1.0)
    radius: float = 0.0
    shape: str = "disc"

    def _to_c(self) -> _library.LightDesc:
        out = _light_base(1, self.color, _real("power", self.power))
        out.position[:] = real_tuple(self.position, "position", 3)
        out.radius = _real("radius", self.radius)
        out.point_shape = _name_code("point light shape", self.shape, POINT_SHAPES)
        return out


POINT_SHAPES = {"disc": 0, "sphere": 1}


@dataclass
class AreaLight:
    """An area light of `power` watts (Blender's convention) in its local xy plane, emitting
    along its local -z: shape "rectangle" (size_x x size_y) or "disk" (diameter size_x, or an
    ellipse size_x x size_y). `transform` is light-to-world (3 x 4 or 4 x 4, no shear)."""

    transform: Any = None
    size_x: float = 1.0
    size_y: float = 1.0
    power: float = 100.0
    color: Color = (1.0, 1.0, 1.0)
    shape: str = "rectangle"

    def _to_c(self) -> _library.LightDesc:
        kind = 2 + _name_code("area light shape", self.shape, {"rectangle": 0, "disk": 1})
        out = _light_base(kind, self.color, _real("power", self.power))
        out.transform[:] = transform12(self.transform)
        out.size_x = _real("size_x", self.size_x)
        out.size_y = _real("size_y", self.size_y)
        return out


@dataclass
class SpotLight:
    """A spot light as Blender's: a point light (`radius`, `shape` as PointLight's) of `power` watts within a cone
    about `direction` (the way its axis points, Blender's local -z), of full angle `spot_size`
    (radians, Blender's Spot Size) with a soft edge of `spot_blend` (0 to 1). `falloff` is the
    attenuation's form: "cycles3" (Blender 3.x: the axis cosine x a smoothstep) or "cycles4"
    (Blender 4.0 onward: the smoothstep alone); dwv_light_desc_t gives the formula."""

    position: Vector = (0.0, 0.0, 0.0)
    direction: Vector = (0.0, 0.0, -1.0)
    power: float = 100.0
    color: Color = (1.0, 1.0, 1.0)
    radius: float = 0.0
    spot_size: float = math.pi / 4.0
    spot_blend: float = 0.15
    falloff: str = "cycles3"
    shape: str = "disc"

    def _to_c(self) -> _library.LightDesc:
        out = _light_base(4, self.color, _real("power", self.power))
        out.position[:] = real_tuple(self.position, "position", 3)
        out.direction[:] = real_tuple(self.direction, "direction", 3)
        out.radius = _real("radius", self.radius)
        out.spot_size = _real("spot_size", self.spot_size)
        out.spot_blend = _real("spot_blend", self.spot_blend)
        out.spot_falloff = _name_code("spot falloff", self.falloff, {"cycles3": 0, "cycles4": 1})
        out.point_shape = _name_code("spot light shape", self.shape, POINT_SHAPES)
        return out


def _light_base(kind: int, color: Color, strength: float) -> _library.LightDesc:
    out = _library.LightDesc()
    # DWV_LIGHT_DESC_INIT's defaults for the fields another kind leaves alone.
    out.direction[:] = (0.0, 0.0, -1.0)
    out.transform[:] = transform12(None)
    out.size_x = out.size_y = 1.0
    out.spot_size = math.pi / 4.0
    out.spot_blend = 0.15
    out.kind = kind
    out.color[:] = real_tuple(color, "color", 3)
    out.strength = strength
    return out


Light = Union[SunLight, PointLight, AreaLight, SpotLight]


@dataclass
class Camera:
    """A camera as Blender's: it looks along its local -z with +y up; the sensor (or the
    orthographic scale) fits the larger image side. `transform` is camera-to-world (3 x 4 or
    4 x 4, rotation and translation only)."""

    transform: Any = None
    kind: str = "perspective"
    focal_length: float = 50.0
    sensor_width: float = 36.0
    ortho_scale: float = 1.0

    @classmethod
    def look_at(cls, eye: Vector, target: Vector, up: Vector = (0.0, 0.0, 1.0), **kwargs: Any) -> "Camera":
        """A camera at `eye` looking at `target` with `up` upwards in the image."""
        e = real_tuple(eye, "eye", 3)
        t = real_tuple(target, "target", 3)
        u = real_tuple(up, "up", 3)
        back = _normalize(tuple(a - b for a, b in zip(e, t)), "eye - target")  # local +z
        right = _normalize(_cross(u, back), "up x (eye - target)")           # local +x
        true_up = _cross(back, right)                                         # local +y
        rows = [(right[i], true_up[i], back[i], e[i]) for i in range(3)]
        return cls(transform=[v for row in rows for v in row], **kwargs)

    def _to_c(self) -> _library.CameraDesc:
        out = _library.CameraDesc()
        out.kind = _name_code("camera kind", self.kind, {"perspective": 0, "orthographic": 1})
        out.transform[:] = transform12(self.transform)
        out.focal_length = _real("focal_length", self.focal_length)
        out.sensor_width = _real("sensor_width", self.sensor_width)
        out.ortho_scale = _real("ortho_scale", self.ortho_scale)
        return out


def _cross(a: Sequence[float], b: Sequence[float]) -> Vector:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _normalize(v: Sequence[float], name: str) -> Vector:
    length = math.sqrt(sum(x * x for x in v))
    if not length > 0.0 or not math.isfinite(length):
        raise Error(f"{name} has no direction (length {length})", _library.DWV_ERROR_INVALID_ARGUMENT)
    return (v[0] / length, v[1] / length, v[2] / length)


# ---------------------------------------------------------------------------------------------
# Bake settings, progress, statistics
# ---------------------------------------------------------------------------------------------

_TARGETS = {"camera": 0, "uv": 1}
# dwv_pass_t by Blender's pass names (its multilayer EXR layers), in the enum's order.
PASS_NAMES = ("Combined", "DiffDir", "DiffInd", "DiffCol", "GlossDir", "GlossInd", "GlossCol", "TransDir",
              "TransInd", "TransCol", "Emit", "Env")
# dwv_bake_type_t by Blender's bake types (scene.cycles.bake_type) that the library bakes.
BAKE_TYPES = {"COMBINED": 0, "DIFFUSE": 1, "GLOSSY": 2, "TRANSMISSION": 3, "EMIT": 4, "ENVIRONMENT": 5}
# DWV_BAKE_FILTER_* by the names of Blender's pass filter (scene.render.bake.use_pass_<name>).
BAKE_FILTERS = {"direct": 1, "indirect": 2, "color": 4, "diffuse": 8, "glossy": 16, "transmission": 32, "emit": 64}


def _pass_mask(passes: Any) -> int:
    """DWV_PASS_BIT of each of Blender's pass names in `passes` (an iterable of names)."""
    if isinstance(passes, (str, bytes)):
        raise TypeError("passes must be a sequence of pass names such as ('DiffDir', 'DiffCol'), not one string")
    mask = 0
    for name in passes:
        if name not in PASS_NAMES:
            raise ValueError(f"unknown pass {name!r} (one of {', '.join(PASS_NAMES)})")
        mask |= 1 << PASS_NAMES.index(name)
    return mask


def _pass_names(mask: int) -> Tuple[str, ...]:
    return tuple(name for k, name in enumerate(PASS_NAMES) if mask & (1 << k))


def _bake_type(bake_type: str, pass_filter: Any) -> Tuple[int, int]:
    if bake_type not in BAKE_TYPES:
        raise ValueError(f"unknown bake type {bake_type!r} (one of {', '.join(BAKE_TYPES)})")
    if isinstance(pass_filter, str):
        raise TypeError("pass_filter must be a set of filter names such as {'direct', 'color'}, not one string")
    bits = 0
    for name in pass_filter:
        if name not in BAKE_FILTERS:
            raise ValueError(f"unknown pass filter {name!r} (any of {', '.join(BAKE_FILTERS)})")
        bits |= BAKE_FILTERS[name]
    return BAKE_TYPES[bake_type], bits


def bake_type_passes(bake_type: str, pass_filter: Any) -> Tuple[str, ...]:
    """The passes (for BakeSettings.passes) that Blender's bake type (COMBINED, DIFFUSE, GLOSSY,
    TRANSMISSION, EMIT, ENVIRONMENT) with its pass filter (names of BAKE_FILTERS) needs; Error
    for a filter that selects nothing (dwv_bake_type_passes)."""
    code, bits = _bake_type(bake_type, pass_filter)
    mask = ctypes.c_uint32()
    _call("dwv_bake_type_passes", code, bits, ctypes.byref(mask))
    return _pass_names(mask.value)
# dwv_channel_walks_t: how walks carry the colour channels (capi/dwivedi.h)
_CHANNEL_WALKS = {"auto": 0, "shared": 1, "separate": 2}
# dwv_subsurface_after_diffuse_t: a subsurface surface met after a diffuse bounce
_AFTER_DIFFUSE = {"by_model": 0, "lambert": 1, "walk": 2}
# dwv_uv_jitter_t: where a UV bake's samples sit in their texel
_UV_JITTERS = {"retry": 0, "mirror": 1}


@dataclass
class BakeSettings:
    """What to bake and how long (dwv_bake_options_t). Whichever budget is reached first ends the
    bake: `samples` per pixel, `time_limit` seconds (0: none), `target_error` relative RMSE of
    the image, as in BakeStats (0: none). threads 0 uses every core; the image is the same for any thread count.
    channel_walks: "shared" (one walk carries the three colour channels by spectral MIS, as Cycles),
    "separate" (one walk per channel, in that channel's own medium) or "auto" (shared for an
    explicit technique; with technique "auto" the pilot chooses per mesh)."""

    target: str = "camera"
    width: int = 256
    height: int = 256
    uv_mesh: int = 0
    uv_margin: int = 16
    technique: str = "auto"
    samples: int = 64
    time_limit: float = 0.0
    target_error: float = 0.0
    threads: int = 0
    max_events: int = 0
    seed: int = 0
    tile_size: int = 0
    channel_walks: str = "auto"
    # A chunk of a split bake (docs/farm.md): sample indices sample_first .. sample_first +
    # sample_count - 1 of `samples` in all; 0 (the default): the whole bake.
    sample_first: int = 0
    sample_count: int = 0
    # Camera bakes: the background as Cycles' Film > Transparent (RGBA 0 where no surface is seen,
    # pixels premultiplied by coverage); False: the world is seen there.
    transparent_background: bool = False
    # Bake passes beside the combined image, by Blender's names (PASS_NAMES; docs/output.md):
    # ("DiffDir", "DiffCol") and so on. A direct or indirect pass brings its colour.
    passes: Tuple[str, ...] = ()
    # Indirect light as Cycles' Light Paths (Blender's defaults; max_bounces 0: one bounce, the
    # image of before indirect light). subsurface_after_diffuse: "by_model" (the blender52_*
    # models walk, the others turn Lambertian, as Cycles 3.x/4.x), "lambert" or "walk" (5.0+).
    max_bounces: int = 12
    diffuse_bounces: int = 4
    glossy_bounces: int = 4
    transmission_bounces: int = 12
    min_light_bounces: int = 0
    subsurface_after_diffuse: str = "by_model"
    # Cycles' Filter Glossy (scene.cycles.blur_glossy; Blender's default 1.0, 0: no blur): specular
    # layers met after a path's bounces roughened as Cycles roughens them (capi's blur_glossy).
    blur_glossy: float = 1.0
    # Cycles' pixel filter of camera bakes (scene.cycles.pixel_filter_type and filter_width):
    # "box", "gaussian" or "blackman_harris" (Blender's default, of width 1.5), the width in pixels
    # (0.01 to 10). The default here is the box of one pixel, the library's.
    pixel_filter: str = "box"
    filter_width: float = 1.0
    # Where a UV bake's samples sit in their texel, as Cycles' bake places them: "retry" (Cycles
    # 3.5 and later, the default) or "mirror" (Cycles up to 3.4: sample 0 at the centre, the others
    # folded back into the triangle; capi's dwv_uv_jitter_t).
    uv_jitter: str = "retry"

    def _to_c(self) -> _library.BakeOptions:
        out = _library.BakeOptions()
        out.target = _name_code("target", self.target, _TARGETS)
        out.width = _uint("width", self.width)
        out.height = _uint("height", self.height)
        out.uv_mesh = _uint("uv_mesh", self.uv_mesh)
        out.uv_margin = _uint("uv_margin", self.uv_margin)
        out.technique = _technique_code(self.technique)
        out.samples = _uint("samples", self.samples, 64)
        out.time_limit = _real("time_limit", self.time_limit)
        out.target_error = _real("target_error", self.target_error)
        out.threads = _uint("threads", self.threads)
        out.max_events = _uint("max_events", self.max_events)
        out.seed = _uint("seed", self.seed, 64)
        out.tile_size = _uint("tile_size", self.tile_size)
        out.channel_walks = _name_code("channel_walks", self.channel_walks, _CHANNEL_WALKS)
        out.sample_first = _uint("sample_first", self.sample_first, 64)
        out.sample_count = _uint("sample_count", self.sample_count, 64)
        if not isinstance(self.transparent_background, bool):
            raise TypeError(f"transparent_background must be True or False, not {type(self.transparent_background).__name__}")
        out.transparent_background = int(self.transparent_background)
        out.passes = _pass_mask(self.passes)
        out.max_bounces = _uint("max_bounces", self.max_bounces)
        out.diffuse_bounces = _uint("diffuse_bounces", self.diffuse_bounces)
        out.glossy_bounces = _uint("glossy_bounces", self.glossy_bounces)
        out.transmission_bounces = _uint("transmission_bounces", self.transmission_bounces)
        out.min_light_bounces = _uint("min_light_bounces", self.min_light_bounces)
        out.subsurface_after_diffuse = _name_code("subsurface_after_diffuse", self.subsurface_after_diffuse,
                                                  _AFTER_DIFFUSE)
        out.blur_glossy = _real("blur_glossy", self.blur_glossy)
        out.pixel_filter = _pixel_filter_code(self.pixel_filter)
        out.filter_width = _real("filter_width", self.filter_width)
        out.uv_jitter = _name_code("uv_jitter", self.uv_jitter, _UV_JITTERS)
        return out

    @classmethod
    def _from_c(cls, c: _library.BakeOptions) -> "BakeSettings":
        return cls(target={v: k for k, v in _TARGETS.items()}.get(c.target, str(c.target)), width=c.width,
                   height=c.height, uv_mesh=c.uv_mesh, uv_margin=c.uv_margin, technique=_technique_name(c.technique),
                   samples=c.samples, time_limit=c.time_limit, target_error=c.target_error, threads=c.threads,
                   max_events=c.max_events, seed=c.seed, tile_size=c.tile_size,
                   sample_first=c.sample_first, sample_count=c.sample_count,
                   transparent_background=bool(c.transparent_background), passes=_pass_names(c.passes),
                   max_bounces=c.max_bounces, diffuse_bounces=c.diffuse_bounces, glossy_bounces=c.glossy_bounces,
                   transmission_bounces=c.transmission_bounces, min_light_bounces=c.min_light_bounces,
                   subsurface_after_diffuse={v: k for k, v in _AFTER_DIFFUSE.items()}.get(
                       c.subsurface_after_diffuse, str(c.subsurface_after_diffuse)),
                   blur_glossy=c.blur_glossy,
                   pixel_filter=_pixel_filter_name(c.pixel_filter),
                   filter_width=c.filter_width,
                   uv_jitter={v: k for k, v in _UV_JITTERS.items()}.get(c.uv_jitter, str(c.uv_jitter)),
                   channel_walks={v: k for k, v in _CHANNEL_WALKS.items()}.get(c.channel_walks, str(c.channel_walks)))


@dataclass(frozen=True)
class Progress:
    """How far a bake is (dwv_bake_progress_t)."""

    done: bool
    fraction: float                  # of the largest budget, 0 to 1
    seconds: float                   # since the start
    estimated_relative_error: float  # of the image so far; inf before the first pass
    samples_per_pixel: int           # completed passes
    events: int                      # scattering events so far


@dataclass(frozen=True)
class ErrorPoint:
    """One point of a bake's error-against-time series (one per completed pass)."""

    seconds: float
    estimated_relative_error: float
    samples_per_pixel: int


@dataclass(frozen=True)
class BakeStats:
    """What a bake did (dwv_bake_stats_t). estimated_relative_error is the image's estimated
    relative RMSE (per-pixel noise over mean brightness, from the spread between each pixel's two
    independent stratified replicates); mean_rgb the mean of the covered pixels."""

    technique: str
    samples_per_pixel: int
    samples: int
    events: int
    walks: int
    seconds: float
    estimated_relative_error: float
    mean_rgb: Color
    truncated_weight: Color
    features: Tuple[str, ...]
    threads: int
    warnings: int
    #: rays the paths after the first scattering traced (indirect light, mirrors' reflections)
    path_rays: int = 0


# ---------------------------------------------------------------------------------------------
# Scene
# ---------------------------------------------------------------------------------------------

#: dwv_texel_format_t, dwv_texture_extension_t, dwv_texture_interpolation_t, dwv_material_input_t by name.
TEXEL_FORMATS = ("float32", "srgb8", "linear8")
TEXTURE_EXTENSIONS = ("repeat", "extend", "clip", "mirror")
TEXTURE_INTERPOLATIONS = ("linear", "closest", "cubic")
BUMP_SHADOWINGS = ("none", "chiang2019", "chiang2019_mapped", "conty2019")
MATERIAL_INPUTS = ("base_color", "subsurface_color", "subsurface_weight", "subsurface_radius", "subsurface_scale",
                   "subsurface_anisotropy", "roughness", "specular", "specular_tint", "normal_map", "bump")


def _choice(name: str, value: str, names: Tuple[str, ...]) -> int:
    if value not in names:
        raise Error(f"{name} {value!r} is not one of {', '.join(names)}", _library.DWV_ERROR_UNKNOWN_NAME)
    return names.index(value)


class Scene:
    """A dwivedi scene (dwv_scene_t): add materials, meshes, lights, a world and a camera, then
    commit() it; a committed scene can be baked any number of times and no longer changed.

    Use it as a context manager (or call close()) to free it at a known time; a bake or an image
    keeps what it needs alive by itself.
    """

    def __init__(self) -> None:
        handle = ctypes.c_void_p()
        _call("dwv_scene_create", ctypes.byref(handle))
        self._handle: Optional[int] = handle.value
        self._lib = _library.library()
        self._committed = False
        self._meshes = 0
        self._materials = 0
        #: Bake settings that came with the scene (Scene.load, Scene.default), else the defaults.
        self.settings = BakeSettings()

    @classmethod
    def _adopt(cls, handle: int, options: _library.BakeOptions) -> "Scene":
        scene = cls.__new__(cls)
        scene._handle = handle
        scene._lib = _library.library()
        scene._committed = True
        scene._meshes = scene._materials = -1  # unknown: loaded by the library
        scene.settings = BakeSettings._from_c(options)
        return scene

    @classmethod
    def load(cls, path: PathLike) -> "Scene":
        """A committed scene from a scene file (JSON, docs/scene-format.md) and the meshes it names;
        the file's bake settings are in .settings."""
        handle = ctypes.c_void_p()
        options = _library.BakeOptions()
        _call("dwv_scene_load", os.fsencode(path), ctypes.byref(handle), ctypes.byref(options))
        return cls._adopt(handle.value, options)

    @classmethod
    def from_json(cls, text: Union[str, bytes], base_dir: Optional[PathLike] = None) -> "Scene":
        """A committed scene from JSON text; relative mesh paths resolve against base_dir (".")."""
        data = text.encode("utf-8") if isinstance(text, str) else bytes(text)
        handle = ctypes.c_void_p()
        options = _library.BakeOptions()
        _call("dwv_scene_load_json", data, len(data), None if base_dir is None else os.fsencode(base_dir),
              ctypes.byref(handle), ctypes.byref(options))
        return cls._adopt(handle.value, options)

    @classmethod
    def default(cls) -> "Scene":
        """The built-in default scene (a thin back-lit leaf beside a thick front-lit wax shape),
        committed, with its resolution and samples in .settings."""
        handle = ctypes.c_void_p()
        options = _library.BakeOptions()
        _call("dwv_scene_create_default", ctypes.byref(handle), ctypes.byref(options))
        return cls._adopt(handle.value, options)

    @property
    def handle(self) -> int:
        """The dwv_scene_t * as an int (for other ctypes code); Error once closed."""
        if self._handle is None:
            raise Error("the scene is closed", _library.DWV_ERROR_INVALID_STATE)
        return self._handle

    @property
    def committed(self) -> bool:
        return self._committed

    def add_material(self, material: Material) -> int:
        """Adds a material; returns its id (0, 1, ... in order)."""
        if not isinstance(material, Material):
            raise TypeError(f"material must be a dwivedi.Material, not {type(material).__name__}")
        c = material._to_c()
        out = ctypes.c_uint32()
        _call("dwv_scene_add_material", self.handle, ctypes.byref(c), ctypes.byref(out))
        self._materials = out.value + 1
        return out.value

    def add_mesh(self, positions: Any, indices: Any, material: int = 0, *, normals: Any = None, uvs: Any = None,
                 transform: Any = None, shadow_terminator_geometry_offset: float = 0.1,
                 uv_name: Optional[str] = None, uv_layers: Optional[Sequence[Tuple[str, Any]]] = None,
                 tangents: Optional[Dict[str, Any]] = None) -> int:
        """Adds a triangle mesh; returns its id (the uv_mesh of a UV bake).

        positions: 3 floats per vertex (object space); indices: 3 per triangle; normals: optional,
        3 per vertex (smooth shading); uvs: optional, 2 per triangle corner (3 corners per
        triangle, Blender's loop UVs); transform: object-to-world, 3 x 4 or 4 x 4. Each array may
        be a flat or nested sequence or any buffer (array.array, memoryview, numpy array):
        float32 / uint32 C-contiguous buffers are passed without a copy.
        shadow_terminator_geometry_offset: Cycles' object setting "Shadow Terminator > Geometry
        Offset" (>= 0, default 0.1 as Cycles; 0: shadow rays of smooth-shaded triangles leave from
        the flat triangle); see dwv_mesh_t.
        uv_name: the name of `uvs` (Blender's UV map name, what bind_texture's uv_layer names; default
        "0"); uv_layers: more UV layers as (name, uvs) pairs (default names "1", "2", ...); tangents:
        per UV layer name, 4 floats per corner (xyz and the bitangent sign, Blender's MikkTSpace
        tangents) for normal maps; layers without them get tangents from their UVs.
        """
        if isinstance(material, bool) or not isinstance(material, numbers.Integral):
            raise TypeError(f"material must be a material id (int), not {type(material).__name__}")
        p = as_c_array(positions, "f", "positions", 3)
        i = as_c_array(indices, "I", "indices", 3)
        n = None if normals is None else as_c_array(normals, "f", "normals", 3)
        u = None if uvs is None else as_c_array(uvs, "f", "uvs", 6)
        mesh = _library.Mesh()
        mesh.vertex_count = min(p.count // 3, 0xFFFFFFFF)
        mesh.triangle_count = min(i.count // 3, 0xFFFFFFFF)
        mesh.material_id = _uint("material", material)
        mesh.positions = p.address or None
        mesh.indices = i.address or None
        if n is not None:
            if n.count != p.count:
                raise Error(f"normals hold {n.count // 3} vectors for {p.count // 3} vertices",
                            _library.DWV_ERROR_INVALID_ARGUMENT)
            mesh.normals = n.address or None
        if u is not None:
            if u.count != 2 * i.count:
                raise Error(f"uvs hold {u.count // 2} corners for {i.count // 3} triangles (3 corners each)",
                            _library.DWV_ERROR_INVALID_ARGUMENT)
            mesh.uvs = u.address or None
        mesh.transform[:] = transform12(transform)
        mesh.shadow_terminator_geometry_offset = _real("shadow_terminator_geometry_offset",
                                                       shadow_terminator_geometry_offset)
        keep: List[Any] = []  # what the pointers borrow, alive until the call returns
        extra = list(uv_layers or ())
        if extra or uv_name is not None or tangents:
            names = [uv_name if uv_name is not None else "0"]
            arrays = []
            for k, (name, values) in enumerate(extra):
                layer = as_c_array(values, "f", f"uv_layers[{k}]", 6)
                if layer.count != 2 * i.count:
                    raise Error(f"uv_layers[{k}] holds {layer.count // 2} corners for {i.count // 3} triangles",
                                _library.DWV_ERROR_INVALID_ARGUMENT)
                names.append(str(name))
                arrays.append(layer)
            keep.extend(arrays)
            if tangents:
                unknown = sorted(set(tangents) - set(names))
                if unknown:
                    raise Error(f"tangents for UV layers the mesh does not have: {', '.join(unknown)}",
                                _library.DWV_ERROR_INVALID_ARGUMENT)
            encoded = [name.encode("utf-8") for name in names]
            name_array = (ctypes.c_char_p * len(encoded))(*encoded)
            layer_array = (ctypes.c_void_p * max(len(arrays), 1))(*[a.address for a in arrays])
            tangent_array = (ctypes.c_void_p * len(names))()
            for k, name in enumerate(names):
                if tangents and name in tangents:
                    t = as_c_array(tangents[name], "f", f"tangents[{name!r}]", 12)
                    if t.count != 4 * i.count:
                        raise Error(f"tangents[{name!r}] hold {t.count // 4} corners for {i.count // 3} triangles",
                                    _library.DWV_ERROR_INVALID_ARGUMENT)
                    keep.append(t)
                    tangent_array[k] = t.address
            keep.extend([encoded, name_array, layer_array, tangent_array])
            mesh.uv_layer_count = len(arrays)
            mesh.uv_layers = ctypes.addressof(layer_array) if arrays else None
            mesh.uv_layer_names = ctypes.addressof(name_array)
            mesh.tangents = ctypes.addressof(tangent_array)
        out = ctypes.c_uint32()
        _call("dwv_scene_add_mesh", self.handle, ctypes.byref(mesh), ctypes.byref(out))
        del keep
        self._meshes = out.value + 1
        return out.value

    def add_texture(self, texels: Any, width: int, height: int, channels: int = 4, *, format: str = "float32",
                    extension: str = "repeat", interpolation: str = "linear") -> int:
        """Adds a texture (dwv_texture_desc_t); returns its id. texels: channels x width x height
        values, row 0 at v = 0 (Blender's Image.pixels order): floats for format "float32"
        (scene-linear or non-colour data), bytes (0-255) for "srgb8" (8-bit sRGB colour) and
        "linear8" (8-bit data, value / 255). extension: "repeat", "extend", "clip", "mirror";
        interpolation: "linear", "closest", "cubic" (Blender's Image Texture node)."""
        desc = _library.TextureDesc()
        desc.width = _uint("width", width)
        desc.height = _uint("height", height)
        desc.channels = _uint("channels", channels)
        desc.format = _choice("format", format, TEXEL_FORMATS)
        desc.extension = _choice("extension", extension, TEXTURE_EXTENSIONS)
        desc.interpolation = _choice("interpolation", interpolation, TEXTURE_INTERPOLATIONS)
        wanted = desc.width * desc.height * desc.channels
        if desc.format == 0:
            data = as_c_array(texels, "f", "texels", 1)
            count, address, owner = data.count, data.address, data
        else:
            try:
                raw = bytes(memoryview(texels).cast("B")) if not isinstance(texels, (bytes, bytearray)) else bytes(texels)
            except TypeError:
                values = [int(v) for v in texels]
                if any(v < 0 or v > 255 for v in values):
                    raise Error("8-bit texels must be in [0, 255]", _library.DWV_ERROR_OUT_OF_RANGE) from None
                raw = bytes(values)
            owner = ctypes.create_string_buffer(raw, max(len(raw), 1))
            count, address = len(raw), ctypes.addressof(owner)
        if count != wanted:
            raise Error(f"texels hold {count} values; {desc.width} x {desc.height} x {desc.channels} needs {wanted}",
                        _library.DWV_ERROR_INVALID_ARGUMENT)
        desc.texels = address or None
        out = ctypes.c_uint32()
        _call("dwv_scene_add_texture", self.handle, ctypes.byref(desc), ctypes.byref(out))
        del owner
        return out.value

    def add_texture_file(self, path: str, *, format: Optional[str] = None, extension: str = "repeat",
                         interpolation: str = "linear") -> int:
        """Adds a texture from a PNG or OpenEXR file (dwv_scene_add_texture_file); returns its id.
        format: "srgb8" or "linear8" for a PNG (default "srgb8"); an EXR's texels are "float32"
        (its default)."""
        desc = _library.TextureDesc()
        if format is None:
            with open(path, "rb") as f:
                format = "float32" if f.read(4) == b"\x76\x2f\x31\x01" else "srgb8"
        desc.format = _choice("format", format, TEXEL_FORMATS)
        desc.extension = _choice("extension", extension, TEXTURE_EXTENSIONS)
        desc.interpolation = _choice("interpolation", interpolation, TEXTURE_INTERPOLATIONS)
        out = ctypes.c_uint32()
        _call("dwv_scene_add_texture_file", self.handle, os.fsencode(path), ctypes.byref(desc), ctypes.byref(out))
        return out.value

    def bind_texture(self, material: int, input: str, texture: int, *, uv_layer: Optional[str] = None,
                     blend: float = 1.0, strength: float = 1.0, distance: float = 1.0, invert: bool = False,
                     bump_shadowing: str = "chiang2019") -> None:
        """Binds texture `texture` to input `input` of material `material` (dwv_texture_binding_t):
        one of MATERIAL_INPUTS ("base_color", "subsurface_color", ..., "normal_map", "bump"),
        through the mesh's UV layer `uv_layer` (a name given to add_mesh; None: its first).
        bump_shadowing (normal map, bump): how Cycles treats tilted normals (dwv_bump_shadowing_t):
        "chiang2019" (Blender 3.x), "chiang2019_mapped" (4.x: without ensure_valid_reflection),
        "conty2019" (5.x) or "none"."""
        binding = _library.TextureBinding()
        binding.input = _choice("input", input, MATERIAL_INPUTS)
        binding.texture_id = _uint("texture", texture)
        binding.invert = 1 if invert else 0
        binding.uv_layer = None if uv_layer is None else str(uv_layer).encode("utf-8")
        binding.blend = _real("blend", blend)
        binding.strength = _real("strength", strength)
        binding.distance = _real("distance", distance)
        binding.bump_shadowing = _choice("bump_shadowing", bump_shadowing, BUMP_SHADOWINGS)
        _call("dwv_scene_bind_texture", self.handle, _uint("material", material), ctypes.byref(binding))

    def texture_memory(self) -> Tuple[int, int]:
        """(bytes, texels) of the scene's textures: the memory per texel is bytes / texels."""
        size, count = ctypes.c_uint64(), ctypes.c_uint64()
        _call("dwv_scene_texture_memory", self.handle, ctypes.byref(size), ctypes.byref(count))
        return size.value, count.value

    def add_light(self, light: Light) -> None:
        """Adds a SunLight, PointLight, AreaLight or SpotLight."""
        if not isinstance(light, (SunLight, PointLight, AreaLight, SpotLight)):
            raise TypeError(f"light must be a SunLight, PointLight, AreaLight or SpotLight, not {type(light).__name__}")
        c = light._to_c()
        _call("dwv_scene_add_light", self.handle, ctypes.byref(c))

    def set_world(self, color: Color, strength: float = 1.0) -> None:
        """A constant world: radiance color x strength from every direction."""
        c = (ctypes.c_double * 3)(*real_tuple(color, "color", 3))
        _call("dwv_scene_set_world", self.handle, c, _real("strength", strength))

    def set_world_environment(self, texels: Any, width: int, height: int, *, strength: float = 1.0,
                              rotation: Any = None, interpolation: str = "linear") -> None:
        """An equirectangular image world, Blender's Environment Texture into a Background node
        (dwv_scene_set_world_environment): texels are 3 floats (linear RGB) per texel, width x
        height of them, row 0 at the bottom (Blender's Image.pixels order without alpha; any
        buffer or sequence, a float32 C-contiguous buffer is passed without a copy); strength is
        the Background's; rotation a 3 x 3 rotation (nested or 9 numbers, row-major) taking world
        directions to the texture's (a Mapping node's), None for none; interpolation "linear",
        "closest" or "cubic". A 1 x 1 image is the constant world of that colour."""
        t = as_c_array(texels, "f", "texels", 3)
        c = _library.EnvironmentDesc()
        c.width = _uint("width", width)
        c.height = _uint("height", height)
        if t.count != 3 * c.width * c.height:
            raise Error(f"texels hold {t.count} numbers: a {c.width} x {c.height} image needs {3 * c.width * c.height}",
                        _library.DWV_ERROR_INVALID_ARGUMENT)
        c.texels = t.address or None
        _environment_settings(c, strength, rotation, interpolation)
        _call("dwv_scene_set_world_environment", self.handle, ctypes.byref(c))

    def set_world_environment_file(self, path: str, *, strength: float = 1.0, rotation: Any = None,
                                   interpolation: str = "linear") -> None:
        """The equirectangular world from an OpenEXR or Radiance (.hdr) file
        (dwv_scene_set_world_environment_file); the other arguments as set_world_environment's."""
        c = _library.EnvironmentDesc()
        _environment_settings(c, strength, rotation, interpolation)
        _call("dwv_scene_set_world_environment_file", self.handle, os.fsencode(path), ctypes.byref(c))

    def set_camera(self, camera: Camera) -> None:
        if not isinstance(camera, Camera):
            raise TypeError(f"camera must be a dwivedi.Camera, not {type(camera).__name__}")
        c = camera._to_c()
        _call("dwv_scene_set_camera", self.handle, ctypes.byref(c))

    def commit(self) -> "Scene":
        """Freezes the scene (builds its ray-tracing structures); returns it."""
        _call("dwv_scene_commit", self.handle)
        self._committed = True
        return self

    def bake(self, settings: Optional[BakeSettings] = None, *, progress: Optional[Callable[[Progress], Any]] = None,
             **overrides: Any) -> "Image":
        """bake(self, ...): see dwivedi.bake."""
        return bake(self, settings, progress=progress, **overrides)

    def close(self) -> None:
        """Drops this object's reference to the scene (running bakes keep theirs)."""
        handle, self._handle = self._handle, None
        if handle is not None:
            self._lib.dwv_scene_release(handle)

    def __enter__(self) -> "Scene":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:  # pragma: no cover - interpreter shutdown
            pass

    def __repr__(self) -> str:
        state = "closed" if self._handle is None else ("committed" if self._committed else "open")
        return f"<dwivedi.Scene {state}>"


# ---------------------------------------------------------------------------------------------
# Bakes
# ---------------------------------------------------------------------------------------------

def _settings(settings: Optional[BakeSettings], scene: Scene, overrides: Dict[str, Any]) -> BakeSettings:
    if settings is None:
        settings = scene.settings if isinstance(scene, Scene) else BakeSettings()
    elif not isinstance(settings, BakeSettings):
        raise TypeError(f"settings must be a dwivedi.BakeSettings, not {type(settings).__name__}")
    if overrides:
        known = BakeSettings.__dataclass_fields__
        unknown = [k for k in overrides if k not in known]
        if unknown:
            raise TypeError(f"unknown bake setting(s) {', '.join(unknown)} (known: {', '.join(known)})")
        settings = BakeSettings(**{**settings.__dict__, **overrides})
    return settings


class Bake:
    """A running bake (dwv_bake_t): poll progress(), wait(), cancel(), then finish() for the image.

    Made by start_bake(); bake() does all of it with Ctrl-C handling. As a context manager it
    cancels and releases the bake on exit if nobody finished it.
    """

    def __init__(self, scene: Scene, settings: BakeSettings) -> None:
        if not isinstance(scene, Scene):
            raise TypeError(f"scene must be a dwivedi.Scene, not {type(scene).__name__}")
        options = settings._to_c()
        handle = ctypes.c_void_p()
        _call("dwv_bake_start", scene.handle, ctypes.byref(options), ctypes.byref(handle))
        self._handle: Optional[int] = handle.value
        self._lib = _library.library()
        self.settings = settings
        self.cancelled = False

    def _live(self) -> int:
        if self._handle is None:
            raise Error("the bake was finished or closed", _library.DWV_ERROR_INVALID_STATE)
        return self._handle

    def progress(self) -> Progress:
        p = _library.BakeProgress()
        _call("dwv_bake_progress", self._live(), ctypes.byref(p))
        return Progress(bool(p.done), p.fraction, p.seconds, p.estimated_relative_error, p.samples_per_pixel,
                        p.events)

    def wait(self, timeout: Optional[float] = None) -> bool:
        """Waits up to `timeout` seconds (None: until it ends); True once the bake has ended."""
        done = ctypes.c_int32()
        t = -1.0 if timeout is None else max(0.0, _real("timeout", timeout))
        _call("dwv_bake_wait", self._live(), t, ctypes.byref(done))
        return bool(done.value)

    def cancel(self) -> None:
        """Asks the bake to stop (it ends within 0.1 s); harmless once it ended."""
        self.cancelled = True
        _call("dwv_bake_cancel", self._live())

    def finish(self) -> "Image":
        """Waits for the end and returns the image; Cancelled if it was cancelled, Error if it
        failed. The bake is released either way."""
        handle = self._live()
        image = ctypes.c_void_p()
        try:
            _call("dwv_bake_finish", handle, ctypes.byref(image))
        finally:
            self.close()
        return Image._adopt(image.value)

    def close(self) -> None:
        """Releases the bake (cancelling it and waiting for it if it still runs)."""
        handle, self._handle = self._handle, None
        if handle is not None:
            self._lib.dwv_bake_release(handle)

    def __enter__(self) -> "Bake":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:  # pragma: no cover - interpreter shutdown
            pass


def start_bake(scene: Scene, settings: Optional[BakeSettings] = None, **overrides: Any) -> Bake:
    """Starts a bake of the committed `scene` on the library's threads and returns at once.

    settings: a BakeSettings (default: the scene's own .settings); keyword overrides replace its
    fields (start_bake(scene, samples=16, width=64, height=64))."""
    return Bake(scene, _settings(settings, scene, overrides))


def bake(scene: Scene, settings: Optional[BakeSettings] = None, *, progress: Optional[Callable[[Progress], Any]] = None,
         interval: float = 0.1, **overrides: Any) -> "Image":
    """Bakes the committed `scene` and returns the Image.

    progress(p: Progress) is called on this thread about every `interval` seconds and once at the
    end; returning True cancels the bake (Cancelled is raised). Ctrl-C (KeyboardInterrupt) cancels
    the bake, waits for it to stop and raises KeyboardInterrupt again.
    """
    interval = _real("interval", interval)
    if not 0.0 < interval <= 10.0:
        raise Error(f"interval = {interval} must be in (0, 10] seconds", _library.DWV_ERROR_OUT_OF_RANGE)
    job = start_bake(scene, settings, **overrides)
    try:
        done = False
        while not done:
            done = job.wait(interval)
            if progress is not None and progress(job.progress()) is True and not done:
                job.cancel()
        return job.finish()
    except KeyboardInterrupt:
        # Ctrl-C lands here whether it came during the wait or the callback: stop the threads
        # (cancel returns within 0.1 s, release waits for them), then let it propagate.
        job.cancel()
        job.close()
        raise
    finally:
        job.close()  # any other exception (one from the callback too) also stops the bake


# ---------------------------------------------------------------------------------------------
# Images
# ---------------------------------------------------------------------------------------------

class _Pixels:
    """One reference to an image for as long as some view of its pixels lives (so releasing the
    Image object never frees memory a memoryview or numpy array still points to)."""

    def __init__(self, image: "Image") -> None:
        _call("dwv_image_retain", image._live())
        self._handle = image._handle
        self._lib = image._lib

    def __del__(self) -> None:
        try:
            self._lib.dwv_image_release(self._handle)
        except Exception:  # pragma: no cover - interpreter shutdown
            pass


def _view(owner: _Pixels, address: int, ctype: Any, shape: Tuple[int, ...]) -> memoryview:
    count = 1
    for n in shape:
        count *= n

    class _Array(ctype * count):  # type: ignore[misc, valid-type]
        __slots__ = ("_owner",)

    buffer = _Array.from_address(address)
    buffer._owner = owner
    code = "f" if ctype is ctypes.c_float else ("I" if ctypes.sizeof(ctypes.c_uint) == 4 else "L")
    return memoryview(buffer).cast("B").cast(code, shape)


@dataclass(frozen=True)
class DisplaySettings:
    """Colour management for display images, as Blender's (dwv_display_options_t): exposure in
    stops in scene linear, the display / view / look transform of an OCIO config, then gamma.
    None means the config's default (look None or "" or "None": no look). config: the OCIO config
    file (None: $OCIO, else dwivedi's own small config)."""

    config: Optional[PathLike] = None
    display: Optional[str] = None
    view: Optional[str] = None
    look: Optional[str] = None
    exposure: float = 0.0
    gamma: float = 1.0

    def _to_c(self) -> Tuple[_library.DisplayOptions, List[bytes]]:
        out = _library.DisplayOptions()
        keep: List[bytes] = []

        def text(value: Any, name: str) -> Optional[bytes]:
            if value is None:
                return None
            if isinstance(value, os.PathLike) or (name == "config" and isinstance(value, (str, bytes))):
                data = os.fsencode(value)
            elif isinstance(value, str):
                data = value.encode("utf-8")
            else:
                raise TypeError(f"{name} must be a str, not {type(value).__name__}")
            if b"\0" in data:
                raise Error(f"{name} {value!r} contains a NUL character", _library.DWV_ERROR_INVALID_ARGUMENT)
            keep.append(data)
            return data

        out.config_path = text(self.config, "config")
        out.display = text(self.display, "display")
        out.view = text(self.view, "view")
        look = self.look
        out.look = text("" if look == "None" else look, "look")
        out.exposure = _real("exposure", self.exposure)
        out.gamma = _real("gamma", self.gamma)
        return out, keep


def _display(display: Optional[DisplaySettings], overrides: Dict[str, Any]) -> DisplaySettings:
    if display is None:
        display = DisplaySettings()
    elif not isinstance(display, DisplaySettings):
        raise TypeError(f"display must be a dwivedi.DisplaySettings, not {type(display).__name__}")
    if overrides:
        known = DisplaySettings.__dataclass_fields__
        unknown = [k for k in overrides if k not in known]
        if unknown:
            raise TypeError(f"unknown display setting(s) {', '.join(unknown)} (known: {', '.join(known)})")
        display = DisplaySettings(**{**display.__dict__, **overrides})
    return display


class Image:
    """A baked (or made) image (dwv_image_t): RGBA scene-linear Rec.709, row 0 at the top, with
    per-pixel variance (of the pixel mean, RGB) and sample counts.

    .rgba, .variance and .samples are memoryviews straight into the library's memory, shaped
    (height, width, channels); .numpy() gives the same without a copy as numpy arrays. They stay
    valid after the Image object is gone.
    """

    def __init__(self, width: int, height: int, rgba: Any) -> None:
        """An image from caller pixels (4 floats per pixel, rows from the top), e.g. to write
        them as EXR or colour-manage them."""
        w = _uint("width", width)
        h = _uint("height", height)
        data = as_c_array(rgba, "f", "rgba", 4)
        if data.count != 4 * w * h:
            raise Error(f"rgba holds {data.count} values; {w} x {h} RGBA needs {4 * w * h}",
                        _library.DWV_ERROR_INVALID_ARGUMENT)
        handle = ctypes.c_void_p()
        _call("dwv_image_create", w, h, data.address or None, ctypes.byref(handle))
        self._handle: Optional[int] = handle.value
        self._lib = _library.library()
        self._info()

    @classmethod
    def _adopt(cls, handle: Optional[int]) -> "Image":
        if not handle:
            raise Error("the library returned no image", _library.DWV_ERROR_INTERNAL)
        image = cls.__new__(cls)
        image._handle = handle
        image._lib = _library.library()
        image._info()
        return image

    def _info(self) -> None:
        info = _library.ImageInfo()
        _call("dwv_image_info", self._live(), ctypes.byref(info))
        self.width: int = info.width
        self.height: int = info.height
        self._addresses = (info.rgba, info.variance, info.samples)
        self._pixels: Optional[_Pixels] = None

    def _live(self) -> int:
        if self._handle is None:
            raise Error("the image is closed", _library.DWV_ERROR_INVALID_STATE)
        return self._handle

    def _owner(self) -> _Pixels:
        if self._pixels is None:
            self._pixels = _Pixels(self)
        return self._pixels

    @property
    def rgba(self) -> memoryview:
        """Float32 RGBA, shape (height, width, 4), read-write view of the library's pixels."""
        return _view(self._owner(), self._addresses[0], ctypes.c_float, (self.height, self.width, 4))

    @property
    def variance(self) -> memoryview:
        """Float32 variance of each pixel's mean, shape (height, width, 3)."""
        return _view(self._owner(), self._addresses[1], ctypes.c_float, (self.height, self.width, 3))

    @property
    def samples(self) -> memoryview:
        """Uint32 samples of each pixel, shape (height, width)."""
        return _view(self._owner(), self._addresses[2], ctypes.c_uint32, (self.height, self.width))

    def pixels(self) -> "array.array[float]":
        """A copy of the RGBA values as a flat array.array('f')."""
        import array
        out = array.array("f")
        out.frombytes(self.rgba.cast("B").tobytes())
        return out

    def numpy(self) -> Tuple[Any, Any, Any]:
        """(rgba, variance, samples) as numpy arrays sharing the library's memory (ImportError
        without numpy)."""
        import numpy  # optional dependency
        return numpy.asarray(self.rgba), numpy.asarray(self.variance), numpy.asarray(self.samples)

    @property
    def stats(self) -> BakeStats:
        s = _library.BakeStats()
        _call("dwv_image_stats", self._live(), ctypes.byref(s))
        return BakeStats(technique=_technique_name(s.technique), samples_per_pixel=s.samples_per_pixel,
                         samples=s.samples, events=s.events, walks=s.walks, seconds=s.seconds,
                         estimated_relative_error=s.estimated_relative_error, mean_rgb=tuple(s.mean_rgb),
                         truncated_weight=tuple(s.truncated_weight), features=feature_names(s.features),
                         threads=s.threads, warnings=s.warnings, path_rays=s.path_rays)

    @property
    def error_vs_time(self) -> List[ErrorPoint]:
        """The estimated relative error after each completed pass, with its time."""
        count = ctypes.c_uint32()
        _call("dwv_image_error_vs_time", self._live(), None, 0, ctypes.byref(count))
        points = (_library.ErrorPoint * max(count.value, 1))()
        _call("dwv_image_error_vs_time", self._live(), points, count.value, ctypes.byref(count))
        return [ErrorPoint(p.seconds, p.estimated_relative_error, p.samples_per_pixel)
                for p in points[:count.value]]

    def write_exr(self, path: PathLike) -> None:
        """Writes a float RGBA OpenEXR (with variance and sample layers and the bake's metadata);
        the file appears complete or not at all."""
        _call("dwv_image_write_exr", self._live(), os.fsencode(path))

    @property
    def passes(self) -> Tuple[str, ...]:
        """Blender's names of the passes the image holds ("Combined" always)."""
        mask = ctypes.c_uint32()
        _call("dwv_image_passes", self._live(), ctypes.byref(mask))
        return _pass_names(mask.value)

    def pass_image(self, name: str) -> "Image":
        """One pass as Blender shows it (direct and indirect divided by their colour), as an Image."""
        code = _pass_mask([name]).bit_length() - 1
        handle = _library._handle_p()
        _call("dwv_image_pass", self._live(), code, ctypes.byref(handle))
        return Image._adopt(handle.value)

    def bake_type(self, bake_type: str, pass_filter: Any) -> "Image":
        """The image Cycles' bake of `bake_type` with `pass_filter` makes (bake_type_passes), from
        the passes this image holds."""
        code, bits = _bake_type(bake_type, pass_filter)
        handle = _library._handle_p()
        _call("dwv_image_bake_type", self._live(), code, bits, ctypes.byref(handle))
        return Image._adopt(handle.value)

    def write_exr_layers(self, path: PathLike) -> None:
        """Writes a multilayer OpenEXR as Blender's: Combined.RGBA and one RGB layer per pass
        (DiffDir, DiffCol, ...), which Blender opens as a multilayer image."""
        _call("dwv_image_write_exr_layers", self._live(), os.fsencode(path))

    def write_partial(self, path: PathLike) -> None:
        """Writes a chunk's exact sums (a bake with sample_count > 0) for merge_partials."""
        _call("dwv_image_write_partial", self._live(), os.fsencode(path))

    def write_png(self, path: PathLike, display: Optional[DisplaySettings] = None, **overrides: Any) -> None:
        """Writes an 8-bit RGBA PNG through the display transform (DisplaySettings or its fields as
        keywords: write_png("a.png", view="Filmic", exposure=1.0))."""
        c, keep = _display(display, overrides)._to_c()
        _call("dwv_image_write_display_png", self._live(), os.fsencode(path), ctypes.byref(c))
        del keep

    def to_display(self, display: Optional[DisplaySettings] = None, **overrides: Any) -> bytearray:
        """The display-transformed pixels, 4 bytes per pixel (RGBA), as the PNG would hold them."""
        c, keep = _display(display, overrides)._to_c()
        size = 4 * self.width * self.height
        out = bytearray(size)
        buffer = (ctypes.c_uint8 * size).from_buffer(out)
        _call("dwv_image_to_display", self._live(), ctypes.byref(c), buffer, size)
        del buffer, keep
        return out

    def close(self) -> None:
        """Drops this object's reference (views of the pixels keep their own)."""
        handle, self._handle = self._handle, None
        if handle is not None:
            self._pixels = None
            self._lib.dwv_image_release(handle)

    def __enter__(self) -> "Image":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:  # pragma: no cover - interpreter shutdown
            pass

    def __repr__(self) -> str:
        return f"<dwivedi.Image {self.width} x {self.height}>"


def merge_partials(paths: Sequence[PathLike]) -> "Image":
    """Merges the partial files of a split bake into the image one bake would have made
    (dwv_merge_partials; docs/farm.md). Raises Error naming the chunk at fault."""
    encoded = [os.fsencode(p) for p in paths]
    array = (ctypes.c_char_p * max(len(encoded), 1))(*encoded)
    handle = _library._handle_p()
    _call("dwv_merge_partials", array, len(encoded), ctypes.byref(handle))
    return Image._adopt(handle.value)
