"""Shading steps shared by every integrator.

The path tracer (``path``) and the classic integrators (``classic``) do the
same things at a surface hit and differ only in how many rays they spawn and
where the light goes; these device functions are those shared steps, in the
order a hit is shaded:

1. ``light_from_lamps``       lamps the ray passed through (they do not block rays);
2. ``light_from_background``  an escaped ray: the world and suns with an angle;
3. ``shade_point``            the material's shader at the hit: its closures,
                              emission, transparency and holdout (``kernels.svm``);
4. ``light_from_emitter``     the emission of the surface hit (two-sided);
5. ``direct_light``           next-event estimation for one chosen light: a light
                              sample, the closures, MIS, clamping, a queued shadow ray;
6. ``sample_direction``       the closures pick the next direction, checked against
                              the geometric side it must leave to.

Light is added with ``add_light`` to row ``row`` of an (N, >=3) array ``out``
(the path's radiance, or a classic integrator's per-camera-sample sums),
weighted by the throughput ``beta[i]``.  ``direct`` selects Cycles' direct
or indirect clamp.  ``pmf_mode`` says how next-event estimation picks lights
(see ``light_sampling``), which the MIS weights of emission found by rays
must follow; ``mp`` is the receiver the ray left (the vertex and its normal for the
importances' facing term, ``light_sampling.receiver``) and ``mis_total`` the sum of light
importances there (``PMF_LOCAL`` only).

Every step is inlined into its kernel (``jit.device``), so sharing costs
nothing at run time.
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from ..jit import by_ref, device, kernel
from .background import sample_world, world_pdf, world_radiance
from .closures import (
    LABEL_DIFFUSE,
    LABEL_GLOSSY,
    LABEL_REFLECT,
    LABEL_TRANSMIT,
    bsdf_eval,
    bsdf_sample_closure,
    free_side,
)
from .closures.layout import CL_SW, CL_TERMINATOR, CL_TYPE, CL_W, CT_BSSRDF, CT_DIFFUSE
from .intersect import SHADOW_SHORTEN, T_INFINITE, offset_origin, triangle_frame
from .light_sampling import (
    PMF_GLOBAL,
    PMF_LOCAL,
    LightSample,
    emission_weight,
    lamp_visible_to_ray,
    lamps_on_segment,
    nee_exclude,
    sample_light,
    sun_light,
)
from .lights import LF_USE_MIS
from .sampling import power_heuristic
from .state import (
    CFG_CAUSTICS_REFLECTIVE,
    CFG_CAUSTICS_REFRACTIVE,
    CFG_FILM_TRANSPARENT,
    CFG_LAMPS_HIT,
    CFG_MAX_TRANSPARENT,
    CFG_WORLD,
    CFG_WORLD_VISIBILITY,
    FCFG_CLAMP_DIRECT,
    FCFG_CLAMP_INDIRECT,
    FCFG_WORLD_IMPORTANCE,
    FCFG_WORLD_PMF,
    MF_BUMP_CORRECTION,
    MF_CLOSURES_ONLY,
    MF_EMISSION_VARIES,
    PF_CAMERA,
    PF_DIFFUSE,
    PF_DIFFUSE_ANCESTOR,
    PF_EMISSION,
    PF_GLOSSY,
    PF_MIS_SKIP,
    PF_REFLECT,
    PF_SINGULAR,
    PF_TERMINATE,
    PF_TRANSMIT,
    PF_TRANSPARENT,
    PF_TRANSPARENT_BG,
    SK_NONE,
    ST_NONFINITE,
)
from .surface import smooth_surface_offset, surface_point
from .svm import (
    BUMP_SET_NORMAL,
    OBJ_TERMINATOR_GEOMETRY,
    OBJ_TERMINATOR_SHADING,
    OP_BUMP,
    ShadingData,
    eval_closure_rows,
    eval_shader,
    shader_scene,
)

DirectionSample = namedtuple("DirectionSample", [
    "ok",                    # False: no direction (absorbed, or through the wrong side)
    "wix", "wiy", "wiz",     # the new direction, world space
    "wr", "wg", "wb",        # weight f * |cos| / pdf
    "pdf",                   # solid-angle pdf (0 for a singular lobe)
    "label",                 # LABEL_* of the lobe sampled
    "pick",                  # the closure sampled (its row in the closure list; -1: none)
])


# -- adding light -----------------------------------------------------------------------------
@device
def clamp_light(r, g, b, limit, stats):
    """Cycles' film_clamp_light: drop non-finite values, cap |r|+|g|+|b| at limit."""
    if not (math.isfinite(r) and math.isfinite(g) and math.isfinite(b)):
        stats[ST_NONFINITE] += 1
        return 0.0, 0.0, 0.0
    s = abs(r) + abs(g) + abs(b)
    if s > limit:
        k = limit / s
        return r * k, g * k, b * k
    return r, g, b


