"""IES light profiles looked up as Cycles looks them up (kernel/util/ies.h, svm/ies.h).

A profile is a block of the flat float64 array ``ies`` (``mcengine.ies.IESProfile.packed``):
H, V, the wrap flags (horizontal, vertical low, vertical high), H horizontal and V vertical
angles in radians, then the H x V intensities.  A direction in the lamp's frame has the
vertical angle acos(-z) (0 = local -Z, the nadir) and the horizontal angle
atan2(x, y) + pi (0 = local -Y, pi/2 = -X); the value is the Catmull-Rom interpolation of
the table, vertically within the columns around it and then across them, clamped at 0, and
0 outside the angles the table covers (upper ends excluded).
"""
from __future__ import annotations

import math

from ..jit import device, function

IES_HEAD = 5          # H, V, wrap_h, wrap_vlow, wrap_vhigh


@device
def cubic_interp(a, b, c, d, x):
    """Catmull-Rom through b (x = 0) and c (x = 1), as Cycles' cubic_interp."""
    return 0.5 * (((d + 3.0 * (b - c) - a) * x + (2.0 * a - 5.0 * b + 4.0 * c - d)) * x + (c - a)) * x + b


@device
def _vertical(ies, base, wrap_vlow, wrap_vhigh, v, v_num, v_frac, h):
    """The column ``h`` interpolated at row ``v`` + ``v_frac`` (ies[base + h * v_num + row])."""
    col = base + h * v_num
    b = ies[col + v]
    c = ies[col + v + 1]
    a = b
    if v > 0:
        a = ies[col + v - 1]
    elif wrap_vlow:
        a = ies[col + 1]
    d = c
    if v + 2 < v_num:
        d = ies[col + v + 2]
    elif wrap_vhigh:
        d = ies[col + v_num - 2]
    return cubic_interp(a, b, c, d, v_frac)


@device
def _fraction(a, b, x):
    """Where x lies between angles a and b (Cycles' inverse_lerp); 0 where a file repeats an
    angle (b = a), which Cycles divides by."""
    return (x - a) / (b - a) if b > a else 0.0


@function
def ies_lookup(ies, ofs, h_angle, v_angle):
    """The profile at ``ies[ofs:]`` at the angles (radians), as Cycles' kernel_ies_interp."""
    h_num = int(ies[ofs])
    v_num = int(ies[ofs + 1])
    wrap_h = ies[ofs + 2] != 0.0
    wrap_vlow = ies[ofs + 3] != 0.0
    wrap_vhigh = ies[ofs + 4] != 0.0
    hs = ofs + IES_HEAD
    vs = hs + h_num
    if v_angle < ies[vs] or v_angle >= ies[vs + v_num - 1]:
        return 0.0
    if h_angle < ies[hs] or h_angle >= ies[hs + h_num - 1]:
        return 0.0
    h_i = 0
    while ies[hs + h_i + 1] < h_angle:
        h_i += 1
    v_i = 0
    while ies[vs + v_i + 1] < v_angle:
        v_i += 1
    h_frac = _fraction(ies[hs + h_i], ies[hs + h_i + 1], h_angle)
    v_frac = _fraction(ies[vs + v_i], ies[vs + v_i + 1], v_angle)
    base = vs + v_num
    b = _vertical(ies, base, wrap_vlow, wrap_vhigh, v_i, v_num, v_frac, h_i)
    c = _vertical(ies, base, wrap_vlow, wrap_vhigh, v_i, v_num, v_frac, h_i + 1)
    a = b
    if h_i > 0:
        a = _vertical(ies, base, wrap_vlow, wrap_vhigh, v_i, v_num, v_frac, h_i - 1)
    elif wrap_h:
        a = _vertical(ies, base, wrap_vlow, wrap_vhigh, v_i, v_num, v_frac, h_num - 2)
    d = b       # (not c: Cycles falls back to b at the last column)
    if h_i + 2 < h_num:
        d = _vertical(ies, base, wrap_vlow, wrap_vhigh, v_i, v_num, v_frac, h_i + 2)
    elif wrap_h:
        d = _vertical(ies, base, wrap_vlow, wrap_vhigh, v_i, v_num, v_frac, 1)
    return max(cubic_interp(a, b, c, d, h_frac), 0.0)


@function
def ies_direction(ies, ofs, x, y, z):
    """The profile at ``ies[ofs:]`` along the direction (x, y, z) of the lamp's frame (any
    length; 0 for the zero vector)."""
    n = math.sqrt(x * x + y * y + z * z)
    if not n > 0.0:
        return 0.0
    cz = min(max(-z / n, -1.0), 1.0)
    return ies_lookup(ies, ofs, math.atan2(x, y) + math.pi, math.acos(cz))
