"""Blender scene -> dwivedi.Scene: the evaluated depsgraph's meshes, materials, lights, world and
camera in Blender's units, which are dwivedi's (capi/dwivedi.h).

Everything here reads Blender data and calls the shim; nothing changes the .blend (a world that is
not an Environment Texture is rendered by Cycles in a scene of its own, made and removed here).
Problems that make a bake meaningless raise ExportError (the operator reports it); things dwivedi
does not model (node trees on material inputs other than Image Textures are evaluated by Blender
into images, camera shift...) are collected as warnings and the bake goes on with the nearest
supported meaning. Image textures go to the library as they are (textures.py).
"""
from __future__ import annotations

import array
import math
from typing import Any, Dict, List, Optional, Tuple

import bpy

from . import evaluate, gather, normals, textures


class ExportError(Exception):
    """The scene cannot be baked as asked (no camera, no UVs...); the message says why."""


class Exported:
    """The outcome of an export: the committed dwivedi scene, the bake's size, the UV mesh id."""

    def __init__(self) -> None:
        self.scene: Any = None
        self.width = 0
        self.height = 0
        self.uv_mesh = 0
        self.warnings: List[str] = []
        self.mesh_count = 0
        self.triangle_count = 0
        self.light_count = 0
        # False where the scene belongs to an ExportCache (which closes it): the bake that uses
        # it must not close it, since the next bake may use it again.
        self.owned = True
        self.reused = False  # the whole scene was the cache's, nothing exported again
        self.images_read = 0  # textures and environment images the export read


# ---------------------------------------------------------------------------------------------
# What the last bake exported, kept for the next one
# ---------------------------------------------------------------------------------------------

class _Meshes:
    """One object's mesh arrays (_mesh_arrays), read at a generation of an ExportCache."""

    def __init__(self, generation: int, want_uvs: bool, maps: Any, uv_names: List[str], arrays: Any) -> None:
        self.generation = generation
        self.want_uvs = want_uvs
        self.maps = maps
        self.uv_names = uv_names
        self.arrays = arrays  # None: the mesh has no faces


class ExportCache:
    """What the last bake exported, so that the next bake re-exports only what changed.

    Blender says what changed through its depsgraph: the add-on's depsgraph_update_post handler
    passes every update to note(), which counts generations. The cache keeps
    - each object's mesh arrays, read at some generation: reused while no update since has
      touched the object's geometry (an Object update with is_updated_geometry: a mesh edit, a
      modifier, a driver) nor any data other than objects, materials, shader node trees,
      lights, cameras, worlds, collections, scenes and images (a mesh, curve or geometry node
      tree, which other objects' modifiers may read); transforms are read again every bake;
    - the whole committed scene of the last bake: reused while no update at all has come since
      (a material, light, world, camera, transform, render setting...) and the bake's export
      settings are the same, and only when that export read no image (a texture, an environment
      or rendered world, inputs Blender evaluated into images): Blender's depsgraph does not say
      when an image's pixels change.
    A file load, undo or redo forgets everything (clear()). Instances (particles, geometry nodes,
    collection instances) are read again every bake."""

    def __init__(self) -> None:
        self.generation = 0
        self._geometry = 0  # the generation of the last update of data any object may read
        self._objects: Dict[str, int] = {}  # object -> the generation of its last geometry update
        self._meshes: Dict[str, _Meshes] = {}
        self._scene: Optional[Tuple[Any, int, Exported]] = None  # (key, generation, export)

    # Types whose updates change no other object's evaluated mesh (their own effect is in the
    # whole scene's generation; Image: see the class comment). An object's own data (a mesh, a
    # curve) is among them: Blender updates the geometry of every object that uses it or reads
    # it (linked duplicates, another object's modifier), which note() takes per object.
    _NOT_GEOMETRY = ("Material", "Light", "Camera", "World", "Scene", "Collection", "Image", "Mesh", "Curve",
                     "MetaBall", "Lattice")

    def note(self, depsgraph: Any) -> None:
        """Takes in a depsgraph's updates (the add-on's depsgraph_update_post handler)."""
        for update in depsgraph.updates:
            changed = update.id
            if isinstance(changed, bpy.types.Image):
                continue
            self.generation += 1
            if isinstance(changed, bpy.types.Object):
                if update.is_updated_geometry:
                    self._objects[changed.original.name_full] = self.generation
            elif not (any(isinstance(changed, getattr(bpy.types, name)) for name in self._NOT_GEOMETRY)
                      or isinstance(changed, bpy.types.NodeTree) and changed.bl_idname == "ShaderNodeTree"):
                self._geometry = self.generation

    def clear(self) -> None:
        """Forgets everything (a file load, undo, redo, the add-on disabled)."""
        self._meshes.clear()
        self._objects.clear()
        if self._scene is not None:
            self._scene[2].scene.close()
            self._scene = None

    def meshes(self, name: str) -> Optional[_Meshes]:
        """The object's arrays if nothing has changed its geometry since they were read."""
        entry = self._meshes.get(name)
        if entry is None or max(self._geometry, self._objects.get(name, 0)) > entry.generation:
            return None
        return entry

    def keep_meshes(self, name: str, entry: _Meshes) -> None:
        self._meshes[name] = entry

    def scene(self, key: Any) -> Optional[Exported]:
        """The last bake's export, as an Exported of its own, if it may be baked again."""
        if self._scene is None or self._scene[0] != key or self._scene[1] != self.generation:
            return None
        kept = self._scene[2]
        out = Exported()
        out.__dict__.update(kept.__dict__)
        out.warnings = list(kept.warnings)
        out.owned, out.reused = False, True
        return out

    def own_updates(self, work: Any) -> Any:
        """Runs work() (writing a bake's result: a render setting set and put back for the PNG,
        images loaded) and returns what it returns; the depsgraph updates it makes are the
        add-on's own and leave the kept scene valid, if nothing else changed before them.
        work() runs on Blender's main thread, so no edit of the artist's comes in between."""
        bpy.context.evaluated_depsgraph_get()  # the updates before: the artist's, counted
        before = self.generation
        try:
            return work()
        finally:
            bpy.context.evaluated_depsgraph_get()
            if self._scene is not None and self._scene[1] == before:
                self._scene = (self._scene[0], self.generation, self._scene[2])

    def keep_scene(self, key: Any, generation: int, exported: Exported) -> None:
        """Keeps `exported` (which the cache now owns: its scene is closed by the cache)."""
        if self._scene is not None and self._scene[2].scene is not exported.scene:
            self._scene[2].scene.close()
        exported.owned = False
        kept = Exported()
        kept.__dict__.update(exported.__dict__)
        kept.warnings = list(exported.warnings)
        self._scene = (key, generation, kept)


CACHE = ExportCache()


# ---------------------------------------------------------------------------------------------
# Materials
# ---------------------------------------------------------------------------------------------

def _input(node: Any, names: Tuple[str, ...]) -> Any:
    for name in names:
        socket = node.inputs.get(name)
        if socket is not None:
            return socket
    return None


def _value(node: Any, names: Tuple[str, ...], default: Any, material_name: str, warnings: List[str]) -> Any:
    """The unlinked value of the first input of `names` the node has (Blender 3.x and 4.x name
    them differently). A linked input's own value is the constant its texture binding starts from
    (textures.py); linked inputs that no binding covers are warned about by material_from_blender."""
    socket = _input(node, names)
    if socket is None:
        return default
    value = socket.default_value
    try:
        return tuple(value)
    except TypeError:
        return float(value)


SHADER_TYPES = ('BSDF_PRINCIPLED', 'SUBSURFACE_SCATTERING')


