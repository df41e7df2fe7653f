"""Subsurface scattering inside one object: random walks and Christensen-Burley disk probes,
as Cycles does them (kernel/integrator/subsurface_random_walk.h, subsurface_disk.h).

When a path picks a BSSRDF closure (``closures.bssrdf``) it refracts into the object and
walks a homogeneous medium there until it leaves through the object's surface:

* the medium: each channel's extinction is 1 / radius / (1 - g) and its single-scattering
  albedo is fitted to the closure's albedo (Chiang, Kutz and Burley 2016, with Wrenninge
  et al.'s polynomials in the anisotropy g), at least 0.2 (the throughput takes the rest);
* each step picks a colour channel by throughput x albedo and samples a distance with its
  extinction; after the first step the direction is either the Henyey-Greenstein phase
  function's or Dwivedi's guided one (away from the entry plane, or towards an opposite
  side the first step found); the step's weight is the balance heuristic over the
  {classic, guided, backward guided} x {r, g, b} strategies;
* after 9 steps the phase function is made isotropic with the similarity relation;
* the walk meets only the object's own triangles (an Embree scene per object with
  subsurface materials, ``LocalBVH``, traced one ray at a time from the walk); it gives up after 256 steps or when its
  throughput falls below 1e-6.

A Christensen-Burley BSSRDF does not walk: ``disk_probe`` casts one probe ray through a
disk around the point (its axis the normal, the tangent or the bitangent; its radius from
the closure's diffusion profile), keeps up to four of the object's surfaces it crosses
(reservoir sampling beyond), weights each by the profile at its distance with MIS over the
three axes, and resamples one of them as the exit (Cycles' subsurface_disk.h).

The path then continues from the exit point with a Lambert closure of weight 1 (the path
tracer does that, ``path.shade``).  The walk's numbers come from the path's sampler with a
key of the walk's own (``sampling.walk_key``: with Sobol, stratified over the pixel's samples
at every step), as Cycles scrambles its sequence's dimensions for the walk.
"""
from __future__ import annotations

import math
import weakref
from collections import namedtuple

import numpy as np

from ..jit import device
from . import embree
from .closures.bssrdf import disk_sample, disk_weight
from .embree import intersect_one
from .intersect import triangle_frame
from .motion import BVH_LEAF, build_bvh, corner_normals, hit_triangle, ray_box
from .sampling import make_orthonormals, orthonormal_basis, rand, sample_2d, sample_4d

MAX_STEPS = 256                  # Cycles' BSSRDF_MAX_BOUNCES
SIMILARITY_LEVEL = 9             # steps with the real phase function (Cycles' similarity level)
THROUGHPUT_EPSILON = 1e-6        # Cycles' VOLUME_THROUGHPUT_EPSILON
MIN_ALPHA = 0.2                  # single-scattering albedo floor (the throughput compensates)
DISK_MAX_HITS = 4                # surfaces a disk probe keeps (Cycles' BSSRDF_MAX_HITS, and
                                 # LOCAL_MAX_HITS for Bevel)
_INV_2PI = 0.5 / math.pi
_INV_4PI = 0.25 / math.pi

LocalBVH = namedtuple("LocalBVH", [
    "root",      # (O, 2) int32  [first, end) node rows of object o's hierarchy (empty: none)
    "box",       # (K, 6) f64    node bounds (lo, hi)
    "node",      # (K, 3) int32  skip row, first leaf entry, leaf count (0: inner node)
    "tris",      # (L,) int32    the leaves' triangles (scene ids); Embree: primitive ids
    "embree",    # (O,) int64    object o's Embree scene (kernels.embree.build_local), 0: none
    "first",     # (O,) int64    Embree: where object o's primitive ids start in ``tris``
    "intersect", # (1,) int64    Embree: the address of rtcIntersect1 (0: hierarchies here)
])


