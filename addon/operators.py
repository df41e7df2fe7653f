"""Operators: "Compare with Cycles" (Render Properties > MC Engine).

The operator renders the scene as it is in memory (saved or not) with MC
Engine and with Cycles, ``seeds`` times each under matched settings
(``comparison.compare_scene``, which puts every setting back afterwards),
writes the comparison files (``mcengine.report``), loads ``side_by_side.png``
as the image "MC Engine vs Cycles", shows it in an Image Editor and reports
the verdict in the info bar: INFO when the engines agree, WARNING when they
differ, ERROR when a render failed.

Rendering blocks Blender's interface like a bake does; the cursor shows the
progress over the ``2 x seeds`` renders.  The Render Result keeps the last
(Cycles) render.
"""
from __future__ import annotations

import re
import tempfile
from pathlib import Path

import bpy

__all__ = ["MCENGINE_OT_compare_with_cycles", "IMAGE_NAME", "register", "unregister"]

IMAGE_NAME = "MC Engine vs Cycles"
# Default output: <temp>/mcengine_compare/<scene name>/ (scene names made file-safe).
OUTPUT_FOLDER = "mcengine_compare"
_UNSAFE = re.compile(r"[^A-Za-z0-9._-]+")


class MCENGINE_OT_compare_with_cycles(bpy.types.Operator):
    """Render this scene with MC Engine and with Cycles and show where they differ"""

    bl_idname = "mcengine.compare_with_cycles"
    bl_label = "Compare with Cycles"
    bl_options = {"REGISTER"}

    samples: bpy.props.IntProperty(
        name="Samples", min=0, soft_max=4096, default=0,
        description="Samples per render; 0 uses the scene's Cycles samples")
    resolution_percentage: bpy.props.IntProperty(
        name="Resolution", subtype="PERCENTAGE", min=1, max=100, default=50,
        description="Size of the comparison renders, relative to the scene's resolution")
    seeds: bpy.props.IntProperty(
        name="Seeds", min=2, max=16, default=2,
        description="Renders per engine; their spread measures the noise the verdict allows for")
    directory: bpy.props.StringProperty(
        name="Output Folder", subtype="DIR_PATH", default="",
        description="Where the report and images go; empty: a folder in the temporary "
                    "directory, named after the scene")

    @classmethod
    def poll(cls, context):
        scene = context.scene
        if scene is None or scene.camera is None:
            cls.poll_message_set("The scene needs an active camera")
            return False
        return True

    def invoke(self, context, event):
        return context.window_manager.invoke_props_dialog(self, confirm_text="Compare")

    def execute(self, context):
        from mcengine.report import write_comparison

        from .comparison import CompareError, CompareOptions, compare_scene

        scene = context.scene
        out = self._output_folder(scene)
        options = CompareOptions(samples=self.samples or None,
                                 percentage=self.resolution_percentage, seeds=self.seeds)
        wm = context.window_manager
        wm.progress_begin(0, 2 * self.seeds)
        try:
            comparison = compare_scene(scene, options, name=scene.name,
                                       on_render=lambda engine, i, total: wm.progress_update(i))
            paths = write_comparison(comparison, out)
        except (CompareError, OSError, ValueError) as exc:
            self.report({"ERROR"}, f"Compare with Cycles: {exc}")
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        image = load_image(paths["side_by_side.png"])
        show_image(context, image)
        level = "INFO" if comparison.verdict == "agree" else "WARNING"
        self.report({level}, f"Compare with Cycles: {comparison.summary()}; "
                             f"report in {paths['report.md']}")
        return {"FINISHED"}

    def _output_folder(self, scene) -> Path:
        if self.directory:
            return Path(bpy.path.abspath(self.directory))
        name = _UNSAFE.sub("_", scene.name).strip("_") or "scene"
        return Path(tempfile.gettempdir()) / OUTPUT_FOLDER / name


def load_image(path) -> bpy.types.Image:
    """The image datablock :data:`IMAGE_NAME` showing ``path`` (reloaded if it exists)."""
    image = bpy.data.images.get(IMAGE_NAME)
    if image is None or image.source != "FILE":
        image = bpy.data.images.load(str(path), check_existing=False)
        image.name = IMAGE_NAME
    else:
        image.filepath = str(path)
        image.reload()
    return image


def show_image(context, image) -> None:
    """Show ``image`` in an Image Editor: one already open, else the render view.

    Without a window (background mode) there is nothing to show.
    """
    if context.window is None:
        return
    area = _image_editor(context.window_manager)
    if area is None:
        try:  # opens an Image Editor as F12 does (new window, full screen, ...)
            bpy.ops.render.view_show("INVOKE_DEFAULT")
        except RuntimeError:
            return
        area = _image_editor(context.window_manager)
    if area is not None:
        area.spaces.active.image = image
        area.tag_redraw()


def _image_editor(wm):
    """An Image Editor area in any open window (the render view's first), or None."""
    found = None
    for window in wm.windows:
        for area in window.screen.areas:
            if area.type == "IMAGE_EDITOR":
                shown = area.spaces.active.image
                if shown is not None and shown.type == "RENDER_RESULT":
                    return area
                found = found or area
    return found


def register() -> None:
    if not MCENGINE_OT_compare_with_cycles.is_registered:
        bpy.utils.register_class(MCENGINE_OT_compare_with_cycles)


def unregister() -> None:
    if MCENGINE_OT_compare_with_cycles.is_registered:
        bpy.utils.unregister_class(MCENGINE_OT_compare_with_cycles)