def _surface_shader(material: Any) -> Any:
    """The Principled BSDF or Subsurface Scattering node that feeds the material's active output
    (Cycles or All), else the first such node in the tree, else None."""
    if not material.use_nodes or material.node_tree is None:
        return None
    nodes = material.node_tree.nodes
    output = None
    for node in nodes:
        if node.type == 'OUTPUT_MATERIAL' and node.is_active_output and node.target in {'ALL', 'CYCLES'}:
            output = node
            break
    if output is not None:
        surface = output.inputs.get("Surface")
        if surface is not None and surface.is_linked:
            linked = surface.links[0].from_node
            if linked.type in SHADER_TYPES:
                return linked
    for node in nodes:
        if node.type in SHADER_TYPES:
            return node
    return None


def subsurface_model(version: Tuple[int, ...], method: str) -> Tuple[str, Optional[str]]:
    """The dwivedi subsurface model (dwivedi.SUBSURFACE_MODELS) of a Blender version's subsurface
    method (the Principled BSDF's subsurface_method or the Subsurface Scattering node's falloff),
    and a note where it is not modelled exactly (Christensen-Burley, an unknown method).

    The identifiers keep their stored values across releases while their meaning moves: 3.x
    RANDOM_WALK_FIXED_RADIUS / RANDOM_WALK are 4.0's RANDOM_WALK / RANDOM_WALK_SKIN; 5.2 adds a
    new RANDOM_WALK and keeps the 4.x one as RANDOM_WALK_LEGACY (docs/blender-compatibility.md)."""
    version = tuple(version)
    if version < (4, 0, 0):
        table = {'RANDOM_WALK_FIXED_RADIUS': "fixed_radius", 'RANDOM_WALK': "blender3_random_walk"}
    elif version < (5, 2, 0):
        table = {'RANDOM_WALK': "blender4_random_walk", 'RANDOM_WALK_SKIN': "blender4_skin"}
    else:
        table = {'RANDOM_WALK': "blender52_random_walk", 'RANDOM_WALK_LEGACY': "blender52_legacy",
                 'RANDOM_WALK_SKIN': "blender52_skin"}
    if method in table:
        return table[method], None
    if method == 'BURLEY':
        return "fixed_radius", ("subsurface method Christensen-Burley is not modelled: baked as 3.x Random Walk "
                                "(Fixed Radius), whose radius scaling it shares")
    return "fixed_radius", f"subsurface method {method} is not known to dwivedi: baked as Random Walk (Fixed Radius)"


def _nonzero(node: Any, names: Tuple[str, ...]) -> bool:
    socket = _input(node, names)
    if socket is None:
        return False
    if socket.is_linked:
        return True
    value = socket.default_value
    try:
        return any(float(v) != 0.0 for v in tuple(value)[:3])  # a colour's alpha is not its amount
    except TypeError:
        return float(value) != 0.0


# Principled inputs dwivedi does not model, by the name of the feature, per Blender generation.
_UNMODELLED_3X = (("Metallic", ("Metallic",)), ("Transmission", ("Transmission",)), ("Sheen", ("Sheen",)),
                  ("Clearcoat", ("Clearcoat",)), ("Anisotropic", ("Anisotropic",)))
_UNMODELLED_4X = (("Metallic", ("Metallic",)), ("Transmission", ("Transmission Weight",)),
                  ("Coat", ("Coat Weight",)), ("Sheen", ("Sheen Weight",)), ("Anisotropic", ("Anisotropic",)),
                  ("Thin Film", ("Thin Film Thickness",)), ("Diffuse Roughness", ("Diffuse Roughness",)))


def material_from_blender(material: Any, dwivedi: Any, warnings: List[str],
                          version: Optional[Tuple[int, ...]] = None, evaluation: Optional[Any] = None) -> Any:
    """A dwivedi.Material from a Blender material (None: Blender's default grey surface), as the
    Cycles of Blender `version` (default bpy.app.version) shades it: the subsurface model of the
    node's method (subsurface_model), the Principled specular layer (3.x v1 or 4.x+ v2) and exit.

    Blender 4.x+: Subsurface Weight, Subsurface Scale, Subsurface Radius, the base colour is the
    subsurface colour. Blender 3.x: Subsurface (a factor that also scales the radius), Subsurface
    Color mixed with Base Color by it, Subsurface Radius (see dwv_material_t). `evaluation`: whose
    images of the inputs Blender evaluated it reads (textures.evaluation_of; default the
    material's own, evaluated once for every object)."""
    if version is None:
        version = tuple(bpy.app.version) if bpy is not None else (3, 4, 0)
    version = tuple(version)
    if material is None:
        return dwivedi.Material.diffuse((0.8, 0.8, 0.8))
    name = material.name
    node = _surface_shader(material)
    if node is None:
        warnings.append(f"material '{name}' has no Principled BSDF or Subsurface Scattering node: baked as "
                        "diffuse in its viewport colour")
        return dwivedi.Material.diffuse(tuple(material.diffuse_color)[:3])
    blender4 = version >= (4, 0, 0)
    if node.type == 'SUBSURFACE_SCATTERING':
        # Color is the walk's albedo, Radius x Scale its radius; exit Lambertian (no retro-reflection,
        # no Fresnel-weighted exit). 4.x+: the entry refracts with the node's IOR and alpha =
        # Roughness itself (svm_closure.h: bssrdf->alpha = saturate(Roughness)), hence roughness =
        # sqrt(Roughness) for dwivedi's alpha = roughness^2.
        color = _value(node, ("Color",), (0.8, 0.8, 0.8, 1.0), name, warnings)[:3]
        ior = min(max(_value(node, ("IOR",), 1.4, name, warnings), 1.0), 4.0)
        model, note = subsurface_model(version, getattr(node, "falloff", 'RANDOM_WALK_FIXED_RADIUS'))
        if note:
            warnings.append(f"material '{name}': {note}")
        node_roughness = min(max(_value(node, ("Roughness",), 1.0, name, warnings), 0.0), 1.0) if blender4 else 1.0
        return dwivedi.Material(base_color=color, subsurface_weight=1.0, subsurface_color=color,
                                subsurface_min_footprint=footprint_rule(version),
                                subsurface_radius=_value(node, ("Radius",), (1.0, 0.2, 0.1), name, warnings)[:3],
                                subsurface_scale=_value(node, ("Scale",), 0.05, name, warnings),
                                subsurface_anisotropy=max(-0.99, min(0.99, _value(node, ("Anisotropy",), 0.0, name,
                                                                                  warnings))),
                                subsurface_ior=ior, ior=ior, roughness=math.sqrt(node_roughness),
                                subsurface_model=model)
    method = getattr(node, "subsurface_method", 'RANDOM_WALK_FIXED_RADIUS')
    base = _value(node, ("Base Color",), (0.8, 0.8, 0.8, 1.0), name, warnings)[:3]
    base = tuple(min(max(float(c), 0.0), 1.0) for c in base)
    radius = _value(node, ("Subsurface Radius",), (1.0, 0.2, 0.1), name, warnings)[:3]
    anisotropy = _value(node, ("Subsurface Anisotropy",), 0.0, name, warnings)
    sss_ior = min(max(_value(node, ("Subsurface IOR",), 1.4, name, warnings), 1.0), 4.0)
    roughness = min(max(_value(node, ("Roughness",), 0.5, name, warnings), 0.0), 1.0)
    distribution = getattr(node, "distribution", 'GGX')
    unmodelled = [label for label, names in (_UNMODELLED_4X if blender4 else _UNMODELLED_3X) if _nonzero(node, names)]
    if _input(node, ("Emission Strength",)) is not None and _nonzero(node, ("Emission Strength",)) and \
            _nonzero(node, ("Emission Color", "Emission")):
        unmodelled.append("Emission")
    alpha_socket = _input(node, ("Alpha",))
    if alpha_socket is not None and (alpha_socket.is_linked or float(alpha_socket.default_value) < 1.0):
        unmodelled.append("Alpha")
    thin_wall = _input(node, ("Thin Wall",))
    if thin_wall is not None and (thin_wall.is_linked or bool(thin_wall.default_value)):
        unmodelled.append("Thin Wall (baked as a solid)")
    if unmodelled:
        warnings.append(f"material '{name}': {', '.join(unmodelled)} not modelled by dwivedi (ignored)")
    if blender4:
        weight = min(max(_value(node, ("Subsurface Weight",), 0.0, name, warnings), 0.0), 1.0)
        scale = _value(node, ("Subsurface Scale",), 0.05, name, warnings)
        ior = min(max(_value(node, ("IOR",), 1.5, name, warnings), 1.0), 4.0)
        level = max(_value(node, ("Specular IOR Level",), 0.5, name, warnings), 0.0)
        tint = tuple(min(max(float(c), 0.0), 1.0) for c in _value(node, ("Specular Tint",), (1.0, 1.0, 1.0, 1.0),
                                                                  name, warnings)[:3])
        out = dwivedi.Material(base_color=base, subsurface_weight=weight, subsurface_color=base,
                               subsurface_radius=radius, subsurface_scale=scale, subsurface_anisotropy=anisotropy,
                               subsurface_ior=sss_ior, kind="subsurface" if weight > 0.0 else "diffuse",
                               roughness=roughness, ior=ior, specular_model="principled_v2", specular=level,
                               specular_tint=tint, specular_multiscatter=distribution == 'MULTI_GGX')
    else:  # Blender 3.x
        factor = _value(node, ("Subsurface",), 0.0, name, warnings)
        # Cycles 3.x's Principled (v1) adds to the walk a retro-reflection lobe (by Roughness)
        # and weights the exit by 1 - (1 - cos)^5 / 2: from_blender_3x selects that exit. Its
        # specular (GGX over everything, not layered) is DWV_SPECULAR_PRINCIPLED_V1.
        color = _value(node, ("Subsurface Color",), (0.8, 0.8, 0.8, 1.0), name, warnings)[:3]
        out = dwivedi.Material.from_blender_3x(base, factor, color, radius, anisotropy, sss_ior, roughness)
        if factor <= 0.0:
            out.kind = "diffuse"
        specular = max(_value(node, ("Specular",), 0.5, name, warnings), 0.0)
        if specular >= 12.5:
            warnings.append(f"material '{name}': Specular {specular:g} is clamped to 12.4 (Cycles' IOR for it is "
                            "infinite from 12.5)")
            specular = 12.4
        out.specular_model = "principled_v1"
        out.specular = specular
        tint = min(max(_value(node, ("Specular Tint",), 0.0, name, warnings), 0.0), 1.0)
        out.specular_tint = (tint, tint, tint)
        out.ior = min(max(_value(node, ("IOR",), 1.45, name, warnings), 1.0), 4.0)
        if distribution == 'MULTI_GGX' and roughness > 0.075:
            warnings.append(f"material '{name}': Multiscatter GGX (3.x's stochastic microsurface walk) is not "
                            "modelled: its specular is baked as GGX")
    weight_socket = _input(node, ("Subsurface Weight",))
    if blender4 and out.kind == "diffuse" and weight_socket is not None and textures.passes(
            weight_socket, evaluation or (material.name_full, None)):
        out.kind = "subsurface"  # a textured weight may be above 0 anywhere
    if out.kind == "subsurface":
        model, note = subsurface_model(version, method)
        out.subsurface_model = model
        if note:
            warnings.append(f"material '{name}': {note}")
    out.subsurface_anisotropy = max(-0.99, min(0.99, out.subsurface_anisotropy))  # the library clamps per model
    out.subsurface_min_footprint = footprint_rule(version)
    return out