def no_local_bvh(objects: int = 0) -> LocalBVH:
    """A LocalBVH without hierarchies (nothing that a subsurface walk, a Bevel or an Ambient
    Occlusion node traces)."""
    return LocalBVH(np.zeros((objects, 2), np.int32), np.zeros((0, 6)), np.zeros((0, 3), np.int32),
                    np.zeros(0, np.int32), np.zeros(objects, np.int64), np.zeros(objects, np.int64),
                    np.zeros(1, np.int64))


def build_local_bvh(verts, tris, tri_object, objects, wanted, embree_scenes=True,
                    scene_ids=None) -> LocalBVH:
    """One hierarchy over each object in ``wanted`` (object indices), over its own triangles
    as they are at the frame: an Embree scene each (as Cycles' walk uses Embree), or, with
    ``embree_scenes=False`` or where the library is not found, compiled hierarchies here.
    With ``scene_ids`` (triangle ids), one more hierarchy over those, as slot ``objects``:
    the scene that Ambient Occlusion nodes' rays meet.

    The Embree scenes are released when the returned ``embree`` array is garbage collected.
    """
    objects_ids = [(o, np.flatnonzero(tri_object == o).astype(np.int32))
                   for o in sorted(set(int(w) for w in wanted))]
    if scene_ids is not None:
        objects_ids.append((objects, np.asarray(scene_ids, np.int32)))
        objects += 1
    objects_ids = [(o, ids) for o, ids in objects_ids if len(ids)]
    if not objects_ids:
        return no_local_bvh(objects)
    if embree_scenes:
        local = _embree_local(verts, tris, objects, objects_ids)
        if local is not None:
            return local
    root = np.zeros((objects, 2), np.int32)
    boxes, nodes, leaves = [], [], []
    base_node = base_leaf = 0
    for o, ids in objects_ids:
        corners = verts[tris[ids]]                       # (n, 3, 3)
        box, node, order = build_bvh(corners.min(axis=1), corners.max(axis=1), BVH_LEAF)
        node = node.astype(np.int64)
        node[:, 0] += base_node
        node[:, 1] += base_leaf
        boxes.append(box)
        nodes.append(node)
        leaves.append(ids[order])
        root[o] = base_node, base_node + len(box)
        base_node += len(box)
        base_leaf += len(ids)
    empty = no_local_bvh(objects)
    return empty._replace(root=root, box=np.ascontiguousarray(np.concatenate(boxes)),
                          node=np.concatenate(nodes).astype(np.int32),
                          tris=np.concatenate(leaves).astype(np.int32))


def _embree_local(verts, tris, objects, objects_ids) -> LocalBVH | None:
    handles = np.zeros(objects, np.int64)
    first = np.zeros(objects, np.int64)
    owners, address, start = [], 0, 0
    for o, ids in objects_ids:
        built = embree.build_local(verts, tris[ids])
        if built is None:
            return None
        scene, handles[o], address = built
        owners.append(scene)
        first[o] = start
        start += len(ids)
    weakref.finalize(handles, owners.clear)     # the scenes live as long as their handles
    return no_local_bvh(objects)._replace(
        tris=np.concatenate([ids for _, ids in objects_ids]).astype(np.int32),
        embree=handles, first=first, intersect=np.array([address], np.int64))


@device
def local_closest(lb, verts, tris, obj, ox, oy, oz, dx, dy, dz, tmax, skip):
    """Closest hit within (0, tmax) on object ``obj``'s own triangles, ignoring triangle
    ``skip`` (the one the ray starts on, or -1): (t, triangle), triangle -1 for none."""
    if lb.intersect[0] != 0:
        return _embree_closest(lb, verts, tris, obj, ox, oy, oz, dx, dy, dz, tmax, skip)
    k, end = lb.root[obj, 0], lb.root[obj, 1]
    best, found = tmax, -1
    while k < end:
        if not ray_box(ox, oy, oz, dx, dy, dz, lb.box, k, best):
            k = lb.node[k, 0]
            continue
        first = lb.node[k, 1]
        for e in range(first, first + lb.node[k, 2]):
            p = lb.tris[e]
            if p == skip:
                continue
            t = _hit_prim(verts, tris, p, ox, oy, oz, dx, dy, dz)
            if t < best:
                best, found = t, p
        k += 1
    return best, found


