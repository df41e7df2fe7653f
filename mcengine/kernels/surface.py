"""The shading point: where a ray hit, the normals there, and the local frame.

Embree reports only which triangle a ray hit; the hit distance and
barycentrics are recomputed here in float64, from the triangle as it is at
the path's time (``intersect.prim_corners``: moving objects move).  All BSDFs
are two-sided, so the normals are turned towards the incoming ray and
``backfacing`` remembers which side was hit (it inverts the index of
refraction).
"""
from __future__ import annotations

import math
from collections import namedtuple

from ..jit import device
from .intersect import intersect_triangle, offset_scale, prim_corners, prim_frame, prim_normals
from .sampling import orthonormal_basis

SurfacePoint = namedtuple("SurfacePoint", [
    "hx", "hy", "hz",        # the hit point
    "ngx", "ngy", "ngz",     # unit geometric normal, facing the incoming ray
    "nsx", "nsy", "nsz",     # unit shading normal (interpolated), on the same side
    "cos_o",                 # cosine between the geometric normal and the way back (> 0)
    "backfacing",            # the ray came from the inside of the surface
    "area",                  # area of the triangle (at the path's time, for a moving one)
    "time",                  # the path's time over the shutter (0.5 without motion blur)
    "prim", "b1", "b2",      # the triangle hit and the barycentrics of its 2nd and 3rd corners
])

Frame = namedtuple("Frame", [
    "tx", "ty", "tz",        # tangent
    "bx", "by", "bz",        # bitangent
    "wox", "woy", "woz",     # the way back to the viewer, in (t, b, ns) coordinates
])


@device
def past_self_hit(sc, p, ox, oy, oz, dx, dy, dz, time):
    """Distance to move a ray that re-hit the triangle it left, to just past that hit.

    Triangles are flat, so a ray leaving one can only hit it again through
    rounding: the ray continues from just past that hit.
    """
    ax, ay, az, bx, by, bz, cx, cy, cz = prim_corners(sc, p, time)
    t, b1, b2 = intersect_triangle(ox, oy, oz, dx, dy, dz, ax, ay, az, bx, by, bz, cx, cy, cz)
    if not math.isfinite(t) or t < 0.0:
        t = 0.0
    return t + offset_scale(ox + t * dx, oy + t * dy, oz + t * dz) * 4.0


@device
def hit_distance(sc, p, ox, oy, oz, dx, dy, dz, tmax, time):
    """(t, b1, b2) of the ray's hit on triangle p at ``time`` (t = tmax if p < 0)."""
    if p < 0:
        return tmax, 0.0, 0.0
    ax, ay, az, bx, by, bz, cx, cy, cz = prim_corners(sc, p, time)
    t, b1, b2 = intersect_triangle(ox, oy, oz, dx, dy, dz, ax, ay, az, bx, by, bz, cx, cy, cz)
    return (t if (math.isfinite(t) and t > 0.0) else 0.0), b1, b2


@device
def surface_point(sc, p, b1, b2, dx, dy, dz, time):
    """Hit point, geometric and shading normals facing the ray, and the side hit.

    Returns a :class:`SurfacePoint`, triangle p taken as it is at ``time``.  All
    BSDFs are two-sided, so both normals are turned towards the incoming
    ray; ``backfacing`` records that the ray came from the inside (relative to
    the winding, or to the shading normals where they disagree with it).
    """
    b0 = 1.0 - b1 - b2
    ax, ay, az, bx, by, bz, cx, cy, cz = prim_corners(sc, p, time)
    hx = b0 * ax + b1 * bx + b2 * cx
    hy = b0 * ay + b1 * by + b2 * cy
    hz = b0 * az + b1 * bz + b2 * cz
    ngx, ngy, ngz, area = prim_frame(sc, p, time)
    n0x, n0y, n0z, n1x, n1y, n1z, n2x, n2y, n2z = prim_normals(sc, p, time)
    nsx = b0 * n0x + b1 * n1x + b2 * n2x
    nsy = b0 * n0y + b1 * n1y + b2 * n2y
    nsz = b0 * n0z + b1 * n1z + b2 * n2z
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
    return SurfacePoint(hx, hy, hz, ngx, ngy, ngz, nsx, nsy, nsz, cos_o_geo, backfacing, area, time,
                        p, b1, b2)


