"""Render session: the one entry point the add-on, the CLI and the tests use.

Typical use::

    session = RenderSession(scene)          # validates, builds the BVH, loads kernels
    session.run(on_pass=show, should_stop=esc_pressed)
    rgba = session.image()                  # (h, w, 4) float32, top row first
    depth = session.pass_image("Depth")     # render passes the scene asks for
    clean = session.denoised()              # with the scene's denoising settings

``run`` renders progressive passes until ``scene.integrator.samples`` samples
per pixel are done, the time limit is reached or ``should_stop()`` returns
True (polled every 0.1 s; a stop takes effect when the chunks being traced
finish, a fraction of a second).  After a stop the image holds what was
rendered so far: every pixel is the mean of its own finished samples.

Work is split into passes (1, 1, 2, 4, ... samples per pixel, so the first
image appears at once; after the first, the rest in one pass once it is at most
``QUICK_FINISH_PATHS`` paths, a fraction of a second, unless a time limit asks for
finer steps) and each pass into chunks of at most ``batch_size`` paths over
disjoint pixel ranges, shrinking towards the pass's end so that the workers finish
it together (``_chunks``), traced by one worker thread each.  The schedule depends
only on the scene and settings, so the same seed gives the same image for any
number of threads.
"""
from __future__ import annotations

import os
import threading
import time
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from dataclasses import dataclass, field

import numpy as np

from . import accel_cache, blas, displacement, memory
from . import passes as render_passes
from .adaptive import Adaptive
from .denoise import denoise
from .film import Film
from .integrators import get as integrator_info
from .kernels import classic, light_tracing, path
from .kernels.classic import WHITTED_RAYS
from .kernels.closures.layout import ROUGHNESS_SQ_THRESHOLD
from .kernels.passes import (
    P_AO,
    P_DENOISING_ALBEDO,
    P_DENOISING_NORMAL,
    PC_DENOISE,
    PC_LIGHT,
    alloc_pass_buffers,
)
from .kernels.state import (
    MF_CLOSURES_ONLY,
    ST_BOUNCE_RAYS,
    ST_CAMERA_RAYS,
    ST_NONFINITE,
    ST_SELF_HITS,
    ST_SHADOW_RAYS,
    ST_SIZE,
    alloc_path_state,
    alloc_scratch,
    alloc_shadow_queue,
)
from .kernels.svm import OP_CLOSURE
from .kernels.svm.nodes import (
    G_ROUGHNESS,
    GL_ROUGHNESS,
    K_GLASS,
    K_GLOSSY,
    K_METALLIC,
    K_PRINCIPLED,
    K_REFRACTION,
    M_ROUGHNESS,
    P_ALPHA,
    P_COAT_ROUGHNESS,
    P_COAT_WEIGHT,
    P_METALLIC,
    P_ROUGHNESS,
    P_TRANSMISSION,
    R_ROUGHNESS,
)
from .packing import pack_passes, pack_scene, scene_images
from .parallel import in_background
from .scene import SceneDescription, SceneError

DEFAULT_BATCH = 1 << 17       # paths per chunk: ~50 MB of buffers per worker
PASS_PATHS = 1 << 21          # a pass grows until it holds about this many paths
MIN_CHUNK_PATHS = 1 << 12     # below this, per-call overhead dominates
# After the first pass, a rest of at most this many paths is rendered in one pass: each pass
# ends in a wait for its last chunk, and small renders (previews, the viewport, a study's
# rungs) spent 5-11 % of their tracing time in those waits and in small chunks.
QUICK_FINISH_PATHS = 1 << 18


