"""Bevel (kernel/svm/bevel.h): the normals of the object's surfaces around the point, averaged,
so that its edges look rounded within the Radius.

Each of the node's samples casts one probe through a disk about the point, as a
Christensen-Burley subsurface probe does (``subsurface.probe``, on the object's own
hierarchy): the disk's axis is the geometric normal (half of the samples), the tangent or the
bitangent (a quarter each; Cycles' ``make_orthonormals`` frame, on which the result depends:
the MIS weight leaves out the other axes' disk densities), its radius drawn from the cubic
profile 10 (R - r)^3 / (pi R^5);
every surface of the object the probe crosses within twice the disk's height (four of them,
a uniform subset beyond four) adds its smooth normal weighted by the profile at its distance
over the disk's pdf and the power-heuristic MIS weight over the three axes.  The output is the
normalised sum (on the viewer's side), the shading normal when nothing was found.  A linked
Normal input is bent by the same amount: normalize(Normal + bevel - N).

As in Cycles, the node traces only where the surface shader is evaluated for a path (not for
shadow rays, light samples, displacement or the world: ``ShadingData.min_pdf`` 0; there it
gives the shading normal) and only while the path's smallest BSDF pdf is at least 8 (not
after a diffuse or rough bounce).  The samples' disk points are the first points of an
Owen-scrambled Sobol set per shading point (``sampling.branched_2d``), stratified as Cycles
stratifies them.  The hierarchy is the frame's triangles (``subsurface.LocalBVH``): a moving
object is bevelled as it is at the frame (warned).
"""
from __future__ import annotations

import math

from ...jit import device, function
from ..intersect import intersect_prim
from ..motion import corner_normals
from ..sampling import branched_2d, node_key
from ..subsurface import DISK_MAX_HITS, disk_axes, facing_corners, probe
from .nodes import OFFSETS

_RADIUS = OFFSETS["Bevel"]["Radius"]
_NORMAL = OFFSETS["Bevel"]["Normal"]
_SAMPLES = OFFSETS["Bevel"]["prop:samples"]
MIN_RAY_PDF = 8.0         # no bevel after a blurrier bounce (Cycles' "blurry indirect rays")
_NEWTON_STEPS = 10        # Cycles' svm_bevel_cubic_quintic_root_find
_NEWTON_TOLERANCE = 1e-6


@function
def bevel_node(regs, b, c, sd, tex, verts, tris, local):
    """Inputs at regs[b:] (Radius, Normal, samples), the bevelled normal to regs[c:]."""
    nx, ny, nz = sd.nx, sd.ny, sd.nz
    if sd.min_pdf > 0.0:
        nx, ny, nz = bevel_normal(regs[b + _RADIUS], int(regs[b + _SAMPLES]), sd, tex, verts,
                                  tris, local)
        rx, ry, rz = regs[b + _NORMAL], regs[b + _NORMAL + 1], regs[b + _NORMAL + 2]
        if rx != 0.0 or ry != 0.0 or rz != 0.0:      # a linked Normal keeps its own bend
            nx, ny, nz = rx + nx - sd.nx, ry + ny - sd.ny, rz + nz - sd.nz
            length = math.sqrt(nx * nx + ny * ny + nz * nz)
            if length > 0.0:
                nx, ny, nz = nx / length, ny / length, nz / length
    regs[c], regs[c + 1], regs[c + 2] = nx, ny, nz


@device
def _cubic_pdf(radius, r):
    """The cubic profile's density on the disk at distance r (0 beyond the radius)."""
    if r >= radius:
        return 0.0
    f = radius - r
    return 10.0 * f * f * f / (radius ** 5 * math.pi)


@device
def _cubic_radius(radius, xi):
    """The disk radius with cumulative probability xi under the cubic profile: Newton's
    method on 10 x^2 - 20 x^3 + 15 x^4 - 4 x^5 = xi, as Cycles solves it."""
    x = 0.25
    for _ in range(_NEWTON_STEPS):
        x2 = x * x
        x3 = x2 * x
        nx = 1.0 - x
        f = 10.0 * x2 - 20.0 * x3 + 15.0 * x2 * x2 - 4.0 * x2 * x3 - xi
        df = 20.0 * (x * nx) * (nx * nx)
        if abs(f) < _NEWTON_TOLERANCE or df == 0.0:
            break
        x = min(max(x - f / df, 0.0), 1.0)
    return x * radius


