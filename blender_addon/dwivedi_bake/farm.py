"""The add-on's farm sub-panel (docs/farm.md): "Export for a Farm" writes the scene as a scene file
and the split bake's chunk commands, Slurm job array and merge (the shim's dwivedi.farm) into a
folder; "Merge Farm Chunks" merges a folder of chunks (dwivedi.merge_partials: every chunk checked
before anything is written) and loads the result as a Blender image.

Settings: scene.dwivedi_farm; the bake's own settings (samples in all, technique, channel walks,
seed, walk event cap, threads) come from scene.dwivedi_bake, as the main panel sets them. Split
bakes are camera bakes. The farm's nodes run the `dwivedi` command (the CLI, built from the same
sources as this add-on's library) on the exported folder.
"""
from __future__ import annotations

import glob
import importlib
import os
import re
import sys
import traceback

import bpy
from bpy.props import IntProperty, PointerProperty, StringProperty

from . import export, passes

SCENE_FILE = "dwivedi_scene.json"


def _addon():
    """The add-on's package module (its shim(), image and folder helpers): registered by then."""
    return sys.modules[__package__]


def farm_folder(settings) -> str:
    """The farm folder as an absolute path: relative to the .blend ("//"), or to the add-on's
    folder for unsaved files when the .blend is not saved."""
    raw = settings.folder.strip() or "//dwivedi_farm/"
    if raw.startswith("//") and not bpy.data.filepath:
        return os.path.join(_addon().unsaved_file_folder(), raw[2:])
    return os.path.abspath(bpy.path.abspath(raw))


def output_name(scene) -> str:
    """The merged output's name: the Blender scene's, in the characters a plan allows."""
    name = re.sub(r"[^A-Za-z0-9._-]", "_", scene.name) or "scene"
    return ("_" + name if not (name[0].isalnum() or name[0] == "_") else name)[:90] + "_camera"


def _shim_module(dwivedi, name):
    """The shim's module `name` (dwivedi.farm, dwivedi.scene_file), wherever the shim was imported
    from (the add-on's bundled copy is dwivedi_bake.dwivedi)."""
    return importlib.import_module(f"{dwivedi.__name__}.{name}")


def _writer_module(dwivedi):
    """The shim with a SceneFileWriter in place of Scene: export.export_scene makes its calls on
    it, and they become a scene file instead of a library scene."""
    from types import SimpleNamespace
    writer = _shim_module(dwivedi, "scene_file").SceneFileWriter
    names = {name: getattr(dwivedi, name) for name in dir(dwivedi) if not name.startswith("__")}
    names["Scene"] = writer
    return SimpleNamespace(**names)


class DwivediFarmSettings(bpy.types.PropertyGroup):
    folder: StringProperty(name="Farm Folder", subtype='DIR_PATH', default="//dwivedi_farm/",
                           description="Where the scene file, the chunk commands and scripts, the chunks and the merged "
                                       "result go (move it to the farm's shared storage as a whole)")
    chunks: IntProperty(name="Chunks", default=8, min=1, max=100000,
                        description="How many tasks the samples are cut into (at most the samples per pixel)")
    cpus_per_task: IntProperty(name="Cores per Chunk", default=1, min=1, max=1024,
                               description="Slurm: cores each chunk asks for (its threads)")
    program: StringProperty(name="dwivedi Command", default="dwivedi",
                            description="The dwivedi command on the farm's nodes (a name on their PATH or a full path)")
    partition: StringProperty(name="Slurm Partition", default="", description="Empty: the cluster's default")
    last_result: StringProperty(default="", options={'SKIP_SAVE'})


class _FarmOperator:
    """What both farm operators do around their work (`run`, returning a one-line summary): every
    failure reported as an error and CANCELLED, none escaping into Blender; the summary shown."""

    def execute(self, context):
        farm_settings = context.scene.dwivedi_farm
        try:
            summary = self.run(context)
        except Exception as error:
            message = str(error) or type(error).__name__
            if not isinstance(error, (export.ExportError, ValueError, OSError, TypeError)):
                traceback.print_exc()
            self.report({'ERROR'}, f"{self.bl_label} failed: {message}")
            farm_settings.last_result = message.splitlines()[0] if message else ""
            return {'CANCELLED'}
        farm_settings.last_result = summary
        self.report({'INFO'}, summary)
        return {'FINISHED'}