@device
def _hit_prim(verts, tris, p, ox, oy, oz, dx, dy, dz):
    """``motion.hit_triangle`` on triangle p of the scene tables (float64)."""
    a, b, c = tris[p, 0], tris[p, 1], tris[p, 2]
    return hit_triangle(ox, oy, oz, dx, dy, dz, verts[a, 0], verts[a, 1], verts[a, 2],
                        verts[b, 0], verts[b, 1], verts[b, 2], verts[c, 0], verts[c, 1],
                        verts[c, 2])


@device
def _embree_closest(lb, verts, tris, obj, ox, oy, oz, dx, dy, dz, tmax, skip):
    """local_closest through the object's Embree scene (float32 rays from the float64 point);
    the distance to the triangle found is recomputed in float64.  A hit on ``skip``, which
    rounding can report near the ray's start, is traced again from just past it."""
    scene = lb.embree[obj]
    if scene == 0:
        return tmax, -1
    tnear = 0.0
    for _ in range(3):
        t32, q = intersect_one(lb.intersect[0], scene, ox, oy, oz, dx, dy, dz, tnear, tmax)
        if q < 0:
            return tmax, -1
        p = lb.tris[lb.first[obj] + q]
        if p != skip:
            t = _hit_prim(verts, tris, p, ox, oy, oz, dx, dy, dz)
            # Embree's watertight float32 test may find a hit the float64 one misses at an edge.
            return (t if t < math.inf else min(t32, tmax)), p
        tnear = t32 * (1.0 + 2.0 ** -22) + 1e-30
    return tmax, -1


# -- the medium --------------------------------------------------------------------------
@device
def remap(albedo, radius, g):
    """(extinction, single-scattering albedo) of one channel from the surface albedo, the
    radius and the anisotropy g (Cycles' subsurface_random_walk_remap)."""
    g2 = g * g
    g3 = g2 * g
    g4 = g3 * g
    g5 = g4 * g
    g6 = g5 * g
    g7 = g6 * g
    a = (1.8260523782 - 1.28451056436 * g - 1.79904629312 * g2 + 9.19393289202 * g3
         - 22.8215585862 * g4 + 32.0234874259 * g5 - 23.6264803333 * g6 + 7.21067002658 * g7)
    b = 4.98511194385 + 0.127355959438 * math.exp(
        31.1491581433 * g - 201.847017512 * g2 + 841.576016723 * g3 - 2018.09288505 * g4
        + 2731.71560286 * g5 - 1935.41424244 * g6 + 559.009054474 * g7)
    c = (1.09686102424 - 0.394704063468 * g + 1.05258115941 * g2 - 8.83963712726 * g3
         + 28.8643230661 * g4 - 46.8802913581 * g5 + 38.5402837518 * g6 - 12.7181042538 * g7)
    d = (0.496310210422 + 0.360146581622 * g - 2.15139309747 * g2 + 17.8896899217 * g3
         - 55.2984010333 * g4 + 82.065982243 * g5 - 58.5106008578 * g6 + 15.8478295021 * g7)
    e = 4.23190299701 + 0.00310603949088 * math.exp(
        76.7316253952 * g - 594.356773233 * g2 + 2448.8834203 * g3 - 5576.68528998 * g4
        + 7116.60171912 * g5 - 4763.54467887 * g6 + 1303.5318055 * g7)
    f = (2.40602999408 - 2.51814844609 * g + 9.18494908356 * g2 - 79.2191708682 * g3
         + 259.082868209 * g4 - 403.613804597 * g5 + 302.85712436 * g6 - 87.4370473567 * g7)
    blend = albedo ** 0.25
    alpha = ((1.0 - blend) * a * math.atan(b * albedo) ** c
             + blend * d * math.atan(e * albedo) ** f)
    alpha = min(max(alpha, 0.0), 0.999999)
    return 1.0 / max(radius, 1e-16) / (1.0 - g), alpha


