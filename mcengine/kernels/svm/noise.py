"""Cycles' Perlin noise and its fractals (kernel/svm/noise.h, fractal_noise.h, noisetex.h).

One code path serves the four dimensions: a point is (x, y, z, w) and
``dim`` says which of them count (1D: x only, which the Noise node fills
with W; 2D: x, y; 3D: x, y, z; 4D: all).  Unused components stay 0, so a
fractal's scaling of the point leaves them 0.

Arithmetic is float64; where Cycles' float32 rounding is large enough to
see (a point plus a seed offset of 100-200, whose float32 spacing is 1.5e-5)
the sum is rounded to float32 as Cycles does (``r32``).  The lattice hashes
are Cycles' own (``hash.py``), so patterns agree to float rounding.

The four Perlin functions are called, not inlined: each fractal calls the
noise at two sites for four dimensions, and inlining the 4D lattice (16
hashes) at every one of them made compilation slow.
"""
from __future__ import annotations

import math

from ...jit import device, function
from .hash import hash_float, hash_float2, hash_uint, hash_uint2, hash_uint3, hash_uint4, r32
from .math_nodes import fmod
from .nodes import (
    NOISE_FBM,
    NOISE_HETERO_TERRAIN,
    NOISE_HYBRID_MULTIFRACTAL,
    NOISE_MULTIFRACTAL,
    NOISE_RIDGED_MULTIFRACTAL,
)


@device
def _fade(t):
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0)


@device
def _neg(v, bit):
    return -v if bit else v


@device
def _grad1(h, x):
    h &= 15
    g = 1.0 + (h & 7)
    return _neg(g, h & 8) * x


@device
def _grad2(h, x, y):
    h &= 7
    u = x if h < 4 else y
    v = 2.0 * (y if h < 4 else x)
    return _neg(u, h & 1) + _neg(v, h & 2)


@device
def _grad3(h, x, y, z):
    h &= 15
    u = x if h < 8 else y
    vt = x if (h == 12 or h == 14) else z
    v = y if h < 4 else vt
    return _neg(u, h & 1) + _neg(v, h & 2)


@device
def _grad4(h, x, y, z, w):
    h &= 31
    u = x if h < 24 else y
    v = y if h < 16 else z
    s = z if h < 8 else w
    return _neg(u, h & 1) + _neg(v, h & 2) + _neg(s, h & 4)


@device
def _lerp(a, b, t):
    return (1.0 - t) * a + t * b


@function
def perlin_1d(x):
    fx = math.floor(x)
    X = int(fx)
    fx = x - fx
    return _lerp(_grad1(hash_uint(X), fx), _grad1(hash_uint(X + 1), fx - 1.0), _fade(fx))


@function
def perlin_2d(x, y):
    fx, fy = math.floor(x), math.floor(y)
    X, Y = int(fx), int(fy)
    fx, fy = x - fx, y - fy
    u, v = _fade(fx), _fade(fy)
    return _lerp(_lerp(_grad2(hash_uint2(X, Y), fx, fy),
                       _grad2(hash_uint2(X + 1, Y), fx - 1.0, fy), u),
                 _lerp(_grad2(hash_uint2(X, Y + 1), fx, fy - 1.0),
                       _grad2(hash_uint2(X + 1, Y + 1), fx - 1.0, fy - 1.0), u), v)


@device
def _perlin_3d_layer(X, Y, Z, fx, fy, fz, u, v):
    """The bilinear mix of the four corners of cell layer Z (offset fz)."""
    return _lerp(_lerp(_grad3(hash_uint3(X, Y, Z), fx, fy, fz),
                       _grad3(hash_uint3(X + 1, Y, Z), fx - 1.0, fy, fz), u),
                 _lerp(_grad3(hash_uint3(X, Y + 1, Z), fx, fy - 1.0, fz),
                       _grad3(hash_uint3(X + 1, Y + 1, Z), fx - 1.0, fy - 1.0, fz), u), v)


@function
def perlin_3d(x, y, z):
    fx, fy, fz = math.floor(x), math.floor(y), math.floor(z)
    X, Y, Z = int(fx), int(fy), int(fz)
    fx, fy, fz = x - fx, y - fy, z - fz
    u, v = _fade(fx), _fade(fy)
    lo = _perlin_3d_layer(X, Y, Z, fx, fy, fz, u, v)
    hi = _perlin_3d_layer(X, Y, Z + 1, fx, fy, fz - 1.0, u, v)
    return _lerp(lo, hi, _fade(fz))


