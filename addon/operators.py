"""Operators: "Compare with Cycles" and "Study Accuracy vs Time" (Render Properties > MC Engine).

The operator renders the scene as it is in memory (saved or not) with MC
Engine and with Cycles, ``seeds`` times each under matched settings
(``batch.comparison.compare_scene``, which puts every setting back afterwards),
writes the comparison files (``mcengine.evaluation.output``), loads ``side_by_side.png``
as the image "MC Engine vs Cycles", shows it in an Image Editor and reports
the verdict in the info bar: INFO when the engines agree, WARNING when they
differ, ERROR when a render failed.

"Study Accuracy vs Time" runs a short study of the scene in memory
(``batch.study.study_scene``: every integrator at 1, 2, 4, ... samples, small
image), writes the study's files (``mcengine.evaluation.output``), loads
``error_vs_time.png`` as the image "MC Engine Study", shows it in an Image
Editor and reports one line: each integrator's time to the target error or
the error where it levels off.

Rendering blocks Blender's interface like a bake does; the cursor shows the
progress over the renders.  The Render Result keeps the last render.
"""
from __future__ import annotations

import re
import tempfile
from pathlib import Path

import bpy

__all__ = ["MCENGINE_OT_compare_with_cycles", "MCENGINE_OT_study_accuracy", "IMAGE_NAME",
           "STUDY_IMAGE_NAME", "register", "unregister"]

IMAGE_NAME = "MC Engine vs Cycles"
STUDY_IMAGE_NAME = "MC Engine Study"
# Default output: <temp>/mcengine_compare/<scene name>/ (scene names made file-safe).
OUTPUT_FOLDER = "mcengine_compare"
STUDY_FOLDER = "mcengine_study"
_UNSAFE = re.compile(r"[^A-Za-z0-9._-]+")


class _RendersScene:
    """Mixin of the operators that render the open scene: they need an active camera."""

    @classmethod
    def poll(cls, context):
        scene = context.scene
        if scene is None or scene.camera is None:
            cls.poll_message_set("The scene needs an active camera")
            return False
        return True


class MCENGINE_OT_compare_with_cycles(_RendersScene, bpy.types.Operator):
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


    def invoke(self, context, event):
        return context.window_manager.invoke_props_dialog(self, confirm_text="Compare")

    def execute(self, context):
        from mcengine.evaluation.output import write_comparison

        from .batch.comparison import CompareError, CompareOptions, compare_scene

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
        return _output_folder(self.directory, OUTPUT_FOLDER, scene)


def _output_folder(directory: str, default_folder: str, scene) -> Path:
    """``directory`` (Blender path), or <temp>/<default_folder>/<scene name>."""
    if directory:
        return Path(bpy.path.abspath(directory))
    name = _UNSAFE.sub("_", scene.name).strip("_") or "scene"
    return Path(tempfile.gettempdir()) / default_folder / name


class MCENGINE_OT_study_accuracy(_RendersScene, bpy.types.Operator):
    """Render this scene with every integrator at 1, 2, 4, ... samples and plot error against time"""

    bl_idname = "mcengine.study_accuracy"
    bl_label = "Study Accuracy vs Time"
    bl_options = {"REGISTER"}

    max_samples: bpy.props.IntProperty(
        name="Samples", min=2, soft_max=256, max=4096, default=16,
        description="Largest sample count of the ladder 1, 2, 4, ...; the reference gets 16x")
    size: bpy.props.IntProperty(
        name="Size", subtype="PIXEL", min=8, soft_max=512, max=4096, default=64,
        description="Longest side of the study's renders in pixels (the aspect ratio is kept)")
    seeds: bpy.props.IntProperty(
        name="Seeds", min=2, max=16, default=2,
        description="Renders per sample count; their spread gives the error bars")
    with_cycles: bpy.props.BoolProperty(
        name="Cycles", default=False,
        description="Also study Cycles, against its own reference")
    directory: bpy.props.StringProperty(
        name="Output Folder", subtype="DIR_PATH", default="",
        description="Where the report and plots go; empty: a folder in the temporary "
                    "directory, named after the scene")


    def invoke(self, context, event):
        return context.window_manager.invoke_props_dialog(self, confirm_text="Study")

    def execute(self, context):
        from mcengine.evaluation.output import write_study
        from mcengine.evaluation.study import StudyError, StudyOptions, summarise

        from .batch.study import StudySettings, study_scene

        scene = context.scene
        out = _output_folder(self.directory, STUDY_FOLDER, scene)
        options = StudyOptions(with_cycles=self.with_cycles, max_samples=self.max_samples,
                               seeds=self.seeds)       # every integrator
        settings = StudySettings(resolution=_study_size(scene, self.size))
        wm = context.window_manager
        wm.progress_begin(0, 1)
        try:
            study = study_scene(scene, options, settings,
                                on_render=lambda label, i, total: wm.progress_update(i / total))
            paths = write_study(study, out)
        except (StudyError, OSError, ValueError) as exc:
            self.report({"ERROR"}, f"Study Accuracy vs Time: {exc}")
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        image = load_image(paths["time"], STUDY_IMAGE_NAME)
        show_image(context, image)
        self.report({"INFO"}, f"Study: {study_summary(summarise(study))}; report in {paths['html']}")
        return {"FINISHED"}


def _study_size(scene, longest: int) -> tuple:
    """(width, height) with the scene's aspect ratio and ``longest`` pixels on the long side."""
    r = scene.render
    w, h = r.resolution_x * r.pixel_aspect_x, r.resolution_y * r.pixel_aspect_y
    scale = longest / max(w, h)
    return max(4, round(r.resolution_x * scale)), max(4, round(r.resolution_y * scale))


def study_summary(summaries: dict) -> str:
    """One line: per integrator, its time to the target or where its error levels off."""
    parts = []
    for name, s in summaries.items():
        if s.plateau:
            parts.append(f"{name} levels off at relMSE {s.floor:.2g}")
        elif s.time_to_target is not None:
            approx = "~" if s.target_how == "extrapolated" else ""
            parts.append(f"{name} {approx}{s.time_to_target:.2g} s")
        else:
            parts.append(f"{name} not reached")
    target = next(iter(summaries.values())).target if summaries else 0.0
    return f"time to relMSE {target:g}: " + ", ".join(parts)


def load_image(path, name: str = IMAGE_NAME) -> bpy.types.Image:
    """The image datablock ``name`` showing ``path`` (reloaded if it exists)."""
    image = bpy.data.images.get(name)
    if image is None or image.source != "FILE":
        image = bpy.data.images.load(str(path), check_existing=False)
        image.name = name
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


_CLASSES = (MCENGINE_OT_compare_with_cycles, MCENGINE_OT_study_accuracy)


def register() -> None:
    for cls in _CLASSES:
        if not cls.is_registered:
            bpy.utils.register_class(cls)


def unregister() -> None:
    for cls in reversed(_CLASSES):
        if cls.is_registered:
            bpy.utils.unregister_class(cls)