@device
def diffusion_length(alpha):
    """Dwivedi's diffusion length for single-scattering albedo alpha (d'Eon and Krivanek
    2020, eq. 67)."""
    return 1.0 / math.sqrt(1.0 - alpha ** (2.44294 - 0.0215813 * alpha + 0.578637 / alpha))


@device
def hg_phase(cos_theta, g):
    """Henyey-Greenstein phase function (per steradian)."""
    if abs(g) < 1e-3:
        return _INV_4PI
    fac = 1.0 + g * (g - 2.0 * cos_theta)
    return (1.0 - g * g) / (4.0 * math.pi * fac * math.sqrt(max(fac, 0.0)))


@device
def around(dx, dy, dz, cos_theta, u):
    """The unit direction at angle acos(cos_theta) from d, at azimuth 2 pi u."""
    sin_theta = math.sqrt(max(1.0 - cos_theta * cos_theta, 0.0))
    phi = 2.0 * math.pi * u
    x, y = sin_theta * math.cos(phi), sin_theta * math.sin(phi)
    tx, ty, tz, bx, by, bz = orthonormal_basis(dx, dy, dz)
    return (x * tx + y * bx + cos_theta * dx, x * ty + y * by + cos_theta * dy,
            x * tz + y * bz + cos_theta * dz)


@device
def hg_sample(dx, dy, dz, g, u1, u2):
    """(direction, pdf) from the Henyey-Greenstein phase function around d."""
    cos_theta = 1.0 - 2.0 * u1
    if abs(g) >= 1e-3:
        k = (1.0 - g * g) / (1.0 - g * cos_theta)
        cos_theta = (1.0 + g * g - k * k) / (2.0 * g)
    x, y, z = around(dx, dy, dz, cos_theta, u2)
    return x, y, z, hg_phase(cos_theta, g)


@device
def _step_pdf(sigma, t, hit):
    """Density of stopping at t (a scattering point), or probability of passing t (a hit)."""
    tr = math.exp(-sigma * t)
    return tr if hit else sigma * tr


