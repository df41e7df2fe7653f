"""Colour nodes: Mix, ColorRamp, curves and colour adjustments (kernel/svm/mix.h, color_util.h,
ramp.h, hsv.h, invert.h, gamma.h, brightness.h).

``eval_color_node`` evaluates one node: inputs at regs[b:] in the order of
``nodes.VALUE_NODES``, outputs to regs[c:].  A ColorRamp or a curve arrives
as the table Cycles bakes from it at export (``nodes.RAMP_TABLE_SIZE`` + 1
entries: RGBA for a ramp, RGB for RGB and Vector Curves, one value for a
Float Curve), looked up with Cycles' linear interpolation between entries
and, for curves whose extension is "Extrapolated", its linear continuation
past the ends.
"""
from __future__ import annotations

import math

from ...jit import device, function
from ..colorspace import hsv_to_rgb, rgb_to_hsv
from ..scalar import saturate
from .nodes import (
    DATA_FLOAT,
    DATA_VECTOR,
    FACTOR_NON_UNIFORM,
    MIX_ADD,
    MIX_BLEND,
    MIX_BURN,
    MIX_COLOR,
    MIX_DARKEN,
    MIX_DIFFERENCE,
    MIX_DIVIDE,
    MIX_DODGE,
    MIX_EXCLUSION,
    MIX_HUE,
    MIX_LIGHTEN,
    MIX_LINEAR_LIGHT,
    MIX_MULTIPLY,
    MIX_OVERLAY,
    MIX_SATURATION,
    MIX_SCREEN,
    MIX_SOFT_LIGHT,
    MIX_SUBTRACT,
    MIX_VALUE,
    NODES,
    OFFSETS,
)

_MIX = NODES["Mix"].code
_MIX_RGB = NODES["MixRGB"].code
_RAMP = NODES["ValToRGB"].code
_RGB_CURVE = NODES["RGBCurve"].code
_VECTOR_CURVE = NODES["VectorCurve"].code
_FLOAT_CURVE = NODES["FloatCurve"].code
_HSV = NODES["HueSaturation"].code
_INVERT = NODES["Invert"].code
_BRIGHT = NODES["BrightContrast"].code
_GAMMA = NODES["Gamma"].code

_M = OFFSETS["Mix"]
_M_FAC = _M["Factor_Float"]
_M_FAC_V = _M["Factor_Vector"]
_M_A = _M["A_Float"]
_M_B = _M["B_Float"]
_M_A_V = _M["A_Vector"]
_M_B_V = _M["B_Vector"]
_M_A_C = _M["A_Color"]
_M_B_C = _M["B_Color"]
_M_DATA = _M["prop:data_type"]
_M_FACTOR_MODE = _M["prop:factor_mode"]
_M_BLEND = _M["prop:blend_type"]
_M_CLAMP = _M["prop:clamp_factor"]
_M_CLAMP_RESULT = _M["prop:clamp_result"]
_MR = OFFSETS["MixRGB"]
_MR_FAC = _MR["Fac"]
_MR_C1 = _MR["Color1"]
_MR_C2 = _MR["Color2"]
_MR_BLEND = _MR["prop:blend_type"]
_MR_CLAMP = _MR["prop:use_clamp"]
_R_FAC = OFFSETS["ValToRGB"]["Fac"]
_R_INTERPOLATE = OFFSETS["ValToRGB"]["prop:interpolate"]
_R_TABLE = OFFSETS["ValToRGB"]["prop:table"]
# The three curve nodes share one layout: factor, input, min_x, max_x, extrapolate, table.
_C = OFFSETS["RGBCurve"]
_C_FAC = _C["Fac"]
_C_IN = _C["Color"]
_C_MIN = _C["prop:min_x"]
_C_MAX = _C["prop:max_x"]
_C_EXTRAPOLATE = _C["prop:extrapolate"]
_C_TABLE = _C["prop:table"]
_FC = OFFSETS["FloatCurve"]
_FC_FAC = _FC["Factor"]
_FC_IN = _FC["Value"]
_FC_MIN = _FC["prop:min_x"]
_FC_MAX = _FC["prop:max_x"]
_FC_EXTRAPOLATE = _FC["prop:extrapolate"]
_FC_TABLE = _FC["prop:table"]
_H = OFFSETS["HueSaturation"]
_H_HUE = _H["Hue"]
_H_SAT = _H["Saturation"]
_H_VAL = _H["Value"]
_H_FAC = _H["Fac"]
_H_COLOR = _H["Color"]
_I_FAC = OFFSETS["Invert"]["Fac"]
_I_COLOR = OFFSETS["Invert"]["Color"]
_B_COLOR = OFFSETS["BrightContrast"]["Color"]
_B_BRIGHT = OFFSETS["BrightContrast"]["Bright"]
_B_CONTRAST = OFFSETS["BrightContrast"]["Contrast"]
_G_COLOR = OFFSETS["Gamma"]["Color"]
_G_GAMMA = OFFSETS["Gamma"]["Gamma"]


