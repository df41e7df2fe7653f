"""Input nodes: what the shading point offers the graph (kernel/svm/tex_coord.h, geometry.h,
attribute.h, vertex_color.h, fresnel.h, light_path.h, camera.h, value.h).

Texture Coordinate, UV Map, Attribute, Color Attribute, Geometry, Tangent, Object
Info, Camera Data, Fresnel, Layer Weight, Light Path and Light Falloff read the point
(``ShadingData``: its path flags, ray length and bounce counts for Light
Path, the ray length for Light Falloff) and the scene's per-corner attributes and per-object data
(``TextureData``); Value and RGB are constants (the compiler folds them, so
they only run here when evaluated ahead of time).  Every output of a node is
computed, each into its registers (``nodes.OUTPUT_OFFSETS``).
"""
from __future__ import annotations

import math

from ...jit import deref, device, function
from ..camera import C_FWD, C_HALF_H, C_HALF_W, C_POS, C_RIGHT, C_SHIFT_X, C_SHIFT_Y, C_TYPE, C_UP, CAM_ORTHO
from ..closures.fresnel import fresnel_dielectric
from ..state import PF_CAMERA, PF_DIFFUSE, PF_EMISSION, PF_GLOSSY, PF_REFLECT, PF_SHADOW, PF_SINGULAR, PF_TRANSMIT
from .data import (
    ATTR_DEFAULT_UV,
    OBJ_COLOR,
    OBJ_INVERSE,
    OBJ_MATRIX,
    OBJ_PASS_INDEX,
    OBJ_RANDOM,
    OBJ_TEXSPACE_LOC,
    OBJ_TEXSPACE_SIZE,
)
from .math_nodes import FLT_MAX, safe_normalize
from .nodes import AXIS_X, AXIS_Y, AXIS_Z, DIRECTION_UV_MAP, NODES, OFFSETS

_VALUE = NODES["Value"].code
_RGB = NODES["RGB"].code
_TEX_COORD = NODES["TexCoord"].code
_UV_MAP = NODES["UVMap"].code
_ATTRIBUTE = NODES["Attribute"].code
_GEOMETRY = NODES["NewGeometry"].code
_TC_USE_OBJECT = OFFSETS["TexCoord"]["prop:use_object"]
_TC_INVERSE = OFFSETS["TexCoord"]["prop:object_inverse"]
_TC_UNDISPLACED = OFFSETS["TexCoord"]["prop:undisplaced"]
_UV_ATTRIBUTE = OFFSETS["UVMap"]["prop:attribute"]
_ATTR_OFFSET = OFFSETS["Attribute"]["prop:attribute"]
_ATTR_SIZE = OFFSETS["Attribute"]["prop:attribute_size"]
_FRESNEL = NODES["Fresnel"].code
_LAYER_WEIGHT = NODES["LayerWeight"].code
_LIGHT_PATH = NODES["LightPath"].code
_OBJECT_INFO = NODES["ObjectInfo"].code
_CAMERA_DATA = NODES["CameraData"].code
_VERTEX_COLOR = NODES["VertexColor"].code
_FR_IOR = OFFSETS["Fresnel"]["IOR"]
_FR_NORMAL = OFFSETS["Fresnel"]["Normal"]
_LW_BLEND = OFFSETS["LayerWeight"]["Blend"]
_LW_NORMAL = OFFSETS["LayerWeight"]["Normal"]
_OI_MATERIAL_INDEX = OFFSETS["ObjectInfo"]["prop:material_index"]
_VC_OFFSET = OFFSETS["VertexColor"]["prop:attribute"]
_VC_SIZE = OFFSETS["VertexColor"]["prop:attribute_size"]
_TANGENT = NODES["Tangent"].code
_TG_DIRECTION = OFFSETS["Tangent"]["prop:direction_type"]
_TG_AXIS = OFFSETS["Tangent"]["prop:axis"]
_TG_ATTRIBUTE = OFFSETS["Tangent"]["prop:attribute"]
_LIGHT_FALLOFF = NODES["LightFalloff"].code
_LF_SMOOTH = OFFSETS["LightFalloff"]["Smooth"]
_RANDOM_SCALE = 1.0 / 4294967295.0       # Object Info Random: the object's 32-bit random id