def texture_uses(material: Any, converted: Any, warnings: List[str],
                 version: Optional[Tuple[int, ...]] = None, evaluation: Optional[Any] = None) -> List[Any]:
    """The image textures on the material's inputs (textures.Use, in binding order; the inputs
    Blender evaluated: `evaluation`'s images, as material_from_blender), adjusting `converted`
    where a texture changes what its constants mean; warns about linked inputs that are not
    passed (their own values are used)."""
    if material is None:
        return []
    if version is None:
        version = tuple(bpy.app.version) if bpy is not None else (3, 4, 0)
    node = _surface_shader(material)
    if node is None:
        return []
    blender4 = tuple(version) >= (4, 0, 0)
    evaluation = evaluation or (material.name_full, None)
    uses = textures.material_uses(node, blender4, converted, evaluation)
    unpassed = textures.linked_unpassed(node, blender4, evaluation)
    if unpassed:
        warnings.append(f"material '{material.name}': {', '.join(repr(n) for n in unpassed)} linked to nodes other "
                        "than an Image Texture (with a UV Map, a Normal Map or a Bump node): not evaluated, the "
                        "inputs' own values are used")
    return uses


def footprint_rule(version: Tuple[int, ...]) -> float:
    """Cycles 4.0-4.3's bssrdf_setup turns a channel whose radius is below a quarter of the ray's
    footprint (a camera pixel's, a UV bake texel's) into diffuse; Cycles commit 58f78fb1e
    ("Remove camera size optimization from SSS shader", 2025-01-21) removed it before v4.4.0:
    0.25 there, else 0."""
    return 0.25 if (4, 0, 0) <= tuple(version) < (4, 4, 0) else 0.0


# ---------------------------------------------------------------------------------------------
# Geometry
# ---------------------------------------------------------------------------------------------

def _rows(matrix: Any) -> List[float]:
    return [float(matrix[r][c]) for r in range(3) for c in range(4)]


def _mesh_arrays(mesh: Any, want_uvs: bool, texture_maps: Optional[List[Optional[str]]] = None) -> Dict[str, Any]:
    """Positions, triangle indices, per-corner UVs, normals and per-triangle material indices of
    an evaluated mesh, in float32 / uint32 buffers: foreach_get fills them and gather.py picks
    the corners' values, without a Python loop per element. texture_maps (a list, maybe empty, of
    the UV maps normal maps read; None: layer 0) asks for all UV maps by name and those maps'
    tangents, for textured materials.

    Smooth and flat faces both come out right: all-flat meshes share vertices without normals
    (flat shading); meshes whose every corner normal is its vertex's normal (all faces smooth, no
    sharp edges or custom normals: _normals_domain 'POINT') share vertices with those normals;
    otherwise every triangle corner gets its own vertex with Blender's corner (split) normal,
    which is the face normal on flat faces and honours sharp edges."""
    mesh.calc_loop_triangles()
    tris = mesh.loop_triangles
    t = len(tris)
    loops = array.array("i", bytes(12 * t))
    tris.foreach_get("loops", loops)
    material_index = array.array("i", bytes(4 * t))
    tris.foreach_get("material_index", material_index)
    out: Dict[str, Any] = {"triangles": t, "material_index": material_index}

    if want_uvs and mesh.uv_layers.active is not None:
        out["uvs"] = gather.corner_uvs(mesh, mesh.uv_layers.active, loops)
    else:
        out["uvs"] = None
    out["layers"] = None
    if texture_maps is not None and len(mesh.uv_layers) > 0:
        # Textures read UV maps by name, layer 0 without one: the active render map (a UV bake's
        # layer 0 stays the active map it lays out).
        render = next((layer for layer in mesh.uv_layers if layer.active_render), mesh.uv_layers.active)
        first = mesh.uv_layers.active if want_uvs else render
        out["layers"] = textures.uv_layers(mesh, loops, first, texture_maps)
        out["uvs"] = out["layers"]["uvs"]

    vertex_co = array.array("f", bytes(12 * len(mesh.vertices)))
    mesh.vertices.foreach_get("co", vertex_co)
    domain = _normals_domain(mesh)
    if domain != 'CORNER':
        indices = array.array("I", bytes(12 * t))
        tris.foreach_get("vertices", indices)
        out.update(positions=vertex_co, indices=indices,
                   normals=_vertex_normals(mesh) if domain == 'POINT' else None)
        return out

    if hasattr(mesh, "calc_normals_split"):  # Blender < 4.1 computes corner normals on demand
        mesh.calc_normals_split()
    corner_normals = array.array("f", bytes(36 * t))
    tris.foreach_get("split_normals", corner_normals)
    corner_vertices = array.array("I", bytes(12 * t))
    tris.foreach_get("vertices", corner_vertices)
    # Blender 3.x's vertex normals vary in their last bits from one evaluation to the next (threads
    # add into them in any order): the smooth faces' corners get the same normals summed in a fixed
    # order, so that a scene exports, and bakes, the same bits every time (normals.py).
    normals.settle_corner_normals(mesh, corner_vertices, corner_normals, bpy.app.version)
    out.update(positions=gather.rows(vertex_co, 3, corner_vertices), indices=array.array("I", range(3 * t)),
               normals=corner_normals)
    return out


