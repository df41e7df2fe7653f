"""Cycles' hash functions (util/hash.h), bit for bit, for the procedural textures.

Two families:

* Bob Jenkins' lookup3 on 1-4 unsigned 32-bit keys (``hash_uint*``), used on
  lattice integers (Perlin noise) and on the IEEE-754 single-precision bit
  patterns of float keys (White Noise, 1D Voronoi, the noise seeds); its
  unit-interval form divides by 2^32 exactly as Cycles' float32 does
  (``uint_to_float_incl``: (float)h * (1 / (float)0xFFFFFFFF), and
  (float)0xFFFFFFFF rounds to 2^32).
* PCG 2D/3D/4D on signed 32-bit ints (``pcg*``), used on Voronoi cells, in
  [0, 1] through h / 2^31 after rounding h to float32.

numba has no 32-bit wrapping integers: everything runs on int64 and is
wrapped after each step (``& M32`` for unsigned, ``_i32`` for signed).
"""
from __future__ import annotations

import math

import numpy as np

from ...jit import device

M32 = 0xFFFFFFFF
_SEED = 0xDEADBEEF
_TWO_M32 = 2.0 ** -32
_TWO_M31 = 2.0 ** -31
_TWO_149 = 2.0 ** 149


@device
def r32(x):
    """``x`` rounded to float32 (where Cycles' float arithmetic rounds and it shows)."""
    return float(np.float32(x))


@device
def float_bits(x):
    """The IEEE-754 single-precision bit pattern of ``x`` rounded to float32 (as uint)."""
    f = r32(x)
    if f != f:
        return 0x7FC00000
    sign = 0x80000000 if math.copysign(1.0, f) < 0.0 else 0
    a = abs(f)
    if a == 0.0:
        return sign
    if a == math.inf:
        return sign | 0x7F800000
    m, e = math.frexp(a)             # a = m 2^e, 0.5 <= m < 1
    if e >= -125:
        return sign | ((e + 126) << 23) | (int(m * 16777216.0) - 8388608)
    return sign | int(a * _TWO_149)  # subnormal


@device
def _rot(x, k):
    return ((x << k) | (x >> (32 - k))) & M32


@device
def _final(a, b, c):
    c ^= b
    c = (c - _rot(b, 14)) & M32
    a ^= c
    a = (a - _rot(c, 11)) & M32
    b ^= a
    b = (b - _rot(a, 25)) & M32
    c ^= b
    c = (c - _rot(b, 16)) & M32
    a ^= c
    a = (a - _rot(c, 4)) & M32
    b ^= a
    b = (b - _rot(a, 14)) & M32
    c ^= b
    c = (c - _rot(b, 24)) & M32
    return c


@device
def hash_uint(kx):
    a = (_SEED + (1 << 2) + 13 + (kx & M32)) & M32
    b = c = (_SEED + (1 << 2) + 13) & M32
    return _final(a, b, c)


@device
def hash_uint2(kx, ky):
    init = (_SEED + (2 << 2) + 13) & M32
    return _final((init + (kx & M32)) & M32, (init + (ky & M32)) & M32, init)


@device
def hash_uint3(kx, ky, kz):
    init = (_SEED + (3 << 2) + 13) & M32
    return _final((init + (kx & M32)) & M32, (init + (ky & M32)) & M32,
                  (init + (kz & M32)) & M32)


@device
def hash_uint4(kx, ky, kz, kw):
    init = (_SEED + (4 << 2) + 13) & M32
    a = (init + (kx & M32)) & M32
    b = (init + (ky & M32)) & M32
    c = (init + (kz & M32)) & M32
    # lookup3's mix(a, b, c)
    a = (a - c) & M32
    a ^= _rot(c, 4)
    c = (c + b) & M32
    b = (b - a) & M32
    b ^= _rot(a, 6)
    a = (a + c) & M32
    c = (c - b) & M32
    c ^= _rot(b, 8)
    b = (b + a) & M32
    a = (a - c) & M32
    a ^= _rot(c, 16)
    c = (c + b) & M32
    b = (b - a) & M32
    b ^= _rot(a, 19)
    a = (a + c) & M32
    c = (c - b) & M32
    c ^= _rot(b, 4)
    b = (b + a) & M32
    a = (a + (kw & M32)) & M32
    return _final(a, b, c)


@device
def unit(h):
    """A 32-bit hash in [0, 1] as Cycles' float32 computes it."""
    return r32(float(h)) * _TWO_M32


@device
def hash_float(x):
    return unit(hash_uint(float_bits(x)))


@device
def hash_float2(x, y):
    return unit(hash_uint2(float_bits(x), float_bits(y)))


@device
def hash_bits3(a, b, c):
    """hash_float3_to_float of keys given as their float32 bit patterns (``float_bits``)."""
    return unit(hash_uint3(a, b, c))


@device
def hash_bits4(a, b, c, d):
    """hash_float4_to_float of keys given as their float32 bit patterns (``float_bits``)."""
    return unit(hash_uint4(a, b, c, d))


@device
def hash_float3(x, y, z):
    return hash_bits3(float_bits(x), float_bits(y), float_bits(z))


@device
def hash_float4(x, y, z, w):
    return hash_bits4(float_bits(x), float_bits(y), float_bits(z), float_bits(w))


# -- PCG (signed 32-bit arithmetic) -----------------------------------------------------------------
@device
def _i32(v):
    v &= M32
    return v - 0x100000000 if v >= 0x80000000 else v


@device
def _pcg_unit(h):
    return r32(float(h & 0x7FFFFFFF)) * _TWO_M31


@device
def pcg2(x, y):
    """hash_int2_to_float2: two values in [0, 1]."""
    x = _i32(x * 1664525 + 1013904223)
    y = _i32(y * 1664525 + 1013904223)
    x = _i32(x + y * 1664525)
    y = _i32(y + x * 1664525)
    x ^= x >> 16
    y ^= y >> 16
    x = _i32(x + y * 1664525)
    y = _i32(y + x * 1664525)
    return _pcg_unit(x), _pcg_unit(y)


@device
def pcg3(x, y, z):
    """hash_int3_to_float3: three values in [0, 1]."""
    x = _i32(x * 1664525 + 1013904223)
    y = _i32(y * 1664525 + 1013904223)
    z = _i32(z * 1664525 + 1013904223)
    x = _i32(x + y * z)
    y = _i32(y + z * x)
    z = _i32(z + x * y)
    x ^= x >> 16
    y ^= y >> 16
    z ^= z >> 16
    x = _i32(x + y * z)
    y = _i32(y + z * x)
    z = _i32(z + x * y)
    return _pcg_unit(x), _pcg_unit(y), _pcg_unit(z)


@device
def pcg4(x, y, z, w):
    """hash_int4_to_float4: four values in [0, 1]."""
    x = _i32(x * 1664525 + 1013904223)
    y = _i32(y * 1664525 + 1013904223)
    z = _i32(z * 1664525 + 1013904223)
    w = _i32(w * 1664525 + 1013904223)
    x = _i32(x + y * w)
    y = _i32(y + z * x)
    z = _i32(z + x * y)
    w = _i32(w + y * z)
    x ^= x >> 16
    y ^= y >> 16
    z ^= z >> 16
    w ^= w >> 16
    x = _i32(x + y * w)
    y = _i32(y + z * x)
    z = _i32(z + x * y)
    w = _i32(w + y * z)
    return _pcg_unit(x), _pcg_unit(y), _pcg_unit(z), _pcg_unit(w)
