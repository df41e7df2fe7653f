"""Converter nodes: Math, Vector Math, Map Range, Clamp, Separate/Combine XYZ and Color,
RGB to BW, Blackbody, Wavelength (kernel/svm/math_util.h, math.h, map_range.h, clamp.h,
sepcomb_*.h, convert.h, blackbody.h, wavelength.h).

``eval_math_node`` evaluates one node of the family: inputs at regs[b:] in the
order of ``nodes.VALUE_NODES``, outputs to regs[c:].  Every operation follows
Cycles' definition at its edges (division by zero, logarithms and powers of
negatives, zero-length vectors: the ``safe_*`` functions of util/math_*.h).
Cycles computes in single precision, these in double: results agree to float
rounding.  An output the operation does not define (Vector Math's Value for a
vector operation and the other way round; Blender hides that socket) is 0.
"""
from __future__ import annotations

import math

import numpy as np

from ...jit import device, function
from ..colorspace import blackbody, hsl_to_rgb, hsv_to_rgb, luminance, rgb_to_hsl, rgb_to_hsv, wavelength
from ..scalar import safe_acos
from .nodes import (
    CLAMP_TYPES,
    COLOR_MODES,
    DATA_TYPES,
    MAP_RANGE_INTERPOLATIONS,
    NODES,
    OFFSETS,
    OPERATIONS,
    OUTPUT_OFFSETS,
)

FLT_MAX = 3.4028234663852886e38      # the largest float32 (Cycles' FLT_MAX)

_MATH = NODES["Math"].code
_VECTOR_MATH = NODES["VectorMath"].code
_MAP_RANGE = NODES["MapRange"].code
_CLAMP = NODES["Clamp"].code
_SEPARATE_XYZ = NODES["SeparateXYZ"].code
_COMBINE_XYZ = NODES["CombineXYZ"].code
_SEPARATE_COLOR = NODES["SeparateColor"].code
_COMBINE_COLOR = NODES["CombineColor"].code
_RGB_TO_BW = NODES["RGBToBW"].code
_BLACKBODY = NODES["Blackbody"].code
_WAVELENGTH = NODES["Wavelength"].code

_M_B = OFFSETS["Math"]["Value_001"]
_M_C = OFFSETS["Math"]["Value_002"]
_M_OP = OFFSETS["Math"]["prop:operation"]
_M_CLAMP = OFFSETS["Math"]["prop:use_clamp"]
_VM_B = OFFSETS["VectorMath"]["Vector_001"]
_VM_C = OFFSETS["VectorMath"]["Vector_002"]
_VM_SCALE = OFFSETS["VectorMath"]["Scale"]
_VM_OP = OFFSETS["VectorMath"]["prop:operation"]
_VM_VALUE_OUT = OUTPUT_OFFSETS["VectorMath"]["Value"]
_MR = OFFSETS["MapRange"]
_MR_FROM_MIN, _MR_FROM_MAX = _MR["From Min"], _MR["From Max"]
_MR_TO_MIN, _MR_TO_MAX, _MR_STEPS = _MR["To Min"], _MR["To Max"], _MR["Steps"]
_MR_VECTOR = _MR["Vector"]
_MR_FROM_MIN3, _MR_FROM_MAX3 = _MR["From_Min_FLOAT3"], _MR["From_Max_FLOAT3"]
_MR_TO_MIN3, _MR_TO_MAX3, _MR_STEPS3 = _MR["To_Min_FLOAT3"], _MR["To_Max_FLOAT3"], _MR["Steps_FLOAT3"]
_MR_CLAMP, _MR_INTERP, _MR_TYPE = _MR["prop:clamp"], _MR["prop:interpolation_type"], _MR["prop:data_type"]
_MR_VECTOR_OUT = OUTPUT_OFFSETS["MapRange"]["Vector"]
_CL_MIN = OFFSETS["Clamp"]["Min"]
_CL_MAX = OFFSETS["Clamp"]["Max"]
_CL_TYPE = OFFSETS["Clamp"]["prop:clamp_type"]
_SC_MODE = OFFSETS["SeparateColor"]["prop:mode"]
_CC_MODE = OFFSETS["CombineColor"]["prop:mode"]