@dataclass
class RenderStats:
    """What the render did and how long it took (seconds, counts)."""

    time_pack: float = 0.0          # packing the scene for the kernels: true displacement,
                                    # tables, shaders, the world's map (a first run also
                                    # compiles the shader evaluator, which packing runs once
                                    # per material)
    time_bvh: float = 0.0           # building (or reusing) the BVH; without moving objects
                                    # on its own thread beside the packing (the two overlap,
                                    # extra["bvh_wait"]: what was left to wait for after it)
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
    texture_bytes: int = 0          # texels of the images the shaders read
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

    def phases(self, time_export: float = 0.0) -> dict:
        """Seconds per phase; tracing and shading are summed over the worker threads."""
        return {"export": time_export, "pack": self.time_pack, "bvh": self.time_bvh,
                "kernels": self.time_kernels,
                "tracing": self.time_embree, "shading": max(self.time_workers - self.time_embree, 0.0),
                "render": self.time_render}

    def metadata(self, total_seconds: float, samples: int) -> dict:
        """Statistics for the image's metadata, named and formatted as Cycles' (its keys
        after "cycles.<view layer>."; times as "MM:SS.hh"): ``samples`` (configured),
        ``total_time``, ``render_time``, ``synchronization_time`` (total less render);
        and ``samples_rendered``, ``rays_per_second``, ``nonfinite_samples``."""
        render = min(self.time_render, total_seconds)
        return {"samples": str(int(samples)), "samples_rendered": str(int(self.samples_done)),
                "total_time": clock_text(total_seconds), "render_time": clock_text(render),
                "synchronization_time": clock_text(total_seconds - render),
                "rays_per_second": f"{self.rays_per_second:.0f}",
                "nonfinite_samples": str(int(self.nonfinite))}

    def accounting(self, pixels: int, time_export: float = 0.0) -> str:
        """One line: rays per pixel by kind, Mrays/s, time per phase, and the count of
        non-finite samples dropped when there were any (so a bug cannot hide behind the guard)."""
        r = self.rays_per_pixel(pixels)
        t = self.phases(time_export)
        line = (f"rays/pixel: camera {r['camera']:.1f}, bounce {r['bounce']:.1f}, "
                f"shadow {r['shadow']:.1f} | {self.rays_per_second / 1e6:.2f} Mrays/s | "
                f"export {t['export']:.2f} s, pack {t['pack']:.2f} s, BVH {t['bvh']:.2f} s, "
                f"kernels {t['kernels']:.2f} s, "
                f"tracing {t['tracing']:.2f} s, shading {t['shading']:.2f} s (thread-seconds), "
                f"wall {t['render']:.2f} s")
        if self.texture_bytes:
            line += f" | images {self.texture_bytes / (1 << 20):.1f} MiB"
        if self.nonfinite:
            line += f" | {self.nonfinite:,} non-finite samples dropped"
        return line


def clock_text(seconds: float) -> str:
    """Cycles' time_human_readable_from_seconds: "MM:SS.hh", or "HH:MM:SS.hh" from an hour."""
    seconds = max(float(seconds), 0.0)
    whole = int(seconds)
    h, m, sec, hundredths = whole // 3600, (whole // 60) % 60, whole % 60, int(seconds * 100) % 100
    if h > 0:
        return f"{h:02d}:{m:02d}:{sec:02d}.{hundredths:02d}"
    return f"{m:02d}:{sec:02d}.{hundredths:02d}"


class _TimedAccel:
    """Accel wrapper that adds the time spent in Embree to a worker's counter."""

    def __init__(self, accel, clock):
        self._accel = accel
        self._clock = clock
        self.masked = accel.masked

    def closest(self, o, d, t, times=None, mask=None):
        t0 = time.perf_counter()
        r = self._accel.closest(o, d, t, times, mask)
        self._clock[0] += time.perf_counter() - t0
        return r

    def occluded(self, o, d, t, times=None, mask=None):
        t0 = time.perf_counter()
        r = self._accel.occluded(o, d, t, times, mask)
        self._clock[0] += time.perf_counter() - t0
        return r


