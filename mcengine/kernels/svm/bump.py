"""Bump: Cycles' finite-difference bump (kernel/svm/displace.h, bump.h, util/differential.h).

The compiler emits a Bump node's Height sub-graph three times: at the point, and at the
point moved by Filter Width times the ray differential's dPdx, then dPdy
(``OP_BUMP``: ``bump_point`` is the moved point; every texture coordinate follows from it,
as Cycles shifts P and each attribute by its x or y derivative).  The differentials
are Cycles' compact ones: a footprint ``sd.dp`` (ray_dP + t ray_dD) times the two unit
tangents ``make_orthonormals`` builds about the geometric normal.  The node then
combines the three heights as ``svm_node_set_bump`` does:

    R_x = dPdy x N, R_y = N x dPdx, det = dPdx . R_x,
    N' = normalize(w |det| N - d sign(det) ((h_x - h_c) R_x + (h_y - h_c) R_y)),
    out = normalize(s N' + (1 - s) N)

with N the Normal input (unlinked: the shading normal), d the Distance (negated by
Invert), w the filter width and s = max(Strength, 0); in object space (displacement
as bump with method 'BOTH') N and the differentials are taken to object space first.

On a truly displaced mesh ('Displacement and Bump') the bump the compiler makes of the
material's Displacement evaluates its heights where Cycles' svm_node_enter_bump_eval puts
them: at the point and normal before displacement, with the undisplaced triangle's
differentials (``undisplaced_point``); Bump nodes of the surface keep the displaced point.

The Displacement node (``svm_node_displacement``) gives N (h - midlevel) scale, in object
space N taken there and the vector brought back as a direction; the material output's
Displacement becomes a bump through the compiler (``shaders``: displacement as bump).
"""
from __future__ import annotations

import math

from ...jit import device, function
from ..sampling import make_orthonormals
from .data import OBJ_INVERSE, OBJ_MATRIX, ShadingData
from .input_nodes import attribute, normal_to_object, normal_to_world, transform_direction, transform_point
from .math_nodes import safe_normalize
from .nodes import OFFSETS, SPACE_OBJECT, SPACE_TANGENT, SPACE_WORLD

_BUMP_STRENGTH = OFFSETS["Bump"]["Strength"]
_BUMP_DISTANCE = OFFSETS["Bump"]["Distance"]
_BUMP_WIDTH = OFFSETS["Bump"]["Filter Width"]
_BUMP_HEIGHT = OFFSETS["Bump"]["Height"]
_BUMP_HEIGHT_DX = OFFSETS["Bump"]["Height_dx"]
_BUMP_HEIGHT_DY = OFFSETS["Bump"]["Height_dy"]
_BUMP_NORMAL = OFFSETS["Bump"]["Normal"]
_BUMP_INVERT = OFFSETS["Bump"]["prop:invert"]
_BUMP_OBJECT = OFFSETS["Bump"]["prop:use_object_space"]
_BUMP_STATE = OFFSETS["Bump"]["prop:state"]
_DISP_HEIGHT = OFFSETS["Displacement"]["Height"]
_DISP_MIDLEVEL = OFFSETS["Displacement"]["Midlevel"]
_DISP_SCALE = OFFSETS["Displacement"]["Scale"]
_DISP_NORMAL = OFFSETS["Displacement"]["Normal"]
_DISP_SPACE = OFFSETS["Displacement"]["prop:space"]
_VD_MIDLEVEL = OFFSETS["VectorDisplacement"]["Midlevel"]
_VD_SCALE = OFFSETS["VectorDisplacement"]["Scale"]
_VD_SPACE = OFFSETS["VectorDisplacement"]["prop:space"]
_VD_TANGENT = OFFSETS["VectorDisplacement"]["prop:attribute"]


