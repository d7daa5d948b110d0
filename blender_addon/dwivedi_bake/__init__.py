"""Dwivedi Subsurface Bake: bakes subsurface scattering (Dwivedi-guided random walks, the dwivedi
library) from Blender's scene, as the camera sees it or into an object's UV texture.

Settings: Properties editor > Render > "Dwivedi Subsurface Bake" (scene.dwivedi_bake). The
operator bpy.ops.dwivedi.bake() exports the evaluated scene, bakes it (modal with a progress bar
and Esc to cancel in the UI; blocking in background mode), writes an OpenEXR and a PNG through
the scene's colour management into the output folder and loads the EXR as a Blender image.
"""
from __future__ import annotations

bl_info = {
    "name": "Dwivedi Subsurface Bake",
    "author": "dwivedi developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Render > Dwivedi Subsurface Bake",
    "description": "Bake random-walk subsurface scattering with Dwivedi-guided walks (Cycles-compatible)",
    "category": "Render",
}

import os
import traceback

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty

from . import export, libcheck

TECHNIQUES = [
    ('AUTO', "Auto", "Chosen per scene: incident-illumination guiding with a classical share"),
    ('CLASSICAL', "Classical", "Analog phase-function and free-flight sampling"),
    ('POE', "Entry Normal", "Dwivedi sampling about the entry point's normal (Krivanek, d'Eon 2014)"),
    ('CLOSEST', "Closest Point", "Dwivedi sampling about the closest surface point's normal (Meng 2016)"),
    ('INCIDENT', "Incident Illumination", "Dwivedi sampling toward lit surface patches (Meng 2016)"),
    ('BACKWARD', "Backward", "Entry normal or an opposite interface, by depth (as Cycles)"),
    ('CYCLES', "Cycles Mixture", "Cycles' own mixture: half classical, half backward-guided"),
    ('SHEET', "Thin Sheet", "Toward the lit side through a thin sheet (leaves, ears, paper): importance linear in depth"),
]

# dwv_channel_walks_t (capi/dwivedi.h): how walks carry the three colour channels of a medium whose
# channels differ; a grey medium walks once whichever is chosen.
CHANNEL_WALKS = [
    ('AUTO', "Auto", "Shared for an explicit technique; with technique Auto the bake's pilot chooses per mesh"),
    ('SHARED', "Shared", "One walk carries all three colour channels, weighted by spectral MIS (as Cycles)"),
    ('SEPARATE', "Separate", "One walk per colour channel, each in that channel's own medium: less colour noise "
                             "where the channels' radii differ, for more walks per sample"),
]


# The module name differs by how the add-on is installed: "dwivedi_bake" as a legacy add-on
# (Blender 3.x, or 4.x's Install legacy add-on), "bl_ext.<repository>.dwivedi_bake" as an
# extension (4.2+). Preferences are looked up by it, never by a hard-coded name.
ADDON_NAME = __package__ or __name__
PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__))
# The library the packages bundle (tools/package_addon.py), beside the bundled shim.
BUNDLED_LIBRARY = os.path.join(PACKAGE_DIR, "dwivedi", "libdwivedi.so.1")
# Set on every copy of this add-on that is registered: a second copy (the legacy add-on and the
# extension, or two folders) finds the first by it and refuses to register.
_DWIVEDI_BAKE_REGISTERED = False


def is_extension():
    return ADDON_NAME.startswith("bl_ext.")


def _import_shim():
    try:
        from . import dwivedi  # bundled by tools/package_addon.py
    except ImportError:
        if is_extension():  # an extension imports only what it carries
            raise
        import dwivedi  # a development checkout (legacy add-on) with python_shim on sys.path
    return dwivedi


class LibraryStatus:
    """The outcome of the last library check: ok with the path and version in use, or the problem."""

    def __init__(self, ok, message, path=None, version=None):
        self.ok = ok
        self.message = message
        self.path = path
        self.version = version


_status = None        # LibraryStatus of the last check
_status_key = None    # (path, identity of the file) it was made for
_loaded_identity = {}  # path -> (device, inode, size, mtime) of the file when it was loaded


def _wanted_library():
    """(path, where from) of the library to use: the preferences' file, else the bundled one,
    else (a development checkout without one) None for the shim's own search."""
    prefs = preferences()
    wanted = prefs.library_path.strip() if prefs is not None else ""
    if wanted:
        return os.path.abspath(bpy.path.abspath(wanted)), "the library named in the add-on preferences"
    if os.path.isdir(os.path.join(PACKAGE_DIR, "dwivedi")) or not _shim_on_path():
        return BUNDLED_LIBRARY, "the add-on's bundled library"
    return None, "the shim's search"


