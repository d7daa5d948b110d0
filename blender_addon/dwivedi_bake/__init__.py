"""Dwivedi Subsurface Bake: bakes subsurface scattering (Dwivedi-guided random walks, the dwivedi
library) from Blender's scene, as the camera sees it or into an object's UV texture.

Settings: Properties editor > Render > "Dwivedi Subsurface Bake" (scene.dwivedi_bake); the
operator is also in the Render menu (so F3 finds it). bpy.ops.dwivedi.bake() exports the evaluated
scene and bakes it, as Cycles' bake does: in the UI on the library's threads with the progress and
a cancel button in the status bar and the panel (Esc cancels too); blocking in background mode.
A camera bake is written as OpenEXR + PNG (the scene's colour management) into the output folder
and opened in an Image Editor as F12 shows a render; a UV bake fills the active Image Texture
node's image of the active object's material. The running bake is session state of this module,
never scene data: a .blend saved during a bake opens ready to bake.
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

from . import export, farm, libcheck, passes

# The techniques (dwv_technique_t), named and explained for artists: what each is good for, in one
# line; the research names (and papers) are in docs/ and the library's header.
TECHNIQUES = [
    ('AUTO', "Auto", "Best for most scenes: a short trial chooses per object how the walks are steered"),
    ('CLASSICAL', "Unguided", "Plain random walks, as in the textbooks: the reference, noisiest on thick, "
                              "bright materials"),
    ('POE', "Toward Entry Surface", "Walks steered back to the surface where light entered: flat, thick objects "
                                     "(Krivanek and d'Eon 2014)"),
    ('CLOSEST', "Toward Nearest Surface", "Walks steered to the nearest surface: curved and thin parts, such as "
                                          "ears, fingers, noses (Meng et al. 2016)"),
    ('INCIDENT', "Toward Light", "Walks steered to where light falls on the object: back-lit and strongly lit "
                                 "scenes (Meng et al. 2016)"),
    ('BACKWARD', "Entry or Far Side", "Steered to the entry surface or the far side, by depth, as Cycles steers: "
                                      "objects both thin and thick"),
    ('CYCLES', "As Cycles", "Cycles' own mix of unguided and steered walks: to compare with a Cycles render"),
    ('SHEET', "Thin Sheet", "Light passing through thin sheets: leaves, ears, paper, fabric"),
]

# dwv_channel_walks_t (capi/dwivedi.h): how walks carry the three colour channels of a medium whose
# channels differ; a grey medium walks once whichever is chosen.
CHANNEL_WALKS = [
    ('AUTO', "Auto", "Shared for a chosen technique; with technique Auto the trial chooses per object"),
    ('SHARED', "Shared", "One walk carries red, green and blue together (as Cycles): fastest"),
    ('SEPARATE', "Separate", "One walk per colour channel: less colour noise where the channel radii differ "
                             "much (skin), for more time per sample"),
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


def _blend_relative_path_options():
    """Blender 5.x warns on a "//" path unless the property says it takes one
    (PATH_SUPPORTS_BLEND_RELATIVE, unknown to older versions, which have no Property RNA field
    is_path_supports_blend_relative either): the option where it exists."""
    if "is_path_supports_blend_relative" in bpy.types.Property.bl_rna.properties:
        return {'PATH_SUPPORTS_BLEND_RELATIVE'}
    return set()


class DwivediBakeSettings(bpy.types.PropertyGroup):
    """The bake's settings, saved with the scene. Nothing about a running bake is here (see _Run)."""
    target: EnumProperty(name="Target", default='CAMERA', description="What is baked: the camera's view or a UV image",
                         items=[
        ('CAMERA', "Camera", "What the active camera sees, at the render resolution (like F12)"),
        ('UV', "UV", "The active object's subsurface light in its UV map, into the image of the active Image "
                     "Texture node of its material (like Cycles' Bake)")])
    technique: EnumProperty(name="Technique", items=TECHNIQUES, default='AUTO', description=(
        "How the walks are steered inside the material; Auto suits most scenes, the others are for special "
        "shapes and comparisons"))
    channel_walks: EnumProperty(name="Channel Walks", items=CHANNEL_WALKS, default='AUTO', description=(
        "Whether one walk carries the red, green and blue light together or each colour walks on its own"))
    samples: IntProperty(name="Samples", description="Samples per pixel: more is less noise and a longer bake",
                         default=64, min=0, soft_min=1, max=1 << 24)
    time_limit: FloatProperty(name="Time Limit", description="Stop after this time; 0: no limit", default=0.0,
                              min=0.0, subtype='TIME_ABSOLUTE' if bpy.app.version >= (3, 0, 0) else 'NONE',
                              unit='TIME')
    target_error: FloatProperty(name="Noise Threshold", default=0.0, min=0.0, max=1.0, precision=4, description=(
        "Stop once the estimated noise (relative error of the image) is below this; 0: no threshold"))
    threads: IntProperty(name="Threads", description="CPU threads for the bake; 0: all cores", default=0, min=0,
                         max=1024)
    seed: IntProperty(name="Seed", default=0, min=0, description=(
        "Changes the noise pattern: bakes with different seeds have independent noise, the same seed repeats it"))
    walk_event_cap: IntProperty(name="Walk Event Cap", default=0, min=0, description=(
        "Scattering events per walk at most; 0: 10^6 (keeps the light Cycles loses on thick, bright objects); "
        "256: Cycles' own cap, to match its render there"))
    output_dir: StringProperty(name="Output Folder", default="//dwivedi_bake/", subtype='DIR_PATH',
                               options=_blend_relative_path_options(), description=(
        "Where the baked EXR and PNG are saved (// is the .blend's folder)"))
    uv_margin: IntProperty(name="Margin", description="Pixels the bake extends past the UV islands' edges, so "
                           "that texture filtering does not bleed in the background", default=16, min=0, max=64)
    load_result: BoolProperty(name="Show Result", default=True, description=(
        "Open the camera bake in an Image Editor when it is done, as F12 shows a render"))
    world_resolution: IntProperty(name="World Resolution", default=1024, min=8, max=16384, description=(
        "Width of the image Cycles renders the world into when its nodes are not an Environment Texture "
        "(the height is half): larger keeps small bright lights sharp, and takes longer"))
    texture_bake_size: IntProperty(name="Texture Bake Size", default=256, min=8, max=8192, description=(
        "Width and height of the images into which Blender evaluates material inputs driven by node trees "
        "other than an Image Texture (procedural textures, Mapping...): larger keeps fine patterns, and takes longer"))


