"""Material inputs driven by node trees other than an Image Texture (a procedural texture, a
Mapping node, a Mix...), evaluated by Blender itself: Cycles bakes the input's value as emission
into a float image on the object's active UV map (Object.bake, type EMIT, 1 sample), which the
add-on then passes as an image texture (textures.py). A Normal input fed by anything but an
Image Texture through a Normal Map or Bump node is baked as Blender's normal bake does (type
NORMAL, tangent space of the active UV map: the shading normal as 0.5 + 0.5 (x, y, z) in its
MikkTSpace frame) and bound as a tangent-space normal map of that UV map, which maps it back.

Per object: an image in UV space holds the input at the object's own surface points, so it is
right only for the UVs it was baked on. A material shared by several objects is evaluated once
for all the objects that evaluate the same surface the same way (the same mesh data without
modifiers, when the input reads nothing but the mesh: see reads_only_mesh), and otherwise once
per object; each library material of those (export.py) is bound to its own images.

Nothing of the user's is changed: the bake runs on a temporary copy of the object (same mesh,
modifiers, transform and parent) whose material slots are its own, holding a temporary copy of
the evaluated material (the emission wiring and the target image node are made there) and, on
every other slot (another material, an empty slot, a material without nodes or from a library),
a throwaway material whose faces Cycles writes into a throwaway image (Cycles writes each face
into its own material's active image). The bake's settings are the operator's arguments; the
render engine and samples, the selection and the active object are set for it and put back.
The copies and images are removed once the pixels are read. (An Object Info node's Random is
the copy's, not the object's: warned.) The resolution is the user's
(scene.dwivedi_bake.texture_bake_size) and the warning states it; texture detail finer than it
is lost.
"""
from __future__ import annotations

import array
from typing import Any, Dict, List, Optional, Tuple

import bpy

from . import textures


class EvaluationError(Exception):
    """Blender could not evaluate an input (its bake failed): the message says which and why."""


# Nodes whose outputs depend on their inputs only (and on their own settings).
_PURE = {"MATH", "VECT_MATH", "MIX_RGB", "MIX", "VALTORGB", "RGB", "VALUE", "SEPRGB", "COMBRGB", "SEPXYZ",
         "COMBXYZ", "SEPHSV", "COMBHSV", "SEPARATE_COLOR", "COMBINE_COLOR", "HUE_SAT", "BRIGHTCONTRAST", "GAMMA",
         "INVERT", "CURVE_RGB", "CURVE_VEC", "CURVE_FLOAT", "MAP_RANGE", "CLAMP", "RGBTOBW", "BLACKBODY",
         "WAVELENGTH", "MAPPING", "NORMAL", "REROUTE", "VECTOR_ROTATE", "FRAME", "GROUP_INPUT"}
# Textures: their Vector input (or, unlinked, the mesh's generated coordinates or UV map).
_TEXTURES = {"TEX_NOISE", "TEX_VORONOI", "TEX_WAVE", "TEX_MAGIC", "TEX_CHECKER", "TEX_BRICK", "TEX_GRADIENT",
             "TEX_MUSGRAVE", "TEX_WHITE_NOISE", "TEX_IMAGE", "TEX_GABOR"}
# Sources read from the mesh alone (the same for every object of one mesh without modifiers).
_MESH_SOURCES = {"UVMAP", "VERTEX_COLOR", "TANGENT"}
# Texture Coordinate outputs in the mesh's own space (Object: unless the node names another object).
_MESH_COORDINATES = {"Generated", "UV", "Normal", "Object"}