@function
def eval_input_node(code, regs, b, c, sd_ref, tex_ref):
    """An input node: inputs at regs[b:], outputs to regs[c:]; the point and the texture
    data by reference (``jit.by_ref``)."""
    sd, tex = deref(sd_ref), deref(tex_ref)
    if code == _TEX_COORD:
        tex_coord(regs, b, c, sd, tex)
    elif code == _UV_MAP:
        off = int(regs[b + _UV_ATTRIBUTE])
        x, y, _z, _w = attribute(tex, sd, off, 2)
        regs[c], regs[c + 1], regs[c + 2] = x, y, 0.0
    elif code == _ATTRIBUTE:
        attribute_node(regs, b, c, sd, tex)
    elif code == _GEOMETRY:
        geometry(regs, c, sd, tex)
    elif code == _TANGENT:
        tangent_node(regs, b, c, sd, tex)
    elif code == _FRESNEL or code == _LAYER_WEIGHT:
        fresnel_nodes(code, regs, b, c, sd)
    elif code == _LIGHT_PATH:
        light_path(regs, c, sd)
    elif code == _LIGHT_FALLOFF:
        light_falloff(regs, b, c, sd)
    elif code == _OBJECT_INFO:
        object_info(regs, b, c, sd, tex)
    elif code == _CAMERA_DATA:
        cx, cy, cz = camera_space(tex.camera, sd.px, sd.py, sd.pz)
        dist = math.sqrt(cx * cx + cy * cy + cz * cz)
        vx, vy, vz = safe_normalize(cx, cy, cz)
        _store3(regs, c, vx, vy, vz)
        regs[c + 3] = cz
        regs[c + 4] = dist
    elif code == _VERTEX_COLOR:
        off = int(regs[b + _VC_OFFSET])
        size = int(regs[b + _VC_SIZE])
        x, y, z, w = attribute(tex, sd, off, size)
        if off < 0 or sd.prim < 0:
            w = 0.0
        elif size != 4:
            w = 1.0
        _store3(regs, c, x, y, z)
        regs[c + 3] = w
    elif code == _VALUE:
        regs[c] = regs[b]
    elif code == _RGB:
        regs[c], regs[c + 1], regs[c + 2] = regs[b], regs[b + 1], regs[b + 2]


@device
def attribute(tex, sd, off, size):
    """Per-corner attribute at offset ``off`` (``size`` components, at most 4) interpolated
    at the point; zeros without a triangle or when the scene has no such attribute."""
    x = y = z = w = 0.0
    p = sd.prim
    if p < 0 or off < 0:
        return x, y, z, w
    b0, b1, b2 = 1.0 - sd.u - sd.v, sd.u, sd.v
    a = tex.attr
    x = b0 * float(a[p, 0, off]) + b1 * float(a[p, 1, off]) + b2 * float(a[p, 2, off])
    if size > 1:
        y = b0 * float(a[p, 0, off + 1]) + b1 * float(a[p, 1, off + 1]) + b2 * float(a[p, 2, off + 1])
    if size > 2:
        z = b0 * float(a[p, 0, off + 2]) + b1 * float(a[p, 1, off + 2]) + b2 * float(a[p, 2, off + 2])
    if size > 3:
        w = b0 * float(a[p, 0, off + 3]) + b1 * float(a[p, 1, off + 3]) + b2 * float(a[p, 2, off + 3])
    return x, y, z, w


@device
def _store3(regs, c, x, y, z):
    regs[c], regs[c + 1], regs[c + 2] = x, y, z


@device
def transform_point(m, o, x, y, z):
    """Row-major 3 x 4 matrix at m[o:o + 12] applied to a point."""
    return (m[o] * x + m[o + 1] * y + m[o + 2] * z + m[o + 3],
            m[o + 4] * x + m[o + 5] * y + m[o + 6] * z + m[o + 7],
            m[o + 8] * x + m[o + 9] * y + m[o + 10] * z + m[o + 11])


@device
def transform_direction(m, o, x, y, z):
    """Row-major 3 x 4 matrix at m[o:o + 12] applied to a direction (no translation)."""
    return (m[o] * x + m[o + 1] * y + m[o + 2] * z,
            m[o + 4] * x + m[o + 5] * y + m[o + 6] * z,
            m[o + 8] * x + m[o + 9] * y + m[o + 10] * z)


@device
def normal_to_object(row, x, y, z):
    """World normal -> object space, normalised: M^T n with M the object -> world matrix of
    the object's row of ``TextureData.objects`` (Cycles' object_inverse_normal_transform)."""
    m = OBJ_MATRIX
    return safe_normalize(row[m] * x + row[m + 4] * y + row[m + 8] * z,
                          row[m + 1] * x + row[m + 5] * y + row[m + 9] * z,
                          row[m + 2] * x + row[m + 6] * y + row[m + 10] * z)


