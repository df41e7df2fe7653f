"""Image textures: Image Texture and Environment Texture (kernel/svm/image.h and Cycles' CPU
texture sampler).

An image is a rectangle of texels in one of ``TextureData``'s pools (``data.IMG_*``):
texture coordinates (x, y) in [0, 1] span it, texel i covering [i/W, (i+1)/W], row 0 at
the bottom.  Lookups, as Cycles' CPU sampler makes them:

* Closest: the texel under (x, y); Linear: the four texels around (xW - 1/2, yH - 1/2),
  bilinear weights; Cubic (and Smart): sixteen texels, uniform cubic B-spline weights;
* the extension applies to each tap's integer index: Repeat wraps, Extend clamps, Mirror
  reflects, Clip reads zeros outside (and the whole lookup is zero when every tap is);
* after interpolation, a linked Alpha output divides the colour by alpha (alpha not 0 or
  1), then sRGB-encoded images are decoded, channel by channel (Cycles'
  compress-as-sRGB);
* a missing image reads magenta (1, 0, 1), alpha 1.

Image Texture projects its vector Flat (x, y), on a Sphere or a Tube, or Box (three
planar lookups blended by the object-space normal); Environment Texture maps a direction
to the equirectangular or mirror-ball image; Sky Texture reads the sky image that
``mcengine.sky`` precomputes and adds the sun disc.
"""
from __future__ import annotations

import math

import numpy as np

from ...jit import deref, device, function
from ..colorspace import XYZ_TO_RGB
from ..scalar import safe_acos, saturate
from .data import (
    IMG_CHANNELS,
    IMG_FLAGS,
    IMG_FLOAT,
    IMG_HEIGHT,
    IMG_OFFSET,
    IMG_WIDTH,
    IMGF_SRGB,
    IMGF_UNASSOCIATE,
    OBJ_MATRIX,
)
from .nodes import (
    EXT_CLIP,
    EXT_EXTEND,
    EXT_REPEAT,
    INTERP_CLOSEST,
    INTERP_LINEAR,
    NODES,
    OFFSETS,
    PROJ_BOX,
    PROJ_EQUIRECTANGULAR,
    PROJ_SPHERE,
    PROJ_TUBE,
)

_TEX_IMAGE = NODES["TexImage"].code
_TEX_ENVIRONMENT = NODES["TexEnvironment"].code
_TI = OFFSETS["TexImage"]
_TI_VECTOR = _TI["Vector"]
_TI_IMAGE = _TI["prop:image"]
_TI_INTERPOLATION = _TI["prop:interpolation"]
_TI_EXTENSION = _TI["prop:extension"]
_TI_PROJECTION = _TI["prop:projection"]
_TI_BLEND = _TI["prop:projection_blend"]
_TI_ALPHA_LINKED = _TI["prop:alpha_linked"]
_TE = OFFSETS["TexEnvironment"]
_TE_VECTOR = _TE["Vector"]
_TE_IMAGE = _TE["prop:image"]
_TE_INTERPOLATION = _TE["prop:interpolation"]
_TE_PROJECTION = _TE["prop:projection"]
_TE_ALPHA_LINKED = _TE["prop:alpha_linked"]
_TEX_SKY = NODES["TexSky"].code
_TS = OFFSETS["TexSky"]
_TS_VECTOR = _TS["Vector"]
_TS_IMAGE = _TS["prop:image"]
_TS_ELEVATION = _TS["prop:sky_elevation"]
_TS_ROTATION = _TS["prop:sky_rotation"]
_TS_DIAMETER = _TS["prop:sky_diameter"]
_TS_INTENSITY = _TS["prop:sun_intensity"]
_TS_HORIZON = _TS["prop:sky_horizon"]
_TS_BOTTOM = _TS["prop:sky_bottom_x"]     # x, y, z follow
_TS_TOP = _TS["prop:sky_top_x"]

# Texture coordinates beyond this many texels are read at 0 (their integer index would
# overflow; Cycles' own result there is undefined).
_MAX_TEXELS = 1e9
_INV_255 = 1.0 / 255.0