def _node_reads_only_mesh(node: Any, output: Any, groups: Tuple[Any, ...], seen: set) -> bool:
    kind = node.type
    if kind == 'TEX_COORD':
        return output.name in _MESH_COORDINATES and (output.name != "Object" or node.object is None)
    if kind == 'ATTRIBUTE':
        return getattr(node, "attribute_type", 'GEOMETRY') == 'GEOMETRY'
    if kind == 'UVMAP' and getattr(node, "from_instancer", False):
        return False
    if kind == 'GROUP_INPUT':
        # The group node's input of that identifier, in the tree around the group.
        if not groups:
            return False
        outer = groups[-1]
        socket = next((s for s in outer.inputs if s.identifier == output.identifier), None)
        return socket is None or _socket_reads_only_mesh(socket, groups[:-1], seen)
    if kind == 'GROUP':
        if node.node_tree is None:
            return True
        inner = next((n for n in node.node_tree.nodes if n.type == 'GROUP_OUTPUT' and n.is_active_output),
                     next((n for n in node.node_tree.nodes if n.type == 'GROUP_OUTPUT'), None))
        socket = None if inner is None else next((s for s in inner.inputs if s.identifier == output.identifier), None)
        return socket is None or _socket_reads_only_mesh(socket, groups + (node,), seen)
    if kind not in _PURE and kind not in _TEXTURES and kind not in _MESH_SOURCES:
        return False  # the camera, a light path, the world position, an object's info, a bump...
    return all(_socket_reads_only_mesh(s, groups, seen) for s in node.inputs)


def _socket_reads_only_mesh(socket: Any, groups: Tuple[Any, ...], seen: set) -> bool:
    for link in socket.links:
        if not link.is_valid or link.is_muted:
            continue
        key = (tuple(g.as_pointer() for g in groups), link.from_node.as_pointer(), link.from_socket.identifier)
        if key in seen:
            continue
        seen.add(key)
        if not _node_reads_only_mesh(link.from_node, link.from_socket, groups, seen):
            return False
    return True


def reads_only_mesh(socket: Any) -> bool:
    """Whether the value linked into `socket` depends on the shaded mesh alone (its UV maps,
    generated and object-space coordinates, attributes, tangents, through nodes that compute
    from their inputs): then every object of one mesh data block without modifiers evaluates it
    to the same image. Anything else (world positions, a Bump's world-space gradient, another
    object's space, an object's info, the camera, a node not known here) may differ per object."""
    return _socket_reads_only_mesh(socket, (), set())


# Blender's normal bake looks at each texel along the smooth normal, and its BSDFs keep the normal
# valid for reflection of that direction (Cycles' ensure_valid_reflection: R = 2 (N.I) N - I above
# the surface, so N within about 45 degrees of it): a bump tilted further comes out at 45 degrees
# (measured in 3.4: a Wave bump of Distance 0.3 has tangents of its tilt up to 3.0, the bake gave
# 1.08 and a third of its texels at the limit). So a Bump node of constant settings over a
# procedural Height is not normal-baked: its Height is evaluated instead (textures.
# evaluable_bump_height: an emission bake of a scalar, which nothing clamps), and the library's bump computes the normal from that
# height's surface gradient as svm_node_set_bump does (dwv_texture_binding_t, DWV_INPUT_BUMP).
# Other Normal trees (a bump of a bump, linked Strength...) are normal-baked and warned about where
# they reach the limit.
# What evaluating the height into an image leaves (said with every evaluated Bump height): the
# image's texels hold the height at their centres, interpolated linearly between them (so the
# gradient is the texels' differences), and Cycles' render takes the height's differences over
# each pixel's footprint (ray differentials). Measured on tests/blender/test_evaluate.py's sphere
# (a Wave Texture bump of Distance 0.3, tilts up to 70 degrees, 24 x 24 pixels, two seeds; the
# three channels' means differ alike): +0.60% (3.4), -0.08% (4.3), +0.35% (5.2) with the height at
# 512 x 512 (the default's, HEIGHT_SIZE_FACTOR), +0.51% / -0.14% / +0.48% at 256 x 256; the
# Distance / 16 normal bake this replaced gave +1.1% / +1.7% / +2.9% at 256 x 256. A Wave twice as
# fine, 64 x 64 pixels: +0.12% / +0.37% / +0.06% at 512 x 512, +0.15% / +0.99% / +1.30% at 256.
BUMP_FIGURES = ("; a strong bump's height evaluated at 512 x 512 (a Wave bump of Distance 0.3, tilts up to 70 "
                "degrees) gave means +0.6% (Blender 3.4), -0.1% (4.3), +0.4% (5.2) off Cycles', at 256 x 256 "
                "+0.5% / -0.1% / +0.5%, and a Wave twice as fine (tilts up to 80 degrees) +0.1% / +0.4% / +0.1% "
                "at 512 x 512, +0.2% / +1.0% / +1.3% at 256 x 256")
