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
    writer.write("scene.json", bake={"width": 640, "height": 360, "samples": 256})

Meshes are written inline, so a scene file holds at most the 2^22 JSON values the reader takes;
write() refuses a larger scene with a message (too big for a file without mesh files).
Standard library only; nothing here calls the library.
"""
from __future__ import annotations

import ctypes
import json
import math
import os
from typing import Any, Dict, List, Optional

from ._buffers import as_c_array, real_tuple, transform12
from . import _library
from .baker import (SPECULAR_MODELS, SUBSURFACE_MODELS, AreaLight, Camera, Error, Material, PointLight, SpotLight,
                    SunLight)

MAX_JSON_VALUES = 1 << 22  # docs/scene-format.md: "at most 2^22 JSON values"
_RADIANS_PER_DEGREE = 3.14159265358979323846 / 180.0  # as src/scenefile/scene_json_lights.c


def _floats(values: Any, name: str, group: int, kind: str = "f") -> List[Any]:
    """`values` as the library would receive them (float32, or uint32 for kind 'I'), as a list."""
    array = as_c_array(values, kind, name, group)
    if array.count == 0:
        return []
    ctype = ctypes.c_float if kind == "f" else ctypes.c_uint32
    return list((ctype * array.count).from_address(array.address))


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


class SceneFileWriter:
    """Records a scene's building calls (dwivedi.Scene's) and writes them as a scene file."""

    def __init__(self) -> None:
        self.materials: Dict[str, Dict[str, Any]] = {}
        self.meshes: List[Dict[str, Any]] = []
        self.lights: List[Dict[str, Any]] = []
        self.world: Optional[Dict[str, Any]] = None
        self.camera: Optional[Dict[str, Any]] = None
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
                 transform: Any = None, shadow_terminator_geometry_offset: float = 0.1) -> int:
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
        self._values += sum(len(mesh[k]) for k in ("positions", "indices", "normals", "uvs") if k in mesh) + 32
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

    # What the scene file cannot yet hold so that it bakes the same bits: refused, never left out.
    def set_world_environment(self, *_args: Any, **_kwargs: Any) -> None:
        raise Error("a scene file cannot hold an environment-map world yet (its rotation is written as Euler "
                    "degrees, which need not give back the same matrix): bake this scene on one machine",
                    _library.DWV_ERROR_INVALID_ARGUMENT)

    def add_texture(self, *_args: Any, **_kwargs: Any) -> int:
        raise Error("a scene file cannot hold textured materials yet (extra UV layers and tangents are not in the "
                    "format): bake this scene on one machine", _library.DWV_ERROR_INVALID_ARGUMENT)

    bind_texture = add_texture

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
    def document(self, bake: Optional[Dict[str, Any]] = None, description: str = "") -> Dict[str, Any]:
        out: Dict[str, Any] = {"version": 1}
        if description:
            out["description"] = description
        out.update(materials=self.materials, meshes=self.meshes, lights=self.lights)
        if self.world is not None:
            out["world"] = self.world
        if self.camera is not None:
            out["camera"] = self.camera
        if bake:
            out["bake"] = dict(bake)
        return out

    def write(self, path: str, bake: Optional[Dict[str, Any]] = None, description: str = "") -> None:
        """Writes the scene file (under a temporary name, renamed into place when complete);
        ValueError if it would hold more values than a scene file may."""
        if self._values > MAX_JSON_VALUES:  # read when called (a test lowers it)
            raise ValueError(f"the scene's meshes hold about {self._values} numbers, more than the {MAX_JSON_VALUES} "
                             "a scene file takes inline: bake it in fewer or smaller meshes")
        text = json.dumps(self.document(bake, description), separators=(",", ":"), allow_nan=False)
        folder = os.path.dirname(os.path.abspath(path))
        temporary = os.path.join(folder, f".{os.path.basename(path)}.{os.getpid()}.tmp")
        try:
            with open(temporary, "w", encoding="utf-8") as f:
                f.write(text)
                f.write("\n")
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
