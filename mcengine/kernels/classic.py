"""The lecture's classic algorithms: ray casting, Whitted and distribution ray tracing.

They differ from path tracing in how rays branch at a surface hit:

* ``raycast``: the camera ray only; direct light from every light, no
  recursion.  Light reflected from other surfaces, the world's light on
  surfaces and everything seen in mirrors or through glass is missing: a
  biased, fast image;
* ``whitted``: direct light from every light, plus perfect mirror reflection
  and refraction rays (both at a glass surface, weighted by Fresnel) down to
  ``depth`` ray levels.  Diffuse surfaces do not spawn rays, so where every
  hit is glass the ray tree is binary: 2^depth - 1 rays per camera sample;
* ``distribution``: direct light from every light, plus ``branching`` (b)
  BSDF-sampled secondary rays at every hit, each carrying 1/b of the weight,
  down to ``depth`` ray levels: 1 + b + ... + b^(depth-1) rays per camera
  sample, the lecture's p * n * b^r.  Light found by secondary rays is
  combined with the light samples by multiple importance sampling; at the
  last level, where no rays follow, the light samples take full weight.
  Its expected value equals path tracing with depth - 1 bounces.

"Every light" means one sample on each lamp and one on the emissive
triangles as a group (picked by power).  The depth counts ray levels, the
camera ray being level 1, as in the lecture.

Random numbers are independent (``sampling.SAMPLER_INDEPENDENT``): a child ray's key
is a hash of its parent's, so no two rays of a tree share numbers.

Wavefront execution: each generation of rays is one Embree call; the
shading kernel writes the next generation into a second buffer.  A chunk
holds few enough camera samples that its widest generation fits the batch.
"""
from __future__ import annotations

import math

import numpy as np

from ..jit import by_ref, device, kernel
from .camera import generate_camera_rays
from .closures.layout import (
    CL_AX,
    CL_AY,
    CL_ETA,
    CL_N,
    CL_TYPE,
    CL_W,
    CT_MICROFACET,
    CT_MICROFACET_GLASS,
    CT_MICROFACET_REFRACTION,
    CT_TRANSPARENT,
    LABEL_RAY_PORTAL,
    LABEL_REFLECT,
    LABEL_SINGULAR,
    LABEL_TRANSMIT,
    ROUGHNESS_SQ_THRESHOLD,
)
from .closures.microfacet import microfacet_fresnel
from .intersect import offset_origin
from .light_sampling import PMF_EVERY, pick_light
from .lights import L_PMF
from .sampling import SAMPLER_INDEPENDENT, SET_BSDF, SET_LIGHT, mix64, sample_4d
from .shading import (
    direct_light,
    leaves_correct_side,
    light_from_background,
    light_from_emitter,
    light_from_lamps,
    next_path_flags,
    sample_direction,
    set_ray,
    shade_point,
)
from .shadows import trace_shadows
from .state import (
    CFG_LAMPS_HIT,
    CFG_LIGHTS,
    CFG_MAX_TRANSPARENT,
    FCFG_EMIT_SCALE,
    MF_EMISSIVE,
    PF_TERMINATE,
    ST_BOUNCE_RAYS,
    ST_CAMERA_RAYS,
    ST_SELF_HITS,
)
from .surface import hit_distance, past_self_hit, surface_point
from .svm import shader_scene
from .svm.nodes import K_GLASS, K_GLOSSY, K_METALLIC, K_PRINCIPLED, K_REFRACTION, K_TRANSPARENT

# Integer codes of the classic integrators in the kernels: ``IntegratorInfo.kernel_code``
# of mcengine.integrators (a test checks that they agree).
CODE_RAYCAST = 1
CODE_WHITTED = 2
CODE_DISTRIBUTION = 3
# Most Whitted rays one closure node can spawn at a hit (session sizes chunks with it):
# Principled: coat, metallic, specular mirror rays, glass reflection and refraction, alpha.
WHITTED_RAYS = {K_PRINCIPLED: 6, K_GLOSSY: 1, K_METALLIC: 1, K_GLASS: 2, K_REFRACTION: 1,
                K_TRANSPARENT: 1}