@device
def add_light(out, row, r, g, b, direct, fcfg, stats):
    """Add a clamped contribution to row ``row`` of ``out`` (direct or indirect limit)."""
    limit = fcfg[FCFG_CLAMP_DIRECT] if direct else fcfg[FCFG_CLAMP_INDIRECT]
    r, g, b = clamp_light(r, g, b, limit, stats)
    out[row, 0] += r
    out[row, 1] += g
    out[row, 2] += b


# -- rays -----------------------------------------------------------------------------------------
@device
def set_ray(ray_o, ray_d, ray_tmax, o32, d32, t32, i, ox, oy, oz, dx, dy, dz, tmax):
    """Write ray i (float64 and Embree's float32 copies)."""
    ray_o[i, 0], ray_o[i, 1], ray_o[i, 2] = ox, oy, oz
    ray_d[i, 0], ray_d[i, 1], ray_d[i, 2] = dx, dy, dz
    ray_tmax[i] = tmax
    o32[i, 0], o32[i, 1], o32[i, 2] = ox, oy, oz
    d32[i, 0], d32[i, 1], d32[i, 2] = dx, dy, dz
    t32[i] = min(tmax, T_INFINITE)


@device
def shader_normal(sc, regs, sp):
    """Cycles' sd->N at ``sp`` once its material's shader has run there: the normal a
    displacement bump set (``BUMP_SET_NORMAL``, still in that material's registers), else
    the interpolated shading normal.  A BSDF's own Normal input (a normal map) does not
    change it."""
    m = sc.mat_index[sp.prim]
    start = sc.mat_prog[m, 0]
    if start < sc.mat_prog[m, 1] and sc.svm_ops[start, 0] == OP_BUMP \
            and sc.svm_ops[start, 1] == BUMP_SET_NORMAL:
        b = sc.svm_ops[start, 2]
        return regs[b], regs[b + 1], regs[b + 2]
    return sp.nsx, sp.nsy, sp.nsz


@device
def terminator_origin(sc, sp, nx, ny, nz, wix, wiy, wiz):
    """Where a shadow ray towards wi starts on a smooth-shaded triangle: Cycles'
    shadow_ray_offset with the object's Shadow Terminator Geometry Offset (0.1 by default;
    0: never).  Where the light is at most that cosine above the flat triangle (or above
    the shader's normal n), the ray starts from the curved surface the corner normals
    describe (``surface.smooth_surface_offset``) rather than from the facet, in full once
    the light is below the facet; so a lit smooth (or bumped) surface is not shadowed by
    its own facets near the terminator."""
    nl = nx * wix + ny * wiy + nz * wiz
    ngx, ngy, ngz = sp.ngx, sp.ngy, sp.ngz
    if nl < 0.0:
        nl = -nl
        ngx, ngy, ngz = -ngx, -ngy, -ngz
    ngl = ngx * wix + ngy * wiy + ngz * wiz
    cutoff = sc.tex.objects[sc.tex.tri_object[sp.prim], OBJ_TERMINATOR_GEOMETRY]
    if not cutoff > 0.0:
        return sp.hx, sp.hy, sp.hz
    amount = 2.0 - (ngl + nl) / cutoff if nl < cutoff else 1.0 - ngl / cutoff
    amount = min(max(amount, 0.0), 1.0)
    if amount <= 0.0:
        return sp.hx, sp.hy, sp.hz
    tx, ty, tz = smooth_surface_offset(sc, sp, ngx, ngy, ngz)
    return sp.hx + amount * tx, sp.hy + amount * ty, sp.hz + amount * tz


