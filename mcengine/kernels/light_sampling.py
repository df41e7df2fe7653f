"""Next-event estimation: which light to sample, its sample, and the MIS weights of light found by rays.

Lights are lamps (``lights``) and emissive triangles.  Next-event estimation
at a shading point picks one light (path tracing) or visits every light
(classic integrators):

* ``PMF_GLOBAL``: one distribution over "all lamps, then all emissive
  triangles" in proportion to an estimate of their power;
* ``PMF_LOCAL``: in proportion to each light's estimated irradiance at the
  point (``lamp_importance``), the emissive triangles counting as one light
  (then one triangle by the light tree, ``light_tree``), times Cycles' light-tree
  facing term: lights wholly behind an opaque surface are not picked (``receiver``);
* ``PMF_EVERY``: every lamp, and the emissive triangles as one light.

Emission that a BSDF-sampled ray finds (lamps it passes through, suns, emissive
triangles) is weighted by the power heuristic against the probability that
next-event estimation from the vertex the ray left would have produced it,
with the same picking rule: the receiver the ray left (point and normal) is kept in the
path state (``mis_p``) so that both sides use the same probabilities.
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from ..jit import device
from .closures import has_transmission
from .closures.layout import CL_TYPE, LABEL_DIFFUSE, LABEL_GLOSSY, LABEL_TRANSMIT
from .intersect import prim_corners, prim_frame
from .light_tree import sphere_importance, tree_pick, tree_pmf
from .lights import (
    L_FLAGS,
    L_LIGHT_SETS,
    L_MAX_BOUNCES,
    L_PMF,
    L_SUN_OMC,
    L_TYPE,
    LF_CAST_SHADOW,
    LF_LIGHT_TRACED,
    LF_USE_MIS,
    LF_VIS_CAMERA,
    LF_VIS_DIFFUSE,
    LF_VIS_GLOSSY,
    LF_VIS_TRANSMISSION,
    LT_SUN,
    in_light_sets,
    intersect_lamp,
    lamp_importance,
    sample_lamp,
    sun_radiance,
)
from .sampling import power_heuristic, uniform_triangle
from .state import (
    FCFG_EMIT_SCALE,
    PF_CAMERA,
    PF_CAUSTIC_EYE,
    PF_DIFFUSE,
    PF_GLOSSY,
    PF_MIS_SKIP,
    PF_REFLECT,
    PF_TRANSMIT,
    VIS_DIFFUSE,
    VIS_GLOSSY,
    VIS_TRANSMISSION,
)
from .svm import OBJ_LIGHT_SETS, OBJ_RECEIVER_SET, OBJ_VISIBILITY

# How a light's selection probability is known, for MIS weights.
PMF_GLOBAL = 0            # by power, scene-wide (lamps[:, L_PMF], emit_pmf)
PMF_EVERY = 1             # every light is sampled (classic integrators)
PMF_LOCAL = 2             # by estimated irradiance at the vertex the ray left

LightSample = namedtuple("LightSample", [
    "wix", "wiy", "wiz",   # unit direction from the shading point to the light point
    "dist",                # distance to it (inf for suns)
    "lr", "lg", "lb",      # radiance / sampling pdf (pick probability included); 0: no light
    "pdf",                 # solid-angle pdf incl. the pick probability (0: delta light, no MIS)
    "use_mis",             # the light takes part in MIS
    "cast_shadow",         # a shadow ray decides visibility
    "exclude",             # BSDF lobe labels the light must not illuminate
    "lnx", "lny", "lnz",   # emitter's unit normal (zero for lamps), to offset the shadow ray's end
    "tri", "b1", "b2",     # the emissive triangle and the point's barycentrics (lamps: -1)
])


@device
def _no_light():
    return LightSample(0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, False, False, 0, 0.0, 0.0, 0.0, -1, 0.0, 0.0)


def light_distribution(lamp_power, tri_power, world_power=0.0):
    """CDF over lamps, then emissive triangles, then the world (when it is sampled: its
    power > 0); (cdf, lamp pmf, triangle pmf, world pmf)."""
    w = np.concatenate([lamp_power, tri_power, [world_power] if world_power > 0 else []])
    w = w.astype(np.float64)
    total = w.sum()
    if total <= 0.0:
        return np.zeros(len(w) + 1), np.zeros(len(lamp_power)), np.zeros(len(tri_power)), 0.0
    pmf = w / total
    cdf = np.concatenate([[0.0], np.cumsum(pmf)])
    cdf[-1] = 1.0
    n = len(lamp_power) + len(tri_power)
    return (cdf, pmf[:len(lamp_power)], pmf[len(lamp_power):n],
            float(pmf[n]) if world_power > 0 else 0.0)


@device
def pick_light(cdf, u):
    """Index i with cdf[i] <= u < cdf[i+1] (binary search), skipping zero-width bins."""
    lo, hi = 0, cdf.shape[0] - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if cdf[mid] <= u:
            lo = mid
        else:
            hi = mid
    return lo


@device
def receiver(hx, hy, hz, nx, ny, nz, cl, ncl):
    """Where next-event estimation picks a light, for the importances' facing term: the point
    and its shading normal (facing the viewer; the shader's, where a displacement bump moved
    it: Cycles' sd->N), or no normal (0, 0, 0) where a closure transmits (Cycles'
    SD_BSDF_HAS_TRANSMISSION: light from behind counts there too)."""
    for k in range(ncl):
        if has_transmission(int(cl[k, CL_TYPE])):
            return hx, hy, hz, 0.0, 0.0, 0.0
    return hx, hy, hz, nx, ny, nz


@device
def sample_triangle_point(sc, tri, u1, u2, time):
    """Uniform point on triangle ``tri`` as it is at ``time``: (x, y, z, b1, b2)."""
    b1, b2 = uniform_triangle(u1, u2)
    b0 = 1.0 - b1 - b2
    ax, ay, az, bx, by, bz, cx, cy, cz = prim_corners(sc, tri, time)
    return (b0 * ax + b1 * bx + b2 * cx,
            b0 * ay + b1 * by + b2 * cy,
            b0 * az + b1 * bz + b2 * cz, b1, b2)


@device
def lamp_visible_to_ray(flags, lamp_flags):
    """Cycles' is_light_shader_visible_to_path for a ray of the given path flags; and not
    to a singular bounce's ray on a path whose caustics light tracing renders."""
    if (flags & PF_CAUSTIC_EYE) and (flags & PF_MIS_SKIP) and (lamp_flags & LF_LIGHT_TRACED):
        return False
    if flags & PF_CAMERA:
        return (lamp_flags & LF_VIS_CAMERA) != 0
    if (lamp_flags & LF_USE_MIS) == 0:
        return False
    if (flags & PF_DIFFUSE) and not (lamp_flags & LF_VIS_DIFFUSE):
        return False
    if (flags & PF_GLOSSY) and (flags & PF_REFLECT) and not (lamp_flags & LF_VIS_GLOSSY):
        return False
    if (flags & PF_TRANSMIT) and not (lamp_flags & LF_VIS_TRANSMISSION):
        return False
    return True