def _shim_on_path():
    try:
        import importlib.util
        return importlib.util.find_spec("dwivedi") is not None
    except (ImportError, ValueError):
        return False


def check_library():
    """Checks the library the add-on would use and loads it; returns (and keeps) a LibraryStatus.
    Never raises: every problem becomes the status' message (see libcheck)."""
    global _status, _status_key
    _status_key = _current_key()
    try:
        _status = _check_library()
    except Exception as error:  # a bug here must not take the panel down
        traceback.print_exc()
        _status = LibraryStatus(False, f"the library check failed: {error}")
    return _status


def _check_library():
    dwivedi = _import_shim()
    path, origin = _wanted_library()
    if path is None:
        try:
            found = dwivedi.library_path()
            return LibraryStatus(True, f"libdwivedi {dwivedi.version()} ({found})", found, dwivedi.version())
        except Exception as error:
            return LibraryStatus(False, str(error).splitlines()[0])
    problem = libcheck.check_file(path, dwivedi.ABI_VERSION, dwivedi.LIBRARY_FUNCTIONS)
    if problem is not None:
        if problem.kind == "missing" and path == BUNDLED_LIBRARY:
            problem.message += " (the add-on package is incomplete: install it again)"
        return LibraryStatus(False, f"{origin}: {problem.message}", path)
    identity = libcheck.file_identity(path)
    if dwivedi.loaded_library_path() == path:
        if path in _loaded_identity and _loaded_identity[path] != identity:
            return LibraryStatus(False, f"{origin}: {path} was replaced since Blender loaded it: restart Blender "
                                        "to use the new file", path)
    else:
        try:
            dwivedi.use_library(path)
        except dwivedi.Error as error:  # the loader's own message, e.g. a missing dependency
            return LibraryStatus(False, f"{origin}: {str(error).splitlines()[0]}", path)
        _loaded_identity[path] = identity
    try:
        version = dwivedi.version()
    except Exception as error:
        return LibraryStatus(False, f"{origin}: {path} loads but does not answer: {error}", path)
    return LibraryStatus(True, f"libdwivedi {version} ({path})", path, version)


def _current_key():
    try:
        path = _wanted_library()[0]
    except Exception:
        return None
    return path, libcheck.file_identity(path) if path else None


def library_status():
    """The last check's status, checked again when there was none or when the file (or the
    preferences' choice) changed since (one stat per call: cheap enough for every redraw)."""
    if _status is None or _current_key() != _status_key:
        return check_library()
    return _status


def shim():
    """The dwivedi Python shim with the checked library loaded; ExportError saying what is wrong
    with the library otherwise (the bake operator reports it)."""
    status = check_library()
    if not status.ok:
        raise export.ExportError(f"the dwivedi library cannot be used: {status.message}")
    return _import_shim()


def preferences():
    addon = bpy.context.preferences.addons.get(ADDON_NAME)
    return addon.preferences if addon is not None else None


def draw_status(layout):
    """The library's state in a panel: its version, or the problem with an ERROR icon."""
    status = library_status()
    if status.ok:
        layout.label(text=status.message, icon='CHECKMARK')
        return
    box = layout.box()
    box.label(text="dwivedi library not usable:", icon='ERROR')
    for line in _wrap(status.message, 70):
        box.label(text=line)


def _wrap(text, width):
    words, lines, line = text.split(), [], ""
    for word in words:
        if line and len(line) + 1 + len(word) > width:
            lines.append(line)
            line = word
        else:
            line = f"{line} {word}" if line else word
    return lines + ([line] if line else [])


def _library_path_changed(self, context):
    check_library()


class DwivediBakePreferences(bpy.types.AddonPreferences):
    bl_idname = ADDON_NAME

    library_path: StringProperty(
        name="Library",
        description="libdwivedi.so.1 to use; empty: the one bundled with the add-on (or found on the system)",
        subtype='FILE_PATH', default="", update=_library_path_changed)

    def draw(self, context):
        layout = self.layout
        layout.prop(self, "library_path")
        draw_status(layout)


def _poll_mesh(self, obj):
    return obj.type == 'MESH'