# ---------------------------------------------------------------------------------------------
# Session state: the running bake and the last bake's messages (never saved in the .blend)
# ---------------------------------------------------------------------------------------------

class _Run:
    """The bake running in this Blender session (at most one) and the last bake's messages.

    It lives in this module, not in scene properties: a .blend saved or autosaved during a bake
    holds none of it and opens ready to bake; a file load, disabling the add-on and Blender's own
    end of the modal operator all end it through stop()."""

    def __init__(self):
        self.job = None          # the _Job baking, None when idle
        self.timer = None        # the window manager's event timer of the modal operator
        self.window_manager = None
        self.fraction = 0.0      # 0..1, the library's progress
        self.cancel_requested = False
        self.level = 'INFO'      # the last message: INFO, WARNING (cancelled) or ERROR
        self.message = ""
        self.warnings = []       # the last bake's warnings, one a line
        self.context_key = None  # what the messages were about (see context_key())

    @property
    def running(self):
        return self.job is not None

    def say(self, level, message, context, warnings=None):
        self.level = level
        self.message = message
        if warnings is not None:
            self.warnings = list(warnings)
        self.context_key = context_key(context)

    def messages_for(self, context):
        """(level, message, warnings) when they are about the current context, else nothing:
        a message about another scene, target or object is stale."""
        if self.running or context_key(context) == self.context_key:
            return self.level, self.message, self.warnings
        return 'INFO', "", []

    def stop(self):
        """Cancels and frees the running bake: the library's threads are stopped and joined
        (dwv_bake_release waits for them) and the timer removed. Safe to call at any time."""
        job, self.job = self.job, None
        if job is not None:
            try:
                if job.bake is not None:
                    job.bake.cancel()
            finally:
                job.close()
        timer, self.timer = self.timer, None
        if timer is not None and self.window_manager is not None:
            try:
                self.window_manager.event_timer_remove(timer)
            except (ReferenceError, RuntimeError, ValueError):
                pass  # the window manager went with a file load
        self.window_manager = None
        self.fraction = 0.0
        self.cancel_requested = False
        redraw()


_RUN = _Run()


def context_key(context):
    """What a message is about: the scene, the target, and for a UV bake the object."""
    scene = getattr(context, "scene", None)
    if scene is None or not hasattr(scene, "dwivedi_bake"):
        return None
    settings = scene.dwivedi_bake
    obj = _uv_object(context) if settings.target == 'UV' else None
    return scene.name_full, settings.target, obj.name_full if obj is not None else None


def redraw(status_bar=True):
    """Redraws the panels and the status bars that show the bake's state. Python cannot reach
    the status bar's area (a global area, not in screen.areas) to tag it, and it redraws on
    job notifiers only; WorkSpace.status_text_set(None) (no text of its own: the default status)
    is what tags it for a redraw, so it is called when the shown percentage changes."""
    wm = getattr(bpy.context, "window_manager", None)
    if wm is None:
        return
    for window in wm.windows:
        screen = window.screen
        if screen is None:
            continue
        for area in screen.areas:
            if area.type in {'PROPERTIES', 'IMAGE_EDITOR'}:
                area.tag_redraw()
        if status_bar and window.workspace is not None and hasattr(bpy.context, "temp_override"):
            try:
                # 4.2+'s status_text_set wrapper also swaps the status bar's draw function back
                # to the one it first saw; the RNA function under it only clears and tags.
                workspace = window.workspace
                clear = getattr(workspace, "status_text_set_internal", None) or workspace.status_text_set
                with bpy.context.temp_override(window=window):
                    clear(None)
            except (RuntimeError, TypeError):
                pass


def _progress_percent(_self):
    return 100.0 * _RUN.fraction


def draw_progress(layout, text):
    """The running bake's progress as a bar that cannot be dragged (layout.progress where Blender
    has it, 4.0+; else a read-only percentage property drawn as a slider), with a cancel button."""
    row = layout.row(align=True)
    if hasattr(row, "progress"):
        row.progress(factor=_RUN.fraction, type='BAR', text=f"{text} {100.0 * _RUN.fraction:.0f}%")
    else:
        row.prop(bpy.context.window_manager, "dwivedi_bake_progress", text=text, slider=True)
    row.operator(DWIVEDI_OT_bake_cancel.bl_idname, text="", icon='CANCEL')


