"""Light tracing of the caustics that path tracing cannot find, added to path tracing.

A point or spot lamp of radius 0 cannot be hit by a ray, so path tracing
finds its light only by next-event estimation, which cannot see it through
sharp glass or in a sharp mirror: the caustic a glass ball throws on the floor
renders black (Cycles renders it black too).  Light tracing finds it: a path
leaves the lamp, refracts through the ball, lands on the floor and is joined
to the camera there, its light added to the pixels the point projects to.

The integrator ``light`` (Path + Light Tracing) splits the paths between the
two methods, so that every path is counted once, with no weights to balance.
Writing a path from the camera, E x1 ... xk L (xk the vertex next to the
lamp), light tracing takes exactly those whose first vertex x1 scatters
through a lobe that is not singular (it can be joined to the camera) and
whose last vertex xk scatters through a singular one (sharp glass or mirror:
no light sample can go through it), for the lamps it emits from
(``prepare``: point and spot lamps of radius 0, and area lamps that path
tracing's rays can hit).  Path tracing keeps all the others: the kernels flag
its paths (``PF_CAUSTIC_EYE``: x1 was not singular) and its rays do not see
the light-traced lamps after a singular bounce on such a path
(``lights.LF_LIGHT_TRACED``).  So on an area-light scene the sum is path
tracing's image (the tests compare them), and with a lamp of radius 0 the
caustics appear.  Paths that are singular at both ends (a caustic seen
through glass or in a mirror from a point lamp) stay out of reach of both,
as they are for bidirectional path tracing with a pinhole camera.

A light path follows the adjoint rules: a singular bounce weighs its sample
by the geometric cosines and Snell's solid-angle map (``adjoint_singular``),
a smooth bounce evaluates the closures set up for a viewer on the side the
path goes to, as path tracing would evaluate them there.  It obeys the
bounce limits as the path it stands for would in path tracing (the total and
per-type counts of the scatterings between the camera and xk), Russian
roulette on what each bounce keeps, and the transparent bounce limit.  Light
paths are one per camera sample (keys from the sample's; independent numbers
whatever the scene's sampler, which the camera paths use), and splat into a
film of the worker's own (``session``); the image adds ``splat / paths``.
"""
from __future__ import annotations

import math

import numpy as np

from ..jit import by_ref, device, kernel
from .camera import C_APERTURE, C_MOTION_STEPS, C_VIEW_POST, C_VIEW_PRE
from .closures import bsdf_eval, bsdf_sample_closure, free_side
from .closures.layout import (
    CL_ETA,
    CL_N,
    CL_TYPE,
    LABEL_DIFFUSE,
    LABEL_GLOSSY,
    LABEL_REFLECT,
    LABEL_SINGULAR,
    LABEL_TRANSMIT,
    LABEL_TRANSPARENT,
)
from .emission import emitter_distribution, sample_emission, spot_cones
from .importance import camera_sees, in_film, splat
from .intersect import SHADOW_SHORTEN, offset_origin, triangle_frame
from .lights import (
    L_FLAGS,
    L_LIGHT_SETS,
    L_PMF,
    L_RADIUS,
    L_TYPE,
    LF_LIGHT_TRACED,
    LF_USE_MIS,
    LF_VIS_GLOSSY,
    LF_VIS_TRANSMISSION,
    LIGHT_SETS_ALL,
    LT_AREA,
    LT_POINT,
    LT_SPOT,
    light_set_columns,
)
from .sampling import SET_BSDF, SET_TERMINATE, bounce_set, mix64, path_key, rand
from .shading import leaves_correct_side, set_ray, shade_point
from .state import (
    CFG_FULL_W,
    CFG_LIGHT_TRACING,
    CFG_MAX_BOUNCE,
    CFG_MAX_DIFFUSE,
    CFG_MAX_GLOSSY,
    CFG_MAX_TRANSMISSION,
    CFG_MAX_TRANSPARENT,
    CFG_REGION_W,
    CFG_REGION_X,
    CFG_REGION_Y,
    CFG_SEED,
    PF_CAMERA,
    PF_TRANSPARENT_BG,
    ST_BOUNCE_RAYS,
    ST_SELF_HITS,
    ST_SHADOW_RAYS,
    compact_paths,
)
from .surface import hit_distance, past_self_hit, surface_point
from .svm import OBJ_HOLDOUT, shader_scene

