"""Material inputs driven by node trees other than an Image Texture (a procedural texture, a
Mapping node, a Mix...), evaluated by Blender itself: Cycles bakes the input's value as emission
into a float image on the object's active UV map (Object.bake, type EMIT, 1 sample), which the
add-on then passes as an image texture (textures.py). The material is changed only for the bake
and restored (its links, nodes, the scene's render settings, the selection), and the image is
removed once its pixels are read. The resolution is the user's (scene.dwivedi_bake.texture_bake_size)
and the warning states it; texture detail finer than it is lost.
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
    """A float image of `socket`'s value over the object's active UV map."""
    tree = material.node_tree
    output = _active_output(tree)
    image = bpy.data.images.new(f"dwivedi {material.name} {socket.name}", size, size, alpha=False, float_buffer=True)
    image.colorspace_settings.name = 'Non-Color'
    emission = tree.nodes.new("ShaderNodeEmission")
    target = tree.nodes.new("ShaderNodeTexImage")
    target.image = image
    surface = output.inputs["Surface"]
    previous = [link.from_socket for link in surface.links]
    active = tree.nodes.active
    scene = bpy.context.scene
    saved = (scene.render.engine, scene.cycles.samples, scene.render.bake.margin, scene.render.bake.use_clear,
             scene.render.bake.target)
    view_layer = bpy.context.view_layer
    selected = [o for o in view_layer.objects if o.select_get()]
    was_active = view_layer.objects.active
    try:
        tree.links.new(socket.links[0].from_socket, emission.inputs["Color"])
        emission.inputs["Strength"].default_value = 1.0
        tree.links.new(emission.outputs["Emission"], surface)
        tree.nodes.active = target
        scene.render.engine = 'CYCLES'
        scene.cycles.samples = 1
        scene.render.bake.margin = 4
        scene.render.bake.use_clear = True
        scene.render.bake.target = 'IMAGE_TEXTURES'
        for o in selected:
            o.select_set(False)
        obj.select_set(True)
        view_layer.objects.active = obj
        bpy.ops.object.bake(type='EMIT')
    except BaseException:
        bpy.data.images.remove(image)
        raise
    finally:
        for link in list(surface.links):
            tree.links.remove(link)
        for source in previous:
            tree.links.new(source, surface)
        tree.nodes.remove(emission)
        tree.nodes.remove(target)
        tree.nodes.active = active
        (scene.render.engine, scene.cycles.samples, scene.render.bake.margin, scene.render.bake.use_clear,
         scene.render.bake.target) = saved
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
        if len(original.material_slots) != 1 or getattr(mesh, "uv_layers", None) is None or len(mesh.uv_layers) == 0:
            warnings.append(f"material '{material.name}': {', '.join(repr(s.name) for s in sockets)} driven by node "
                            f"trees could not be evaluated by Blender (object '{original.name}' needs one material "
                            "and a UV map): their own values are used")
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
                        "finer than that is lost; set Texture Bake Size)")
    return images