def draw_status_bar(self, context):
    """Appended to the status bar (STATUSBAR_HT_header), as Cycles' bake job shows there."""
    if _RUN.running:
        draw_progress(self.layout, "Dwivedi Bake")


def draw_render_menu(self, context):
    """Appended to the Render menu (TOPBAR_MT_render): the menu search (F3) finds the bake there."""
    self.layout.separator()
    self.layout.operator(DWIVEDI_OT_bake.bl_idname, text="Dwivedi Subsurface Bake", icon='RENDER_STILL')


# ---------------------------------------------------------------------------------------------
# What is baked, and where it goes
# ---------------------------------------------------------------------------------------------

def _uv_object(context):
    """The object a UV bake bakes: the active object if it is a mesh, else the first selected
    mesh (Cycles bakes the selected objects; the active one is the usual single target)."""
    active = getattr(context, "active_object", None)
    if active is not None and active.type == 'MESH':
        return active
    for obj in getattr(context, "selected_objects", None) or ():
        if obj.type == 'MESH':
            return obj
    return None


def uv_target(context):
    """(object, image) of a UV bake, as Cycles finds them: the active (or a selected) mesh, and
    the image of the active Image Texture node of its active material; ExportError saying what
    to do when there is none."""
    obj = _uv_object(context)
    if obj is None:
        raise export.ExportError("select the mesh to bake (a UV bake bakes the active object)")
    material = obj.active_material
    if material is None or not material.use_nodes or material.node_tree is None:
        raise export.ExportError(f"'{obj.name}' has no node material: a UV bake writes into the image of the "
                                 "active Image Texture node of its material")
    node = material.node_tree.nodes.active
    if node is None or node.type != 'TEX_IMAGE':
        raise export.ExportError(f"material '{material.name}' of '{obj.name}' has no active Image Texture node: "
                                 "add one (Shader Editor), give it an image and click it to make it active, as for "
                                 "Cycles' Bake")
    image = node.image
    if image is None:
        raise export.ExportError(f"the active Image Texture node of material '{material.name}' has no image: "
                                 "give it one (New, 32-bit Float) to bake into")
    width, height = image.size
    if width < 1 or height < 1:
        raise export.ExportError(f"image '{image.name}' has no pixels (its file cannot be read?): reload it or "
                                 "make a new one")
    return obj, image


def output_folder(settings):
    """The output folder as an absolute path; ExportError for a relative one ("//") in a file
    that was never saved (the UI asks for a folder instead; a script must name one)."""
    raw = settings.output_dir.strip() or "//dwivedi_bake/"
    if raw.startswith("//") and not bpy.data.filepath:
        raise export.ExportError("the .blend is not saved, so the Output Folder (//, the .blend's folder) is "
                                 "nowhere: save the file or choose an Output Folder")
    return os.path.abspath(bpy.path.abspath(raw))


def lost_at_quit(folder):
    """A warning when `folder` is in Blender's session temporary folder, which Blender deletes at
    quit (Cycles' own results there would be lost the same way)."""
    if not bpy.app.tempdir:
        return None
    base = os.path.realpath(bpy.app.tempdir)
    real = os.path.realpath(folder)
    if real == base or real.startswith(base + os.sep):
        return (f"the output folder {folder} is Blender's temporary folder, which Blender deletes at quit: "
                "choose another Output Folder to keep the images")
    return None


def _check_folder(folder):
    try:
        os.makedirs(folder, exist_ok=True)
    except OSError as error:
        raise export.ExportError(f"cannot create the output folder {folder}: {error.strerror}") from None
    if not os.path.isdir(folder) or not os.access(folder, os.W_OK | os.X_OK):
        raise export.ExportError(f"the output folder {folder} is not writable")


def _safe_name(name):
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name) or "scene"


def readable(warning):
    """A warning with Blender's identifiers of subsurface methods replaced by the names Blender
    shows for them (RANDOM_WALK -> Random Walk)."""
    import re
    names = {}
    for node_type in ("ShaderNodeBsdfPrincipled", "ShaderNodeSubsurfaceScattering"):
        rna = getattr(bpy.types, node_type, None)
        for prop in ("subsurface_method", "falloff"):
            if rna is not None and prop in rna.bl_rna.properties:
                names.update((item.identifier, item.name) for item in rna.bl_rna.properties[prop].enum_items)
    return re.sub(r"\b[A-Z][A-Z0-9]*(?:_[A-Z0-9]+)+\b|\b[A-Z]{4,}\b",
                  lambda m: names.get(m.group(0), m.group(0)), warning)


class _ExportSettings:
    """What export.export_scene reads: the scene's bake settings (World Resolution...), with the
    UV bake's object and size as the bake found them (the active object and its image)."""

    def __init__(self, settings, uv_object, uv_size):
        self._settings = settings
        self.target = settings.target
        self.uv_object = uv_object
        self.uv_size = uv_size

    def __getattr__(self, name):
        return getattr(self._settings, name)


