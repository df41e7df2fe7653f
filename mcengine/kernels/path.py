"""Path tracing, wavefront style: the integrator that matches Cycles.

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
from the third vertex on, film transparency.  The steps shared with the
classic integrators are in ``shading``.

Stages are scalar loops compiled by numba (``nogil``), so two workers in two
Python threads keep both cores busy; Embree releases the GIL as well.
"""
from __future__ import annotations

import math

import numpy as np

from ..jit import by_ref, device, function, kernel
from .camera import generate_camera_rays
from .closures.layout import (
    CL_ANISOTROPY,
    CL_AX,
    CL_AY,
    CL_BUMP_CORRECTION,
    CL_ENERGY,
    CL_N,
    CL_NS,
    CL_PORTAL_P,
    CL_RADIUS,
    CL_SSS_ALBEDO,
    CL_SSS_METHOD,
    CL_STRIDE,
    CL_SW,
    CL_TERMINATOR,
    CL_TYPE,
    CL_W,
    CT_ASHIKHMIN_SHIRLEY,
    CT_BSSRDF,
    CT_DIFFUSE,
    CT_MICROFACET,
    CT_MICROFACET_GLASS,
    CT_MICROFACET_REFRACTION,
    CT_TRANSPARENT,
    LABEL_DIFFUSE,
    LABEL_RAY_PORTAL,
    LABEL_REFLECT,
    LABEL_SINGULAR,
    LABEL_SUBSURFACE,
    LABEL_TRANSPARENT,
    SSS_BURLEY,
)
from .intersect import offset_origin, offset_scale, ray_masks
from .light_sampling import (
    PMF_GLOBAL,
    PMF_LOCAL,
    emitter_lights,
    light_links,
    local_light_total,
    pick_emitter,
    pick_light,
    pick_light_local,
    receiver,
    receiver_set,
)
from .passes import (
    LK_BACKGROUND,
    LK_SURFACE,
    P_AO,
    PC_DATA,
    PC_DENOISE,
    PC_LIGHT,
    PC_SPLIT,
    ao_pass,
    background_passes,
    light_pass,
    queue_ao_ray,
    shadow_pass,
    singular_weights,
    split_eval,
    split_light,
    surface_passes,
)
from .sampling import (
    SET_AO,
    SET_BSDF,
    SET_LIGHT,
    SET_TERMINATE,
    bounce_set,
    exit_key,
    node_key,
    sample_1d,
    sample_2d,
    sample_4d,
    walk_key,
)
from .shading import (
    direct_light,
    light_from_emitter,
    light_from_lamps,
    light_from_suns,
    light_from_world,
    next_path_flags,
    sample_direction,
    set_ray,
    shade_point,
    shader_normal,
)
from .shadows import trace_shadows
from .state import (
    CFG_CAUSTICS,
    CFG_LAMPS_HIT,
    CFG_LIGHT_LINKING,
    CFG_LIGHT_TRACING,
    CFG_LIGHTS,
    CFG_LOCAL_LIGHTS,
    CFG_MAX_BOUNCE,
    CFG_MAX_DIFFUSE,
    CFG_MAX_GLOSSY,
    CFG_MAX_TRANSMISSION,
    CFG_MAX_TRANSPARENT,
    CFG_MIN_LIGHT_BOUNCES,
    CFG_MIS,
    CFG_SAMPLER,
    CFG_SOBOL_MASK,
    CFG_SUBSURFACE,
    FCFG_FILTER_GLOSSY,
    FCFG_WORLD_IMPORTANCE,
    MF_BSSRDF_BUMP,
    MF_BUMP_CORRECTION,
    MF_EMISSIVE,
    PF_CAMERA,
    PF_CAUSTIC_EYE,
    PF_DENOISE,
    PF_MIS_SKIP,
    PF_SUBSURFACE,
    PF_SURFACE_PASS,
    PF_TERMINATE,
    PF_TRANSPARENT,
    PF_TRANSPARENT_BG,
    SK_AO,
    SK_DIRECT,
    SK_INDIRECT,
    ST_BOUNCE_RAYS,
    ST_CAMERA_RAYS,
    ST_SELF_HITS,
    compact_paths,
)
from .subsurface import disk_probe, random_walk
from .surface import hit_distance, past_self_hit, surface_point
from .svm import OBJ_HOLDOUT, OBJ_TERMINATOR_SHADING, shader_scene


# -- 3. shading ---------------------------------------------------------------------------------
@device
def _keep_transparent(cl, n):
    """Drop every closure but the transparent one (at most one: closures merge them);
    returns the new count."""
    for k in range(n):
        if cl[k, CL_TYPE] == CT_TRANSPARENT:
            if k > 0:
                for c in range(cl.shape[1]):
                    cl[0, c] = cl[k, c]
            return 1
    return 0