@device
def normal_to_world(row, x, y, z):
    """Object normal -> world space, normalised: M^-T n (Cycles' object_normal_transform)."""
    m = OBJ_INVERSE
    return safe_normalize(row[m] * x + row[m + 4] * y + row[m + 8] * z,
                          row[m + 1] * x + row[m + 5] * y + row[m + 9] * z,
                          row[m + 2] * x + row[m + 6] * y + row[m + 10] * z)


@device
def camera_axes(cam, x, y, z):
    """(x, y, z) on the camera's axes: right, up, forward (Cycles' camera space)."""
    return (x * cam[C_RIGHT] + y * cam[C_RIGHT + 1] + z * cam[C_RIGHT + 2],
            x * cam[C_UP] + y * cam[C_UP + 1] + z * cam[C_UP + 2],
            x * cam[C_FWD] + y * cam[C_FWD + 1] + z * cam[C_FWD + 2])


@device
def camera_space(cam, px, py, pz):
    """A world point in camera space: +X right, +Y up, +Z forward, from the camera."""
    return camera_axes(cam, px - cam[C_POS], py - cam[C_POS + 1], pz - cam[C_POS + 2])


@device
def tex_coord(regs, b, c, sd, tex):
    """Texture Coordinate: Generated, Normal, UV, Object, Camera, Window, Reflection."""
    px, py, pz = sd.px, sd.py, sd.pz
    nx, ny, nz = sd.nx, sd.ny, sd.nz
    ob = sd.obj
    objects = tex.objects
    # Generated: the object-space point in the object's texture space (world: the direction);
    # on a truly displaced mesh the point before displacement, as Cycles' generated attribute
    # (the per-corner attribute at the offset in prop:undisplaced, whose fourth component
    # says whether the triangle's mesh is displaced: ``mcengine.displacement``).
    gx, gy, gz = px, py, pz
    onx, ony, onz = nx, ny, nz
    ox, oy, oz = px, py, pz
    if ob >= 0 and sd.prim >= 0:
        row = objects[ob]
        ox, oy, oz = transform_point(row, OBJ_INVERSE, px, py, pz)
        undisplaced = int(regs[b + _TC_UNDISPLACED])
        if undisplaced >= 0 and tex.attr[sd.prim, 0, undisplaced + 3] > 0.0:
            ux, uy, uz, _uw = attribute(tex, sd, undisplaced, 3)
            gx, gy, gz = texture_space(row, ux, uy, uz)
        else:
            gx, gy, gz = texture_space(row, ox, oy, oz)
        onx, ony, onz = normal_to_object(row, nx, ny, nz)
    if regs[b + _TC_USE_OBJECT] != 0.0:
        ox, oy, oz = transform_point(regs, b + _TC_INVERSE, px, py, pz)
    u, v, _z, _w = attribute(tex, sd, ATTR_DEFAULT_UV, 2)
    cam = tex.camera
    cx, cy, cz = camera_space(cam, px, py, pz)
    # Window: normalized device coordinates, (0, 0) bottom left, (1, 1) top right.
    if cam[C_TYPE] == CAM_ORTHO:
        vx, vy = cx, cy
    else:
        vx, vy = (cx / cz, cy / cz) if cz != 0.0 else (0.0, 0.0)
    wx = 0.5 * ((vx - cam[C_SHIFT_X]) / cam[C_HALF_W] + 1.0)
    wy = 0.5 * ((vy - cam[C_SHIFT_Y]) / cam[C_HALF_H] + 1.0)
    # Reflection of the direction to the viewer about the normal (world: that direction).
    wox, woy, woz = sd.wox, sd.woy, sd.woz
    rx, ry, rz = wox, woy, woz
    if sd.prim >= 0:
        d = 2.0 * (nx * wox + ny * woy + nz * woz)
        rx, ry, rz = d * nx - wox, d * ny - woy, d * nz - woz
    _store3(regs, c, gx, gy, gz)
    _store3(regs, c + 3, onx, ony, onz)
    _store3(regs, c + 6, u, v, 0.0)
    _store3(regs, c + 9, ox, oy, oz)
    _store3(regs, c + 12, cx, cy, cz)
    _store3(regs, c + 15, wx, wy, 0.0)
    _store3(regs, c + 18, rx, ry, rz)