@device
def push_shadow(sq, sc, n_shadow, owner, sp, nx, ny, nz, wix, wiy, wiz, dist, lnx, lny, lnz, cr, cg, cb,
                transparent_left, depths):
    """Queue a shadow ray from the shading point ``sp`` towards the light point.

    Returns the new queue length.  Both ends leave their surfaces (pbrt's
    SpawnRayTo): the direction is re-aimed from the offset origin at the offset
    target, else at grazing angles the shifted ray meets the emitter's plane
    before its end.  ``owner`` is the row the light goes to if unoccluded;
    ``transparent_left`` is how many transparent surfaces the ray may pass;
    ``depths`` the path's bounce counts (what a Light Path node on the way sees); n is the
    shader's normal (after a displacement bump), which the shadow terminator offset reads.
    """
    hx, hy, hz = sp.hx, sp.hy, sp.hz
    ox, oy, oz = terminator_origin(sc, sp, nx, ny, nz, wix, wiy, wiz)
    sox, soy, soz = offset_origin(ox, oy, oz, sp.ngx, sp.ngy, sp.ngz, wix, wiy, wiz)
    sdx, sdy, sdz = wix, wiy, wiz
    tmax = T_INFINITE
    ex = ey = ez = math.inf
    if not math.isinf(dist):
        ex, ey, ez = hx + dist * wix, hy + dist * wiy, hz + dist * wiz
        if lnx != 0.0 or lny != 0.0 or lnz != 0.0:
            ex, ey, ez = offset_origin(ex, ey, ez, lnx, lny, lnz, -wix, -wiy, -wiz)
        sdx, sdy, sdz = ex - sox, ey - soy, ez - soz
        length = math.sqrt(sdx * sdx + sdy * sdy + sdz * sdz)
        if not length > 0.0:
            return n_shadow   # the light point is where the ray starts: no direction to test
        sdx, sdy, sdz = sdx / length, sdy / length, sdz / length
        tmax = length * (1.0 - SHADOW_SHORTEN)
    sq.o32[n_shadow, 0], sq.o32[n_shadow, 1], sq.o32[n_shadow, 2] = sox, soy, soz
    sq.d32[n_shadow, 0], sq.d32[n_shadow, 1], sq.d32[n_shadow, 2] = sdx, sdy, sdz
    sq.t32[n_shadow] = tmax
    sq.contrib[n_shadow, 0], sq.contrib[n_shadow, 1], sq.contrib[n_shadow, 2] = cr, cg, cb
    sq.path[n_shadow] = owner
    sq.time[n_shadow] = sp.time
    sq.target[n_shadow, 0], sq.target[n_shadow, 1], sq.target[n_shadow, 2] = ex, ey, ez
    sq.transparent[n_shadow] = transparent_left
    sq.alive[n_shadow] = 1
    for k in range(5):
        sq.depths[n_shadow, k] = depths[k]
    sq.travelled[n_shadow] = 0.0
    sq.kind[n_shadow] = SK_NONE
    return n_shadow + 1


@device
def next_path_flags(flags, label):
    """Path flags after a BSDF sample with ``label`` (Cycles' path_state_next)."""
    new = flags & ~(PF_CAMERA | PF_MIS_SKIP | PF_TRANSPARENT_BG | PF_TRANSPARENT | PF_DIFFUSE |
                    PF_GLOSSY | PF_SINGULAR | PF_TRANSMIT | PF_REFLECT | PF_TERMINATE)
    new |= PF_REFLECT if label & LABEL_REFLECT else PF_TRANSMIT
    if label & LABEL_DIFFUSE:
        new |= PF_DIFFUSE | PF_DIFFUSE_ANCESTOR
    elif label & LABEL_GLOSSY:
        new |= PF_GLOSSY
    else:   # singular: a glossy ray for light visibility, no MIS at its hit
        new |= PF_GLOSSY | PF_SINGULAR | PF_MIS_SKIP
    return new