_K_CHILD = np.uint64(0xA24BAED4963EE407)
_K_LIGHT = np.uint64(0x9FB21C651E98DF25)
_NO_MASK = np.uint64(0)          # the independent sampler has no Sobol index to mask


@device
def _push_child(nx, n_next, st, i, key, sp, wix, wiy, wiz, br, bg, bb, flags, mis_pdf, p):
    """Write the next-generation node ``n_next`` from node i, its ray leaving
    the shading point ``sp`` along wi; returns n_next + 1."""
    nx.key[n_next] = key
    nx.pixel[n_next] = st.pixel[i]
    nx.root[n_next] = st.root[i]
    nx.time[n_next] = st.time[i]
    nx.beta[n_next, 0], nx.beta[n_next, 1], nx.beta[n_next, 2] = br, bg, bb
    nx.bounce[n_next] = st.bounce[i] + 1
    nx.transparent[n_next] = st.transparent[i]
    nx.flags[n_next] = flags
    nx.mis_pdf[n_next] = mis_pdf
    nx.mis_p[n_next, 0], nx.mis_p[n_next, 1], nx.mis_p[n_next, 2] = sp.hx, sp.hy, sp.hz
    nx.mis_p[n_next, 3] = nx.mis_p[n_next, 4] = nx.mis_p[n_next, 5] = 0.0   # every light: no pick
    nx.self_prim[n_next] = p
    ox, oy, oz = offset_origin(sp.hx, sp.hy, sp.hz, sp.ngx, sp.ngy, sp.ngz, wix, wiy, wiz)
    set_ray(nx.ray_o, nx.ray_d, nx.ray_tmax, nx.o32, nx.d32, nx.t32, n_next,
            ox, oy, oz, wix, wiy, wiz, math.inf)
    return n_next + 1


@device
def _copy_node(nx, n_next, st, i, advance):
    """Carry node i into the next generation, its ray moved ``advance`` forward."""
    nx.key[n_next] = st.key[i]
    nx.pixel[n_next] = st.pixel[i]
    nx.root[n_next] = st.root[i]
    nx.time[n_next] = st.time[i]
    for c in range(3):
        nx.beta[n_next, c] = st.beta[i, c]
    nx.bounce[n_next] = st.bounce[i]
    nx.transparent[n_next] = st.transparent[i]
    nx.flags[n_next] = st.flags[i]
    nx.mis_pdf[n_next] = st.mis_pdf[i]
    for c in range(6):
        nx.mis_p[n_next, c] = st.mis_p[i, c]
    nx.self_prim[n_next] = st.self_prim[i]
    nx.dp[n_next] = st.dp[i] + st.dd[i] * advance
    nx.dd[n_next] = st.dd[i]
    dx, dy, dz = st.ray_d[i, 0], st.ray_d[i, 1], st.ray_d[i, 2]
    set_ray(nx.ray_o, nx.ray_d, nx.ray_tmax, nx.o32, nx.d32, nx.t32, n_next,
            st.ray_o[i, 0] + advance * dx, st.ray_o[i, 1] + advance * dy,
            st.ray_o[i, 2] + advance * dz, dx, dy, dz, st.ray_tmax[i] - advance)
    return n_next + 1


