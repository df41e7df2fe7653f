"""The MC Engine render engine: F12, previews and the viewport render with mcengine.

``render(depsgraph)`` exports the evaluated scene to a
:class:`mcengine.scene.SceneDescription`, creates a render session and shows
every progressive pass in the Render Result, with progress and statistics in
the status bar.  Esc stops the render between passes (the session polls
``test_break``) and keeps the partial image.  Material, light and world
previews go through ``render`` too, with the preview's sampling
(``preview.py``).  The viewport's Rendered mode is ``view_update`` and
``view_draw``, thin calls into ``viewport.py``.

Errors never escape as tracebacks: an invalid scene or any failure becomes
one ERROR report (and ``error_set``); unsupported features become one WARNING
report each.  Images from the core are top row first; Blender's render
passes are bottom row first, so rows are flipped when written.
"""
from __future__ import annotations

import logging
import math
import time

import bpy
import numpy as np

from mcengine.scene import Camera, SceneError

from . import export
from .export.camera import camera_from_view
from .export.settings import unit_scale
from .preview import preview_integrator
from .viewport import ViewportRender, draw_frame, parts_to_export, status_line

__all__ = ["ENGINE_ID", "MCEngine", "session_factory", "register", "unregister"]

ENGINE_ID = "MCENGINE"
log = logging.getLogger(__name__)


# Blender's own image memory per rendered pixel: the render result's float RGBA
# pass, and the copy the image editor and file output make of it.
BLENDER_BYTES_PER_PIXEL = 2 * 4 * 4


def default_session_factory(scene, threads=None):
    """Create the core's render session (imported lazily: it loads numba kernels)."""
    from mcengine.session import RenderSession
    return RenderSession(scene, threads=threads, host_bytes_per_pixel=BLENDER_BYTES_PER_PIXEL)


#: Callable ``(SceneDescription, threads=None) -> session``; tests replace it with a fake.
session_factory = default_session_factory

#: What the last render did, for the command line and tools: ``stats`` (the
#: session's RenderStats), ``pixels``, ``export_seconds``, ``accounting`` (one line).
last_render: dict = {}