_K_LIGHT_PATH = np.uint64(0x5851F42D4C957F2D)
# The shutter time of every light path: light tracing is off where anything moves (``prepare``).
_TIME = 0.5
# Light path flags (PathState.flags of a light path).
LP_CAUSTIC = 1          # xk scattered through a singular lobe: the path is light tracing's


# -- host side ---------------------------------------------------------------------------------
def prepare(scene, sc, cfg, plan) -> tuple:
    """Switch light tracing on for this render if it can add something: returns
    ``(tables, warnings)``, ``tables`` = (emit_cdf, emit_pmf, cones) or None.

    Marks the lamps it emits from (``LF_LIGHT_TRACED`` in ``sc.lamps``, changed in
    place) and sets ``CFG_LIGHT_TRACING``; path tracing then leaves their caustic paths
    to it.  Off, with a warning, where it would not render what path tracing does.
    """
    it = scene.integrator
    cfg[CFG_LIGHT_TRACING] = 0
    off = []
    if not (it.caustics_reflective and it.caustics_refractive):
        off.append("Path + Light Tracing renders as path tracing with the Caustics switches "
                   "off (light tracing would only add caustics)")
    if sc.camera[C_APERTURE] > 0.0:
        off.append("Path + Light Tracing renders as path tracing with depth of field (light "
                   "paths cannot be joined to a thin lens)")
    cam = sc.camera
    if len(sc.motion.slot_info) or cam[C_MOTION_STEPS] > 0 or \
            (cam[C_VIEW_PRE], cam[C_VIEW_POST]) != (1.0, 1.0):
        off.append("Path + Light Tracing renders as path tracing with motion blur (light "
                   "paths have no shutter time yet)")
    if it.filter_glossy > 0:
        off.append("Path + Light Tracing renders as path tracing with Filter Glossy (blurred "
                   "lobes are no longer singular, so the two would count some paths twice)")
    if "ray portal" in plan.lobes:
        off.append("Path + Light Tracing renders as path tracing with Ray Portal BSDFs (light "
                   "paths do not go through portals)")
    lamps = sc.lamps
    if off or not plan.caustics or not len(lamps):
        return None, off
    kind = lamps[:, L_TYPE].astype(int)
    flags = lamps[:, L_FLAGS].astype(np.int64)
    point = np.isin(kind, (LT_POINT, LT_SPOT)) & (lamps[:, L_RADIUS] <= 0.0)
    area = (kind == LT_AREA) & ((flags & LF_USE_MIS) != 0) & plan.lamps_hit
    # A lamp that lights only some objects (light linking) leaves its caustics to path
    # tracing, which tests the link at the first surface its light reaches.
    everyone = np.all(lamps[:, L_LIGHT_SETS:L_LIGHT_SETS + 2]
                      == light_set_columns([LIGHT_SETS_ALL]), axis=1)
    traced = (point | area) & everyone
    emit_cdf, emit_pmf = emitter_distribution(lamps[:, L_PMF], traced)
    if not emit_cdf[-1] > 0.0:
        return None, []
    lamps[traced, L_FLAGS] = (flags[traced] | LF_LIGHT_TRACED).astype(np.float64)
    cfg[CFG_LIGHT_TRACING] = 1
    notes = []
    if it.clamp_direct > 0 or it.clamp_indirect > 0:
        notes.append("light-traced caustics are not clamped (Clamping applies to path tracing)")
    return (emit_cdf, emit_pmf, spot_cones(lamps)), notes


