"""The 3D viewport's Rendered mode: what an edit re-exports, and the progressive render.

Blender calls the engine's ``view_update`` after every change of the scene
(with the depsgraph's list of updated data blocks) and ``view_draw`` whenever
the viewport redraws.  The engine is a thin layer over this module, which
needs no window and is tested headless:

* :func:`parts_to_export` maps the depsgraph's updates to the parts of the
  scene to export again (names of :data:`.export.PARTS`): an object's
  transform or geometry -> "objects"; a material (or a node tree) ->
  "materials"; a light or a light object -> "lights"; the world -> "world";
  the scene's settings -> "settings" and "world"; camera data and camera
  objects -> nothing, because the view (:func:`view_camera`) is read at every
  draw and a change of it only restarts the sampling.
* :class:`ViewportRender` keeps the last export, and runs one progressive
  render at a time on a thread of its own: :meth:`~ViewportRender.frame`
  starts a new render when the scene or the view changed (the old one is
  told to stop and its images are never shown again) and returns the newest
  image of the current one.  The render session polls the stop request
  between chunks, so the old render stops within a tenth of a second; its
  thread is not waited for, so an edit never blocks the interface.

Viewport sampling follows Cycles' viewport settings: ``preview_samples``
samples per pixel (0: until the view changes), no time limit, no adaptive
sampling, and the viewport's denoising (``preview_denoising*``: each image
from the start sample on is shown denoised, with the guides it asks for).
The viewport renders Combined only: no render passes (F12 has them).

:func:`draw_frame` is the only code that needs a window: it draws the image
with Blender's ``gpu`` module through the scene's display transform.
"""
from __future__ import annotations

import threading
from dataclasses import dataclass, replace

import numpy as np

from mcengine.denoise import DenoiseError
from mcengine.scene import Denoising, Film, Integrator, RenderPasses, SceneDescription

from .export import PARTS

__all__ = ["UNLIMITED_SAMPLES", "parts_to_export", "viewport_integrator", "viewport_film",
           "Frame", "ViewportRender", "status_line", "draw_frame"]

# Cycles' preview_samples = 0 renders until stopped; this many samples is "until stopped".
UNLIMITED_SAMPLES = 1 << 24

# Data blocks whose change moves or reshapes what meshes are exported.
_GEOMETRY_IDS = {"MESH", "CURVE", "FONT", "META", "CURVES", "POINTCLOUD", "VOLUME", "LATTICE",
                 "GREASEPENCIL", "GREASEPENCIL_V3"}


def parts_to_export(updates) -> set:
    """The parts of the scene (names of ``export.PARTS``) that ``depsgraph.updates`` change.

    Each update has ``id`` (its ``id_type``, and ``type`` for an object) and
    the flags ``is_updated_geometry``, ``is_updated_transform`` and
    ``is_updated_shading``.  An empty set means that only the view may have
    changed (or nothing that MC Engine renders).
    """
    parts = set()
    for update in updates:
        block = update.id
        kind = block.id_type
        if kind == "OBJECT":
            if block.type == "LIGHT":
                parts.add("lights")
            elif block.type != "CAMERA" and (update.is_updated_geometry
                                             or update.is_updated_transform
                                             or update.is_updated_shading):
                parts.add("objects")
        elif kind in _GEOMETRY_IDS:
            parts.add("objects")
        elif kind == "MATERIAL":
            parts.add("materials")
        elif kind == "LIGHT":
            parts.add("lights")
        elif kind == "WORLD":
            parts.add("world")
        elif kind == "NODETREE":       # a node group used by materials or the world
            parts.update(("materials", "world"))
        elif kind in ("IMAGE", "TEXTURE"):
            parts.update(("materials", "world"))
        elif kind == "COLLECTION":     # objects linked, unlinked, hidden or shown
            parts.update(("objects", "lights"))
        elif kind == "SCENE":
            parts.update(("settings", "world"))
    return parts & PARTS


def viewport_integrator(integrator: Integrator, preview_samples: int) -> Integrator:
    """Cycles' viewport sampling: ``preview_samples`` (0: unlimited), no time limit, no
    adaptive sampling."""
    samples = int(preview_samples) if preview_samples > 0 else UNLIMITED_SAMPLES
    return replace(integrator, samples=samples, time_limit=0.0, use_adaptive_sampling=False)


def viewport_film(film: Film, width: int, height: int) -> Film:
    """The scene's film (filter, exposure, transparency) at the viewport's size, whole frame."""
    return replace(film, width=int(width), height=int(height), pixel_aspect_x=1.0,
                   pixel_aspect_y=1.0, region=None)


@dataclass
class Frame:
    """What the viewport shows: ``image`` (h, w, 4) float32 RGBA, bottom row first (as
    drawn), ``samples`` done, ``target`` samples, ``rendering`` (more will come),
    ``error`` (one line, or "")."""

    image: np.ndarray | None
    samples: int
    target: int
    rendering: bool
    error: str = ""