class _Buffers:
    """Wavefront buffers of one worker: allocated once, reused by later renders.

    Freshly mapped memory is slow on first touch on these machines (about
    2 s per GB), so buffers go back to a pool when a render ends and the next
    render of the same batch size takes them from there.
    """

    _pool: dict = {}
    _pool_lock = threading.Lock()

    def __init__(self, batch, classic, passes=False, ao=False):
        self.key = (batch, classic, passes, ao)
        self.state = alloc_path_state(batch)
        # A shadow ray per path and bounce, and at camera vertices an Ambient Occlusion one.
        shadows = 2 * batch if ao else batch
        self.shadow = alloc_shadow_queue(shadows)
        # Render passes' per-path buffers: full size only for light passes or denoising.
        self.passes = alloc_pass_buffers(batch if passes else 1, shadows if passes else 1)
        if classic:   # a second generation of rays and per-camera-sample sums
            self.next_state = alloc_path_state(batch)
            self.acc = np.zeros((batch, 4))
            self.root_pixel = np.zeros(batch, np.int32)

    @staticmethod
    def bytes_for(batch, classic, passes=False, ao=False) -> int:
        """Memory of one worker's buffers for ``batch`` paths (without allocating them)."""
        one = _Buffers(1, classic, passes, ao).nbytes
        two = _Buffers(2, classic, passes, ao).nbytes
        return (two - one) * batch + (2 * one - two)     # per path, plus the fixed part

    @property
    def nbytes(self) -> int:
        arrays = [*self.state, *self.shadow, *self.passes]
        if self.key[1]:
            arrays += [*self.next_state, self.acc, self.root_pixel]
        return sum(a.nbytes for a in arrays)

    @classmethod
    def take(cls, batch, classic, passes=False, ao=False) -> "_Buffers":
        with cls._pool_lock:
            free = cls._pool.get((batch, classic, passes, ao))
            if free:
                return free.pop()
        return cls(batch, classic, passes, ao)

    def give_back(self) -> None:
        with self._pool_lock:
            free = self._pool.setdefault(self.key, [])
            if len(free) < default_threads():
                free.append(self)


class _Worker:
    """One worker thread's buffers, counters and timers for one render."""

    def __init__(self, buffers, accel, sc, splat_pixels=0):
        self.buffers = buffers
        self.scratch = alloc_scratch(sc)       # closures and shader registers of this scene
        # Light tracing: a second scratch (a vertex shaded for the camera), the film its
        # light paths add to (the film region's pixels) and how many it traced.
        self.cam_scratch = alloc_scratch(sc) if splat_pixels else None
        self.splat = np.zeros((splat_pixels, 3)) if splat_pixels else None
        self.light_paths = 0
        self.stats = np.zeros(ST_SIZE, np.int64)
        self.embree_clock = [0.0]
        self.busy = 0.0
        self.accel = _TimedAccel(accel, self.embree_clock)


def _constant_closure_rays(kind: int, regs, b: int) -> int:
    """Rays a Whitted hit spawns for closure node ``kind`` whose inputs are the constants at
    regs[b:] (at most ``WHITTED_RAYS[kind]``): a microfacet lobe spawns its mirror ray (and
    a glass lobe its refracted ray too) only when smooth, alpha_x alpha_y = roughness^4 at
    most ROUGHNESS_SQ_THRESHOLD, as ``kernels.classic`` decides."""
    def smooth(roughness):
        return min(max(roughness, 0.0), 1.0) ** 4 <= ROUGHNESS_SQ_THRESHOLD

    if kind == K_PRINCIPLED:
        r = smooth(regs[b + P_ROUGHNESS])
        return (int(regs[b + P_ALPHA] < 1.0)
                + int(regs[b + P_COAT_WEIGHT] > 0.0 and smooth(regs[b + P_COAT_ROUGHNESS]))
                + int(r and regs[b + P_METALLIC] > 0.0)
                + 2 * int(r and regs[b + P_TRANSMISSION] > 0.0)
                + int(r))                                           # the dielectric specular
    roughness = {K_GLOSSY: G_ROUGHNESS, K_METALLIC: M_ROUGHNESS, K_GLASS: GL_ROUGHNESS,
                 K_REFRACTION: R_ROUGHNESS}.get(kind)
    if roughness is not None and not smooth(abs(regs[b + roughness])):
        return 0
    return WHITTED_RAYS.get(kind, 0)