@kernel
def shade_classic(start, end, prim, st, nx, n_next, sq, acc, sc, cfg, fcfg, scratch, stats,
                  code, depth, branching):
    """Shade nodes [start, end); children go to ``nx`` from ``n_next`` on.

    Returns ``(n_shadow, n_next)``.  Light is added to the per-camera-sample
    accumulators ``acc[root]`` (RGB and transparency); shadow rays name the
    root they belong to.
    """
    n_shadow = 0
    n_lamps = sc.lamps.shape[0]
    lamps_hit = cfg[CFG_LAMPS_HIT] != 0
    scene_ref = by_ref(shader_scene(sc))
    for i in range(start, end):
        p = prim[i]
        ox, oy, oz = st.ray_o[i, 0], st.ray_o[i, 1], st.ray_o[i, 2]
        dx, dy, dz = st.ray_d[i, 0], st.ray_d[i, 1], st.ray_d[i, 2]
        if p >= 0 and p == st.self_prim[i]:
            stats[ST_SELF_HITS] += 1
            n_next = _copy_node(nx, n_next, st, i,
                                past_self_hit(sc, p, ox, oy, oz, dx, dy, dz, st.time[i]))
            continue
        root = st.root[i]
        flags = st.flags[i]
        mis_pdf = st.mis_pdf[i]
        mp = (st.mis_p[i, 0], st.mis_p[i, 1], st.mis_p[i, 2], 0.0, 0.0, 0.0)
        bounce = st.bounce[i]
        br, bg, bb = st.beta[i, 0], st.beta[i, 1], st.beta[i, 2]
        t_hit, b1, b2 = hit_distance(sc, p, ox, oy, oz, dx, dy, dz, st.ray_tmax[i], st.time[i])
        direct = bounce <= 1

        if lamps_hit:
            passed = light_from_lamps(sc, cfg, fcfg, stats, acc, root, st.beta, i,
                                      ox, oy, oz, dx, dy, dz, t_hit, flags, mis_pdf, PMF_EVERY,
                                      mp, 0.0, st.transparent[i], direct, -1)
            if passed:
                st.transparent[i] += passed
                if st.transparent[i] >= cfg[CFG_MAX_TRANSPARENT]:
                    continue
        if p < 0:
            acc[root, 3] += light_from_background(sc, cfg, fcfg, scratch, stats, acc, root, st.beta, i,
                                                  dx, dy, dz, flags, mis_pdf, PMF_EVERY,
                                                  mp, 0.0, direct, -1)
            continue
        sp = surface_point(sc, p, b1, b2, dx, dy, dz, st.time[i])
        if sp.area <= 0.0:
            continue
        m = sc.mat_index[p]
        terminate = (flags & PF_TERMINATE) != 0
        if terminate and not (sc.mat_flags[m] & MF_EMISSIVE):
            continue   # a terminated path only collects emission, and there is none
        depths = (st.bounce[i], st.diffuse[i], st.glossy[i], st.transmission[i], st.transparent[i])
        # Ray differentials on camera rays only (Bump nodes leave later levels' normals alone).
        footprint = st.dp[i] + st.dd[i] * t_hit if bounce == 0 else 0.0
        res = shade_point(sc, scene_ref, cfg, scratch, sp, m, p, b1, b2, dx, dy, dz, t_hit, flags,
                          not terminate, depths, footprint)
        if res.er != 0.0 or res.eg != 0.0 or res.eb != 0.0:
            light_from_emitter(sc, fcfg, stats, acc, root, st.beta, i, p, t_hit, sp,
                               flags, mis_pdf, PMF_EVERY, mp, 0.0, direct,
                               res.er, res.eg, res.eb)
        if terminate or res.n == 0:
            continue
        cl, ncl = scratch.cl, res.n
        key = st.key[i]
        spawn = bounce + 2 <= depth          # the children's level is bounce + 2
        # Light samples share MIS with the BSDF rays only if BSDF rays follow.
        nee_mis = code == CODE_DISTRIBUTION and spawn

        # -- direct light from every light ------------------------------------------
        if cfg[CFG_LIGHTS]:
            n_emit = sc.emit_tri.shape[0]
            for li in range(n_lamps + (1 if n_emit else 0)):
                if li < n_lamps:
                    if sc.lamps[li, L_PMF] <= 0.0:
                        continue
                    idx = li
                    pmf = 1.0
                else:
                    _, _, u_pick, _ = sample_4d(SAMPLER_INDEPENDENT, key, SET_LIGHT, _NO_MASK)
                    j = pick_light(sc.emit_cdf, u_pick)
                    idx = n_lamps + j
                    pmf = sc.emit_pmf[j] * fcfg[FCFG_EMIT_SCALE]
                lkey = mix64(key ^ (np.uint64(li + 1) * _K_LIGHT))
                lu, lv, _, _ = sample_4d(SAMPLER_INDEPENDENT, lkey, SET_LIGHT, _NO_MASK)
                n_shadow = direct_light(sc, cfg, fcfg, stats, sq, n_shadow, acc, root, st.beta, i,
                                        scratch, ncl, sp, dx, dy, dz, idx, pmf, depths, lu, lv,
                                        nee_mis, float(branching),
                                        cfg[CFG_MAX_TRANSPARENT] - st.transparent[i])
        if not spawn:
            continue

        # -- secondary rays -------------------------------------------------------------
        if code == CODE_DISTRIBUTION:
            k = 1.0 / branching
            for c in range(branching):
                ckey = mix64(key ^ (np.uint64(c + 1) * _K_CHILD))
                bu, bv, u_lobe, bw = sample_4d(SAMPLER_INDEPENDENT, ckey, SET_BSDF, _NO_MASK)
                ds = sample_direction(cl, ncl, sp, dx, dy, dz, u_lobe, bu, bv, bw)
                if not ds.ok or ds.label & LABEL_RAY_PORTAL:
                    continue      # (no ray portals here: warned by the session)
                n_next = _push_child(nx, n_next, st, i, ckey, sp, ds.wix, ds.wiy, ds.wiz,
                                     br * ds.wr * k, bg * ds.wg * k, bb * ds.wb * k,
                                     next_path_flags(flags, ds.label), branching * ds.pdf, p)
        else:
            n_next = _whitted_children(cl, ncl, sp, dx, dy, dz, nx, n_next, st, i, key,
                                       br, bg, bb, flags, p)
    return n_shadow, n_next