@device
def differentials(sd):
    """dPdx, dPdy at the point from its compact footprint (differential_from_compact)."""
    ax, ay, az, bx, by, bz = make_orthonormals(sd.ngx, sd.ngy, sd.ngz)
    d = sd.dp
    return d * ax, d * ay, d * az, d * bx, d * by, d * bz


@device
def barycentric_step(sd, verts, tris, ex, ey, ez):
    """(du, dv) with e = du e1 + dv e2 in the plane of the point's triangle (Cramer's rule
    about its normal); (0, 0) off a triangle."""
    p = sd.prim
    if p < 0:
        return 0.0, 0.0
    t = tris[p]
    v0, v1, v2 = verts[t[0]], verts[t[1]], verts[t[2]]
    e1x, e1y, e1z = v1[0] - v0[0], v1[1] - v0[1], v1[2] - v0[2]
    e2x, e2y, e2z = v2[0] - v0[0], v2[1] - v0[1], v2[2] - v0[2]
    nx, ny, nz = e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x
    den = nx * nx + ny * ny + nz * nz
    if den <= 0.0:
        return 0.0, 0.0
    # On a back face Cycles has negated dPdu and dPdv before solving for du, dv, so
    # its attributes (UV maps, colours, the Texture Coordinate's Normal) move the
    # other way than P: kept, to agree with it.
    sign = -1.0 if sd.backfacing else 1.0
    return (sign * ((ey * e2z - ez * e2y) * nx + (ez * e2x - ex * e2z) * ny + (ex * e2y - ey * e2x) * nz) / den,
            sign * ((e1y * ez - e1z * ey) * nx + (e1z * ex - e1x * ez) * ny + (e1x * ey - e1y * ex) * nz) / den)


@device
def dpdv_node(regs, c, sd, verts, tris):
    """The point's dPdv (Cycles' sd->dPdv: the triangle's third vertex less its first, negated
    on a back face), normalised, to regs[c:]; zero off a triangle."""
    regs[c] = regs[c + 1] = regs[c + 2] = 0.0
    p = sd.prim
    if p < 0:
        return
    t = tris[p]
    v0, v2 = verts[t[0]], verts[t[2]]
    x, y, z = v2[0] - v0[0], v2[1] - v0[1], v2[2] - v0[2]
    length = math.sqrt(x * x + y * y + z * z)
    if not length > 0.0:
        return
    s = (-1.0 if sd.backfacing else 1.0) / length
    regs[c], regs[c + 1], regs[c + 2] = x * s, y * s, z * s


@function
def bump_point(sd, verts, tris, width, axis):
    """The shading point moved by ``width`` times dPdx (axis 1) or dPdy (axis 2), with its
    barycentrics on the triangle: what a Bump node's Height sees in its x or y sample."""
    xx, xy, xz, yx, yy, yz = differentials(sd)
    if axis == 1:
        ex, ey, ez = width * xx, width * xy, width * xz
    else:
        ex, ey, ez = width * yx, width * yy, width * yz
    du, dv = barycentric_step(sd, verts, tris, ex, ey, ez)
    return ShadingData(sd.px + ex, sd.py + ey, sd.pz + ez, sd.nx, sd.ny, sd.nz, sd.ngx, sd.ngy, sd.ngz,
                       sd.wox, sd.woy, sd.woz, sd.backfacing, sd.allocate, sd.reflective_caustics,
                       sd.refractive_caustics, sd.bump_correction, sd.prim, sd.u + du, sd.v + dv, sd.obj,
                       sd.path_flags, sd.ray_length, sd.depth, sd.diffuse_depth, sd.glossy_depth,
                       sd.transmission_depth, sd.transparent_depth, sd.dp, sd.rng, sd.min_pdf)


