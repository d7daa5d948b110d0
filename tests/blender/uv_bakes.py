"""UV bakes of one image by this Blender's Cycles and by the add-on, for the tests that compare
them (test_bake_passes.py, test_bake_footprint.py): Render > Bake's type and pass filter, the
image cleared before each bake and read back after, and the texels to compare."""
import bpy

import harness
import scenes

LIGHT_FILTERS = ("direct", "indirect", "color", "diffuse", "glossy", "transmission", "emit")


def sphere_bake(size, amount=None):
    """scenes.default_sphere_scene's 1 m smooth sphere (this Blender's default Principled
    subsurface material at Roughness 0.5, Subsurface / Scale `amount` or the default) in a grey
    world, set up for a UV bake into a new size x size image without margins: (scene, image)."""
    scene = scenes.default_sphere_scene(size, scenes.methods()[0], roughness=0.5, amount=amount)
    scenes.set_world(scene, (0.2, 0.2, 0.2), 1.0)
    image = scenes.bake_image(bpy.data.objects["Sphere"], (size, size))
    scene.render.bake.margin = 0
    scene.dwivedi_bake.target = 'UV'
    scene.dwivedi_bake.uv_margin = 0
    return scene, image


def set_filter(scene, bake_type, pass_filter):
    scene.cycles.bake_type = bake_type
    bake = scene.render.bake
    for name in LIGHT_FILTERS:
        setattr(bake, "use_pass_" + name, name.upper() in pass_filter)


def clear(image):
    image.pixels.foreach_set([0.0] * len(image.pixels))


def pixels(image):
    out = [0.0] * len(image.pixels)
    image.pixels.foreach_get(out)
    return out


def cycles_bake(scene, image, bake_type, pass_filter, seed, samples):
    clear(image)
    scene.cycles.seed = seed
    scene.cycles.samples = samples
    result = bpy.ops.object.bake(type=bake_type, pass_filter=pass_filter, margin=0, use_clear=True)
    assert result == {'FINISHED'}, result
    return pixels(image)


def dwivedi_bake(scene, image, seed, samples, work):
    clear(image)
    props = scene.dwivedi_bake
    props.samples = samples
    props.seed = seed
    props.threads = 2
    props.output_dir = str(work)
    result, error = harness.call_operator()
    assert result == {'FINISHED'}, error
    return pixels(image)


def interior(covered, size):
    """Texels covered with all four neighbours covered (an island's edge texels are rasterized
    differently by Blender and the library)."""
    keep = set()
    for i in covered:
        x, y = i % size, i // size
        if 0 < x < size - 1 and 0 < y < size - 1 and {i - 1, i + 1, i - size, i + size} <= covered:
            keep.add(i)
    return sorted(keep)


def only(texels, rgba):
    return [rgba[4 * i + c] for i in texels for c in range(4)]


def compare(cycles, ours, size):
    """harness.compare_two_seeds over the interior texels both sides covered in all their bakes,
    with the texel count and the largest relative difference of a texel's two-seed means."""
    covered = {i for i in range(size * size) if all(p[4 * i + 3] > 0.0 for p in cycles + ours)}
    texels = interior(covered, size)
    figures = harness.compare_two_seeds([only(texels, p) for p in cycles], [only(texels, p) for p in ours])
    figures["texels"] = len(texels)
    means = [[(a + b) / 2 for a, b in zip(only(texels, p), only(texels, q))] for p, q in (cycles, ours)]
    figures["largest_texel_difference"] = max(
        (abs(o - c) / max(abs(c), 1e-6) for k, (c, o) in enumerate(zip(*means)) if k % 4 < 3), default=0.0)
    return figures