class _Job:
    """One bake: the exported scene, the running dwivedi bake and where its result goes."""

    def __init__(self, context, settings):
        self.dwivedi = shim()
        if settings.samples < 1:
            raise export.ExportError(f"Samples is {settings.samples}: a bake needs at least 1 sample per pixel")
        scene = context.scene
        self.scene = scene
        self.target = settings.target
        self.uv_object, self.uv_image = uv_target(context) if settings.target == 'UV' else (None, None)
        self.folder = output_folder(settings)
        _check_folder(self.folder)
        self.notes = []
        lost = lost_at_quit(self.folder)
        size = tuple(self.uv_image.size) if self.uv_image is not None else (0, 0)
        self.exported = export.export_scene(context, _ExportSettings(settings, self.uv_object, size[0]),
                                            self.dwivedi, export.CACHE)
        if self.uv_image is not None:
            self.exported.width, self.exported.height = size  # the image's own size, as Cycles bakes
        self.warnings = [readable(w) for w in self.exported.warnings] + ([lost] if lost else [])
        stem = _safe_name(scene.name) + ("_camera" if settings.target == 'CAMERA'
                                         else "_uv_" + _safe_name(self.uv_object.name))
        self.exr = os.path.join(self.folder, stem + ".exr")
        self.png = os.path.join(self.folder, stem + ".png")
        # Cycles' bake type and pass filter (passes.py): a UV bake writes that image into the
        # active image; a camera bake writes the passes it needs, and the view layer's enabled
        # light passes, as layers of a multilayer OpenEXR.
        try:
            self.bake_type, self.pass_filter = passes.bake_request(scene)
            wanted = () if passes.is_full_combined(self.bake_type, self.pass_filter) else \
                self.dwivedi.bake_type_passes(self.bake_type, self.pass_filter)
        except (passes.UnsupportedBake, self.dwivedi.Error) as error:
            raise export.ExportError(str(error)) from None
        if settings.target == 'CAMERA':
            wanted = tuple(wanted) + passes.view_layer_passes(context.view_layer)
        self.passes = tuple(name for name in self.dwivedi.PASS_NAMES if name in wanted and name != "Combined")
        if not passes.is_full_combined(self.bake_type, self.pass_filter):
            self.notes.append("bake type " + passes.summary(self.bake_type, self.pass_filter))
        self.bake_settings = self.dwivedi.BakeSettings(
            target=settings.target.lower(), width=self.exported.width, height=self.exported.height,
            uv_mesh=self.exported.uv_mesh, uv_margin=settings.uv_margin, technique=settings.technique.lower(),
            channel_walks=settings.channel_walks.lower(), samples=settings.samples, time_limit=settings.time_limit,
            target_error=settings.target_error, threads=settings.threads, seed=settings.seed,
            max_events=settings.walk_event_cap,
            transparent_background=settings.target == 'CAMERA' and scene.render.film_transparent,
            passes=self.passes,
            **export.light_paths(scene), **export.pixel_filter(scene), **export.uv_jitter())
        self.display = display_settings(scene, self.dwivedi)
        self.bake = None
        self.result = None  # the Blender image that holds the result, once finished

    def start(self):
        self.bake = self.dwivedi.start_bake(self.exported.scene, self.bake_settings)

    def finish(self):
        """Writes the files and the Blender image; returns a one-line summary."""
        image = self.bake.finish()
        self.bake = None
        try:
            stats = image.stats
            if self.target == 'CAMERA':
                export.CACHE.own_updates(lambda: self._write_files(image))
                self.result = export.CACHE.own_updates(lambda: file_image(self.exr))
                where = self.exr
            else:
                if passes.is_full_combined(self.bake_type, self.pass_filter):
                    where = export.CACHE.own_updates(
                        lambda: write_uv_image(image, self.uv_image, self.exr, self.dwivedi))
                else:
                    typed = image.bake_type(self.bake_type, self.pass_filter)
                    try:
                        where = export.CACHE.own_updates(
                            lambda: write_uv_image(typed, self.uv_image, self.exr, self.dwivedi))
                    finally:
                        typed.close()
                self.result = self.uv_image
        finally:
            image.close()
            self.close()
        # Degenerate geometry the library met (zero-area, non-finite or too distant triangles, open
        # meshes, backs of faces): said in the summary, so that a left-out mesh is not a mystery.
        degenerate = f", {stats.warnings} geometry warnings" if stats.warnings else ""
        # The technique asked for and whether the walks carried the colour channels apart (the
        # Channel Walks setting, or auto's choice per mesh), which the setting alone does not say.
        walks = stats.technique + (" with channel walks" if "channel_walks" in stats.features else "")
        # Indirect light's work (getattr: an older shim's stats have no path rays).
        path_rays = getattr(stats, "path_rays", 0)
        walks += f", {path_rays / max(stats.samples, 1):.2f} path rays a sample" if path_rays else ""
        notes = "".join(f" ({note})" for note in self.notes if note)
        return (f"Dwivedi bake: {self.exported.width} x {self.exported.height}, {stats.samples_per_pixel} spp, "
                f"{stats.seconds:.2f} s, est. error {stats.estimated_relative_error:.2%}, {walks}{degenerate} -> "
                f"{where}{notes}")

    def _write_files(self, image):
        """The camera bake's OpenEXR (scene linear, with the variance and sample layers) and PNG
        (the scene's colour management), the background as Film > Transparent says."""
        film_alpha(image, self.scene)
        if self.passes:
            # Blender's layout of a render's passes, which its Image Editor shows as a multilayer
            # image (a pass menu); the variance and sample channels are in single-layer files only.
            image.write_exr_layers(self.exr)
        else:
            image.write_exr(self.exr)
        try:
            image.write_png(self.png, self.display)
        except self.dwivedi.Error as error:
            # The library's OpenColorIO cannot read this Blender's config (Blender 5.2 ships an
            # OCIO 2.5 config, the library has 2.1): the PNG through Blender's own colour
            # management instead (Image.save_render with the scene's view settings).
            if "OCIO" not in str(error) and "config" not in str(error):
                raise
            png_through_blender(image, self.scene, self.png)
            self.notes.append("the PNG was made by Blender's colour management (the library's OpenColorIO "
                              "cannot read this Blender's config)")

    def close(self):
        if self.bake is not None:
            self.bake.close()
            self.bake = None
        if self.exported.scene is not None:
            if self.exported.owned:  # else export.CACHE keeps it for the next bake
                self.exported.scene.close()
            self.exported.scene = None


