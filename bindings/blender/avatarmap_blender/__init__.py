"""avatarmap for Blender: File > Import > avatarmap take.

Imports a video, a landmark file (*.landmarks.jsonl) or an avatarmap animation (*.pose.jsonl,
.vrma, .glb animation, .bvh) onto an armature through the avatarmap Python package, and sets
the scene's frame rate and frame range from the take. Works on Debian's Blender 3.4 as it is:
the shims its importers need under Python 3.11 / NumPy 1.24 are applied by this add-on around
its own calls (compat.py), never by patching Blender. See docs/blender.md.

Command line: blender -b --python bindings/blender/import_take.py -- INPUT [options]
"""
bl_info = {
    "name": "avatarmap take",
    "author": "avatarmap",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "File > Import > avatarmap take",
    "description": "Video, landmarks or avatarmap animation onto an armature",
    "category": "Import-Export",
}

if "bpy" in locals():  # Blender's "Reload Scripts"
    import importlib
    importlib.reload(compat)  # noqa: F821
    importlib.reload(take)  # noqa: F821

import bpy
from bpy.props import StringProperty
from bpy_extras.io_utils import ImportHelper

from . import compat, take  # noqa: F401
from .take import Take, TakeError, import_take, load_avatarmap  # noqa: F401

_FILTER = ("*.mp4;*.mkv;*.avi;*.mov;*.webm;*.m4v;*.mpg;*.mpeg;*.ts;*.wmv;*.flv;*.gif;"
           "*.jsonl;*.vrma;*.glb;*.bvh")


class AvatarmapPreferences(bpy.types.AddonPreferences):
    bl_idname = __name__

    package_dir: StringProperty(
        name="Python package folder", subtype='DIR_PATH', default="",
        description="Folder holding the avatarmap package (a checkout's bindings/python); "
                    "empty: installed package, $AVATARMAP_PYTHON_DIR, ~/.local")
    library: StringProperty(
        name="C library", subtype='FILE_PATH', default="",
        description="libavatarmap_c.so to load; empty: $AVATARMAP_C_LIBRARY or the "
                    "package's own search")
    models: StringProperty(
        name="Models folder", subtype='DIR_PATH', default="",
        description="Capture models (videos only); empty: $AVATARMAP_MODELS or the "
                    "installed ones")

    @staticmethod
    def defaults():
        """The preferences' defaults, for the operator run without the add-on enabled (its
        classes registered by a script)."""
        class _Defaults:
            package_dir = library = models = ""
        return _Defaults()

    def draw(self, context):
        for name in ("package_dir", "library", "models"):
            self.layout.prop(self, name)


class IMPORT_ANIM_OT_avatarmap_take(bpy.types.Operator, ImportHelper):
    """Import a video, landmarks or an avatarmap animation onto an armature"""
    bl_idname = "import_anim.avatarmap_take"
    bl_label = "Import avatarmap take"
    bl_options = {'REGISTER', 'UNDO'}

    filter_glob: StringProperty(default=_FILTER, options={'HIDDEN'})
    armature: StringProperty(
        name="Armature", default="",
        description="Name of the armature: an existing one with the take's skeleton gets the "
                    "take as a new action; empty: a new armature named after the file")
    avatar: StringProperty(
        name="Avatar", subtype='FILE_PATH', default="",
        description="Avatar (.vrm, .glb, .bvh) whose rig the armature takes; empty: the "
                    "proxy skeleton of the 55 VRM bones")

    def execute(self, context):
        addon = context.preferences.addons.get(__name__)
        prefs = addon.preferences if addon else AvatarmapPreferences.defaults()
        wm = context.window_manager

        def progress(done, total):
            if total > 0:
                wm.progress_update(min(done, total) / total)

        wm.progress_begin(0.0, 1.0)
        try:
            result = import_take(context, self.filepath, armature=self.armature,
                                 avatar=bpy.path.abspath(self.avatar) if self.avatar else "",
                                 models=bpy.path.abspath(prefs.models) if prefs.models else "",
                                 package_dir=bpy.path.abspath(prefs.package_dir)
                                 if prefs.package_dir else "",
                                 library=bpy.path.abspath(prefs.library)
                                 if prefs.library else "",
                                 progress=progress)
        except TakeError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        finally:
            wm.progress_end()
        self.report({'INFO'}, "%s: %d frames at %g fps on %s" % (
            result.action, result.frames, result.fps, result.armature))
        return {'FINISHED'}


def _menu(self, context):
    self.layout.operator(IMPORT_ANIM_OT_avatarmap_take.bl_idname,
                         text="avatarmap take (video, landmarks, .pose.jsonl, .vrma, .bvh)")


_CLASSES = (AvatarmapPreferences, IMPORT_ANIM_OT_avatarmap_take)


def register():
    for cls in _CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.TOPBAR_MT_file_import.append(_menu)


def unregister():
    bpy.types.TOPBAR_MT_file_import.remove(_menu)
    for cls in reversed(_CLASSES):
        bpy.utils.unregister_class(cls)