@function
def bevel_normal(radius, samples, sd, tex, verts, tris, local):
    """Cycles' svm_bevel: the averaged normal of the object's surfaces within ``radius`` of
    the point, from ``samples`` disk probes; the shading normal where it does not trace."""
    obj = sd.obj
    if (radius <= 0.0 or samples < 1 or obj < 0 or sd.prim < 0 or sd.min_pdf < MIN_RAY_PDF
            or obj >= local.root.shape[0]):
        return sd.nx, sd.ny, sd.nz
    normals, normal_index = tex.normals, tex.normal_index
    sx = sy = sz = 0.0
    for s in range(samples):
        u1, u2 = branched_2d(sd.rng, s)
        nx, ny, nz, tx, ty, tz, bx, by, bz, pick_n, pick_t, pick_b, u1 = disk_axes(
            sd.ngx, sd.ngy, sd.ngz, u1)
        disk_r = _cubic_radius(radius, u2)
        disk_pdf = _cubic_pdf(radius, disk_r)
        if not disk_pdf > 0.0:
            continue
        h = math.sqrt(max(radius * radius - disk_r * disk_r, 0.0))
        phi = 2.0 * math.pi * u1
        c, d = disk_r * math.cos(phi), disk_r * math.sin(phi)
        ox = sd.px + nx * h + tx * c + bx * d
        oy = sd.py + ny * h + ty * c + by * d
        oz = sd.pz + nz * h + tz * c + bz * d
        count, p0, p1, p2, p3, _, _, _, _ = probe(local, verts, tris, obj, ox, oy, oz, -nx, -ny,
                                                  -nz, 2.0 * h, node_key(sd.rng, s))
        scale = count / DISK_MAX_HITS if count > DISK_MAX_HITS else 1.0
        for k in range(min(count, DISK_MAX_HITS)):
            p = p0 if k == 0 else p1 if k == 1 else p2 if k == 2 else p3
            t, b1, b2 = intersect_prim(ox, oy, oz, -nx, -ny, -nz, verts, tris, p)
            if not math.isfinite(t):
                continue
            gx, gy, gz = _geometric_normal(verts, tris, normals, normal_index, p)
            pdf_n = pick_n * abs(nx * gx + ny * gy + nz * gz)
            pdf_t = pick_t * abs(tx * gx + ty * gy + tz * gz)
            pdf_b = pick_b * abs(bx * gx + by * gy + bz * gz)
            den = pdf_n * pdf_n + pdf_t * pdf_t + pdf_b * pdf_b
            if not den > 0.0:
                continue
            hx, hy, hz = ox - t * nx - sd.px, oy - t * ny - sd.py, oz - t * nz - sd.pz
            w = pdf_n / den * scale * _cubic_pdf(radius, math.sqrt(hx * hx + hy * hy + hz * hz)) \
                / disk_pdf
            mx, my, mz = _smooth_normal(normals, normal_index, p, b1, b2, gx, gy, gz)
            sx += w * mx
            sy += w * my
            sz += w * mz
    length = math.sqrt(sx * sx + sy * sy + sz * sz)
    if not length > 0.0:
        return sd.nx, sd.ny, sd.nz
    if sd.backfacing:
        length = -length
    return sx / length, sy / length, sz / length


@device
def _geometric_normal(verts, tris, normals, normal_index, p):
    """Unit normal of triangle p's plane on the object's outside (0 if degenerate)."""
    a, b, c = tris[p, 0], tris[p, 1], tris[p, 2]
    e1x, e1y, e1z = verts[b, 0] - verts[a, 0], verts[b, 1] - verts[a, 1], verts[b, 2] - verts[a, 2]
    e2x, e2y, e2z = verts[c, 0] - verts[a, 0], verts[c, 1] - verts[a, 1], verts[c, 2] - verts[a, 2]
    gx, gy, gz = e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x
    length = math.sqrt(gx * gx + gy * gy + gz * gz)
    if not length > 0.0:
        return 0.0, 0.0, 0.0
    return facing_corners(normals, normal_index, p, gx / length, gy / length, gz / length)


@device
def _smooth_normal(normals, normal_index, p, b1, b2, gx, gy, gz):
    """The corner normals of triangle p interpolated at barycentrics (b1, b2) and
    normalised; the geometric normal g where they cancel (Cycles' triangle_smooth_normal)."""
    b0 = 1.0 - b1 - b2
    n0x, n0y, n0z, n1x, n1y, n1z, n2x, n2y, n2z = corner_normals(normals, normal_index, p)
    x = b0 * n0x + b1 * n1x + b2 * n2x
    y = b0 * n0y + b1 * n1y + b2 * n2y
    z = b0 * n0z + b1 * n1z + b2 * n2z
    length = math.sqrt(x * x + y * y + z * z)
    if not length > 0.0:
        return gx, gy, gz
    return x / length, y / length, z / length