@kernel
def shade(n, prim, st, sq, sc, cfg, fcfg, scratch, stats, pd, pb, fp):
    """Shade the hits of the n live paths; returns the number of queued shadow rays.

    ``pd``, ``pb`` and ``fp`` are the render passes' settings, buffers and film
    (``kernels.passes``); light that goes to Combined is handed to the light
    passes right after it is added.
    """
    n_shadow = 0
    light_passes = pd.cfg[PC_LIGHT] != 0
    split = pd.cfg[PC_SPLIT] != 0     # light split into diffuse/glossy/transmission
    surface_pass_work = pd.cfg[PC_DATA] != 0 or pd.cfg[PC_DENOISE] != 0
    ao = pd.cfg[P_AO] >= 0
    r0 = g0 = b0 = 0.0
    queued = 0
    n_lamps = sc.lamps.shape[0]
    lamps_hit = cfg[CFG_LAMPS_HIT] != 0
    mis = cfg[CFG_MIS] != 0
    caustics = cfg[CFG_CAUSTICS] != 0
    light_tracing = cfg[CFG_LIGHT_TRACING] != 0
    nee = cfg[CFG_LIGHTS] != 0 and sc.light_cdf.shape[0] > 1
    local = cfg[CFG_LOCAL_LIGHTS] != 0
    pmf_mode = PMF_LOCAL if local else PMF_GLOBAL
    has_group = sc.emit_tri.shape[0] > 0
    world_light = n_lamps + sc.emit_tri.shape[0]      # NEE's index of the world
    world_importance = fcfg[FCFG_WORLD_IMPORTANCE]
    max_transparent = cfg[CFG_MAX_TRANSPARENT]
    sampler, mask = cfg[CFG_SAMPLER], np.uint64(cfg[CFG_SOBOL_MASK])
    walks = cfg[CFG_SUBSURFACE] != 0
    linking = cfg[CFG_LIGHT_LINKING] != 0
    scene_ref = by_ref(shader_scene(sc))     # the shader evaluator's (svm.eval_shader)
    for i in range(n):
        st.alive[i] = 0
        p = prim[i]
        ox, oy, oz = st.ray_o[i, 0], st.ray_o[i, 1], st.ray_o[i, 2]
        dx, dy, dz = st.ray_d[i, 0], st.ray_d[i, 1], st.ray_d[i, 2]
        flags = st.flags[i]
        # Where a subsurface walk left its object: that triangle, whatever the ray met.
        exit_walk = (flags & PF_SUBSURFACE) != 0
        if exit_walk:
            p = st.self_prim[i]
        elif p >= 0 and p == st.self_prim[i]:
            stats[ST_SELF_HITS] += 1
            s = past_self_hit(sc, p, ox, oy, oz, dx, dy, dz, st.time[i])
            set_ray(st.ray_o, st.ray_d, st.ray_tmax, st.o32, st.d32, st.t32, i,
                    ox + s * dx, oy + s * dy, oz + s * dz, dx, dy, dz, st.ray_tmax[i] - s)
            st.alive[i] = 1
            continue
        mis_pdf = st.mis_pdf[i]
        t_hit, b1, b2 = hit_distance(sc, p, ox, oy, oz, dx, dy, dz, st.ray_tmax[i], st.time[i])
        direct = st.bounce[i] <= 1   # clamp index (bounce - 1) <= 0
        # Light-picking probabilities at the vertex this ray left, for MIS.
        mp = (st.mis_p[i, 0], st.mis_p[i, 1], st.mis_p[i, 2],
              st.mis_p[i, 3], st.mis_p[i, 4], st.mis_p[i, 5])
        # Light linking: lights found by the ray count if they light the receiver it left
        # (camera rays, also through transparent surfaces, see every light).
        ray_set = st.mis_set[i] if linking and not (flags & PF_CAMERA) else -1
        mis_total = st.mis_total[i] if local and mis and not (flags & PF_MIS_SKIP) else 0.0

        # -- light arriving along the ray ------------------------------------------------------
        if lamps_hit and not exit_walk:
            if light_passes:
                r0, g0, b0 = st.radiance[i, 0], st.radiance[i, 1], st.radiance[i, 2]
            passed = light_from_lamps(sc, cfg, fcfg, stats, st.radiance, i, st.beta, i,
                                      ox, oy, oz, dx, dy, dz, t_hit, flags, mis_pdf, pmf_mode,
                                      mp, mis_total, st.transparent[i], direct, ray_set)
            if passed:
                if light_passes:
                    _pass_light(pd, fp, st, pb, i, r0, g0, b0, LK_SURFACE)
                st.transparent[i] += passed
                if st.transparent[i] >= max_transparent:
                    continue   # Cycles: the path ends after the lamp's light
        if p < 0:
            if light_passes:
                r0, g0, b0 = st.radiance[i, 0], st.radiance[i, 1], st.radiance[i, 2]
            st.transparency[i] += light_from_world(sc, cfg, fcfg, scratch, stats, st.radiance, i,
                                                   st.beta, i, dx, dy, dz, flags, mis_pdf,
                                                   pmf_mode, mis_total, direct)
            if light_passes:
                _pass_light(pd, fp, st, pb, i, r0, g0, b0, LK_BACKGROUND)
                r0, g0, b0 = st.radiance[i, 0], st.radiance[i, 1], st.radiance[i, 2]
            light_from_suns(sc, cfg, fcfg, stats, st.radiance, i, st.beta, i, dx, dy, dz, flags,
                            mis_pdf, pmf_mode, mp, mis_total, direct, ray_set)
            if light_passes:
                _pass_light(pd, fp, st, pb, i, r0, g0, b0, LK_SURFACE)
            background_passes(pd, fp, st.pixel[i], flags)
            continue
        sp = surface_point(sc, p, b1, b2, dx, dy, dz, st.time[i])
        if sp.area <= 0.0:
            continue   # degenerate triangle: Embree should not report it; drop the path
        m = sc.mat_index[p]
        terminate = (flags & PF_TERMINATE) != 0
        if terminate and not (sc.mat_flags[m] & MF_EMISSIVE):
            continue   # a terminated path only collects emission, and there is none
        # The ray's length from the vertex it left (transparent surfaces may lie between):
        # Light Path's Ray Length and the emission's MIS distance.
        hx, hy, hz = sp.hx - mp[0], sp.hy - mp[1], sp.hz - mp[2]
        ray_length = math.sqrt(hx * hx + hy * hy + hz * hz)
        depths = (st.bounce[i], st.diffuse[i], st.glossy[i], st.transmission[i], st.transparent[i])
        footprint = st.dp[i] + st.dd[i] * ray_length     # Cycles' differential_transfer_compact
        bounce = st.bounce[i]
        vertex = bounce + st.transparent[i]      # random-number dimensions of this vertex
        if exit_walk:
            # A walk's exit: one Lambert closure, no emission, holdout, Russian roulette or
            # data passes (Cycles shades it so); the path keeps its bounce counts.
            ncl = _exit_closure(sc, cfg, scratch, sp, m, p, b1, b2, dx, dy, dz, ray_length,
                                flags, depths, footprint)
            flags &= ~PF_SUBSURFACE
            st.flags[i] = flags
            rtr = rtg = rtb = 0.0
        else:
            res = shade_point(sc, scene_ref, cfg, scratch, sp, m, p, b1, b2, dx, dy, dz,
                              ray_length, flags, not terminate, depths, footprint, walks,
                              node_key(st.key[i], vertex), st.min_pdf[i])
            ncl, rtr, rtg, rtb = res.n, res.tr, res.tg, res.tb

            # Holdout: the film's alpha drops by the holdout weight on camera paths. A holdout
            # object's weight is its opacity, 1 - transparency; only its transparent closure
            # stays, without emission (Cycles' surface_shader_apply_holdout).
            emits = res.er != 0.0 or res.eg != 0.0 or res.eb != 0.0
            if flags & PF_TRANSPARENT_BG:
                if sc.tex.objects[sc.tex.tri_object[p], OBJ_HOLDOUT] > 0.0:
                    ncl = _keep_transparent(scratch.cl, ncl)
                    emits = False
                    hr, hg, hb = max(1.0 - rtr, 0.0), max(1.0 - rtg, 0.0), max(1.0 - rtb, 0.0)
                else:
                    hr = hg = hb = res.holdout
                if hr > 0.0 or hg > 0.0 or hb > 0.0:
                    st.transparency[i] += (hr * st.beta[i, 0] + hg * st.beta[i, 1]
                                           + hb * st.beta[i, 2]) / 3.0
                    if hr >= 1.0 and hg >= 1.0 and hb >= 1.0:
                        continue
            # Emission (two-sided), if it lights the receiver the ray left.
            if emits and emitter_lights(sc, p, ray_set):
                if light_passes:
                    r0, g0, b0 = st.radiance[i, 0], st.radiance[i, 1], st.radiance[i, 2]
                light_from_emitter(sc, fcfg, stats, st.radiance, i, st.beta, i, p,
                                   ray_length, sp, flags, mis_pdf, pmf_mode, mp,
                                   mis_total, direct, res.er, res.eg, res.eb)
                if light_passes:
                    _pass_light(pd, fp, st, pb, i, r0, g0, b0, LK_SURFACE)
            if terminate or ncl == 0:
                continue
            if caustics and fcfg[FCFG_FILTER_GLOSSY] > 0.0:
                blur_closures(scratch.cl, ncl, fcfg[FCFG_FILTER_GLOSSY] * st.min_pdf[i])

            # Russian roulette (Cycles: from the third vertex on, with the
            # throughput as it is; emission here is not affected by it).
            if bounce > cfg[CFG_MIN_LIGHT_BOUNCES] + 1:
                q = min(math.sqrt(max(abs(st.beta[i, 0]), abs(st.beta[i, 1]), abs(st.beta[i, 2]))),
                        1.0)
                if q < 1.0:
                    if sample_1d(sampler, st.key[i], bounce_set(vertex, SET_TERMINATE), mask) >= q:
                        continue
                    st.beta[i, 0] /= q
                    st.beta[i, 1] /= q
                    st.beta[i, 2] /= q

            # -- render passes written at the surface (data passes, denoising features) --------
            if surface_pass_work:
                flags = surface_passes(pd, fp, st.pixel[i], flags, sp.hx, sp.hy, sp.hz, sp.nsx,
                                       sp.nsy, sp.nsz, t_hit, p, b1, b2, m, scratch.cl, ncl,
                                       st.beta[i, 0], st.beta[i, 1], st.beta[i, 2], rtr, rtg, rtb,
                                       -dx, -dy, -dz, pb, i)
                st.flags[i] = flags
        key = st.key[i]
        if ao and (flags & PF_CAMERA):
            au, av = sample_2d(sampler, key, bounce_set(vertex, SET_AO), mask)
            n_shadow = queue_ao_ray(pd, sc, scratch, sq, n_shadow, i, ncl, sp, st.beta[i, 0],
                                    st.beta[i, 1], st.beta[i, 2], rtr, rtg, rtb, au, av,
                                    depths, max_transparent - st.transparent[i])

        # -- next-event estimation: one light --------------------------------------------------
        # Where lights are picked (the point and, on opaque surfaces, its normal: Cycles' sd->N,
        # which a displacement bump has moved); the next ray keeps it for the MIS weights of
        # the light it finds.
        recv = (sp.hx, sp.hy, sp.hz, 0.0, 0.0, 0.0)
        recv_set = receiver_set(sc, p) if linking else -1     # light linking: its light set
        total = 0.0       # the lights' summed importance here: this pick's, the next MIS's
        if local:
            rnx, rny, rnz = shader_normal(sc, scratch.regs, sp)
            recv = receiver(sp.hx, sp.hy, sp.hz, rnx, rny, rnz, scratch.cl, ncl)
            if nee or mis:
                total = local_light_total(sc.lamps, sc.emit_group, has_group, world_importance,
                                          recv, scratch.importance)
        if nee:
            lu, lv, u_pick, u_group = sample_4d(sampler, key, bounce_set(vertex, SET_LIGHT), mask)
            if local:
                idx, pmf = pick_light_local(n_lamps, sc.emit_group, has_group, world_importance,
                                            recv, total, scratch.importance, u_pick)
                if idx == n_lamps + 1:
                    idx = world_light
                elif idx == n_lamps:
                    j, q = pick_emitter(sc, fcfg, recv, u_group)
                    idx = n_lamps + max(j, 0)       # j = -1 comes with q = 0: no light
                    pmf *= q
            else:
                idx = pick_light(sc.light_cdf, u_pick)
                pmf = sc.light_cdf[idx + 1] - sc.light_cdf[idx]
            if linking and not light_links(sc, idx, recv_set):
                pmf = 0.0        # the light does not light this object: no sample (Cycles)
            if split:
                r0, g0, b0 = st.radiance[i, 0], st.radiance[i, 1], st.radiance[i, 2]
                queued = n_shadow
            n_shadow = direct_light(sc, cfg, fcfg, stats, sq, n_shadow, st.radiance, i, st.beta, i,
                                    scratch, ncl, sp, dx, dy, dz, idx, pmf, depths, lu, lv,
                                    True, 1.0, max_transparent - st.transparent[i])
            if split:
                _nee_passes(pd, fp, st, sq, pb, i, scratch, ncl, -dx, -dy, -dz, bounce, flags,
                            queued, n_shadow, r0, g0, b0)

        # -- BSDF sampling: the next ray ---------------------------------------------------------
        bu, bv, u_lobe, bw = sample_4d(sampler, key, bounce_set(vertex, SET_BSDF), mask)
        ds = sample_direction(scratch.cl, ncl, sp, dx, dy, dz, u_lobe, bu, bv, bw)
        if not ds.ok:
            continue
        st.beta[i, 0] *= ds.wr
        st.beta[i, 1] *= ds.wg
        st.beta[i, 2] *= ds.wb
        if ds.label & LABEL_SUBSURFACE:
            # Into the object: walk to where the light leaves it (Cycles' subsurface_bounce
            # and subsurface_scatter; no bounce is counted).
            if split and bounce == 0:
                pb.pw[i, 0] = pb.pw[i, 1] = pb.pw[i, 2] = 1.0
                pb.pw[i, 3] = pb.pw[i, 4] = pb.pw[i, 5] = 0.0
            if _walk(sc, st, i, scratch.cl, ds.pick, p, sp, ds.wix, ds.wiy, ds.wiz, vertex,
                     sampler, mask):
                st.alive[i] = 1
            continue
        if ds.label & LABEL_RAY_PORTAL:
            # On from the portal's point (Cycles' integrate_surface_ray_portal): a transparent
            # bounce that keeps the path's flags; light the new ray finds is not weighted by
            # MIS (no light sample can pass a portal), its length counts from that point.
            st.transparent[i] += 1
            flags |= PF_TRANSPARENT | PF_MIS_SKIP
            if st.transparent[i] >= max_transparent:
                flags |= PF_TERMINATE
            st.flags[i] = flags
            k = ds.pick
            qx, qy, qz = scratch.cl[k, CL_PORTAL_P], scratch.cl[k, CL_PORTAL_P + 1], scratch.cl[k, CL_PORTAL_P + 2]
            ex, ey, ez = qx - sp.hx, qy - sp.hy, qz - sp.hz
            if ex * ex + ey * ey + ez * ez > 1e-9:
                st.self_prim[i] = -1           # elsewhere: it may meet this triangle again
            else:
                qx, qy, qz = offset_origin(sp.hx, sp.hy, sp.hz, sp.ngx, sp.ngy, sp.ngz,
                                           ds.wix, ds.wiy, ds.wiz)
                st.self_prim[i] = p
            st.mis_p[i, 0], st.mis_p[i, 1], st.mis_p[i, 2] = qx, qy, qz
            st.dp[i] = footprint
            set_ray(st.ray_o, st.ray_d, st.ray_tmax, st.o32, st.d32, st.t32, i,
                    qx, qy, qz, ds.wix, ds.wiy, ds.wiz, math.inf)
            st.alive[i] = 1
            continue
        if ds.label & LABEL_TRANSPARENT:
            # Straight through: a transparent bounce, the path keeps its flags and MIS data.
            st.transparent[i] += 1
            flags |= PF_TRANSPARENT
            if st.transparent[i] >= max_transparent:
                flags |= PF_TERMINATE
            st.flags[i] = flags
        else:
            if split and bounce == 0:
                _first_bounce_weights(pb, i, scratch.cl, ncl, -dx, -dy, -dz, ds)
            new_flags = next_path_flags(flags, ds.label) | PF_SURFACE_PASS
            if light_tracing and (flags & PF_CAMERA) and not (flags & PF_TRANSPARENT) \
                    and not (ds.label & LABEL_SINGULAR):
                new_flags |= PF_CAUSTIC_EYE     # x1 can be joined to the camera (light_tracing)
            st.flags[i] = count_bounce(st, i, cfg, new_flags, ds.label)
            st.mis_pdf[i] = ds.pdf
            for c in range(6):
                st.mis_p[i, c] = recv[c]
            st.mis_total[i] = total
            if linking:
                st.mis_set[i] = recv_set
            st.dp[i] = footprint     # Cycles keeps the camera's dD at every bounce
            if ds.pdf > 0.0:
                st.min_pdf[i] = min(st.min_pdf[i], ds.pdf)
        nox, noy, noz = offset_origin(sp.hx, sp.hy, sp.hz, sp.ngx, sp.ngy, sp.ngz,
                                      ds.wix, ds.wiy, ds.wiz)
        set_ray(st.ray_o, st.ray_d, st.ray_tmax, st.o32, st.d32, st.t32, i,
                nox, noy, noz, ds.wix, ds.wiy, ds.wiz, math.inf)
        st.self_prim[i] = p
        st.alive[i] = 1
    return n_shadow