def _normals_domain(mesh: Any) -> str:
    """Where the mesh's normals live, as Blender 4.1+'s Mesh.normals_domain says: 'FACE' (every
    face flat), 'POINT' (every corner normal is its vertex's normal: all faces smooth, no sharp
    edges, no custom normals) or 'CORNER'. Before 4.1 from the same rules: 3.x / 4.0 Auto Smooth
    or custom normals make corner normals (calc_normals_split), otherwise a smooth face's corner
    takes its vertex's normal and a flat face's its face normal."""
    domain = getattr(mesh, "normals_domain", None)
    if domain is not None:
        return domain
    smooth = array.array("b", bytes(len(mesh.polygons)))
    mesh.polygons.foreach_get("use_smooth", smooth)
    if not any(smooth):
        return 'FACE'
    if getattr(mesh, "use_auto_smooth", False) or mesh.has_custom_normals or not all(smooth):
        return 'CORNER'
    return 'POINT'


def _vertex_normals(mesh: Any) -> Any:
    """The mesh's vertex normals (Mesh.vertex_normals from 4.1 on; before, Blender's vary in their
    last bits from one evaluation to the next, and normals.py sums them in a fixed order)."""
    if tuple(bpy.app.version) < (4, 1, 0):
        return normals.mesh_vertex_normals(mesh)
    out = array.array("f", bytes(12 * len(mesh.vertices)))
    mesh.vertex_normals.foreach_get("vector", out)
    return out


def _subset(arrays: Dict[str, Any], keep: Any) -> Dict[str, Any]:
    """The triangles `keep` of a split-corner or shared-vertex mesh, as a mesh of their own
    (vertices are kept whole: unreferenced ones cost nothing to the library)."""
    def pick(values: Any, group: int) -> Any:
        return gather.rows(values, group, keep)

    uvs = None if arrays["uvs"] is None else pick(arrays["uvs"], 6)
    layers = arrays.get("layers")
    if layers is not None:
        layers = {**layers, "uvs": uvs, "uv_layers": [(name, pick(v, 6)) for name, v in layers["uv_layers"]],
                  "tangents": {name: pick(v, 12) for name, v in layers["tangents"].items()}}
    return {**arrays, "indices": gather.rows(arrays["indices"], 3, keep, "I"), "uvs": uvs, "triangles": len(keep),
            "layers": layers}


def _layer_arguments(arrays: Dict[str, Any]) -> Dict[str, Any]:
    """add_mesh's UV arguments of a textured mesh (its UV maps by name and tangents), else none."""
    layers = arrays.get("layers")
    if layers is None:
        return {}
    return {"uv_name": layers["uv_name"], "uv_layers": layers["uv_layers"], "tangents": layers["tangents"]}


def _shadow_terminator_geometry_offset(obj: Any) -> float:
    """Cycles' per-object "Shadow Terminator > Geometry Offset" (dwv_mesh_t's field of that name):
    Object.cycles.shadow_terminator_geometry_offset in Blender 3.x, a property of Object itself in
    later versions; Cycles' default 0.1 where neither exists."""
    for owner in (obj, getattr(obj, "cycles", None)):
        value = getattr(owner, "shadow_terminator_geometry_offset", None)
        if isinstance(value, float):
            return value
    return 0.1


def _is_geometry(obj: Any) -> bool:
    return obj.type in {'MESH', 'CURVE', 'SURFACE', 'META', 'FONT'}


# ---------------------------------------------------------------------------------------------
# Lights, world, camera
# ---------------------------------------------------------------------------------------------

def _light_emission(obj: Any, warnings: List[str]) -> Tuple[Tuple[float, float, float], float]:
    """The factors a light's node tree puts on its colour and power, as Cycles evaluates them
    (the light's colour x power x its shader's emission): an Emission node into the active Light
    Output with Color and Strength unlinked gives its colour and strength; no tree (or nodes off)
    gives 1; an output with nothing linked gives 0 (Cycles' light then emits nothing); anything
    else is not evaluated (warning: factor 1)."""
    data = obj.data
    tree = getattr(data, "node_tree", None)
    if not getattr(data, "use_nodes", False) or tree is None:
        return (1.0, 1.0, 1.0), 1.0
    output = next((n for n in tree.nodes if n.type == 'OUTPUT_LIGHT' and n.is_active_output), None)
    if output is None:
        output = next((n for n in tree.nodes if n.type == 'OUTPUT_LIGHT'), None)
    surface = output.inputs.get("Surface") if output is not None else None
    if surface is None or not surface.is_linked:
        return (0.0, 0.0, 0.0), 0.0
    node = surface.links[0].from_node
    if node.type == 'EMISSION':
        color_in, strength_in = node.inputs["Color"], node.inputs["Strength"]
        if not color_in.is_linked and not strength_in.is_linked:
            return tuple(color_in.default_value)[:3], float(strength_in.default_value)
    warnings.append(f"light '{obj.name}': its nodes are not a constant Emission (textures are not evaluated): "
                    "its colour and power are used")
    return (1.0, 1.0, 1.0), 1.0


def spot_falloff(version: Tuple[int, ...]) -> str:
    """dwivedi's spot attenuation for a Blender version: 3.x multiplies the smoothstep by the
    cosine to the axis, 4.0's light rewrite dropped it (dwv_light_desc_t)."""
    return "cycles3" if tuple(version) < (4, 0, 0) else "cycles4"


def area_power_scale(version: Tuple[int, ...]) -> float:
    """dwivedi's area light has Cycles 3.x's radiance P / (4 A) (kernel/light/light.h: eval_fac =
    0.25 invarea); Cycles 4.0 onward gives a Lambertian emitter of power P its radiance P / (pi A)
    (kernel/light/area.h: eval_fac = M_1_PI_F invarea): the power is scaled by 4 / pi there."""
    return 4.0 / math.pi if tuple(version) >= (4, 0, 0) else 1.0


def point_shape(data: Any, version: Tuple[int, ...]) -> str:
    """The shape of a point or spot light: Cycles 4.0 onward makes it a sphere unless Soft Falloff
    is on (Blender's default; its sync: is_sphere = !use_soft_falloff), which keeps 3.x's disc
    facing the shaded point."""
    if tuple(version) < (4, 0, 0):
        return "disc"
    return "disc" if getattr(data, "use_soft_falloff", True) else "sphere"