# -- 1-3. light arriving along the ray ---------------------------------------------------------
@device
def light_from_lamps(sc, cfg, fcfg, stats, out, row, beta, i, ox, oy, oz, dx, dy, dz, t_hit,
                     flags, mis_pdf, pmf_mode, mp, mis_total, transparent, direct, light_set):
    """Add the light of lamps the ray passes before t_hit; returns how many it passed.

    Each lamp passed counts as a transparent bounce (Cycles), at most as many
    as ``transparent`` (the bounces made so far) leaves below the limit.  Only lamps that
    light ``light_set`` count (the receiver the ray left, light linking; -1: every lamp).
    """
    lr, lg, lb, passed = lamps_on_segment(
        sc.lamps, sc.ies, ox, oy, oz, dx, dy, dz, t_hit, flags, mis_pdf, pmf_mode,
        mp, mis_total, cfg[CFG_MAX_TRANSPARENT] - transparent, light_set)
    if passed:
        add_light(out, row, beta[i, 0] * lr, beta[i, 1] * lg, beta[i, 2] * lb, direct, fcfg, stats)
    return passed


@device
def light_from_background(sc, cfg, fcfg, scratch, stats, out, row, beta, i, dx, dy, dz, flags,
                          mis_pdf, pmf_mode, mp, mis_total, direct, light_set):
    """Add the world's and the suns' light (of the suns that light ``light_set``, -1: all)
    to an escaped ray.

    Returns the film transparency it leaves: on a transparent film a camera
    ray (also through transparent surfaces) sees no background, and the
    pixel's alpha drops by its average throughput.
    """
    transparency = light_from_world(sc, cfg, fcfg, scratch, stats, out, row, beta, i, dx, dy, dz,
                                    flags, mis_pdf, pmf_mode, mis_total, direct)
    light_from_suns(sc, cfg, fcfg, stats, out, row, beta, i, dx, dy, dz, flags, mis_pdf,
                    pmf_mode, mp, mis_total, direct, light_set)
    return transparency


@device
def light_from_world(sc, cfg, fcfg, scratch, stats, out, row, beta, i, dx, dy, dz, flags, mis_pdf,
                     pmf_mode, mis_total, direct):
    """The world's part of ``light_from_background`` (returns the film transparency)."""
    transparent_film = cfg[CFG_FILM_TRANSPARENT] != 0 and (flags & PF_TRANSPARENT_BG) != 0
    # The world is seen by the rays its Ray Visibility lets see it (as a lamp that MIS can
    # hit: Cycles' is_light_shader_visible_to_path of the background shader).
    if not transparent_film and cfg[CFG_WORLD] and lamp_visible_to_ray(
            flags, int(cfg[CFG_WORLD_VISIBILITY]) | LF_USE_MIS):
        wr, wg, wb = world_radiance(sc, cfg, scratch, dx, dy, dz, flags)
        # MIS against next-event estimation's sample of the world (when it makes one).
        pick = 0.0
        if pmf_mode == PMF_LOCAL:
            pick = fcfg[FCFG_WORLD_IMPORTANCE] / mis_total if mis_total > 0.0 else 0.0
        elif pmf_mode == PMF_GLOBAL:
            pick = fcfg[FCFG_WORLD_PMF]
        if pick > 0.0 and not (flags & PF_MIS_SKIP):
            w = power_heuristic(mis_pdf, pick * world_pdf(sc, dx, dy, dz))
            wr, wg, wb = wr * w, wg * w, wb * w
        add_light(out, row, beta[i, 0] * wr, beta[i, 1] * wg, beta[i, 2] * wb, direct, fcfg, stats)
    if transparent_film:
        return (beta[i, 0] + beta[i, 1] + beta[i, 2]) / 3.0
    return 0.0


@device
def light_from_suns(sc, cfg, fcfg, stats, out, row, beta, i, dx, dy, dz, flags, mis_pdf, pmf_mode,
                    mp, mis_total, direct, light_set):
    """The suns' part of ``light_from_background``: suns with an angle seen by the ray (those
    that light ``light_set``; -1: all)."""
    if sc.lamps.shape[0] and cfg[CFG_LAMPS_HIT]:
        lr, lg, lb = sun_light(sc.lamps, sc.ies, dx, dy, dz, flags, mis_pdf, pmf_mode,
                               mp, mis_total, light_set)
        if lr != 0.0 or lg != 0.0 or lb != 0.0:
            add_light(out, row, beta[i, 0] * lr, beta[i, 1] * lg, beta[i, 2] * lb, direct, fcfg,
                      stats)


