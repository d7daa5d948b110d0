"""Image textures on material inputs: an Image Texture node connected to a shader input (directly,
or through a UV Map node or a Texture Coordinate node's UV for its vector; through a Normal Map
node in tangent space or a Bump node for the Normal) is passed to the library as it is: its
pixels (Image.pixels), its colour space (image.colorspace_settings: sRGB bytes stay 8-bit sRGB,
Non-Color and linear bytes 8-bit data, float images scene-linear float), its extension and
interpolation, and the UV map it reads (the UV Map node's, else the mesh's active render UV map).

Anything else linked to an input (a Mapping node, a procedural texture, a Mix node..., and a
Normal input fed by anything but those nodes) is evaluated by Blender into an image first
(evaluate.py: an emission bake; for a Normal fed by a Bump node of constant settings over a
procedural Height, an emission bake of that height bound as the bump's height texture; for any
other Normal tree a tangent-space normal bake bound as a normal map), per material of each
object, or once for the objects of one mesh where the result cannot differ; each object's material then reads its own evaluation's images (OWNERS, evaluation_of).
"""
from __future__ import annotations

import array
from typing import Any, Dict, List, Optional, Tuple

from . import gather


class MissingImage(Exception):
    """An Image Texture's image has no pixels (its file is missing or unreadable), or pixels the
    library refuses (NaN or infinite values)."""


# Blender's image colour spaces whose 8-bit values are data (value / 255) rather than sRGB.
_LINEAR_SPACES = {"Non-Color", "Linear", "Linear Rec.709", "Linear CIE-XYZ E", "Raw", "Linear Rec.2020"}

_EXTENSIONS = {"REPEAT": "repeat", "EXTEND": "extend", "CLIP": "clip", "MIRROR": "mirror"}
# Cycles interpolates "Smart" as Cubic (kernel/device/cpu/image.h).
_INTERPOLATIONS = {"Linear": "linear", "Closest": "closest", "Cubic": "cubic", "Smart": "cubic"}


class Use:
    """One texture on one input: the Image Texture node, its output ('Color' or 'Alpha'), the UV
    map name (None: the active render UV map) and the binding's blend, strength, distance and
    invert."""

    def __init__(self, input_name: str, node: Any, output: str, uv_map: Optional[str], blend: float = 1.0,
                 strength: float = 1.0, distance: float = 1.0, invert: bool = False) -> None:
        self.input = input_name
        self.node = node
        self.output = output
        self.uv_map = uv_map
        self.blend = blend
        self.strength = strength
        self.distance = distance
        self.invert = invert


class EvaluatedImage:
    """What the Image Texture node of an input that Blender evaluated into an image would be: the
    image, linear interpolation, the edge extended (the bake's margin covers the seams)."""

    def __init__(self, image: Any) -> None:
        self.image = image
        self.interpolation = 'Linear'
        self.extension = 'EXTEND'


# What an object's material was evaluated as (evaluate.py): the evaluation (material name, owner)
# whose images it reads, the owner "mesh NAME" (images shared by the objects of that mesh) or
# "object NAME". Per (material name, object name); an object missing here (its material had
# nothing to evaluate, or the object was not evaluated) has the evaluation (material name, None),
# which has no images.
Evaluation = Tuple[str, Optional[str]]
OWNERS: Dict[Tuple[str, str], Evaluation] = {}
# Inputs whose node trees Blender evaluated into images, per (evaluation, node name, input
# identifier): (EvaluatedImage, UV map). Filled before the materials are exported (the
# depsgraph's copies of a material and an object share their names); cleared after.
EVALUATED: Dict[Tuple[Evaluation, str, str], Tuple[EvaluatedImage, str]] = {}


def evaluation_of(material_name: str, object_name: str) -> Evaluation:
    """The evaluation whose images the material of object `object_name` reads."""
    return OWNERS.get((material_name, object_name), (material_name, None))


def evaluated_key(evaluation: Evaluation, socket: Any) -> Tuple[Evaluation, str, str]:
    return evaluation, socket.node.name, socket.identifier


