"""Vector nodes: Mapping (kernel/svm/mapping.h, mapping_util.h), Vector Rotate
(kernel/svm/vector_rotate.h), Vector Transform (kernel/svm/vector_transform.h) and
Normal (kernel/svm/normal.h).

``eval_vector_node`` evaluates one node of the family: inputs at regs[b:] in
the order of ``nodes.VALUE_NODES``, outputs to regs[c:].
"""
from __future__ import annotations

import math

from ...jit import deref, device, function
from ..camera import C_FWD, C_POS, C_RIGHT, C_UP
from .data import OBJ_INVERSE, OBJ_MATRIX
from .input_nodes import (
    camera_axes,
    camera_space,
    normal_to_object,
    normal_to_world,
    transform_direction,
    transform_point,
)
from .math_nodes import rotate_around_axis, safe_divide, safe_normalize
from .nodes import (
    NODES,
    OFFSETS,
    ROTATE_EULER_XYZ,
    ROTATE_X,
    ROTATE_Y,
    ROTATE_Z,
    TRANSFORM_SPACES,
    VECTOR_TYPES,
)

_MAPPING = NODES["Mapping"].code
_VECTOR_ROTATE = NODES["VectorRotate"].code
_VR_CENTER = OFFSETS["VectorRotate"]["Center"]
_VR_AXIS = OFFSETS["VectorRotate"]["Axis"]
_VR_ANGLE = OFFSETS["VectorRotate"]["Angle"]
_VR_ROTATION = OFFSETS["VectorRotate"]["Rotation"]
_VR_TYPE = OFFSETS["VectorRotate"]["prop:rotation_type"]
_VR_INVERT = OFFSETS["VectorRotate"]["prop:invert"]
_VECTOR_TRANSFORM = NODES["VectorTransform"].code
_VT_TYPE = OFFSETS["VectorTransform"]["prop:vector_type"]
_VT_FROM = OFFSETS["VectorTransform"]["prop:convert_from"]
_VT_TO = OFFSETS["VectorTransform"]["prop:convert_to"]
_NORMAL_NODE = NODES["Normal"].code
_NN_DIRECTION = OFFSETS["Normal"]["prop:direction"]
_WORLD = TRANSFORM_SPACES["WORLD"]
_OBJECT = TRANSFORM_SPACES["OBJECT"]
_CAMERA = TRANSFORM_SPACES["CAMERA"]
_MP_LOCATION = OFFSETS["Mapping"]["Location"]
_MP_ROTATION = OFFSETS["Mapping"]["Rotation"]
_MP_SCALE = OFFSETS["Mapping"]["Scale"]
_MP_TYPE = OFFSETS["Mapping"]["prop:vector_type"]
_POINT = VECTOR_TYPES["POINT"]
_TEXTURE = VECTOR_TYPES["TEXTURE"]
_VECTOR = VECTOR_TYPES["VECTOR"]
_NORMAL = VECTOR_TYPES["NORMAL"]


@function
def eval_vector_node(code, regs, b, c, sd_ref, tex_ref):
    """A vector node: inputs at regs[b:], outputs to regs[c:]; the point and the texture data
    by reference (``jit.by_ref``)."""
    if code == _MAPPING:
        mapping_node(regs, b, c)
    elif code == _VECTOR_ROTATE:
        vector_rotate(regs, b, c)
    elif code == _VECTOR_TRANSFORM:
        vector_transform(regs, b, c, deref(sd_ref), deref(tex_ref))
    elif code == _NORMAL_NODE:
        normal_node(regs, b, c)


@device
def normal_node(regs, b, c):
    """Normal: the node's unit direction, and its dot product with the unit Normal input
    (svm_node_normal; a zero vector normalises to zero here, to NaN in Cycles)."""
    dx, dy, dz = safe_normalize(regs[b + _NN_DIRECTION], regs[b + _NN_DIRECTION + 1],
                                regs[b + _NN_DIRECTION + 2])
    nx, ny, nz = safe_normalize(regs[b], regs[b + 1], regs[b + 2])
    regs[c], regs[c + 1], regs[c + 2] = dx, dy, dz
    regs[c + 3] = dx * nx + dy * ny + dz * nz