def _light(obj: Any, matrix: Any, dwivedi: Any, warnings: List[str]) -> Any:
    data = obj.data
    node_color, node_strength = _light_emission(obj, warnings)
    color = tuple(c * f for c, f in zip(tuple(data.color), node_color))
    energy = data.energy * node_strength
    location, rotation, scale = matrix.decompose()
    rot = rotation.to_matrix()
    if data.type == 'SUN':
        direction = rot @ _vector((0.0, 0.0, -1.0))
        return dwivedi.SunLight(direction=tuple(direction), strength=energy, color=color, angle=data.angle)
    if data.type == 'POINT':
        return dwivedi.PointLight(position=tuple(location), power=energy, color=color, radius=data.shadow_soft_size,
                                  shape=point_shape(data, bpy.app.version))
    if data.type == 'SPOT':
        if abs(scale[0] - scale[1]) > 1e-6 * max(abs(scale[0]), abs(scale[1]), 1e-30):
            warnings.append(f"light '{obj.name}': the spot's cone is round in dwivedi (the object's unequal x and "
                            "y scale, which makes Cycles 4.x's cone elliptic, is ignored)")
        direction = rot @ _vector((0.0, 0.0, -1.0))
        return dwivedi.SpotLight(position=tuple(location), direction=tuple(direction), power=energy, color=color,
                                 radius=data.shadow_soft_size, spot_size=data.spot_size, spot_blend=data.spot_blend,
                                 falloff=spot_falloff(bpy.app.version), shape=point_shape(data, bpy.app.version))
    if data.type == 'AREA':
        sx = data.size * abs(scale[0])
        sy = (data.size_y if data.shape in {'RECTANGLE', 'ELLIPSE'} else data.size) * abs(scale[1])
        shape = "disk" if data.shape in {'DISK', 'ELLIPSE'} else "rectangle"
        rigid = _rigid(location, rot)
        return dwivedi.AreaLight(transform=rigid, size_x=sx, size_y=sy, power=energy * area_power_scale(bpy.app.version),
                                 color=color, shape=shape)
    warnings.append(f"light '{obj.name}' of type {data.type} is not supported (left out)")
    return None


def _vector(values: Tuple[float, float, float]) -> Any:
    from mathutils import Vector
    return Vector(values)


def _rigid(location: Any, rot3: Any) -> List[float]:
    return [float(rot3[r][c]) if c < 3 else float(location[r]) for r in range(3) for c in range(4)]


class World:
    """What the world exports as: a constant colour x strength, or an equirectangular map
    (texels: 3 floats a texel, row 0 at the bottom; rotation: 9 numbers, world -> texture)."""

    def __init__(self, color: Tuple[float, float, float] = (0.0, 0.0, 0.0), strength: float = 0.0) -> None:
        self.color = tuple(color)
        self.strength = strength
        self.texels: Any = None
        self.width = self.height = 0
        self.rotation: List[float] = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
        self.interpolation = "linear"

    def apply(self, dw_scene: Any) -> None:
        if self.texels is None:
            dw_scene.set_world(self.color, self.strength)
        else:
            dw_scene.set_world_environment(self.texels, self.width, self.height, strength=self.strength,
                                           rotation=self.rotation, interpolation=self.interpolation)


# The Environment Texture node's interpolation as dwivedi's (Cycles treats Smart as Cubic).
INTERPOLATIONS = {'Linear': "linear", 'Closest': "closest", 'Cubic': "cubic", 'Smart': "cubic"}
# Image colour spaces whose pixels are scene-linear Rec.709 as Blender hands them over (a float
# image's pixels are already converted to scene linear on load, whatever its colour space).
LINEAR_SPACES = {'Linear', 'Linear Rec.709', 'Linear BT.709', 'Linear Rec.709 (sRGB)', 'Non-Color', 'Raw'}


def _world_background(world: Any) -> Any:
    """The Background node that feeds the world's active output, None for an unlinked output
    (a black world), or the string "none" when there is no Background at all."""
    nodes = world.node_tree.nodes
    for node in nodes:
        if node.type == 'OUTPUT_WORLD' and node.is_active_output:
            surface = node.inputs.get("Surface")
            if surface is not None and surface.is_linked and surface.links[0].from_node.type == 'BACKGROUND':
                return surface.links[0].from_node
            if surface is not None and not surface.is_linked:
                return None
            break
    background = next((n for n in nodes if n.type == 'BACKGROUND'), None)
    return "none" if background is None else background


def _mapping_rotation(node: Any) -> Optional[List[float]]:
    """The rotation a Mapping node applies to a direction (world -> texture), row-major, or None
    where it does more than rotate one (a location on a Point or Texture mapping, an unequal
    scale, a linked input): such a world is rendered by Cycles instead."""
    from mathutils import Euler
    inputs = node.inputs
    for name in ("Location", "Rotation", "Scale"):
        socket = inputs.get(name)
        if socket is not None and socket.is_linked:
            return None
    kind = node.vector_type
    location = inputs.get("Location")
    if kind in {'POINT', 'TEXTURE'} and location is not None and any(abs(v) > 0.0 for v in location.default_value):
        return None
    scale = tuple(inputs["Scale"].default_value)
    if max(abs(scale[0] - scale[1]), abs(scale[1] - scale[2])) > 1e-6 * max(abs(v) for v in scale) or scale[0] <= 0.0:
        return None
    matrix = Euler(tuple(inputs["Rotation"].default_value), 'XYZ').to_matrix()
    if kind == 'TEXTURE':  # the inverse mapping
        matrix.transpose()
    return [float(matrix[r][c]) for r in range(3) for c in range(3)]


def _environment_texture(background: Any) -> Optional[Tuple[Any, List[float]]]:
    """(the Environment Texture node, its rotation) where the Background is exactly that: its
    Color from an equirectangular Environment Texture's Color, whose Vector is unlinked (the ray
    direction), the Texture Coordinate's Generated (the same in a world), or a Mapping of either
    that only rotates; Strength unlinked. Otherwise None."""
    color_in, strength_in = background.inputs["Color"], background.inputs["Strength"]
    if strength_in.is_linked or not color_in.is_linked:
        return None
    link = color_in.links[0]
    node = link.from_node
    if node.type != 'TEX_ENVIRONMENT' or link.from_socket.name != "Color" or node.projection != 'EQUIRECTANGULAR':
        return None
    def is_direction(link: Any) -> bool:  # the ray direction, as an unlinked Vector is
        return link.from_node.type == 'TEX_COORD' and link.from_socket.name == "Generated"

    rotation = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    vector = node.inputs["Vector"]
    if vector.is_linked:
        source = vector.links[0]
        if source.from_node.type == 'MAPPING':
            rotation = _mapping_rotation(source.from_node)
            inner = source.from_node.inputs["Vector"]
            # An unlinked Mapping input is the zero vector, not a direction.
            if rotation is None or not inner.is_linked or not is_direction(inner.links[0]):
                return None
        elif not is_direction(source):
            return None
    return node, rotation


def _rgb(image: Any, width: int, height: int) -> Any:
    """An image's pixels without alpha: an array('f') of 3 x width x height, row 0 at the bottom
    (standard library only: Debian's Blender has no numpy)."""
    count = width * height
    rgba = array.array("f", bytes(16 * count))
    image.pixels.foreach_get(rgba)
    rgb = array.array("f", bytes(12 * count))
    for c in range(3):
        rgb[c::3] = rgba[c::4]
    return rgb


def _srgb_to_linear(rgb: Any) -> Any:
    """8-bit sRGB values (k / 255) to linear by the sRGB transfer function (IEC 61966-2-1), by a
    table of the 256 values."""
    table = [k / 255.0 / 12.92 if k / 255.0 <= 0.04045 else ((k / 255.0 + 0.055) / 1.055) ** 2.4
             for k in range(256)]
    return array.array("f", [table[min(255, max(0, int(round(v * 255.0))))] for v in rgb])