@function
def eval_color_node(code, regs, b, c):
    if code == _MIX:
        mix_node(regs, b, c)
    elif code == _MIX_RGB:
        # The legacy node always clamps its factor; "Clamp" clamps the result.
        t = saturate(regs[b + _MR_FAC])
        k = b + _MR_C1
        q = b + _MR_C2
        r, g, bl = mix_colors(int(regs[b + _MR_BLEND]), t, regs[k], regs[k + 1], regs[k + 2],
                              regs[q], regs[q + 1], regs[q + 2])
        if regs[b + _MR_CLAMP] != 0.0:
            r, g, bl = saturate(r), saturate(g), saturate(bl)
        regs[c], regs[c + 1], regs[c + 2] = r, g, bl
    elif code == _RAMP:
        ramp_node(regs, b, c)
    elif code == _RGB_CURVE or code == _VECTOR_CURVE:
        curves_node(regs, b, c)
    elif code == _FLOAT_CURVE:
        float_curve_node(regs, b, c)
    elif code == _HSV:
        hsv_node(regs, b, c)
    elif code == _INVERT:
        f = regs[b + _I_FAC]
        for k in range(3):
            x = regs[b + _I_COLOR + k]
            regs[c + k] = f * (1.0 - x) + (1.0 - f) * x
    elif code == _BRIGHT:
        bright = regs[b + _B_BRIGHT]
        contrast = regs[b + _B_CONTRAST]
        a = 1.0 + contrast
        off = bright - contrast * 0.5
        for k in range(3):
            regs[c + k] = positive(a * regs[b + _B_COLOR + k] + off)
    elif code == _GAMMA:
        gamma = regs[b + _G_GAMMA]
        for k in range(3):
            x = regs[b + _G_COLOR + k]
            if gamma == 0.0:
                x = 1.0
            elif x > 0.0:
                x = x ** gamma
            regs[c + k] = x


@device
def positive(x):
    """Cycles' max(x, 0): NaN gives 0."""
    return x if x > 0.0 else 0.0


@device
def lerp(a, b, t):
    return (1.0 - t) * a + t * b


# -- Mix ----------------------------------------------------------------------------------------
@device
def _blend(kind, t, a, b):
    """One channel of the blend modes that work channel by channel (color_util.h)."""
    tm = 1.0 - t
    if kind == MIX_BLEND:
        return lerp(a, b, t)
    if kind == MIX_ADD:
        return lerp(a, a + b, t)
    if kind == MIX_MULTIPLY:
        return lerp(a, a * b, t)
    if kind == MIX_SUBTRACT:
        return lerp(a, a - b, t)
    if kind == MIX_SCREEN:
        return 1.0 - (tm + t * (1.0 - b)) * (1.0 - a)
    if kind == MIX_DIVIDE:
        return tm * a + t * a / b if b != 0.0 else a
    if kind == MIX_DIFFERENCE:
        return lerp(a, abs(a - b), t)
    if kind == MIX_EXCLUSION:
        return max(lerp(a, a + b - 2.0 * a * b, t), 0.0)
    if kind == MIX_DARKEN:
        return lerp(a, min(a, b), t)
    if kind == MIX_LIGHTEN:
        return lerp(a, max(a, b), t)
    if kind == MIX_OVERLAY:
        if a < 0.5:
            return a * (tm + 2.0 * t * b)
        return 1.0 - (tm + 2.0 * t * (1.0 - b)) * (1.0 - a)
    if kind == MIX_DODGE:
        if a == 0.0:
            return a
        d = 1.0 - t * b
        if d <= 0.0:
            return 1.0
        return min(a / d, 1.0)
    if kind == MIX_BURN:
        d = tm + t * b
        if d <= 0.0:
            return 0.0
        return saturate(1.0 - (1.0 - a) / d)
    if kind == MIX_SOFT_LIGHT:
        screen = 1.0 - (1.0 - b) * (1.0 - a)
        return tm * a + t * ((1.0 - a) * b * a + a * screen)
    if kind == MIX_LINEAR_LIGHT:
        return a + t * (2.0 * b - 1.0)
    return 0.0


@device
def mix_colors(kind, t, ar, ag, ab, br, bg, bb):
    """Cycles' svm_mix: colour A blended with B by mode ``kind`` at factor t."""
    if kind == MIX_HUE or kind == MIX_COLOR:
        h2, s2, _v2 = rgb_to_hsv(br, bg, bb)
        if s2 == 0.0:
            return ar, ag, ab
        h, s, v = rgb_to_hsv(ar, ag, ab)
        r, g, b = hsv_to_rgb(h2, s2 if kind == MIX_COLOR else s, v)
        return lerp(ar, r, t), lerp(ag, g, t), lerp(ab, b, t)
    if kind == MIX_SATURATION:
        h, s, v = rgb_to_hsv(ar, ag, ab)
        if s == 0.0:
            return ar, ag, ab
        _h2, s2, _v2 = rgb_to_hsv(br, bg, bb)
        return hsv_to_rgb(h, (1.0 - t) * s + t * s2, v)
    if kind == MIX_VALUE:
        h, s, v = rgb_to_hsv(ar, ag, ab)
        _h2, _s2, v2 = rgb_to_hsv(br, bg, bb)
        return hsv_to_rgb(h, s, (1.0 - t) * v + t * v2)
    return _blend(kind, t, ar, br), _blend(kind, t, ag, bg), _blend(kind, t, ab, bb)


