"""The scene settings the batch tools change, and putting them back.

* :func:`apply_overrides`: the settings of one render (engine, samples, seed,
  resolution, threads, frame, integrator), each None to keep the scene's;
* :func:`set_image_format`: the file an image is saved as;
* :func:`make_unbiased`: the settings under which both engines estimate the
  same image;
* :func:`restoring`: every setting above (:data:`TOUCHED_SETTINGS`) put back
  on exit, so a tool can render the user's open scene and leave it as it was.
"""
from __future__ import annotations

import contextlib

from mcengine.integrators import get as get_integrator
from mcengine.samplers import get as get_sampler

__all__ = ["apply_overrides", "set_image_format", "make_unbiased", "TOUCHED_SETTINGS",
           "restoring"]


def apply_overrides(scene, *, engine=None, samples=None, seed=None, resolution=None,
                    threads=None, frame=None, integrator=None, depth=None,
                    branching=None, overwrite=None, placeholders=None, sampler=None) -> None:
    """Change the settings of the next render in memory; None keeps the scene's.

    engine      RenderEngine bl_idname ("MCENGINE", "CYCLES")
    samples     ``scene.cycles.samples`` (both engines read Cycles' sampling settings)
    seed        ``scene.cycles.seed``
    resolution  (width, height) at 100 %
    threads     CPU threads, 0 = all
    frame       frame to render (set with ``frame_set``, so animation is evaluated)
    integrator, depth, branching
                MC Engine's algorithm (a name of :mod:`mcengine.integrators`)
                and its parameters; ignored while the add-on is not registered
    overwrite, placeholders
                Output > Overwrite and Placeholders (``render.use_overwrite``,
                ``render.use_placeholder``), read by the command line's frames
    sampler     MC Engine's sampler (a name of :mod:`mcengine.samplers`); likewise
    """
    render = scene.render
    if engine is not None:
        render.engine = engine
    if samples is not None:
        scene.cycles.samples = int(samples)
    if seed is not None:
        scene.cycles.seed = int(seed)
    if resolution is not None:
        render.resolution_x, render.resolution_y = (int(v) for v in resolution)
        render.resolution_percentage = 100
    if threads is not None:
        render.threads_mode = "AUTO" if threads == 0 else "FIXED"
        if threads:
            render.threads = threads
    if overwrite is not None:
        render.use_overwrite = bool(overwrite)
    if placeholders is not None:
        render.use_placeholder = bool(placeholders)
    if frame is not None:
        scene.frame_set(frame)
    own = getattr(scene, "mcengine", None)
    if own is not None:
        if integrator is not None:
            own.integrator = get_integrator(integrator).enum_id
        if depth is not None:
            own.depth = depth
        if branching is not None:
            own.branching = branching
        if sampler is not None:
            own.sampler = get_sampler(sampler).enum_id


def set_image_format(scene, file_format: str) -> None:
    """Save images as ``file_format``: OPEN_EXR (32-bit float RGBA), OPEN_EXR_MULTILAYER
    (every pass, 32-bit float; Blender 5.0 calls it a multi-layer image) or PNG (8-bit RGBA)."""
    settings = scene.render.image_settings
    if file_format == "OPEN_EXR_MULTILAYER":
        settings.media_type = "MULTI_LAYER_IMAGE"
    else:
        settings.media_type = "IMAGE"
        settings.file_format = file_format
    settings.color_mode = "RGBA"
    settings.color_depth = "8" if file_format == "PNG" else "32"


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


# Every scene setting that the functions above, render.render_scene, the
# comparison and the study change, as (owner path from the scene, attribute).
# Restored in this order: the image format before its colour mode and depth
# (a format change resets them), the view transform before the look, the
# threads mode before the thread count.
TOUCHED_SETTINGS = (
    ("render", "engine"), ("render", "resolution_x"), ("render", "resolution_y"),
    ("render", "resolution_percentage"), ("render", "filepath"), ("render", "use_file_extension"),
    ("render", "threads_mode"), ("render", "threads"), ("render", "use_overwrite"),
    ("render", "use_placeholder"),
    ("render.image_settings", "media_type"), ("render.image_settings", "file_format"),
    ("render.image_settings", "color_mode"), ("render.image_settings", "color_depth"),
    ("cycles", "samples"), ("cycles", "seed"), ("cycles", "use_denoising"),
    ("cycles", "use_adaptive_sampling"), ("cycles", "sample_clamp_direct"),
    ("cycles", "sample_clamp_indirect"), ("cycles", "blur_glossy"), ("cycles", "device"),
    ("cycles", "time_limit"), ("cycles", "use_layer_samples"),
    ("view_settings", "view_transform"), ("view_settings", "look"),
    ("mcengine", "integrator"), ("mcengine", "depth"), ("mcengine", "branching"),
    ("mcengine", "sampler"),
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

    (The frame is not restored, and the Render Result image keeps the last
    render.)
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
