"""Render session: the one entry point the add-on, the CLI and the tests use.

Typical use::

    session = RenderSession(scene)          # validates, builds the BVH, loads kernels
    session.run(on_pass=show, should_stop=esc_pressed)
    rgba = session.image()                  # (h, w, 4) float32, top row first

``run`` renders progressive passes until ``scene.integrator.samples`` samples
per pixel are done, the time limit is reached or ``should_stop()`` returns
True (polled every 0.1 s; a stop takes effect when the chunks being traced
finish, a fraction of a second).  After a stop the image holds what was
rendered so far: every pixel is the mean of its own finished samples.

Work is split into passes (1, 1, 2, 4, ... samples per pixel, so the first
image appears at once) and each pass into chunks of at most ``batch_size``
paths over disjoint pixel ranges, traced by one worker thread each.  The
schedule depends only on the scene and settings, so the same seed gives the
same image for any number of threads.
"""
from __future__ import annotations

import math
import os
import threading
import time
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from dataclasses import dataclass, field

import numpy as np

from . import features as features_mod
from . import integrator as K
from .bsdf import M_EMISSIVE, pack_materials
from .camera import pack_camera
from .film import Film
from .intersect import Accel
from .lights import (L_PMF, light_distribution, pack_lights)
from .sampling import filter_table
from .scene import SceneDescription

DEFAULT_BATCH = 1 << 17       # paths per chunk: ~50 MB of buffers per worker
PASS_PATHS = 1 << 21          # a pass grows until it holds about this many paths
MIN_CHUNK_PATHS = 1 << 12     # below this, per-call overhead dominates


@dataclass
class RenderStats:
    """What the render did and how long it took (seconds, counts)."""

    time_bvh: float = 0.0
    time_kernels: float = 0.0       # compiling or loading the numba kernels
    time_render: float = 0.0        # tracing and shading, wall clock
    time_embree: float = 0.0        # inside Embree, summed over workers
    time_workers: float = 0.0       # busy time summed over workers
    camera_rays: int = 0
    bounce_rays: int = 0
    shadow_rays: int = 0
    self_hits: int = 0
    nonfinite: int = 0
    paths: int = 0
    samples_done: int = 0
    samples_target: int = 0
    eta_seconds: float = float("nan")
    extra: dict = field(default_factory=dict)

    @property
    def rays(self) -> int:
        return self.camera_rays + self.bounce_rays + self.shadow_rays

    @property
    def rays_per_second(self) -> float:
        return self.rays / self.time_render if self.time_render > 0 else 0.0

    @property
    def paths_per_second(self) -> float:
        return self.paths / self.time_render if self.time_render > 0 else 0.0

    @property
    def embree_share(self) -> float:
        return self.time_embree / self.time_workers if self.time_workers > 0 else 0.0

    def rays_per_pixel(self, pixels: int) -> dict:
        p = max(pixels, 1)
        return {"camera": self.camera_rays / p, "bounce": self.bounce_rays / p,
                "shadow": self.shadow_rays / p}


class _TimedAccel:
    """Accel wrapper that adds the time spent in Embree to a worker's counter."""

    def __init__(self, accel, clock):
        self._accel = accel
        self._clock = clock

    def closest(self, o, d, t):
        t0 = time.perf_counter()
        r = self._accel.closest(o, d, t)
        self._clock[0] += time.perf_counter() - t0
        return r

    def occluded(self, o, d, t):
        t0 = time.perf_counter()
        r = self._accel.occluded(o, d, t)
        self._clock[0] += time.perf_counter() - t0
        return r


class _Worker:
    """Buffers and counters of one worker thread, allocated once per render."""

    def __init__(self, batch, accel):
        self.state = K.alloc_path_state(batch)
        self.shadow = K.alloc_shadow_queue(batch)
        self.stats = np.zeros(K.ST_SIZE, np.int64)
        self.embree_clock = [0.0]
        self.busy = 0.0
        self.accel = _TimedAccel(accel, self.embree_clock)