@device
def mix_node(regs, b, c):
    """The Mix node: float, vector (uniform or per-component factor) or colour."""
    data = int(regs[b + _M_DATA])
    clamp = regs[b + _M_CLAMP] != 0.0
    t = regs[b + _M_FAC]
    if clamp:
        t = saturate(t)
    regs[c] = regs[c + 1] = regs[c + 2] = regs[c + 3] = 0.0
    regs[c + 4] = regs[c + 5] = regs[c + 6] = 0.0
    if data == DATA_FLOAT:
        regs[c] = regs[b + _M_A] * (1.0 - t) + regs[b + _M_B] * t
    elif data == DATA_VECTOR:
        non_uniform = int(regs[b + _M_FACTOR_MODE]) == FACTOR_NON_UNIFORM
        for k in range(3):
            tk = t
            if non_uniform:
                tk = regs[b + _M_FAC_V + k]
                if clamp:
                    tk = saturate(tk)
            regs[c + 1 + k] = regs[b + _M_A_V + k] * (1.0 - tk) + regs[b + _M_B_V + k] * tk
    else:
        a = b + _M_A_C
        q = b + _M_B_C
        r, g, bl = mix_colors(int(regs[b + _M_BLEND]), t, regs[a], regs[a + 1], regs[a + 2],
                              regs[q], regs[q + 1], regs[q + 2])
        if regs[b + _M_CLAMP_RESULT] != 0.0:
            r, g, bl = saturate(r), saturate(g), saturate(bl)
        regs[c + 4], regs[c + 5], regs[c + 6] = r, g, bl


# -- ramps and curves (ramp.h) ------------------------------------------------------------------
@device
def ramp_lookup(regs, table, stride, channel, f, interpolate, extrapolate):
    """Channel ``channel`` of a baked table (count at regs[table], then entries of ``stride``
    values) at position f in [0, 1]; linear past the ends when ``extrapolate``."""
    n = int(regs[table]) // stride
    first = table + 1 + channel
    if extrapolate and (f < 0.0 or f > 1.0):
        if f < 0.0:
            t0 = regs[first]
            dy = t0 - regs[first + stride]
            f = -f
        else:
            t0 = regs[first + (n - 1) * stride]
            dy = t0 - regs[first + (n - 2) * stride]
            f = f - 1.0
        return t0 + dy * f * (n - 1)
    f = saturate(f) * (n - 1)
    i = min(int(f), n - 1)
    t = f - i
    a = regs[first + i * stride]
    if interpolate and t > 0.0:
        a = (1.0 - t) * a + t * regs[first + (i + 1) * stride]
    return a


@device
def ramp_node(regs, b, c):
    """ColorRamp: the ramp's colour and alpha at Fac (Constant ramps are not interpolated)."""
    f = regs[b + _R_FAC]
    interpolate = regs[b + _R_INTERPOLATE] != 0.0
    table = b + _R_TABLE
    for k in range(4):
        regs[c + k] = ramp_lookup(regs, table, 4, k, f, interpolate, False)


@device
def curves_node(regs, b, c):
    """RGB Curves and Vector Curves: each component through its curve, mixed in by Fac."""
    fac = regs[b + _C_FAC]
    lo = regs[b + _C_MIN]
    span = regs[b + _C_MAX] - lo
    extrapolate = regs[b + _C_EXTRAPOLATE] != 0.0
    for k in range(3):
        x = regs[b + _C_IN + k]
        y = ramp_lookup(regs, b + _C_TABLE, 3, k, (x - lo) / span, True, extrapolate)
        regs[c + k] = (1.0 - fac) * x + fac * y


@device
def float_curve_node(regs, b, c):
    fac = regs[b + _FC_FAC]
    x = regs[b + _FC_IN]
    lo = regs[b + _FC_MIN]
    span = regs[b + _FC_MAX] - lo
    y = ramp_lookup(regs, b + _FC_TABLE, 1, 0, (x - lo) / span, True,
                    regs[b + _FC_EXTRAPOLATE] != 0.0)
    regs[c] = (1.0 - fac) * x + fac * y


@device
def hsv_node(regs, b, c):
    """Hue/Saturation/Value: shift the hue, scale saturation and value, mix in by Fac."""
    fac = regs[b + _H_FAC]
    k = b + _H_COLOR
    r0, g0, b0 = regs[k], regs[k + 1], regs[k + 2]
    h, s, v = rgb_to_hsv(r0, g0, b0)
    h = h + regs[b + _H_HUE] + 0.5
    h -= math.floor(h)
    s = saturate(s * regs[b + _H_SAT])
    v *= regs[b + _H_VAL]
    r, g, bl = hsv_to_rgb(h, s, v)
    regs[c] = positive(fac * r + (1.0 - fac) * r0)
    regs[c + 1] = positive(fac * g + (1.0 - fac) * g0)
    regs[c + 2] = positive(fac * bl + (1.0 - fac) * b0)