def _image_source(socket: Any, evaluation: Optional[Evaluation] = None) -> Optional[Tuple[Any, str, Optional[str]]]:
    """(Image Texture node, its output name, UV map or None) when `socket` is fed straight by an
    Image Texture node that the library can look up as Blender does, or was evaluated into an
    image (EVALUATED); None otherwise."""
    if socket is None or not socket.is_linked:
        return None
    evaluated = EVALUATED.get(evaluated_key(evaluation, socket)) if evaluation else None
    if evaluated is not None:
        return evaluated[0], "Color", evaluated[1]
    link = socket.links[0]
    node = link.from_node
    if node.type != 'TEX_IMAGE' or node.image is None or link.from_socket.name not in ("Color", "Alpha"):
        return None
    if getattr(node, "projection", 'FLAT') != 'FLAT' or node.image.source not in {'FILE', 'GENERATED'}:
        return None
    if getattr(node, "extension", 'REPEAT') not in _EXTENSIONS or node.interpolation not in _INTERPOLATIONS:
        return None
    vector = node.inputs.get("Vector")
    uv_map = None
    if vector is not None and vector.is_linked:
        source = vector.links[0].from_node
        if source.type == 'UVMAP' and not getattr(source, "from_instancer", False):
            uv_map = source.uv_map or None
        elif not (source.type == 'TEX_COORD' and vector.links[0].from_socket.name == "UV"):
            return None
    return node, link.from_socket.name, uv_map


def passes(socket: Any, evaluation: Optional[Evaluation] = None) -> bool:
    """Whether a linked input is one this module passes on (no warning about it), for a material
    whose evaluated inputs are `evaluation`'s (evaluation_of)."""
    return _image_source(socket, evaluation) is not None or _normal_uses(socket, evaluation) is not None


def _plain(socket: Any, default: float) -> float:
    return float(socket.default_value) if socket is not None and not socket.is_linked else default


def _normal_uses(socket: Any, evaluation: Optional[Evaluation] = None) -> Optional[List[Use]]:
    """The normal map and bump feeding a Normal input (or the tangent-space normal map Blender
    baked of it, EVALUATED), or None if it is fed otherwise."""
    if socket is None or not socket.is_linked:
        return None
    evaluated = EVALUATED.get(evaluated_key(evaluation, socket)) if evaluation else None
    if evaluated is not None:
        return [Use("normal_map", evaluated[0], "Color", evaluated[1])]
    node = socket.links[0].from_node
    uses: List[Use] = []
    if node.type == 'BUMP':
        height = _image_source(node.inputs.get("Height"), evaluation)
        if height is None or not _plain_bump(node):
            return None
        inner = node.inputs.get("Normal")
        if inner is not None and inner.is_linked:
            mapped = _normal_uses(inner)
            if mapped is None or any(u.input != "normal_map" for u in mapped):
                return None
            uses.extend(mapped)
        uses.append(Use("bump", height[0], height[1], height[2], strength=min(max(_plain(node.inputs["Strength"], 1.0), 0.0), 1.0),
                        distance=_plain(node.inputs["Distance"], 1.0), invert=bool(node.invert)))
        return uses
    if node.type == 'NORMAL_MAP':
        if node.space != 'TANGENT' or node.inputs.get("Strength").is_linked:
            return None
        colour = _image_source(node.inputs.get("Color"))
        if colour is None or colour[1] != "Color":
            return None
        uv_map = node.uv_map or colour[2]
        return [Use("normal_map", colour[0], "Color", uv_map, strength=max(_plain(node.inputs["Strength"], 1.0), 0.0))]
    return None


def _plain_bump(node: Any) -> bool:
    """Whether a Bump node's settings are constants (Strength, Distance and, where the node has
    one (5.2), Filter Width unlinked): what the library's bump takes (dwv_texture_binding_t)."""
    return not any(s is not None and s.is_linked for s in (node.inputs.get(name) for name in
                                                           ("Strength", "Distance", "Filter Width")))