# A Bump's height is evaluated at HEIGHT_SIZE_FACTOR x the Texture Bake Size per axis (at most
# MAX_SIZE, the setting's own maximum): the bump's normal is the image's gradient, the texels'
# differences, which fall short of the height's slopes by sinc(pi texel / period) and hold them
# constant across a texel; a Wave bump of 7 texels a period at 256 x 256 (the test's finer one)
# came out +1.3% above Cycles 5.2, at 512 x 512 -0.1%. The cost: about 1 to 2 s more per
# evaluated height on this machine (4 x the texels of 256 x 256).
HEIGHT_SIZE_FACTOR = 2
MAX_SIZE = 8192
# The z (cosine to the smooth normal) at or below which a baked normal is taken as clamped.
CLAMPED_Z = 0.72


def _clamped_share(image: Any) -> float:
    """The fraction of a normal bake's covered texels (the others hold the cleared black, not of
    unit length) at the bake's limit (CLAMPED_Z)."""
    pixels = array.array("f", [0.0]) * len(image.pixels)
    image.pixels.foreach_get(pixels)
    covered = clamped = 0
    for k in range(0, len(pixels), 4):
        x, y, z = 2.0 * pixels[k] - 1.0, 2.0 * pixels[k + 1] - 1.0, 2.0 * pixels[k + 2] - 1.0
        if abs(x * x + y * y + z * z - 1.0) >= 0.05:
            continue
        covered += 1
        clamped += z <= CLAMPED_Z
    return clamped / max(covered, 1)


def _active_output(tree: Any) -> Any:
    for node in tree.nodes:
        if node.type == 'OUTPUT_MATERIAL' and node.is_active_output and node.target in {'ALL', 'CYCLES'}:
            return node
    return next((node for node in tree.nodes if node.type == 'OUTPUT_MATERIAL'), None)


def _matching_socket(tree: Any, socket: Any) -> Any:
    node = tree.nodes.get(socket.node.name)
    return None if node is None else next((s for s in node.inputs if s.identifier == socket.identifier), None)


class _SceneState:
    """What the bake sets on the scene and view layer (the render engine and samples, the
    selection and the active object), taken before and put back after."""

    def __init__(self, scene: Any, view_layer: Any) -> None:
        self.scene, self.view_layer = scene, view_layer
        self.engine, self.samples = scene.render.engine, scene.cycles.samples
        self.selected = [o for o in view_layer.objects if o.select_get()]
        self.active = view_layer.objects.active

    def restore(self) -> None:
        self.scene.render.engine, self.scene.cycles.samples = self.engine, self.samples
        for o in self.view_layer.objects:
            if o.select_get():
                o.select_set(False)
        for o in self.selected:
            o.select_set(True)
        self.view_layer.objects.active = self.active