# A Bump node's state block on truly displaced meshes (register b of its ``OP_BUMP`` rows
# with ``BUMP_UNDISPLACED`` set, and its prop:state): the filter width, the offsets of the
# undisplaced point and normal attributes (``mcengine.displacement``), then what its Height's
# evaluations found there for ``bump_normal``: the undisplaced dPdx, dPdy and normal (a zero
# normal: the point is not on a displaced mesh).
BS_WIDTH = 0
BS_POINT = 1
BS_NORMAL = 2
BS_DPDX = 3
BS_DPDY = 6
BS_N = 9
BS_SIZE = 12


@function
def undisplaced_point(sd, verts, tris, regs, s, axis, tex):
    """What a Bump node's Height sees on a truly displaced mesh, as Cycles'
    svm_node_enter_bump_eval sets it up: the point and normal before displacement (the
    attributes named in state block ``s``), the compact ray differential of the undisplaced
    triangle, moved along dPdx (axis 1) or dPdy (axis 2) by the filter width as
    ``bump_point`` moves the displaced point (Cycles' svm_node_bump_P_dx keeps the hit
    triangle's dPdu and du).  Records the undisplaced dPdx, dPdy and normal in the block.  On a
    mesh without true displacement (the attribute's flag 0) the point is ``bump_point``'s
    (axis 0: ``sd`` itself) and the recorded normal zero."""
    p = sd.prim
    off_p = int(regs[s + BS_POINT])
    off_n = int(regs[s + BS_NORMAL])
    width = regs[s + BS_WIDTH]
    if p < 0 or sd.obj < 0 or off_p < 0 or tex.attr[p, 0, off_p + 3] <= 0.0:
        regs[s + BS_N] = regs[s + BS_N + 1] = regs[s + BS_N + 2] = 0.0
        if axis == 0:
            return sd
        return bump_point(sd, verts, tris, width, axis)
    row = tex.objects[sd.obj]
    xx, xy, xz, yx, yy, yz = differentials(sd)
    dua, dva = barycentric_step(sd, verts, tris, xx, xy, xz)
    dub, dvb = barycentric_step(sd, verts, tris, yx, yy, yz)
    a = tex.attr
    c0x, c0y, c0z = float(a[p, 0, off_p]), float(a[p, 0, off_p + 1]), float(a[p, 0, off_p + 2])
    e1x, e1y, e1z = float(a[p, 1, off_p]) - c0x, float(a[p, 1, off_p + 1]) - c0y, float(a[p, 1, off_p + 2]) - c0z
    e2x, e2y, e2z = float(a[p, 2, off_p]) - c0x, float(a[p, 2, off_p + 1]) - c0y, float(a[p, 2, off_p + 2]) - c0z
    u, v = sd.u, sd.v
    px, py, pz = transform_point(row, OBJ_MATRIX, c0x + u * e1x + v * e2x, c0y + u * e1y + v * e2y,
                                 c0z + u * e1z + v * e2z)
    dxx, dxy, dxz = transform_direction(row, OBJ_MATRIX, dua * e1x + dva * e2x, dua * e1y + dva * e2y,
                                        dua * e1z + dva * e2z)
    dyx, dyy, dyz = transform_direction(row, OBJ_MATRIX, dub * e1x + dvb * e2x, dub * e1y + dvb * e2y,
                                        dub * e1z + dvb * e2z)
    nx, ny, nz, _ = attribute(tex, sd, off_n, 3)
    nx, ny, nz = normal_to_world(row, nx, ny, nz)
    if sd.backfacing:
        nx, ny, nz = -nx, -ny, -nz
    regs[s + BS_DPDX], regs[s + BS_DPDX + 1], regs[s + BS_DPDX + 2] = dxx, dxy, dxz
    regs[s + BS_DPDY], regs[s + BS_DPDY + 1], regs[s + BS_DPDY + 2] = dyx, dyy, dyz
    regs[s + BS_N], regs[s + BS_N + 1], regs[s + BS_N + 2] = nx, ny, nz
    dp = 0.5 * (math.sqrt(dxx * dxx + dxy * dxy + dxz * dxz) + math.sqrt(dyx * dyx + dyy * dyy + dyz * dyz))
    # The heights' offsets are the displaced triangle's (Cycles' dPdu du.dx + dPdv dv.dx, its
    # barycentric steps unchanged by the bump evaluation): the same as bump_point's.
    ex = ey = ez = du = dv = 0.0
    if axis == 1:
        ex, ey, ez, du, dv = width * xx, width * xy, width * xz, width * dua, width * dva
    elif axis == 2:
        ex, ey, ez, du, dv = width * yx, width * yy, width * yz, width * dub, width * dvb
    return ShadingData(px + ex, py + ey, pz + ez, nx, ny, nz, sd.ngx, sd.ngy, sd.ngz,
                       sd.wox, sd.woy, sd.woz, sd.backfacing, sd.allocate, sd.reflective_caustics,
                       sd.refractive_caustics, sd.bump_correction, sd.prim, u + du, v + dv, sd.obj,
                       sd.path_flags, sd.ray_length, sd.depth, sd.diffuse_depth, sd.glossy_depth,
                       sd.transmission_depth, sd.transparent_depth, dp, sd.rng, sd.min_pdf)


