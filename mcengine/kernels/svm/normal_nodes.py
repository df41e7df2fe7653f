"""Normal nodes: a perturbed shading normal for the closures (kernel/svm/tex_coord.h).

Normal Map works as Cycles does, in object space: the MikkTSpace tangent and
sign of the UV map (per-corner attribute ``tangent:<uv map>``, object space, as
Blender's ``Mesh.calc_tangents`` gives them), the interpolated, *unnormalised*
vertex normal in object space, N' = normalize(c.x T + c.y B + c.z n) with
B = sign (n x T) and c = 2 (Color - 0.5), then to world space by the normal
transform.  Object and World spaces take c as the normal itself.  Anything
zero or not finite falls back to the shading normal.
"""
from __future__ import annotations

import math

from ...jit import device, function
from .data import OBJ_INVERSE, OBJ_MATRIX
from .nodes import (
    NODES,
    OFFSETS,
    SPACE_BLENDER_OBJECT,
    SPACE_BLENDER_WORLD,
    SPACE_OBJECT,
    SPACE_TANGENT,
)

_NORMAL_MAP = NODES["NormalMap"].code
_NM_STRENGTH = OFFSETS["NormalMap"]["Strength"]
_NM_COLOR = OFFSETS["NormalMap"]["Color"]
_NM_SPACE = OFFSETS["NormalMap"]["prop:space"]
_NM_TANGENT = OFFSETS["NormalMap"]["prop:attribute"]


@function
def eval_normal_node(code, regs, b, c, sd, tex):
    if code == _NORMAL_MAP:
        x, y, z = normal_map(regs, b, sd, tex)
        regs[c], regs[c + 1], regs[c + 2] = x, y, z


@device
def _normalize(x, y, z):
    """x / |x|, or zeros when |x| is zero (Cycles' safe_normalize)."""
    length = math.sqrt(x * x + y * y + z * z)
    if not length > 0.0:
        return 0.0, 0.0, 0.0
    return x / length, y / length, z / length


@device
def _to_object(o, x, y, z):
    """World normal -> object space, normalised (M^T n; Cycles' object_inverse_normal_transform)."""
    return _normalize(o[OBJ_MATRIX] * x + o[OBJ_MATRIX + 4] * y + o[OBJ_MATRIX + 8] * z,
                      o[OBJ_MATRIX + 1] * x + o[OBJ_MATRIX + 5] * y + o[OBJ_MATRIX + 9] * z,
                      o[OBJ_MATRIX + 2] * x + o[OBJ_MATRIX + 6] * y + o[OBJ_MATRIX + 10] * z)


@device
def _to_world(o, x, y, z):
    """Object normal -> world space, normalised (M^-T n; Cycles' object_normal_transform)."""
    return _normalize(o[OBJ_INVERSE] * x + o[OBJ_INVERSE + 4] * y + o[OBJ_INVERSE + 8] * z,
                      o[OBJ_INVERSE + 1] * x + o[OBJ_INVERSE + 5] * y + o[OBJ_INVERSE + 9] * z,
                      o[OBJ_INVERSE + 2] * x + o[OBJ_INVERSE + 6] * y + o[OBJ_INVERSE + 10] * z)


@device
def normal_map(regs, b, sd, tex):
    """Cycles' svm_node_normal_map: the perturbed world normal, on the viewer's side."""
    cx = 2.0 * (regs[b + _NM_COLOR] - 0.5)
    cy = 2.0 * (regs[b + _NM_COLOR + 1] - 0.5)
    cz = 2.0 * (regs[b + _NM_COLOR + 2] - 0.5)
    strength = regs[b + _NM_STRENGTH]
    space = int(regs[b + _NM_SPACE])
    linear_strength = True
    if space == SPACE_TANGENT:
        off = int(regs[b + _NM_TANGENT])
        p = sd.prim
        if p < 0 or sd.obj < 0 or off < 0:
            return sd.nx, sd.ny, sd.nz
        o = tex.objects[sd.obj]
        b0, b1, b2 = 1.0 - sd.u - sd.v, sd.u, sd.v
        a = tex.attr
        tx = b0 * float(a[p, 0, off]) + b1 * float(a[p, 1, off]) + b2 * float(a[p, 2, off])
        ty = b0 * float(a[p, 0, off + 1]) + b1 * float(a[p, 1, off + 1]) + b2 * float(a[p, 2, off + 1])
        tz = b0 * float(a[p, 0, off + 2]) + b1 * float(a[p, 1, off + 2]) + b2 * float(a[p, 2, off + 2])
        sign = b0 * float(a[p, 0, off + 3]) + b1 * float(a[p, 1, off + 3]) + b2 * float(a[p, 2, off + 3])
        # The unnormalised interpolation of the corner normals, each in object space.
        nx = ny = nz = 0.0
        for k in range(3):
            w = b0 if k == 0 else (b1 if k == 1 else b2)
            x, y, z = _to_object(o, float(tex.normals[p, k, 0]), float(tex.normals[p, k, 1]),
                                 float(tex.normals[p, k, 2]))
            nx += w * x
            ny += w * y
            nz += w * z
        if nx == 0.0 and ny == 0.0 and nz == 0.0:
            nx, ny, nz = _to_object(o, sd.ngx, sd.ngy, sd.ngz)
        cx *= strength
        cy *= strength
        cz = 1.0 + (cz - 1.0) * min(max(strength, 0.0), 1.0)
        bx, by, bz = sign * (ny * tz - nz * ty), sign * (nz * tx - nx * tz), sign * (nx * ty - ny * tx)
        x, y, z = _normalize(cx * tx + cy * bx + cz * nx, cx * ty + cy * by + cz * ny,
                             cx * tz + cy * bz + cz * nz)
        x, y, z = _to_world(o, x, y, z)
        linear_strength = False
    else:
        if space == SPACE_BLENDER_OBJECT or space == SPACE_BLENDER_WORLD:
            cy, cz = -cy, -cz
        if (space == SPACE_OBJECT or space == SPACE_BLENDER_OBJECT) and sd.obj >= 0:
            x, y, z = _to_world(tex.objects[sd.obj], cx, cy, cz)
        else:
            x, y, z = _normalize(cx, cy, cz)
    if sd.backfacing:
        x, y, z = -x, -y, -z
    if linear_strength and strength != 1.0:
        s = max(strength, 0.0)
        x, y, z = _normalize(sd.nx + (x - sd.nx) * s, sd.ny + (y - sd.ny) * s, sd.nz + (z - sd.nz) * s)
    if (x == 0.0 and y == 0.0 and z == 0.0) or not (math.isfinite(x) and math.isfinite(y)
                                                      and math.isfinite(z)):
        return sd.nx, sd.ny, sd.nz
    return x, y, z