def _bake_socket(obj: Any, material: Any, socket: Any, size: int, warnings: Optional[List[str]] = None) -> Any:
    """A float image of `socket`'s value (the Normal input: the tangent-space normal map of the
    shading normal) over the object's active UV map, on the faces of
    `material`; baked on a copy of the object (the module's comment). EvaluationError if
    Blender's bake fails. A normal still at the bake's limit is said in `warnings`."""
    normal = socket.name == "Normal"
    scene = bpy.context.scene
    view_layer = bpy.context.view_layer
    image = bpy.data.images.new(f"dwivedi {material.name} {socket.name}", size, size, alpha=False, float_buffer=True)
    image.colorspace_settings.name = 'Non-Color'
    made_materials: List[Any] = []
    spare_image = None
    proxy = None
    state = _SceneState(scene, view_layer)
    try:
        evaluated = material.copy()  # a library material's copy is local: it can be wired
        made_materials.append(evaluated)
        tree = evaluated.node_tree
        output = _active_output(tree)
        target_socket = _matching_socket(tree, socket)
        if output is None or target_socket is None or not target_socket.is_linked:
            raise EvaluationError(f"material '{material.name}' has no material output or no linked "
                                  f"'{socket.name}' to evaluate")
        surface = output.inputs["Surface"]
        if not normal:
            emission = tree.nodes.new("ShaderNodeEmission")
            source = target_socket.links[0].from_socket
            tree.links.new(source, emission.inputs["Color"])
            emission.inputs["Strength"].default_value = 1.0
            for link in list(surface.links):
                tree.links.remove(link)
            tree.links.new(emission.outputs["Emission"], surface)
        target = tree.nodes.new("ShaderNodeTexImage")
        target.image = image
        tree.nodes.active = target
        proxy = obj.copy()  # shares the mesh; its slots become its own (the mesh is not touched)
        proxy.name = f"{obj.name} (dwivedi evaluation)"
        scene.collection.objects.link(proxy)
        spare = None
        for slot in proxy.material_slots:
            mine = slot.material == material
            slot.link = 'OBJECT'
            if not mine and spare is None:
                spare_image = bpy.data.images.new("dwivedi spare", 8, 8, alpha=False, float_buffer=True)
                spare = bpy.data.materials.new("dwivedi spare")
                made_materials.append(spare)
                spare.use_nodes = True
                node = spare.node_tree.nodes.new("ShaderNodeTexImage")
                node.image = spare_image
                spare.node_tree.nodes.active = node
            slot.material = evaluated if mine else spare
        proxy.hide_render = False
        proxy.hide_viewport = False
        proxy.hide_select = False
        scene.render.engine = 'CYCLES'
        scene.cycles.samples = 1
        for o in state.selected:
            o.select_set(False)
        proxy.select_set(True)
        view_layer.objects.active = proxy
        try:
            result = bpy.ops.object.bake(type='NORMAL' if normal else 'EMIT', margin=4, use_clear=True,
                                         target='IMAGE_TEXTURES', save_mode='INTERNAL', use_selected_to_active=False,
                                         use_split_materials=False, use_automatic_name=False,
                                         normal_space='TANGENT', normal_r='POS_X', normal_g='POS_Y', normal_b='POS_Z')
        except RuntimeError as error:
            raise EvaluationError(f"Blender could not evaluate '{socket.name}' of material '{material.name}' on "
                                  f"object '{obj.name}': {str(error).strip()}") from None
        if result != {'FINISHED'}:
            raise EvaluationError(f"Blender could not evaluate '{socket.name}' of material '{material.name}' on "
                                  f"object '{obj.name}' (its bake returned {sorted(result)})")
        if normal:
            clamped = _clamped_share(image)
            if clamped > 0.001 and warnings is not None:
                warnings.append(f"material '{material.name}': {100.0 * clamped:.1f}% of the texels of its Normal "
                                f"on object '{obj.name}' are at Blender's normal bake's limit (about 45 degrees "
                                "from the smooth normal): the bump is baked flatter than Cycles renders it (only "
                                "a Bump node of unlinked Strength and Distance feeding the Normal straight, over "
                                "a smooth normal or an image normal map, is evaluated past that limit: by its "
                                "height)")
    except BaseException:
        bpy.data.images.remove(image)
        raise
    finally:
        if proxy is not None:
            bpy.data.objects.remove(proxy)
        for made in made_materials:
            bpy.data.materials.remove(made)
        if spare_image is not None:
            bpy.data.images.remove(spare_image)
        state.restore()
    return image


def _reads_object_random(tree: Any, seen: Optional[set] = None) -> bool:
    """Whether a node tree (or a group in it) reads an Object Info node's Random, which Cycles
    hashes from the object's name: the evaluation's copy of the object has a name of its own."""
    seen = set() if seen is None else seen
    if tree is None or tree.as_pointer() in seen:
        return False
    seen.add(tree.as_pointer())
    for node in tree.nodes:
        if node.type == 'OBJECT_INFO' and node.outputs["Random"].is_linked:
            return True
        if node.type == 'GROUP' and _reads_object_random(node.node_tree, seen):
            return True
    return False


def _owner(obj: Any, sockets: List[Any]) -> str:
    """Whose images an object's material reads: its mesh's, shared by every object of that mesh
    data block, when the mesh alone decides the evaluated inputs (no modifiers, and inputs that
    read only the mesh: reads_only_mesh); else the object's own."""
    if not obj.modifiers and all(reads_only_mesh(s) for s in sockets):
        return f"mesh {obj.data.name_full}"
    return f"object {obj.name_full}"