@function
def _walk(sc, st, i, cl, k, p, sp, wix, wiy, wiz, vertex, sampler, mask):
    """Take path i from ``sp`` on triangle p to where BSSRDF closure k lets the light out of
    the object: a random walk along wi, or Christensen-Burley's disk probe; returns whether
    it found an exit.  Then its ray comes from outside to the exit triangle (the next
    ``shade`` shades the exit there, ``PF_SUBSURFACE``) and its key changes, so the exit
    draws other numbers than the entry (``sampling.exit_key``)."""
    obj = sc.tex.tri_object[p]
    if obj >= sc.local.root.shape[0]:
        return False
    wkey = walk_key(st.key[i], vertex)
    if cl[k, CL_SSS_METHOD] == SSS_BURLEY:
        left, q, ex, ey, ez, gx, gy, gz, wr, wg, wb = disk_probe(
            sc.local, sc.verts, sc.tris, sc.tex.normals, sc.tex.normal_index, obj, sampler, wkey, mask,
            sp.hx, sp.hy, sp.hz, sp.ngx, sp.ngy, sp.ngz, sp.backfacing, cl[k, CL_RADIUS], cl[k, CL_RADIUS + 1],
            cl[k, CL_RADIUS + 2])
        if not left:
            return False
        tr, tg, tb = st.beta[i, 0] * wr, st.beta[i, 1] * wg, st.beta[i, 2] * wb
        ddx, ddy, ddz, t = gx, gy, gz, 0.5     # the exit faces its normal
    else:
        left, q, ex, ey, ez, ddx, ddy, ddz, t, tr, tg, tb = random_walk(
            sc.local, sc.verts, sc.tris, obj, sampler, wkey, mask, sp.hx, sp.hy, sp.hz, wix, wiy, wiz,
            sp.nsx, sp.nsy, sp.nsz, p, cl[k, CL_SSS_ALBEDO], cl[k, CL_SSS_ALBEDO + 1],
            cl[k, CL_SSS_ALBEDO + 2], cl[k, CL_RADIUS], cl[k, CL_RADIUS + 1],
            cl[k, CL_RADIUS + 2], cl[k, CL_ANISOTROPY], st.beta[i, 0], st.beta[i, 1],
            st.beta[i, 2])
        if not left:
            return False
    st.beta[i, 0], st.beta[i, 1], st.beta[i, 2] = tr, tg, tb
    # Cycles' trick for the exit's normals: a ray from outside, twice the last step away
    # (the walk arrived along dd; the disk's exit faces its normal).
    s = max(2.0 * t, offset_scale(ex, ey, ez))
    set_ray(st.ray_o, st.ray_d, st.ray_tmax, st.o32, st.d32, st.t32, i,
            ex + s * ddx, ey + s * ddy, ez + s * ddz, -ddx, -ddy, -ddz, s)
    st.self_prim[i] = q
    st.key[i] = exit_key(st.key[i], vertex)
    st.flags[i] = (st.flags[i] & ~PF_CAMERA) | PF_SUBSURFACE
    return True


