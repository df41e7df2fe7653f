"""Wavefront path tracing: camera rays, surface shading, next-event estimation.

One *chunk* is a batch of path samples (a range of film pixels times a few
samples each).  A worker traces its chunk bounce by bounce:

1. ``generate_camera_rays``      fill the path state and the ray buffers;
2. ``Accel.closest``             one Embree call for all live rays;
3. ``shade``                     emission (lamps, world, emissive triangles,
                                 with MIS), Russian roulette, next-event
                                 estimation (one light sample, a shadow ray),
                                 BSDF sampling of the next direction;
4. ``Accel.occluded``            one Embree call for all shadow rays;
5. ``finish_bounce``             add unoccluded light, write finished paths to
                                 the film, compact the live paths to the front.

The algorithm follows Cycles (intern/cycles/kernel/integrator/) where that
decides the expected value: bounce limits (a vertex scatters while no bounce
counter exceeds its limit; the next vertex only collects emission), lamps
that rays pass through, per-light visibility and MIS switches, light
``max_bounces`` gating NEE only, clamping per contribution, Russian roulette
from the third vertex on, film transparency.  See notes in each step.

Stages are scalar loops compiled by numba (``nogil``), so two workers in two
Python threads keep both cores busy; Embree releases the GIL as well.
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from .bsdf import (LABEL_DIFFUSE, LABEL_GLOSSY, LABEL_REFLECT, LABEL_SINGULAR, LABEL_TRANSMIT,
                   M_EMISSION, M_EMISSIVE, bsdf_eval, bsdf_has_lobes, bsdf_sample)
from .camera import camera_ray
from .intersect import SHADOW_SHORTEN, T_INFINITE, intersect_prim, offset_origin, offset_scale
from .jit import device, kernel
from .lights import (L_FLAGS, L_MAX_BOUNCES, L_PMF, L_SUN_COS, L_TYPE, LF_CAST_SHADOW,
                     group_importance, lamp_importance,
                     LF_USE_MIS, LF_VIS_CAMERA, LF_VIS_DIFFUSE, LF_VIS_GLOSSY,
                     LF_VIS_TRANSMISSION, LT_SUN, intersect_lamp, pick_light, sample_lamp,
                     sample_triangle_point, sun_radiance)
from .sampling import (DIM_BSDF_LOBE, DIM_BSDF_U, DIM_BSDF_V, DIM_FILTER_X, DIM_FILTER_Y,
                       DIM_LIGHT_GROUP, DIM_LIGHT_PICK, DIM_LIGHT_U, DIM_LIGHT_V, DIM_ROULETTE, bounce_dim,
                       filter_offset, orthonormal_basis, path_key, power_heuristic, rand)

# -- path state ----------------------------------------------------------------------
PathState = namedtuple("PathState", [
    "key",           # (B,) uint64   RNG key of the path sample
    "pixel",         # (B,) int32    film pixel (index into the film region)
    "root",          # (B,) int32    camera sample a ray belongs to (classic integrators)
    "ray_o",         # (B, 3) f64    ray origin
    "ray_d",         # (B, 3) f64    unit ray direction
    "ray_tmax",      # (B,) f64      ray length (far clip for camera rays)
    "beta",          # (B, 3) f64    path throughput
    "radiance",      # (B, 3) f64    radiance collected so far
    "transparency",  # (B,) f64      1 if the camera ray escaped to a transparent film
    "bounce",        # (B,) int32    scattering events so far (= index of the next vertex)
    "diffuse",       # (B,) int32    diffuse scattering events so far
    "glossy",        # (B,) int32
    "transmission",  # (B,) int32
    "transparent",   # (B,) int32    transparent passes (lamps count as one)
    "flags",         # (B,) int32    PF_* bits
    "mis_pdf",       # (B,) f64      pdf of the BSDF sample that made the current ray
    "mis_p",         # (B, 3) f64    the vertex that ray left (light picking there, for MIS)
    "self_prim",     # (B,) int32    triangle the ray starts on (-1: none)
    "alive",         # (B,) uint8    still tracing after this bounce
    "o32",           # (B, 3) f32    Embree input: origins
    "d32",           # (B, 3) f32    Embree input: directions
    "t32",           # (B,) f32      Embree input: tfar
])

ShadowQueue = namedtuple("ShadowQueue", [
    "o32", "d32", "t32",   # Embree input
    "contrib",             # (B, 3) f64  radiance to add if unoccluded
    "path",                # (B,) int32  path the contribution belongs to
])

SceneData = namedtuple("SceneData", [
    "verts",         # (V, 3) f64
    "tris",          # (T, 3) int32
    "normals",       # (T, 3, 3) f32  shading normals at the corners
    "mat_index",     # (T,) int32
    "materials",     # (M, MATERIAL_STRIDE) f64
    "lamps",         # (NL, LIGHT_STRIDE) f64
    "light_cdf",     # (NL + NE + 1,) f64  NEE light distribution
    "emit_tri",      # (NE,) int32  emissive triangle ids
    "emit_pmf",      # (NE,) f64    their NEE probabilities
    "emit_cdf",      # (NE + 1,) f64  distribution over emissive triangles alone
    "emit_group",    # (5,) f64     emissive triangles as one light: centre, radius^2, scale
    "tri_light",     # (T,) int32   index into emit_tri, or -1
    "tri_area",      # (T,) f64
    "tri_normal",    # (T, 3) f64  unit geometric normal (from the winding)
    "world",         # (3,) f64     background radiance
    "camera",        # (CAMERA_PARAMS,) f64
    "filter_table",  # (FILTER_TABLE_SIZE,) f64
])

# Path flags.
PF_CAMERA = 1            # no scattering yet: the ray is a camera ray
PF_MIS_SKIP = 2          # emission found by this ray gets MIS weight 1
PF_TERMINATE = 4         # a bounce limit was reached: the next hit only collects emission
PF_TRANSPARENT_BG = 8    # camera ray on a transparent film: the background gives alpha 0
PF_DIFFUSE = 16          # label of the BSDF sample that made the ray
PF_GLOSSY = 32
PF_TRANSMIT = 64
PF_REFLECT = 128

# Integer settings (cfg array).
CFG_MAX_BOUNCE = 0
CFG_MAX_DIFFUSE = 1
CFG_MAX_GLOSSY = 2
CFG_MAX_TRANSMISSION = 3
CFG_MAX_TRANSPARENT = 4
CFG_MIN_LIGHT_BOUNCES = 5
CFG_SEED = 6
CFG_FILM_TRANSPARENT = 7
CFG_WORLD_CAMERA = 8      # world visible to camera rays
CFG_LAMPS_HIT = 9         # some lamp can be hit by rays (Cycles' use_light_mis)
CFG_REGION_X = 10         # film region origin and width in the full frame
CFG_REGION_Y = 11
CFG_REGION_W = 12
CFG_FULL_W = 13
CFG_LIGHTS = 14           # NEE has something to sample
CFG_WORLD = 15            # the world is not black
CFG_LOCAL_LIGHTS = 16     # pick lights by their estimated irradiance at each point
CFG_SIZE = 17
# Float settings (fcfg array).
FCFG_CLAMP_DIRECT = 0     # limit on |r|+|g|+|b| of a direct contribution (inf: off)
FCFG_CLAMP_INDIRECT = 1
FCFG_EMIT_SCALE = 2       # 1 / (share of the emissive triangles in the scene-wide pmf)
FCFG_SIZE = 3

# How a light's selection probability is known, for MIS weights.
PMF_GLOBAL = 0            # by power, scene-wide (lamps[:, L_PMF], emit_pmf)
PMF_EVERY = 1             # every light is sampled (classic integrators)
PMF_LOCAL = 2             # by estimated irradiance at the vertex the ray left

# Statistics counters (stats array, per worker).
ST_CAMERA_RAYS = 0
ST_BOUNCE_RAYS = 1
ST_SHADOW_RAYS = 2
ST_SELF_HITS = 3          # rays that re-hit their origin triangle and were re-traced
ST_NONFINITE = 4          # contributions dropped because they were NaN or infinite
ST_SIZE = 5


def alloc_path_state(n: int) -> PathState:
    """Buffers for n paths, allocated once per worker and reused."""
    return PathState(
        key=np.zeros(n, np.uint64), pixel=np.zeros(n, np.int32), root=np.zeros(n, np.int32),
        ray_o=np.zeros((n, 3)), ray_d=np.zeros((n, 3)), ray_tmax=np.zeros(n),
        beta=np.zeros((n, 3)), radiance=np.zeros((n, 3)), transparency=np.zeros(n),
        bounce=np.zeros(n, np.int32), diffuse=np.zeros(n, np.int32),
        glossy=np.zeros(n, np.int32), transmission=np.zeros(n, np.int32),
        transparent=np.zeros(n, np.int32), flags=np.zeros(n, np.int32),
        mis_pdf=np.zeros(n), mis_p=np.zeros((n, 3)), self_prim=np.zeros(n, np.int32),
        alive=np.zeros(n, np.uint8),
        o32=np.zeros((n, 3), np.float32), d32=np.zeros((n, 3), np.float32),
        t32=np.zeros(n, np.float32))


def alloc_shadow_queue(n: int) -> ShadowQueue:
    return ShadowQueue(o32=np.zeros((n, 3), np.float32), d32=np.zeros((n, 3), np.float32),
                       t32=np.zeros(n, np.float32), contrib=np.zeros((n, 3)),
                       path=np.zeros(n, np.int32))


# -- 1. camera rays ----------------------------------------------------------------------
@kernel
def generate_camera_rays(pixels, spp, sample_base, st, sc, cfg):
    """Start ``spp`` paths for each film pixel in ``pixels``; returns the path count.

    The sample index of a path is the pixel's count of finished samples
    (``sample_base``) plus its rank here, so every sample of a pixel has its
    own random numbers whatever the pass schedule.
    """
    n = 0
    region_x, region_y, region_w = cfg[CFG_REGION_X], cfg[CFG_REGION_Y], cfg[CFG_REGION_W]
    transparent_bg = PF_TRANSPARENT_BG if cfg[CFG_FILM_TRANSPARENT] else 0
    for pi in range(pixels.shape[0]):
        pix = pixels[pi]
        x = region_x + pix % region_w
        y = region_y + pix // region_w
        global_pixel = y * cfg[CFG_FULL_W] + x
        for j in range(spp):
            sample = sample_base[pix] + j
            key = path_key(cfg[CFG_SEED], global_pixel, sample)
            # Cycles takes the first sample of every pixel at the pixel centre.
            if sample == 0:
                fx, fy = 0.5, 0.5
            else:
                fx = filter_offset(sc.filter_table, rand(key, DIM_FILTER_X))
                fy = filter_offset(sc.filter_table, rand(key, DIM_FILTER_Y))
            ox, oy, oz, dx, dy, dz, tmax = camera_ray(sc.camera, x + fx, y + fy)
            st.key[n] = key
            st.pixel[n] = pix
            st.ray_o[n, 0], st.ray_o[n, 1], st.ray_o[n, 2] = ox, oy, oz
            st.ray_d[n, 0], st.ray_d[n, 1], st.ray_d[n, 2] = dx, dy, dz
            st.ray_tmax[n] = tmax
            st.beta[n, 0], st.beta[n, 1], st.beta[n, 2] = 1.0, 1.0, 1.0
            st.radiance[n, 0], st.radiance[n, 1], st.radiance[n, 2] = 0.0, 0.0, 0.0
            st.transparency[n] = 0.0
            st.bounce[n] = 0
            st.diffuse[n] = 0
            st.glossy[n] = 0
            st.transmission[n] = 0
            st.transparent[n] = 0
            st.flags[n] = PF_CAMERA | PF_MIS_SKIP | transparent_bg
            st.mis_pdf[n] = 0.0
            st.self_prim[n] = -1
            st.o32[n, 0], st.o32[n, 1], st.o32[n, 2] = ox, oy, oz
            st.d32[n, 0], st.d32[n, 1], st.d32[n, 2] = dx, dy, dz
            st.t32[n] = min(tmax, T_INFINITE)
            n += 1
    return n


# -- helpers shared by every integrator ----------------------------------------------------
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
def add_light(radiance, i, r, g, b, direct, fcfg, stats):
    """Add a clamped contribution to row i of ``radiance`` (direct or indirect limit)."""
    limit = fcfg[FCFG_CLAMP_DIRECT] if direct else fcfg[FCFG_CLAMP_INDIRECT]
    r, g, b = clamp_light(r, g, b, limit, stats)
    radiance[i, 0] += r
    radiance[i, 1] += g
    radiance[i, 2] += b


@device
def lamp_visible_to_ray(flags, lamp_flags):
    """Cycles' is_light_shader_visible_to_path for a ray of the given path flags."""
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
def nee_exclude(lamp_flags):
    """BSDF lobes a light must not illuminate (its ray-visibility switches)."""
    ex = 0
    if not (lamp_flags & LF_VIS_DIFFUSE):
        ex |= LABEL_DIFFUSE
    if not (lamp_flags & LF_VIS_GLOSSY):
        ex |= LABEL_GLOSSY
    if not (lamp_flags & LF_VIS_TRANSMISSION):
        ex |= LABEL_TRANSMIT
    return ex


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
def past_self_hit(verts, tris, p, ox, oy, oz, dx, dy, dz):
    """Distance to move a ray that re-hit the triangle it left, to just past that hit.

    Triangles are flat, so a ray leaving one can only hit it again through
    rounding: the ray continues from just past that hit.
    """
    t, b1, b2 = intersect_prim(ox, oy, oz, dx, dy, dz, verts, tris, p)
    if not math.isfinite(t) or t < 0.0:
        t = 0.0
    return t + offset_scale(ox + t * dx, oy + t * dy, oz + t * dz) * 4.0


