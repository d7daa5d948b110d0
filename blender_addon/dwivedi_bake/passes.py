"""Cycles' bake type and pass filter (Render Properties > Bake) for Dwivedi bakes.

Blender keeps them in scene.cycles.bake_type and scene.render.bake.use_pass_direct / _indirect /
_color (Diffuse, Glossy, Transmission) and use_pass_diffuse / _glossy / _transmission / _emit
(Combined's filter), the same in 3.4, 4.3 and 5.2. The library bakes Combined, Diffuse, Glossy,
Transmission, Emit and Environment (capi dwv_bake_type_t); the others (Ambient Occlusion, Shadow,
Position, Normal, UV, Roughness) are Cycles' to bake. Camera bakes add the view layer's enabled
light passes (View Layer Properties > Passes > Light) as layers of a multilayer OpenEXR, named as
Blender names them.
"""

# scene.cycles.bake_type -> the library's name (dwivedi.BAKE_TYPES).
SUPPORTED = {"COMBINED": "COMBINED", "DIFFUSE": "DIFFUSE", "GLOSSY": "GLOSSY", "TRANSMISSION": "TRANSMISSION",
             "EMIT": "EMIT", "ENVIRONMENT": "ENVIRONMENT"}
# Combined's filter with everything in it: the bake's own combined image.
FULL_COMBINED = frozenset({"direct", "indirect", "diffuse", "glossy", "transmission", "emit"})
# The view layer's light passes (bpy ViewLayer.use_pass_*; Cycles' environment: ViewLayer.cycles
# in 3.x, the view layer itself in 4.x+), by Blender's pass names.
VIEW_LAYER_PASSES = (("DiffDir", "use_pass_diffuse_direct"), ("DiffInd", "use_pass_diffuse_indirect"),
                     ("DiffCol", "use_pass_diffuse_color"), ("GlossDir", "use_pass_glossy_direct"),
                     ("GlossInd", "use_pass_glossy_indirect"), ("GlossCol", "use_pass_glossy_color"),
                     ("TransDir", "use_pass_transmission_direct"), ("TransInd", "use_pass_transmission_indirect"),
                     ("TransCol", "use_pass_transmission_color"), ("Emit", "use_pass_emit"),
                     ("Env", "use_pass_environment"))


class UnsupportedBake(Exception):
    """A bake type the library does not bake; the message says what to do."""


def bake_request(scene):
    """(bake type, pass filter) as the library names them (dwivedi.BAKE_TYPES, BAKE_FILTERS) from
    the scene's Cycles bake settings; COMBINED with the full filter where the scene has none."""
    cycles = getattr(scene, "cycles", None)
    bake_type = getattr(cycles, "bake_type", "COMBINED") if cycles is not None else "COMBINED"
    if bake_type not in SUPPORTED:
        raise UnsupportedBake(
            f"Bake Type '{bake_type}' (Render Properties > Bake) is not one Dwivedi bakes: it bakes Combined, "
            "Diffuse, Glossy, Transmission, Emit and Environment; bake this one with Cycles' Bake")
    settings = scene.render.bake
    names = ("direct", "indirect", "color", "diffuse", "glossy", "transmission", "emit")
    pass_filter = frozenset(name for name in names if getattr(settings, "use_pass_" + name, False))
    return SUPPORTED[bake_type], pass_filter


def view_layer_passes(view_layer):
    """Blender's names of the light passes enabled on `view_layer`."""
    out = []
    for name, prop in VIEW_LAYER_PASSES:
        owner = view_layer
        if not hasattr(owner, prop):
            owner = getattr(view_layer, "cycles", None)  # 3.x keeps Cycles' own passes here
        if owner is not None and getattr(owner, prop, False):
            out.append(name)
    return tuple(out)


def is_full_combined(bake_type, pass_filter):
    return bake_type == "COMBINED" and FULL_COMBINED <= pass_filter


def summary(bake_type, pass_filter):
    """'Diffuse (direct, color)' for the bake's summary line."""
    shown = ", ".join(name for name in ("direct", "indirect", "color", "diffuse", "glossy", "transmission", "emit")
                      if name in pass_filter)
    return f"{bake_type.capitalize()} ({shown})" if shown else bake_type.capitalize()