def default_threads() -> int:
    return max(1, min(os.cpu_count() or 1, 64))


class RenderSession:
    """A render of one scene description; see the module docstring."""

    def __init__(self, scene: SceneDescription, *, threads: int | None = None,
                 batch_size: int | None = None, host_bytes_per_pixel: int = 0,
                 force_effects=()):
        blas.use_one_thread()          # numpy's small matrix calls: microseconds, not ms
        # Truly displaced meshes move first: the packed tables and the BVH see them moved.
        t0 = time.perf_counter()
        scene = scene.validate()
        images = scene_images(scene)   # once, for both: a 4K image takes about 0.06 s
        scene = self.scene = displacement.displace(scene, images)
        time_displace = time.perf_counter() - t0
        self.threads = int(threads or default_threads())
        self.batch_size = int(batch_size or DEFAULT_BATCH)
        it = scene.integrator
        self.stats = RenderStats(samples_target=it.samples)
        # Without moving objects the BVH needs nothing of the packing: Embree builds it while
        # the scene is packed (numpy and Embree release the GIL).
        visibility = scene.geometry.triangle_visibility()
        bvh = None if scene.motion_blur and scene.motion_blur.objects else \
            in_background(lambda: self._build_bvh(scene, None, visibility))
        # The effects plan (``features``): what the scene calls for, as kernel flags.
        t0 = time.perf_counter()
        self.sc, self.cfg, self.fcfg, self.plan = pack_scene(scene, force_effects, images)
        self.stats.time_pack = time.perf_counter() - t0 + time_displace
        self.stats.texture_bytes = int(self.sc.tex.pix8.nbytes + self.sc.tex.pixf.nbytes)
        self.integrator = integrator_info(it.name)
        self.warnings = []             # what this integrator renders differently, in words
        self.light_tables = None       # light tracing's lamps (``kernels.light_tracing``)
        if self.integrator.light_tracing:
            self.light_tables, self.warnings = light_tracing.prepare(scene, self.sc, self.cfg,
                                                                     self.plan)
        self._classic_setup()
        if self._classic and ("holdout" in self.plan.lobes or any(
                info.holdout for info in scene.geometry.object_pass_info())):
            self.warnings.append(f"{self.integrator.name} does not render holdouts (Holdout "
                                 f"shaders and holdout objects): they render as ordinary "
                                 f"surfaces; Path Tracing renders them as Cycles")
        if self._classic and self.plan.traced:
            self.warnings.append(f"{self.integrator.name} does not trace Bevel and Ambient "
                                 f"Occlusion nodes: they give the shading normal and no "
                                 f"occlusion; Path Tracing traces them as Cycles")
        if self._classic and "ray portal" in self.plan.lobes:
            self.warnings.append(f"{self.integrator.name} does not follow Ray Portal BSDFs: "
                                 f"their rays end there; Path Tracing follows them as Cycles")
        if self._classic and self.plan.light_linking:
            self.warnings.append(f"{self.integrator.name} does not honour light linking: every "
                                 f"light lights every object; Path Tracing honours it as Cycles")
        guides = ((P_DENOISING_ALBEDO,) if scene.denoising.uses_albedo else ()) + \
            ((P_DENOISING_NORMAL,) if scene.denoising.uses_normal else ())
        self.pass_layout = render_passes.layout(scene.passes, guides)
        self.pd = pack_passes(scene, self.pass_layout)
        # The workers' buffers (``_Buffers``' arguments after the batch size): per-path pass
        # buffers are needed by light passes and denoising features only, a second shadow ray
        # per path by the Ambient Occlusion pass.
        self._buffers = (self._classic, bool(self.pd.cfg[PC_LIGHT] or self.pd.cfg[PC_DENOISE]),
                         bool(self.pd.cfg[P_AO] >= 0))
        x0, y0, x1, y1 = scene.film.window
        if self.light_tables is not None:
            host_bytes_per_pixel += self.threads * 3 * 8     # the workers' light-tracing films
        self._check_memory((x1 - x0) * (y1 - y0), host_bytes_per_pixel)
        self.film = Film(x1 - x0, y1 - y0, self.pass_layout.stride)
        self.adaptive = Adaptive.from_settings(it)
        self.active = np.arange(self.film.count.size, dtype=np.int32)
        self.pass_samples = 0          # samples every still-active pixel has
        t0 = time.perf_counter()
        self.accel, self.stats.extra["bvh_reused"], self.stats.time_bvh = (
            bvh.result() if bvh is not None else self._build_bvh(scene, self.sc.motion, visibility))
        self.stats.extra["bvh_wait"] = time.perf_counter() - t0
        if visibility is not None:
            self._warn_ray_visibility()
        t0 = time.perf_counter()
        self._warm_up()
        self.stats.time_kernels = time.perf_counter() - t0
        self._stop = threading.Event()
        self._workers = threading.local()
        self._all_workers = []
        self._buffer_bytes = 0
        self._lock = threading.Lock()

    @staticmethod
    def _build_bvh(scene, motion, visibility):
        """(BVH, whether it was reused, seconds) of the scene's triangles, with the moving
        ones of ``motion`` (``kernels.motion.MotionData``; None: nothing moves) and each
        triangle's ray ``visibility`` (``Geometry.triangle_visibility``)."""
        t0 = time.perf_counter()
        it = scene.integrator
        accel, reused = accel_cache.accel_for(scene.geometry.vertices, scene.geometry.triangles,
                                              motion, visibility, it.use_spatial_splits,
                                              it.use_compact_bvh)
        return accel, reused, time.perf_counter() - t0

    def _warn_ray_visibility(self) -> None:
        """Name where objects' Ray Visibility (some object's) is not honoured (every ray
        sees them there)."""
        if not self.accel.masked:
            self.warnings.append("Ray Visibility needs Embree's library, which was not found "
                                 "(embreex's own API has no ray masks): every object is seen "
                                 "by every ray")
        elif self._classic:
            self.warnings.append(f"{self.integrator.name} does not honour objects' Ray "
                                 f"Visibility: every object is seen by every ray; Path Tracing "
                                 f"honours it as Cycles")
        elif self.light_tables is not None:
            self.warnings.append("light tracing's paths see every object whatever its Ray "
                                 "Visibility (the camera paths honour it)")

    # -- public ------------------------------------------------------------------------
    @property
    def samples_done(self) -> int:
        """Samples of the pixels still being sampled (converged pixels stopped earlier)."""
        return self.pass_samples if self.pass_samples else self.film.samples_min()

    def image(self, bottom_up: bool = False) -> np.ndarray:
        """(h, w, 4) float32 linear RGBA of the film region, top row first (or last)."""
        return self.film.image(self.scene.film.exposure, bottom_up)

    def pass_names(self) -> list[str]:
        """The render passes besides Combined, in Blender's order (``RenderPasses.names``)."""
        return self.scene.passes.names()

    def pass_image(self, name: str, bottom_up: bool = False) -> np.ndarray:
        """(h, w, C) float32 image of render pass ``name`` (one of ``pass_names()``)."""
        return self.film.pass_image(name, self.pass_layout, self.scene.film.exposure, bottom_up)

    def denoised(self, bottom_up: bool = False) -> np.ndarray | None:
        """The image denoised with the scene's settings (None when denoising is off).

        Raises ``denoise.DenoiseError`` if Open Image Denoise is missing or fails.
        """
        d = self.scene.denoising
        if not d.enabled:
            return None
        albedo = self._guide("Denoising Albedo", d.uses_albedo, bottom_up)
        normal = self._guide("Denoising Normal", d.uses_normal, bottom_up)
        return denoise(self.image(bottom_up), d, albedo, normal)

    def _guide(self, name: str, used: bool, bottom_up: bool):
        if not used:
            return None
        return self.film.pass_image(name, self.pass_layout, 1.0, bottom_up)

    def variance(self) -> np.ndarray:
        """(h, w, 3) float32 variance of each pixel's mean (inf below 2 samples)."""
        return self.film.variance(self.scene.film.exposure)

    def sample_counts(self) -> np.ndarray:
        """(h, w) int: samples taken in each pixel (they differ with adaptive sampling)."""
        return self.film.count.reshape(self.film.height, self.film.width).copy()

    def run(self, on_pass=None, should_stop=None) -> "RenderSession":
        """Render the remaining samples; ``on_pass(self)`` after each pass."""
        target = self.scene.integrator.samples
        time_limit = self.scene.integrator.time_limit
        t_start = time.perf_counter()
        spp = 1
        with ThreadPoolExecutor(max_workers=self.threads, thread_name_prefix="mcengine") as pool:
            while self.pass_samples < target and self.active.size:
                if self._stopping(should_stop, t_start, time_limit):
                    break
                k = self._pass_size(spp, target)
                pixels = self.active
                futures = {pool.submit(self._trace, pixels[a:b], k)
                           for a, b in self._chunks(k, pixels.size)}
                while futures:
                    finished, futures = wait(futures, timeout=0.1, return_when=FIRST_COMPLETED)
                    for f in finished:
                        f.result()   # re-raise worker errors here
                    if futures and self._stopping(should_stop, t_start, time_limit):
                        self._stop.set()
                self._merge_splats()
                if not self._stop.is_set():
                    self.pass_samples += k
                    if self.adaptive is not None:
                        self.active = self.adaptive.unconverged(self.film, self.pass_samples)
                if self.pass_samples > 1:
                    spp *= 2
                self._update_stats(t_start)
                if on_pass is not None:
                    on_pass(self)
                if self._stop.is_set():
                    break
        self._update_stats(t_start)
        self._release_buffers()
        return self

    def _release_buffers(self):
        """Give the workers' buffers back to the pool (threads end with the run)."""
        with self._lock:
            for w in self._all_workers:
                if w.buffers is not None:
                    w.buffers.give_back()
                    w.buffers = None
        self._workers = threading.local()

    @property
    def buffer_bytes(self) -> int:
        """Memory of the wavefront buffers and the film (bounded by batch size and resolution)."""
        return sum(a.nbytes for a in self.film.arrays) + self.film.passes.nbytes + self._buffer_bytes

    # -- internals -----------------------------------------------------------------------
    @property
    def _classic(self) -> bool:
        return self.integrator.kernel_code != 0

    def _merge_splats(self):
        """Light tracing's pixels of this pass into the film (the workers are idle now)."""
        if self.light_tables is None:
            return
        with self._lock:
            workers = list(self._all_workers)
        for w in workers:
            if w.light_paths:
                self.film.add_splats(w.splat, w.light_paths)
                w.light_paths = 0

    def _classic_setup(self):
        """Chunk size of the classic integrators: their widest ray generation must fit the batch."""
        it = self.scene.integrator
        if not self._classic:
            self.roots_per_chunk = self.batch_size
            return
        self.code = self.integrator.kernel_code
        self.depth = int(it.depth) if self.integrator.uses_depth else 1
        self.branching = int(it.branching)
        # Whitted spawns a mirror and a refracted ray per smooth closure, and one through
        # a transparent closure; its tree is binary unless a material has several.
        b = self.branching if self.integrator.uses_branching else max(2, self._whitted_width())
        widest = b ** (self.depth - 1)
        if widest > self.batch_size:
            raise SceneError(
                f"{self.integrator.name}: {b}^{self.depth - 1} = {widest} rays in the last ray "
                f"level per camera sample exceed the batch of {self.batch_size}; lower the depth"
                + (" or the branching" if self.integrator.uses_branching else ""))
        self.roots_per_chunk = max(1, self.batch_size // widest)

    def _check_memory(self, pixels: int, host_bytes_per_pixel: int) -> None:
        """SceneError, with the figures, if the render cannot fit in the memory left."""
        need = memory.estimate(pixels, self.scene.geometry.num_triangles,
                               self.threads * _Buffers.bytes_for(self.batch_size, *self._buffers),
                               host_bytes_per_pixel, 8 * self.pass_layout.stride,
                               self.stats.texture_bytes)
        free = memory.available()
        if free is not None and need.total > free:
            raise SceneError(f"not enough memory: this render needs {need.describe()}, "
                             f"{free / memory.GIB:.2f} GiB are available; lower the resolution "
                             f"or render a region")

    def _whitted_width(self) -> int:
        """Most rays one Whitted hit can spawn, over the scene's materials.

        Per closure node ``WHITTED_RAYS`` (two per smooth glass, one per smooth mirror or
        transparent closure); for a material whose inputs are all constant
        (``MF_CLOSURES_ONLY``), the rays its closures spawn with those inputs
        (``_constant_closure_rays``): only smooth closures spawn rays, so a rough Principled
        BSDF spawns none. The width sets the chunk size (``_classic_setup``: the batch over
        width^(depth - 1)); counting the default Principled BSDF's six possible rays made
        Whitted's chunks of depth 5 hold 101 camera rays, and its render time grow with the
        square of the samples (12 s at 64 samples of the Cornell box at 128 x 128)."""
        ops, regs, widest = self.sc.svm_ops, self.sc.svm_regs, 1
        for m, (start, end) in enumerate(self.sc.mat_prog):
            rows = ops[start:end][ops[start:end, 0] == OP_CLOSURE]
            constant = bool(self.sc.mat_flags[m] & MF_CLOSURES_ONLY)
            widest = max(widest, sum(_constant_closure_rays(int(kind), regs, int(b)) if constant
                                     else WHITTED_RAYS.get(int(kind), 0)
                                     for kind, b in rows[:, 1:3]))
        return widest

    def _stopping(self, should_stop, t_start, time_limit) -> bool:
        if self._stop.is_set():
            return True
        if time_limit > 0 and time.perf_counter() - t_start >= time_limit:
            return True
        return bool(should_stop is not None and should_stop())

    def _pass_size(self, spp, target):
        """Samples per pixel of the next pass: 1, 1, 2, 4, ... capped at ~PASS_PATHS paths,
        or after the first pass all the rest when that is at most QUICK_FINISH_PATHS paths
        and no time limit needs the steps."""
        rest = target - self.pass_samples
        if self.pass_samples > 0 and self.scene.integrator.time_limit <= 0 \
                and rest * self.active.size <= QUICK_FINISH_PATHS:
            spp = rest
        cap = max(1, PASS_PATHS // max(self.active.size, 1))
        cap = min(cap, max(1, self.roots_per_chunk))
        if self.adaptive is not None:
            # Stop at the minimum and at every check point, so convergence is
            # tested there.
            cap = min(cap, self.adaptive.next_check(self.pass_samples) - self.pass_samples)
        return max(1, min(spp, cap, target - self.pass_samples))

    def _chunks(self, spp, npix):
        """Pixel ranges [a, b) of a pass of ``spp`` samples over ``npix`` pixels, in the order
        the workers take them: each at most a batch and at most a quarter of what is left per
        worker (at least two chunks per worker), at least MIN_CHUNK_PATHS paths but for a
        last one that a batch could not take with the one before it.  The chunks
        shrink towards the pass's end (guided scheduling), so the workers finish it together:
        a pass ends in a wait for its last chunk, and equal chunks of a batch each left one
        core idle for up to a chunk's time at every pass."""
        most = max(1, min(npix, self.roots_per_chunk // spp))
        least = max(1, min(most, MIN_CHUNK_PATHS // spp))
        a = 0
        while a < npix:
            size = min(most, max(least, -(-(npix - a) // (2 * self.threads))))
            if npix - a - size < least and npix - a <= most:
                size = npix - a          # no smaller chunk after this one, if a batch holds both
            yield a, a + size
            a += size

    def _worker(self) -> _Worker:
        w = getattr(self._workers, "w", None)
        if w is None:
            w = _Worker(_Buffers.take(self.batch_size, *self._buffers), self.accel,
                        self.sc, self._splat_pixels)
            self._workers.w = w
            scratch = sum(a.nbytes for a in w.scratch)
            if w.splat is not None:
                scratch += sum(a.nbytes for a in w.cam_scratch) + w.splat.nbytes
            self._buffer_bytes = max(self._buffer_bytes, self.threads * (w.buffers.nbytes + scratch))
            with self._lock:
                self._all_workers.append(w)
        return w

    def _trace_with(self, w, pixels, spp, film, pass_film):
        b = w.buffers
        if self.light_tables is not None:
            # Light paths first: their keys come from the samples' numbers before the
            # camera paths count them (film[2]).
            w.light_paths += light_tracing.trace_light_chunk(
                pixels, spp, film[2], w.accel, self.sc, self.cfg, b.state, b.shadow, w.scratch,
                w.cam_scratch, self.light_tables, w.splat, w.stats)
        if not self._classic:
            path.trace_chunk(pixels, spp, w.accel, self.sc, self.cfg, self.fcfg, b.state, b.shadow,
                             w.scratch, film, w.stats, self.pd, b.passes, pass_film)
        else:
            classic.trace_chunk_classic(pixels, spp, w.accel, self.sc, self.cfg, self.fcfg,
                                        (b.state, b.next_state, b.shadow, b.acc, b.root_pixel,
                                         w.scratch),
                                        film, w.stats, self.code, self.depth, self.branching)

    def _trace(self, pixels, spp):
        if self._stop.is_set():
            return
        w = self._worker()
        t0 = time.perf_counter()
        self._trace_with(w, pixels, spp, self.film.arrays, self.film.passes)
        w.busy += time.perf_counter() - t0

    def _warm_up(self):
        """Compile (or load from the cache) every kernel on a one-pixel scratch film."""
        size = max(64, self.batch_size // max(self.roots_per_chunk, 1)) if self._classic else 64
        scratch_film = Film(1, 1, self.pass_layout.stride)
        self._trace_with(_Worker(_Buffers(size, *self._buffers), self.accel, self.sc,
                                 self._splat_pixels),
                         np.zeros(1, np.int32), 1, scratch_film.arrays, scratch_film.passes)

    @property
    def _splat_pixels(self) -> int:
        """Pixels of a worker's light-tracing film (0: no light tracing)."""
        x0, y0, x1, y1 = self.scene.film.window
        return (x1 - x0) * (y1 - y0) if self.light_tables is not None else 0

    def _update_stats(self, t_start):
        s = self.stats
        s.time_render = time.perf_counter() - t_start
        totals = np.zeros(ST_SIZE, np.int64)
        with self._lock:
            workers = list(self._all_workers)
        for w in workers:
            totals += w.stats
        s.camera_rays = int(totals[ST_CAMERA_RAYS])
        s.bounce_rays = int(totals[ST_BOUNCE_RAYS])
        s.shadow_rays = int(totals[ST_SHADOW_RAYS])
        s.self_hits = int(totals[ST_SELF_HITS])
        s.nonfinite = int(totals[ST_NONFINITE])
        s.paths = s.camera_rays
        s.time_embree = sum(w.embree_clock[0] for w in workers)
        s.time_workers = sum(w.busy for w in workers)
        s.samples_done = self.samples_done
        if self.adaptive is not None:
            remaining = self.adaptive.remaining_samples(self.film, self.active,
                                                        self.scene.integrator.samples)
        else:
            remaining = (s.samples_target - s.samples_done) * self.film.count.size
        s.eta_seconds = remaining / s.paths_per_second if s.paths_per_second > 0 else float("nan")