class MCEngine(bpy.types.RenderEngine):
    """Final renders, material, light and world previews, and the viewport's Rendered mode
    with mcengine."""

    bl_idname = ENGINE_ID
    bl_label = "MC Engine"
    # False: keep Cycles' shader nodes and material panels, which the exporter reads.
    bl_use_shading_nodes_custom = False
    # Material Preview viewport shading uses EEVEE, as for Cycles.
    bl_use_eevee_viewport = True
    # Material, light and world previews (and their icons) render with MC Engine
    # (see preview.py).
    bl_use_preview = True

    def render(self, depsgraph):
        desc, session = self._prepare(depsgraph)
        if session is None:
            return
        x0, y0, x1, y1 = desc.film.window
        self._pixels = (x1 - x0) * (y1 - y0)
        result = self.begin_result(0, 0, x1 - x0, y1 - y0)
        progress = _Progress(desc.integrator.samples, desc.integrator.time_limit)
        try:
            session.run(on_pass=lambda s: self._publish(result, s, progress),
                        should_stop=self._stop_requested)
        except Exception as exc:
            self._fail(_describe(exc, "rendering"), exc)
        finally:
            try:
                self._write_pixels(result, session)  # the final (or partial) image
            except Exception as exc:
                self._fail(_describe(exc, "reading the image"), exc)
            self.end_result(result)
            if not self.is_preview:
                self._record(depsgraph.scene.original, session)

    # -- the 3D viewport's Rendered mode (viewport.py) -------------------------
    def view_update(self, context, depsgraph):
        """After an edit: export again what it changed (everything the first time)."""
        render = self._viewport()
        try:
            render.update_scene(
                lambda parts, previous: export.export(depsgraph, camera=Camera(), parts=parts,
                                                      previous=previous),
                parts_to_export(depsgraph.updates))
        except Exception as exc:
            log.debug("MC Engine viewport export failed", exc_info=exc)
            render.export_failed(_describe(exc, "exporting the scene"))

    def view_draw(self, context, depsgraph):
        """Draw the newest image of the view's progressive render, restarting it if the view
        or the scene changed; ask for another redraw while it renders."""
        render = self._viewport()
        scene = depsgraph.scene
        region, view = context.region, context.region_data
        scale = max(1, int(self.get_preview_pixel_size(scene)))
        camera = camera_from_view(view.view_matrix, view.window_matrix, unit_scale(scene))
        cycles = getattr(scene, "cycles", None)
        frame = render.frame(camera, max(1, region.width // scale), max(1, region.height // scale),
                             cycles.preview_samples if cycles is not None else 0)
        if frame.image is not None:
            draw_frame(self, scene, frame.image, region.width, region.height)
        self.update_stats("", status_line(frame))
        if frame.rendering:
            self.tag_redraw()

    def _viewport(self) -> ViewportRender:
        render = getattr(self, "_mcengine_viewport", None)
        if render is None:
            # Looked up at each render, so that tests and the command line can replace it.
            render = ViewportRender(lambda desc: session_factory(desc))
            self._mcengine_viewport = render
        return render

    def __del__(self):
        # Blender frees the engine (the viewport left Rendered mode): stop its render.
        try:
            render = getattr(self, "_mcengine_viewport", None)
        except ReferenceError:      # the Blender side is already gone
            return
        if render is not None:
            render.stop()

    # -- steps ---------------------------------------------------------------
    def _prepare(self, depsgraph):
        """Export and create the session: (scene description, session), or (None, None)
        after reporting an error."""
        self.update_stats("", "Exporting scene")
        start = time.perf_counter()
        try:
            exported = export.export(depsgraph)
        except Exception as exc:
            self._fail(_describe(exc, "exporting the scene"), exc)
            return None, None
        seconds = time.perf_counter() - start
        self._export_seconds = seconds
        log.info("scene exported in %.3f s", seconds)
        if self.is_preview:   # Blender's preview scene: few samples, no reports
            exported.scene.integrator = preview_integrator(exported.scene.integrator)
        for warning in () if self.is_preview else exported.scene.warnings:
            self.report({"WARNING"}, warning)
        # The first render after installing compiles the numba kernels (cached afterwards).
        self.update_stats("", f"Exported in {seconds:.2f} s | Preparing renderer (the first "
                              f"render compiles its kernels, about a minute)")
        render = depsgraph.scene.render
        # Blender's Performance > Threads setting; AUTO leaves the choice to the core.
        threads = render.threads if render.threads_mode == "FIXED" else None
        try:
            session = session_factory(exported.scene, threads=threads)
        except Exception as exc:
            self._fail(_describe(exc, "preparing the renderer"), exc)
            return None, None
        if not self.is_preview:
            _store_effects(depsgraph.scene.original, session.plan, exported.ignored)
        return exported.scene, session

    def _publish(self, result, session, progress) -> None:
        """After each pass: show the image, the progress and the statistics."""
        self._write_pixels(result, session)
        done = int(session.samples_done)
        self.update_progress(progress.fraction(done))
        self.update_stats("", stats_line(done, progress.samples, getattr(session, "stats", None),
                                         self._pixels))

    def _record(self, scene, session) -> None:
        """Keep the last render's ray accounting for the panel and the command line."""
        stats = getattr(session, "stats", None)
        if stats is None or not hasattr(stats, "accounting"):
            return
        line = stats.accounting(self._pixels, self._export_seconds)
        last_render.clear()
        last_render.update(stats=stats, pixels=self._pixels, export_seconds=self._export_seconds,
                           accounting=line)
        settings = getattr(scene, "mcengine", None)
        if settings is not None:
            settings["last_accounting"] = line

    def _write_pixels(self, result, session) -> None:
        """Copy the session's image into the Combined pass (Blender's rows: bottom first)."""
        image = np.asarray(session.image(bottom_up=True), np.float32)
        width, height = result.resolution_x, result.resolution_y
        if image.shape != (height, width, 4):
            raise SceneError(f"the renderer returned an image of shape {image.shape} for a "
                             f"{width}x{height} render region")
        result.layers[0].passes["Combined"].rect.foreach_set(image.reshape(-1))
        self.update_result(result)

    def _stop_requested(self) -> bool:
        """Polled by the session: True once the user pressed Esc."""
        return self.test_break()

    def _fail(self, message: str, exc: Exception) -> None:
        log.debug("MC Engine error", exc_info=exc)
        if self.is_preview:   # a preview stays empty; the user's render reports the problem
            return
        self.report({"ERROR"}, f"MC Engine: {message}")
        self.error_set(f"MC Engine: {message}")


class _Progress:
    """Render progress: samples done over samples, or elapsed over the time limit if later."""

    def __init__(self, samples: int, time_limit: float):
        self.samples = max(int(samples), 1)
        self.time_limit = float(time_limit)
        self.start = time.perf_counter()

    def fraction(self, samples_done: int) -> float:
        fraction = samples_done / self.samples
        if self.time_limit > 0:
            fraction = max(fraction, (time.perf_counter() - self.start) / self.time_limit)
        return min(fraction, 1.0)


def stats_line(done: int, total: int, stats, pixels: int = 0) -> str:
    """Status-bar text, e.g. "Sample 12/64 | 3.1 Mrays/s | Rays/px 12 cam, 30 bounce, 25 shadow |
    Remaining 00:04".

    Parts ``stats`` lacks (no ``rays_per_second`` or ``eta_seconds``, or a value
    that is not finite yet) are left out.
    """
    parts = [f"Sample {done}/{total}"]
    rate = getattr(stats, "rays_per_second", None)
    if rate is not None and math.isfinite(rate) and rate > 0:
        parts.append(f"{rate / 1e6:.1f} Mrays/s")
    per_pixel = getattr(stats, "rays_per_pixel", None)
    if pixels > 0 and callable(per_pixel):
        r = per_pixel(pixels)
        parts.append(f"Rays/px {r['camera']:.0f} cam, {r['bounce']:.0f} bounce, "
                     f"{r['shadow']:.0f} shadow")
    eta = getattr(stats, "eta_seconds", None)
    if eta is not None and math.isfinite(eta):
        parts.append(f"Remaining {_clock(eta)}")
    nonfinite = getattr(stats, "nonfinite", 0)
    if nonfinite:
        parts.append(f"{nonfinite:,} non-finite samples dropped")
    return " | ".join(parts)


def _clock(seconds: float) -> str:
    minutes, secs = divmod(int(round(max(seconds, 0.0))), 60)
    hours, minutes = divmod(minutes, 60)
    return f"{hours}:{minutes:02d}:{secs:02d}" if hours else f"{minutes:02d}:{secs:02d}"


def _describe(exc: Exception, doing: str) -> str:
    """One line for the user: scene errors as they are, anything else with its type."""
    if isinstance(exc, SceneError):
        return str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    return f"failed while {doing}: {type(exc).__name__}: {exc}".splitlines()[0]


def _store_effects(scene, plan, ignored) -> None:
    """Remember what the render simulated (its effects plan) and ignored, for the MC Engine
    panel, the command line and the reports.

    Written as ID properties rather than through RNA: the render may run off the
    main thread, and RNA updates would send notifiers from it.
    """
    settings = getattr(scene, "mcengine", None)
    if settings is not None:
        settings["last_effects"] = plan.summary()
        settings["last_ignored"] = ", ".join(ignored)


def register() -> None:
    if not MCEngine.is_registered:
        bpy.utils.register_class(MCEngine)


def unregister() -> None:
    if MCEngine.is_registered:
        bpy.utils.unregister_class(MCEngine)