class DwivediBakeSettings(bpy.types.PropertyGroup):
    target: EnumProperty(name="Target", default='CAMERA', items=[
        ('CAMERA', "Camera", "The active camera's view at the render resolution"),
        ('UV', "UV", "The outgoing subsurface radiance of one object laid out in its UV map")])
    technique: EnumProperty(name="Technique", items=TECHNIQUES, default='AUTO')
    channel_walks: EnumProperty(name="Channel Walks", items=CHANNEL_WALKS, default='AUTO',
                                description="How the walks carry the red, green and blue channels")
    samples: IntProperty(name="Samples", description="Samples per pixel (the bake stops there)",
                         default=64, min=0, soft_min=1, max=1 << 24)
    time_limit: FloatProperty(name="Time Limit", description="Seconds; 0: no limit", default=0.0, min=0.0,
                              subtype='TIME_ABSOLUTE' if bpy.app.version >= (3, 0, 0) else 'NONE', unit='TIME')
    target_error: FloatProperty(name="Target Error", description="Relative error of the image to stop at; 0: none",
                                default=0.0, min=0.0, max=1.0, precision=4)
    threads: IntProperty(name="Threads", description="0: all cores", default=0, min=0, max=1024)
    seed: IntProperty(name="Seed", default=0, min=0)
    walk_event_cap: IntProperty(name="Walk Event Cap", default=0, min=0, description=(
        "Scattering events per walk at most; 0: 10^6 (dwivedi keeps the light Cycles loses on thick, high-albedo "
        "objects); 256: Cycles' own cap (BSSRDF_MAX_BOUNCES), to match its render there"))
    output_dir: StringProperty(name="Output Folder", description="Where the EXR and PNG are written",
                               default="//dwivedi_bake/", subtype='DIR_PATH')
    uv_object: PointerProperty(name="UV Object", type=bpy.types.Object, poll=_poll_mesh,
                               description="The mesh whose UV map the UV bake fills")
    uv_size: IntProperty(name="Image Size", description="Width and height of the UV texture", default=1024,
                         min=1, max=16384)
    uv_margin: IntProperty(name="Margin", description="Pixels of dilation around UV islands", default=16,
                           min=0, max=64)
    load_result: BoolProperty(name="Load Result", description="Load the baked EXR as a Blender image",
                              default=True)
    texture_bake_size: IntProperty(name="Texture Bake Size", default=256, min=8, max=8192, description=(
        "Width and height of the images into which Blender evaluates material inputs driven by node trees "
        "other than an Image Texture (procedural textures, Mapping...)"))
    # Runtime state shown in the panel while a bake runs.
    running: BoolProperty(default=False, options={'SKIP_SAVE'})
    progress: FloatProperty(name="Progress", default=0.0, min=0.0, max=100.0, subtype='PERCENTAGE',
                            options={'SKIP_SAVE'})
    last_result: StringProperty(default="", options={'SKIP_SAVE'})
    # The last bake's warnings, one a line (what was not modelled, such as this Blender's own
    # subsurface model); also reported to the Info log.
    last_warnings: StringProperty(default="", options={'SKIP_SAVE'})


def output_folder(settings):
    """The output folder as an absolute path: relative to the .blend ("//"), or to Blender's
    temporary folder for an unsaved file."""
    raw = settings.output_dir.strip() or "//dwivedi_bake/"
    if raw.startswith("//") and not bpy.data.filepath:
        return os.path.join(unsaved_file_folder(), raw[2:])
    return os.path.abspath(bpy.path.abspath(raw))


def unsaved_file_folder():
    """Where "//" points for an unsaved file: the extension's own user folder on Blender 4.2+
    (bpy.utils.extension_path_user, never the package folder), else Blender's temporary folder."""
    if is_extension() and hasattr(bpy.utils, "extension_path_user"):
        try:
            return bpy.utils.extension_path_user(ADDON_NAME, path="bakes", create=True)
        except (ValueError, OSError):
            pass
    return bpy.app.tempdir or os.path.realpath("/tmp")


def _check_folder(folder):
    try:
        os.makedirs(folder, exist_ok=True)
    except OSError as error:
        raise export.ExportError(f"cannot create the output folder {folder}: {error.strerror}") from None
    if not os.path.isdir(folder) or not os.access(folder, os.W_OK | os.X_OK):
        raise export.ExportError(f"the output folder {folder} is not writable")


def _safe_name(name):
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name) or "scene"