def _evaluated_size(socket: Any, size: int) -> int:
    """The evaluated image's width and height for `socket` at Texture Bake Size `size`."""
    return min(HEIGHT_SIZE_FACTOR * size, MAX_SIZE) if socket.node.type == 'BUMP' else size


def _input_name(socket: Any) -> str:
    """How the warnings name an evaluated input: a Bump's Height by its node."""
    return f"the Height of Bump node '{socket.node.name}'" if socket.node.type == 'BUMP' else repr(socket.name)


def evaluate_objects(objects: List[Any], shader_of: Any, blender4: bool, size: int,
                     warnings: List[str]) -> List[Any]:
    """Bakes the evaluable inputs (textures.evaluable_inputs) of the objects' materials into
    images registered in textures.EVALUATED, per evaluation (textures.OWNERS: per material and
    object or mesh, _owner); returns the images (for removal). EvaluationError if a bake fails
    (the images made so far are removed first)."""
    images: List[Any] = []
    # Per material: its evaluated inputs, the UV maps and the objects each evaluation was made for.
    made: Dict[str, Tuple[Any, List[Any], Dict[str, Tuple[str, List[str]]]]] = {}
    try:
        for obj in objects:
            original = obj.original if hasattr(obj, "original") else obj
            for material in dict.fromkeys(slot.material for slot in original.material_slots):
                if material is None:
                    continue
                node = shader_of(material)
                if node is None:
                    continue
                sockets = textures.evaluable_inputs(node, blender4)
                if not sockets:
                    continue
                mesh = original.data
                if getattr(mesh, "uv_layers", None) is None or len(mesh.uv_layers) == 0:
                    warnings.append(f"material '{material.name}': {', '.join(repr(s.name) for s in sockets)} driven "
                                    f"by node trees could not be evaluated by Blender on object '{original.name}' (it "
                                    "has no UV map): their own values are used there")
                    continue
                owner = _owner(original, sockets)
                evaluation = (material.name_full, owner)
                textures.OWNERS[(material.name_full, original.name_full)] = evaluation
                if material.name_full not in made and _reads_object_random(material.node_tree):
                    warnings.append(f"material '{material.name}': an Object Info node's Random is evaluated on a "
                                    "copy of each object, whose random number is not the object's (Cycles hashes "
                                    "it from the name)")
                entry = made.setdefault(material.name_full, (material, sockets, {}))
                if owner in entry[2]:
                    entry[2][owner][1].append(original.name)
                    continue
                uv_map = mesh.uv_layers.active.name
                for socket in sockets:
                    image = _bake_socket(original, material, socket, _evaluated_size(socket, size), warnings)
                    images.append(image)
                    textures.EVALUATED[textures.evaluated_key(evaluation, socket)] = (textures.EvaluatedImage(image),
                                                                                    uv_map)
                entry[2][owner] = (uv_map, [original.name])
    except BaseException:
        for image in images:
            bpy.data.images.remove(image)
        raise
    for material, sockets, evaluations in made.values():
        maps = sorted({uv for uv, _ in evaluations.values()})
        users = sum(len(names) for _, names in evaluations.values())
        if len(evaluations) > 1:
            each = (f" {len(evaluations)} times (each object's own images"
                    f"{'' if len(evaluations) == users else ', shared by the objects of one mesh'})")
        else:
            each = f" once for its {users} objects (one mesh)" if users > 1 else ""
        uv_maps = f"UV map{'s' if len(maps) > 1 else ''} {', '.join(repr(m) for m in maps)}"
        normal = any(s.name == "Normal" for s in sockets)
        height = any(s.node.type == 'BUMP' for s in sockets)
        sizes = " and ".join(f"{n} x {n}" for n in sorted({_evaluated_size(s, size) for s in sockets}))
        warnings.append(f"material '{material.name}': {', '.join(_input_name(s) for s in sockets)} driven by node "
                        f"trees, evaluated by Blender into {sizes} images on {uv_maps}{each} (detail finer "
                        "than that is lost; set Texture Bake Size"
                        + (f"; a Bump's height at {HEIGHT_SIZE_FACTOR} x that" if height else "") + ")"
                        + ("; the Normal as a tangent-space normal map" if normal else "")
                        + (BUMP_FIGURES if height else ""))
    return images