def trace_light_chunk(pixels, spp, sample_base, accel, sc, cfg, st, sq, scratch, cam_scratch,
                      tables, splat_film, stats):
    """Trace one light path per camera sample of the chunk (``spp`` for each pixel in
    ``pixels``, sample numbers from ``sample_base``); their light goes to ``splat_film``
    (the film region's pixels, RGB).  Returns the number of light paths."""
    emit_cdf, emit_pmf, cones = tables
    n = start_light_paths(pixels, spp, sample_base, st, sc, cfg, emit_cdf, emit_pmf, cones)
    n_pixels = splat_film.shape[0]
    max_iterations = 4 * (int(cfg[CFG_MAX_BOUNCE]) + int(cfg[CFG_MAX_TRANSPARENT]) + 4)
    for _ in range(max_iterations):
        if n == 0:
            break
        stats[ST_BOUNCE_RAYS] += n
        prim = accel.closest(st.o32[:n], st.d32[:n], st.t32[:n])
        nq = extend_light_paths(n, prim, st, sq, sc, cfg, scratch, cam_scratch, n_pixels, stats)
        if nq:
            stats[ST_SHADOW_RAYS] += nq
            occluded = accel.occluded(sq.o32[:nq], sq.d32[:nq], sq.t32[:nq])
            splat_joined(nq, occluded, sq, splat_film, sc.filter_table, cfg, n_pixels)
        n = compact_light_paths(n, st)
    return pixels.size * spp


# -- kernels -----------------------------------------------------------------------------------
@device
def light_key(camera_key):
    """Random-number key of the light path of a camera sample."""
    return mix64(camera_key ^ _K_LIGHT_PATH)


