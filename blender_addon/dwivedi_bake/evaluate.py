"""Material inputs driven by node trees other than an Image Texture (a procedural texture, a
Mapping node, a Mix...), evaluated by Blender itself: Cycles bakes the input's value as emission
into a float image on the object's active UV map (Object.bake, type EMIT, 1 sample), which the
add-on then passes as an image texture (textures.py). A Normal input fed by anything but an
Image Texture through a Normal Map or Bump node is baked as Blender's normal bake does (type
NORMAL, tangent space of the active UV map: the shading normal as 0.5 + 0.5 (x, y, z) in its
MikkTSpace frame) and bound as a tangent-space normal map of that UV map, which maps it back.

An object with several materials is baked per material: the material being evaluated gets the
target image, every other material of the object a throwaway image for its own faces (Cycles
writes each face into its own material's active image), so each material's image holds its
faces only. The materials are changed only for the bake and restored (their links, nodes, the
scene's render settings, the selection), and the images are removed once their pixels are read.
The resolution is the user's (scene.dwivedi_bake.texture_bake_size) and the warning states it;
texture detail finer than it is lost.
"""
from __future__ import annotations

from typing import Any, List

import bpy

from . import textures


def _active_output(tree: Any) -> Any:
    for node in tree.nodes:
        if node.type == 'OUTPUT_MATERIAL' and node.is_active_output and node.target in {'ALL', 'CYCLES'}:
            return node
    return next((node for node in tree.nodes if node.type == 'OUTPUT_MATERIAL'), None)


def _bake_socket(obj: Any, material: Any, socket: Any, size: int) -> Any:
    """A float image of `socket`'s value (the Normal input: the tangent-space normal map of the
    shading normal) over the object's active UV map, on the faces of `material`."""
    normal = socket.name == "Normal"
    tree = material.node_tree
    output = _active_output(tree)
    image = bpy.data.images.new(f"dwivedi {material.name} {socket.name}", size, size, alpha=False, float_buffer=True)
    image.colorspace_settings.name = 'Non-Color'
    emission = None if normal else tree.nodes.new("ShaderNodeEmission")
    target = tree.nodes.new("ShaderNodeTexImage")
    target.image = image
    surface = output.inputs["Surface"]
    previous = [link.from_socket for link in surface.links]
    active = tree.nodes.active
    # The object's other materials write their faces into a throwaway image.
    others = []
    spare = None
    for slot in obj.material_slots:
        other = slot.material
        if other is None or other == material or other.node_tree is None or any(o[0] == other for o in others):
            continue
        if spare is None:
            spare = bpy.data.images.new("dwivedi spare", 8, 8, alpha=False, float_buffer=True)
        node = other.node_tree.nodes.new("ShaderNodeTexImage")
        node.image = spare
        others.append((other, node, other.node_tree.nodes.active))
        other.node_tree.nodes.active = node
    scene = bpy.context.scene
    bake = scene.render.bake
    saved = (scene.render.engine, scene.cycles.samples, bake.margin, bake.use_clear, bake.target, bake.normal_space,
             bake.normal_r, bake.normal_g, bake.normal_b)
    view_layer = bpy.context.view_layer
    selected = [o for o in view_layer.objects if o.select_get()]
    was_active = view_layer.objects.active
    try:
        if not normal:
            tree.links.new(socket.links[0].from_socket, emission.inputs["Color"])
            emission.inputs["Strength"].default_value = 1.0
            tree.links.new(emission.outputs["Emission"], surface)
        tree.nodes.active = target
        scene.render.engine = 'CYCLES'
        scene.cycles.samples = 1
        bake.margin = 4
        bake.use_clear = True
        bake.target = 'IMAGE_TEXTURES'
        bake.normal_space, bake.normal_r, bake.normal_g, bake.normal_b = 'TANGENT', 'POS_X', 'POS_Y', 'POS_Z'
        for o in selected:
            o.select_set(False)
        obj.select_set(True)
        view_layer.objects.active = obj
        bpy.ops.object.bake(type='NORMAL' if normal else 'EMIT')
    except BaseException:
        bpy.data.images.remove(image)
        raise
    finally:
        if not normal:
            for link in list(surface.links):
                tree.links.remove(link)
            for source in previous:
                tree.links.new(source, surface)
            tree.nodes.remove(emission)
        tree.nodes.remove(target)
        tree.nodes.active = active
        for other, node, other_active in others:
            other.node_tree.nodes.remove(node)
            other.node_tree.nodes.active = other_active
        if spare is not None:
            bpy.data.images.remove(spare)
        (scene.render.engine, scene.cycles.samples, bake.margin, bake.use_clear, bake.target, bake.normal_space,
         bake.normal_r, bake.normal_g, bake.normal_b) = saved
        obj.select_set(False)
        for o in selected:
            o.select_set(True)
        view_layer.objects.active = was_active
    return image


def evaluate_object(obj: Any, materials: List[Any], shader_of: Any, blender4: bool, size: int,
                    done: set, warnings: List[str]) -> List[Any]:
    """Bakes the evaluable inputs (textures.evaluable_inputs) of the object's materials not yet
    evaluated into images registered in textures.EVALUATED; returns the images (for removal)."""
    images = []
    original = obj.original if hasattr(obj, "original") else obj
    for material in materials:
        if material is None or material.name_full in done:
            continue
        node = shader_of(material)
        if node is None:
            continue
        sockets = textures.evaluable_inputs(node, blender4)
        if not sockets:
            continue
        done.add(material.name_full)
        mesh = original.data
        if getattr(mesh, "uv_layers", None) is None or len(mesh.uv_layers) == 0:
            warnings.append(f"material '{material.name}': {', '.join(repr(s.name) for s in sockets)} driven by node "
                            f"trees could not be evaluated by Blender (object '{original.name}' has no UV map): "
                            "their own values are used")
            continue
        users = [o for o in bpy.data.objects if any(slot.material == material for slot in o.material_slots)]
        if len(users) > 1:
            warnings.append(f"material '{material.name}' is used by {len(users)} objects: its node-tree inputs are "
                            f"evaluated on '{original.name}''s UV map and used for all of them")
        uv_map = mesh.uv_layers.active.name
        for socket in sockets:
            image = _bake_socket(original, material, socket, size)
            images.append(image)
            textures.EVALUATED[textures.evaluated_key(material.name_full, socket)] = (textures.EvaluatedImage(image), uv_map)
        warnings.append(f"material '{material.name}': {', '.join(repr(s.name) for s in sockets)} driven by node "
                        f"trees, evaluated by Blender into {size} x {size} images on UV map '{uv_map}' (detail "
                        "finer than that is lost; set Texture Bake Size)"
                        + ("; the Normal as a tangent-space normal map" if any(s.name == "Normal" for s in sockets)
                           else ""))
    return images
