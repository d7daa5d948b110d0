"""Times the add-on's export and load in Blender, stage by stage, on large meshes (issue 20):

    blender -b --factory-startup --python tools/profile_export.py -- [--objects N] [--level L]
        [--size PX] [--samples S] [--profile FILE] [--repeat K]

Builds N subdivided Suzannes (Subdivision Surface at level L, smooth shading, two materials on
every other one, a sun, a camera, a grey world), then runs the add-on's Bake operator K times
(default 4: cold; unchanged; after the sun's strength changed; after one object's modifier
changed: what the export cache, export.ExportCache, saves each time) and prints
the seconds of each stage: Blender's own depsgraph evaluation, the export's parts (meshes read
from Blender, their arrays, materials, lights, world, camera, add_mesh), the library's scene
commit, the bake, and writing and loading the result. --profile FILE writes cProfile's listing
of the first bake's export (sorted by cumulative time) to FILE. Nothing is asserted: the figures
are for docs/speed.md, measured on whatever else the machine runs.
"""
import argparse
import cProfile
import io
import os
import pstats
import sys
import tempfile
import time
from pathlib import Path

import bpy

SOURCE = Path(__file__).resolve().parent.parent
for folder in (SOURCE / "python_shim", SOURCE / "blender_addon"):
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))

import dwivedi  # noqa: E402
import dwivedi_bake  # noqa: E402
from dwivedi_bake import export  # noqa: E402


def arguments():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="profile_export.py")
    parser.add_argument("--objects", type=int, default=2, help="how many Suzannes (default 2)")
    parser.add_argument("--level", type=int, default=3, help="their Subdivision Surface level (default 3)")
    parser.add_argument("--size", type=int, default=32, help="the bake's width and height (default 32)")
    parser.add_argument("--samples", type=int, default=1, help="samples per pixel (default 1)")
    parser.add_argument("--repeat", type=int, default=4, help="bakes in a row (default 4: cold, unchanged, a light "
                        "changed, a modifier changed)")
    parser.add_argument("--profile", type=Path, default=None, help="cProfile listing of the first export")
    return parser.parse_args(argv)


def material(name, color):
    out = bpy.data.materials.new(name)
    out.use_nodes = True
    node = out.node_tree.nodes["Principled BSDF"]
    node.inputs["Base Color"].default_value = (*color, 1.0)
    weight = node.inputs.get("Subsurface Weight") or node.inputs["Subsurface"]
    weight.default_value = 1.0 if weight.name == "Subsurface Weight" else 0.2
    node.inputs["Subsurface Radius"].default_value = (0.05, 0.03, 0.02)
    return out