@function
def eval_image_node(code, regs, b, c, sd_ref, tex_ref):
    """An image node: inputs at regs[b:], outputs to regs[c:]; the point and the texture
    data by reference (``jit.by_ref``)."""
    sd, tex = deref(sd_ref), deref(tex_ref)
    if code == _TEX_IMAGE:
        image_texture_node(regs, b, c, sd, tex)
    elif code == _TEX_ENVIRONMENT:
        environment_texture_node(regs, b, c, tex)
    elif code == _TEX_SKY:
        sky_texture_node(regs, b, c, tex)


# -- lookups -----------------------------------------------------------------------------------
@device
def wrap_index(i, n, extension):
    """Texel index i of a row of n under ``extension``; -1 outside a clipped image."""
    if extension == EXT_REPEAT:
        return i % n
    if extension == EXT_EXTEND:
        return min(max(i, 0), n - 1)
    if extension == EXT_CLIP:
        return i if 0 <= i < n else -1
    m = abs(i + 1 if i < 0 else i) % (2 * n)     # EXT_MIRROR
    return m if m < n else 2 * n - m - 1


@device
def texel(tex, img, i, j):
    """RGBA of texel (i, j) of image ``img`` (zeros when either index is -1)."""
    if i < 0 or j < 0:
        return 0.0, 0.0, 0.0, 0.0
    info = tex.images
    channels = info[img, IMG_CHANNELS]
    k = info[img, IMG_OFFSET] + (j * info[img, IMG_WIDTH] + i) * channels
    if info[img, IMG_FLOAT]:
        p = tex.pixf
        if channels == 1:
            v = float(p[k])
            return v, v, v, 1.0
        return float(p[k]), float(p[k + 1]), float(p[k + 2]), float(p[k + 3])
    q = tex.pix8
    if channels == 1:
        v = float(q[k]) * _INV_255
        return v, v, v, 1.0
    return (float(q[k]) * _INV_255, float(q[k + 1]) * _INV_255, float(q[k + 2]) * _INV_255,
            float(q[k + 3]) * _INV_255)


@device
def _bspline(f):
    """Uniform cubic B-spline weights of the taps at -1, 0, 1, 2 for the fraction f."""
    g = 1.0 - f
    f2 = f * f
    f3 = f2 * f
    return (g * g * g / 6.0, (3.0 * f3 - 6.0 * f2 + 4.0) / 6.0,
            (-3.0 * f3 + 3.0 * f2 + 3.0 * f + 1.0) / 6.0, f3 / 6.0)


@device
def _tap(w0, w1, w2, w3, k):
    """The k-th of four values (a tap's weight or index)."""
    if k == 0:
        return w0
    if k == 1:
        return w1
    if k == 2:
        return w2
    return w3


@device
def interpolate(tex, img, x, y, interpolation, extension):
    """RGBA of image ``img`` at texture coordinates (x, y), associated alpha as stored."""
    w = tex.images[img, IMG_WIDTH]
    h = tex.images[img, IMG_HEIGHT]
    s = x * w
    t = y * h
    if not (abs(s) < _MAX_TEXELS and abs(t) < _MAX_TEXELS):
        s = t = 0.0
    if interpolation == INTERP_CLOSEST:
        i = int(math.floor(s))
        j = int(math.floor(t))
        return texel(tex, img, wrap_index(i, w, extension), wrap_index(j, h, extension))
    s -= 0.5
    t -= 0.5
    fi = math.floor(s)
    fj = math.floor(t)
    fx = s - fi
    fy = t - fj
    i = int(fi)
    j = int(fj)
    r = g = b = a = 0.0
    if interpolation == INTERP_LINEAR:
        if extension == EXT_CLIP and (i < -1 or i >= w or j < -1 or j >= h):
            return r, g, b, a
        i0, i1 = wrap_index(i, w, extension), wrap_index(i + 1, w, extension)
        for dj in range(2):
            wy = fy if dj else 1.0 - fy
            jj = wrap_index(j + dj, h, extension)
            for di in range(2):
                wt = (fx if di else 1.0 - fx) * wy
                tr, tg, tb, ta = texel(tex, img, i1 if di else i0, jj)
                r += wt * tr
                g += wt * tg
                b += wt * tb
                a += wt * ta
        return r, g, b, a
    if extension == EXT_CLIP and (i < -2 or i > w or j < -2 or j > h):
        return r, g, b, a
    x0, x1, x2, x3 = _bspline(fx)
    y0, y1, y2, y3 = _bspline(fy)
    i0, i1 = wrap_index(i - 1, w, extension), wrap_index(i, w, extension)
    i2, i3 = wrap_index(i + 1, w, extension), wrap_index(i + 2, w, extension)
    for dj in range(4):
        wy = _tap(y0, y1, y2, y3, dj)
        jj = wrap_index(j - 1 + dj, h, extension)
        for di in range(4):
            wt = _tap(x0, x1, x2, x3, di) * wy
            tr, tg, tb, ta = texel(tex, img, _tap(i0, i1, i2, i3, di), jj)
            r += wt * tr
            g += wt * tg
            b += wt * tb
            a += wt * ta
    return r, g, b, a