@device
def with_normal(sd, nx, ny, nz):
    """``sd`` with shading normal n: displacement as bump sets it before the surface runs."""
    return ShadingData(sd.px, sd.py, sd.pz, nx, ny, nz, sd.ngx, sd.ngy, sd.ngz,
                       sd.wox, sd.woy, sd.woz, sd.backfacing, sd.allocate, sd.reflective_caustics,
                       sd.refractive_caustics, sd.bump_correction, sd.prim, sd.u, sd.v, sd.obj,
                       sd.path_flags, sd.ray_length, sd.depth, sd.diffuse_depth, sd.glossy_depth,
                       sd.transmission_depth, sd.transparent_depth, sd.dp, sd.rng, sd.min_pdf)


@function
def bump_normal(regs, b, sd, tex):
    """Cycles' svm_node_set_bump: the bumped normal from the three heights."""
    nx, ny, nz = regs[b + _BUMP_NORMAL], regs[b + _BUMP_NORMAL + 1], regs[b + _BUMP_NORMAL + 2]
    state = int(regs[b + _BUMP_STATE])
    undisplaced = state >= 0 and (regs[state + BS_N] != 0.0 or regs[state + BS_N + 1] != 0.0
                                  or regs[state + BS_N + 2] != 0.0)
    if nx == 0.0 and ny == 0.0 and nz == 0.0:
        if undisplaced:
            # Cycles' bump evaluation left the undisplaced normal in sd->N.
            nx, ny, nz = regs[state + BS_N], regs[state + BS_N + 1], regs[state + BS_N + 2]
        else:
            nx, ny, nz = sd.nx, sd.ny, sd.nz
    if undisplaced:
        xx, xy, xz = regs[state + BS_DPDX], regs[state + BS_DPDX + 1], regs[state + BS_DPDX + 2]
        yx, yy, yz = regs[state + BS_DPDY], regs[state + BS_DPDY + 1], regs[state + BS_DPDY + 2]
    else:
        xx, xy, xz, yx, yy, yz = differentials(sd)
    object_space = regs[b + _BUMP_OBJECT] != 0.0 and sd.obj >= 0
    if object_space:
        row = tex.objects[sd.obj]
        nx, ny, nz = normal_to_object(row, nx, ny, nz)
        xx, xy, xz = transform_direction(row, OBJ_INVERSE, xx, xy, xz)
        yx, yy, yz = transform_direction(row, OBJ_INVERSE, yx, yy, yz)
    rxx, rxy, rxz = yy * nz - yz * ny, yz * nx - yx * nz, yx * ny - yy * nx
    ryx, ryy, ryz = ny * xz - nz * xy, nz * xx - nx * xz, nx * xy - ny * xx
    h_c = regs[b + _BUMP_HEIGHT]
    dhx = regs[b + _BUMP_HEIGHT_DX] - h_c
    dhy = regs[b + _BUMP_HEIGHT_DY] - h_c
    det = xx * rxx + xy * rxy + xz * rxz
    scale = regs[b + _BUMP_DISTANCE]
    if regs[b + _BUMP_INVERT] != 0.0:
        scale = -scale
    strength = max(regs[b + _BUMP_STRENGTH], 0.0)
    k = scale * (-1.0 if det < 0.0 else 1.0)
    m = regs[b + _BUMP_WIDTH] * abs(det)
    ox, oy, oz = safe_normalize(m * nx - k * (dhx * rxx + dhy * ryx), m * ny - k * (dhx * rxy + dhy * ryy),
                                m * nz - k * (dhx * rxz + dhy * ryz))
    if (ox == 0.0 and oy == 0.0 and oz == 0.0) or not (math.isfinite(ox) and math.isfinite(oy)
                                                         and math.isfinite(oz)):
        ox, oy, oz = nx, ny, nz
    else:
        ox, oy, oz = safe_normalize(strength * ox + (1.0 - strength) * nx, strength * oy + (1.0 - strength) * ny,
                                    strength * oz + (1.0 - strength) * nz)
    if object_space:
        ox, oy, oz = normal_to_world(tex.objects[sd.obj], ox, oy, oz)
    return ox, oy, oz