@device
def _whitted_children(cl, ncl, sp, dx, dy, dz, nx, n_next, st, i, key, br, bg, bb, flags, p):
    """Whitted: every perfectly smooth closure spawns its mirror ray, and its refracted
    ray where it transmits, each weighted deterministically by its Fresnel terms;
    a transparent closure passes the ray on straight."""
    for k in range(ncl):
        t = cl[k, CL_TYPE]
        if t == CT_TRANSPARENT:
            ckey = mix64(key ^ (np.uint64(3 * k + 1) * _K_CHILD))
            n_next = _push_child(nx, n_next, st, i, ckey, sp, dx, dy, dz, br * cl[k, CL_W],
                                 bg * cl[k, CL_W + 1], bb * cl[k, CL_W + 2], flags, 0.0, p)
            continue
        if not (t == CT_MICROFACET or t == CT_MICROFACET_GLASS or t == CT_MICROFACET_REFRACTION):
            continue
        if cl[k, CL_AX] * cl[k, CL_AY] > ROUGHNESS_SQ_THRESHOLD:
            continue
        nx_, ny_, nz_ = cl[k, CL_N], cl[k, CL_N + 1], cl[k, CL_N + 2]
        cos_i = -(dx * nx_ + dy * ny_ + dz * nz_)
        if cos_i <= 0.0:
            continue
        rr, rg, rb, tr, tg, tb, cos_t = microfacet_fresnel(cl, k, cos_i)
        eta = cl[k, CL_ETA]
        for refract in range(2):
            if refract:
                wr_, wg_, wb_ = tr, tg, tb
                inv = 1.0 / eta
                a = inv * cos_i - cos_t     # Cycles' refract_angle (its cos_t is -ours)
                wix, wiy, wiz = dx * inv + a * nx_, dy * inv + a * ny_, dz * inv + a * nz_
                label = LABEL_TRANSMIT | LABEL_SINGULAR
            else:
                wr_, wg_, wb_ = rr, rg, rb
                wix, wiy, wiz = dx + 2.0 * cos_i * nx_, dy + 2.0 * cos_i * ny_, dz + 2.0 * cos_i * nz_
                label = LABEL_REFLECT | LABEL_SINGULAR
            if wr_ <= 0.0 and wg_ <= 0.0 and wb_ <= 0.0:
                continue
            if not leaves_correct_side(sp, wix, wiy, wiz, label):
                continue
            ckey = mix64(key ^ (np.uint64(3 * k + 2 + refract) * _K_CHILD))
            n_next = _push_child(nx, n_next, st, i, ckey, sp, wix, wiy, wiz,
                                 br * cl[k, CL_W] * wr_, bg * cl[k, CL_W + 1] * wg_,
                                 bb * cl[k, CL_W + 2] * wb_, next_path_flags(flags, label), 0.0, p)
    return n_next


