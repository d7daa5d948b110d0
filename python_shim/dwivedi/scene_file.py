"""Writing a scene file (docs/scene-format.md) from the calls that build a dwivedi.Scene.

SceneFileWriter takes the same add_material / add_mesh / add_light / set_world / set_camera calls
as dwivedi.Scene (with the same Material, light and Camera objects) and writes them as a scene
file that `dwivedi bake` and Scene.load read back into the same scene: every value is written
exactly (floats as their shortest repr, which parses back to the same bits; meshes inline as the
float32 values the library would have copied; a sun's angle in degrees chosen so that the file's
degrees-to-radians gives back the same double). The Blender add-on's "Export for a farm" passes
it to its export in place of dwivedi.Scene.

    writer = SceneFileWriter()
    writer.add_material(Material(...)); writer.add_mesh(positions, indices, 0); ...
    writer.write("scene.json", bake={"width": 640, "height": 360, "samples": 256,
                                     **light_path_keys(BakeSettings(max_bounces=8))})

Meshes are written inline, so a scene file holds at most the 2^22 JSON values the reader takes;
write() refuses a larger scene with a message (too big for a file without mesh files).
Textures and an environment world's image are written beside the scene file, in the folder
SCENE_files/ (SCENE the file's name without .json): float textures and the environment as
uncompressed OpenEXR (float channels: the same bits come back), 8-bit textures as PNG (the same
bytes), each named in the scene file by its path relative to it and its SHA-256, which the reader
checks (a farm node with another file of that name refuses it). The environment's rotation is
written as its 3 x 3 matrix ("rotation"), exactly.
Standard library only; nothing here calls the library.
"""
from __future__ import annotations

import array
import ctypes
import hashlib
import json
import math
import os
from typing import Any, Dict, List, Optional, Sequence, Tuple

from ._buffers import as_c_array, real_tuple, transform12
from . import _library
from . import image_files
from .baker import (BUMP_SHADOWINGS, MATERIAL_INPUTS, SPECULAR_MODELS, SUBSURFACE_MODELS, TEXEL_FORMATS,
                    TEXTURE_EXTENSIONS, TEXTURE_INTERPOLATIONS, AreaLight, BakeSettings, Camera, Error, Material,
                    PointLight, SpotLight, SunLight)

MAX_JSON_VALUES = 1 << 22  # docs/scene-format.md: "at most 2^22 JSON values"
_RADIANS_PER_DEGREE = 3.14159265358979323846 / 180.0  # as src/scenefile/scene_json_lights.c


def _floats(values: Any, name: str, group: int, kind: str = "f") -> List[Any]:
    """`values` as the library would receive them (float32, or uint32 for kind 'I'), as a list."""
    array = as_c_array(values, kind, name, group)
    if array.count == 0:
        return []
    ctype = ctypes.c_float if kind == "f" else ctypes.c_uint32
    return list((ctype * array.count).from_address(array.address))


def _float_array(values: Any, name: str, group: int) -> "array.array[float]":
    """`values` as the float32 values the library would receive, as an array.array('f')."""
    c = as_c_array(values, "f", name, group)
    out = array.array("f")
    if c.count:
        out.frombytes(ctypes.string_at(c.address, 4 * c.count))
    return out


def degrees_for(radians: float) -> float:
    """A degrees value d with d x (pi / 180) == radians exactly in doubles (the file's angles are
    degrees; the reader multiplies): radians x (180 / pi), nudged by an ulp or two if needed."""
    d = radians / _RADIANS_PER_DEGREE
    for candidate in (d, math.nextafter(d, math.inf), math.nextafter(d, -math.inf),
                      math.nextafter(math.nextafter(d, math.inf), math.inf),
                      math.nextafter(math.nextafter(d, -math.inf), -math.inf)):
        if candidate * _RADIANS_PER_DEGREE == radians:
            return candidate
    return d  # no double maps back exactly (not seen): the nearest


