"""Material, light and world previews: Blender's preview scene, rendered cheaply.

With ``bl_use_preview`` Blender asks the engine to render its own preview
scene (a sphere, cube or other shape carrying the material, a light over a
floor, a world around a sphere) at the size of the preview or icon, with
``RenderEngine.is_preview`` set.  The export is the same as for F12; only the
sampling changes (:func:`preview_integrator`): :data:`PREVIEW_SAMPLES`
samples per pixel, no time limit and no adaptive sampling, whatever the
preview scene's own Cycles settings say (its file keeps Cycles' 4096
samples).  Previews do not report warnings (the user's scene is not the one
rendered), and they leave the last render's statistics alone.

:func:`render_icon` renders an ID's preview icon without a window (tests and
``tools/preview_gallery.py``).
"""
from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from mcengine.scene import Integrator

__all__ = ["PREVIEW_SAMPLES", "preview_integrator", "render_icon"]

# Samples per pixel of a preview: 16 keep a 128 x 128 icon under a second on two
# cores (about a quarter of a second measured) and the material's colour clear.
PREVIEW_SAMPLES = 16


def preview_integrator(integrator: Integrator) -> Integrator:
    """The preview's sampling: few samples, no time limit, every pixel sampled alike."""
    return replace(integrator, samples=min(int(integrator.samples), PREVIEW_SAMPLES),
                   time_limit=0.0, use_adaptive_sampling=False)


def render_icon(idblock, timeout: float = 300.0) -> np.ndarray:
    """Render the preview icon of a material, light or world with the current scene's
    engine; returns it as (h, w, 4) display-referred RGBA, bottom row first.

    Blender renders icons on a job thread, and without a window nothing tells
    when the job ends, so the icon's pixels are polled until they are written
    and stop changing.  Raises TimeoutError after ``timeout`` seconds (a cold
    numba cache first compiles the kernels, a few minutes).
    """
    import bpy

    def pixels():
        w, h = idblock.preview.image_size
        return np.array(idblock.preview.image_pixels_float[:], np.float64).reshape(h, w, 4)

    with bpy.context.temp_override(id=idblock):
        bpy.ops.ed.lib_id_generate_preview()
    deadline = time.monotonic() + timeout
    previous = None
    while time.monotonic() < deadline:
        current = pixels()
        if current[..., 3].any() and previous is not None and np.array_equal(current, previous):
            return current
        previous = current if current[..., 3].any() else None
        time.sleep(0.25)
    raise TimeoutError(f"no preview of {idblock.name} within {timeout:.0f} s")
