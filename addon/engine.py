"""The MC Engine render engine: F12, previews and the viewport render with mcengine.

``render(depsgraph)`` exports the evaluated scene to a
:class:`mcengine.scene.SceneDescription`, creates a render session and shows
every progressive pass in the Render Result, with progress and statistics in
the status bar.  Esc stops the render between passes (the session polls
``test_break``) and keeps the partial image.  At the end the render passes the
view layer enables are written (``update_render_passes`` registers the same
list for the compositor, as Cycles does), Combined is denoised when Cycles'
denoising is on (the noisy image goes to "Noisy Image"), and the render's
statistics and Cryptomatte manifests go to the result's metadata (shown in the
image editor's Metadata panel, written to EXR headers).  Material, light and
world previews go through ``render`` too, with the preview's sampling
(``preview.py``), Combined only.  The viewport's Rendered mode is
``view_update`` and ``view_draw``, thin calls into ``viewport.py`` (Combined
only, not denoised).

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

from mcengine.scene import Camera, Denoising, RenderPasses, SceneError

from . import export, warmup
from .export.camera import camera_from_view
from .export.passes import preview_denoising, result_passes
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

    def update_render_passes(self, scene=None, renderlayer=None):
        """Register the passes of ``renderlayer`` for the compositor (as Cycles lists them)."""
        for name, channels, kind in result_passes(scene, renderlayer):
            self.register_pass(scene, renderlayer, name, len(channels), channels, kind)

    def render(self, depsgraph):
        t_start = time.perf_counter()
        desc, session = self._prepare(depsgraph)
        if session is None:
            return
        x0, y0, x1, y1 = desc.film.window
        self._pixels = (x1 - x0) * (y1 - y0)
        layer = depsgraph.view_layer.name
        # Previews show Combined only, never denoised.
        passes = ([("Combined", "RGBA", "COLOR")] if self.is_preview
                  else result_passes(depsgraph.scene, depsgraph.view_layer))
        for name, channels, _kind in passes[1:]:
            self.add_pass(name, len(channels), channels, layer=layer)
        result = self.begin_result(0, 0, x1 - x0, y1 - y0, layer=layer)
        progress = _Progress(desc.integrator.samples, desc.integrator.time_limit)
        try:
            session.run(on_pass=lambda s: self._publish(result, s, progress),
                        should_stop=self._stop_requested)
        except Exception as exc:
            self._fail(_describe(exc, "rendering"), exc)
        finally:
            try:
                self._write_final(result, session, desc, [p[0] for p in passes[1:]])
            except Exception as exc:
                self._fail(_describe(exc, "reading the image"), exc)
            try:
                if not self.is_preview:
                    self._write_metadata(result, session, desc, layer,
                                         time.perf_counter() - t_start)
            except Exception as exc:
                self._fail(_describe(exc, "writing the render statistics"), exc)
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
        denoising, denoise_from = preview_denoising(scene)
        frame = render.frame(camera, max(1, region.width // scale), max(1, region.height // scale),
                             cycles.preview_samples if cycles is not None else 0,
                             denoising, denoise_from)
        if frame.image is not None:
            draw_frame(self, scene, frame.image, region.width, region.height)
        self.update_stats("", status_line(frame))
        if frame.rendering:
            self.tag_redraw()

    def _viewport(self) -> ViewportRender:
        render = getattr(self, "_mcengine_viewport", None)
        if render is None:
            # Looked up at each render, so that tests and the command line can replace it.
            # On the render's thread: it waits for a background kernel compile to end.
            render = ViewportRender(lambda desc: (warmup.wait(lambda: False,
                                                              integrator=desc.integrator.name),
                                                  session_factory(desc))[1])
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
            exported = export.export(depsgraph, frame_set=self.frame_set)
        except Exception as exc:
            self._fail(_describe(exc, "exporting the scene"), exc)
            return None, None
        seconds = time.perf_counter() - start
        self._export_seconds = seconds
        log.info("scene exported in %.3f s", seconds)
        if self.is_preview:   # Blender's preview scene: few samples, no reports, no passes
            exported.scene.integrator = preview_integrator(exported.scene.integrator)
            exported.scene.passes = RenderPasses()
            exported.scene.denoising = Denoising()
        for warning in () if self.is_preview else exported.scene.warnings:
            self.report({"WARNING"}, warning)
        # Kernels being compiled in the background since the add-on was enabled: wait for
        # this integrator's rather than compile them twice.
        if not warmup.wait(self.test_break, lambda line: self.update_stats("", line),
                           integrator=exported.scene.integrator.name):
            return None, None
        # The first render after installing compiles the numba kernels (cached afterwards).
        self.update_stats("", f"Exported in {seconds:.2f} s | Preparing renderer (the first "
                              f"render compiles its kernels, a few minutes)")
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
            for warning in session.warnings:
                self.report({"WARNING"}, warning)
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
        self._write_pass(result, "Combined", session.image(bottom_up=True))
        self.update_result(result)

    def _write_pass(self, result, name: str, image) -> None:
        """Copy an (h, w, C) image, bottom row first, into pass ``name`` of the result."""
        image = np.asarray(image, np.float32)
        width, height = result.resolution_x, result.resolution_y
        target = result.layers[0].passes[name]
        if image.shape != (height, width, target.channels):
            raise SceneError(f"the renderer returned an image of shape {image.shape} for the "
                             f"{width}x{height} pass {name!r} of {target.channels} channels")
        target.rect.foreach_set(image.reshape(-1))

    def _write_final(self, result, session, desc, names) -> None:
        """The final (or partial) image, denoised if asked, and every render pass."""
        available = set(session.pass_names())
        noisy = session.image(bottom_up=True)
        combined = noisy
        if desc.denoising.enabled:
            self.update_stats("", "Denoising")
            try:
                combined = session.denoised(bottom_up=True)
            except Exception as exc:   # OIDN failed: the noisy image, and say so
                self.report({"WARNING"}, f"MC Engine: {_describe(exc, 'denoising')}; "
                                         f"the image is not denoised")
        self._write_pass(result, "Combined", combined)
        for name in names:
            if name == "Noisy Image":
                image = noisy
            elif name in available:
                image = session.pass_image(name, bottom_up=True)
            else:   # a pass this render does not compute (the warning said so)
                channels = result.layers[0].passes[name].channels
                image = np.zeros((result.resolution_y, result.resolution_x, channels), np.float32)
            self._write_pass(result, name, image)
        self.update_result(result)

    def _write_metadata(self, result, session, desc, layer: str, seconds: float) -> None:
        """Render statistics and Cryptomatte manifests in the result's metadata."""
        from mcengine.passes import cryptomatte_metadata
        fields = {}
        stats = getattr(session, "stats", None)
        if hasattr(stats, "metadata"):
            fields.update({f"mcengine.{layer}.{key}": value for key, value in
                           stats.metadata(seconds, desc.integrator.samples).items()})
        fields.update(cryptomatte_metadata(desc.passes, desc.geometry.object_pass_info(),
                                           desc.materials, desc.geometry.material_index.tolist()))
        # The engine's whole result, as Cycles does (a tile's metadata is not merged into it).
        full = self.get_result() or result
        for key, value in fields.items():
            full.stamp_data_add_field(key, value)

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