@function
def _exit_closure(sc, cfg, scratch, sp, m, p, b1, b2, dx, dy, dz, ray_length, flags, depths,
                  footprint):
    """The closure list at a walk's exit (Cycles' subsurface_shader_data_setup): one Lambert
    closure of weight 1 about the smooth normal, or, when a BSSRDF of the material there
    takes a linked Normal input (MF_BSSRDF_BUMP, Cycles' SD_HAS_BSSRDF_BUMP), about its
    BSSRDFs' normals averaged by weight: the material's shader runs only then.
    Returns the count, 1."""
    cl = scratch.cl
    nx, ny, nz = sp.nsx, sp.nsy, sp.nsz
    if sc.mat_flags[m] & MF_BSSRDF_BUMP:
        res = shade_point(sc, by_ref(shader_scene(sc)), cfg, scratch, sp, m, p, b1, b2, dx, dy,
                          dz, ray_length, flags, True, depths, footprint, True)
        ax = ay = az = 0.0
        for k in range(res.n):
            if cl[k, CL_TYPE] == CT_BSSRDF:
                w = abs(cl[k, CL_W] + cl[k, CL_W + 1] + cl[k, CL_W + 2]) / 3.0
                ax += cl[k, CL_N] * w
                ay += cl[k, CL_N + 1] * w
                az += cl[k, CL_N + 2] * w
        length = math.sqrt(ax * ax + ay * ay + az * az)
        if length > 0.0:
            nx, ny, nz = ax / length, ay / length, az / length
    for c in range(CL_STRIDE):
        cl[0, c] = 0.0
    cl[0, CL_TYPE] = CT_DIFFUSE
    cl[0, CL_W] = cl[0, CL_W + 1] = cl[0, CL_W + 2] = cl[0, CL_SW] = cl[0, CL_ENERGY] = 1.0
    cl[0, CL_N], cl[0, CL_N + 1], cl[0, CL_N + 2] = nx, ny, nz
    cl[0, CL_NS], cl[0, CL_NS + 1], cl[0, CL_NS + 2] = sp.nsx, sp.nsy, sp.nsz
    cl[0, CL_BUMP_CORRECTION] = 1.0 if sc.mat_flags[m] & MF_BUMP_CORRECTION else 0.0
    frequency = sc.tex.objects[sc.tex.tri_object[p], OBJ_TERMINATOR_SHADING]
    if frequency > 1.0:
        cl[0, CL_TERMINATOR] = frequency
    return 1