@device
def hit_distance(verts, tris, p, ox, oy, oz, dx, dy, dz, tmax):
    """(t, b1, b2) of the ray's hit on triangle p (t = tmax if p < 0)."""
    if p < 0:
        return tmax, 0.0, 0.0
    t, b1, b2 = intersect_prim(ox, oy, oz, dx, dy, dz, verts, tris, p)
    return (t if (math.isfinite(t) and t > 0.0) else 0.0), b1, b2


@device
def surface_geometry(verts, tris, tri_normal, normals, p, b1, b2, dx, dy, dz):
    """Hit point, geometric and shading normals facing the ray, and the side hit.

    Returns ``(hx, hy, hz, ngx, ngy, ngz, nsx, nsy, nsz, cos_o_geo, backfacing)``.
    All BSDFs are two-sided, so both normals are turned towards the incoming
    ray; ``backfacing`` records that the ray came from the inside (relative to
    the winding, or to the shading normals where they disagree with it).
    """
    b0 = 1.0 - b1 - b2
    va, vb, vc = tris[p, 0], tris[p, 1], tris[p, 2]
    hx = b0 * verts[va, 0] + b1 * verts[vb, 0] + b2 * verts[vc, 0]
    hy = b0 * verts[va, 1] + b1 * verts[vb, 1] + b2 * verts[vc, 1]
    hz = b0 * verts[va, 2] + b1 * verts[vb, 2] + b2 * verts[vc, 2]
    ngx, ngy, ngz = tri_normal[p, 0], tri_normal[p, 1], tri_normal[p, 2]
    nsx = b0 * normals[p, 0, 0] + b1 * normals[p, 1, 0] + b2 * normals[p, 2, 0]
    nsy = b0 * normals[p, 0, 1] + b1 * normals[p, 1, 1] + b2 * normals[p, 2, 1]
    nsz = b0 * normals[p, 0, 2] + b1 * normals[p, 1, 2] + b2 * normals[p, 2, 2]
    ln = math.sqrt(nsx * nsx + nsy * nsy + nsz * nsz)
    if ln > 0.0 and math.isfinite(ln):
        nsx, nsy, nsz = nsx / ln, nsy / ln, nsz / ln
        if nsx * ngx + nsy * ngy + nsz * ngz < 0.0:
            # Shading normals on the other side than the winding says: trust
            # the normals (mirrored instances, flipped faces).
            ngx, ngy, ngz = -ngx, -ngy, -ngz
    else:
        nsx, nsy, nsz = ngx, ngy, ngz
    cos_o_geo = -(dx * ngx + dy * ngy + dz * ngz)
    backfacing = cos_o_geo < 0.0
    if backfacing:
        ngx, ngy, ngz = -ngx, -ngy, -ngz
        nsx, nsy, nsz = -nsx, -nsy, -nsz
        cos_o_geo = -cos_o_geo
    return hx, hy, hz, ngx, ngy, ngz, nsx, nsy, nsz, cos_o_geo, backfacing


