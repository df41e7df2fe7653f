"""Normal nodes: a perturbed shading normal for the closures (kernel/svm/tex_coord.h);
Bump, Displacement and Vector Displacement are in ``bump.py``.

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

from ...jit import deref, device, function
from .bump import bump_normal, displacement, vector_displacement
from .input_nodes import attribute, normal_to_object, normal_to_world
from .math_nodes import safe_normalize
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
_BUMP = NODES["Bump"].code
_DISPLACEMENT = NODES["Displacement"].code
_VECTOR_DISPLACEMENT = NODES["VectorDisplacement"].code


@function
def eval_normal_node(code, regs, b, c, sd_ref, tex_ref):
    """A node of normals and displacement: inputs at regs[b:], outputs to regs[c:]; the point
    and the texture data by reference (``jit.by_ref``)."""
    sd, tex = deref(sd_ref), deref(tex_ref)
    if code == _NORMAL_MAP:
        x, y, z = normal_map(regs, b, sd, tex)
        regs[c], regs[c + 1], regs[c + 2] = x, y, z
    elif code == _BUMP:
        x, y, z = bump_normal(regs, b, sd, tex)
        regs[c], regs[c + 1], regs[c + 2] = x, y, z
    elif code == _DISPLACEMENT:
        x, y, z = displacement(regs, b, sd, tex)
        regs[c], regs[c + 1], regs[c + 2] = x, y, z
    elif code == _VECTOR_DISPLACEMENT:
        x, y, z = vector_displacement(regs, b, sd, tex)
        regs[c], regs[c + 1], regs[c + 2] = x, y, z


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
        tx, ty, tz, sign = attribute(tex, sd, off, 4)
        # The unnormalised interpolation of the corner normals, each in object space.
        b0, b1, b2 = 1.0 - sd.u - sd.v, sd.u, sd.v
        nx = ny = nz = 0.0
        for k in range(3):
            w = b0 if k == 0 else (b1 if k == 1 else b2)
            row = tex.normal_index[p, k]
            x, y, z = normal_to_object(o, float(tex.normals[row, 0]), float(tex.normals[row, 1]),
                                       float(tex.normals[row, 2]))
            nx += w * x
            ny += w * y
            nz += w * z
        if nx == 0.0 and ny == 0.0 and nz == 0.0:
            nx, ny, nz = normal_to_object(o, sd.ngx, sd.ngy, sd.ngz)
        cx *= strength
        cy *= strength
        cz = 1.0 + (cz - 1.0) * min(max(strength, 0.0), 1.0)
        bx, by, bz = sign * (ny * tz - nz * ty), sign * (nz * tx - nx * tz), sign * (nx * ty - ny * tx)
        x, y, z = safe_normalize(cx * tx + cy * bx + cz * nx, cx * ty + cy * by + cz * ny,
                                 cx * tz + cy * bz + cz * nz)
        x, y, z = normal_to_world(o, x, y, z)
        linear_strength = False
    else:
        if space == SPACE_BLENDER_OBJECT or space == SPACE_BLENDER_WORLD:
            cy, cz = -cy, -cz
        if (space == SPACE_OBJECT or space == SPACE_BLENDER_OBJECT) and sd.obj >= 0:
            x, y, z = normal_to_world(tex.objects[sd.obj], cx, cy, cz)
        else:
            x, y, z = safe_normalize(cx, cy, cz)
    if sd.backfacing:
        x, y, z = -x, -y, -z
    if linear_strength and strength != 1.0:
        s = max(strength, 0.0)
        x, y, z = safe_normalize(sd.nx + (x - sd.nx) * s, sd.ny + (y - sd.ny) * s, sd.nz + (z - sd.nz) * s)
    if (x == 0.0 and y == 0.0 and z == 0.0) or not (math.isfinite(x) and math.isfinite(y)
                                                      and math.isfinite(z)):
        return sd.nx, sd.ny, sd.nz
    return x, y, z