class _Job:
    """One progressive render on its own thread; ``stop()`` ends it between chunks."""

    def __init__(self, session_factory, desc: SceneDescription, denoise_from: int = 1):
        self.desc = desc
        self._denoise_from = denoise_from
        self._factory = session_factory
        self._stop = threading.Event()
        self._lock = threading.Lock()
        self.image = None
        self.samples = 0
        self.error = ""
        self.finished = threading.Event()
        self.thread = threading.Thread(target=self._run, name="mcengine-viewport", daemon=True)
        self.thread.start()

    def _run(self) -> None:
        try:
            session = self._factory(self.desc)
            if not self._stop.is_set():
                session.run(on_pass=self._publish, should_stop=self._stop.is_set)
        except Exception as exc:   # shown in the viewport, never raised into Blender
            self.error = f"{type(exc).__name__}: {exc}".splitlines()[0]
        finally:
            self.finished.set()

    def _publish(self, session) -> None:
        if self._stop.is_set():
            return
        samples = int(session.samples_done)
        image = None
        if self.desc.denoising.enabled and samples >= self._denoise_from and not self.error:
            try:
                image = session.denoised(bottom_up=True)
            except DenoiseError as exc:       # shown; the noisy images go on
                self.error = f"denoising failed ({exc}); showing the noisy image"
        if image is None:
            image = session.image(bottom_up=True)
        image = np.asarray(image, np.float32)
        with self._lock:
            self.image, self.samples = image, samples

    def stop(self) -> None:
        self._stop.set()

    @property
    def stopped(self) -> bool:
        return self._stop.is_set()

    def frame(self) -> Frame:
        with self._lock:
            image, samples = self.image, self.samples
        return Frame(image=image, samples=samples, target=self.desc.integrator.samples,
                     rendering=not self.finished.is_set(), error=self.error)


class ViewportRender:
    """The viewport's scene (the last export) and its progressive render.

    ``session_factory(desc)`` creates a render session (``RenderSession`` or a
    stand-in with ``run(on_pass, should_stop)``, ``image(bottom_up)`` and
    ``samples_done``); it is called on the render's thread.
    """

    def __init__(self, session_factory):
        self._factory = session_factory
        self.exported = None       # export.ExportResult, the camera being a placeholder
        self._scene_version = 0
        self._key = None           # (scene version, camera, film, samples) of the job
        self._job: _Job | None = None
        self.error = ""            # the last export's failure, one line

    # -- the scene ---------------------------------------------------------------
    def update_scene(self, export, parts) -> bool:
        """Export again with ``export(parts, previous)`` (everything the first time).

        Returns True if the scene changed, in which case the next
        :meth:`frame` restarts the render.  Settings and the world count as
        changed only if their exported values differ.
        """
        if self.exported is not None and not parts:
            return False
        result = export(PARTS if self.exported is None else set(parts), self.exported)
        old, new = (self.exported.scene if self.exported else None), result.scene
        self.exported = result
        self.error = ""
        changed = (old is None or bool(set(parts) & {"objects", "materials", "lights"})
                   or old.world != new.world or old.film != new.film
                   or old.integrator != new.integrator)
        if changed:
            self._scene_version += 1
        return changed

    def export_failed(self, message: str) -> None:
        """The scene could not be exported: stop rendering and show ``message``."""
        self.error = message
        self.stop()

    # -- the render --------------------------------------------------------------
    def frame(self, camera, width: int, height: int, preview_samples: int,
              denoising: Denoising = Denoising(), denoise_from: int = 1) -> Frame:
        """The image to draw for this view, (re)starting the render if anything changed;
        ``denoising`` (the viewport's settings) applies from ``denoise_from`` samples on."""
        if self.error or self.exported is None:
            return Frame(image=None, samples=0, target=0, rendering=False, error=self.error)
        scene = self.exported.scene
        film = viewport_film(scene.film, width, height)
        integrator = viewport_integrator(scene.integrator, preview_samples)
        key = (self._scene_version, _camera_key(camera), film, integrator.samples, denoising,
               denoise_from)
        if key != self._key or self._job is None:
            self.stop()
            self._key = key
            self._job = _Job(self._factory, replace(scene, camera=camera, film=film,
                                                    integrator=integrator, passes=RenderPasses(),
                                                    denoising=denoising), denoise_from)
        return self._job.frame()

    def stop(self) -> None:
        """Tell the current render to stop (it ends within a tenth of a second)."""
        if self._job is not None:
            self._job.stop()
            self._job = None
            self._key = None

    def wait(self, timeout: float | None = None) -> bool:
        """Wait for the current render to finish (tests); True if it did."""
        job = self._job
        return job is None or job.finished.wait(timeout)


def _camera_key(camera) -> tuple:
    """The camera as a hashable value (its arrays, the matrix and motion steps, as bytes)."""
    fields = {name: (np.asarray(value, np.float64).tobytes() if name in ("matrix_world", "motion")
                     else value) for name, value in camera.__dict__.items()}
    return tuple(sorted(fields.items()))


def status_line(frame: Frame) -> str:
    """The viewport's status text: the samples, what is being prepared, or the error."""
    if frame.error:
        return f"MC Engine: {frame.error}"
    if frame.image is None:
        return "Preparing renderer (the first render compiles its kernels, a few minutes)" \
            if frame.rendering else ""
    if frame.target >= UNLIMITED_SAMPLES:
        return f"Sample {frame.samples}"
    return f"Sample {frame.samples}/{frame.target}"


def draw_frame(engine, scene, image: np.ndarray, width: int, height: int) -> None:
    """Draw ``image`` (bottom row first, scene-linear, premultiplied) over the region
    through the scene's view transform; the texture is uploaded once per new image."""
    import gpu
    from gpu_extras.presets import draw_texture_2d

    cached = getattr(engine, "_mcengine_texture", None)
    if cached is None or cached[0] is not image:
        rows, cols = image.shape[:2]
        pixels = gpu.types.Buffer("FLOAT", rows * cols * 4, np.ascontiguousarray(image, np.float32))
        cached = (image, gpu.types.GPUTexture((cols, rows), format="RGBA16F", data=pixels))
        engine._mcengine_texture = cached
    gpu.state.blend_set("ALPHA_PREMULT")
    engine.bind_display_space_shader(scene)
    draw_texture_2d(cached[1], (0, 0), width, height)
    engine.unbind_display_space_shader()
    gpu.state.blend_set("NONE")