@function
def displacement(regs, b, sd, tex):
    """Cycles' svm_node_displacement: the displacement vector (world space)."""
    nx, ny, nz = regs[b + _DISP_NORMAL], regs[b + _DISP_NORMAL + 1], regs[b + _DISP_NORMAL + 2]
    if nx == 0.0 and ny == 0.0 and nz == 0.0:
        nx, ny, nz = sd.nx, sd.ny, sd.nz
    f = (regs[b + _DISP_HEIGHT] - regs[b + _DISP_MIDLEVEL]) * regs[b + _DISP_SCALE]
    if int(regs[b + _DISP_SPACE]) == SPACE_OBJECT and sd.obj >= 0:
        row = tex.objects[sd.obj]
        nx, ny, nz = normal_to_object(row, nx, ny, nz)
        return transform_direction(row, OBJ_MATRIX, nx * f, ny * f, nz * f)
    return nx * f, ny * f, nz * f


@device
def vector_displacement(regs, b, sd, tex):
    """Cycles' svm_node_vector_displacement: (Vector - Midlevel) x Scale, in world space.

    Tangent space: x along the default UV map's tangent, y along the shading normal (taken
    to object space), z along the bitangent normalize(N x T) times the tangent's sign;
    tangent and object space are then brought to world space by the object's matrix (a
    direction).  Without a tangent (no UV map, or no triangle) a tangent-space vector is
    left in object space."""
    m, s = regs[b + _VD_MIDLEVEL], regs[b + _VD_SCALE]
    x, y, z = (regs[b] - m) * s, (regs[b + 1] - m) * s, (regs[b + 2] - m) * s
    space = int(regs[b + _VD_SPACE])
    if space == SPACE_WORLD or sd.obj < 0:
        return x, y, z
    row = tex.objects[sd.obj]
    off = int(regs[b + _VD_TANGENT])
    if space == SPACE_TANGENT and off >= 0 and sd.prim >= 0:
        nx, ny, nz = normal_to_object(row, sd.nx, sd.ny, sd.nz)
        tx, ty, tz, sign = attribute(tex, sd, off, 4)
        bx, by, bz = safe_normalize(ny * tz - nz * ty, nz * tx - nx * tz, nx * ty - ny * tx)
        bx, by, bz = sign * bx, sign * by, sign * bz
        x, y, z = (tx * x + nx * y + bx * z, ty * x + ny * y + by * z, tz * x + nz * y + bz * z)
    return transform_direction(row, OBJ_MATRIX, x, y, z)