class DWIVEDI_OT_farm_export(_FarmOperator, bpy.types.Operator):
    """Write the scene file and the chunk commands (and a Slurm job array with its merge) for a farm"""
    bl_idname = "dwivedi.farm_export"
    bl_label = "Export for a Farm"
    bl_options = {'REGISTER'}

    def run(self, context):
        return self._export(context, context.scene.dwivedi_bake, context.scene.dwivedi_farm)

    def _export(self, context, bake, farm_settings):
        addon = _addon()
        dwivedi = addon.shim()
        farm = _shim_module(dwivedi, "farm")
        if bake.target != 'CAMERA':
            raise export.ExportError("farm bakes are camera bakes (a split UV bake is not supported): set Target "
                                     "to Camera")
        if not 1 <= farm_settings.chunks <= bake.samples:
            raise export.ExportError(f"Chunks is {farm_settings.chunks}: from 1 to Samples ({bake.samples})")
        folder = farm_folder(farm_settings)
        addon._check_folder(folder)
        exported = export.export_scene(context, bake, _writer_module(dwivedi))
        for warning in exported.warnings:
            self.report({'WARNING'}, warning)
        # Partial files carry the combined image's sums only (the library refuses passes in a chunk).
        try:
            bake_type, pass_filter = passes.bake_request(context.scene)
        except passes.UnsupportedBake as error:
            raise export.ExportError(str(error)) from None
        if not passes.is_full_combined(bake_type, pass_filter) or passes.view_layer_passes(context.view_layer):
            self.report({'WARNING'}, "a farm bake makes the Combined image only: the bake type "
                                     f"{passes.summary(bake_type, pass_filter)} and the view layer's light passes "
                                     "are not baked by its chunks (bake on this machine for passes)")
        if bake.time_limit > 0.0 or bake.target_error > 0.0:
            self.report({'WARNING'}, "Time Limit and Target Error do not apply to a farm bake: every chunk bakes "
                                     "all its samples")
        scene_path = os.path.join(folder, SCENE_FILE)
        exported.scene.write(scene_path, description=f"exported from Blender scene '{context.scene.name}'", bake={
            "target": "camera", "width": exported.width, "height": exported.height, "samples": bake.samples,
            "technique": bake.technique.lower(), "channel_walks": bake.channel_walks.lower(), "seed": bake.seed,
            "max_events": bake.walk_event_cap, "transparent_background": bool(context.scene.render.film_transparent),
            **export.light_paths(context.scene), **export.pixel_filter(context.scene)})
        dwivedi.Scene.load(scene_path).close()  # the library reads it back, or says why here, not on the farm
        bake_args = ["--threads", str(bake.threads)] if bake.threads > 0 else []
        made = farm.plan(scene_path, bake.samples, farm_settings.chunks, folder, name=output_name(context.scene),
                         seed=bake.seed, dwivedi=farm_settings.program.strip() or "dwivedi", bake_args=bake_args,
                         cpus_per_task=farm_settings.cpus_per_task, partition=farm_settings.partition.strip() or None)
        farm.write_plan(made, folder)
        return (f"Farm export: {len(made.chunks)} chunks of {made.spp} spp, {exported.width} x {exported.height} -> "
                f"{folder} (chunks.txt, merge.txt; Slurm: submit.sh)")


class DWIVEDI_OT_farm_merge(_FarmOperator, bpy.types.Operator):
    """Merge the chunks in the farm folder and load the result as a Blender image"""
    bl_idname = "dwivedi.farm_merge"
    bl_label = "Merge Farm Chunks"
    bl_options = {'REGISTER'}

    def run(self, context):
        return self._merge(context, farm_folder(context.scene.dwivedi_farm))

    def _merge(self, context, folder):
        addon = _addon()
        dwivedi = addon.shim()
        farm = _shim_module(dwivedi, "farm")
        if os.path.isfile(os.path.join(folder, farm.PLAN_FILE)):
            parts, name = farm.read_plan_parts(folder)  # exactly the plan's chunks: a stray file is no part
        else:
            parts, name = sorted(glob.glob(os.path.join(glob.escape(folder), "*.dwvpart"))), "merged"
            if not parts:
                raise export.ExportError(f"no farm plan ({farm.PLAN_FILE}) and no .dwvpart chunks in {folder}")
        image = dwivedi.merge_partials(parts)  # refuses a missing, duplicated or foreign chunk, naming it
        try:
            exr = os.path.join(folder, name + ".exr")
            png = os.path.join(folder, name + ".png")
            addon.film_alpha(image, context.scene)  # the background as Film > Transparent says, as the bake
            image.write_exr(exr)
            try:
                image.write_png(png, addon.display_settings(context.scene, dwivedi))
            except dwivedi.Error as error:
                if "OCIO" not in str(error) and "config" not in str(error):
                    raise
                addon.png_through_blender(image, context.scene, png)  # as the bake does (Blender 5.2's config)
            addon.file_image(exr, "Dwivedi Farm")
            stats = image.stats
        finally:
            image.close()
        return (f"Merged {len(parts)} chunks: {stats.samples_per_pixel} spp, est. error "
                f"{stats.estimated_relative_error:.2%} -> {exr} (image 'Dwivedi Farm')")


class DWIVEDI_PT_farm(bpy.types.Panel):
    bl_label = "Farm"
    bl_idname = "DWIVEDI_PT_farm"
    bl_parent_id = "DWIVEDI_PT_bake"
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = "render"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        settings = context.scene.dwivedi_farm
        layout.prop(settings, "folder")
        layout.prop(settings, "chunks")
        layout.prop(settings, "program")
        layout.prop(settings, "cpus_per_task")
        layout.prop(settings, "partition")
        row = layout.row(align=True)
        row.operator(DWIVEDI_OT_farm_export.bl_idname, icon='EXPORT')
        row.operator(DWIVEDI_OT_farm_merge.bl_idname, icon='IMAGE_DATA')
        if settings.last_result:
            layout.label(text=settings.last_result)


CLASSES = (DwivediFarmSettings, DWIVEDI_OT_farm_export, DWIVEDI_OT_farm_merge, DWIVEDI_PT_farm)


def register():
    """After the main panel (this one's parent) is registered."""
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.dwivedi_farm = PointerProperty(type=DwivediFarmSettings)


def unregister():
    del bpy.types.Scene.dwivedi_farm
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