def build_scene_data(scene: SceneDescription):
    """Pack a scene description into kernel arrays; returns (SceneData, cfg, fcfg, Features)."""
    g = scene.geometry
    verts = g.vertices.astype(np.float64)
    tris = np.ascontiguousarray(g.triangles, np.int32)
    if len(tris):
        p = verts[tris]
        cross = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
        length = np.linalg.norm(cross, axis=1)
        tri_area = 0.5 * length
        tri_normal = cross / np.where(length > 0, length, 1.0)[:, None]
        lo, hi = verts.min(axis=0), verts.max(axis=0)
    else:
        tri_area = np.zeros(0)
        tri_normal = np.zeros((0, 3))
        lo = hi = np.zeros(3)
    lamp_pos = [np.asarray(li.matrix_world, float)[:3, 3] for li in scene.lights if li.type != "SUN"]
    if lamp_pos:
        lo = np.minimum(lo, np.min(lamp_pos, axis=0))
        hi = np.maximum(hi, np.max(lamp_pos, axis=0))
    scene_radius = max(0.5 * float(np.linalg.norm(hi - lo)), 1e-6)

    materials = pack_materials(scene.materials)
    mat_index = np.ascontiguousarray(g.material_index, np.int32)
    emissive = (materials[mat_index, M_EMISSIVE] > 0.0) & (tri_area > 0.0) if len(tris) else np.zeros(0, bool)
    emit_tri = np.flatnonzero(emissive).astype(np.int32)
    emit_power = materials[mat_index[emit_tri], 3:6].mean(axis=1) * math.pi * tri_area[emit_tri]
    tri_light = np.full(len(tris), -1, np.int32)
    tri_light[emit_tri] = np.arange(len(emit_tri), dtype=np.int32)

    lamps, lamp_power = pack_lights(scene.lights, scene_radius)
    cdf, lamp_pmf, emit_pmf = light_distribution(lamp_power, emit_power)
    if len(lamps):
        lamps[:, L_PMF] = lamp_pmf
    feats = features_mod.detect(scene, len(emit_tri), lamp_power)

    film = scene.film
    x0, y0, x1, y1 = film.window
    world = np.asarray(scene.world.color, np.float64).reshape(3)
    sc = K.SceneData(
        verts=verts, tris=tris, normals=np.ascontiguousarray(g.normals, np.float32),
        mat_index=mat_index, materials=materials,
        lamps=lamps,
        light_cdf=cdf, emit_tri=emit_tri, emit_pmf=emit_pmf, tri_light=tri_light,
        tri_area=tri_area, tri_normal=tri_normal, world=world, camera=pack_camera(scene.camera, film),
        filter_table=filter_table(film.filter_type, film.filter_width))

    it = scene.integrator
    cfg = np.zeros(K.CFG_SIZE, np.int64)
    cfg[K.CFG_MAX_BOUNCE] = it.max_bounces
    cfg[K.CFG_MAX_DIFFUSE] = it.diffuse_bounces
    cfg[K.CFG_MAX_GLOSSY] = it.glossy_bounces
    cfg[K.CFG_MAX_TRANSMISSION] = it.transmission_bounces
    cfg[K.CFG_MAX_TRANSPARENT] = it.transparent_max_bounces
    cfg[K.CFG_MIN_LIGHT_BOUNCES] = it.min_light_bounces
    cfg[K.CFG_SEED] = it.seed & 0x7FFFFFFFFFFFFFFF
    cfg[K.CFG_FILM_TRANSPARENT] = 1 if film.transparent else 0
    cfg[K.CFG_WORLD_CAMERA] = 1 if scene.world.visible_camera else 0
    cfg[K.CFG_LAMPS_HIT] = 1 if feats.lamps_hit else 0
    cfg[K.CFG_REGION_X], cfg[K.CFG_REGION_Y], cfg[K.CFG_REGION_W] = x0, y0, x1 - x0
    cfg[K.CFG_FULL_W] = film.width
    cfg[K.CFG_LIGHTS] = 1 if feats.nee else 0
    cfg[K.CFG_WORLD] = 1 if feats.world else 0
    fcfg = np.zeros(K.FCFG_SIZE)
    # Cycles compares |r|+|g|+|b| with 3x the clamp setting; 0 means off.
    fcfg[K.FCFG_CLAMP_DIRECT] = 3.0 * it.clamp_direct if it.clamp_direct > 0 else math.inf
    fcfg[K.FCFG_CLAMP_INDIRECT] = 3.0 * it.clamp_indirect if it.clamp_indirect > 0 else math.inf
    return sc, cfg, fcfg, feats


def default_threads() -> int:
    return max(1, min(os.cpu_count() or 1, 64))


