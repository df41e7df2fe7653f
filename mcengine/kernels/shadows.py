"""Shadow rays: is the light point visible, and how much light passes?

Without transparent materials a shadow ray is one Embree occlusion query; shadow rays
pass through the objects whose Shadow ray visibility is off (``VIS_SHADOW``).
When some material lets shadow rays through (a Transparent BSDF, Principled
Alpha, with the material's Transparent Shadows on), the queue is traced hit by
hit instead: a hit on such a material multiplies the ray's light by the
shader's transparency there (Cycles' shade_shadow) and the ray goes on from
just past it, at most as many times as the path may still make transparent
bounces; any other hit blocks it.
"""
from __future__ import annotations

import math

import numpy as np

from ..jit import by_ref, kernel
from .intersect import SHADOW_SHORTEN, intersect_triangle, offset_scale, prim_corners
from .shading import shade_point
from .state import (
    CFG_MAX_TRANSPARENT,
    CFG_TRANSPARENT_SHADOWS,
    MF_TRANSPARENT,
    PF_SHADOW,
    ST_SHADOW_RAYS,
    VIS_SHADOW,
)
from .surface import surface_point
from .svm import shader_scene

# sq.alive values while tracing transparent shadows.
SHADOW_BLOCKED = 0
SHADOW_TRACING = 1
SHADOW_ARRIVED = 2


def trace_shadows(n_shadow, accel, sq, sc, cfg, scratch, stats):
    """Occlusion of the n_shadow queued shadow rays (True: no light arrives).

    Without transparent shadows, one Embree occlusion query; with them, closest
    hits repeated while some ray passes a transparent surface.
    """
    if n_shadow == 0:
        return np.zeros(0, np.bool_)
    stats[ST_SHADOW_RAYS] += n_shadow
    if not cfg[CFG_TRANSPARENT_SHADOWS]:
        return accel.occluded(sq.o32[:n_shadow], sq.d32[:n_shadow], sq.t32[:n_shadow],
                              sq.time[:n_shadow], VIS_SHADOW)
    for _ in range(int(cfg[CFG_MAX_TRANSPARENT]) + 2):
        prim = accel.closest(sq.o32[:n_shadow], sq.d32[:n_shadow], sq.t32[:n_shadow],
                             sq.time[:n_shadow], VIS_SHADOW)
        if advance_shadows(n_shadow, prim, sq, sc, cfg, scratch) == 0:
            break
    return sq.alive[:n_shadow] != SHADOW_ARRIVED


@kernel
def advance_shadows(n_shadow, prim, sq, sc, cfg, scratch):
    """Continue the shadow rays that hit a transparent surface; returns how many go on.

    With transparent shadows a shadow ray is traced hit by hit: a hit on a
    material whose shader lets light through multiplies the ray's light by the
    transparency there (Cycles' shade_shadow) and the ray goes on from just
    past it, at most as many times as the path may still make transparent
    bounces; any other hit blocks it.
    """
    going = 0
    scene_ref = by_ref(shader_scene(sc))
    for s in range(n_shadow):
        if sq.alive[s] != SHADOW_TRACING:
            continue
        p = prim[s]
        if p < 0:
            sq.alive[s] = SHADOW_ARRIVED
            continue
        m = sc.mat_index[p]
        if not (sc.mat_flags[m] & MF_TRANSPARENT) or sq.transparent[s] <= 0:
            sq.alive[s] = SHADOW_BLOCKED
            continue
        # In float64 from here (numba's float() would keep float32): the shader evaluator
        # and the functions below are then the ones the integrators compiled (a float32 d
        # compiled another copy of each, about 2 minutes).
        f64 = np.float64
        ox, oy, oz = f64(sq.o32[s, 0]), f64(sq.o32[s, 1]), f64(sq.o32[s, 2])
        dx, dy, dz = f64(sq.d32[s, 0]), f64(sq.d32[s, 1]), f64(sq.d32[s, 2])
        ax, ay, az, bx, by, bz, cx, cy, cz = prim_corners(sc, p, sq.time[s])
        t, b1, b2 = intersect_triangle(ox, oy, oz, dx, dy, dz, ax, ay, az, bx, by, bz, cx, cy, cz)
        if not math.isfinite(t):
            t = 0.0
        sp = surface_point(sc, p, b1, b2, dx, dy, dz, sq.time[s])
        # Light Path sees a shadow ray from the shading point, with the path's bounces and
        # the transparent surfaces passed so far (Cycles' shadow path state).
        dep = sq.depths[s]
        res = shade_point(sc, scene_ref, cfg, scratch, sp, m, p, b1, b2, dx, dy, dz,
                          sq.travelled[s] + t, PF_SHADOW, False,
                          (dep[0], dep[1], dep[2], dep[3], dep[4]), 0.0)
        dep[4] += 1
        sq.contrib[s, 0] *= res.tr
        sq.contrib[s, 1] *= res.tg
        sq.contrib[s, 2] *= res.tb
        if sq.contrib[s, 0] == 0.0 and sq.contrib[s, 1] == 0.0 and sq.contrib[s, 2] == 0.0:
            sq.alive[s] = SHADOW_BLOCKED
            continue
        sq.transparent[s] -= 1
        # On from just past the surface, towards the same end point.
        k = t + offset_scale(sp.hx, sp.hy, sp.hz) * 4.0
        sq.travelled[s] += k
        nox, noy, noz = ox + k * dx, oy + k * dy, oz + k * dz
        sq.o32[s, 0], sq.o32[s, 1], sq.o32[s, 2] = nox, noy, noz
        if math.isfinite(sq.target[s, 0]):
            ex, ey, ez = sq.target[s, 0] - nox, sq.target[s, 1] - noy, sq.target[s, 2] - noz
            length = math.sqrt(ex * ex + ey * ey + ez * ez)
            sq.t32[s] = length * (1.0 - SHADOW_SHORTEN) if (ex * dx + ey * dy + ez * dz) > 0.0 else 0.0
        going += 1
    return going
