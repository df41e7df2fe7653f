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
"""
from __future__ import annotations

import math
import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .kernels.background import bake_background
from .kernels.state import alloc_scratch

DEFAULT_MAP = (1024, 512)     # Automatic, without an Environment Texture


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


def bake_world(sc, cfg, out) -> None:
    """Bake the world's radiance into ``out`` (H, W, 3) for its importance map, in bands of
    rows on as many threads as there are cores (the kernel releases the GIL; each band has
    its own shader registers): world_hdri_sun's map took 86 ms on one thread, 46 ms on two."""
    h = out.shape[0]
    bands = max(1, min(os.cpu_count() or 1, h))
    edges = [h * k // bands for k in range(bands + 1)]
    if bands == 1:
        bake_background(sc, cfg, alloc_scratch(sc), out, 0, h)
        return
    with ThreadPoolExecutor(max_workers=bands, thread_name_prefix="mcengine-bake") as pool:
        for done in [pool.submit(bake_background, sc, cfg, alloc_scratch(sc), out, edges[k],
                                 edges[k + 1]) for k in range(bands)]:
            done.result()


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