@device
def euler_rotation(rx, ry, rz):
    """Rows of the rotation by Euler angles XYZ (about X first, then Y, then Z)."""
    cx, cy, cz = math.cos(rx), math.cos(ry), math.cos(rz)
    sx, sy, sz = math.sin(rx), math.sin(ry), math.sin(rz)
    return ((cy * cz, sy * sx * cz - cx * sz, sy * cx * cz + sx * sz),
            (cy * sz, sy * sx * sz + cx * cz, sy * cx * sz - sx * cz),
            (-sy, cy * sx, cy * cx))


@device
def mapping_node(regs, b, c):
    """Mapping: Point R(v s) + t; Texture R^T(v - t) / s; Vector R(v s); Normal
    normalize(R(v / s)); divisions by a zero scale component give 0 (svm_mapping)."""
    kind = int(regs[b + _MP_TYPE])
    vx, vy, vz = regs[b], regs[b + 1], regs[b + 2]
    tx, ty, tz = regs[b + _MP_LOCATION], regs[b + _MP_LOCATION + 1], regs[b + _MP_LOCATION + 2]
    sx, sy, sz = regs[b + _MP_SCALE], regs[b + _MP_SCALE + 1], regs[b + _MP_SCALE + 2]
    r0, r1, r2 = euler_rotation(regs[b + _MP_ROTATION], regs[b + _MP_ROTATION + 1],
                                regs[b + _MP_ROTATION + 2])
    x = y = z = 0.0
    if kind == _TEXTURE:
        dx, dy, dz = vx - tx, vy - ty, vz - tz
        x = safe_divide(r0[0] * dx + r1[0] * dy + r2[0] * dz, sx)
        y = safe_divide(r0[1] * dx + r1[1] * dy + r2[1] * dz, sy)
        z = safe_divide(r0[2] * dx + r1[2] * dy + r2[2] * dz, sz)
    elif kind == _POINT or kind == _VECTOR or kind == _NORMAL:
        if kind == _NORMAL:
            px, py, pz = safe_divide(vx, sx), safe_divide(vy, sy), safe_divide(vz, sz)
        else:
            px, py, pz = vx * sx, vy * sy, vz * sz
        x = r0[0] * px + r0[1] * py + r0[2] * pz
        y = r1[0] * px + r1[1] * py + r1[2] * pz
        z = r2[0] * px + r2[1] * py + r2[2] * pz
        if kind == _POINT:
            x, y, z = x + tx, y + ty, z + tz
        elif kind == _NORMAL:
            x, y, z = safe_normalize(x, y, z)
    regs[c], regs[c + 1], regs[c + 2] = x, y, z


@device
def vector_rotate(regs, b, c):
    """Vector Rotate about Center: by Euler XYZ angles (inverted: the transposed rotation), or
    by Angle about X, Y, Z or Axis (inverted: by -Angle); a zero Axis leaves the vector as it
    is (svm_node_vector_rotate)."""
    kind = int(regs[b + _VR_TYPE])
    invert = regs[b + _VR_INVERT] != 0.0
    o = b + _VR_CENTER
    cx, cy, cz = regs[o], regs[o + 1], regs[o + 2]
    vx, vy, vz = regs[b] - cx, regs[b + 1] - cy, regs[b + 2] - cz
    if kind == ROTATE_EULER_XYZ:
        o = b + _VR_ROTATION
        r0, r1, r2 = euler_rotation(regs[o], regs[o + 1], regs[o + 2])
        if invert:
            x = r0[0] * vx + r1[0] * vy + r2[0] * vz
            y = r0[1] * vx + r1[1] * vy + r2[1] * vz
            z = r0[2] * vx + r1[2] * vy + r2[2] * vz
        else:
            x = r0[0] * vx + r0[1] * vy + r0[2] * vz
            y = r1[0] * vx + r1[1] * vy + r1[2] * vz
            z = r2[0] * vx + r2[1] * vy + r2[2] * vz
        regs[c], regs[c + 1], regs[c + 2] = x + cx, y + cy, z + cz
        return
    if kind == ROTATE_X:
        ax, ay, az = 1.0, 0.0, 0.0
    elif kind == ROTATE_Y:
        ax, ay, az = 0.0, 1.0, 0.0
    elif kind == ROTATE_Z:
        ax, ay, az = 0.0, 0.0, 1.0
    else:
        o = b + _VR_AXIS
        ax, ay, az = regs[o], regs[o + 1], regs[o + 2]
    length = math.sqrt(ax * ax + ay * ay + az * az)
    if length == 0.0:
        regs[c], regs[c + 1], regs[c + 2] = regs[b], regs[b + 1], regs[b + 2]
        return
    angle = regs[b + _VR_ANGLE]
    x, y, z = rotate_around_axis(vx, vy, vz, ax / length, ay / length, az / length,
                                 -angle if invert else angle)
    regs[c], regs[c + 1], regs[c + 2] = x + cx, y + cy, z + cz