def film_alpha(image, scene):
    """The camera bake's alpha as Cycles' Film > Transparent makes it. On, the library has already
    left out the background (the bake's transparent_background: RGBA 0 where no surface is seen,
    pixels premultiplied by coverage, the world still lighting the scene). Off, every pixel is
    opaque: the world is the background."""
    if scene.render.film_transparent:
        return
    rgba = image.rgba.cast("B").cast("f")
    try:
        import numpy
        numpy.asarray(rgba).reshape(-1, 4)[:, 3] = 1.0
    except ImportError:
        for i in range(3, len(rgba), 4):
            rgba[i] = 1.0


def png_through_blender(image, scene, path):
    """Writes `image` as an 8-bit PNG through Blender's colour management (the scene's display,
    view, look, exposure, gamma), as Image.save_render does."""
    target = bpy.data.images.new("Dwivedi PNG (temporary)", image.width, image.height, alpha=True, float_buffer=True)
    try:
        _set_linear(target)
        target.pixels.foreach_set(_blender_rows(image))
        settings = scene.render.image_settings
        saved = (settings.file_format, settings.color_mode, settings.color_depth)
        try:
            settings.file_format = 'PNG'
            settings.color_mode = 'RGBA'
            settings.color_depth = '8'
            target.save_render(path, scene=scene)
        finally:
            settings.file_format, settings.color_mode, settings.color_depth = saved
    finally:
        bpy.data.images.remove(target)


def display_settings(scene, dwivedi):
    """The scene's colour management as dwivedi.DisplaySettings, with Blender's own OCIO config."""
    view = scene.view_settings
    look = view.look
    return dwivedi.DisplaySettings(config=export.ocio_config_path(), display=scene.display_settings.display_device,
                                   view=view.view_transform, look=None if look in ("", "None") else look,
                                   exposure=view.exposure, gamma=view.gamma)


def _set_linear(target):
    for colorspace in ("Linear Rec.709", "Linear"):  # Blender 4.x, 3.x names of scene linear
        try:
            target.colorspace_settings.name = colorspace
            return
        except TypeError:
            continue


def _blender_rows(image):
    """The image's RGBA floats in Blender's row order (bottom row first; the library's is the top)."""
    import array
    raw = image.rgba.cast("B")
    stride = 16 * image.width
    flipped = array.array("f")
    flipped.frombytes(b"".join(raw[y * stride:(y + 1) * stride] for y in range(image.height - 1, -1, -1)))
    return flipped


CAMERA_IMAGE = "Dwivedi Camera"


def file_image(path, name=CAMERA_IMAGE):
    """The Blender image `name` ("Dwivedi Camera", or the farm merge's) showing the EXR at `path`:
    the file itself (so the image comes back after the .blend is saved and opened again), reloaded
    after every bake, with a fake user so that saving keeps it even when no editor shows it."""
    target = bpy.data.images.get(name)
    if target is not None and (target.source != 'FILE' or bpy.path.abspath(target.filepath) != path):
        bpy.data.images.remove(target)
        target = None
    if target is None:
        target = bpy.data.images.load(path, check_existing=False)
        target.name = name
    else:
        target.reload()
    target.use_fake_user = True
    return target