@kernel
def start_light_paths(pixels, spp, sample_base, st, sc, cfg, emit_cdf, emit_pmf, cones):
    """Emit a light path for each camera sample; returns how many left a lamp.  A light
    path's ``pixel`` holds the lamp it left."""
    n = 0
    region_x, region_y, region_w = cfg[CFG_REGION_X], cfg[CFG_REGION_Y], cfg[CFG_REGION_W]
    for pi in range(pixels.shape[0]):
        pix = pixels[pi]
        global_pixel = (region_y + pix // region_w) * cfg[CFG_FULL_W] + region_x + pix % region_w
        for j in range(spp):
            key = light_key(path_key(cfg[CFG_SEED], global_pixel, sample_base[pix] + j))
            # The lamp's numbers take the camera's dimension sets (a light path has none).
            em = sample_emission(sc.lamps, sc.ies, emit_cdf, emit_pmf, cones, rand(key, 0), rand(key, 1),
                                 rand(key, 2), rand(key, 3), rand(key, 4))
            if not em.ok or (em.br == 0.0 and em.bg == 0.0 and em.bb == 0.0):
                continue
            st.key[n] = key
            st.pixel[n] = em.idx
            set_ray(st.ray_o, st.ray_d, st.ray_tmax, st.o32, st.d32, st.t32, n,
                    em.px, em.py, em.pz, em.dx, em.dy, em.dz, math.inf)
            st.beta[n, 0], st.beta[n, 1], st.beta[n, 2] = em.br, em.bg, em.bb
            st.bounce[n] = 0
            st.diffuse[n] = 0
            st.glossy[n] = 0
            st.transmission[n] = 0
            st.transparent[n] = 0
            st.flags[n] = 0
            st.self_prim[n] = -1
            st.alive[n] = 1
            n += 1
    return n


@device
def adjoint_singular(cl, k, label, ngx, ngy, ngz, wix, wiy, wiz, wox, woy, woz):
    """Factor from a singular lobe's sampled weight (closure row k, set up for a viewer at
    wi, where the light comes from) to the light path's weight, wo being the sampled
    direction: the geometric cosines of the area measure, and for a refraction Snell's map
    of solid angle (eta_i^2 cos_i dw_i = eta_o^2 cos_o dw_o) with eta the lobe's relative
    index seen from wi.  Path tracing's weights leave out the 1 / eta^2 of radiance,
    as Cycles does; this leaves it out in the same way, so a path through a closed
    object gets the same weight both ways."""
    cos_g = abs(ngx * wox + ngy * woy + ngz * woz) / abs(ngx * wix + ngy * wiy + ngz * wiz)
    if label & LABEL_TRANSPARENT or not label & LABEL_TRANSMIT:
        return cos_g
    nx, ny, nz = cl[k, CL_N], cl[k, CL_N + 1], cl[k, CL_N + 2]
    eta = cl[k, CL_ETA]
    cos_i = abs(nx * wix + ny * wiy + nz * wiz)
    cos_o = abs(nx * wox + ny * woy + nz * woz)
    if not (eta > 0.0 and cos_o > 0.0):
        return 0.0
    return cos_g * cos_i / (eta * eta * cos_o)


@device
def _shade_for(sc, scene_ref, cfg, scratch, p, b1, b2, dx, dy, dz, t, flags):
    """Triangle p's closures at (b1, b2) for a viewer at -d (to ``scratch.cl``)."""
    sp = surface_point(sc, p, b1, b2, dx, dy, dz, _TIME)
    res = shade_point(sc, scene_ref, cfg, scratch, sp, sc.mat_index[p], p, b1, b2, dx, dy, dz, t,
                      flags, True, (0, 0, 0, 0, 0), 0.0)
    return sp, res


@kernel
def extend_light_paths(n, prim, st, sq, sc, cfg, scratch, cam_scratch, n_pixels, stats):
    """Shade the hits of the n live light paths: join each vertex after a singular one to
    the camera (queued segments), sample the next direction.  Returns the queue length."""
    q = 0
    cam = sc.camera
    table = sc.filter_table
    x0, y0, rw = cfg[CFG_REGION_X], cfg[CFG_REGION_Y], cfg[CFG_REGION_W]
    rh = n_pixels // rw
    max_bounce = cfg[CFG_MAX_BOUNCE]
    max_transparent = cfg[CFG_MAX_TRANSPARENT]
    scene_ref = by_ref(shader_scene(sc))
    for i in range(n):
        p = prim[i]
        ox, oy, oz = st.ray_o[i, 0], st.ray_o[i, 1], st.ray_o[i, 2]
        dx, dy, dz = st.ray_d[i, 0], st.ray_d[i, 1], st.ray_d[i, 2]
        if p >= 0 and p == st.self_prim[i]:
            stats[ST_SELF_HITS] += 1
            s = past_self_hit(sc, p, ox, oy, oz, dx, dy, dz, _TIME)
            set_ray(st.ray_o, st.ray_d, st.ray_tmax, st.o32, st.d32, st.t32, i,
                    ox + s * dx, oy + s * dy, oz + s * dz, dx, dy, dz, math.inf)
            continue
        st.alive[i] = 0
        if p < 0 or triangle_frame(sc.verts, sc.tris, p)[3] <= 0.0:
            continue
        t_hit, b1, b2 = hit_distance(sc, p, ox, oy, oz, dx, dy, dz, math.inf, _TIME)
        sp, res = _shade_for(sc, scene_ref, cfg, scratch, p, b1, b2, dx, dy, dz, t_hit, 0)
        if res.n == 0:
            continue
        hx, hy, hz = sp.hx, sp.hy, sp.hz
        ngx, ngy, ngz = sp.ngx, sp.ngy, sp.ngz
        wix, wiy, wiz = -dx, -dy, -dz                  # towards where the light came from
        cos_in = sp.cos_o
        caustic = (st.flags[i] & LP_CAUSTIC) != 0
        vertex = st.bounce[i] + 1                      # this vertex: x_(k - vertex + 1)

        # -- join this vertex to the camera: it is x1 of a path E x1 ... xk L ------------------
        # A holdout object keeps only its transparent closure for the camera (path.py), which
        # has nothing to join: the film there is cleared, not lit.
        if (caustic and vertex - 1 <= max_bounce
                and not sc.tex.objects[sc.tex.tri_object[p], OBJ_HOLDOUT] > 0.0):
            view = camera_sees(cam, hx, hy, hz)
            if view.ok and in_film(table, x0, y0, rw, rh, view.rx, view.ry):
                wcx, wcy, wcz = view.wx, view.wy, view.wz
                _, res2 = _shade_for(sc, scene_ref, cfg, cam_scratch, p, b1, b2, -wcx, -wcy, -wcz, view.dist,
                                     PF_CAMERA | PF_TRANSPARENT_BG)
                # x1's scattering counts towards the bounce limits of its lobe type.
                exclude = 0
                if st.diffuse[i] + 1 > cfg[CFG_MAX_DIFFUSE]:
                    exclude |= LABEL_DIFFUSE
                if st.glossy[i] + 1 > cfg[CFG_MAX_GLOSSY]:
                    exclude |= LABEL_GLOSSY
                if st.transmission[i] + 1 > cfg[CFG_MAX_TRANSMISSION]:
                    exclude |= LABEL_TRANSMIT
                fr, fg, fb, _ = bsdf_eval(cam_scratch.cl, res2.n, wcx, wcy, wcz, wix, wiy, wiz,
                                          exclude)
                if fr != 0.0 or fg != 0.0 or fb != 0.0:
                    k = view.importance * view.geometry * abs(ngx * wcx + ngy * wcy + ngz * wcz) / cos_in
                    q = _queue_join(sq, q, hx, hy, hz, ngx, ngy, ngz, wcx, wcy, wcz, view.dist,
                                    st.beta[i, 0] * fr * k, st.beta[i, 1] * fg * k,
                                    st.beta[i, 2] * fb * k, view.rx, view.ry)

        # -- the next direction ----------------------------------------------------------------
        if caustic and vertex > max_bounce:
            continue                                   # a further x1 would pass the limit
        key = st.key[i]
        d = 4 * bounce_set(vertex + st.transparent[i], SET_BSDF)
        wox, woy, woz, wr, wg, wb, pdf, label, kpick = bsdf_sample_closure(
            scratch.cl, res.n, wix, wiy, wiz, rand(key, d + 2), rand(key, d), rand(key, d + 1),
            rand(key, d + 3))
        if (wr == 0.0 and wg == 0.0 and wb == 0.0) or not (
                free_side(scratch.cl[kpick, CL_TYPE]) or leaves_correct_side(sp, wox, woy, woz, label)):
            continue
        flags = st.flags[i]
        if label & LABEL_TRANSPARENT:
            st.transparent[i] += 1
            if st.transparent[i] >= max_transparent:
                continue
            nr, ng_, nb = st.beta[i, 0] * wr, st.beta[i, 1] * wg, st.beta[i, 2] * wb
        else:
            singular = (label & LABEL_SINGULAR) != 0
            if not caustic:
                # xk: only a singular lobe makes a path that path tracing leaves out, and
                # only if the lamp would be visible to that ray.
                lamp_flags = int(sc.lamps[st.pixel[i], L_FLAGS])
                if not singular:
                    continue
                if label & LABEL_REFLECT and not (lamp_flags & LF_VIS_GLOSSY):
                    continue
                if label & LABEL_TRANSMIT and not (lamp_flags & LF_VIS_TRANSMISSION):
                    continue
                flags |= LP_CAUSTIC
            elif not _count_bounce(st, i, cfg, label):
                continue
            st.bounce[i] = vertex
            if singular:
                k = adjoint_singular(scratch.cl, kpick, label, ngx, ngy, ngz, wix, wiy, wiz,
                                     wox, woy, woz)
                nr, ng_, nb = st.beta[i, 0] * wr * k, st.beta[i, 1] * wg * k, st.beta[i, 2] * wb * k
            else:
                # The light this vertex sends towards wo, from closures set up for a viewer there.
                _, res3 = _shade_for(sc, scene_ref, cfg, cam_scratch, p, b1, b2, -wox, -woy, -woz, t_hit, 0)
                fr, fg, fb, _ = bsdf_eval(cam_scratch.cl, res3.n, wox, woy, woz, wix, wiy, wiz, 0)
                k = abs(ngx * wox + ngy * woy + ngz * woz) / (cos_in * pdf)
                nr, ng_, nb = st.beta[i, 0] * fr * k, st.beta[i, 1] * fg * k, st.beta[i, 2] * fb * k
            if vertex >= 2:
                # Russian roulette on what the bounce kept.
                old = max(st.beta[i, 0], st.beta[i, 1], st.beta[i, 2])
                survive = min(max(nr, ng_, nb) / old, 1.0) if old > 0.0 else 0.0
                if survive < 1.0:
                    if not rand(key, 4 * bounce_set(vertex + st.transparent[i], SET_TERMINATE)) < survive:
                        continue
                    nr, ng_, nb = nr / survive, ng_ / survive, nb / survive
        if nr == 0.0 and ng_ == 0.0 and nb == 0.0:
            continue
        st.beta[i, 0], st.beta[i, 1], st.beta[i, 2] = nr, ng_, nb
        st.flags[i] = flags
        nox, noy, noz = offset_origin(hx, hy, hz, ngx, ngy, ngz, wox, woy, woz)
        set_ray(st.ray_o, st.ray_d, st.ray_tmax, st.o32, st.d32, st.t32, i, nox, noy, noz,
                wox, woy, woz, math.inf)
        st.self_prim[i] = p
        st.alive[i] = 1
    return q


@device
def _count_bounce(st, i, cfg, label):
    """Count a scattering between x1 and xk by its lobe (as ``path.count_bounce`` does);
    False when a limit is passed (path tracing would end the path there)."""
    if label & LABEL_REFLECT:
        if label & LABEL_DIFFUSE:
            st.diffuse[i] += 1
            return st.diffuse[i] <= cfg[CFG_MAX_DIFFUSE]
        st.glossy[i] += 1
        return st.glossy[i] <= cfg[CFG_MAX_GLOSSY]
    st.transmission[i] += 1
    return st.transmission[i] <= cfg[CFG_MAX_TRANSMISSION]


@device
def _queue_join(sq, q, ax, ay, az, anx, any_, anz, dx, dy, dz, length, cr, cg, cb, rx, ry):
    """Queue the segment from surface point a along the unit direction d to the camera's
    near plane; the raster position goes to ``target``."""
    ax, ay, az = offset_origin(ax, ay, az, anx, any_, anz, dx, dy, dz)
    sq.o32[q, 0], sq.o32[q, 1], sq.o32[q, 2] = ax, ay, az
    sq.d32[q, 0], sq.d32[q, 1], sq.d32[q, 2] = dx, dy, dz
    sq.t32[q] = min(length * (1.0 - SHADOW_SHORTEN), 1e30)
    sq.contrib[q, 0], sq.contrib[q, 1], sq.contrib[q, 2] = cr, cg, cb
    sq.target[q, 0], sq.target[q, 1], sq.target[q, 2] = rx, ry, 0.0
    return q + 1


@kernel
def splat_joined(nq, occluded, sq, film, table, cfg, n_pixels):
    """Add the unoccluded joins to the light-tracing film."""
    rw = cfg[CFG_REGION_W]
    for s in range(nq):
        if not occluded[s]:
            splat(film, table, cfg[CFG_REGION_X], cfg[CFG_REGION_Y], rw, n_pixels // rw,
                  sq.target[s, 0], sq.target[s, 1], sq.contrib[s, 0], sq.contrib[s, 1],
                  sq.contrib[s, 2])


@kernel
def compact_light_paths(n, st):
    """Move the live light paths to the front; returns how many there are."""
    m, _ = compact_paths(st, n)
    return m