_CLAMP_RANGE = CLAMP_TYPES["RANGE"]
_FLOAT_VECTOR = DATA_TYPES["FLOAT_VECTOR"]
_STEPPED = MAP_RANGE_INTERPOLATIONS["STEPPED"]
_SMOOTHSTEP = MAP_RANGE_INTERPOLATIONS["SMOOTHSTEP"]
_SMOOTHERSTEP = MAP_RANGE_INTERPOLATIONS["SMOOTHERSTEP"]
_HSV = COLOR_MODES["HSV"]
_HSL = COLOR_MODES["HSL"]

_O = OPERATIONS
OP_ADD, OP_SUBTRACT, OP_MULTIPLY, OP_DIVIDE = _O["ADD"], _O["SUBTRACT"], _O["MULTIPLY"], _O["DIVIDE"]
OP_MULTIPLY_ADD, OP_POWER, OP_LOGARITHM = _O["MULTIPLY_ADD"], _O["POWER"], _O["LOGARITHM"]
OP_SQRT, OP_INVERSE_SQRT, OP_ABSOLUTE, OP_EXPONENT = (_O["SQRT"], _O["INVERSE_SQRT"], _O["ABSOLUTE"],
                                                      _O["EXPONENT"])
OP_MINIMUM, OP_MAXIMUM, OP_LESS_THAN, OP_GREATER_THAN = (_O["MINIMUM"], _O["MAXIMUM"], _O["LESS_THAN"],
                                                         _O["GREATER_THAN"])
OP_SIGN, OP_COMPARE, OP_SMOOTH_MIN, OP_SMOOTH_MAX = (_O["SIGN"], _O["COMPARE"], _O["SMOOTH_MIN"],
                                                     _O["SMOOTH_MAX"])
OP_ROUND, OP_FLOOR, OP_CEIL, OP_TRUNC, OP_FRACT = (_O["ROUND"], _O["FLOOR"], _O["CEIL"], _O["TRUNC"],
                                                   _O["FRACT"])
OP_MODULO, OP_FLOORED_MODULO, OP_WRAP, OP_SNAP, OP_PINGPONG = (
    _O["MODULO"], _O["FLOORED_MODULO"], _O["WRAP"], _O["SNAP"], _O["PINGPONG"])
OP_SINE, OP_COSINE, OP_TANGENT = _O["SINE"], _O["COSINE"], _O["TANGENT"]
OP_ARCSINE, OP_ARCCOSINE, OP_ARCTANGENT, OP_ARCTAN2 = (_O["ARCSINE"], _O["ARCCOSINE"], _O["ARCTANGENT"],
                                                       _O["ARCTAN2"])
OP_SINH, OP_COSH, OP_TANH, OP_RADIANS, OP_DEGREES = (_O["SINH"], _O["COSH"], _O["TANH"], _O["RADIANS"],
                                                     _O["DEGREES"])
OP_CROSS_PRODUCT, OP_PROJECT, OP_REFLECT, OP_REFRACT = (_O["CROSS_PRODUCT"], _O["PROJECT"], _O["REFLECT"],
                                                        _O["REFRACT"])
OP_FACEFORWARD, OP_DOT_PRODUCT, OP_DISTANCE, OP_LENGTH = (_O["FACEFORWARD"], _O["DOT_PRODUCT"],
                                                          _O["DISTANCE"], _O["LENGTH"])
OP_SCALE, OP_NORMALIZE, OP_FRACTION = _O["SCALE"], _O["NORMALIZE"], _O["FRACTION"]

FLT_EPSILON = 1.1920928955078125e-07
_INT_MIN = -2147483648.0