@device
def shading_data(sp, dx, dy, dz, allocate, reflective, refractive, bump, prim, b1, b2, obj, flags,
                 ray_length, depths, dp, rng=0, min_pdf=0.0):
    """The ``ShadingData`` of surface point ``sp`` for a ray of direction d, every field of
    one fixed type (float64, bool, int64; numba's int() and float() would keep an int32 an
    int32 and a float32 a float32), whatever its callers pass: the shader evaluator and
    every node function it calls are then compiled once, not once per combination of
    argument types (and the compiler's folding ahead of time, from Python values, uses the
    same compiled code)."""
    i64, f64 = np.int64, np.float64
    return ShadingData(sp.hx, sp.hy, sp.hz, sp.nsx, sp.nsy, sp.nsz, sp.ngx, sp.ngy, sp.ngz,
                       -f64(dx), -f64(dy), -f64(dz), bool(sp.backfacing), bool(allocate),
                       bool(reflective), bool(refractive), bool(bump), i64(prim), f64(b1), f64(b2),
                       i64(obj), i64(flags), f64(ray_length), i64(depths[0]), i64(depths[1]),
                       i64(depths[2]), i64(depths[3]), i64(depths[4]), f64(dp), np.uint64(rng),
                       f64(min_pdf))


@device
def shade_point(sc, scene_ref, cfg, scratch, sp, m, p, b1, b2, dx, dy, dz, t_hit, flags,
                allocate, depths, footprint, walks=False, rng=0, min_pdf=0.0):
    """Run material m's shader at ``sp`` (on triangle p at barycentrics b1, b2) for a ray of
    direction d and length t_hit (from the vertex it left, through transparent surfaces, as
    Cycles measures it), on a path with ``flags`` and ``depths`` (bounces: all, diffuse,
    glossy, transmission, transparent) and the ray differential's ``footprint`` there (0: none,
    the Bump node then leaves the normal unchanged).

    The closures go to ``scratch.cl``, each with the object's Shadow Terminator Shading
    Offset (``closures.shift_cos_in``); returns the ``ShaderResult``.  With
    ``allocate`` false only emission, transparency and holdout are computed.  BSSRDF
    closures stay for a caller that ``walks`` (the path tracer with subsurface walks on);
    for others they become Lambert closures of their weight (Cycles' zero-radius limit).
    A path's own shading gives ``rng``, the key of the numbers of ray-traced nodes, and
    ``min_pdf``, its smallest BSDF pdf so far; 0 (shadow rays, exits of walks): those nodes
    trace nothing.  ``scene_ref`` is ``by_ref(shader_scene(sc))``, made by the kernel
    before its loop (``svm.eval_shader``).
    """
    from_diffuse = (flags & PF_DIFFUSE) != 0
    obj = sc.tex.tri_object[p]
    sd = shading_data(sp, dx, dy, dz, allocate,
                      cfg[CFG_CAUSTICS_REFLECTIVE] != 0 or not from_diffuse,
                      cfg[CFG_CAUSTICS_REFRACTIVE] != 0 or not from_diffuse,
                      (sc.mat_flags[m] & MF_BUMP_CORRECTION) != 0,
                      p, b1, b2, obj, flags, t_hit, depths, footprint, rng, min_pdf)
    if sc.mat_flags[m] & MF_CLOSURES_ONLY:
        res = eval_closure_rows(sc.svm_ops, sc.mat_prog[m, 0], sc.mat_prog[m, 1], scratch.regs,
                                scratch.cl, sd)
    else:
        res = eval_shader(sc.mat_prog[m, 0], sc.mat_prog[m, 1], scratch.regs, scratch.cl, sd,
                          scene_ref)
    if not walks:
        for k in range(res.n):
            if scratch.cl[k, CL_TYPE] == CT_BSSRDF:
                scratch.cl[k, CL_TYPE] = CT_DIFFUSE
                scratch.cl[k, CL_SW] = abs(scratch.cl[k, CL_W] + scratch.cl[k, CL_W + 1]
                                           + scratch.cl[k, CL_W + 2]) / 3.0
    frequency = sc.tex.objects[obj, OBJ_TERMINATOR_SHADING]
    if frequency > 1.0:
        for k in range(res.n):
            scratch.cl[k, CL_TERMINATOR] = frequency
    return res