@device
def _pass_light(pd, fp, st, pb, i, r0, g0, b0, kind):
    """Hand the light path i added to Combined since its radiance was (r0, g0, b0) to the
    light passes."""
    r, g, b = st.radiance[i, 0] - r0, st.radiance[i, 1] - g0, st.radiance[i, 2] - b0
    if r != 0.0 or g != 0.0 or b != 0.0:
        light_pass(pd, fp, st.pixel[i], st.flags[i], st.bounce[i], pb, i, r, g, b, kind)


@device
def _nee_passes(pd, fp, st, sq, pb, i, scratch, ncl, wox, woy, woz, bounce, flags, queued,
                n_shadow, r0, g0, b0):
    """Pass weights of the light sample just taken at path i: the BSDF's own at the first
    bounce (Cycles: direct light), else those of the first bounce.  Given to its shadow ray,
    or used at once for a light that casts no shadow."""
    if flags & PF_SURFACE_PASS:
        w0, w1, w2, w3, w4, w5 = pb.pw[i, 0], pb.pw[i, 1], pb.pw[i, 2], pb.pw[i, 3], pb.pw[i, 4], \
            pb.pw[i, 5]
    else:
        last = scratch.light
        w0, w1, w2, w3, w4, w5 = split_eval(scratch.cl, ncl, wox, woy, woz, last[0], last[1],
                                            last[2], int(last[3]), -1, 0.0, 0.0, 0.0)
    if n_shadow > queued:
        s = n_shadow - 1
        pb.sw[s, 0], pb.sw[s, 1], pb.sw[s, 2] = w0, w1, w2
        pb.sw[s, 3], pb.sw[s, 4], pb.sw[s, 5] = w3, w4, w5
        sq.kind[s] = SK_DIRECT if bounce == 0 else SK_INDIRECT
        return
    r, g, b = st.radiance[i, 0] - r0, st.radiance[i, 1] - g0, st.radiance[i, 2] - b0
    if r != 0.0 or g != 0.0 or b != 0.0:
        split_light(pd, fp, st.pixel[i], bounce == 0, w0, w1, w2, w3, w4, w5, r, g, b)