@device
def texture_space(row, ox, oy, oz):
    """An object-space point in the object's texture space (its Generated coordinates):
    the texture-space box of the object's row of ``TextureData.objects`` maps to the unit cube."""
    lx, ly, lz = row[OBJ_TEXSPACE_LOC], row[OBJ_TEXSPACE_LOC + 1], row[OBJ_TEXSPACE_LOC + 2]
    sx, sy, sz = row[OBJ_TEXSPACE_SIZE], row[OBJ_TEXSPACE_SIZE + 1], row[OBJ_TEXSPACE_SIZE + 2]
    return (ox - lx) / (2.0 * sx) + 0.5, (oy - ly) / (2.0 * sy) + 0.5, (oz - lz) / (2.0 * sz) + 0.5


@device
def surface_tangent(row, sd, tx, ty, tz):
    """An object-space tangent direction at the point, in world space and perpendicular to
    the shading normal: transformed as a normal, then N x normalize(T x N), as Cycles ends
    svm_node_tangent and primitive_tangent (zero stays zero)."""
    tx, ty, tz = normal_to_world(row, tx, ty, tz)
    nx, ny, nz = sd.nx, sd.ny, sd.nz
    cx, cy, cz = safe_normalize(ty * nz - tz * ny, tz * nx - tx * nz, tx * ny - ty * nx)
    return ny * cz - nz * cy, nz * cx - nx * cz, nx * cy - ny * cx


@device
def radial_tangent(sd, tex, axis):
    """The tangent of the circle about an object axis through the centre of the object's
    texture space, at the point (Tangent node, radial; Geometry's Tangent is the one about Z);
    zero off a mesh."""
    if sd.obj < 0 or sd.prim < 0:
        return 0.0, 0.0, 0.0
    row = tex.objects[sd.obj]
    ox, oy, oz = transform_point(row, OBJ_INVERSE, sd.px, sd.py, sd.pz)
    gx, gy, gz = texture_space(row, ox, oy, oz)
    if axis == AXIS_X:
        tx, ty, tz = 0.0, 0.5 - gz, gy - 0.5
    elif axis == AXIS_Y:
        tx, ty, tz = 0.5 - gz, 0.0, gx - 0.5
    else:
        tx, ty, tz = 0.5 - gy, gx - 0.5, 0.0
    return surface_tangent(row, sd, tx, ty, tz)


@device
def tangent_node(regs, b, c, sd, tex):
    """Tangent: radial about the chosen object axis, or the UV map's (MikkTSpace) tangent;
    zero where the map has no tangents."""
    if regs[b + _TG_DIRECTION] == DIRECTION_UV_MAP:
        off = int(regs[b + _TG_ATTRIBUTE])
        tx = ty = tz = 0.0
        if off >= 0 and sd.obj >= 0 and sd.prim >= 0:
            x, y, z, _w = attribute(tex, sd, off, 3)
            tx, ty, tz = surface_tangent(tex.objects[sd.obj], sd, x, y, z)
    else:
        tx, ty, tz = radial_tangent(sd, tex, int(regs[b + _TG_AXIS]))
    _store3(regs, c, tx, ty, tz)


@device
def attribute_node(regs, b, c, sd, tex):
    """Attribute (geometry type): Color, Vector, Fac, Alpha of a per-corner attribute."""
    off = int(regs[b + _ATTR_OFFSET])
    size = int(regs[b + _ATTR_SIZE])
    x, y, z, w = attribute(tex, sd, off, size)
    if size == 1:
        y = z = x
    alpha = w if size == 4 else 1.0
    fac = x if size == 1 else (x + y + z) / 3.0
    if off < 0 or sd.prim < 0:
        alpha = 0.0
    regs[c], regs[c + 1], regs[c + 2] = x, y, z
    regs[c + 3], regs[c + 4], regs[c + 5] = x, y, z
    regs[c + 6] = fac
    regs[c + 7] = alpha


@device
def geometry(regs, c, sd, tex):
    """Geometry: Position, Normal, Tangent (radial about object Z), True Normal, Incoming,
    Parametric, Backfacing; Pointiness and Random Per Island are mesh attributes, which the
    compiler reads with an Attribute node where they are linked (0.5 and 0 stand here)."""
    _store3(regs, c, sd.px, sd.py, sd.pz)
    _store3(regs, c + 3, sd.nx, sd.ny, sd.nz)
    tx, ty, tz = radial_tangent(sd, tex, AXIS_Z)
    _store3(regs, c + 6, tx, ty, tz)
    _store3(regs, c + 9, sd.ngx, sd.ngy, sd.ngz)
    _store3(regs, c + 12, sd.wox, sd.woy, sd.woz)
    _store3(regs, c + 15, 1.0 - sd.u - sd.v, sd.u, 0.0)
    _store3(regs, c + 18, 1.0 if sd.backfacing else 0.0, 0.5, 0.0)


