"""Test scenes for the add-on, built by script inside Blender (nothing binary is committed).

Each builder empties the current file and makes one small scene with Cycles settings that render
only what dwivedi bakes: Principled BSDF with subsurface method RANDOM_WALK_FIXED_RADIUS, specular,
sheen and clearcoat 0 (so only the subsurface lobe reflects light), a black or constant world,
a box pixel filter one pixel wide and no denoising.
"""
import math

import bpy


def _reset():
    # read_homefile keeps the preferences (and so the enabled add-ons); read_factory_settings would not.
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    scene = bpy.context.scene
    scene.render.engine = 'CYCLES'
    scene.cycles.device = 'CPU'
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.pixel_filter_type = 'BOX'
    scene.cycles.filter_width = 1.0
    scene.cycles.seed = 0
    # Paths that matter: camera -> entry -> walk -> exit -> light. Allow a few bounces so that
    # concave or multi-object light transport is not cut, none of it is needed in these scenes.
    scene.cycles.max_bounces = 4
    scene.cycles.diffuse_bounces = 4
    scene.cycles.glossy_bounces = 0
    scene.cycles.transmission_bounces = 0
    scene.cycles.transparent_max_bounces = 0
    scene.cycles.caustics_reflective = False
    scene.cycles.caustics_refractive = False
    scene.cycles.sample_clamp_direct = 0.0
    scene.cycles.sample_clamp_indirect = 0.0
    scene.render.threads_mode = 'FIXED'
    scene.render.threads = 2
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.view_settings.view_transform = 'Standard'
    scene.view_settings.look = 'None'
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    world = bpy.data.worlds.new("World")
    world.use_nodes = True
    scene.world = world
    set_world(scene, (0.0, 0.0, 0.0), 1.0)
    return scene


def set_world(scene, color, strength):
    background = scene.world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (color[0], color[1], color[2], 1.0)
    background.inputs["Strength"].default_value = strength


def principled_material(name, color, radius, scale=1.0, weight=1.0, anisotropy=0.0):
    """A Principled BSDF that is pure random-walk subsurface (Blender 3.x and 4.x inputs)."""
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    bsdf = material.node_tree.nodes["Principled BSDF"]
    # 3.x's Fixed Radius walk where it exists; 4.0 renamed it Random Walk (5.2 made a new Random
    # Walk, which the add-on maps as 5.2's Cycles does).
    methods = [item.identifier for item in bsdf.bl_rna.properties["subsurface_method"].enum_items]
    bsdf.subsurface_method = 'RANDOM_WALK_FIXED_RADIUS' if 'RANDOM_WALK_FIXED_RADIUS' in methods else 'RANDOM_WALK'
    inputs = bsdf.inputs
    rgba = (color[0], color[1], color[2], 1.0)
    if "Subsurface Weight" in inputs:  # Blender 4.x
        inputs["Base Color"].default_value = rgba
        inputs["Subsurface Weight"].default_value = weight
        inputs["Subsurface Scale"].default_value = scale
        inputs["Specular IOR Level"].default_value = 0.0
    else:  # Blender 3.x: the subsurface colour is mixed with the base colour by "Subsurface"
        inputs["Base Color"].default_value = rgba
        inputs["Subsurface Color"].default_value = rgba
        inputs["Subsurface"].default_value = weight * scale
        inputs["Specular"].default_value = 0.0
        inputs["Clearcoat"].default_value = 0.0
        inputs["Sheen"].default_value = 0.0
    inputs["Subsurface Radius"].default_value = tuple(radius)
    inputs["Subsurface Anisotropy"].default_value = anisotropy
    inputs["Metallic"].default_value = 0.0
    inputs["Roughness"].default_value = 0.5
    return material