def _image_texels(image: Any, what: str) -> Optional[Tuple[Any, int, int]]:
    """An image's RGB texels as scene-linear floats (row 0 at the bottom), its width and height;
    None where its colour space is neither linear nor sRGB (the world is rendered instead).
    ExportError where the image has no pixels (a missing file)."""
    width, height = int(image.size[0]), int(image.size[1])  # reading the size loads the file
    if width == 0 or height == 0:
        raise ExportError(f"{what}: image '{image.name}' has no pixels (is its file '{image.filepath}' missing?)")
    space = image.colorspace_settings.name
    # A float image in a colour space that is not linear (Blender 5.2 tags an EXR it wrote
    # through a view transform "sRGB") is decoded by Cycles 5.2 otherwise than Image.pixels holds
    # it above 1 (a 3000 hot spot lit 12% less in Cycles than from Image.pixels): such a world is
    # rendered by Cycles instead, as is an 8-bit image in a space other than sRGB or linear.
    if space not in LINEAR_SPACES and (image.is_float or space != 'sRGB'):
        return None
    rgb = _rgb(image, width, height)
    if not image.is_float and space == 'sRGB':
        rgb = _srgb_to_linear(rgb)
    return rgb, width, height


def _render_world(scene: Any, world: Any, width: int) -> Tuple[Any, int, int]:
    """The world as Cycles renders it through an equirectangular panoramic camera at the origin
    looking along +x (where Cycles' environment camera faces the centre of an environment
    texture, blender/camera.cpp), width x width/2 pixels, in a scene of its own that is removed
    afterwards: the texels of dwivedi's equirectangular map."""
    import os
    import tempfile
    height = max(1, width // 2)
    tmp = bpy.data.scenes.new("dwivedi world bake")
    camera_data = bpy.data.cameras.new("dwivedi world bake")
    camera = bpy.data.objects.new("dwivedi world bake", camera_data)
    folder = tempfile.mkdtemp(prefix="dwivedi-world-")
    path = os.path.join(folder, "world.exr")
    image = None
    try:
        tmp.world = world
        tmp.render.engine = 'CYCLES'
        tmp.cycles.device = 'CPU'
        tmp.cycles.samples = 16
        tmp.cycles.use_denoising = False
        tmp.cycles.use_adaptive_sampling = False
        tmp.cycles.pixel_filter_type = 'BOX'
        tmp.cycles.filter_width = 1.0
        tmp.render.resolution_x, tmp.render.resolution_y = width, height
        tmp.render.resolution_percentage = 100
        tmp.render.film_transparent = False
        tmp.render.image_settings.file_format = 'OPEN_EXR'
        tmp.render.image_settings.color_depth = '32'
        tmp.render.filepath = path
        camera_data.type = 'PANO'
        if hasattr(camera_data, "panorama_type"):  # Blender 4.x+
            camera_data.panorama_type = 'EQUIRECTANGULAR'
        else:
            camera_data.cycles.panorama_type = 'EQUIRECTANGULAR'
        camera.rotation_euler = (math.pi / 2.0, 0.0, -math.pi / 2.0)  # local -z to +x, +y up
        tmp.collection.objects.link(camera)
        tmp.camera = camera
        bpy.ops.render.render(write_still=True, scene=tmp.name)
        image = bpy.data.images.load(path)
        return _rgb(image, width, height), width, height
    finally:
        if image is not None:
            bpy.data.images.remove(image)
        bpy.data.scenes.remove(tmp)
        bpy.data.objects.remove(camera)
        bpy.data.cameras.remove(camera_data)
        if os.path.exists(path):
            os.remove(path)
        os.rmdir(folder)


def world_from_blender(scene: Any, warnings: List[str], render_width: int = 1024) -> World:
    """The scene's world: a constant Background; an Environment Texture passed as it is (image,
    Mapping rotation, interpolation, Background strength); any other world tree rendered by
    Cycles into a render_width x render_width/2 equirectangular image (with a warning)."""
    world = scene.world
    if world is None:
        return World()
    if not world.use_nodes or world.node_tree is None:
        return World(tuple(world.color), 1.0)
    background = _world_background(world)
    if background is None:
        return World()
    if background == "none":
        warnings.append("the world has no Background node: baked with a black world")
        return World()
    color_in, strength_in = background.inputs["Color"], background.inputs["Strength"]
    if not color_in.is_linked and not strength_in.is_linked:
        return World(tuple(color_in.default_value)[:3], float(strength_in.default_value))
    out = World((1.0, 1.0, 1.0), 1.0)
    found = _environment_texture(background)
    if found is not None and found[0].image is not None:
        node, rotation = found
        texels = _image_texels(node.image, "the world's Environment Texture")
        if texels is not None:
            out.texels, out.width, out.height = texels
            out.strength = float(strength_in.default_value)
            out.rotation = rotation
            out.interpolation = INTERPOLATIONS.get(node.interpolation, "linear")
            return out
    if found is not None and found[0].image is None:
        warnings.append("the world's Environment Texture has no image: Cycles renders it black (so does dwivedi)")
        return World()
    out.texels, out.width, out.height = _render_world(scene, world, render_width)
    what = (f"the world's image '{found[0].image.name}' is in colour space "
            f"'{found[0].image.colorspace_settings.name}'") if found is not None else \
        "the world's nodes are not an Environment Texture dwivedi reads as it is"
    warnings.append(f"{what}: Cycles rendered the world into a {out.width} x {out.height} equirectangular image, "
                    "which is baked (World Resolution sets its width)")
    return out


# Blender's defaults of scene.cycles' Light Paths (used where Cycles' settings are absent).
_LIGHT_PATH_DEFAULTS = {"max_bounces": 12, "diffuse_bounces": 4, "glossy_bounces": 4, "transmission_bounces": 12,
                        "min_light_bounces": 0}


def light_paths(scene: Any, version: Optional[Tuple[int, ...]] = None) -> Dict[str, Any]:
    """Cycles' Light Paths of the scene (scene.cycles: Max Bounces Total, Diffuse, Glossy,
    Transmission, Min Light Bounces, Filter Glossy) as dwivedi.BakeSettings keys, and what a subsurface surface
    met after a diffuse bounce does in that Blender's Cycles: Lambertian up to 4.x (bssrdf_setup's
    fallback after a diffuse ancestor), a walk from 5.0 on (multi-bounce random walk)."""
    if version is None:
        version = tuple(bpy.app.version) if bpy is not None else (3, 4, 0)
    cycles = getattr(scene, "cycles", None)
    out: Dict[str, Any] = {}
    for key, default in _LIGHT_PATH_DEFAULTS.items():
        value = getattr(cycles, key, default) if cycles is not None else default
        out[key] = max(0, min(1024, int(value)))
    out["subsurface_after_diffuse"] = "walk" if tuple(version) >= (5, 0, 0) else "lambert"
    # Filter Glossy (Light Paths > Caustics; Blender's default 1.0, soft range 0 to 10).
    blur = float(getattr(cycles, "blur_glossy", 1.0)) if cycles is not None else 1.0
    out["blur_glossy"] = blur if math.isfinite(blur) and blur > 0.0 else 0.0
    return out


# Blender's Film > Pixel Filter types (scene.cycles.pixel_filter_type) as the library names them.
_PIXEL_FILTERS = {"BOX": "box", "GAUSSIAN": "gaussian", "BLACKMAN_HARRIS": "blackman_harris"}


def pixel_filter(scene: Any) -> Dict[str, Any]:
    """Cycles' pixel filter of the scene (Film > Pixel Filter: type and width in pixels; Blender's
    default Blackman-Harris of 1.5) as dwivedi.BakeSettings keys: camera bakes draw each sample's
    place in its pixel by it, as Cycles' camera rays do (UV bakes jitter over their texel either way)."""
    cycles = getattr(scene, "cycles", None)
    kind = str(getattr(cycles, "pixel_filter_type", "BLACKMAN_HARRIS")) if cycles is not None else "BLACKMAN_HARRIS"
    width = float(getattr(cycles, "filter_width", 1.5)) if cycles is not None else 1.5
    if kind not in _PIXEL_FILTERS:
        raise ExportError(f"the scene's pixel filter '{kind}' is not one dwivedi bakes (Box, Gaussian or Blackman-Harris)")
    if not (math.isfinite(width) and 0.01 <= width <= 10.0):
        raise ExportError(f"the scene's pixel filter width {width} px is outside Blender's range, 0.01 to 10")
    return {"pixel_filter": _PIXEL_FILTERS[kind], "filter_width": width}


def uv_jitter(version: Optional[Tuple[int, ...]] = None) -> Dict[str, Any]:
    """Where that Blender's Cycles places a UV bake's samples in their texel, as a
    dwivedi.BakeSettings key: up to 3.4 sample 0 at the centre and the others folded back into
    their triangle (bake_clamp_mirror_repeat), from 3.5 on tried again where they leave it
    (bake_jitter_barycentric)."""
    if version is None:
        version = tuple(bpy.app.version) if bpy is not None else (3, 4, 0)
    return {"uv_jitter": "mirror" if tuple(version) < (3, 5, 0) else "retry"}


def render_size(scene: Any) -> Tuple[int, int]:
    """The render resolution times its percentage, as Blender renders it."""
    r = scene.render
    width = max(1, int(r.resolution_x * r.resolution_percentage / 100))
    height = max(1, int(r.resolution_y * r.resolution_percentage / 100))
    return width, height


def camera_from_blender(scene: Any, width: int, height: int, dwivedi: Any, warnings: List[str]) -> Any:
    """The scene's active camera as dwivedi's, which always fits the larger image side: Blender's
    sensor fit (Auto, Horizontal, Vertical) becomes the extent of that side."""
    obj = scene.camera
    if obj is None:
        raise ExportError("the scene has no active camera (Scene properties > Camera): a camera bake needs one")
    if obj.type != 'CAMERA':
        raise ExportError(f"the scene's camera '{obj.name}' is a {obj.type} object, not a camera")
    cam = obj.data
    if cam.type not in {'PERSP', 'ORTHO'}:
        raise ExportError(f"camera '{obj.name}' is {cam.type}: only perspective and orthographic cameras are baked")
    if cam.shift_x != 0.0 or cam.shift_y != 0.0:
        warnings.append(f"camera '{obj.name}': lens shift is ignored")
    r = scene.render
    if r.pixel_aspect_x != r.pixel_aspect_y:
        warnings.append("non-square pixel aspect is ignored")
    larger = max(width, height)
    fit = cam.sensor_fit
    if fit == 'HORIZONTAL':
        factor = larger / width
    elif fit == 'VERTICAL':
        factor = larger / height
    else:
        factor = 1.0
    sensor = (cam.sensor_height if fit == 'VERTICAL' else cam.sensor_width) * factor
    evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()) if hasattr(obj, "evaluated_get") else obj
    location, rotation, _scale = evaluated.matrix_world.decompose()
    transform = _rigid(location, rotation.to_matrix())
    if cam.type == 'ORTHO':
        return dwivedi.Camera(transform=transform, kind="orthographic", ortho_scale=cam.ortho_scale * factor)
    return dwivedi.Camera(transform=transform, kind="perspective", focal_length=cam.lens, sensor_width=sensor)