LIGHT_PATH_KEYS = ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces", "min_light_bounces",
                   "subsurface_after_diffuse", "blur_glossy")


def light_path_keys(settings: BakeSettings) -> Dict[str, Any]:
    """The "bake" keys of a BakeSettings' light paths (docs/scene-format.md), checked as the
    library will check them (dwivedi.Error where a value is out of range)."""
    settings._to_c()  # the same checks as a bake's
    return {key: getattr(settings, key) for key in LIGHT_PATH_KEYS}


class SceneFileWriter:
    """Records a scene's building calls (dwivedi.Scene's) and writes them as a scene file."""

    def __init__(self) -> None:
        self.materials: Dict[str, Dict[str, Any]] = {}
        self.meshes: List[Dict[str, Any]] = []
        self.lights: List[Dict[str, Any]] = []
        self.world: Optional[Dict[str, Any]] = None
        self.camera: Optional[Dict[str, Any]] = None
        self.textures: List[Dict[str, Any]] = []  # each: the JSON entry and its texels (written at write())
        self.environment: Optional[Dict[str, Any]] = None
        self._values = 0

    # dwivedi.Scene's building calls -------------------------------------------------------------
    def add_material(self, material: Material) -> int:
        if not isinstance(material, Material):
            raise TypeError(f"material must be a dwivedi.Material, not {type(material).__name__}")
        material._to_c()  # the shim's own checks of every field (names, types)
        if material.subsurface_model not in SUBSURFACE_MODELS or material.specular_model not in SPECULAR_MODELS:
            raise ValueError("unknown subsurface or specular model")
        self.materials[f"material{len(self.materials)}"] = {
            "kind": material.kind, "base_color": list(real_tuple(material.base_color, "base_color", 3)),
            "subsurface_weight": float(material.subsurface_weight),
            "subsurface_color": list(real_tuple(material.subsurface_color, "subsurface_color", 3)),
            "subsurface_radius": list(real_tuple(material.subsurface_radius, "subsurface_radius", 3)),
            "subsurface_scale": float(material.subsurface_scale),
            "subsurface_anisotropy": float(material.subsurface_anisotropy),
            "subsurface_ior": float(material.subsurface_ior), "subsurface_exit": material.subsurface_exit,
            "roughness": float(material.roughness), "subsurface_model": material.subsurface_model,
            "specular_model": material.specular_model, "ior": float(material.ior), "specular": float(material.specular),
            "specular_tint": list(real_tuple(material.specular_tint, "specular_tint", 3)),
            "specular_distribution": "multiscatter_ggx" if material.specular_multiscatter else "ggx",
            "subsurface_min_footprint": float(material.subsurface_min_footprint)}
        return len(self.materials) - 1

    def add_mesh(self, positions: Any, indices: Any, material: int = 0, *, normals: Any = None, uvs: Any = None,
                 transform: Any = None, shadow_terminator_geometry_offset: float = 0.1, uv_name: Optional[str] = None,
                 uv_layers: Optional[Sequence[Tuple[str, Any]]] = None,
                 tangents: Optional[Dict[str, Any]] = None) -> int:
        if isinstance(material, bool) or not isinstance(material, int) or not 0 <= material < len(self.materials):
            raise ValueError(f"material {material!r} is not a material id of this scene")
        mesh: Dict[str, Any] = {"name": f"mesh{len(self.meshes)}", "material": f"material{material}",
                                "transform": {"matrix": [float(v) for v in transform12(transform)]},
                                "positions": [float(v) for v in _floats(positions, "positions", 3)],
                                "indices": _floats(indices, "indices", 3, "I"),
                                "shadow_terminator_geometry_offset": float(shadow_terminator_geometry_offset)}
        if normals is not None:
            mesh["normals"] = [float(v) for v in _floats(normals, "normals", 3)]
        if uvs is not None:
            mesh["uvs"] = [float(v) for v in _floats(uvs, "uvs", 6)]
        # UV layers and tangents as dwivedi.Scene.add_mesh names them: layer 0 is `uvs` (named
        # uv_name, default "0"), then uv_layers' (name, uvs) pairs; tangents by layer name.
        names = [uv_name if uv_name is not None else "0"] + [str(name) for name, _ in (uv_layers or ())]
        unknown = sorted(set(tangents or ()) - set(names))
        if unknown:
            raise Error(f"tangents for UV layers the mesh does not have: {', '.join(unknown)}",
                        _library.DWV_ERROR_INVALID_ARGUMENT)
        if uv_name is not None:
            mesh["uv_name"] = str(uv_name)
        count = sum(len(mesh[k]) for k in ("positions", "indices", "normals", "uvs") if k in mesh)
        if tangents and names[0] in tangents:
            mesh["tangents"] = [float(v) for v in _floats(tangents[names[0]], "tangents", 12)]
            count += len(mesh["tangents"])
        if uv_layers:
            mesh["uv_layers"] = []
            for k, (name, values) in enumerate(uv_layers):
                layer: Dict[str, Any] = {"name": str(name), "uvs": [float(v) for v in _floats(values, f"uv_layers[{k}]", 6)]}
                if tangents and str(name) in tangents:
                    layer["tangents"] = [float(v) for v in _floats(tangents[str(name)], f"tangents[{name!r}]", 12)]
                count += len(layer["uvs"]) + len(layer.get("tangents", ()))
                mesh["uv_layers"].append(layer)
        self._values += count + 32
        self.meshes.append(mesh)
        return len(self.meshes) - 1

    def add_light(self, light: Any) -> None:
        color = list(real_tuple(light.color, "color", 3))
        if isinstance(light, SunLight):
            self.lights.append({"kind": "sun", "color": color, "strength": float(light.strength),
                                "direction": list(real_tuple(light.direction, "direction", 3)),
                                "angle": degrees_for(float(light.angle))})
        elif isinstance(light, PointLight):
            self.lights.append({"kind": "point", "color": color, "strength": float(light.power),
                                "position": list(real_tuple(light.position, "position", 3)),
                                "radius": float(light.radius), **_point_shape(light)})
        elif isinstance(light, AreaLight):
            self.lights.append({"kind": "area", "color": color, "strength": float(light.power), "shape": light.shape,
                                "size_x": float(light.size_x), "size_y": float(light.size_y),
                                "transform": {"matrix": [float(v) for v in transform12(light.transform)]}})
        elif isinstance(light, SpotLight):
            self.lights.append({"kind": "spot", "color": color, "strength": float(light.power),
                                "position": list(real_tuple(light.position, "position", 3)),
                                "direction": list(real_tuple(light.direction, "direction", 3)),
                                "radius": float(light.radius), "spot_size": degrees_for(float(light.spot_size)),
                                "spot_blend": float(light.spot_blend), "spot_falloff": light.falloff,
                                **_point_shape(light)})
        else:
            raise TypeError(f"light must be a SunLight, PointLight, AreaLight or SpotLight, not {type(light).__name__}")

    def set_world(self, color: Any, strength: float = 1.0) -> None:
        self.world = {"color": list(real_tuple(color, "color", 3)), "strength": float(strength)}
        self.environment = None

    def set_world_environment(self, texels: Any, width: int, height: int, *, strength: float = 1.0,
                              rotation: Any = None, interpolation: str = "linear") -> None:
        """As dwivedi.Scene.set_world_environment; the image is written as an EXR beside the file."""
        if interpolation not in ("linear", "closest", "cubic"):
            raise ValueError(f"interpolation {interpolation!r} is not linear, closest or cubic")
        values = _float_array(texels, "texels", 3)
        if len(values) != 3 * width * height:
            raise Error(f"texels hold {len(values)} numbers: a {width} x {height} image needs {3 * width * height}",
                        _library.DWV_ERROR_INVALID_ARGUMENT)
        matrix = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0] if rotation is None else list(rotation)
        if len(matrix) == 3:  # rows
            matrix = [x for row in matrix for x in row]
        self.world = None
        self.environment = {"entry": {"interpolation": interpolation, "strength": float(strength),
                                      "rotation": list(real_tuple(matrix, "rotation", 9))},
                            "texels": values, "width": int(width), "height": int(height)}

    def add_texture(self, texels: Any, width: int, height: int, channels: int = 4, *, format: str = "float32",
                    extension: str = "repeat", interpolation: str = "linear") -> int:
        """As dwivedi.Scene.add_texture; the texels are written as an EXR (float32) or a PNG (8-bit)
        beside the file."""
        if format not in TEXEL_FORMATS or extension not in TEXTURE_EXTENSIONS or \
                interpolation not in TEXTURE_INTERPOLATIONS or channels not in (1, 3, 4):
            raise ValueError(f"texture format {format!r}, extension {extension!r}, interpolation {interpolation!r} "
                             f"or channels {channels!r} is not one the library takes")
        if format == "float32":
            values: Any = _float_array(texels, "texels", 1)
        elif isinstance(texels, (bytes, bytearray)):
            values = bytes(texels)
        else:
            try:
                values = bytes(memoryview(texels).cast("B"))
            except TypeError:
                values = bytes(int(v) for v in texels)  # ValueError outside 0..255
        if len(values) != width * height * channels:
            raise Error(f"texels hold {len(values)} values; {width} x {height} x {channels} needs "
                        f"{width * height * channels}", _library.DWV_ERROR_INVALID_ARGUMENT)
        entry: Dict[str, Any] = {"extension": extension, "interpolation": interpolation}
        if format != "float32":
            entry["colorspace"] = "srgb" if format == "srgb8" else "non_color"
        self.textures.append({"entry": entry, "texels": values, "width": int(width), "height": int(height),
                              "channels": int(channels), "float": format == "float32"})
        return len(self.textures) - 1

    def bind_texture(self, material: int, input: str, texture: int, *, uv_layer: Optional[str] = None,
                     blend: float = 1.0, strength: float = 1.0, distance: float = 1.0, invert: bool = False,
                     bump_shadowing: str = "chiang2019") -> None:
        if not 0 <= material < len(self.materials) or not 0 <= texture < len(self.textures):
            raise ValueError(f"material {material!r} or texture {texture!r} is not one of this scene")
        if input not in MATERIAL_INPUTS or bump_shadowing not in BUMP_SHADOWINGS:
            raise ValueError(f"input {input!r} or bump_shadowing {bump_shadowing!r} is not one the library takes")
        binding: Dict[str, Any] = {"input": input, "texture": f"texture{texture}", "blend": float(blend),
                                   "strength": float(strength), "distance": float(distance), "invert": bool(invert),
                                   "bump_shadowing": bump_shadowing}
        if uv_layer is not None:
            binding["uv_layer"] = str(uv_layer)
        self.materials[f"material{material}"].setdefault("textures", []).append(binding)

    def set_camera(self, camera: Camera) -> None:
        if not isinstance(camera, Camera):
            raise TypeError(f"camera must be a dwivedi.Camera, not {type(camera).__name__}")
        out: Dict[str, Any] = {"kind": camera.kind,
                               "transform": {"matrix": [float(v) for v in transform12(camera.transform)]}}
        if camera.kind == "orthographic":
            out["ortho_scale"] = float(camera.ortho_scale)
        else:
            out["focal_length"] = float(camera.focal_length)
            out["sensor_width"] = float(camera.sensor_width)
        self.camera = out

    def commit(self) -> "SceneFileWriter":
        return self

    def close(self) -> None:
        pass

    # The file ------------------------------------------------------------------------------------
    def document(self, bake: Optional[Dict[str, Any]] = None, description: str = "",
                 files: Optional[Dict[str, Dict[str, str]]] = None) -> Dict[str, Any]:
        """The scene file's JSON; `files` gives each texture's ("texture0", ...) and the
        environment's ("environment") "file" and "sha256" (write() makes them)."""
        files = files or {}
        out: Dict[str, Any] = {"version": 1}
        if description:
            out["description"] = description
        if self.textures:
            out["textures"] = {f"texture{k}": dict(files.get(f"texture{k}", {}), **t["entry"])
                               for k, t in enumerate(self.textures)}
        out.update(materials=self.materials, meshes=self.meshes, lights=self.lights)
        if self.environment is not None:
            out["world"] = {"environment": dict(files.get("environment", {}), **self.environment["entry"])}
        elif self.world is not None:
            out["world"] = self.world
        if self.camera is not None:
            out["camera"] = self.camera
        if bake:
            out["bake"] = dict(bake)
        return out

    def _image_files(self, path: str) -> Dict[str, Tuple[str, bytes]]:
        """The image files the scene needs: name -> (path relative to the scene file, bytes)."""
        stem = os.path.splitext(os.path.basename(path))[0]
        folder = f"{stem}_files"
        out: Dict[str, Tuple[str, bytes]] = {}
        for k, t in enumerate(self.textures):
            if t["float"]:
                data = image_files.exr_bytes(t["texels"], t["width"], t["height"], t["channels"])
                out[f"texture{k}"] = (f"{folder}/texture{k}.exr", data)
            else:
                data = image_files.png_bytes(t["texels"], t["width"], t["height"], t["channels"])
                out[f"texture{k}"] = (f"{folder}/texture{k}.png", data)
        if self.environment is not None:
            e = self.environment
            out["environment"] = (f"{folder}/environment.exr",
                                  image_files.exr_bytes(e["texels"], e["width"], e["height"], 3))
        return out

    def write(self, path: str, bake: Optional[Dict[str, Any]] = None, description: str = "") -> None:
        """Writes the scene file (under a temporary name, renamed into place when complete) and,
        first, its image files into SCENE_files/ beside it (each the same way); ValueError if it
        would hold more values than a scene file may."""
        if self._values > MAX_JSON_VALUES:  # read when called (a test lowers it)
            raise ValueError(f"the scene's meshes hold about {self._values} numbers, more than the {MAX_JSON_VALUES} "
                             "a scene file takes inline: bake it in fewer or smaller meshes")
        folder = os.path.dirname(os.path.abspath(path))
        images = self._image_files(path)
        files = {name: {"file": relative, "sha256": hashlib.sha256(data).hexdigest()}
                 for name, (relative, data) in images.items()}
        text = json.dumps(self.document(bake, description, files), separators=(",", ":"), allow_nan=False)
        if images:
            os.makedirs(os.path.join(folder, os.path.dirname(next(iter(images.values()))[0])), exist_ok=True)
        for relative, data in images.values():
            _write_replacing(os.path.join(folder, relative), data)
        _write_replacing(path, (text + "\n").encode("utf-8"))


def _write_replacing(path: str, data: bytes) -> None:
    """Writes `data` under a temporary name beside `path`, then renames it into place."""
    folder = os.path.dirname(os.path.abspath(path))
    temporary = os.path.join(folder, f".{os.path.basename(path)}.{os.getpid()}.tmp")
    try:
        with open(temporary, "wb") as f:
            f.write(data)
        os.replace(temporary, path)
    except BaseException:
        if os.path.exists(temporary):
            os.unlink(temporary)
        raise


def _point_shape(light: Any) -> dict:
    """A point or spot light's "point_shape" key, written for the sphere only (a disc's scene file
    stays as before the key existed)."""
    if light.shape not in ("disc", "sphere"):
        raise ValueError(f"point light shape {light.shape!r}: 'disc' or 'sphere'")
    return {"point_shape": "sphere"} if light.shape == "sphere" else {}