@device
def hidden_lobes(diffuse, glossy, transmission):
    """BSDF lobes a light must not illuminate: those whose rays do not see it (``diffuse``,
    ``glossy``, ``transmission``: whether rays of that kind do; Cycles' SHADER_EXCLUDE_*)."""
    ex = 0
    if not diffuse:
        ex |= LABEL_DIFFUSE
    if not glossy:
        ex |= LABEL_GLOSSY
    if not transmission:
        ex |= LABEL_TRANSMIT
    return ex


@device
def nee_exclude(lamp_flags):
    """BSDF lobes a lamp (or the world) must not illuminate (its ray-visibility switches)."""
    return hidden_lobes(lamp_flags & LF_VIS_DIFFUSE, lamp_flags & LF_VIS_GLOSSY,
                        lamp_flags & LF_VIS_TRANSMISSION)


@device
def emitter_exclude(sc, tri):
    """BSDF lobes emissive triangle ``tri`` must not illuminate: those whose rays do not see
    its object (Cycles gives a mesh light the SHADER_EXCLUDE_* flags of its object's ray
    visibility)."""
    vis = int(sc.tex.objects[sc.tex.tri_object[tri], OBJ_VISIBILITY])
    return hidden_lobes(vis & VIS_DIFFUSE, vis & VIS_GLOSSY, vis & VIS_TRANSMISSION)