@device
def _perlin_4d_layer(X, Y, Z, W, fx, fy, fz, fw, u, v, t):
    """The trilinear mix of the eight corners of cell layer W (offset fw)."""
    acc = 0.0
    for k in range(2):
        for j in range(2):
            for i in range(2):
                g = _grad4(hash_uint4(X + i, Y + j, Z + k, W), fx - i, fy - j, fz - k, fw)
                acc += g * (u if i else 1.0 - u) * (v if j else 1.0 - v) * (t if k else 1.0 - t)
    return acc


@function
def perlin_4d(x, y, z, w):
    fx, fy, fz, fw = math.floor(x), math.floor(y), math.floor(z), math.floor(w)
    X, Y, Z, W = int(fx), int(fy), int(fz), int(fw)
    fx, fy, fz, fw = x - fx, y - fy, z - fz, w - fw
    u, v, t = _fade(fx), _fade(fy), _fade(fz)
    lo = _perlin_4d_layer(X, Y, Z, W, fx, fy, fz, fw, u, v, t)
    hi = _perlin_4d_layer(X, Y, Z, W + 1, fx, fy, fz, fw - 1.0, u, v, t)
    return _lerp(lo, hi, _fade(fw))


@device
def _wrap(p):
    """Cycles repeats the noise every 100000 (and shifts huge coordinates by half a cell).

    The coordinate is Cycles' float32 one: beyond 1e6 its spacing (0.06-0.25) is
    what the pattern shows."""
    p = r32(p)
    return fmod(p, 100000.0) + (0.5 if abs(p) >= 1000000.0 else 0.0)


@device
def snoise(dim, x, y, z, w):
    """Signed Perlin noise of the point's first ``dim`` components, about [-1, 1]."""
    if dim == 1:
        return 0.25 * perlin_1d(_wrap(x))
    if dim == 2:
        return 0.6616 * perlin_2d(_wrap(x), _wrap(y))
    if dim == 3:
        return 0.9820 * perlin_3d(_wrap(x), _wrap(y), _wrap(z))
    return 0.8344 * perlin_4d(_wrap(x), _wrap(y), _wrap(z), _wrap(w))


@function
def noise_fbm(dim, x, y, z, w, detail, roughness, lacunarity, normalize):
    fscale = 1.0
    amp = 1.0
    maxamp = 0.0
    total = 0.0
    for _ in range(int(detail) + 1):
        total += amp * snoise(dim, fscale * x, fscale * y, fscale * z, fscale * w)
        maxamp += amp
        amp *= roughness
        fscale *= lacunarity
    rmd = detail - math.floor(detail)
    if rmd != 0.0:
        total2 = total + amp * snoise(dim, fscale * x, fscale * y, fscale * z, fscale * w)
        if normalize != 0.0:
            return _lerp(0.5 * total / maxamp + 0.5, 0.5 * total2 / (maxamp + amp) + 0.5, rmd)
        return _lerp(total, total2, rmd)
    return 0.5 * total / maxamp + 0.5 if normalize != 0.0 else total


@function
def noise_multifractal(dim, x, y, z, w, detail, roughness, lacunarity):
    value = 1.0
    pwr = 1.0
    for _ in range(int(detail) + 1):
        value *= pwr * snoise(dim, x, y, z, w) + 1.0
        pwr *= roughness
        x, y, z, w = x * lacunarity, y * lacunarity, z * lacunarity, w * lacunarity
    rmd = detail - math.floor(detail)
    if rmd != 0.0:
        value *= rmd * pwr * snoise(dim, x, y, z, w) + 1.0
    return value


@function
def noise_hetero_terrain(dim, x, y, z, w, detail, roughness, lacunarity, offset):
    pwr = roughness
    value = offset + snoise(dim, x, y, z, w)
    x, y, z, w = x * lacunarity, y * lacunarity, z * lacunarity, w * lacunarity
    for _ in range(1, int(detail) + 1):
        value += (snoise(dim, x, y, z, w) + offset) * pwr * value
        pwr *= roughness
        x, y, z, w = x * lacunarity, y * lacunarity, z * lacunarity, w * lacunarity
    rmd = detail - math.floor(detail)
    if rmd != 0.0:
        value += rmd * ((snoise(dim, x, y, z, w) + offset) * pwr * value)
    return value