# -- the walk ------------------------------------------------------------------------------------
@device
def random_walk(lb, verts, tris, obj, sampler, wkey, mask, px, py, pz, dx, dy, dz, nx, ny, nz,
                entry, ar, ag, ab, rr, rg, rb, g, tr, tg, tb):
    """Walk from the entry point p (on triangle ``entry`` of object ``obj``, smooth normal n
    facing out) along the entry direction d, with the closure's albedo a, radius r and
    anisotropy g, starting with the path throughput t (closure weight included).  Step k
    draws its numbers from the walk key's dimension sets 2k (colour channel, distance, the
    guided and the backward choices) and 2k + 1 (direction), as Cycles draws each step's
    from its sampler.

    Returns (left, exit triangle, exit point, last direction, last step length, throughput
    r, g, b).
    """
    sr, alr = remap(ar, rr, g)
    sg, alg = remap(ag, rg, g)
    sb, alb = remap(ab, rb, g)
    # The throughput holds the albedo already; scattering adds it back.
    tr = tr / ar if ar != 0.0 else 0.0
    tg = tg / ag if ag != 0.0 else 0.0
    tb = tb / ab if ab != 0.0 else 0.0
    if alr < MIN_ALPHA:
        tr *= alr / MIN_ALPHA
        alr = MIN_ALPHA
    if alg < MIN_ALPHA:
        tg *= alg / MIN_ALPHA
        alg = MIN_ALPHA
    if alb < MIN_ALPHA:
        tb *= alb / MIN_ALPHA
        alb = MIN_ALPHA
    # Guided sampling with the highest albedo (the safe side: lower would make fireflies).
    dl = diffusion_length(max(alr, alg, alb))
    if dl == 1.0:
        return False, -1, px, py, pz, dx, dy, dz, 0.0, 0.0, 0.0, 0.0
    phase_log = math.log((dl + 1.0) / (dl - 1.0))
    guided_fraction_0 = 1.0 - max(0.5, abs(g) ** 0.125)
    # The similarity relation's medium, for the steps after SIMILARITY_LEVEL.
    star_r = sr - sr * alr * g
    star_g = sg - sg * alg * g
    star_b = sb - sb * alb * g
    ox, oy, oz = px, py, pz
    hit = False
    have_opposite = False
    opposite = 0.0
    t = 0.0
    found = -1
    for step in range(MAX_STEPS):
        if step <= SIMILARITY_LEVEL:
            gs, guided_fraction = g, guided_fraction_0
            s_r, s_g, s_b = sr, sg, sb
            c_r, c_g, c_b = sr * alr, sg * alg, sb * alb
        else:
            gs, guided_fraction = 0.0, 0.75
            s_r, s_g, s_b = star_r, star_g, star_b
            c_r, c_g, c_b = sr * alr * (1.0 - g), sg * alg * (1.0 - g), sb * alb * (1.0 - g)
        u, u_t, u_guided, u_backward = sample_4d(sampler, wkey, 2 * step, mask)
        # Colour channel, in proportion to throughput x albedo.
        wr, wg, wb = abs(tr * alr), abs(tg * alg), abs(tb * alb)
        total = wr + wg + wb
        if (1.0 - total) < 1.0:
            pr, pg, pb = wr / total, wg / total, wb / total
        else:
            pr = pg = pb = 1.0 / 3.0
        if u < pr:
            sigma = s_r
        elif u < pr + pg:
            sigma = s_g
        else:
            sigma = s_b

        backward_fraction = 0.0
        forward_factor = backward_factor = 0.0
        forward_stretch = backward_stretch = 1.0
        if step > 0:
            guided = u_guided < guided_fraction
            backward = False
            if have_opposite:
                x = min(max(-((px - ox) * nx + (py - oy) * ny + (pz - oz) * nz), 0.0), opposite)
                backward_fraction = 1.0 / (1.0 + math.exp((opposite - 2.0 * x) / dl))
                backward = u_backward < backward_fraction
            u1, u2 = sample_2d(sampler, wkey, 2 * step + 1, mask)
            if guided:
                cos_theta = dl - (dl + 1.0) * math.exp(-u1 * phase_log)
                if backward:
                    cos_theta = -cos_theta
                ndx, ndy, ndz = around(nx, ny, nz, cos_theta, u2)
                hg = hg_phase(dx * ndx + dy * ndy + dz * ndz, gs)
            else:
                ndx, ndy, ndz, hg = hg_sample(dx, dy, dz, gs, u1, u2)
                cos_theta = ndx * nx + ndy * ny + ndz * nz
            dx, dy, dz = ndx, ndy, ndz
            # Guided / classic direction densities (the classic one cancels in the estimator).
            forward_factor = _INV_2PI / ((dl - cos_theta) * phase_log) / hg
            backward_factor = _INV_2PI / ((dl + cos_theta) * phase_log) / hg
            forward_stretch = 1.0 - cos_theta / dl
            backward_stretch = 1.0 + cos_theta / dl
            if guided:
                sigma *= backward_stretch if backward else forward_stretch

        t = -math.log(1.0 - u_t) / sigma
        # The first step also looks ten mean free paths ahead for an opposite side.
        tmax = max(t, 10.0 / min(s_r, s_g, s_b)) if step == 0 else t
        t_hit, found = local_closest(lb, verts, tris, obj, px, py, pz, dx, dy, dz, tmax,
                                     entry if step == 0 else -1)
        hit = found >= 0
        if step == 0:
            if hit:
                have_opposite = True
                opposite = -((px + t_hit * dx - ox) * nx + (py + t_hit * dy - oy) * ny
                             + (pz + t_hit * dz - oz) * nz)
            hit = hit and t_hit < t
        if hit:
            t = t_hit
        px, py, pz = px + t * dx, py + t * dy, pz + t * dz

        ttr, ttg, ttb = math.exp(-s_r * t), math.exp(-s_g * t), math.exp(-s_b * t)
        qr = ttr if hit else s_r * ttr
        qg = ttg if hit else s_g * ttg
        qb = ttb if hit else s_b * ttb
        if step > 0:
            fr_ = _step_pdf(forward_stretch * s_r, t, hit)
            fg_ = _step_pdf(forward_stretch * s_g, t, hit)
            fb_ = _step_pdf(forward_stretch * s_b, t, hit)
            if have_opposite:
                k0, k1 = 1.0 - backward_fraction, backward_fraction
                fr_ = fr_ * forward_factor * k0 + _step_pdf(backward_stretch * s_r, t, hit) * backward_factor * k1
                fg_ = fg_ * forward_factor * k0 + _step_pdf(backward_stretch * s_g, t, hit) * backward_factor * k1
                fb_ = fb_ * forward_factor * k0 + _step_pdf(backward_stretch * s_b, t, hit) * backward_factor * k1
            else:
                fr_, fg_, fb_ = fr_ * forward_factor, fg_ * forward_factor, fb_ * forward_factor
            qr = qr * (1.0 - guided_fraction) + fr_ * guided_fraction
            qg = qg * (1.0 - guided_fraction) + fg_ * guided_fraction
            qb = qb * (1.0 - guided_fraction) + fb_ * guided_fraction
        pdf = pr * qr + pg * qg + pb * qb
        if hit:
            tr, tg, tb = tr * ttr / pdf, tg * ttg / pdf, tb * ttb / pdf
            break
        tr, tg, tb = tr * c_r * ttr / pdf, tg * c_g * ttg / pdf, tb * c_b * ttb / pdf
        if max(tr, tg, tb) < THROUGHPUT_EPSILON:
            break
    if not hit or not (math.isfinite(tr) and math.isfinite(tg) and math.isfinite(tb)):
        return False, -1, px, py, pz, dx, dy, dz, 0.0, 0.0, 0.0, 0.0
    return True, found, px, py, pz, dx, dy, dz, t, tr, tg, tb