def build(objects, level):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    skin, lips = material("skin", (0.9, 0.6, 0.5)), material("lips", (0.8, 0.3, 0.3))
    for k in range(objects):
        bpy.ops.mesh.primitive_monkey_add(size=0.4, location=((k % 4 - 1.5) * 0.5, 0.0, (k // 4) * 0.5))
        obj = bpy.context.active_object
        bpy.ops.object.shade_smooth()
        obj.data.materials.append(skin)
        if k % 2:
            obj.data.materials.append(lips)
            indices = [i % 2 for i in range(len(obj.data.polygons))]
            obj.data.polygons.foreach_set("material_index", indices)
        modifier = obj.modifiers.new("subdivision", 'SUBSURF')
        modifier.levels = modifier.render_levels = level
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", 'SUN'))
    sun.rotation_euler = (0.6, 0.0, 0.4)
    scene.collection.objects.link(sun)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.location = (0.0, -4.0, 0.3)
    camera.rotation_euler = (1.5, 0.0, 0.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    world = bpy.data.worlds.new("world")
    world.color = (0.05, 0.05, 0.05)
    world.use_nodes = False
    scene.world = world
    return scene


class Stages:
    """Seconds spent in the export's parts, by wrapping the functions that do them."""

    WRAPPED = {"mesh arrays": (export, "_mesh_arrays"), "materials": (export, "material_from_blender"),
               "texture uses": (export, "texture_uses"), "lights": (export, "_light"),
               "world": (export, "world_from_blender"), "camera": (export, "camera_from_blender"),
               "evaluated inputs": (export, "_evaluate_inputs"), "add_mesh": (dwivedi.Scene, "add_mesh"),
               "scene commit (library)": (dwivedi.Scene, "commit"), "export_scene": (export, "export_scene"),
               "bake (library)": (dwivedi, "bake")}

    def __init__(self):
        self.seconds = {}
        self.saved = []
        for label, (owner, name) in self.WRAPPED.items():
            original = getattr(owner, name)
            self.saved.append((owner, name, original))
            setattr(owner, name, self._timed(label, original))

    def _timed(self, label, function):
        def timed(*args, **kwargs):
            start = time.perf_counter()
            try:
                return function(*args, **kwargs)
            finally:
                self.seconds[label] = self.seconds.get(label, 0.0) + time.perf_counter() - start
        return timed

    def restore(self):
        for owner, name, original in self.saved:
            setattr(owner, name, original)


def main():
    args = arguments()
    scene = build(args.objects, args.level)
    start = time.perf_counter()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    depsgraph.update()
    evaluation = time.perf_counter() - start
    triangles = 0
    for obj in scene.objects:
        if obj.type == 'MESH':
            mesh = obj.evaluated_get(depsgraph).to_mesh()
            mesh.calc_loop_triangles()
            triangles += len(mesh.loop_triangles)
            obj.evaluated_get(depsgraph).to_mesh_clear()
    dwivedi_bake.register()
    props = scene.dwivedi_bake
    props.samples, props.threads, props.seed, props.load_result = args.samples, 2, 1, False
    props.output_dir = tempfile.mkdtemp(prefix="dwivedi-profile-")
    scene.render.resolution_x = scene.render.resolution_y = args.size
    scene.render.resolution_percentage = 100
    print(f"profile_export: Blender {bpy.app.version_string}, {args.objects} Suzannes at level {args.level}: "
          f"{triangles} triangles; depsgraph evaluation {evaluation:.3f} s; bake {args.size} x {args.size}, "
          f"{args.samples} spp, 2 threads")
    changes = [("cold", None), ("unchanged", None),
               ("sun changed (meshes kept, the scene committed again)",
                lambda: setattr(bpy.data.lights["sun"], "energy", 2.0)),
               ("one object's modifier changed (that mesh read again)",
                lambda: setattr(bpy.data.objects["Suzanne"].modifiers[0], "levels", args.level))]
    for turn in range(args.repeat):
        label, change = changes[min(turn, len(changes) - 1)]
        if change is not None:
            if turn == 3:  # the modifier's viewport level: its render level stays, so the bake is the same size
                bpy.data.objects["Suzanne"].modifiers[0].levels = max(0, args.level - 1)
            else:
                change()
        stages = Stages()
        profile = cProfile.Profile() if args.profile is not None and turn == 0 else None
        start = time.perf_counter()
        if profile is not None:
            profile.enable()
        result = bpy.ops.dwivedi.bake()
        if profile is not None:
            profile.disable()
        whole = time.perf_counter() - start
        stages.restore()
        if result != {'FINISHED'}:
            raise SystemExit(f"profile_export: the bake returned {result}")
        seconds = stages.seconds
        inner = sum(v for k, v in seconds.items() if k not in ("export_scene", "scene commit (library)",
                                                                 "bake (library)", "evaluated inputs"))
        rest = seconds.get("export_scene", 0.0) - inner - seconds.get("scene commit (library)", 0.0) \
            - seconds.get("evaluated inputs", 0.0)
        print(f"bake {turn + 1} ({label}): whole operator {whole:.3f} s")
        for label in ("evaluated inputs", "mesh arrays", "materials", "texture uses", "lights", "world", "camera",
                      "add_mesh", "scene commit (library)"):
            print(f"  {label:40s} {seconds.get(label, 0.0):8.3f} s")
        print(f"  {'export, rest (to_mesh, depsgraph walk)':40s} {rest:8.3f} s")
        print(f"  {'export_scene in all':40s} {seconds.get('export_scene', 0.0):8.3f} s")
        print(f"  {'bake (library)':40s} {seconds.get('bake (library)', 0.0):8.3f} s")
        print(f"  {'files, result image, rest of operator':40s} "
              f"{whole - seconds.get('export_scene', 0.0) - seconds.get('bake (library)', 0.0):8.3f} s")
        if profile is not None:
            text = io.StringIO()
            pstats.Stats(profile, stream=text).sort_stats("cumulative").print_stats(40)
            args.profile.write_text(text.getvalue())
            print(f"  cProfile listing: {args.profile}")
    sys.stdout.flush()


main()