@device
def _first_bounce_weights(pb, i, cl, ncl, wox, woy, woz, ds):
    """Pass weights of path i's first scattering event (Cycles' pass_diffuse_weight and
    pass_glossy_weight): the shares of the BSDF's value in the sampled direction."""
    if ds.label & LABEL_SINGULAR:
        w0, w1, w2, w3, w4, w5 = singular_weights(ds.label)
    else:
        w0, w1, w2, w3, w4, w5 = split_eval(cl, ncl, wox, woy, woz, ds.wix, ds.wiy, ds.wiz, 0,
                                            ds.pick, ds.wr * ds.pdf, ds.wg * ds.pdf,
                                            ds.wb * ds.pdf)
    pb.pw[i, 0], pb.pw[i, 1], pb.pw[i, 2] = w0, w1, w2
    pb.pw[i, 3], pb.pw[i, 4], pb.pw[i, 5] = w3, w4, w5


@kernel
def start_denoising_features(n, st, pb):
    """New camera paths look for their denoising albedo and normal."""
    for i in range(n):
        st.flags[i] |= PF_DENOISE
        pb.dn[i, 0] = pb.dn[i, 1] = pb.dn[i, 2] = 1.0


@device
def blur_closures(cl, ncl, blur_pdf):
    """Cycles' Filter Glossy: after unlikely bounces (smallest pdf on the path x
    blur_glossy below 1), microfacet alphas grow to at least sqrt(1 - p) / 2."""
    if blur_pdf >= 1.0:
        return
    r = math.sqrt(1.0 - blur_pdf) * 0.5
    for k in range(ncl):
        t = cl[k, CL_TYPE]
        if t == CT_MICROFACET or t == CT_MICROFACET_REFRACTION or t == CT_MICROFACET_GLASS \
                or t == CT_ASHIKHMIN_SHIRLEY:
            cl[k, CL_AX] = max(cl[k, CL_AX], r)
            cl[k, CL_AY] = max(cl[k, CL_AY], r)