def write_uv_image(image, target, path, dwivedi):
    """Writes the UV bake into the Blender image `target` as Cycles' bake does (the texels the bake
    covered, islands and margin; the others keep what they had) and keeps it: packed again if
    packed, saved to its own file, and an image made in Blender (Image > New, on no disk) made
    float and saved as an OpenEXR at `path` (`dwivedi`: the shim, which writes it). Returns where
    the image now is."""
    import array
    baked = _blender_rows(image)
    if target.source == 'GENERATED' and not target.is_float:
        target.use_generated_float = True  # a bake is scene-linear float (Cycles asks for 32-bit float)
        _set_linear(target)
    current = array.array("f", bytes(4 * len(baked)))
    target.pixels.foreach_get(current)
    # An 8-bit image stores display-encoded bytes: scene-linear values are sRGB-encoded for an
    # sRGB image (IEC 61966-2-1's transfer function) and clipped to [0, 1].
    encode = not target.is_float and target.colorspace_settings.name in ("sRGB", "sRGB 2.1")
    clip = not target.is_float
    try:
        import numpy
        now = numpy.frombuffer(current, dtype=numpy.float32).reshape(-1, 4)
        new = numpy.frombuffer(baked, dtype=numpy.float32).reshape(-1, 4).copy()
        if clip:
            numpy.clip(new, 0.0, 1.0, out=new)
        if encode:
            rgb = new[:, :3]
            new[:, :3] = numpy.where(rgb <= 0.0031308, 12.92 * rgb, 1.055 * numpy.power(rgb, 1.0 / 2.4) - 0.055)
        covered = new[:, 3] > 0.0
        now[covered] = new[covered]
    except ImportError:
        for i in range(0, len(baked), 4):
            if baked[i + 3] > 0.0:
                for c in range(4):
                    v = min(max(baked[i + c], 0.0), 1.0) if clip else baked[i + c]
                    if encode and c < 3:
                        v = 12.92 * v if v <= 0.0031308 else 1.055 * v ** (1.0 / 2.4) - 0.055
                    current[i + c] = v
    target.pixels.foreach_set(current)
    target.update()
    if target.packed_file is not None:
        target.pack()
        return f"image '{target.name}', packed in the .blend"
    if target.source == 'GENERATED' or not target.filepath:
        # On no disk yet: the pixels as a float OpenEXR written by the library (full 32-bit float;
        # Image.save would write half floats), and the image made that file's.
        width, height = target.size
        stride = 4 * width
        rows = array.array("f")
        for y in range(height - 1, -1, -1):
            rows.extend(current[y * stride:(y + 1) * stride])
        made = dwivedi.Image(width, height, rows)
        try:
            made.write_exr(path)
        finally:
            made.close()
        target.source = 'FILE'
        target.filepath = bpy.path.relpath(path) if bpy.data.filepath else path
        target.reload()
        return f"image '{target.name}' ({path})"
    try:
        target.save()
    except RuntimeError as error:
        raise export.ExportError(f"image '{target.name}' is baked but could not be saved ({error}): save it with "
                                 "Image > Save As, or it is lost at quit") from None
    return f"image '{target.name}' ({bpy.path.abspath(target.filepath)})"


def show_in_image_editor(context, image):
    """Shows `image` as F12 shows a render: in an Image Editor that already shows it or the
    Render Result, else in the render view Blender opens the way its preferences say
    (Preferences > Interface > Temporary Editors > Render In). False where there is no UI."""
    wm = context.window_manager
    if wm is None or bpy.app.background:
        return False

    def editors():
        for window in wm.windows:
            for area in window.screen.areas:
                if area.type == 'IMAGE_EDITOR':
                    yield window, area

    for wanted in (image, "render"):
        for window, area in editors():
            shown = area.spaces.active.image
            if shown == image if wanted is image else (shown is not None and shown.type == 'RENDER_RESULT'):
                area.spaces.active.image = image
                area.tag_redraw()
                return True
    window = context.window or (wm.windows[0] if wm.windows else None)
    if window is None:
        return False
    before = {area.as_pointer() for _, area in editors()}
    try:
        with context.temp_override(window=window, screen=window.screen):
            bpy.ops.render.view_show('INVOKE_DEFAULT')
    except (RuntimeError, TypeError, AttributeError):
        return False
    for _, area in editors():
        if area.as_pointer() not in before or (area.spaces.active.image is not None
                                               and area.spaces.active.image.type == 'RENDER_RESULT'):
            area.spaces.active.image = image
            area.tag_redraw()
            return True
    return False


# ---------------------------------------------------------------------------------------------
# Operators
# ---------------------------------------------------------------------------------------------