# -- Christensen-Burley: a disk probe ------------------------------------------------------------
@device
def _hit_weight(normals, normal_index, verts, tris, p, hx, hy, hz, px, py, pz, flip, axes, picks,
                scale, radius, disk_r):
    """Weight (r, g, b) of the probe's hit h on triangle p: the profile at its distance
    from p0 = (px, py, pz) over the disk's pdf, times the MIS weight of the disk's axis
    (power heuristic over the three ``axes`` (n, t, b) picked with probabilities ``picks``)
    and ``scale``."""
    gx, gy, gz = hit_normal(normals, normal_index, verts, tris, p, flip)
    pdf_n = picks[0] * abs(axes[0] * gx + axes[1] * gy + axes[2] * gz)
    pdf_t = picks[1] * abs(axes[3] * gx + axes[4] * gy + axes[5] * gz)
    pdf_b = picks[2] * abs(axes[6] * gx + axes[7] * gy + axes[8] * gz)
    w = pdf_n / (pdf_n * pdf_n + pdf_t * pdf_t + pdf_b * pdf_b) * scale
    r = math.sqrt((hx - px) ** 2 + (hy - py) ** 2 + (hz - pz) ** 2)
    er, eg, eb = disk_weight(radius[0], radius[1], radius[2], disk_r, r)
    return er * w, eg * w, eb * w


@device
def hit_normal(normals, normal_index, verts, tris, p, flip):
    """Triangle p's geometric normal, on the side its corner normals say, flipped when the
    probe started on a back face."""
    gx, gy, gz, _ = triangle_frame(verts, tris, p)
    gx, gy, gz = facing_corners(normals, normal_index, p, gx, gy, gz)
    if flip:
        gx, gy, gz = -gx, -gy, -gz
    return gx, gy, gz