def evaluable_bump_height(normal: Any) -> Optional[Any]:
    """The Height input of a plain Bump node (_plain_bump; its own Normal unlinked or an image
    normal map passed as it is) feeding the Normal input `normal` straight, when that Height is
    linked to a node tree that no Image Texture feeds as it is: evaluated by Blender into a
    height image (an emission bake of a scalar, evaluate.py) which the library's bump then
    differentiates, instead of Blender's normal bake of the whole Normal."""
    node = normal.links[0].from_node if normal is not None and normal.is_linked else None
    if node is None or node.type != 'BUMP' or not _plain_bump(node):
        return None
    height, inner = node.inputs.get("Height"), node.inputs.get("Normal")
    if height is None or not height.is_linked or _image_source(height) is not None:
        return None
    if inner is not None and inner.is_linked:
        mapped = _normal_uses(inner)
        if mapped is None or any(u.input != "normal_map" for u in mapped):
            return None
    return height


def _socket(node: Any, names: Tuple[str, ...]) -> Any:
    for name in names:
        socket = node.inputs.get(name)
        if socket is not None:
            return socket
    return None


def material_uses(node: Any, blender4: bool, material: Any, evaluation: Optional[Evaluation] = None) -> List[Use]:
    """The textures of a Principled BSDF or Subsurface Scattering node's inputs (those Blender
    evaluated: `evaluation`'s images), in the order the library applies them; `material` (a dwivedi.Material made from the node's own values) is
    adjusted where a texture changes what a constant meant (Blender 3.x's subsurface colour mix)."""
    uses: List[Use] = []

    def add(input_name: str, names: Tuple[str, ...], blend: float = 1.0) -> Optional[Tuple[Any, str, Optional[str]]]:
        found = _image_source(_socket(node, names), evaluation)
        if found is not None:
            uses.append(Use(input_name, found[0], found[1], found[2], blend=blend))
        return found

    if node.type == 'SUBSURFACE_SCATTERING':
        colour = add("base_color", ("Color",))
        if colour is not None:
            uses.append(Use("subsurface_color", colour[0], colour[1], colour[2]))
        add("subsurface_radius", ("Radius",))
        add("subsurface_scale", ("Scale",))
        add("subsurface_anisotropy", ("Anisotropy",))
    elif blender4:
        base = add("base_color", ("Base Color",))
        if base is not None:
            uses.append(Use("subsurface_color", base[0], base[1], base[2]))
        add("subsurface_weight", ("Subsurface Weight",))
        add("subsurface_radius", ("Subsurface Radius",))
        add("subsurface_scale", ("Subsurface Scale",))
        add("subsurface_anisotropy", ("Subsurface Anisotropy",))
        add("specular_tint", ("Specular Tint",))
        add("specular", ("Specular IOR Level",))
    else:
        # 3.x: the walk's colour is mix(Base Color, Subsurface Color, Subsurface); the bindings
        # rebuild the mix from the constant they start with (dwv_texture_binding_t.blend).
        factor = _plain(node.inputs.get("Subsurface"), 0.0)
        base_socket, colour_socket = node.inputs.get("Base Color"), node.inputs.get("Subsurface Color")
        base = add("base_color", ("Base Color",))
        colour = _image_source(colour_socket, evaluation)
        if factor > 0.0 and (base is not None or colour is not None):
            if base is not None:
                material.subsurface_color = tuple(colour_socket.default_value)[:3]
                if colour is not None:
                    uses.append(Use("subsurface_color", colour[0], colour[1], colour[2]))
                uses.append(Use("subsurface_color", base[0], base[1], base[2], blend=max(0.0, 1.0 - factor)))
            else:
                material.subsurface_color = tuple(base_socket.default_value)[:3]
                uses.append(Use("subsurface_color", colour[0], colour[1], colour[2], blend=min(factor, 1.0)))
        add("subsurface_radius", ("Subsurface Radius",))
        add("specular", ("Specular",))
    if node.type != 'SUBSURFACE_SCATTERING':
        add("roughness", ("Roughness",))
    normal = _normal_uses(node.inputs.get("Normal"), evaluation)
    if normal:
        uses.extend(normal)
    return uses