@device
def receiver_set(sc, tri):
    """The light set the object of triangle ``tri`` receives (light linking)."""
    return int(sc.tex.objects[sc.tex.tri_object[tri], OBJ_RECEIVER_SET])


@device
def lamp_lights(lamps, li, light_set):
    """Whether lamp ``li`` lights receivers of ``light_set`` (-1: any, no light linking)."""
    return light_set < 0 or in_light_sets(lamps, li, L_LIGHT_SETS, light_set)


@device
def emitter_lights(sc, tri, light_set):
    """Whether emissive triangle ``tri`` lights receivers of ``light_set`` (-1: any, no
    light linking); Cycles' light_link_object_match."""
    return light_set < 0 or in_light_sets(sc.tex.objects, sc.tex.tri_object[tri], OBJ_LIGHT_SETS,
                                          light_set)


@device
def light_links(sc, idx, light_set):
    """Whether next-event estimation's light ``idx`` (a lamp, NL + j for emissive triangle j,
    or the world after them, which no link restricts) lights receivers of ``light_set``."""
    n_lamps = sc.lamps.shape[0]
    if idx < n_lamps:
        return lamp_lights(sc.lamps, idx, light_set)
    if idx < n_lamps + sc.emit_tri.shape[0]:
        return emitter_lights(sc, sc.emit_tri[idx - n_lamps], light_set)
    return True


@device
def local_light_total(lamps, group, has_group, world, recv, importance):
    """Sum of every light's importance at the receiver (lamps, the emissive triangles as
    one, and the world's constant importance ``world``, 0 when it is not sampled); each
    lamp's is left in ``importance`` (NL,) for :func:`pick_light_local`."""
    total = world
    for li in range(lamps.shape[0]):
        w = lamp_importance(lamps, li, recv)
        importance[li] = w
        total += w
    if has_group:
        total += sphere_importance(group, 0, recv)
    return total


@device
def lamp_pick_pmf(lamps, li, pmf_mode, recv, total):
    """Probability that next-event estimation at the receiver picks lamp li."""
    if pmf_mode == PMF_EVERY:
        return 1.0
    if pmf_mode == PMF_LOCAL:
        return lamp_importance(lamps, li, recv) / total if total > 0.0 else 0.0
    return lamps[li, L_PMF]


@device
def pick_light_local(n_lamps, group, has_group, world, recv, total, importance, u):
    """Pick a light at the receiver (point, normal) in proportion to its importance there,
    given what :func:`local_light_total` found there (``total``, ``importance``).

    Returns ``(choice, pmf)``: a lamp index, ``n_lamps`` for the emissive
    triangles as a group, or ``n_lamps + 1`` for the world (of importance
    ``world``); ``pmf`` 0 if nothing can light p.
    """
    if total <= 0.0:
        return 0, 0.0
    target = u * total
    if target < world:
        return n_lamps + 1, world / total
    acc = world
    last = -1
    last_w = 0.0
    for li in range(n_lamps):
        w = importance[li]
        if w > 0.0:
            acc += w
            last, last_w = li, w
            if target < acc:
                return li, w / total
    if has_group:
        return n_lamps, sphere_importance(group, 0, recv) / total
    if last < 0:
        return n_lamps + 1, world / total
    return last, last_w / total      # rounding at the end of the scan