@device
def smooth_surface_offset(sc, sp, ngx, ngy, ngz):
    """Cycles' shadow_ray_smooth_surface_offset: from the flat triangle at ``sp`` to the
    curved surface its corner normals describe (a parabola through the corners, bounded by
    the corners' tangent planes), along the interpolated corner normal; ng is the geometric
    normal on the side the shadow ray leaves to.  Zero on a flat-shaded triangle (its
    corner normals are its plane's)."""
    ax, ay, az, bx, by, bz, cx, cy, cz = prim_corners(sc, sp.prim, sp.time)
    n0x, n0y, n0z, n1x, n1y, n1z, n2x, n2y, n2z = prim_normals(sc, sp.prim, sp.time)
    u, v, w = 1.0 - sp.b1 - sp.b2, sp.b1, sp.b2
    px, py, pz = u * ax + v * bx + w * cx, u * ay + v * by + w * cy, u * az + v * bz + w * cz
    nx, ny, nz = u * n0x + v * n1x + w * n2x, u * n0y + v * n1y + w * n2y, u * n0z + v * n1z + w * n2z
    qa = (n2x - n0x) * (ax - cx) + (n2y - n0y) * (ay - cy) + (n2z - n0z) * (az - cz)
    qb = (n2x - n1x) * (bx - cx) + (n2y - n1y) * (by - cy) + (n2z - n1z) * (bz - cz)
    qc = (n1x - n0x) * (bx - ax) + (n1y - n0y) * (by - ay) + (n1z - n0z) * (bz - az)
    h = qa * u * (u - 1.0) + (qa + qb + qc) * u * v + qb * v * (v - 1.0)
    # Tangent-plane envelope: how far each corner's plane lies above the point.
    ab0 = (bx - ax) * n0x + (by - ay) * n0y + (bz - az) * n0z
    ac0 = (cx - ax) * n0x + (cy - ay) * n0y + (cz - az) * n0z
    ba1 = (ax - bx) * n1x + (ay - by) * n1y + (az - bz) * n1z
    bc1 = (cx - bx) * n1x + (cy - by) * n1y + (cz - bz) * n1z
    ca2 = (ax - cx) * n2x + (ay - cy) * n2y + (az - cz) * n2z
    cb2 = (bx - cx) * n2x + (by - cy) * n2y + (bz - cz) * n2z
    d0 = (ax - px) * n0x + (ay - py) * n0y + (az - pz) * n0z
    d1 = (bx - px) * n1x + (by - py) * n1y + (bz - pz) * n1z
    d2 = (cx - px) * n2x + (cy - py) * n2y + (cz - pz) * n2z
    if nx * ngx + ny * ngy + nz * ngz > 0.0:
        h0 = max(d0 + max(max(ab0, ac0), 0.0), 0.0)
        h1 = max(d1 + max(max(ba1, bc1), 0.0), 0.0)
        h2 = max(d2 + max(max(ca2, cb2), 0.0), 0.0)
        h = max(min(min(h0, h1), h2), 0.5 * h)
    else:
        h0 = max(-d0 + max(max(-ab0, -ac0), 0.0), 0.0)
        h1 = max(-d1 + max(max(-ba1, -bc1), 0.0), 0.0)
        h2 = max(-d2 + max(max(-ca2, -cb2), 0.0), 0.0)
        h = min(-min(min(h0, h1), h2), 0.5 * h)
    return nx * h, ny * h, nz * h


@device
def local_frame(nsx, nsy, nsz, dx, dy, dz):
    """Tangent frame around the shading normal and wo = -d in it (a :class:`Frame`)."""
    tx, ty, tz, bx, by, bz = orthonormal_basis(nsx, nsy, nsz)
    wox = -(dx * tx + dy * ty + dz * tz)
    woy = -(dx * bx + dy * by + dz * bz)
    woz = -(dx * nsx + dy * nsy + dz * nsz)
    return Frame(tx, ty, tz, bx, by, bz, wox, woy, woz)