@device
def facing_corners(normals, normal_index, p, gx, gy, gz):
    """The normal g of triangle p, on the side its corner normals say (the object's outside:
    a mirrored object's winding is reversed); ``normals[normal_index[p, k]]`` is corner k's."""
    n0x, n0y, n0z, n1x, n1y, n1z, n2x, n2y, n2z = corner_normals(normals, normal_index, p)
    sx = n0x + n1x + n2x
    sy = n0y + n1y + n2y
    sz = n0z + n1z + n2z
    if sx * gx + sy * gy + sz * gz < 0.0:
        return -gx, -gy, -gz
    return gx, gy, gz


@device
def disk_axes(ngx, ngy, ngz, u):
    """The frame (n, t, b) of a disk probe about a point of geometric normal ng, its axis n
    picked by u as Cycles picks it: the normal for u < 1/2, else the tangent or the
    bitangent of Cycles' frame (a quarter each), swapped with the normal.  Returns the
    frame, the probabilities with which n, t and b are picked as axes, and u rescaled to
    [0, 1).  Cycles' frame, not any other: the MIS over the three axes leaves out the other
    axes' disk densities, so what the probes find depends on how the frame turns about ng."""
    tx, ty, tz, bx, by, bz = make_orthonormals(ngx, ngy, ngz)
    nx, ny, nz = ngx, ngy, ngz
    if u < 0.5:
        return nx, ny, nz, tx, ty, tz, bx, by, bz, 0.5, 0.25, 0.25, u * 2.0
    if u < 0.75:
        return tx, ty, tz, nx, ny, nz, bx, by, bz, 0.25, 0.5, 0.25, (u - 0.5) * 4.0
    return bx, by, bz, tx, ty, tz, nx, ny, nz, 0.25, 0.25, 0.5, (u - 0.75) * 4.0


@device
def probe(lb, verts, tris, obj, ox, oy, oz, dx, dy, dz, tmax, key):
    """Every surface of object ``obj`` on the probe o + t d, 0 < t < tmax, nearest first: the
    first four, then (reservoir sampling with hashes of ``key``) a uniform subset of four, as
    Cycles' local intersection keeps them.  Returns (count of surfaces crossed, the four
    kept triangles (-1: none), their distances)."""
    count = 0
    p0 = p1 = p2 = p3 = -1
    t0 = t1 = t2 = t3 = 0.0
    t = 0.0
    p = -1
    while count < MAX_STEPS:
        step, p = local_closest(lb, verts, tris, obj, ox + t * dx, oy + t * dy, oz + t * dz,
                                dx, dy, dz, tmax - t, p)
        if p < 0:
            break
        t += step
        count += 1
        slot = count - 1
        if count > DISK_MAX_HITS:
            slot = int(rand(key, 16 + count) * count)
        if slot == 0:
            p0, t0 = p, t
        elif slot == 1:
            p1, t1 = p, t
        elif slot == 2:
            p2, t2 = p, t
        elif slot == 3:
            p3, t3 = p, t
    return count, p0, p1, p2, p3, t0, t1, t2, t3