def sss_node_material(name, color, radius, scale=1.0):
    """The Subsurface Scattering node, Random Walk (Fixed Radius): walks entering by cosine-weighted
    diffuse transmission and leaving through a Lambertian exit, nothing else (Cycles gives it no
    roughness, so no Principled retro-reflection and no Fresnel-weighted exit)."""
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    tree = material.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    node = tree.nodes.new("ShaderNodeSubsurfaceScattering")
    # 3.x's Fixed Radius walk; 4.0-5.1 store it as Random Walk, 5.2 calls it Random Walk (Legacy).
    falloffs = [item.identifier for item in node.bl_rna.properties["falloff"].enum_items]
    node.falloff = next(m for m in ('RANDOM_WALK_FIXED_RADIUS', 'RANDOM_WALK_LEGACY', 'RANDOM_WALK') if m in falloffs)
    node.inputs["Color"].default_value = (color[0], color[1], color[2], 1.0)
    node.inputs["Scale"].default_value = scale
    node.inputs["Radius"].default_value = tuple(radius)
    tree.links.new(node.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    return material


def diffuse_material(name, color):
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    bsdf = material.node_tree.nodes["Principled BSDF"]
    inputs = bsdf.inputs
    inputs["Base Color"].default_value = (color[0], color[1], color[2], 1.0)
    if "Specular IOR Level" in inputs:
        inputs["Specular IOR Level"].default_value = 0.0
    else:
        inputs["Specular"].default_value = 0.0
        inputs["Sheen"].default_value = 0.0
        inputs["Subsurface"].default_value = 0.0
    inputs["Roughness"].default_value = 1.0
    return material


def _camera(scene, location, rotation, ortho_scale=None, lens=50.0):
    data = bpy.data.cameras.new("Camera")
    if ortho_scale is not None:
        data.type = 'ORTHO'
        data.ortho_scale = ortho_scale
    else:
        data.lens = lens
    camera = bpy.data.objects.new("Camera", data)
    camera.location = location
    camera.rotation_euler = rotation
    scene.collection.objects.link(camera)
    scene.camera = camera
    return camera


def _sun(scene, rotation, strength, angle=0.0, color=(1.0, 1.0, 1.0)):
    data = bpy.data.lights.new("Sun", 'SUN')
    data.energy = strength
    data.angle = angle
    data.color = color
    sun = bpy.data.objects.new("Sun", data)
    sun.rotation_euler = rotation
    scene.collection.objects.link(sun)
    return sun


def _box(scene, name, size, location, material):
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=location)
    obj = bpy.context.active_object
    obj.name = name
    obj.scale = size
    obj.data.materials.append(material)
    return obj


def slab_scene(resolution=32, samples=256, thickness=0.1, color=(0.8, 0.8, 0.8), radius=(1.0, 0.5, 0.25),
               width=4.0):
    """A wide slab `thickness` m thick (4 x 4 m), lit from below by a sun travelling straight
    up, seen from above by an orthographic camera over its centre: only light transmitted
    through the slab reaches the camera. Radius (1.0, 0.5, 0.25) m, colour 0.8: Cycles' fixed
    radius walk has the mean free path radius / (4 pi) (bssrdf_setup_radius), so a 0.1 m slab
    is about 1.26, 2.5 and 5.0 mean free paths thick in R, G, B."""
    scene = _reset()
    scene.render.resolution_x = resolution
    scene.render.resolution_y = resolution
    scene.cycles.samples = samples
    material = principled_material("Slab", color, radius)
    _box(scene, "Slab", (width, width, thickness), (0.0, 0.0, 0.0), material)
    _camera(scene, (0.0, 0.0, 3.0), (0.0, 0.0, 0.0), ortho_scale=1.0)
    # A sun's light travels along its local -z: rotated by pi about x it travels +z (upwards).
    _sun(scene, (math.pi, 0.0, 0.0), 3.0)
    return scene