@device
def local_light_total(lamps, group, has_group, px, py, pz):
    """Sum of every light's importance at p (lamps, and the emissive triangles as one)."""
    total = 0.0
    for li in range(lamps.shape[0]):
        total += lamp_importance(lamps, li, px, py, pz)
    if has_group:
        total += group_importance(group, px, py, pz)
    return total


@device
def lamp_pick_pmf(lamps, li, pmf_mode, px, py, pz, total):
    """Probability that next-event estimation at p picks lamp li."""
    if pmf_mode == PMF_EVERY:
        return 1.0
    if pmf_mode == PMF_LOCAL:
        return lamp_importance(lamps, li, px, py, pz) / total if total > 0.0 else 0.0
    return lamps[li, L_PMF]


@device
def pick_light_local(lamps, group, has_group, px, py, pz, u):
    """Pick a light at p in proportion to its importance there.

    Returns ``(choice, pmf)``: a lamp index, or ``n_lamps`` for the emissive
    triangles as a group; ``pmf`` 0 if nothing can light p.
    """
    n_lamps = lamps.shape[0]
    total = local_light_total(lamps, group, has_group, px, py, pz)
    if total <= 0.0:
        return 0, 0.0
    target = u * total
    acc = 0.0
    last = -1
    last_w = 0.0
    for li in range(n_lamps):
        w = lamp_importance(lamps, li, px, py, pz)
        if w > 0.0:
            acc += w
            last, last_w = li, w
            if target < acc:
                return li, w / total
    if has_group:
        return n_lamps, group_importance(group, px, py, pz) / total
    return last, last_w / total      # rounding at the end of the scan