@kernel
def add_unoccluded(n_shadow, occluded, sq, acc):
    for s in range(n_shadow):
        if not occluded[s]:
            r = sq.path[s]
            acc[r, 0] += sq.contrib[s, 0]
            acc[r, 1] += sq.contrib[s, 1]
            acc[r, 2] += sq.contrib[s, 2]


@kernel
def splat_roots(n, root_pixel, acc, film_sum, film_sq, film_n):
    for r in range(n):
        pix = root_pixel[r]
        cr, cg, cb = acc[r, 0], acc[r, 1], acc[r, 2]
        film_sum[pix, 0] += cr
        film_sum[pix, 1] += cg
        film_sum[pix, 2] += cb
        film_sum[pix, 3] += 1.0 - acc[r, 3]
        film_sq[pix, 0] += cr * cr
        film_sq[pix, 1] += cg * cg
        film_sq[pix, 2] += cb * cb
        film_n[pix] += 1


@kernel
def _start_roots(n, st, root_pixel, acc):
    for i in range(n):
        st.root[i] = i
        root_pixel[i] = st.pixel[i]
        acc[i, 0] = acc[i, 1] = acc[i, 2] = acc[i, 3] = 0.0


def trace_chunk_classic(pixels, spp, accel, sc, cfg, fcfg, buffers, film, stats,
                        code, depth, branching):
    """Trace spp camera samples for each pixel with a classic integrator.

    ``buffers`` = (state A, state B, shadow queue, acc (B, 4), root_pixel (B,)).
    The caller sizes the chunk so that its widest generation fits the states
    and at most ``shadow capacity / lights per hit`` nodes are shaded at once.
    """
    cur, nxt, sq, acc, root_pixel, scratch = buffers
    film_sum, film_sq, film_n = film
    n = generate_camera_rays(pixels, spp, film_n, cur, sc, cfg)
    n_roots = n
    _start_roots(n, cur, root_pixel, acc)
    stats[ST_CAMERA_RAYS] += n
    lights_per_hit = sc.lamps.shape[0] + 1
    slice_nodes = max(1, sq.path.shape[0] // lights_per_hit)
    first = True
    for _ in range(4 * (depth + int(cfg[CFG_MAX_TRANSPARENT])) + 8):
        if n == 0:
            break
        if not first:
            stats[ST_BOUNCE_RAYS] += n
        first = False
        prim = accel.closest(cur.o32[:n], cur.d32[:n], cur.t32[:n], cur.time[:n])
        n_next = 0
        for start in range(0, n, slice_nodes):
            end = min(n, start + slice_nodes)
            n_shadow, n_next = shade_classic(start, end, prim, cur, nxt, n_next, sq, acc, sc, cfg,
                                             fcfg, scratch, stats, code, depth, branching)
            if n_shadow:
                add_unoccluded(n_shadow, trace_shadows(n_shadow, accel, sq, sc, cfg, scratch, stats),
                               sq, acc)
        cur, nxt = nxt, cur
        n = n_next
    splat_roots(n_roots, root_pixel, acc, film_sum, film_sq, film_n)