# The sRGB curve's power segment, ((c + 0.055) / 1.055) ** 2.4, tabulated at SRGB_STEPS + 1
# points over [0, 1] and read with linear interpolation: within 2.3e-8 of the power (its second
# derivative is below 3.1 there; error <= 3.1 / (8 SRGB_STEPS^2)), and 2.8e-6 of it relatively at
# the segment's start, where Cycles' own decoding (a float power, fastpow24 on SSE) is
# float-precise.  A power per channel was about 4 % of the textured Cornell box's time.
SRGB_STEPS = 4096
SRGB_TABLE = ((np.arange(SRGB_STEPS + 1) / SRGB_STEPS + 0.055) / 1.055) ** 2.4


@device
def srgb_to_linear(c):
    """The sRGB decoding curve (negative values read as 0)."""
    if c < 0.04045:
        return max(c, 0.0) / 12.92
    if c < 1.0:
        s = c * SRGB_STEPS
        k = int(s)
        return SRGB_TABLE[k] + (s - k) * (SRGB_TABLE[k + 1] - SRGB_TABLE[k])
    return ((c + 0.055) / 1.055) ** 2.4      # above 1 (a colour divided by alpha) and NaN


@device
def image_texture(tex, img, x, y, interpolation, extension, alpha_linked):
    """Cycles' svm_image_texture: RGBA at (x, y), magenta for a missing image."""
    if img < 0 or img >= tex.images.shape[0]:
        return 1.0, 0.0, 1.0, 1.0
    r, g, b, a = interpolate(tex, img, x, y, interpolation, extension)
    flags = tex.images[img, IMG_FLAGS]
    if alpha_linked and (flags & IMGF_UNASSOCIATE) and a != 1.0 and a != 0.0:
        r, g, b = r / a, g / a, b / a
    if flags & IMGF_SRGB:
        r, g, b = srgb_to_linear(r), srgb_to_linear(g), srgb_to_linear(b)
    return r, g, b, a


# -- Image Texture -----------------------------------------------------------------------------
@device
def map_to_sphere(x, y, z):
    """Sphere projection of a point of the [0, 1] cube (util/math_float3.h)."""
    x, y, z = 2.0 * (x - 0.5), 2.0 * (y - 0.5), 2.0 * (z - 0.5)
    ln = math.sqrt(x * x + y * y + z * z)
    if ln <= 0.0:
        return 0.0, 0.0
    u = 0.0 if (x == 0.0 and y == 0.0) else 0.5 - math.atan2(x, y) / (2.0 * math.pi)
    return u, 1.0 - safe_acos(z / ln) / math.pi


@device
def map_to_tube(x, y, z):
    """Tube projection of a point of the [0, 1] cube."""
    x, y, z = 2.0 * (x - 0.5), 2.0 * (y - 0.5), 2.0 * (z - 0.5)
    ln = math.sqrt(x * x + y * y)
    if ln <= 0.0:
        return 0.0, 0.0
    return 0.5 * (1.0 - math.atan2(x / ln, y / ln) / math.pi), 0.5 * (z + 1.0)