@device
def emission_at(sc, scratch, tri, b1, b2, dx, dy, dz, dist, depths, time):
    """Radiance emitted by triangle ``tri`` (as it is at ``time``) at barycentrics (b1, b2)
    towards a ray of direction d and length dist that reaches it there (a light sample of a
    material whose emission varies over the surface: its shader runs there, without closures,
    as Cycles evaluates a light sample: path flag "emission", the bounce counts ``depths`` of
    the path sampling it)."""
    m = sc.mat_index[tri]
    sp = surface_point(sc, tri, b1, b2, dx, dy, dz, time)
    sd = shading_data(sp, dx, dy, dz, False, True, True, False, tri, b1, b2,
                      sc.tex.tri_object[tri], PF_EMISSION, dist, depths, 0.0)
    res = eval_shader(sc.mat_prog[m, 0], sc.mat_prog[m, 1], scratch.regs, scratch.cl_light, sd,
                      by_ref(shader_scene(sc)))
    return res.er, res.eg, res.eb


@kernel
def emission_estimates(sc, scratch, tris, out):
    """Mean emitted radiance of each triangle in ``tris`` over four points (its centroid and
    the midpoints towards its corners), facing its normal: the light-picking weights of
    materials whose emission varies over the surface."""
    points = ((1.0 / 3.0, 1.0 / 3.0), (1.0 / 6.0, 1.0 / 6.0), (2.0 / 3.0, 1.0 / 6.0),
              (1.0 / 6.0, 2.0 / 3.0))
    for j in range(tris.shape[0]):
        t = tris[j]
        r = g = b = 0.0
        nx, ny, nz, _ = triangle_frame(sc.verts, sc.tris, t)
        for k in range(4):
            b1, b2 = points[k]
            er, eg, eb = emission_at(sc, scratch, t, b1, b2, -nx, -ny, -nz, 1.0,
                                     (0, 0, 0, 0, 0), 0.5)
            r += er
            g += eg
            b += eb
        out[j, 0], out[j, 1], out[j, 2] = 0.25 * r, 0.25 * g, 0.25 * b


@device
def light_from_emitter(sc, fcfg, stats, out, row, beta, i, p, t_hit, sp, flags, mis_pdf,
                       pmf_mode, mp, mis_total, direct, er, eg, eb):
    """Add emission (er, eg, eb) of triangle p, seen by the ray at ``sp``, MIS-weighted."""
    w = emission_weight(sc, fcfg, p, sp.area, t_hit, sp.cos_o, flags, mis_pdf, pmf_mode, mp,
                        mis_total)
    add_light(out, row, beta[i, 0] * er * w, beta[i, 1] * eg * w, beta[i, 2] * eb * w, direct,
              fcfg, stats)


# -- 5. next-event estimation -----------------------------------------------------------------
@device
def world_light_sample(sc, cfg, scratch, pmf, u1, u2):
    """A direction towards the world drawn from its importance map and sun cone (picked
    with probability ``pmf``), as a :class:`LightSample` (radiance from the world's shader,
    evaluated as for a light: no ray-type flags); it lights only the lobes whose rays see
    the world (its Ray Visibility)."""
    wix, wiy, wiz, pdf = sample_world(sc, u1, u2)
    pdf_l = pmf * pdf
    if pdf_l <= 0.0:
        return LightSample(0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, False, False, 0,
                           0.0, 0.0, 0.0, -1, 0.0, 0.0)
    r, g, b = world_radiance(sc, cfg, scratch, wix, wiy, wiz, 0)
    return LightSample(wix, wiy, wiz, math.inf, r / pdf_l, g / pdf_l, b / pdf_l, pdf_l, True, True,
                       nee_exclude(int(cfg[CFG_WORLD_VISIBILITY])), 0.0, 0.0, 0.0, -1, 0.0, 0.0)