class _Job:
    """One bake: the exported scene, the running dwivedi bake and where its files go."""

    def __init__(self, context, settings):
        self.dwivedi = shim()
        if settings.samples < 1:
            raise export.ExportError(f"Samples is {settings.samples}: a bake needs at least 1 sample per pixel")
        self.folder = output_folder(settings)
        _check_folder(self.folder)
        self.exported = export.export_scene(context, settings, self.dwivedi)
        scene = context.scene
        stem = _safe_name(scene.name) + ("_camera" if settings.target == 'CAMERA'
                                         else "_uv_" + _safe_name(settings.uv_object.name))
        self.exr = os.path.join(self.folder, stem + ".exr")
        self.png = os.path.join(self.folder, stem + ".png")
        self.bake_settings = self.dwivedi.BakeSettings(
            target=settings.target.lower(), width=self.exported.width, height=self.exported.height,
            uv_mesh=self.exported.uv_mesh, uv_margin=settings.uv_margin, technique=settings.technique.lower(),
            channel_walks=settings.channel_walks.lower(), samples=settings.samples, time_limit=settings.time_limit,
            target_error=settings.target_error, threads=settings.threads, seed=settings.seed,
            max_events=settings.walk_event_cap)
        self.display = display_settings(scene, self.dwivedi)
        self.bake = None
        self.notes = []

    def start(self):
        self.bake = self.dwivedi.start_bake(self.exported.scene, self.bake_settings)

    def finish(self, context, settings):
        """Writes the files and loads the image; returns a one-line summary."""
        image = self.bake.finish()
        try:
            image.write_exr(self.exr)
            try:
                image.write_png(self.png, self.display)
            except self.dwivedi.Error as error:
                # The library's OpenColorIO cannot read this Blender's config (Blender 5.2 ships an
                # OCIO 2.5 config, the library has 2.1): the PNG through Blender's own colour
                # management instead (Image.save_render with the scene's view settings).
                if "OCIO" not in str(error) and "config" not in str(error):
                    raise
                png_through_blender(image, context.scene, self.png)
                self.notes.append("the PNG was made by Blender's colour management (the library's OpenColorIO "
                                  "cannot read this Blender's config)")
            stats = image.stats
            if settings.load_result:
                blender_image(image, "Dwivedi " + ("Camera" if settings.target == 'CAMERA' else "UV"), self.exr)
        finally:
            image.close()
            self.close()
        # Degenerate geometry the library met (zero-area, non-finite or too distant triangles, open
        # meshes, backs of faces): said in the summary, so that a left-out mesh is not a mystery.
        degenerate = f", {stats.warnings} geometry warnings" if stats.warnings else ""
        # The technique asked for and whether the walks carried the colour channels apart (the
        # Channel Walks setting, or auto's choice per mesh), which the setting alone does not say.
        walks = stats.technique + (" with channel walks" if "channel_walks" in stats.features else "")
        notes = "".join(f" ({note})" for note in self.notes)
        return (f"Dwivedi bake: {self.exported.width} x {self.exported.height}, {stats.samples_per_pixel} spp, "
                f"{stats.seconds:.2f} s, est. error {stats.estimated_relative_error:.2%}, {walks}{degenerate} -> "
                f"{self.exr}{notes}")

    def close(self):
        if self.bake is not None:
            self.bake.close()
            self.bake = None
        if self.exported.scene is not None:
            self.exported.scene.close()
            self.exported.scene = None


def png_through_blender(image, scene, path):
    """Writes `image` as an 8-bit PNG through Blender's colour management (the scene's display,
    view, look, exposure, gamma), as Image.save_render does."""
    target = blender_image(image, "Dwivedi PNG (temporary)", path)
    settings = scene.render.image_settings
    saved = (settings.file_format, settings.color_mode, settings.color_depth)
    try:
        settings.file_format = 'PNG'
        settings.color_mode = 'RGBA'
        settings.color_depth = '8'
        target.save_render(path, scene=scene)
    finally:
        settings.file_format, settings.color_mode, settings.color_depth = saved
        bpy.data.images.remove(target)


def display_settings(scene, dwivedi):
    """The scene's colour management as dwivedi.DisplaySettings, with Blender's own OCIO config."""
    view = scene.view_settings
    look = view.look
    return dwivedi.DisplaySettings(config=export.ocio_config_path(), display=scene.display_settings.display_device,
                                   view=view.view_transform, look=None if look in ("", "None") else look,
                                   exposure=view.exposure, gamma=view.gamma)