@function
def noise_hybrid_multifractal(dim, x, y, z, w, detail, roughness, lacunarity, offset, gain):
    pwr = 1.0
    value = 0.0
    weight = 1.0
    octaves = int(detail) + 1
    i = 0
    while weight > 0.001 and i < octaves:
        weight = min(weight, 1.0)
        signal = (snoise(dim, x, y, z, w) + offset) * pwr
        pwr *= roughness
        value += weight * signal
        weight *= gain * signal
        x, y, z, w = x * lacunarity, y * lacunarity, z * lacunarity, w * lacunarity
        i += 1
    rmd = detail - math.floor(detail)
    if rmd != 0.0 and weight > 0.001:
        weight = min(weight, 1.0)
        value += rmd * weight * ((snoise(dim, x, y, z, w) + offset) * pwr)
    return value


@function
def noise_ridged_multifractal(dim, x, y, z, w, detail, roughness, lacunarity, offset, gain):
    pwr = roughness
    signal = offset - abs(snoise(dim, x, y, z, w))
    signal *= signal
    value = signal
    for _ in range(1, int(detail) + 1):
        x, y, z, w = x * lacunarity, y * lacunarity, z * lacunarity, w * lacunarity
        weight = min(max(signal * gain, 0.0), 1.0)
        signal = offset - abs(snoise(dim, x, y, z, w))
        signal *= signal
        signal *= weight
        value += signal * pwr
        pwr *= roughness
    return value


@device
def noise_select(kind, dim, x, y, z, w, detail, roughness, lacunarity, offset, gain, normalize):
    if kind == NOISE_FBM:
        return noise_fbm(dim, x, y, z, w, detail, roughness, lacunarity, normalize)
    if kind == NOISE_MULTIFRACTAL:
        return noise_multifractal(dim, x, y, z, w, detail, roughness, lacunarity)
    if kind == NOISE_HYBRID_MULTIFRACTAL:
        return noise_hybrid_multifractal(dim, x, y, z, w, detail, roughness, lacunarity, offset,
                                         gain)
    if kind == NOISE_RIDGED_MULTIFRACTAL:
        return noise_ridged_multifractal(dim, x, y, z, w, detail, roughness, lacunarity, offset,
                                         gain)
    if kind == NOISE_HETERO_TERRAIN:
        return noise_hetero_terrain(dim, x, y, z, w, detail, roughness, lacunarity, offset)
    return 0.0


@device
def seed_offset(dim, seed, i):
    """Component ``i`` of Cycles' random_float<dim>_offset(seed): in [100, 200], float32."""
    h = hash_float(seed) if dim == 1 else hash_float2(seed, float(i))
    return r32(r32(h * 100.0) + 100.0)


@device
def _offset_point(dim, seed, x, y, z, w):
    """The point moved by the seed's offset, rounded to float32 as Cycles adds it."""
    x = r32(x + seed_offset(dim, seed, 0))
    if dim >= 2:
        y = r32(y + seed_offset(dim, seed, 1))
    if dim >= 3:
        z = r32(z + seed_offset(dim, seed, 2))
    if dim >= 4:
        w = r32(w + seed_offset(dim, seed, 3))
    return x, y, z, w


@function
def noise_texture(dim, x, y, z, w, detail, roughness, lacunarity, offset, gain, distortion, kind,
                  normalize):
    """Cycles' noise_texture_<dim>d: (Fac, the Color's green, the Color's blue); the
    Color's red is Fac."""
    if distortion != 0.0:
        dx = dy = dz = dw = 0.0
        for i in range(dim):
            ox, oy, oz, ow = _offset_point(dim, float(i), x, y, z, w)
            d = snoise(dim, ox, oy, oz, ow) * distortion
            if i == 0:
                dx = d
            elif i == 1:
                dy = d
            elif i == 2:
                dz = d
            else:
                dw = d
        x, y, z, w = r32(x + dx), r32(y + dy), r32(z + dz), r32(w + dw)
    value = noise_select(kind, dim, x, y, z, w, detail, roughness, lacunarity, offset, gain,
                         normalize)
    ox, oy, oz, ow = _offset_point(dim, float(dim), x, y, z, w)
    green = noise_select(kind, dim, ox, oy, oz, ow, detail, roughness, lacunarity, offset, gain,
                         normalize)
    ox, oy, oz, ow = _offset_point(dim, float(dim + 1), x, y, z, w)
    blue = noise_select(kind, dim, ox, oy, oz, ow, detail, roughness, lacunarity, offset, gain,
                        normalize)
    return value, green, blue