@device
def box_weights(nx, ny, nz, blend):
    """Weights of the X, Y and Z faces for an object-space normal (svm_node_tex_image_box)."""
    nx, ny, nz = abs(nx), abs(ny), abs(nz)
    s = nx + ny + nz
    if s > 0.0:
        nx, ny, nz = nx / s, ny / s, nz / s
    limit = 0.5 * (1.0 + blend)
    wx = wy = wz = 0.0
    if nx > limit * (nx + ny) and nx > limit * (nx + nz):
        wx = 1.0
    elif ny > limit * (nx + ny) and ny > limit * (ny + nz):
        wy = 1.0
    elif nz > limit * (nx + nz) and nz > limit * (ny + nz):
        wz = 1.0
    elif blend > 0.0:
        half = 0.5 * (1.0 - blend)
        if nz < (1.0 - limit) * (ny + nx):
            wx = saturate((nx / (nx + ny) - half) / blend)
            wy = 1.0 - wx
        elif nx < (1.0 - limit) * (ny + nz):
            wy = min(max((ny / (ny + nz) - half) / blend, 0.0), 1.0)
            wz = 1.0 - wy
        elif ny < (1.0 - limit) * (nx + nz):
            wx = min(max((nx / (nx + nz) - half) / blend, 0.0), 1.0)
            wz = 1.0 - wx
        else:
            d = 2.0 * limit - 1.0
            wx = ((2.0 - limit) * nx + (limit - 1.0)) / d
            wy = ((2.0 - limit) * ny + (limit - 1.0)) / d
            wz = ((2.0 - limit) * nz + (limit - 1.0)) / d
    else:
        wx = 1.0
    return wx, wy, wz


@device
def image_texture_node(regs, b, c, sd, tex):
    img = int(regs[b + _TI_IMAGE])
    interpolation = int(regs[b + _TI_INTERPOLATION])
    extension = int(regs[b + _TI_EXTENSION])
    projection = int(regs[b + _TI_PROJECTION])
    alpha_linked = regs[b + _TI_ALPHA_LINKED] != 0.0
    v = b + _TI_VECTOR
    x, y, z = regs[v], regs[v + 1], regs[v + 2]
    if projection == PROJ_BOX:
        # The shading normal in object space (the transpose of object -> world).
        nx, ny, nz = sd.nx, sd.ny, sd.nz
        if sd.obj >= 0:
            m = tex.objects[sd.obj]
            o = OBJ_MATRIX
            nx, ny, nz = (m[o] * sd.nx + m[o + 4] * sd.ny + m[o + 8] * sd.nz,
                          m[o + 1] * sd.nx + m[o + 5] * sd.ny + m[o + 9] * sd.nz,
                          m[o + 2] * sd.nx + m[o + 6] * sd.ny + m[o + 10] * sd.nz)
        wx, wy, wz = box_weights(nx, ny, nz, regs[b + _TI_BLEND])
        r = g = bb = a = 0.0
        for face in range(3):
            wt = wx if face == 0 else (wy if face == 1 else wz)
            if wt <= 0.0:
                continue
            if face == 0:
                u, vv = (1.0 - y if nx < 0.0 else y), z
            elif face == 1:
                u, vv = (1.0 - x if ny > 0.0 else x), z
            else:
                u, vv = (1.0 - y if nz > 0.0 else y), x
            tr, tg, tb, ta = image_texture(tex, img, u, vv, interpolation, extension, alpha_linked)
            r += wt * tr
            g += wt * tg
            bb += wt * tb
            a += wt * ta
    else:
        if projection == PROJ_SPHERE:
            x, y = map_to_sphere(x, y, z)
        elif projection == PROJ_TUBE:
            x, y = map_to_tube(x, y, z)
        r, g, bb, a = image_texture(tex, img, x, y, interpolation, extension, alpha_linked)
    regs[c], regs[c + 1], regs[c + 2] = r, g, bb
    regs[c + 3] = a


# -- Environment Texture -----------------------------------------------------------------------
@device
def direction_to_equirectangular(x, y, z):
    """(u, v) of a direction in Blender's equirectangular image (v = 0: straight down)."""
    ln = math.sqrt(x * x + y * y + z * z)
    if ln <= 0.0:
        return 0.0, 0.0
    u = (math.atan2(y, x) - math.pi) / (-2.0 * math.pi)
    v = (safe_acos(z / ln) - math.pi) / (-math.pi)
    return u, v


@device
def direction_to_mirror_ball(x, y, z):
    """(u, v) of a unit direction on a mirror ball photographed from -Y."""
    y -= 1.0
    d = 2.0 * math.sqrt(max(-0.5 * y, 0.0))
    if d > 0.0:
        x, z = x / d, z / d
    return 0.5 * (x + 1.0), 0.5 * (z + 1.0)