@function
def eval_math_node(code, regs, b, c):
    if code == _MATH:
        r = math_op(int(regs[b + _M_OP]), regs[b], regs[b + _M_B], regs[b + _M_C])
        if regs[b + _M_CLAMP] != 0.0:
            r = min(max(r, 0.0), 1.0)
        regs[c] = r
    elif code == _VECTOR_MATH:
        vector_math_node(regs, b, c)
    elif code == _MAP_RANGE:
        if int(regs[b + _MR_TYPE]) == _FLOAT_VECTOR:
            map_range_vector(regs, b, c + _MR_VECTOR_OUT)
            regs[c] = 0.0
        else:
            regs[c] = map_range_float(regs, b)
            for k in range(3):
                regs[c + _MR_VECTOR_OUT + k] = 0.0
    elif code == _CLAMP:
        lo, hi = regs[b + _CL_MIN], regs[b + _CL_MAX]
        if int(regs[b + _CL_TYPE]) == _CLAMP_RANGE and lo > hi:
            lo, hi = hi, lo
        regs[c] = min(max(regs[b], lo), hi)
    elif code == _SEPARATE_XYZ or code == _COMBINE_XYZ:    # the same three registers
        regs[c], regs[c + 1], regs[c + 2] = regs[b], regs[b + 1], regs[b + 2]
    elif code == _SEPARATE_COLOR:
        x, y, z = regs[b], regs[b + 1], regs[b + 2]
        mode = int(regs[b + _SC_MODE])
        if mode == _HSV:
            x, y, z = rgb_to_hsv(x, y, z)
        elif mode == _HSL:
            x, y, z = rgb_to_hsl(x, y, z)
        regs[c], regs[c + 1], regs[c + 2] = x, y, z
    elif code == _COMBINE_COLOR:
        x, y, z = regs[b], regs[b + 1], regs[b + 2]
        mode = int(regs[b + _CC_MODE])
        if mode == _HSV:
            x, y, z = hsv_to_rgb(x, y, z)
        elif mode == _HSL:
            x, y, z = hsl_to_rgb(x, y, z)
        regs[c], regs[c + 1], regs[c + 2] = x, y, z
    elif code == _RGB_TO_BW:
        regs[c] = luminance(regs[b], regs[b + 1], regs[b + 2])
    elif code == _BLACKBODY:
        regs[c], regs[c + 1], regs[c + 2] = blackbody(regs[b])
    elif code == _WAVELENGTH:
        regs[c], regs[c + 1], regs[c + 2] = wavelength(regs[b])


# -- scalar helpers (util/math_base.h) ------------------------------------------------------------
@device
def safe_divide(a, b):
    return a / b if b != 0.0 else 0.0


@device
def _as_int32(x):
    """C's (int) conversion of a float as x86 does it: toward zero, INT_MIN when out of range."""
    if not (x > -2147483649.0 and x < 2147483648.0):
        return _INT_MIN
    return float(int(x))


@device
def safe_pow(a, b):
    """Cycles' safe_powf: 0 for a negative base with a non-integer exponent, x^0 = 1, 0^y = 0."""
    if a < 0.0 and b != _as_int32(b):
        return 0.0
    if b == 0.0:
        return 1.0
    if a == 0.0:
        return 0.0
    return math.pow(a, b)


@device
def fract(a):
    return a - math.floor(a)


@device
def fmod(a, b):
    """C's fmod(a, b), bit for bit; a itself when |a| < |b| (nearly always, in the textures'
    coordinate wrapping), without the library call, which costs as much as a Perlin lattice."""
    if abs(a) < abs(b):
        return a
    return np.fmod(a, b)


@device
def sign(a):
    if a == 0.0:
        return 0.0
    return -1.0 if a < 0.0 else 1.0


@device
def smooth_min(a, b, k):
    if k != 0.0:
        h = max(k - abs(a - b), 0.0) / k
        return min(a, b) - h * h * h * k * (1.0 / 6.0)
    return min(a, b)