class RenderSession:
    """A render of one scene description; see the module docstring."""

    def __init__(self, scene: SceneDescription, *, threads: int | None = None,
                 batch_size: int | None = None):
        self.scene = scene.validate()
        self.threads = int(threads or default_threads())
        self.batch_size = int(batch_size or DEFAULT_BATCH)
        self.stats = RenderStats(samples_target=scene.integrator.samples)
        self.sc, self.cfg, self.fcfg, self.features = build_scene_data(scene)
        x0, y0, x1, y1 = scene.film.window
        self.film = Film(x1 - x0, y1 - y0)
        t0 = time.perf_counter()
        self.accel = Accel(scene.geometry.vertices, scene.geometry.triangles)
        self.stats.time_bvh = time.perf_counter() - t0
        t0 = time.perf_counter()
        self._warm_up()
        self.stats.time_kernels = time.perf_counter() - t0
        self._stop = threading.Event()
        self._workers = threading.local()
        self._all_workers = []
        self._lock = threading.Lock()

    # -- public ------------------------------------------------------------------------
    @property
    def samples_done(self) -> int:
        """Samples every pixel has (the minimum over the film)."""
        return self.film.samples_min()

    def image(self) -> np.ndarray:
        """(h, w, 4) float32 linear RGBA of the film region, top row first."""
        return self.film.image(self.scene.film.exposure)

    def variance(self) -> np.ndarray:
        """(h, w, 3) float32 variance of each pixel's mean (inf below 2 samples)."""
        return self.film.variance(self.scene.film.exposure)

    def stop(self) -> None:
        """Ask a running ``run`` to stop after the chunks in flight."""
        self._stop.set()

    def run(self, on_pass=None, should_stop=None) -> "RenderSession":
        """Render the remaining samples; ``on_pass(self)`` after each pass."""
        target = self.scene.integrator.samples
        time_limit = self.scene.integrator.time_limit
        npix = self.film.count.size
        pixels = np.arange(npix, dtype=np.int32)
        t_start = time.perf_counter()
        done = self.samples_done
        with ThreadPoolExecutor(max_workers=self.threads, thread_name_prefix="mcengine") as pool:
            for spp in self._pass_schedule(done, target, npix):
                if self._stopping(should_stop, t_start, time_limit):
                    break
                ppc = self._pixels_per_chunk(spp, npix)
                futures = {pool.submit(self._trace, pixels[a:a + ppc], spp)
                           for a in range(0, npix, ppc)}
                while futures:
                    finished, futures = wait(futures, timeout=0.1, return_when=FIRST_COMPLETED)
                    for f in finished:
                        f.result()   # re-raise worker errors here
                    if futures and self._stopping(should_stop, t_start, time_limit):
                        self._stop.set()
                self._update_stats(t_start)
                if on_pass is not None:
                    on_pass(self)
                if self._stop.is_set():
                    break
        self._update_stats(t_start)
        return self

    # -- internals -----------------------------------------------------------------------
    def _stopping(self, should_stop, t_start, time_limit) -> bool:
        if self._stop.is_set():
            return True
        if time_limit > 0 and time.perf_counter() - t_start >= time_limit:
            return True
        return bool(should_stop is not None and should_stop())

    @staticmethod
    def _pass_schedule(done, target, npix):
        """Samples per pixel of each pass: 1, 1, 2, 4, ... capped at ~PASS_PATHS per pass."""
        cap = max(1, PASS_PATHS // max(npix, 1))
        spp = 1
        first = True
        while done < target:
            k = min(spp, cap, target - done)
            yield k
            done += k
            if not first:
                spp *= 2
            first = False

    def _pixels_per_chunk(self, spp, npix):
        paths = spp * npix
        # At least two chunks per worker for load balance, at most batch_size paths each.
        per_chunk = min(self.batch_size, max(MIN_CHUNK_PATHS, -(-paths // (2 * self.threads))))
        return max(1, min(npix, per_chunk // spp))

    def _worker(self) -> _Worker:
        w = getattr(self._workers, "w", None)
        if w is None:
            w = _Worker(self.batch_size, self.accel)
            self._workers.w = w
            with self._lock:
                self._all_workers.append(w)
        return w

    def _trace(self, pixels, spp):
        if self._stop.is_set():
            return
        w = self._worker()
        t0 = time.perf_counter()
        K.trace_chunk(pixels, spp, w.accel, self.sc, self.cfg, self.fcfg, w.state, w.shadow,
                      self.film.arrays, w.stats)
        w.busy += time.perf_counter() - t0

    def _warm_up(self):
        """Compile (or load from the cache) every kernel on a one-pixel scratch film."""
        w = _Worker(64, self.accel)
        scratch = Film(1, 1)
        K.trace_chunk(np.zeros(1, np.int32), 1, w.accel, self.sc, self.cfg, self.fcfg,
                      w.state, w.shadow, scratch.arrays, w.stats)

    def _update_stats(self, t_start):
        s = self.stats
        s.time_render = time.perf_counter() - t_start
        totals = np.zeros(K.ST_SIZE, np.int64)
        with self._lock:
            workers = list(self._all_workers)
        for w in workers:
            totals += w.stats
        s.camera_rays = int(totals[K.ST_CAMERA_RAYS])
        s.bounce_rays = int(totals[K.ST_BOUNCE_RAYS])
        s.shadow_rays = int(totals[K.ST_SHADOW_RAYS])
        s.self_hits = int(totals[K.ST_SELF_HITS])
        s.nonfinite = int(totals[K.ST_NONFINITE])
        s.paths = s.camera_rays
        s.time_embree = sum(w.embree_clock[0] for w in workers)
        s.time_workers = sum(w.busy for w in workers)
        s.samples_done = self.samples_done
        remaining = (s.samples_target - s.samples_done) * self.film.count.size
        s.eta_seconds = remaining / s.paths_per_second if s.paths_per_second > 0 else float("nan")