def blender_image(image, name, path):
    """The baked pixels as a float Blender image `name` (made again if its size changed), in
    scene-linear colour, with `path` as its file for Image > Save. Made from memory rather than by
    loading the EXR, so that one named image is updated in place bake after bake (a loaded file
    would be a new datablock, or a reload of a file the next bake replaces); the EXR itself loads
    in Blender too, with the same pixels (tests/blender/test_addon.py checks it)."""
    import array
    width, height = image.width, image.height
    target = bpy.data.images.get(name)
    if target is not None and (tuple(target.size) != (width, height) or not target.is_float
                               or target.source != 'GENERATED'):
        bpy.data.images.remove(target)
        target = None
    if target is None:
        target = bpy.data.images.new(name, width, height, alpha=True, float_buffer=True)
    for colorspace in ("Linear Rec.709", "Linear"):  # Blender 4.x, 3.x names of scene linear
        try:
            target.colorspace_settings.name = colorspace
            break
        except TypeError:
            continue
    raw = image.rgba.cast("B")  # rows of 16 x width bytes, row 0 at the top; Blender's is the bottom
    stride = 16 * width
    flipped = array.array("f")
    flipped.frombytes(b"".join(raw[y * stride:(y + 1) * stride] for y in range(height - 1, -1, -1)))
    target.pixels.foreach_set(flipped)
    target.filepath_raw = path
    target.file_format = 'OPEN_EXR'
    target.update()
    return target


class DWIVEDI_OT_bake(bpy.types.Operator):
    """Bake subsurface scattering with dwivedi (Esc cancels)"""
    bl_idname = "dwivedi.bake"
    bl_label = "Dwivedi Subsurface Bake"
    bl_options = {'REGISTER'}

    _timer = None
    _job = None

    def _fail(self, context, error):
        message = str(error) or type(error).__name__
        if not isinstance(error, (export.ExportError, ValueError, OSError, TypeError)):
            traceback.print_exc()
        self.report({'ERROR'}, f"Dwivedi bake failed: {message}")
        settings = context.scene.dwivedi_bake
        settings.running = False
        settings.last_result = message.splitlines()[0] if message else ""
        return {'CANCELLED'}

    def execute(self, context):
        settings = context.scene.dwivedi_bake
        job = None
        try:
            settings.last_warnings = ""
            job = _Job(context, settings)
            settings.last_warnings = "\n".join(job.exported.warnings)
            for warning in job.exported.warnings:
                self.report({'WARNING'}, warning)
            image = job.dwivedi.bake(job.exported.scene, job.bake_settings)
            job.bake = _Finished(image)
            summary = job.finish(context, settings)
        except KeyboardInterrupt:
            if job is not None:
                job.close()
            self.report({'WARNING'}, "Dwivedi bake cancelled")
            return {'CANCELLED'}
        except Exception as error:  # every failure is reported, none escapes into Blender
            if job is not None:
                job.close()
            return self._fail(context, error)
        settings.last_result = summary
        self.report({'INFO'}, summary)
        return {'FINISHED'}

    def invoke(self, context, event):
        if bpy.app.background:
            return self.execute(context)
        settings = context.scene.dwivedi_bake
        if settings.running:
            self.report({'ERROR'}, "a Dwivedi bake is already running")
            return {'CANCELLED'}
        try:
            settings.last_warnings = ""
            self._job = _Job(context, settings)
            settings.last_warnings = "\n".join(self._job.exported.warnings)
            for warning in self._job.exported.warnings:
                self.report({'WARNING'}, warning)
            self._job.start()
        except Exception as error:
            if self._job is not None:
                self._job.close()
                self._job = None
            return self._fail(context, error)
        settings.running = True
        settings.progress = 0.0
        settings.last_result = "baking..."
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.progress_begin(0, 100)
        wm.modal_handler_add(self)
        return {'RUNNING_MODAL'}

    def _end(self, context):
        wm = context.window_manager
        if self._timer is not None:
            wm.event_timer_remove(self._timer)
            self._timer = None
        wm.progress_end()
        context.scene.dwivedi_bake.running = False
        if context.area is not None:
            context.area.tag_redraw()
        for window in wm.windows:
            for area in window.screen.areas:
                if area.type == 'PROPERTIES':
                    area.tag_redraw()

    def modal(self, context, event):
        settings = context.scene.dwivedi_bake
        job = self._job
        try:
            if event.type == 'ESC':
                job.bake.cancel()
                job.bake.wait(1.0)
                job.close()
                self._end(context)
                settings.last_result = "cancelled"
                self.report({'WARNING'}, "Dwivedi bake cancelled")
                return {'CANCELLED'}
            if event.type != 'TIMER':
                return {'PASS_THROUGH'}
            progress = job.bake.progress()
            settings.progress = 100.0 * progress.fraction
            context.window_manager.progress_update(int(100 * progress.fraction))
            if context.area is not None:
                context.area.tag_redraw()
            for window in context.window_manager.windows:
                for area in window.screen.areas:
                    if area.type == 'PROPERTIES':
                        area.tag_redraw()
            if not progress.done:
                return {'RUNNING_MODAL'}
            summary = job.finish(context, settings)
        except Exception as error:
            job.close()
            self._end(context)
            return self._fail(context, error)
        self._end(context)
        settings.last_result = summary
        self.report({'INFO'}, summary)
        return {'FINISHED'}

    def cancel(self, context):
        # Blender ends the modal operator (file load, quit): stop the bake, free everything.
        if self._job is not None:
            self._job.close()
        self._end(context)