# ---------------------------------------------------------------------------------------------
# The whole scene
# ---------------------------------------------------------------------------------------------

def export_scene(context: Any, settings: Any, dwivedi: Any, cache: Optional[ExportCache] = None) -> Exported:
    """Builds and commits the dwivedi scene of `context.scene` for the bake `settings`
    (scene.dwivedi_bake); ExportError if it cannot be baked as asked. With a `cache` (the
    add-on's CACHE, which its depsgraph handler keeps up to date) only what changed since the
    last bake is exported again, and an unchanged scene is the last bake's committed scene
    (then exported.owned is False: the cache closes it)."""
    scene = context.scene
    key = None
    if cache is not None:
        context.evaluated_depsgraph_get()  # Blender hands the pending updates to the handler now
        uv_object = getattr(settings, "uv_object", None)
        key = (scene.name_full, context.view_layer.name, settings.target, uv_object.name_full if uv_object else None,
               getattr(settings, "uv_size", 0), getattr(settings, "world_resolution", 1024),
               getattr(settings, "texture_bake_size", 256), id(dwivedi), dwivedi.library_path())
        kept = cache.scene(key)
        if kept is not None:
            return kept
    generation = cache.generation if cache is not None else 0
    out = Exported()
    warnings = out.warnings
    # Inputs driven by node trees are evaluated by Blender (an emission bake) before the depsgraph
    # is read: the bake re-evaluates it.
    evaluated_images: List[Any] = []
    try:
        evaluated_images = _evaluate_inputs(context, settings, warnings)
        out = _export(context, settings, dwivedi, out, cache)
    finally:
        textures.EVALUATED.clear()
        textures.OWNERS.clear()
        for image in evaluated_images:
            bpy.data.images.remove(image)
    if cache is not None and not evaluated_images and out.images_read == 0:
        cache.keep_scene(key, generation, out)
    return out


def _warn_instanced_evaluation(original: Any, slots: List[Any], warnings: List[str]) -> None:
    """An instance (a collection instance, particles, geometry nodes) of an object whose inputs
    Blender evaluated per object reads that object's images, made where the object itself is."""
    for material in slots:
        if material is None:
            continue
        owner = textures.evaluation_of(material.name_full, original.name_full)[1]
        message = (f"material '{material.name}': its inputs evaluated by Blender on object '{original.name}' are used "
                   "for the object's instances too (evaluated where the object itself is)")
        if owner is not None and owner.startswith("object ") and message not in warnings:
            warnings.append(message)


def _evaluate_inputs(context: Any, settings: Any, warnings: List[str]) -> List[Any]:
    """Bakes the material inputs of the render-visible meshes that node trees other than Image
    Textures drive into images (evaluate.py); returns them."""
    context.evaluated_depsgraph_get()  # the view layer's objects include those linked since its last update
    objects = [obj for obj in context.view_layer.objects
               if obj.type == 'MESH' and not obj.hide_render and obj.visible_get()]
    try:
        return evaluate.evaluate_objects(objects, _surface_shader, tuple(bpy.app.version) >= (4, 0, 0),
                                         int(getattr(settings, "texture_bake_size", 256)), warnings)
    except evaluate.EvaluationError as error:
        raise ExportError(f"{error}; nothing was baked") from None


