"""Render .blend files in this process and get the pixels back as numpy arrays.

Used by the comparison and the study, the command line, the tests and the
benchmark: they need the same scene rendered by MC Engine and by Cycles under
the same settings, many times, without a Blender process per render.
Rendering goes through ``bpy.ops.render.render`` exactly as F12 or
``blender -b`` does; the image is written to a temporary 32-bit EXR (the
scene-linear values) and read back.

``bpy`` is imported inside the functions, so the command line can check its
arguments against :data:`ENGINES` before Blender starts.
"""
from __future__ import annotations

import os
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import interrupt
from .settings import apply_overrides, set_image_format

__all__ = ["ENGINES", "Render", "OpenError", "NoSuchScene", "open_scene", "ensure_registered",
           "error_message", "render_scene"]

# User-facing engine names -> RenderEngine bl_idname.
ENGINES = {"mcengine": "MCENGINE", "cycles": "CYCLES"}


@dataclass
class Render:
    image: np.ndarray       # (h, w, 4) float32, top row first
    seconds: float          # wall time of the render call
    engine: str
    samples: int
    seed: int
    nonfinite: int = 0      # MC Engine: samples dropped as NaN or infinite


class OpenError(Exception):
    """A .blend could not be loaded; the message is one line for the user."""


class NoSuchScene(OpenError):
    """The file has no scene of the name asked for (the message lists its scenes)."""


def error_message(exc: Exception) -> str:
    """One line from a bpy operator's RuntimeError (``Error: ...`` lines joined)."""
    lines = [line.strip() for line in str(exc).splitlines() if line.strip()]
    lines = [line[len("Error:"):].strip() if line.startswith("Error:") else line for line in lines]
    unique = list(dict.fromkeys(lines))
    return "; ".join(unique) or type(exc).__name__


def open_scene(path, scene_name: str | None = None):
    """Load ``path`` as the current file; returns its active scene (or the one named).

    Raises
    ------
    OpenError
        Blender could not load the file (with its reason).
    NoSuchScene
        ``scene_name`` is not a scene of the file.
    """
    import bpy
    try:
        bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    except RuntimeError as exc:
        raise OpenError(f"cannot open {path}: {error_message(exc)}") from None
    if scene_name is None:
        return bpy.context.scene
    scene = bpy.data.scenes.get(scene_name)
    if scene is None:
        names = ", ".join(s.name for s in bpy.data.scenes)
        raise NoSuchScene(f"no scene named {scene_name!r} in {Path(path).name} (scenes: {names})")
    return scene


def ensure_registered():
    """Register the add-on (idempotent: a second call changes nothing)."""
    from .. import register
    register()


def render_scene(scene, engine: str, *, samples=None, seed=None, resolution=None) -> Render:
    """Render the given (already loaded) scene; settings are changed in memory only.

    ``engine`` is a name of :data:`ENGINES` or a bl_idname; None settings keep
    the scene's.  Raises RuntimeError (Blender's) if the render fails, and
    :class:`.interrupt.Interrupted` if a stop was requested before or during
    it (an MC Engine render then stops within a tenth of a second).
    """
    import bpy

    from mcengine.imageio import ImageError, read_exr
    bl_engine = ENGINES.get(engine.lower(), engine.upper())
    ours = bl_engine == ENGINES["mcengine"]
    if ours:
        ensure_registered()
        from ..engine import last_render
        last_render.clear()   # what is left in it afterwards is this render's
    apply_overrides(scene, engine=bl_engine, samples=samples, seed=seed, resolution=resolution)
    set_image_format(scene, "OPEN_EXR")
    interrupt.check()
    fd, tmp = tempfile.mkstemp(suffix=".exr", prefix="mcengine_")
    os.close(fd)
    try:
        scene.render.filepath = tmp
        scene.render.use_file_extension = False
        t0 = time.perf_counter()
        bpy.ops.render.render(write_still=True, scene=scene.name)
        seconds = time.perf_counter() - t0
        interrupt.check()     # an interrupted render is incomplete: not returned
        if os.path.getsize(tmp) == 0:
            raise RuntimeError(f"{bl_engine} wrote no image")
        try:
            image = read_exr(tmp)
        except ImageError as exc:     # e.g. the temporary folder's disk is full
            raise RuntimeError(f"{bl_engine}'s image could not be read back: {exc}") from None
    finally:
        Path(tmp).unlink(missing_ok=True)
    stats = last_render.get("stats") if ours else None
    return Render(image=image, seconds=seconds, engine=bl_engine,
                  samples=scene.cycles.samples, seed=scene.cycles.seed,
                  nonfinite=int(getattr(stats, "nonfinite", 0) or 0))