@device
def math_op(op, a, b, c):
    """The Math node's operation ``op`` (``nodes.OPERATIONS``) on a, b, c (svm_math)."""
    if op == OP_ADD:
        return a + b
    if op == OP_SUBTRACT:
        return a - b
    if op == OP_MULTIPLY:
        return a * b
    if op == OP_DIVIDE:
        return safe_divide(a, b)
    if op == OP_MULTIPLY_ADD:
        return a * b + c
    if op == OP_POWER:
        return safe_pow(a, b)
    if op == OP_LOGARITHM:
        if a <= 0.0 or b <= 0.0:
            return 0.0
        return safe_divide(math.log(a), math.log(b))
    if op == OP_SQRT:
        return math.sqrt(max(a, 0.0))
    if op == OP_INVERSE_SQRT:
        return 1.0 / math.sqrt(a) if a > 0.0 else 0.0
    if op == OP_ABSOLUTE:
        return abs(a)
    if op == OP_EXPONENT:
        return math.exp(a)
    if op == OP_MINIMUM:
        return min(a, b)
    if op == OP_MAXIMUM:
        return max(a, b)
    if op == OP_LESS_THAN:
        return 1.0 if a < b else 0.0
    if op == OP_GREATER_THAN:
        return 1.0 if a > b else 0.0
    if op == OP_SIGN:
        return sign(a)
    if op == OP_COMPARE:
        return 1.0 if a == b or abs(a - b) <= max(c, FLT_EPSILON) else 0.0
    if op == OP_SMOOTH_MIN:
        return smooth_min(a, b, c)
    if op == OP_SMOOTH_MAX:
        return -smooth_min(-a, -b, c)
    if op == OP_ROUND:
        return math.floor(a + 0.5)
    if op == OP_FLOOR:
        return math.floor(a)
    if op == OP_CEIL:
        return math.ceil(a)
    if op == OP_TRUNC:
        return math.floor(a) if a >= 0.0 else math.ceil(a)
    if op == OP_FRACT:
        return fract(a)
    if op == OP_MODULO:
        return fmod(a, b) if b != 0.0 else 0.0
    if op == OP_FLOORED_MODULO:
        return a - math.floor(a / b) * b if b != 0.0 else 0.0
    if op == OP_WRAP:                       # wrap a into [c, b)
        r = b - c
        return a - r * math.floor((a - c) / r) if r != 0.0 else c
    if op == OP_SNAP:
        return math.floor(safe_divide(a, b)) * b
    if op == OP_PINGPONG:
        return abs(fract((a - b) / (b * 2.0)) * b * 2.0 - b) if b != 0.0 else 0.0
    if op == OP_SINE:
        return math.sin(a)
    if op == OP_COSINE:
        return math.cos(a)
    if op == OP_TANGENT:
        return math.tan(a)
    if op == OP_SINH:
        return math.sinh(a)
    if op == OP_COSH:
        return math.cosh(a)
    if op == OP_TANH:
        return math.tanh(a)
    if op == OP_ARCSINE:
        return math.asin(min(max(a, -1.0), 1.0))
    if op == OP_ARCCOSINE:
        return safe_acos(a)
    if op == OP_ARCTANGENT:
        return math.atan(a)
    if op == OP_ARCTAN2:
        return 0.0 if a == 0.0 and b == 0.0 else math.atan2(a, b)
    if op == OP_RADIANS:
        return a * (math.pi / 180.0)
    if op == OP_DEGREES:
        return a * (180.0 / math.pi)
    return 0.0


# -- vectors (util/math_float3.h) -----------------------------------------------------------------
@device
def _dot(ax, ay, az, bx, by, bz):
    return ax * bx + ay * by + az * bz


@device
def safe_normalize(x, y, z):
    """Unit vector; a zero vector stays zero."""
    n = math.sqrt(x * x + y * y + z * z)
    if n != 0.0:
        inv = 1.0 / n
        return x * inv, y * inv, z * inv
    return x, y, z


@device
def _trunc_mod(a, b):
    """Vector Math's modulo: a - trunc(a / b) b (Cycles' SIMD fmod), 0 where b = 0."""
    if b == 0.0:
        return 0.0
    q = a / b
    return a - (math.floor(q) if q >= 0.0 else math.ceil(q)) * b