@device
def environment_texture_node(regs, b, c, tex):
    v = b + _TE_VECTOR
    x, y, z = regs[v], regs[v + 1], regs[v + 2]
    ln = math.sqrt(x * x + y * y + z * z)
    if ln > 0.0:
        x, y, z = x / ln, y / ln, z / ln
    if int(regs[b + _TE_PROJECTION]) == PROJ_EQUIRECTANGULAR:
        u, vv = direction_to_equirectangular(x, y, z)
    else:
        u, vv = direction_to_mirror_ball(x, y, z)
    r, g, bb, a = image_texture(tex, int(regs[b + _TE_IMAGE]), u, vv,
                                int(regs[b + _TE_INTERPOLATION]), EXT_REPEAT,
                                regs[b + _TE_ALPHA_LINKED] != 0.0)
    regs[c], regs[c + 1], regs[c + 2] = r, g, bb
    regs[c + 3] = a


# -- Sky Texture ---------------------------------------------------------------------------------
@device
def sky_texture_node(regs, b, c, tex):
    """Cycles' sky_radiance_nishita: the sun disc where the direction is within half its
    angular diameter of the sun and above the horizon (the disc's XYZ interpolated by
    elevation from its bottom to its top, times the intensity and a limb darkening
    1 - 0.6 (1 - sqrt(1 - (angle / half)^2))), plus the sky image (mcengine.sky: XYZ, Linear,
    Extend) at the direction's azimuth from the sun and its elevation, square-root spaced;
    XYZ to the working space, negative values clamped to 0."""
    v = b + _TS_VECTOR
    x, y, z = regs[v], regs[v + 1], regs[v + 2]
    ln = math.sqrt(x * x + y * y + z * z)
    if ln > 0.0:
        x, y, z = x / ln, y / ln, z / ln
    elevation = math.pi / 2 - safe_acos(z)
    sun_elevation, rotation = regs[b + _TS_ELEVATION], regs[b + _TS_ROTATION]
    diameter = regs[b + _TS_DIAMETER]
    cx = cy = cz = 0.0
    if diameter >= 0.0:
        # The sun's direction: spherical (theta, phi) = (elevation - pi/2, rotation - pi/2).
        st, sp = sun_elevation - math.pi / 2, rotation - math.pi / 2
        sx, sy, sz = math.sin(st) * math.cos(sp), math.sin(st) * math.sin(sp), math.cos(st)
        dx, dy, dz = x - sx, y - sy, z - sz
        ax, ay, az = x + sx, y + sy, z + sz
        angle = 2.0 * math.atan2(math.sqrt(dx * dx + dy * dy + dz * dz),
                                 math.sqrt(ax * ax + ay * ay + az * az))
        half = 0.5 * diameter
        if angle < half and elevation > regs[b + _TS_HORIZON]:
            t = (elevation - sun_elevation) / diameter + 0.5
            q = angle / half
            k = regs[b + _TS_INTENSITY] * (1.0 - 0.6 * (1.0 - math.sqrt(1.0 - q * q)))
            cx = (regs[b + _TS_BOTTOM] + (regs[b + _TS_TOP] - regs[b + _TS_BOTTOM]) * t) * k
            cy = (regs[b + _TS_BOTTOM + 1] + (regs[b + _TS_TOP + 1] - regs[b + _TS_BOTTOM + 1]) * t) * k
            cz = (regs[b + _TS_BOTTOM + 2] + (regs[b + _TS_TOP + 2] - regs[b + _TS_BOTTOM + 2]) * t) * k
    u = (-math.atan2(y, x) - math.pi / 2 + rotation) * (0.5 / math.pi)
    u -= math.floor(u)
    vv = math.copysign(math.sqrt(abs(elevation) * (2.0 / math.pi)), elevation) * 0.5 + 0.5
    sx_, sy_, sz_, _ = image_texture(tex, int(regs[b + _TS_IMAGE]), u, vv, INTERP_LINEAR,
                                     EXT_EXTEND, False)
    cx, cy, cz = cx + sx_, cy + sy_, cz + sz_
    m = XYZ_TO_RGB
    regs[c] = max(m[0, 0] * cx + m[0, 1] * cy + m[0, 2] * cz, 0.0)
    regs[c + 1] = max(m[1, 0] * cx + m[1, 1] * cy + m[1, 2] * cz, 0.0)
    regs[c + 2] = max(m[2, 0] * cx + m[2, 1] * cy + m[2, 2] * cz, 0.0)