def evaluable_inputs(node: Any, blender4: bool) -> List[Any]:
    """The node's linked inputs that a texture could drive but no Image Texture feeds as it is:
    what Blender evaluates into an image (evaluate.py)."""
    if node.type == 'SUBSURFACE_SCATTERING':
        names = ("Color", "Radius", "Scale", "Anisotropy")
    elif blender4:
        names = ("Base Color", "Subsurface Weight", "Subsurface Radius", "Subsurface Scale", "Subsurface Anisotropy",
                 "Specular Tint", "Specular IOR Level", "Roughness")
    else:
        names = ("Base Color", "Subsurface Color", "Subsurface Radius", "Specular", "Roughness")
    out = []
    for name in names:
        socket = node.inputs.get(name)
        if socket is not None and socket.is_linked and _image_source(socket) is None:
            out.append(socket)
    normal = node.inputs.get("Normal")
    if normal is not None and normal.is_linked and _normal_uses(normal) is None:
        # A plain procedural Bump: its height; anything else: a tangent-space normal map (evaluate.py).
        out.append(evaluable_bump_height(normal) or normal)
    return out


def linked_unpassed(node: Any, blender4: bool, evaluation: Optional[Evaluation] = None) -> List[str]:
    """The names of the node's linked inputs that no texture use covers (their own values are
    used): for the warning."""
    covered = {"Base Color", "Color", "Radius", "Scale", "Anisotropy", "Subsurface Radius", "Normal", "Roughness"}
    if blender4:
        covered |= {"Subsurface Weight", "Subsurface Scale", "Subsurface Anisotropy", "Specular Tint",
                    "Specular IOR Level"}
    else:
        covered |= {"Subsurface Color", "Specular"}
    names = []
    for socket in node.inputs:
        if not socket.is_linked:
            continue
        if socket.name in covered and (passes(socket, evaluation) if socket.name != "Normal"
                                       else _normal_uses(socket, evaluation) is not None):
            continue
        names.append(socket.name)
    return names


class TextureCache:
    """The scene's textures, one per image and output (Color, Alpha), made once."""

    def __init__(self, dw_scene: Any) -> None:
        self.scene = dw_scene
        self.ids: Dict[Tuple[str, str, str, str], int] = {}
        self.bytes = 0
        self.texels = 0

    def texture(self, use: Use, material_name: str) -> int:
        node, image = use.node, use.node.image
        extension = _EXTENSIONS[getattr(node, "extension", 'REPEAT')]
        interpolation = _INTERPOLATIONS[node.interpolation]
        key = (image.name_full, use.output, extension, interpolation)
        if key in self.ids:
            return self.ids[key]
        count = len(image.pixels)  # loads the image if it is not loaded yet
        width, height = int(image.size[0]), int(image.size[1])
        channels = int(image.channels)
        if width * height == 0 or channels == 0 or count != width * height * channels:
            where = f" (file '{image.filepath}')" if image.filepath else ""
            raise MissingImage(f"image '{image.name}'{where} of material '{material_name}' has no pixels: its file "
                               "is missing or cannot be read; nothing was baked")
        pixels = array.array("f", [0.0]) * (width * height * channels)
        image.pixels.foreach_get(pixels)
        if channels == 4 and use.output == "Color" and int(image.depth) in (24, 96):
            # An RGB image (Image.pixels always has 4 channels): its constant alpha is left out.
            rgb = array.array("f", [0.0]) * (width * height * 3)
            for c in range(3):
                rgb[c::3] = pixels[c::4]
            pixels, channels = rgb, 3
        if use.output == "Alpha" or channels == 2:
            alpha = channels - 1
            pixels = array.array("f", pixels[alpha::channels]) if channels in (2, 4) else array.array("f", [1.0]) * (width * height)
            channels = 1
        space = image.colorspace_settings.name
        if image.is_float:
            texture = self.scene.add_texture(pixels, width, height, channels, format="float32", extension=extension,
                                             interpolation=interpolation)
        else:
            # Byte images: Image.pixels gives the stored bytes / 255; the library decodes sRGB
            # after interpolation, as Cycles does for byte images.
            data = bytes(min(255, max(0, int(round(v * 255.0)))) for v in pixels)
            colour = space not in _LINEAR_SPACES and use.output == "Color"
            texture = self.scene.add_texture(data, width, height, channels, format="srgb8" if colour else "linear8",
                                             extension=extension, interpolation=interpolation)
        self.ids[key] = texture
        return texture