def sphere_scene(resolution=32, samples=256, shader='PRINCIPLED'):
    """A sphere of radius 1 m, smooth shaded, lit by a sun from the camera's side (45 degrees
    off the view axis), seen by a perspective camera. Radius (0.5, 0.25, 0.1) m (mean free
    paths 0.04, 0.02, 0.008 m), colour (0.9, 0.6, 0.4): thick front-lit wax-like. shader:
    'PRINCIPLED' (Principled BSDF), 'SSS' (the Subsurface Scattering node) or 'DIFFUSE' (a
    Principled BSDF without subsurface, roughness 1)."""
    scene = _reset()
    scene.render.resolution_x = resolution
    scene.render.resolution_y = resolution
    scene.cycles.samples = samples
    if shader == 'PRINCIPLED':
        material = principled_material("Wax", (0.9, 0.6, 0.4), (0.5, 0.25, 0.1))
    elif shader == 'DIFFUSE':
        material = diffuse_material("Clay", (0.9, 0.6, 0.4))
    else:
        material = sss_node_material("Wax", (0.9, 0.6, 0.4), (0.5, 0.25, 0.1))
    bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=1.0)
    sphere = bpy.context.active_object
    sphere.name = "Sphere"
    bpy.ops.object.shade_smooth()
    sphere.data.materials.append(material)
    _camera(scene, (0.0, -3.5, 0.0), (math.pi / 2, 0.0, 0.0), lens=50.0)
    _sun(scene, (math.radians(45.0), 0.0, math.radians(-30.0)), 2.0)
    return scene


def lights_scene(kind, resolution=16, samples=64):
    """A white diffuse 4 x 4 m plane at z = 0 seen from above (orthographic) with one light of
    `kind` ('SUN', 'POINT', 'AREA' square 0.5 m, 'SPOT' not used) 2 m above its centre, strength 10:
    measures Cycles' light units (the radiance of the plane's centre is albedo / pi times the
    irradiance)."""
    scene = _reset()
    scene.render.resolution_x = resolution
    scene.render.resolution_y = resolution
    scene.cycles.samples = samples
    scene.cycles.max_bounces = 0
    bpy.ops.mesh.primitive_plane_add(size=4.0)
    plane = bpy.context.active_object
    plane.data.materials.append(diffuse_material("White", (1.0, 1.0, 1.0)))
    _camera(scene, (0.0, 0.0, 3.0), (0.0, 0.0, 0.0), ortho_scale=0.2)
    data = bpy.data.lights.new("Light", kind)
    data.energy = 10.0
    if kind == 'POINT':
        data.shadow_soft_size = 0.0
    if kind == 'AREA':
        data.shape = 'SQUARE'
        data.size = 0.5
    light = bpy.data.objects.new("Light", data)
    light.location = (0.0, 0.0, 2.0)
    scene.collection.objects.link(light)
    return scene


# ---------------------------------------------------------------------------------------------
# Issue 17: Cycles' own look per Blender version (tests/blender/test_fidelity.py). The materials
# keep the Principled defaults of that Blender (specular layer, roughness, IOR, distribution)
# and switch subsurface on; only the method, colour and amount are set.
# ---------------------------------------------------------------------------------------------

def blender4():
    return bpy.app.version >= (4, 0, 0)


def methods():
    """The subsurface methods of this Blender's Principled BSDF, the default first."""
    if bpy.app.version >= (5, 2, 0):
        return ('RANDOM_WALK', 'RANDOM_WALK_LEGACY', 'RANDOM_WALK_SKIN')
    if blender4():
        return ('RANDOM_WALK', 'RANDOM_WALK_SKIN')
    return ('RANDOM_WALK', 'RANDOM_WALK_FIXED_RADIUS')


def default_subsurface_material(name, method, color=None, amount=None, roughness=None, specular=None,
                                distribution=None):
    """A new Principled BSDF with subsurface switched on as a user would: 3.x Subsurface = amount
    (default 0.05, so the radius is as 4.x's default Scale 0.05) with Subsurface Color = colour;
    4.x+ Subsurface Weight 1 with Subsurface Scale = amount (default: this Blender's own default)
    and Base Color = colour. Everything else at this Blender's defaults unless given."""
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    bsdf = material.node_tree.nodes["Principled BSDF"]
    bsdf.subsurface_method = method
    if distribution is not None:
        bsdf.distribution = distribution
    inputs = bsdf.inputs
    if color is not None:
        rgba = (color[0], color[1], color[2], 1.0)
        inputs["Base Color"].default_value = rgba
        if "Subsurface Color" in inputs:
            inputs["Subsurface Color"].default_value = rgba
    if blender4():
        inputs["Subsurface Weight"].default_value = 1.0
        if amount is not None:
            inputs["Subsurface Scale"].default_value = amount
        if specular is not None:
            inputs["Specular IOR Level"].default_value = specular
    else:
        inputs["Subsurface"].default_value = 0.05 if amount is None else amount
        if specular is not None:
            inputs["Specular"].default_value = specular
    if roughness is not None:
        inputs["Roughness"].default_value = roughness
    return material