@device
def fresnel_nodes(code, regs, b, c, sd):
    """Fresnel (Fac) and Layer Weight (Fresnel, Facing) about the Normal input (unlinked:
    the shading normal), seen from the viewer."""
    k = b + (_FR_NORMAL if code == _FRESNEL else _LW_NORMAL)
    nx, ny, nz = regs[k], regs[k + 1], regs[k + 2]
    if nx == 0.0 and ny == 0.0 and nz == 0.0:
        nx, ny, nz = sd.nx, sd.ny, sd.nz
    cos_i = sd.wox * nx + sd.woy * ny + sd.woz * nz
    if code == _FRESNEL:
        eta = max(regs[b + _FR_IOR], 1e-5)
        if sd.backfacing:
            eta = 1.0 / eta
        regs[c] = fresnel_dielectric(cos_i, eta)[0]
        return
    blend = regs[b + _LW_BLEND]
    eta = max(1.0 - blend, 1e-5)
    if not sd.backfacing:
        eta = 1.0 / eta
    regs[c] = fresnel_dielectric(cos_i, eta)[0]
    f = abs(cos_i)
    if blend != 0.5:
        blend = min(max(blend, 0.0), 1.0 - 1e-5)
        f = f ** (2.0 * blend if blend < 0.5 else 0.5 / (1.0 - blend))
    regs[c + 1] = 1.0 - f


@device
def _flag(flags, bit):
    return 1.0 if flags & bit else 0.0


@device
def light_path(regs, c, sd):
    """Light Path: the kind of ray that reached the point, its length and the bounces so far
    (one more for shadow rays and light samples, as Cycles counts them)."""
    f = sd.path_flags
    regs[c] = _flag(f, PF_CAMERA)
    regs[c + 1] = _flag(f, PF_SHADOW)
    regs[c + 2] = _flag(f, PF_DIFFUSE)
    regs[c + 3] = _flag(f, PF_GLOSSY)
    regs[c + 4] = _flag(f, PF_SINGULAR)
    regs[c + 5] = _flag(f, PF_REFLECT)
    regs[c + 6] = _flag(f, PF_TRANSMIT)
    regs[c + 7] = 0.0                       # volume scattering: no volumes
    regs[c + 8] = sd.ray_length
    regs[c + 9] = sd.depth + (1.0 if f & (PF_SHADOW | PF_EMISSION) else 0.0)
    regs[c + 10] = sd.diffuse_depth
    regs[c + 11] = sd.glossy_depth
    regs[c + 12] = sd.transparent_depth
    regs[c + 13] = sd.transmission_depth
    regs[c + 14] = 0.0                      # Portal Depth: not counted (warned by the export)


@device
def light_falloff(regs, b, c, sd):
    """Light Falloff (svm_node_light_falloff): Strength as it is (Quadratic), times the ray
    length (Linear), times its square (Constant), each times t^2 / (Smooth + t^2) when
    Smooth > 0; Strength alone on every output for a distant light or the world (a ray
    length of FLT_MAX or more)."""
    strength = regs[b]
    t = sd.ray_length
    if t >= FLT_MAX:
        regs[c] = regs[c + 1] = regs[c + 2] = strength
        return
    smooth = regs[b + _LF_SMOOTH]
    f = 1.0
    if smooth > 0.0:
        f = t * t / (smooth + t * t)
    regs[c] = strength * f
    regs[c + 1] = strength * t * f
    regs[c + 2] = strength * t * t * f


@device
def object_info(regs, b, c, sd, tex):
    """Object Info: the object's location, colour, alpha, pass index, random number, and the
    material's pass index (zeros without an object, as for the world)."""
    regs[c + 8] = regs[b + _OI_MATERIAL_INDEX]
    ob = sd.obj
    if ob < 0 or sd.prim < 0:
        for k in range(8):
            regs[c + k] = 0.0
        regs[c + 9] = 0.0
        return
    row = tex.objects[ob]
    _store3(regs, c, row[OBJ_MATRIX + 3], row[OBJ_MATRIX + 7], row[OBJ_MATRIX + 11])
    _store3(regs, c + 3, row[OBJ_COLOR], row[OBJ_COLOR + 1], row[OBJ_COLOR + 2])
    regs[c + 6] = row[OBJ_COLOR + 3]
    regs[c + 7] = row[OBJ_PASS_INDEX]
    regs[c + 9] = row[OBJ_RANDOM] * _RANDOM_SCALE