@device
def disk_probe(lb, verts, tris, normals, normal_index, obj, sampler, wkey, mask, px, py, pz,
               ngx, ngy, ngz, backfacing, rr, rg, rb):
    """Christensen-Burley's exit from point p (geometric normal ng on the viewer's side) of
    object ``obj``, radius r per channel.

    Returns (found, exit triangle, exit point, its normal (the exit faces it), weight r, g,
    b): the factor on the path throughput.  The disk point and the resampling take the walk
    key's dimension set 0; the reservoir's choices beyond four surfaces are hashes.
    """
    u1, u2, u_resample, _ = sample_4d(sampler, wkey, 0, mask)
    nx, ny, nz, tx, ty, tz, bx, by, bz, pick_n, pick_t, pick_b, u2 = disk_axes(ngx, ngy, ngz, u2)
    disk_r, h = disk_sample(rr, rg, rb, u1)
    c, s = disk_r * math.cos(2.0 * math.pi * u2), disk_r * math.sin(2.0 * math.pi * u2)
    ox = px + nx * h + tx * c + bx * s
    oy = py + ny * h + ty * c + by * s
    oz = pz + nz * h + tz * c + bz * s
    dx, dy, dz = -nx, -ny, -nz
    count, p0, p1, p2, p3, t0, t1, t2, t3 = probe(lb, verts, tris, obj, ox, oy, oz, dx, dy, dz,
                                                  2.0 * h, wkey)
    if count == 0:
        return False, -1, px, py, pz, ngx, ngy, ngz, 0.0, 0.0, 0.0
    scale = count / DISK_MAX_HITS if count > DISK_MAX_HITS else 1.0
    kept = min(count, DISK_MAX_HITS)
    # Each kept surface's weight, then one of them resampled by its average weight.
    axes = (nx, ny, nz, tx, ty, tz, bx, by, bz)
    picks = (pick_n, pick_t, pick_b)
    radius = (rr, rg, rb)
    wr1 = wg1 = wb1 = wr2 = wg2 = wb2 = wr3 = wg3 = wb3 = 0.0
    wr0, wg0, wb0 = _hit_weight(normals, normal_index, verts, tris, p0, ox + t0 * dx, oy + t0 * dy, oz + t0 * dz,
                                px, py, pz, backfacing, axes, picks, scale, radius, disk_r)
    if kept > 1:
        wr1, wg1, wb1 = _hit_weight(normals, normal_index, verts, tris, p1, ox + t1 * dx, oy + t1 * dy,
                                    oz + t1 * dz, px, py, pz, backfacing, axes, picks, scale,
                                    radius, disk_r)
    if kept > 2:
        wr2, wg2, wb2 = _hit_weight(normals, normal_index, verts, tris, p2, ox + t2 * dx, oy + t2 * dy,
                                    oz + t2 * dz, px, py, pz, backfacing, axes, picks, scale,
                                    radius, disk_r)
    if kept > 3:
        wr3, wg3, wb3 = _hit_weight(normals, normal_index, verts, tris, p3, ox + t3 * dx, oy + t3 * dy,
                                    oz + t3 * dz, px, py, pz, backfacing, axes, picks, scale,
                                    radius, disk_r)
    s0 = abs(wr0 + wg0 + wb0) / 3.0
    s1 = abs(wr1 + wg1 + wb1) / 3.0
    s2 = abs(wr2 + wg2 + wb2) / 3.0
    s3 = abs(wr3 + wg3 + wb3) / 3.0
    total = s0 + s1 + s2 + s3
    if not total > 0.0:
        return False, -1, px, py, pz, ngx, ngy, ngz, 0.0, 0.0, 0.0
    u = u_resample * total
    if u < s0 or (s1 == 0.0 and s2 == 0.0 and s3 == 0.0):
        p, t, sw, wr, wg, wb = p0, t0, s0, wr0, wg0, wb0
    elif u < s0 + s1 or (s2 == 0.0 and s3 == 0.0):
        p, t, sw, wr, wg, wb = p1, t1, s1, wr1, wg1, wb1
    elif u < s0 + s1 + s2 or s3 == 0.0:
        p, t, sw, wr, wg, wb = p2, t2, s2, wr2, wg2, wb2
    else:
        p, t, sw, wr, wg, wb = p3, t3, s3, wr3, wg3, wb3
    k = total / sw
    gx, gy, gz = hit_normal(normals, normal_index, verts, tris, p, backfacing)
    return True, p, ox + t * dx, oy + t * dy, oz + t * dz, gx, gy, gz, wr * k, wg * k, wb * k