class DWIVEDI_OT_bake(bpy.types.Operator):
    """Bake subsurface scattering with Dwivedi-guided random walks: the camera's view or the active object's UV
    image (the status bar, the panel or Esc cancel)"""
    bl_idname = "dwivedi.bake"
    bl_label = "Dwivedi Subsurface Bake"
    bl_options = {'REGISTER'}

    directory: StringProperty(name="Output Folder", subtype='DIR_PATH', options={'HIDDEN', 'SKIP_SAVE'})
    filter_folder: BoolProperty(default=True, options={'HIDDEN', 'SKIP_SAVE'})
    asked_folder: BoolProperty(default=False, options={'HIDDEN', 'SKIP_SAVE'})

    @classmethod
    def poll(cls, context):
        return context.scene is not None and hasattr(context.scene, "dwivedi_bake")

    def _fail(self, context, error):
        message = str(error) or type(error).__name__
        if not isinstance(error, (export.ExportError, ValueError, OSError, TypeError)):
            traceback.print_exc()
        self.report({'ERROR'}, f"Dwivedi bake failed: {message}")
        _RUN.say('ERROR', message.splitlines()[0] if message else "the bake failed", context)
        return {'CANCELLED'}

    def _warn(self, context, job):
        _RUN.say('INFO', "", context, job.warnings)
        for warning in job.warnings:
            self.report({'WARNING'}, warning)

    def execute(self, context):
        if self.asked_folder and not bpy.app.background:
            # Back from the folder the user chose for an unsaved file: it becomes the output folder.
            context.scene.dwivedi_bake.output_dir = self.directory
            return self._start(context)
        if _RUN.running:
            self.report({'ERROR'}, "a Dwivedi bake is already running")
            return {'CANCELLED'}
        settings = context.scene.dwivedi_bake
        job = None
        try:
            job = _Job(context, settings)
            self._warn(context, job)
            image = job.dwivedi.bake(job.exported.scene, job.bake_settings)
            job.bake = _Finished(image)
            summary = job.finish()
        except KeyboardInterrupt:
            if job is not None:
                job.close()
            self.report({'WARNING'}, "Dwivedi bake cancelled")
            _RUN.say('WARNING', "Bake cancelled", context)
            return {'CANCELLED'}
        except Exception as error:  # every failure is reported, none escapes into Blender
            if job is not None:
                job.close()
            return self._fail(context, error)
        _RUN.say('INFO', summary, context)
        self.report({'INFO'}, summary)
        return {'FINISHED'}

    def invoke(self, context, event):
        if bpy.app.background:
            return self.execute(context)
        if _RUN.running:
            self.report({'ERROR'}, "a Dwivedi bake is already running")
            return {'CANCELLED'}
        raw = context.scene.dwivedi_bake.output_dir.strip() or "//"
        if raw.startswith("//") and not bpy.data.filepath:
            # An unsaved file has no folder for "//": ask for one, as saving would, rather than
            # writing into a temporary folder Blender deletes at quit.
            self.asked_folder = True
            context.window_manager.fileselect_add(self)
            return {'RUNNING_MODAL'}
        return self._start(context)

    def _start(self, context):
        settings = context.scene.dwivedi_bake
        job = None
        try:
            job = _Job(context, settings)
            self._warn(context, job)
            job.start()
        except Exception as error:
            if job is not None:
                job.close()
            return self._fail(context, error)
        _RUN.job = job
        _RUN.fraction = 0.0
        _RUN.cancel_requested = False
        _RUN.say('INFO', "Baking...", context)
        wm = context.window_manager
        _RUN.window_manager = wm
        _RUN.timer = wm.event_timer_add(0.1, window=context.window)
        wm.modal_handler_add(self)
        redraw()
        return {'RUNNING_MODAL'}

    def modal(self, context, event):
        job = _RUN.job
        if job is None:  # stopped from outside (a file load, the add-on disabled)
            return {'CANCELLED'}
        try:
            if event.type == 'ESC' and event.value == 'PRESS' or _RUN.cancel_requested:
                _RUN.stop()
                _RUN.say('WARNING', "Bake cancelled", context, job.warnings)
                self.report({'WARNING'}, "Dwivedi bake cancelled")
                return {'CANCELLED'}
            if event.type != 'TIMER':
                return {'PASS_THROUGH'}
            progress = job.bake.progress()
            shown = int(100 * _RUN.fraction)
            _RUN.fraction = progress.fraction
            redraw(status_bar=int(100 * progress.fraction) != shown)
            if not progress.done:
                return {'PASS_THROUGH'}
            summary = job.finish()
            show = job.target == 'CAMERA' and job.scene.dwivedi_bake.load_result and job.result is not None
        except Exception as error:
            _RUN.stop()
            return self._fail(context, error)
        _RUN.job = None  # finished: stop() only removes the timer
        _RUN.stop()
        _RUN.say('INFO', summary, context, job.warnings)
        self.report({'INFO'}, summary)
        if show:
            show_in_image_editor(context, job.result)
        return {'FINISHED'}

    def cancel(self, context):
        # Blender ends the modal operator itself (a file load, quit): stop the bake, free everything.
        _RUN.stop()


class DWIVEDI_OT_bake_cancel(bpy.types.Operator):
    """Stop the running Dwivedi bake (nothing is written)"""
    bl_idname = "dwivedi.bake_cancel"
    bl_label = "Cancel Dwivedi Bake"
    bl_options = {'INTERNAL'}

    @classmethod
    def poll(cls, context):
        return _RUN.running

    def execute(self, context):
        job = _RUN.job
        if job is not None and job.bake is not None:
            job.bake.cancel()  # the threads stop within 0.1 s; the modal operator frees the bake
        _RUN.cancel_requested = True
        return {'FINISHED'}


class _Finished:
    """A finished bake's image in the shape of a running bake (execute() bakes in one call)."""

    def __init__(self, image):
        self._image = image

    def finish(self):
        return self._image

    def close(self):
        pass

    def cancel(self):
        pass


# ---------------------------------------------------------------------------------------------
# Panels (Properties > Render), laid out as Cycles' render panels are
# ---------------------------------------------------------------------------------------------

MESSAGE_ICONS = {'INFO': 'INFO', 'WARNING': 'ERROR', 'ERROR': 'CANCEL'}


class DWIVEDI_PT_bake(bpy.types.Panel):
    bl_label = "Dwivedi Subsurface Bake"
    bl_idname = "DWIVEDI_PT_bake"  # stable: sub-panels (here and in farm.py) name it as bl_parent_id
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = "render"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        settings = context.scene.dwivedi_bake
        status = library_status()
        if _RUN.running:
            draw_progress(layout, "Baking")
        else:
            row = layout.row()
            row.scale_y = 1.4
            row.operator(DWIVEDI_OT_bake.bl_idname, text="Bake", icon='RENDER_STILL')
        if not status.ok:
            draw_status(layout)
        level, message, warnings = _RUN.messages_for(context)
        if message:
            box = layout.box()
            lines = _wrap(message, 60) or [message]
            box.label(text=lines[0], icon=MESSAGE_ICONS.get(level, 'INFO'))
            for line in lines[1:4]:
                box.label(text=line)
        for warning in warnings[:4]:
            layout.label(text=warning, icon='ERROR')
        if len(warnings) > 4:
            layout.label(text=f"{len(warnings) - 4} more warnings in the Info editor", icon='ERROR')
        layout.prop(settings, "target", expand=True)
        if settings.target == 'UV':
            try:
                obj, image = uv_target(context)
                layout.label(text=f"{obj.name} into '{image.name}' ({image.size[0]} x {image.size[1]})",
                             icon='IMAGE_DATA')
            except export.ExportError as error:
                for n, line in enumerate(_wrap(str(error), 60)):
                    layout.label(text=line, icon='ERROR' if n == 0 else 'BLANK1')
        else:
            width, height = export.render_size(context.scene)
            layout.label(text=f"{width} x {height} (render resolution)", icon='CAMERA_DATA')