@device
def count_bounce(st, i, cfg, flags, label):
    """Count a scattering event of lobe ``label`` on path i (Cycles' path_state_next).

    Returns ``flags`` with PF_TERMINATE added when a limit is passed: the next
    vertex then collects emission only.
    """
    st.bounce[i] += 1
    if st.bounce[i] > cfg[CFG_MAX_BOUNCE]:
        flags |= PF_TERMINATE
    if label & LABEL_REFLECT:
        if label & LABEL_DIFFUSE:
            st.diffuse[i] += 1
            if st.diffuse[i] > cfg[CFG_MAX_DIFFUSE]:
                flags |= PF_TERMINATE
        else:
            st.glossy[i] += 1
            if st.glossy[i] > cfg[CFG_MAX_GLOSSY]:
                flags |= PF_TERMINATE
    else:
        st.transmission[i] += 1
        if st.transmission[i] > cfg[CFG_MAX_TRANSMISSION]:
            flags |= PF_TERMINATE
    return flags


@kernel
def finish_bounce(n, n_shadow, occluded, st, sq, film_sum, film_sq, film_n, pd, pb, fp):
    """Add unoccluded light, write finished paths to the film, compact the rest.

    Returns the number of live paths, now at the front of the state arrays.
    """
    split = pd.cfg[PC_SPLIT] != 0    # shadow rays carry pass weights (``_nee_passes``)
    for s in range(n_shadow):
        if not occluded[s] and sq.alive[s]:
            i = sq.path[s]
            kind = sq.kind[s]
            if kind == SK_AO:
                ao_pass(pd, fp, st.pixel[i], sq.contrib[s, 0], sq.contrib[s, 1], sq.contrib[s, 2])
                continue
            st.radiance[i, 0] += sq.contrib[s, 0]
            st.radiance[i, 1] += sq.contrib[s, 1]
            st.radiance[i, 2] += sq.contrib[s, 2]
            if split:
                shadow_pass(pd, fp, st.pixel[i], pb, s, kind, sq.contrib[s, 0], sq.contrib[s, 1],
                            sq.contrib[s, 2])
    for i in range(n):
        if not st.alive[i]:
            _splat(st, i, film_sum, film_sq, film_n)
    m, first = compact_paths(st, n)
    if pb.pw.shape[0] > 1:
        for j in range(first, m):
            i = st.live[j]
            for c in range(6):
                pb.pw[j, c] = pb.pw[i, c]
            for c in range(3):
                pb.dn[j, c] = pb.dn[i, c]
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