def _export(context: Any, settings: Any, dwivedi: Any, out: Exported, cache: Optional[ExportCache]) -> Exported:
    scene = context.scene
    depsgraph = context.evaluated_depsgraph_get()
    warnings = out.warnings
    target = settings.target
    uv_object = settings.uv_object if target == 'UV' else None
    if target == 'UV':
        if uv_object is None:
            raise ExportError("choose the object to bake in UV space (UV Object)")
        if uv_object.type != 'MESH':
            raise ExportError(f"'{uv_object.name}' is a {uv_object.type} object: a UV bake needs a mesh")
        if len(uv_object.data.uv_layers) == 0:
            raise ExportError(f"mesh '{uv_object.name}' has no UV map: unwrap it (UV > Unwrap) before a UV bake")
        out.width = out.height = settings.uv_size
    else:
        out.width, out.height = render_size(scene)

    dw_scene = dwivedi.Scene()
    try:
        material_ids: Dict[Any, int] = {}
        material_textures: Dict[Any, List[Any]] = {}
        texture_cache = textures.TextureCache(dw_scene)

        def material_id(material: Any, obj: Any) -> int:
            """The library's material for `material` on object `obj`: one per material, or per
            material and object (or mesh) where its inputs were evaluated per object (evaluate.py:
            the object's own images are bound to it)."""
            key = None if material is None else textures.evaluation_of(material.name_full, obj.original.name_full)
            if key not in material_ids:
                converted = material_from_blender(material, dwivedi, warnings, evaluation=key)
                uses = texture_uses(material, converted, warnings, evaluation=key)
                material_ids[key] = dw_scene.add_material(converted)
                material_textures[key] = uses
                try:
                    textures.bind(dw_scene, texture_cache, material_ids[key], uses, material.name if material else "",
                                  tuple(bpy.app.version))
                except textures.MissingImage as error:
                    raise ExportError(str(error)) from None
            return material_ids[key]

        def texture_maps(obj: Any, slots: List[Any], uv_names: List[str]) -> Optional[List[Optional[str]]]:
            """None if no material of the object is textured; else the UV maps its normal maps
            read, after checking that every UV map a texture names is on the mesh (whose UV maps
            are `uv_names`)."""
            maps: Optional[List[Optional[str]]] = None
            for material in slots:
                material_id(material, obj)
                uses = material_textures[None if material is None else textures.evaluation_of(
                    material.name_full, obj.original.name_full)]
                if not uses:
                    continue
                maps = maps or []
                if not uv_names:
                    raise ExportError(f"object '{obj.name}' has no UV map, which the image textures of material "
                                      f"'{material.name}' need (UV > Unwrap)")
                for use in uses:
                    if use.uv_map is not None and use.uv_map not in uv_names:
                        raise ExportError(f"material '{material.name}' reads UV map '{use.uv_map}', which object "
                                          f"'{obj.name}' does not have (its UV maps: {', '.join(uv_names)})")
                    if use.input == "normal_map":
                        maps.append(use.uv_map)
            return maps

        uv_found = False
        skipped: List[str] = []
        for instance in depsgraph.object_instances:
            obj = instance.object
            matrix = instance.matrix_world.copy()
            # Disabled in renders (the object's camera icon): Cycles' render leaves it out, a light
            # as a mesh. The depsgraph here is the view layer's, which still holds it.
            if obj.hide_render:
                continue
            if obj.type == 'LIGHT':
                light = _light(obj, matrix, dwivedi, warnings)
                if light is not None:
                    dw_scene.add_light(light)
                    out.light_count += 1
                continue
            if not _is_geometry(obj):
                if obj.type not in {'CAMERA', 'EMPTY', 'LIGHT_PROBE', 'SPEAKER', 'ARMATURE', 'LATTICE'}:
                    skipped.append(obj.name)
                continue
            original = obj.original if hasattr(obj, "original") else obj
            is_uv_target = (uv_object is not None and original == uv_object and not instance.is_instance)
            # The mesh arrays of the last bake where nothing changed the object's geometry since
            # (ExportCache), else the evaluated mesh read again.
            name = original.name_full
            kept = cache.meshes(name) if cache is not None and not instance.is_instance else None
            mesh = None if kept is not None else obj.to_mesh()
            try:
                if kept is None and (mesh is None or len(mesh.polygons) == 0):
                    continue
                slots = [slot.material for slot in obj.material_slots]
                if instance.is_instance:
                    _warn_instanced_evaluation(original, slots, warnings)
                uv_names = kept.uv_names if kept is not None else [layer.name for layer in mesh.uv_layers]
                maps = texture_maps(obj, slots or [None], uv_names)
                if kept is not None and (kept.want_uvs != is_uv_target or kept.maps != maps):
                    kept, mesh = None, obj.to_mesh()
                if kept is not None:
                    arrays = kept.arrays
                    if arrays is None:
                        continue
                else:
                    arrays = _mesh_arrays(mesh, want_uvs=is_uv_target, texture_maps=maps)
                    if cache is not None and not instance.is_instance:
                        cache.keep_meshes(name, _Meshes(cache.generation, is_uv_target, maps, uv_names, arrays))
                if arrays["layers"] is not None:
                    warnings.extend(arrays["layers"]["warnings"])
                terminator = _shadow_terminator_geometry_offset(obj)
                by_material = dict(gather.groups(arrays["material_index"]))
                transform = _rows(matrix)
                if is_uv_target:
                    if arrays["uvs"] is None:
                        raise ExportError(f"mesh '{uv_object.name}' has no active UV map")
                    # A UV bake names one mesh: the object is one mesh with its main material.
                    main = max(by_material, key=lambda m: len(by_material[m]))
                    if len(by_material) > 1:
                        warnings.append(f"'{obj.name}' has {len(by_material)} materials: the UV bake uses "
                                        f"slot {main + 1}'s for the whole object")
                    material = slots[main] if main < len(slots) else None
                    out.uv_mesh = dw_scene.add_mesh(arrays["positions"], arrays["indices"], material_id(material, obj),
                                                    normals=arrays["normals"], uvs=arrays["uvs"], transform=transform,
                                                    shadow_terminator_geometry_offset=terminator,
                                                    **_layer_arguments(arrays))
                    uv_found = True
                    out.mesh_count += 1
                    out.triangle_count += arrays["triangles"]
                    continue
                for index, tris in sorted(by_material.items()):
                    part = arrays if len(by_material) == 1 else _subset(arrays, tris)
                    material = slots[index] if index < len(slots) else None
                    dw_scene.add_mesh(part["positions"], part["indices"], material_id(material, obj),
                                      normals=part["normals"], uvs=part["uvs"], transform=transform,
                                      shadow_terminator_geometry_offset=terminator, **_layer_arguments(part))
                    out.mesh_count += 1
                    out.triangle_count += part["triangles"]
            finally:
                if mesh is not None:
                    obj.to_mesh_clear()
        if skipped:
            warnings.append(f"objects that are not geometry were left out: {', '.join(sorted(skipped)[:8])}")
        if out.mesh_count == 0:
            raise ExportError("the scene has no visible mesh objects to bake")
        if target == 'UV' and not uv_found:
            raise ExportError(f"'{uv_object.name}' is not rendered in this view layer (hidden or excluded)")
        world = world_from_blender(scene, warnings, getattr(settings, "world_resolution", 1024))
        world.apply(dw_scene)
        out.images_read = len(texture_cache.ids) + (world.texels is not None)
        if target == 'CAMERA':
            dw_scene.set_camera(camera_from_blender(scene, out.width, out.height, dwivedi, warnings))
        elif scene.camera is not None and scene.camera.type == 'CAMERA' and scene.camera.data.type in {'PERSP', 'ORTHO'}:
            dw_scene.set_camera(camera_from_blender(scene, out.width, out.height, dwivedi, []))
        dw_scene.commit()
    except BaseException:
        dw_scene.close()
        raise
    out.scene = dw_scene
    return out


def ocio_config_path() -> Optional[str]:
    """Blender's own OCIO config (the one its colour management uses), or None."""
    import os
    env = os.environ.get("OCIO")
    candidates = []
    for kind in ('LOCAL', 'SYSTEM', 'USER'):
        try:
            base = bpy.utils.resource_path(kind)
        except (TypeError, ValueError):
            continue
        if base:
            candidates.append(os.path.join(base, "datafiles", "colormanagement", "config.ocio"))
    if env:  # Blender itself honours $OCIO first
        candidates.insert(0, env)
    for path in candidates:
        if os.path.isfile(path):
            return path
    return None
