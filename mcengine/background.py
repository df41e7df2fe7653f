"""The world's importance map: which directions next-event estimation samples the world in.

As Cycles builds its background light (scene/light.cpp): the world's shader is
baked into an equirectangular map (``kernels.background.bake_background``) whose
size follows the world's Sampling Method: Manual uses Map Resolution R as
R x R/2; Automatic the largest Environment Texture image of the world's graph
(1024 x 512 without one); None does not sample the world.  Each texel weighs the
mean of |R|, |G|, |B| times the sine of its row's polar angle; rows become CDFs
over their columns and the rows one CDF (a row of zero weight is sampled
uniformly).  MC Engine samples the world this way only when its radiance varies
over directions (a constant world is found by BSDF rays alone, as before).

The last map is kept for the next render whose world bakes from the same inputs
(``world_map``): re-renders, animation frames and the viewport's restarts
after a camera or material edit skip the bake, as they skip the BVH build
(``accel_cache``).  The inputs are recognised by a hash (``digest``: SHA-256 on a
thread pool, 47 ms for a 4096 x 2048 float image) of the world's program, its
registers, the images its nodes read and the map's size (the camera and the objects
only when one of the world's nodes can see them).
A map kept by mistake could only change the noise, never the mean: the
renderer samples the world from the map it holds and weighs by that map's pdf.
"""
from __future__ import annotations

import math
import os
import threading

import numpy as np

from .digest import digest
from .kernels.background import bake_background
from .kernels.state import CFG_SIZE, CFG_WORLD_SHADER, alloc_scratch
from .kernels.svm.data import IMG_CHANNELS, IMG_FLOAT, IMG_HEIGHT, IMG_OFFSET, IMG_WIDTH
from .parallel import map_threads
from .sky import node_image

DEFAULT_MAP = (1024, 512)     # Automatic, without an Environment Texture

_lock = threading.Lock()
_last: tuple[bytes, tuple] | None = None    # (hash of the bake's inputs, importance_map's result)
# World nodes whose outputs can depend on the camera or on objects (Texture Coordinate's
# Camera, Window and Object, Camera Data, Vector Transform): with one of them the camera
# and the objects are inputs of the bake.
_VIEW_NODES = frozenset({"TexCoord", "CameraData", "VectorTransform"})


def map_size(world, images: dict) -> tuple[int, int] | None:
    """(width, height) of the importance map of ``world``; None when it is not sampled."""
    if world.sampling == "NONE":
        return None
    if world.sampling == "MANUAL":
        r = max(int(world.map_resolution), 4)
        return r, max(r // 2, 2)
    sizes = [images[str(n.props.get("image", ""))].pixels.shape[:2] for n in world.nodes
             if n.type == "TexEnvironment" and str(n.props.get("image", "")) in images]
    if not sizes:
        return DEFAULT_MAP
    h, w = max(sizes, key=lambda s: s[0] * s[1])
    return int(w), int(h)


def world_map(sc, world, slots: dict, registers, size) -> tuple[np.ndarray, np.ndarray, float]:
    """The importance map (``importance_map``) of the world ``world`` (the scene
    description's) at ``size`` (W, H): baked from the packed scene ``sc``, whose world
    program's registers are [registers[0], registers[1]) of ``sc.svm_regs`` and whose
    images sit in ``slots`` (``images.ImageTable.slots``); or the last render's map when
    the bake's inputs are the same."""
    global _last
    key = _digest(sc, world, slots, registers, size)
    with _lock:
        if _last is not None and _last[0] == key:
            return _last[1]
        _last = None               # free the old map before baking the new one
    cfg = np.zeros(CFG_SIZE, np.int64)
    cfg[CFG_WORLD_SHADER] = 1
    baked = np.zeros((size[1], size[0], 3))
    bake_world(sc, cfg, baked)
    result = importance_map(baked)
    with _lock:
        _last = (key, result)
    return result


def clear() -> None:
    """Forget the kept importance map."""
    global _last
    with _lock:
        _last = None


def _digest(sc, world, slots, registers, size) -> bytes:
    """A hash of what the bake reads: the world's program and registers, the texels of the
    images its nodes name, the camera and the objects if a node can see them, the size."""
    w = sc.mat_prog.shape[0] - 1              # the world's program is the last
    parts = [np.asarray(size, np.int64), sc.svm_ops[sc.mat_prog[w, 0]:sc.mat_prog[w, 1]],
             sc.svm_regs[int(registers[0]):int(registers[1])], sc.world]
    if any(n.type in _VIEW_NODES for n in world.nodes):
        parts += [sc.camera, sc.tex.objects]
    for name in sorted({node_image(n) for n in world.nodes} & set(slots)):
        row = sc.tex.images[slots[name]]
        pool = sc.tex.pixf if row[IMG_FLOAT] else sc.tex.pix8
        count = int(row[IMG_WIDTH] * row[IMG_HEIGHT] * row[IMG_CHANNELS])
        parts += [row, pool[row[IMG_OFFSET]:row[IMG_OFFSET] + count]]
    return digest(parts)


def bake_world(sc, cfg, out) -> None:
    """Bake the world's radiance into ``out`` (H, W, 3) for its importance map, in bands of
    rows on as many threads as there are cores (the kernel releases the GIL; each band has
    its own shader registers): world_hdri_sun's map took 86 ms on one thread, 46 ms on two."""
    h = out.shape[0]
    bands = max(1, min(os.cpu_count() or 1, h))
    edges = [h * k // bands for k in range(bands + 1)]
    map_threads(lambda k: bake_background(sc, cfg, alloc_scratch(sc), out, edges[k],
                                          edges[k + 1]), range(bands))


def importance_map(radiance: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """(marginal CDF (H + 1,), conditional CDFs (H, W + 1), mean radiance over the sphere)
    of a baked (H, W, 3) map."""
    h, w = radiance.shape[:2]
    sin_theta = np.sin(np.pi * (np.arange(h) + 0.5) / h)
    weight = np.abs(radiance).mean(axis=2) * sin_theta[:, None]
    weight = np.where(np.isfinite(weight), weight, 0.0)
    conditional = np.zeros((h, w + 1))
    conditional[:, 1:] = np.cumsum(weight, axis=1) / w
    rows = conditional[:, -1].copy()
    empty = rows <= 0.0
    conditional[~empty] /= rows[~empty, None]
    conditional[empty] = np.arange(w + 1) / w
    conditional[:, -1] = 1.0
    marginal = np.zeros(h + 1)
    marginal[1:] = np.cumsum(rows) / h
    total = marginal[-1]
    if total > 0.0:
        marginal /= total
        marginal[-1] = 1.0
    # Mean radiance over the sphere: sum of weight x (2 pi / W)(pi / H), over 4 pi.
    mean = float(weight.sum() * (2.0 * math.pi / w) * (math.pi / h) / (4.0 * math.pi))
    return marginal, conditional, mean