@kernel
def splat_all(n, st, film_sum, film_sq, film_n):
    """Write all n paths to the film (end of a chunk)."""
    for i in range(n):
        _splat(st, i, film_sum, film_sq, film_n)


def trace_chunk(pixels, spp, accel, sc, cfg, fcfg, st, sq, scratch, film, stats, pd, pb, fp):
    """Trace spp samples for each pixel in ``pixels`` to completion.

    ``film`` is ``(film_sum, film_sq, film_n)``; ``pd``, ``pb`` and ``fp`` are the
    render passes' settings, buffers and film (``kernels.passes``).  A chunk always runs to the
    end (a fraction of a second): stopping paths half-way would keep the
    short paths and drop the long ones, a bias.  The loop ends when no path
    is alive; its bound guards against a path re-hitting its origin forever.
    """
    film_sum, film_sq, film_n = film
    n = generate_camera_rays(pixels, spp, film_n, st, sc, cfg)
    if pd.cfg[PC_DENOISE]:
        start_denoising_features(n, st, pb)
    stats[ST_CAMERA_RAYS] += n
    max_iterations = 4 * (int(cfg[CFG_MAX_BOUNCE]) + int(cfg[CFG_MAX_TRANSPARENT]) + 4)
    first = True
    for _ in range(max_iterations):
        if n == 0:
            break
        if not first:
            stats[ST_BOUNCE_RAYS] += n
        first = False
        mask = None
        if accel.masked:
            mask = np.empty(n, np.uint32)
            ray_masks(st.flags[:n], mask)
        prim = accel.closest(st.o32[:n], st.d32[:n], st.t32[:n], st.time[:n], mask)
        n_shadow = shade(n, prim, st, sq, sc, cfg, fcfg, scratch, stats, pd, pb, fp)
        occluded = trace_shadows(n_shadow, accel, sq, sc, cfg, scratch, stats)
        n = finish_bounce(n, n_shadow, occluded, st, sq, film_sum, film_sq, film_n, pd, pb, fp)
    splat_all(n, st, film_sum, film_sq, film_n)