@device
def lamps_on_segment(lamps, ies, ox, oy, oz, dx, dy, dz, t_hit, flags, mis_pdf, pmf_mode,
                     mp, mis_total, transparent_left, light_set):
    """Light from lamps the ray passes through before t_hit (lamps do not block rays), of
    those that light ``light_set`` (the receiver the ray left; -1: every lamp).

    Lamps are visited nearest first; each one counts as a transparent bounce
    (Cycles), at most ``transparent_left`` of them.  MIS weights use the NEE
    pdf of the lamp: its selection probability (see :func:`lamp_pick_pmf`)
    times the solid-angle pdf.
    Returns ``(r, g, b, lamps_passed)``, unweighted by the path throughput.
    """
    lr_sum = lg_sum = lb_sum = 0.0
    passed = 0
    last_t = 0.0
    n_lamps = lamps.shape[0]
    more = True
    while more and passed < transparent_left:
        best_t = t_hit
        best = -1
        n_hits = 0
        br = bg = bb = bpdf = 0.0
        for li in range(n_lamps):
            if not lamp_visible_to_ray(flags, int(lamps[li, L_FLAGS])):
                continue
            if not lamp_lights(lamps, li, light_set):
                continue
            tl, lr, lg, lb, lpdf = intersect_lamp(lamps, ies, li, ox, oy, oz, dx, dy, dz, t_hit,
                                                  mp[0], mp[1], mp[2])
            if tl > last_t and tl < t_hit:
                n_hits += 1
                if tl < best_t:
                    best_t, best = tl, li
                    br, bg, bb, bpdf = lr, lg, lb, lpdf
        if best < 0:
            break
        w = 1.0
        if not (flags & PF_MIS_SKIP):
            pmf = lamp_pick_pmf(lamps, best, pmf_mode, mp, mis_total)
            w = power_heuristic(mis_pdf, pmf * bpdf)
        lr_sum += br * w
        lg_sum += bg * w
        lb_sum += bb * w
        passed += 1
        last_t = best_t
        more = n_hits > 1
    return lr_sum, lg_sum, lb_sum, passed


@device
def sun_light(lamps, ies, dx, dy, dz, flags, mis_pdf, pmf_mode, mp, mis_total, light_set):
    """Light from suns with an angle, seen along an escaped ray (MIS-weighted), of those that
    light ``light_set`` (-1: every sun)."""
    r = g = b = 0.0
    for li in range(lamps.shape[0]):
        if int(lamps[li, L_TYPE]) != LT_SUN or lamps[li, L_SUN_OMC] <= 0.0:
            continue
        lflags = int(lamps[li, L_FLAGS])
        if not (lflags & LF_USE_MIS) or not lamp_visible_to_ray(flags, lflags):
            continue
        if not lamp_lights(lamps, li, light_set):
            continue
        lr, lg, lb, lpdf = sun_radiance(lamps, ies, li, dx, dy, dz)
        if lpdf > 0.0:
            w = 1.0
            if not (flags & PF_MIS_SKIP):
                pmf = lamp_pick_pmf(lamps, li, pmf_mode, mp, mis_total)
                w = power_heuristic(mis_pdf, pmf * lpdf)
            r += lr * w
            g += lg * w
            b += lb * w
    return r, g, b


@device
def pick_emitter(sc, fcfg, recv, u):
    """Pick one of the emissive triangles, once next-event estimation at the receiver chose
    them as a group: ``(j, pmf)`` (j indexes ``emit_tri``; -1 when none can light it), by
    the light tree where the scene has one, else by power."""
    if sc.emit_tree.nodes.shape[0] > 0:
        return tree_pick(sc.emit_tree, recv, u)
    j = pick_light(sc.emit_cdf, u)
    return j, sc.emit_pmf[j] * fcfg[FCFG_EMIT_SCALE]


