"""The shading point: where a ray hit, the normals there, and the local frame.

Embree reports only which triangle a ray hit; the hit distance and
barycentrics are recomputed here in float64.  All BSDFs are two-sided, so the
normals are turned towards the incoming ray and ``backfacing`` remembers which
side was hit (it inverts the index of refraction).
"""
from __future__ import annotations

import math
from collections import namedtuple

from ..jit import device
from .intersect import intersect_prim, offset_scale
from .sampling import orthonormal_basis

SurfacePoint = namedtuple("SurfacePoint", [
    "hx", "hy", "hz",        # the hit point
    "ngx", "ngy", "ngz",     # unit geometric normal, facing the incoming ray
    "nsx", "nsy", "nsz",     # unit shading normal (interpolated), on the same side
    "cos_o",                 # cosine between the geometric normal and the way back (> 0)
    "backfacing",            # the ray came from the inside of the surface
])

Frame = namedtuple("Frame", [
    "tx", "ty", "tz",        # tangent
    "bx", "by", "bz",        # bitangent
    "wox", "woy", "woz",     # the way back to the viewer, in (t, b, ns) coordinates
])


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
def surface_point(verts, tris, tri_normal, normals, p, b1, b2, dx, dy, dz):
    """Hit point, geometric and shading normals facing the ray, and the side hit.

    Returns a :class:`SurfacePoint`.  All BSDFs are two-sided, so both normals are turned towards the incoming
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
    return SurfacePoint(hx, hy, hz, ngx, ngy, ngz, nsx, nsy, nsz, cos_o_geo, backfacing)


@device
def local_frame(nsx, nsy, nsz, dx, dy, dz):
    """Tangent frame around the shading normal and wo = -d in it (a :class:`Frame`)."""
    tx, ty, tz, bx, by, bz = orthonormal_basis(nsx, nsy, nsz)
    wox = -(dx * tx + dy * ty + dz * tz)
    woy = -(dx * bx + dy * by + dz * bz)
    woz = -(dx * nsx + dy * nsy + dz * nsz)
    return Frame(tx, ty, tz, bx, by, bz, wox, woy, woz)