class _SubPanel:
    """A sub-panel of the main one (closed by default, as Cycles' are): draws its settings with
    the Render tab's property split."""
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = "render"
    bl_parent_id = DWIVEDI_PT_bake.bl_idname
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        self.draw_settings(layout, context.scene.dwivedi_bake)


class DWIVEDI_PT_bake_sampling(_SubPanel, bpy.types.Panel):
    bl_label = "Sampling"
    bl_idname = "DWIVEDI_PT_bake_sampling"

    def draw_settings(self, layout, settings):
        col = layout.column(align=True)
        col.prop(settings, "samples")
        col.prop(settings, "time_limit")
        col.prop(settings, "target_error")
        layout.prop(settings, "seed")


class DWIVEDI_PT_bake_output(_SubPanel, bpy.types.Panel):
    bl_label = "Output"
    bl_idname = "DWIVEDI_PT_bake_output"

    def draw_settings(self, layout, settings):
        layout.prop(settings, "output_dir")
        if settings.target == 'UV':
            layout.prop(settings, "uv_margin")
        else:
            layout.prop(settings, "load_result")


class DWIVEDI_PT_bake_advanced(_SubPanel, bpy.types.Panel):
    """Choices for research and comparisons: how the walks are steered and carried."""
    bl_label = "Advanced"
    bl_idname = "DWIVEDI_PT_bake_advanced"

    def draw_settings(self, layout, settings):
        layout.prop(settings, "technique")
        layout.prop(settings, "channel_walks")
        layout.prop(settings, "walk_event_cap")
        layout.prop(settings, "threads")
        layout.prop(settings, "world_resolution")
        layout.prop(settings, "texture_bake_size")


CLASSES = (DwivediBakePreferences, DwivediBakeSettings, DWIVEDI_OT_bake, DWIVEDI_OT_bake_cancel, DWIVEDI_PT_bake,
           DWIVEDI_PT_bake_sampling, DWIVEDI_PT_bake_output, DWIVEDI_PT_bake_advanced)


@bpy.app.handlers.persistent
def _stop_before_load(*_args):
    """A file is about to load: end the bake now (its scene is about to go) and forget the
    messages, which were about the old file."""
    _RUN.stop()
    _RUN.say('INFO', "", None, [])


@bpy.app.handlers.persistent
def _note_updates(_scene, depsgraph):
    """What changed, for the export cache (export.ExportCache.note). Persistent: it must see the
    updates of every file loaded after it."""
    export.CACHE.note(depsgraph)


@bpy.app.handlers.persistent
def _forget_exports(*_args):
    """A file loaded, an undo or a redo: the data the cache was read from is gone."""
    export.CACHE.clear()


_CACHE_HANDLERS = (("depsgraph_update_post", _note_updates), ("load_post", _forget_exports),
                   ("undo_post", _forget_exports), ("redo_post", _forget_exports))


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
    # Read-only (a getter, no setter): drawn as a bar nobody can drag, and nothing is stored.
    bpy.types.WindowManager.dwivedi_bake_progress = FloatProperty(
        name="Progress", description="How far the running Dwivedi bake is", subtype='PERCENTAGE', min=0.0,
        max=100.0, precision=0, get=_progress_percent)
    bpy.types.TOPBAR_MT_render.append(draw_render_menu)
    bpy.types.STATUSBAR_HT_header.append(draw_status_bar)
    bpy.app.handlers.load_pre.append(_stop_before_load)
    for name, handler in _CACHE_HANDLERS:
        getattr(bpy.app.handlers, name).append(handler)
    farm.register()  # its sub-panel's parent is DWIVEDI_PT_bake
    _DWIVEDI_BAKE_REGISTERED = True
    status = check_library()
    if not status.ok:
        # The panel shows it with an ERROR icon; the console says it once at enable.
        print(f"Dwivedi Subsurface Bake: the dwivedi library cannot be used: {status.message}")


def unregister():
    global _DWIVEDI_BAKE_REGISTERED, _status, _status_key
    if not _DWIVEDI_BAKE_REGISTERED:
        return
    farm.unregister()
    # Disabled during a bake: Blender frees the modal operator's handler without calling its
    # cancel() (WM_operator_handlers_clear leaves the clean-up to whoever unregisters), so the
    # bake is cancelled and its threads joined here, before its classes go.
    _RUN.stop()
    _RUN.say('INFO', "", None, [])
    if _stop_before_load in bpy.app.handlers.load_pre:
        bpy.app.handlers.load_pre.remove(_stop_before_load)
    for name, handler in _CACHE_HANDLERS:
        if handler in getattr(bpy.app.handlers, name):
            getattr(bpy.app.handlers, name).remove(handler)
    export.CACHE.clear()
    bpy.types.STATUSBAR_HT_header.remove(draw_status_bar)
    bpy.types.TOPBAR_MT_render.remove(draw_render_menu)
    del bpy.types.WindowManager.dwivedi_bake_progress
    del bpy.types.Scene.dwivedi_bake
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
    _DWIVEDI_BAKE_REGISTERED = False
    _status = None
    _status_key = None