def default_sphere_scene(resolution, method, **material):
    """sphere_scene's front-lit smooth sphere (radius 1 m, sun 45 degrees off the view) with a
    default Principled subsurface material of `method`."""
    scene = _reset()
    scene.render.resolution_x = resolution
    scene.render.resolution_y = resolution
    bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=1.0)
    sphere = bpy.context.active_object
    sphere.name = "Sphere"
    bpy.ops.object.shade_smooth()
    sphere.data.materials.append(default_subsurface_material("Default", method, **material))
    _camera(scene, (0.0, -3.5, 0.0), (math.pi / 2, 0.0, 0.0), lens=50.0)
    _sun(scene, (math.radians(45.0), 0.0, math.radians(-30.0)), 2.0)
    return scene


def backlit_slab_scene(resolution, method, thickness=0.2):
    """The issue's back-lit slab: 0.2 m thick (or `thickness`), 4 x 4 m, Subsurface 0.3 (4.x+:
    Scale 0.3), colour (0.9, 0.7, 0.5), a sun from straight below, an orthographic camera above."""
    scene = _reset()
    scene.render.resolution_x = resolution
    scene.render.resolution_y = resolution
    material = default_subsurface_material("Slab", method, color=(0.9, 0.7, 0.5), amount=0.3)
    _box(scene, "Slab", (4.0, 4.0, thickness), (0.0, 0.0, 0.0), material)
    _camera(scene, (0.0, 0.0, 3.0), (0.0, 0.0, 0.0), ortho_scale=1.0)
    _sun(scene, (math.pi, 0.0, 0.0), 3.0)
    return scene


def glossy_cube_scene(resolution, method):
    """A small flat-shaded cube (0.3 m, turned 30 and 20 degrees) of a default subsurface
    material with colour (0.7, 0.8, 0.9) and Roughness 0.3, lit by a point light off to the side
    and a dim grey world (the specular layer reflects both), seen in perspective: other shape,
    light and scale than the sphere and the slab."""
    scene = _reset()
    scene.render.resolution_x = resolution
    scene.render.resolution_y = resolution
    set_world(scene, (0.2, 0.2, 0.2), 1.0)
    material = default_subsurface_material("Jade", method, color=(0.7, 0.8, 0.9), roughness=0.3,
                                           amount=0.02 if blender4() else None)
    bpy.ops.mesh.primitive_cube_add(size=0.3, location=(0.0, 0.0, 0.0),
                                    rotation=(math.radians(30.0), math.radians(20.0), 0.0))
    cube = bpy.context.active_object
    cube.name = "Cube"
    cube.data.materials.append(material)
    _camera(scene, (0.0, -1.2, 0.15), (math.radians(83.0), 0.0, 0.0), lens=50.0)
    data = bpy.data.lights.new("Point", 'POINT')
    data.energy = 20.0
    data.shadow_soft_size = 0.0
    light = bpy.data.objects.new("Point", data)
    light.location = (0.6, -0.6, 0.5)
    scene.collection.objects.link(light)
    return scene


def bake_image(obj, size, name="Baked", float_buffer=True):
    """What Cycles' UV bake wants, made as an artist makes it: a new image (Image > New, `size` =
    (width, height)) in an Image Texture node that is the active node of `obj`'s material, and
    `obj` the active, selected object. Returns the image."""
    image = bpy.data.images.new(name, size[0], size[1], alpha=True, float_buffer=float_buffer)
    material = obj.active_material
    node = material.node_tree.nodes.new('ShaderNodeTexImage')
    node.image = image
    material.node_tree.nodes.active = node
    for other in bpy.context.view_layer.objects:
        other.select_set(other == obj)
    bpy.context.view_layer.objects.active = obj
    return image