@device
def _world_to_camera(cam, kind, x, y, z):
    if kind == _POINT:
        return camera_space(cam, x, y, z)
    x, y, z = camera_axes(cam, x, y, z)
    if kind == _NORMAL:
        return safe_normalize(x, y, z)
    return x, y, z


@device
def _camera_to_world(cam, kind, x, y, z):
    wx = x * cam[C_RIGHT] + y * cam[C_UP] + z * cam[C_FWD]
    wy = x * cam[C_RIGHT + 1] + y * cam[C_UP + 1] + z * cam[C_FWD + 1]
    wz = x * cam[C_RIGHT + 2] + y * cam[C_UP + 2] + z * cam[C_FWD + 2]
    if kind == _POINT:
        return wx + cam[C_POS], wy + cam[C_POS + 1], wz + cam[C_POS + 2]
    if kind == _NORMAL:
        return safe_normalize(wx, wy, wz)
    return wx, wy, wz


@device
def _object_to_world(row, kind, x, y, z):
    if kind == _POINT:
        return transform_point(row, OBJ_MATRIX, x, y, z)
    if kind == _NORMAL:
        return normal_to_world(row, x, y, z)
    return transform_direction(row, OBJ_MATRIX, x, y, z)


@device
def _world_to_object(row, kind, x, y, z):
    if kind == _POINT:
        return transform_point(row, OBJ_INVERSE, x, y, z)
    if kind == _NORMAL:
        return normal_to_object(row, x, y, z)
    return transform_direction(row, OBJ_INVERSE, x, y, z)


@device
def vector_transform(regs, b, c, sd, tex):
    """Vector Transform between world, object and camera space, of a point, a direction or
    a normal (normals through the inverse transpose and normalised).  Object space is the
    shaded object's; without one (the world) the object step is skipped, as in Cycles."""
    kind = int(regs[b + _VT_TYPE])
    src, dst = int(regs[b + _VT_FROM]), int(regs[b + _VT_TO])
    x, y, z = regs[b], regs[b + 1], regs[b + 2]
    cam = tex.camera
    has_object = sd.obj >= 0 and sd.prim >= 0
    if src == _WORLD:
        if dst == _CAMERA:
            x, y, z = _world_to_camera(cam, kind, x, y, z)
        elif dst == _OBJECT and has_object:
            x, y, z = _world_to_object(tex.objects[sd.obj], kind, x, y, z)
    elif src == _CAMERA:
        if dst == _WORLD or dst == _OBJECT:
            x, y, z = _camera_to_world(cam, kind, x, y, z)
        if dst == _OBJECT and has_object:
            x, y, z = _world_to_object(tex.objects[sd.obj], kind, x, y, z)
    elif src == _OBJECT:
        if (dst == _WORLD or dst == _CAMERA) and has_object:
            x, y, z = _object_to_world(tex.objects[sd.obj], kind, x, y, z)
        if dst == _CAMERA:
            x, y, z = _world_to_camera(cam, kind, x, y, z)
    regs[c], regs[c + 1], regs[c + 2] = x, y, z