def bump_shadowing(version: Tuple[int, ...]) -> str:
    """How the Cycles of Blender `version` treats normals that a map tilted (dwv_bump_shadowing_t):
    Chiang 2019's shadowing of diffuse lobes, with 3.x's ensure_valid_reflection on every closure
    (4.x applies it to specular closures only; measured against 4.3's Cycles); 5.x Conty Estevez
    2019's (measured against 5.2; the release between 4.3 and 5.2 that changed it is not known
    here: 5.0 is assumed). The library also takes the normal map's Strength rule from it (4.0+
    scales the map's tangent part, Cycles d71e0f45d; 3.x extrapolates in world space)."""
    version = tuple(version)
    if version < (4, 0, 0):
        return "chiang2019"
    return "chiang2019_mapped" if version < (5, 0, 0) else "conty2019"


def bind(dw_scene: Any, cache: TextureCache, material_id: int, uses: List[Use], material_name: str,
         version: Tuple[int, ...]) -> None:
    """Adds the textures of `uses` and binds them to the material, in order."""
    for use in uses:
        try:
            texture = cache.texture(use, material_name)
        except MissingImage:
            raise
        except Exception as error:  # the library's refusal (a NaN texel...), said with the image's name
            if type(error).__name__ != "Error":
                raise
            raise MissingImage(f"image '{use.node.image.name}' of material '{material_name}': {error}") from None
        dw_scene.bind_texture(material_id, use.input, texture, uv_layer=use.uv_map, blend=use.blend,
                              strength=use.strength, distance=use.distance, invert=use.invert,
                              bump_shadowing=bump_shadowing(version))


def uv_layers(mesh: Any, loops: Any, first: Any, tangent_maps: List[Optional[str]]) -> Dict[str, Any]:
    """A mesh's UV maps per triangle corner for the library: `first` (the map that is layer 0,
    what bindings without a UV map read: the active render map) and the others by name, plus
    Blender's MikkTSpace tangents (Mesh.calc_tangents) of the maps normal maps read."""
    result: Dict[str, Any] = {"uv_name": first.name, "uvs": gather.corner_uvs(mesh, first, loops), "uv_layers": [],
                              "tangents": {},
                              "warnings": []}
    for layer in mesh.uv_layers:
        if layer.name != first.name:
            result["uv_layers"].append((layer.name, gather.corner_uvs(mesh, layer, loops)))
    for name in sorted({first.name if n is None else n for n in tangent_maps}):
        if mesh.uv_layers.get(name) is None:
            continue  # the library refuses the binding with the mesh's layer names
        try:
            mesh.calc_tangents(uvmap=name)
        except RuntimeError as error:
            result["warnings"].append(f"no MikkTSpace tangents for UV map '{name}' ({error}): the library makes "
                                      "them from the UVs")
            continue
        tangent = array.array("f", bytes(12 * len(mesh.loops)))
        sign = array.array("f", bytes(4 * len(mesh.loops)))
        mesh.loops.foreach_get("tangent", tangent)
        mesh.loops.foreach_get("bitangent_sign", sign)  # MikkTSpace's orientation: exactly 1 or -1
        result["tangents"][name] = gather.rows(gather.interleave(tangent, 3, sign), 4, loops)
    return result