@device
def direct_light(sc, cfg, fcfg, stats, sq, n_shadow, out, row, beta, i, scratch, ncl, sp, dx, dy, dz,
                 idx, pmf, depths, u1, u2, mis_on, bsdf_pdf_scale, transparent_left):
    """Light from light ``idx`` (picked with probability ``pmf``) scattered at ``sp`` by
    the ``ncl`` closures in ``scratch.cl`` towards the viewer (-d).  Lights are the lamps,
    then the emissive triangles, then the world (``world_light_sample``).

    The light is added to ``out[row]`` at once if the light casts no shadow,
    else queued behind a shadow ray owned by ``row``; returns the queue length.
    With ``mis_on`` the power heuristic weighs it against BSDF sampling, whose
    pdf is scaled by ``bsdf_pdf_scale`` (the number of BSDF rays per hit).  ``depths``
    are the path's bounce counts (all, diffuse, glossy, transmission, transparent).  The
    light's direction and the closure labels it excludes go to ``scratch.light`` (4,), for
    render passes.
    """
    if pmf <= 0.0:
        return n_shadow
    bounce = depths[0]
    nx, ny, nz = shader_normal(sc, scratch.regs, sp)     # before a light's shader runs
    if idx == sc.lamps.shape[0] + sc.emit_tri.shape[0]:
        ls = world_light_sample(sc, cfg, scratch, pmf, u1, u2)
    else:
        ls = sample_light(sc, idx, pmf, sp.hx, sp.hy, sp.hz, bounce, u1, u2, sp.time)
    scratch.light[0], scratch.light[1], scratch.light[2] = ls.wix, ls.wiy, ls.wiz
    scratch.light[3] = ls.exclude
    lr, lg, lb = ls.lr, ls.lg, ls.lb
    if ls.tri >= 0 and (sc.mat_flags[sc.mat_index[ls.tri]] & MF_EMISSION_VARIES):
        er, eg, eb = emission_at(sc, scratch, ls.tri, ls.b1, ls.b2, ls.wix, ls.wiy, ls.wiz, ls.dist,
                                 depths, sp.time)
        lr, lg, lb = er / ls.pdf, eg / ls.pdf, eb / ls.pdf
    if lr == 0.0 and lg == 0.0 and lb == 0.0:   # (lights may be negative)
        return n_shadow
    fr_, fg_, fb_, bsdf_pdf = bsdf_eval(scratch.cl, ncl, -dx, -dy, -dz, ls.wix, ls.wiy, ls.wiz,
                                        ls.exclude)
    w = power_heuristic(ls.pdf, bsdf_pdf_scale * bsdf_pdf) if (mis_on and ls.use_mis) else 1.0
    cr = beta[i, 0] * fr_ * lr * w
    cg = beta[i, 1] * fg_ * lg * w
    cb = beta[i, 2] * fb_ * lb * w
    if cr == 0.0 and cg == 0.0 and cb == 0.0:
        return n_shadow
    limit = fcfg[FCFG_CLAMP_DIRECT] if bounce == 0 else fcfg[FCFG_CLAMP_INDIRECT]
    cr, cg, cb = clamp_light(cr, cg, cb, limit, stats)
    if ls.cast_shadow:
        return push_shadow(sq, sc, n_shadow, row, sp, nx, ny, nz, ls.wix, ls.wiy, ls.wiz, ls.dist,
                           ls.lnx, ls.lny, ls.lnz, cr, cg, cb, transparent_left, depths)
    out[row, 0] += cr
    out[row, 1] += cg
    out[row, 2] += cb
    return n_shadow


# -- 6. the next direction -----------------------------------------------------------------------
@device
def leaves_correct_side(sp, wix, wiy, wiz, label):
    """Whether a sampled direction leaves to the side of the geometric surface its lobe
    says (reflection to the viewer's side, transmission to the other); a shading
    normal can otherwise send a ray through the wrong side."""
    cos_i_geo = wix * sp.ngx + wiy * sp.ngy + wiz * sp.ngz
    return not ((label & LABEL_REFLECT and cos_i_geo <= 0.0)
                or (label & LABEL_TRANSMIT and cos_i_geo >= 0.0))


@device
def sample_direction(cl, ncl, sp, dx, dy, dz, u_pick, u1, u2, u3):
    """The closures sample the next direction at ``sp`` for a ray of direction d."""
    wix, wiy, wiz, wr, wg, wb, pdf, label, pick = bsdf_sample_closure(cl, ncl, -dx, -dy, -dz,
                                                                      u_pick, u1, u2, u3)
    if (wr == 0.0 and wg == 0.0 and wb == 0.0) or not (
            free_side(cl[pick, CL_TYPE]) or leaves_correct_side(sp, wix, wiy, wiz, label)):
        return DirectionSample(False, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, label, pick)
    return DirectionSample(True, wix, wiy, wiz, wr, wg, wb, pdf, label, pick)