@device
def _floored_mod(a, b):
    return a - math.floor(a / b) * b if b != 0.0 else 0.0


@device
def vector_op(op, a, b):
    """A per-component Vector Math operation on components a, b."""
    if op == OP_ADD:
        return a + b
    if op == OP_SUBTRACT:
        return a - b
    if op == OP_MULTIPLY:
        return a * b
    if op == OP_DIVIDE:
        return safe_divide(a, b)
    if op == OP_SNAP:
        return math.floor(safe_divide(a, b)) * b
    if op == OP_FLOOR:
        return math.floor(a)
    if op == OP_CEIL:
        return math.ceil(a)
    if op == OP_MODULO:
        return _trunc_mod(a, b)
    if op == OP_FRACTION:
        return fract(a)
    if op == OP_ABSOLUTE:
        return abs(a)
    if op == OP_POWER:
        return safe_pow(a, b)
    if op == OP_SIGN:
        return sign(a)
    if op == OP_MINIMUM:
        return a if a < b else b
    if op == OP_MAXIMUM:
        return a if a > b else b
    if op == OP_SINE:
        return math.sin(a)
    if op == OP_COSINE:
        return math.cos(a)
    if op == OP_TANGENT:
        return math.tan(a)
    return 0.0


@device
def vector_math_node(regs, b, c):
    """Vector Math (svm_vector_math): Vector output, and Value for Dot/Distance/Length."""
    op = int(regs[b + _VM_OP])
    ax, ay, az = regs[b], regs[b + 1], regs[b + 2]
    bx, by, bz = regs[b + _VM_B], regs[b + _VM_B + 1], regs[b + _VM_B + 2]
    cx, cy, cz = regs[b + _VM_C], regs[b + _VM_C + 1], regs[b + _VM_C + 2]
    value = 0.0
    x = y = z = 0.0
    if op == OP_CROSS_PRODUCT:
        x, y, z = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    elif op == OP_PROJECT:
        ln2 = _dot(bx, by, bz, bx, by, bz)
        if ln2 != 0.0:
            f = _dot(ax, ay, az, bx, by, bz) / ln2
            x, y, z = f * bx, f * by, f * bz
    elif op == OP_REFLECT:
        nx, ny, nz = safe_normalize(bx, by, bz)
        d = 2.0 * _dot(ax, ay, az, nx, ny, nz)
        x, y, z = ax - d * nx, ay - d * ny, az - d * nz
    elif op == OP_REFRACT:
        eta = regs[b + _VM_SCALE]
        nx, ny, nz = safe_normalize(bx, by, bz)
        d = _dot(nx, ny, nz, ax, ay, az)
        k = 1.0 - eta * eta * (1.0 - d * d)
        if k >= 0.0:
            f = eta * d + math.sqrt(k)
            x, y, z = eta * ax - f * nx, eta * ay - f * ny, eta * az - f * nz
    elif op == OP_FACEFORWARD:
        s = 1.0 if _dot(cx, cy, cz, bx, by, bz) < 0.0 else -1.0
        x, y, z = s * ax, s * ay, s * az
    elif op == OP_MULTIPLY_ADD:
        x, y, z = ax * bx + cx, ay * by + cy, az * bz + cz
    elif op == OP_DOT_PRODUCT:
        value = _dot(ax, ay, az, bx, by, bz)
    elif op == OP_DISTANCE:
        dx, dy, dz = ax - bx, ay - by, az - bz
        value = math.sqrt(dx * dx + dy * dy + dz * dz)
    elif op == OP_LENGTH:
        value = math.sqrt(ax * ax + ay * ay + az * az)
    elif op == OP_SCALE:
        s = regs[b + _VM_SCALE]
        x, y, z = ax * s, ay * s, az * s
    elif op == OP_NORMALIZE:
        x, y, z = safe_normalize(ax, ay, az)
    elif op == OP_WRAP:                     # wrap a into [c, b) per component
        x = _floored_mod(ax - cx, bx - cx) + cx
        y = _floored_mod(ay - cy, by - cy) + cy
        z = _floored_mod(az - cz, bz - cz) + cz
    else:
        x = vector_op(op, ax, bx)
        y = vector_op(op, ay, by)
        z = vector_op(op, az, bz)
    regs[c], regs[c + 1], regs[c + 2] = x, y, z
    regs[c + _VM_VALUE_OUT] = value