@device
def lamps_on_segment(lamps, ox, oy, oz, dx, dy, dz, t_hit, flags, mis_pdf, pmf_mode,
                     mpx, mpy, mpz, mis_total, transparent_left):
    """Light from lamps the ray passes through before t_hit (lamps do not block rays).

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
            tl, lr, lg, lb, lpdf = intersect_lamp(lamps, li, ox, oy, oz, dx, dy, dz, t_hit,
                                                  mpx, mpy, mpz)
            if tl > last_t and tl < t_hit:
                n_hits += 1
                if tl < best_t:
                    best_t, best = tl, li
                    br, bg, bb, bpdf = lr, lg, lb, lpdf
        if best < 0:
            break
        w = 1.0
        if not (flags & PF_MIS_SKIP):
            pmf = lamp_pick_pmf(lamps, best, pmf_mode, mpx, mpy, mpz, mis_total)
            w = power_heuristic(mis_pdf, pmf * bpdf)
        lr_sum += br * w
        lg_sum += bg * w
        lb_sum += bb * w
        passed += 1
        last_t = best_t
        more = n_hits > 1
    return lr_sum, lg_sum, lb_sum, passed


@device
def sun_light(lamps, dx, dy, dz, flags, mis_pdf, pmf_mode, mpx, mpy, mpz, mis_total):
    """Light from suns with an angle, seen along an escaped ray (MIS-weighted)."""
    r = g = b = 0.0
    for li in range(lamps.shape[0]):
        if int(lamps[li, L_TYPE]) != LT_SUN or lamps[li, L_SUN_COS] >= 1.0:
            continue
        lflags = int(lamps[li, L_FLAGS])
        if not (lflags & LF_USE_MIS) or not lamp_visible_to_ray(flags, lflags):
            continue
        lr, lg, lb, lpdf = sun_radiance(lamps, li, dx, dy, dz)
        if lpdf > 0.0:
            w = 1.0
            if not (flags & PF_MIS_SKIP):
                pmf = lamp_pick_pmf(lamps, li, pmf_mode, mpx, mpy, mpz, mis_total)
                w = power_heuristic(mis_pdf, pmf * lpdf)
            r += lr * w
            g += lg * w
            b += lb * w
    return r, g, b


@device
def emission_weight(tri_light, emit_pmf, tri_area, p, t_hit, cos_o_geo, flags, mis_pdf,
                    emit_pmf_scale):
    """MIS weight of emission found by a BSDF ray on emissive triangle p."""
    if flags & PF_MIS_SKIP:
        return 1.0
    j = tri_light[p]
    if j < 0:
        return 1.0
    light_pdf = emit_pmf[j] * emit_pmf_scale * t_hit * t_hit / (tri_area[p] * cos_o_geo)
    return power_heuristic(mis_pdf, light_pdf)


@device
def sample_light(lamps, emit_tri, verts, tris, tri_normal, tri_area, mat_index, materials,
                 idx, pmf, hx, hy, hz, bounce, u1, u2):
    """Sample light ``idx`` (a lamp, or NL + j for emissive triangle j) from point h.

    ``pmf`` is the probability with which the caller chose this light.
    Returns ``(wix, wiy, wiz, dist, Lr, Lg, Lb, pdf, use_mis, cast_shadow,
    exclude, lnx, lny, lnz)``: the direction and distance to the light point,
    the radiance divided by the sampling pdf (pmf included), the solid-angle
    pdf (0 for delta lights, which get no MIS), the light's flags, and the
    emitter's unit normal (zero for lamps) for offsetting the shadow ray's end.
    All-zero radiance means no contribution.
    """
    n_lamps = lamps.shape[0]
    if idx < n_lamps:
        lflags = int(lamps[idx, L_FLAGS])
        if bounce > lamps[idx, L_MAX_BOUNCES]:
            return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, False, False, 0, 0.0, 0.0, 0.0
        wix, wiy, wiz, dist, lr, lg, lb, pdf = sample_lamp(lamps, idx, hx, hy, hz, u1, u2)
        use_mis = (lflags & LF_USE_MIS) != 0
        if pdf > 0.0:
            pdf_l = pmf * pdf
            lr, lg, lb = lr / pdf_l, lg / pdf_l, lb / pdf_l
        else:   # delta light: L is already the L/pdf term
            pdf_l = 0.0
            use_mis = False
            lr, lg, lb = lr / pmf, lg / pmf, lb / pmf
        return (wix, wiy, wiz, dist, lr, lg, lb, pdf_l, use_mis, (lflags & LF_CAST_SHADOW) != 0,
                nee_exclude(lflags), 0.0, 0.0, 0.0)
    tri = emit_tri[idx - n_lamps]
    qx, qy, qz = sample_triangle_point(verts, tris, tri, u1, u2)
    lx, ly, lz = qx - hx, qy - hy, qz - hz
    d2 = lx * lx + ly * ly + lz * lz
    dist = math.sqrt(d2)
    if dist <= 0.0:
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, False, False, 0, 0.0, 0.0, 0.0
    wix, wiy, wiz = lx / dist, ly / dist, lz / dist
    lnx, lny, lnz = tri_normal[tri, 0], tri_normal[tri, 1], tri_normal[tri, 2]
    cos_l = abs(lnx * wix + lny * wiy + lnz * wiz)
    if cos_l <= 0.0:
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, False, False, 0, 0.0, 0.0, 0.0
    pdf_l = pmf * d2 / (tri_area[tri] * cos_l)
    em = mat_index[tri]
    return (wix, wiy, wiz, dist, materials[em, M_EMISSION] / pdf_l,
            materials[em, M_EMISSION + 1] / pdf_l, materials[em, M_EMISSION + 2] / pdf_l,
            pdf_l, True, True, 0, lnx, lny, lnz)


@device
def push_shadow(so32, sd32, st32, scontrib, spath, n_shadow, owner, hx, hy, hz, ngx, ngy, ngz,
                wix, wiy, wiz, dist, lnx, lny, lnz, cr, cg, cb):
    """Queue a shadow ray from h towards the light point; returns the new queue length.

    Both ends leave their surfaces (pbrt's SpawnRayTo): the direction is
    re-aimed from the offset origin at the offset target, else at grazing
    angles the shifted ray meets the emitter's plane before its end.
    """
    sox, soy, soz = offset_origin(hx, hy, hz, ngx, ngy, ngz, wix, wiy, wiz)
    sdx, sdy, sdz = wix, wiy, wiz
    tmax = T_INFINITE
    if not math.isinf(dist):
        ex, ey, ez = hx + dist * wix, hy + dist * wiy, hz + dist * wiz
        if lnx != 0.0 or lny != 0.0 or lnz != 0.0:
            ex, ey, ez = offset_origin(ex, ey, ez, lnx, lny, lnz, -wix, -wiy, -wiz)
        sdx, sdy, sdz = ex - sox, ey - soy, ez - soz
        length = math.sqrt(sdx * sdx + sdy * sdy + sdz * sdz)
        sdx, sdy, sdz = sdx / length, sdy / length, sdz / length
        tmax = length * (1.0 - SHADOW_SHORTEN)
    so32[n_shadow, 0], so32[n_shadow, 1], so32[n_shadow, 2] = sox, soy, soz
    sd32[n_shadow, 0], sd32[n_shadow, 1], sd32[n_shadow, 2] = sdx, sdy, sdz
    st32[n_shadow] = tmax
    scontrib[n_shadow, 0], scontrib[n_shadow, 1], scontrib[n_shadow, 2] = cr, cg, cb
    spath[n_shadow] = owner
    return n_shadow + 1


@device
def local_frame(nsx, nsy, nsz, dx, dy, dz):
    """Tangent frame around the shading normal and wo = -d in it."""
    tx, ty, tz, bx, by, bz = orthonormal_basis(nsx, nsy, nsz)
    wox = -(dx * tx + dy * ty + dz * tz)
    woy = -(dx * bx + dy * by + dz * bz)
    woz = -(dx * nsx + dy * nsy + dz * nsz)
    return tx, ty, tz, bx, by, bz, wox, woy, woz


@device
def next_path_flags(flags, label):
    """Path flags after a BSDF sample with ``label`` (Cycles' path_state_next)."""
    new = flags & ~(PF_CAMERA | PF_MIS_SKIP | PF_TRANSPARENT_BG | PF_DIFFUSE |
                    PF_GLOSSY | PF_TRANSMIT | PF_REFLECT | PF_TERMINATE)
    new |= PF_REFLECT if label & LABEL_REFLECT else PF_TRANSMIT
    if label & LABEL_DIFFUSE:
        new |= PF_DIFFUSE
    elif label & LABEL_GLOSSY:
        new |= PF_GLOSSY
    else:   # singular: a glossy ray for light visibility, no MIS at its hit
        new |= PF_GLOSSY | PF_MIS_SKIP
    return new


# -- 3. shading (path tracing) -------------------------------------------------------------
@kernel
def shade(n, prim, st, sq, sc, cfg, fcfg, stats):
    """Shade the hits of the n live paths; returns the number of queued shadow rays."""
    n_shadow = 0
    n_lamps = sc.lamps.shape[0]
    lamps_hit = cfg[CFG_LAMPS_HIT] != 0
    local = cfg[CFG_LOCAL_LIGHTS] != 0
    pmf_mode = PMF_LOCAL if local else PMF_GLOBAL
    has_group = sc.emit_tri.shape[0] > 0
    for i in range(n):
        st.alive[i] = 0
        p = prim[i]
        ox, oy, oz = st.ray_o[i, 0], st.ray_o[i, 1], st.ray_o[i, 2]
        dx, dy, dz = st.ray_d[i, 0], st.ray_d[i, 1], st.ray_d[i, 2]
        if p >= 0 and p == st.self_prim[i]:
            stats[ST_SELF_HITS] += 1
            s = past_self_hit(sc.verts, sc.tris, p, ox, oy, oz, dx, dy, dz)
            set_ray(st.ray_o, st.ray_d, st.ray_tmax, st.o32, st.d32, st.t32, i,
                    ox + s * dx, oy + s * dy, oz + s * dz, dx, dy, dz, st.ray_tmax[i] - s)
            st.alive[i] = 1
            continue
        flags = st.flags[i]
        t_hit, b1, b2 = hit_distance(sc.verts, sc.tris, p, ox, oy, oz, dx, dy, dz, st.ray_tmax[i])
        arrival_direct = st.bounce[i] <= 1   # clamp index (bounce - 1) <= 0
        # Light-picking probabilities at the vertex this ray left, for MIS.
        mpx, mpy, mpz = st.mis_p[i, 0], st.mis_p[i, 1], st.mis_p[i, 2]
        mis_total = 0.0
        if local and not (flags & PF_MIS_SKIP):
            mis_total = local_light_total(sc.lamps, sc.emit_group, has_group, mpx, mpy, mpz)

        # -- lamps along the ray ---------------------------------------------------------
        if lamps_hit:
            lr, lg, lb, passed = lamps_on_segment(
                sc.lamps, ox, oy, oz, dx, dy, dz, t_hit, flags, st.mis_pdf[i], pmf_mode,
                mpx, mpy, mpz, mis_total, cfg[CFG_MAX_TRANSPARENT] - st.transparent[i])
            if passed:
                add_light(st.radiance, i, st.beta[i, 0] * lr, st.beta[i, 1] * lg, st.beta[i, 2] * lb,
                     arrival_direct, fcfg, stats)
                st.transparent[i] += passed
                if st.transparent[i] >= cfg[CFG_MAX_TRANSPARENT]:
                    continue   # Cycles: the path ends after the lamp's light

        # -- escaped: world and suns -------------------------------------------------------
        if p < 0:
            if flags & PF_TRANSPARENT_BG:
                st.transparency[i] = 1.0
            elif cfg[CFG_WORLD] and (cfg[CFG_WORLD_CAMERA] or not (flags & PF_CAMERA)):
                add_light(st.radiance, i, st.beta[i, 0] * sc.world[0], st.beta[i, 1] * sc.world[1],
                     st.beta[i, 2] * sc.world[2], arrival_direct, fcfg, stats)
            if n_lamps:
                lr, lg, lb = sun_light(sc.lamps, dx, dy, dz, flags, st.mis_pdf[i], pmf_mode,
                                       mpx, mpy, mpz, mis_total)
                if lr + lg + lb > 0.0:
                    add_light(st.radiance, i, st.beta[i, 0] * lr, st.beta[i, 1] * lg, st.beta[i, 2] * lb,
                         arrival_direct, fcfg, stats)
            continue

        # -- surface hit ---------------------------------------------------------------------
        if sc.tri_area[p] <= 0.0:
            continue   # degenerate triangle: Embree should not report it; drop the path
        hx, hy, hz, ngx, ngy, ngz, nsx, nsy, nsz, cos_o_geo, backfacing = surface_geometry(
            sc.verts, sc.tris, sc.tri_normal, sc.normals, p, b1, b2, dx, dy, dz)
        m = sc.mat_index[p]

        # Russian roulette (Cycles: from the third vertex on, with the
        # throughput as it is; emission here is not affected by it).
        q = 1.0
        if st.bounce[i] > cfg[CFG_MIN_LIGHT_BOUNCES] + 1 and not (flags & PF_TERMINATE):
            q = min(math.sqrt(max(abs(st.beta[i, 0]), abs(st.beta[i, 1]), abs(st.beta[i, 2]))), 1.0)

        # Emission (two-sided).
        if sc.materials[m, M_EMISSIVE] > 0.0:
            group_share = 1.0
            if local and mis_total > 0.0:
                group_share = (group_importance(sc.emit_group, mpx, mpy, mpz) / mis_total
                               * fcfg[FCFG_EMIT_SCALE])
            w = emission_weight(sc.tri_light, sc.emit_pmf, sc.tri_area, p, t_hit, cos_o_geo, flags,
                                st.mis_pdf[i], group_share)
            add_light(st.radiance, i, st.beta[i, 0] * sc.materials[m, M_EMISSION] * w,
                 st.beta[i, 1] * sc.materials[m, M_EMISSION + 1] * w,
                 st.beta[i, 2] * sc.materials[m, M_EMISSION + 2] * w, arrival_direct, fcfg, stats)

        if (flags & PF_TERMINATE) or not bsdf_has_lobes(sc.materials, m):
            continue
        bounce = st.bounce[i]
        key = st.key[i]
        if q < 1.0:
            if rand(key, bounce_dim(bounce, DIM_ROULETTE)) >= q:
                continue
            st.beta[i, 0] /= q
            st.beta[i, 1] /= q
            st.beta[i, 2] /= q
        tx, ty, tz, bx, by, bz, wox, woy, woz = local_frame(nsx, nsy, nsz, dx, dy, dz)

        # -- next-event estimation: one light, picked by power ---------------------------------
        if cfg[CFG_LIGHTS]:
            u_pick = rand(key, bounce_dim(bounce, DIM_LIGHT_PICK))
            if local:
                idx, pmf = pick_light_local(sc.lamps, sc.emit_group, has_group, hx, hy, hz, u_pick)
                if idx == n_lamps:
                    j = pick_light(sc.emit_cdf, rand(key, bounce_dim(bounce, DIM_LIGHT_GROUP)))
                    idx = n_lamps + j
                    pmf *= sc.emit_pmf[j] * fcfg[FCFG_EMIT_SCALE]
            else:
                idx = pick_light(sc.light_cdf, u_pick)
                pmf = sc.light_cdf[idx + 1] - sc.light_cdf[idx]
            (wix, wiy, wiz, dist, lr, lg, lb, pdf_l, use_mis, cast_shadow, exclude,
             lnx, lny, lnz) = sample_light(sc.lamps, sc.emit_tri, sc.verts, sc.tris, sc.tri_normal,
                                           sc.tri_area, sc.mat_index, sc.materials, idx, pmf,
                                           hx, hy, hz, bounce,
                                           rand(key, bounce_dim(bounce, DIM_LIGHT_U)),
                                           rand(key, bounce_dim(bounce, DIM_LIGHT_V)))
            if pmf > 0.0 and lr + lg + lb > 0.0 and wix * ngx + wiy * ngy + wiz * ngz > 0.0:
                fr, fg, fb, bsdf_pdf = bsdf_eval(
                    sc.materials, m, wox, woy, woz, wix * tx + wiy * ty + wiz * tz,
                    wix * bx + wiy * by + wiz * bz, wix * nsx + wiy * nsy + wiz * nsz, exclude)
                w = power_heuristic(pdf_l, bsdf_pdf) if use_mis else 1.0
                cr = st.beta[i, 0] * fr * lr * w
                cg = st.beta[i, 1] * fg * lg * w
                cb = st.beta[i, 2] * fb * lb * w
                if cr + cg + cb > 0.0:
                    limit = fcfg[FCFG_CLAMP_DIRECT] if bounce == 0 else fcfg[FCFG_CLAMP_INDIRECT]
                    cr, cg, cb = clamp_light(cr, cg, cb, limit, stats)
                    if cast_shadow:
                        n_shadow = push_shadow(sq.o32, sq.d32, sq.t32, sq.contrib, sq.path, n_shadow, i,
                                               hx, hy, hz, ngx, ngy, ngz, wix, wiy, wiz, dist,
                                               lnx, lny, lnz, cr, cg, cb)
                    else:
                        st.radiance[i, 0] += cr
                        st.radiance[i, 1] += cg
                        st.radiance[i, 2] += cb

        # -- BSDF sampling: the next ray ---------------------------------------------------------
        wlx, wly, wlz, wr, wg, wb, pdf, label = bsdf_sample(
            sc.materials, m, wox, woy, woz, backfacing, rand(key, bounce_dim(bounce, DIM_BSDF_LOBE)),
            rand(key, bounce_dim(bounce, DIM_BSDF_U)), rand(key, bounce_dim(bounce, DIM_BSDF_V)))
        if (pdf <= 0.0 and not (label & LABEL_SINGULAR)) or wr + wg + wb <= 0.0:
            continue
        wix = wlx * tx + wly * bx + wlz * nsx
        wiy = wlx * ty + wly * by + wlz * nsy
        wiz = wlx * tz + wly * bz + wlz * nsz
        cos_i_geo = wix * ngx + wiy * ngy + wiz * ngz
        if (label & LABEL_REFLECT and cos_i_geo <= 0.0) or (label & LABEL_TRANSMIT and cos_i_geo >= 0.0):
            continue   # shading normal sent the ray through the wrong side of the surface
        st.beta[i, 0] *= wr
        st.beta[i, 1] *= wg
        st.beta[i, 2] *= wb

        # Bounce counting (Cycles' path_state_next): a limit reached here
        # lets the next vertex collect emission only.
        new_flags = next_path_flags(flags, label)
        st.bounce[i] = bounce + 1
        if bounce + 1 > cfg[CFG_MAX_BOUNCE]:
            new_flags |= PF_TERMINATE
        if label & LABEL_REFLECT:
            if label & LABEL_DIFFUSE:
                st.diffuse[i] += 1
                if st.diffuse[i] > cfg[CFG_MAX_DIFFUSE]:
                    new_flags |= PF_TERMINATE
            else:
                st.glossy[i] += 1
                if st.glossy[i] > cfg[CFG_MAX_GLOSSY]:
                    new_flags |= PF_TERMINATE
        else:
            st.transmission[i] += 1
            if st.transmission[i] > cfg[CFG_MAX_TRANSMISSION]:
                new_flags |= PF_TERMINATE
        st.flags[i] = new_flags
        st.mis_pdf[i] = pdf
        st.mis_p[i, 0], st.mis_p[i, 1], st.mis_p[i, 2] = hx, hy, hz
        nox, noy, noz = offset_origin(hx, hy, hz, ngx, ngy, ngz, wix, wiy, wiz)
        set_ray(st.ray_o, st.ray_d, st.ray_tmax, st.o32, st.d32, st.t32, i,
                nox, noy, noz, wix, wiy, wiz, math.inf)
        st.self_prim[i] = p
        st.alive[i] = 1
    return n_shadow


# -- 5. after the shadow rays ------------------------------------------------------------------
@kernel
def finish_bounce(n, n_shadow, occluded, st, sq, film_sum, film_sq, film_n):
    """Add unoccluded light, write finished paths to the film, compact the rest.

    Returns the number of live paths, now at the front of the state arrays.
    """
    for s in range(n_shadow):
        if not occluded[s]:
            i = sq.path[s]
            st.radiance[i, 0] += sq.contrib[s, 0]
            st.radiance[i, 1] += sq.contrib[s, 1]
            st.radiance[i, 2] += sq.contrib[s, 2]
    m = 0
    for i in range(n):
        if st.alive[i]:
            if m != i:
                _move(st, i, m)
            m += 1
        else:
            _splat(st, i, film_sum, film_sq, film_n)
    return m


@device
def _splat(st, i, film_sum, film_sq, film_n):
    pix = st.pixel[i]
    r, g, b = st.radiance[i, 0], st.radiance[i, 1], st.radiance[i, 2]
    film_sum[pix, 0] += r
    film_sum[pix, 1] += g
    film_sum[pix, 2] += b
    film_sum[pix, 3] += 1.0 - st.transparency[i]
    film_sq[pix, 0] += r * r
    film_sq[pix, 1] += g * g
    film_sq[pix, 2] += b * b
    film_n[pix] += 1


@device
def _move(st, i, m):
    st.key[m] = st.key[i]
    st.pixel[m] = st.pixel[i]
    for c in range(3):
        st.ray_o[m, c] = st.ray_o[i, c]
        st.ray_d[m, c] = st.ray_d[i, c]
        st.beta[m, c] = st.beta[i, c]
        st.radiance[m, c] = st.radiance[i, c]
        st.o32[m, c] = st.o32[i, c]
        st.d32[m, c] = st.d32[i, c]
        st.mis_p[m, c] = st.mis_p[i, c]
    st.ray_tmax[m] = st.ray_tmax[i]
    st.transparency[m] = st.transparency[i]
    st.bounce[m] = st.bounce[i]
    st.diffuse[m] = st.diffuse[i]
    st.glossy[m] = st.glossy[i]
    st.transmission[m] = st.transmission[i]
    st.transparent[m] = st.transparent[i]
    st.flags[m] = st.flags[i]
    st.mis_pdf[m] = st.mis_pdf[i]
    st.self_prim[m] = st.self_prim[i]
    st.t32[m] = st.t32[i]


@kernel
def splat_all(n, st, film_sum, film_sq, film_n):
    """Write all n paths to the film (end of a chunk)."""
    for i in range(n):
        _splat(st, i, film_sum, film_sq, film_n)


def trace_chunk(pixels, spp, accel, sc, cfg, fcfg, st, sq, film, stats):
    """Trace spp samples for each pixel in ``pixels`` to completion.

    ``film`` is ``(film_sum, film_sq, film_n)``.  A chunk always runs to the
    end (a fraction of a second): stopping paths half-way would keep the
    short paths and drop the long ones, a bias.  The loop ends when no path
    is alive; its bound guards against a path re-hitting its origin forever.
    """
    film_sum, film_sq, film_n = film
    n = generate_camera_rays(pixels, spp, film_n, st, sc, cfg)
    stats[ST_CAMERA_RAYS] += n
    max_iterations = 4 * (int(cfg[CFG_MAX_BOUNCE]) + int(cfg[CFG_MAX_TRANSPARENT]) + 4)
    first = True
    for _ in range(max_iterations):
        if n == 0:
            break
        if not first:
            stats[ST_BOUNCE_RAYS] += n
        first = False
        prim = accel.closest(st.o32[:n], st.d32[:n], st.t32[:n])
        n_shadow = shade(n, prim, st, sq, sc, cfg, fcfg, stats)
        if n_shadow:
            occluded = accel.occluded(sq.o32[:n_shadow], sq.d32[:n_shadow], sq.t32[:n_shadow])
            stats[ST_SHADOW_RAYS] += n_shadow
        else:
            occluded = np.zeros(0, np.bool_)
        n = finish_bounce(n, n_shadow, occluded, st, sq, film_sum, film_sq, film_n)
    splat_all(n, st, film_sum, film_sq, film_n)