class _Finished:
    """A finished bake's image in the shape of a running bake (execute() bakes in one call)."""

    def __init__(self, image):
        self._image = image

    def finish(self):
        return self._image

    def close(self):
        pass


class DWIVEDI_PT_bake(bpy.types.Panel):
    bl_label = "Dwivedi Subsurface Bake"
    bl_idname = "DWIVEDI_PT_bake"
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = "render"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        settings = context.scene.dwivedi_bake
        status = library_status()
        if not status.ok:
            draw_status(layout)
        layout.prop(settings, "target", expand=True)
        if settings.target == 'UV':
            layout.prop(settings, "uv_object")
            layout.prop(settings, "uv_size")
            layout.prop(settings, "uv_margin")
        else:
            width, height = export.render_size(context.scene)
            layout.label(text=f"{width} x {height} (render resolution)")
        layout.prop(settings, "technique")
        layout.prop(settings, "channel_walks")
        col = layout.column(align=True)
        col.prop(settings, "samples")
        col.prop(settings, "time_limit")
        col.prop(settings, "target_error")
        layout.prop(settings, "threads")
        layout.prop(settings, "walk_event_cap")
        layout.prop(settings, "texture_bake_size")
        layout.prop(settings, "seed")
        layout.prop(settings, "output_dir")
        layout.prop(settings, "load_result")
        if settings.running:
            layout.prop(settings, "progress", slider=True)
            layout.label(text="Esc cancels", icon='INFO')
        else:
            layout.operator(DWIVEDI_OT_bake.bl_idname, icon='RENDER_STILL')
        if settings.last_result:
            layout.label(text=settings.last_result)
        for warning in settings.last_warnings.splitlines()[:4]:
            layout.label(text=warning, icon='ERROR' if warning.startswith("Blender ") else 'INFO')


CLASSES = (DwivediBakePreferences, DwivediBakeSettings, DWIVEDI_OT_bake, DWIVEDI_PT_bake)


def _other_copy():
    """(module name, folder) of another copy of this add-on that is registered, else None."""
    import sys
    for name, module in list(sys.modules.items()):
        if name != __name__ and getattr(module, "_DWIVEDI_BAKE_REGISTERED", False) is True:
            return name, os.path.dirname(getattr(module, "__file__", "") or "?")
    if hasattr(bpy.types.Scene, "dwivedi_bake") or hasattr(bpy.types, "DWIVEDI_OT_bake"):
        return "an unknown module", "?"
    return None


class AlreadyEnabled(RuntimeError):
    pass


def register():
    global _DWIVEDI_BAKE_REGISTERED
    other = _other_copy()
    if other is not None:
        # Two copies would register the same classes and Scene.dwivedi_bake: refuse before
        # registering anything, so the copy already enabled keeps working.
        raise AlreadyEnabled(f"Dwivedi Subsurface Bake is already enabled as '{other[0]}' ({other[1]}): disable "
                             f"that copy before enabling this one ('{ADDON_NAME}', {PACKAGE_DIR})")
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.dwivedi_bake = PointerProperty(type=DwivediBakeSettings)
    _DWIVEDI_BAKE_REGISTERED = True
    status = check_library()
    if not status.ok:
        # The panel shows it with an ERROR icon; the console says it once at enable.
        print(f"Dwivedi Subsurface Bake: the dwivedi library cannot be used: {status.message}")


def unregister():
    global _DWIVEDI_BAKE_REGISTERED, _status, _status_key
    if not _DWIVEDI_BAKE_REGISTERED:
        return
    del bpy.types.Scene.dwivedi_bake
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
    _DWIVEDI_BAKE_REGISTERED = False
    _status = None
    _status_key = None