# -- Map Range (svm/map_range.h; the float clamp is MapRangeNode::expand's Range clamp) ----------
@device
def _smoothstep(lo, hi, x):
    if x < lo:
        return 0.0
    if x >= hi:
        return 1.0
    t = (x - lo) / (hi - lo)
    return (3.0 - 2.0 * t) * (t * t)


@device
def _smootherstep(lo, hi, x):
    t = min(max(safe_divide(x - lo, hi - lo), 0.0), 1.0)
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0)


@device
def map_range_float(regs, b):
    value = regs[b]
    fmin, fmax = regs[b + _MR_FROM_MIN], regs[b + _MR_FROM_MAX]
    tmin, tmax = regs[b + _MR_TO_MIN], regs[b + _MR_TO_MAX]
    interp = int(regs[b + _MR_INTERP])
    result = 0.0
    if fmax != fmin:
        if interp == _SMOOTHSTEP:
            f = 1.0 - _smoothstep(fmax, fmin, value) if fmin > fmax else _smoothstep(fmin, fmax, value)
        elif interp == _SMOOTHERSTEP:
            f = (1.0 - _smootherstep(fmax, fmin, value) if fmin > fmax
                 else _smootherstep(fmin, fmax, value))
        else:
            f = (value - fmin) / (fmax - fmin)
            if interp == _STEPPED:
                steps = regs[b + _MR_STEPS]
                f = math.floor(f * (steps + 1.0)) / steps if steps > 0.0 else 0.0
        result = tmin + f * (tmax - tmin)
    if regs[b + _MR_CLAMP] != 0.0:
        lo, hi = (tmax, tmin) if tmin > tmax else (tmin, tmax)
        result = min(max(result, lo), hi)
    return result


@device
def map_range_vector(regs, b, out):
    interp = int(regs[b + _MR_INTERP])
    use_clamp = regs[b + _MR_CLAMP] != 0.0 and interp != _SMOOTHSTEP and interp != _SMOOTHERSTEP
    for k in range(3):
        value = regs[b + _MR_VECTOR + k]
        fmin, fmax = regs[b + _MR_FROM_MIN3 + k], regs[b + _MR_FROM_MAX3 + k]
        tmin, tmax = regs[b + _MR_TO_MIN3 + k], regs[b + _MR_TO_MAX3 + k]
        f = safe_divide(value - fmin, fmax - fmin)
        if interp == _STEPPED:
            steps = regs[b + _MR_STEPS3 + k]
            f = math.floor(f * (steps + 1.0)) / steps if steps > 0.0 else 0.0
        elif interp == _SMOOTHSTEP:
            f = min(max(f, 0.0), 1.0)
            f = (3.0 - 2.0 * f) * (f * f)
        elif interp == _SMOOTHERSTEP:
            f = min(max(f, 0.0), 1.0)
            f = f * f * f * (f * (f * 6.0 - 15.0) + 10.0)
        result = tmin + f * (tmax - tmin)
        if use_clamp:
            lo, hi = (tmax, tmin) if tmin > tmax else (tmin, tmax)
            result = min(max(result, lo), hi)
        regs[out + k] = result


@device
def rotate_around_axis(px, py, pz, ax, ay, az, angle):
    """p rotated by ``angle`` about the unit axis a (right-handed)."""
    c, s = math.cos(angle), math.sin(angle)
    d = (px * ax + py * ay + pz * az) * (1.0 - c)
    return (px * c + (ay * pz - az * py) * s + ax * d,
            py * c + (az * px - ax * pz) * s + ay * d,
            pz * c + (ax * py - ay * px) * s + az * d)
