"""Render .blend files in this process and get the pixels back as numpy arrays.

Used by the comparison tools, the tests and the benchmark: they need the same
scene rendered by MC Engine and by Cycles under the same settings, many times,
without a Blender process per render.  Rendering goes through
``bpy.ops.render.render`` exactly as F12 or ``blender -b`` does; the image is
written to a temporary 32-bit EXR (the scene-linear values) and read back.
"""
from __future__ import annotations

import contextlib
import os
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ENGINES = {"mcengine": "MCENGINE", "cycles": "CYCLES"}


@dataclass
class Render:
    image: np.ndarray       # (h, w, 4) float32, top row first
    seconds: float          # wall time of the render call
    engine: str
    samples: int
    seed: int


def open_blend(path):
    """Load ``path`` as the current file; returns its active scene."""
    import bpy
    bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    return bpy.context.scene


def ensure_registered():
    """Register the add-on (idempotent: a second call changes nothing)."""
    from . import register
    register()


def make_unbiased(scene):
    """Settings under which the two engines estimate the same image.

    Denoising, adaptive sampling, clamping and Filter Glossy change the
    expected value (or correlate pixels) differently in each engine; the
    comparison turns them off, as Cycles' own reference renders do.
    """
    c = scene.cycles
    c.use_denoising = False
    c.use_adaptive_sampling = False
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.device = "CPU"
    scene.view_settings.view_transform = "Standard"


# Every scene setting that make_unbiased, render_scene and the comparison
# (mcengine_blender.comparison) change, as (owner path from the scene, attribute).
# Restored in this order: the image format before its colour mode and depth
# (a format change resets them), the view transform before the look.
TOUCHED_SETTINGS = (
    ("render", "engine"), ("render", "resolution_x"), ("render", "resolution_y"),
    ("render", "resolution_percentage"), ("render", "filepath"), ("render", "use_file_extension"),
    ("render.image_settings", "media_type"), ("render.image_settings", "file_format"),
    ("render.image_settings", "color_mode"), ("render.image_settings", "color_depth"),
    ("cycles", "samples"), ("cycles", "seed"), ("cycles", "use_denoising"),
    ("cycles", "use_adaptive_sampling"), ("cycles", "sample_clamp_direct"),
    ("cycles", "sample_clamp_indirect"), ("cycles", "blur_glossy"), ("cycles", "device"),
    ("cycles", "time_limit"), ("cycles", "use_layer_samples"),
    ("view_settings", "view_transform"), ("view_settings", "look"),
    ("mcengine", "integrator"),
)


def _owner(scene, path: str):
    """The settings struct at ``path`` (None if absent, e.g. add-on not registered)."""
    owner = scene
    for name in path.split("."):
        owner = getattr(owner, name, None)
    return owner


@contextlib.contextmanager
def restoring(scene):
    """Put back every setting of :data:`TOUCHED_SETTINGS` on exit (also on errors).

    Lets the comparison render the user's open scene with other settings and
    leave it as it was.  (The Render Result image keeps the last render.)
    """
    saved = [(path, name, getattr(_owner(scene, path), name)) for path, name in TOUCHED_SETTINGS
             if hasattr(_owner(scene, path), name)]
    try:
        yield scene
    finally:
        for path, name, value in saved:
            owner = _owner(scene, path)
            if getattr(owner, name) != value:
                setattr(owner, name, value)


def render_scene(scene, engine: str, *, samples=None, seed=None, resolution=None) -> Render:
    """Render the given (already loaded) scene; settings are changed in memory only."""
    import bpy

    from mcengine.imageio import read_exr
    bl_engine = ENGINES.get(engine.lower(), engine.upper())
    if bl_engine == "MCENGINE":
        ensure_registered()
    scene.render.engine = bl_engine
    if samples is not None:
        scene.cycles.samples = int(samples)
    if seed is not None:
        scene.cycles.seed = int(seed)
    if resolution is not None:
        scene.render.resolution_x, scene.render.resolution_y = (int(v) for v in resolution)
        scene.render.resolution_percentage = 100
    settings = scene.render.image_settings
    settings.media_type = "IMAGE"
    settings.file_format = "OPEN_EXR"
    settings.color_mode = "RGBA"
    settings.color_depth = "32"
    fd, tmp = tempfile.mkstemp(suffix=".exr", prefix="mcengine_")
    os.close(fd)
    try:
        scene.render.filepath = tmp
        scene.render.use_file_extension = False
        t0 = time.perf_counter()
        bpy.ops.render.render(write_still=True, scene=scene.name)
        seconds = time.perf_counter() - t0
        if os.path.getsize(tmp) == 0:
            raise RuntimeError(f"{bl_engine} wrote no image")
        image = read_exr(tmp)
    finally:
        Path(tmp).unlink(missing_ok=True)
    return Render(image=image, seconds=seconds, engine=bl_engine,
                  samples=scene.cycles.samples, seed=scene.cycles.seed)


def render_file(path, engine: str, *, samples=None, seed=None, resolution=None,
                unbiased=False, edit=None) -> Render:
    """Open ``path``, optionally make it unbiased and ``edit(scene)``, then render."""
    scene = open_blend(path)
    if unbiased:
        make_unbiased(scene)
    if edit is not None:
        edit(scene)
    return render_scene(scene, engine, samples=samples, seed=seed, resolution=resolution)