@device
def emitter_pick_pmf(sc, fcfg, pmf_mode, mp, mis_total, j):
    """The probability that next-event estimation at the receiver ``mp`` picked emissive
    triangle j (``mis_total``: the lights' summed importance there, for ``PMF_LOCAL``)."""
    if pmf_mode == PMF_EVERY:
        return sc.emit_pmf[j] * fcfg[FCFG_EMIT_SCALE]
    if pmf_mode == PMF_LOCAL:
        if not mis_total > 0.0:
            return 0.0
        group = sphere_importance(sc.emit_group, 0, mp) / mis_total
        if sc.emit_tree.nodes.shape[0] > 0:
            return group * tree_pmf(sc.emit_tree, j, mp)
        return group * sc.emit_pmf[j] * fcfg[FCFG_EMIT_SCALE]
    return sc.emit_pmf[j]


@device
def emission_weight(sc, fcfg, p, area, t_hit, cos_o_geo, flags, mis_pdf, pmf_mode, mp,
                    mis_total):
    """MIS weight of emission found by a BSDF ray on emissive triangle p (of that ``area``)."""
    if flags & PF_MIS_SKIP or sc.tri_light.shape[0] == 0:
        return 1.0
    j = sc.tri_light[p]
    if j < 0:
        return 1.0
    light_pdf = (emitter_pick_pmf(sc, fcfg, pmf_mode, mp, mis_total, j)
                 * t_hit * t_hit / (area * cos_o_geo))
    return power_heuristic(mis_pdf, light_pdf)


@device
def sample_light(sc, idx, pmf, hx, hy, hz, bounce, u1, u2, time):
    """Sample light ``idx`` (a lamp, or NL + j for emissive triangle j) from point h,
    emissive triangles as they are at ``time``.

    ``pmf`` is the probability with which the caller chose this light.
    Returns the direction and distance to the light point,
    the radiance divided by the sampling pdf (pmf included), the solid-angle
    pdf (0 for delta lights, which get no MIS), the light's flags, and the
    emitter's unit normal (zero for lamps) for offsetting the shadow ray's end,
    as a :class:`LightSample`.  All-zero radiance means no contribution.
    """
    lamps = sc.lamps
    n_lamps = lamps.shape[0]
    if idx < n_lamps:
        lflags = int(lamps[idx, L_FLAGS])
        if bounce > lamps[idx, L_MAX_BOUNCES]:
            return _no_light()
        wix, wiy, wiz, dist, lr, lg, lb, pdf = sample_lamp(lamps, sc.ies, idx, hx, hy, hz, u1, u2)
        use_mis = (lflags & LF_USE_MIS) != 0
        if pdf > 0.0:
            pdf_l = pmf * pdf
            lr, lg, lb = lr / pdf_l, lg / pdf_l, lb / pdf_l
        else:   # delta light: L is already the L/pdf term
            pdf_l = 0.0
            use_mis = False
            lr, lg, lb = lr / pmf, lg / pmf, lb / pmf
        return LightSample(wix, wiy, wiz, dist, lr, lg, lb, pdf_l, use_mis,
                           (lflags & LF_CAST_SHADOW) != 0, nee_exclude(lflags), 0.0, 0.0, 0.0,
                           -1, 0.0, 0.0)
    tri = np.int64(sc.emit_tri[idx - n_lamps])
    qx, qy, qz, b1, b2 = sample_triangle_point(sc, tri, u1, u2, time)
    lx, ly, lz = qx - hx, qy - hy, qz - hz
    d2 = lx * lx + ly * ly + lz * lz
    dist = math.sqrt(d2)
    if dist <= 0.0:
        return _no_light()
    wix, wiy, wiz = lx / dist, ly / dist, lz / dist
    lnx, lny, lnz, area = prim_frame(sc, tri, time)
    cos_l = abs(lnx * wix + lny * wiy + lnz * wiz)
    if cos_l <= 0.0:
        return _no_light()
    pdf_l = pmf * d2 / (area * cos_l)
    em = sc.mat_index[tri]
    emission = sc.mat_emission
    return LightSample(wix, wiy, wiz, dist, emission[em, 0] / pdf_l,
                       emission[em, 1] / pdf_l, emission[em, 2] / pdf_l,
                       pdf_l, True, True, emitter_exclude(sc, tri), lnx, lny, lnz, tri, b1, b2)
