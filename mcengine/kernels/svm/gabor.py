"""Gabor Texture (kernel/svm/gabor.h): sparse Gabor convolution noise, 2D and 3D.

Each unit cell of the scaled coordinates holds eight impulses (``IMPULSES_COUNT``), each
a Gabor kernel (a Gaussian times a Hann window, zero beyond unit distance, modulating a
sinusoid of the given frequency) at a random centre, with a random sign and an orientation
turned away from the base one by a random angle times the isotropy (1 - Anisotropy).  The
point sums the kernels of its own cell and its neighbours as a phasor; Value is its
imaginary part, Phase its angle, Intensity its length, each normalised by six standard
deviations of the noise.  Every random number is Cycles' lookup3 hash of the cell's
coordinates and the impulse's number (``hash``), so the pattern is Cycles' own.
"""
from __future__ import annotations

import math

from ...jit import device, function
from .hash import hash_float3, hash_float4
from .nodes import OFFSETS, OUTPUT_OFFSETS

IMPULSES_COUNT = 8
GABOR_2D = 2            # "gabor_type" (nodes.DIMENSIONS)
GABOR_3D = 3

_GB = OFFSETS["TexGabor"]
_GB_SCALE, _GB_FREQUENCY, _GB_ANISOTROPY = _GB["Scale"], _GB["Frequency"], _GB["Anisotropy"]
_GB_ORIENTATION_2D, _GB_ORIENTATION_3D = _GB["Orientation 2D"], _GB["Orientation 3D"]
_GB_TYPE = _GB["prop:gabor_type"]
_GBO = OUTPUT_OFFSETS["TexGabor"]
_GB_VALUE, _GB_PHASE, _GB_INTENSITY = _GBO["Value"], _GBO["Phase"], _GBO["Intensity"]

# sqrt(impulses x second moment 1/2 x the integral of the squared kernel: 1/4 in 2D,
# 1/(4 sqrt 2) in 3D)
_STD_2D = math.sqrt(IMPULSES_COUNT * 0.5 * 0.25)
_STD_3D = math.sqrt(IMPULSES_COUNT * 0.5 / (4.0 * math.sqrt(2.0)))


@device
def _kernel(distance_squared, phase):
    """The windowed Gaussian envelope at squared distance d^2 as a phasor of angle ``phase``."""
    hann = 0.5 + 0.5 * math.cos(math.pi * distance_squared)
    envelope = math.exp(-math.pi * distance_squared) * hann
    return envelope * math.cos(phase), envelope * math.sin(phase)


@device
def _cell_2d(cx, cy, px, py, frequency, isotropy, base_orientation):
    re = im = 0.0
    for i in range(IMPULSES_COUNT):
        k = float(i * 3)
        orientation = base_orientation + (hash_float3(cx, cy, k) - 0.5) * math.pi * isotropy
        # hash_float3_to_float2 of the kernel centre's seed
        qx = px - hash_float3(cx, cy, k + 1.0)
        qy = py - hash_float3(k + 1.0, cx, cy)
        d2 = qx * qx + qy * qy
        if d2 >= 1.0:
            continue
        weight = -1.0 if hash_float3(cx, cy, k + 2.0) < 0.5 else 1.0
        fx, fy = frequency * math.cos(orientation), frequency * math.sin(orientation)
        a, b = _kernel(d2, 2.0 * math.pi * (qx * fx + qy * fy))
        re += weight * a
        im += weight * b
    return re, im


@device
def gabor_2d(x, y, frequency, isotropy, orientation):
    fx, fy = math.floor(x), math.floor(y)
    lx, ly = x - fx, y - fy
    re = im = 0.0
    for j in range(-1, 2):
        for i in range(-1, 2):
            a, b = _cell_2d(fx + i, fy + j, lx - i, ly - j, frequency, isotropy, orientation)
            re += a
            im += b
    return re, im


@device
def _orientation_3d(ox, oy, oz, isotropy, sx, sy, sz, sw):
    """The base orientation turned by random inclination and azimuth angles (in [0, pi]) times
    the isotropy (compute_3d_orientation)."""
    if isotropy == 0.0:
        return ox, oy, oz
    inclination = math.acos(oz)
    azimuth = (-1.0 if oy < 0.0 else 1.0) * math.acos(ox / math.sqrt(ox * ox + oy * oy))
    # hash_float4_to_float2
    inclination += hash_float4(sx, sy, sz, sw) * math.pi * isotropy
    azimuth += hash_float4(sz, sx, sw, sy) * math.pi * isotropy
    s = math.sin(inclination)
    return s * math.cos(azimuth), s * math.sin(azimuth), math.cos(inclination)


@device
def _cell_3d(cx, cy, cz, px, py, pz, frequency, isotropy, ox, oy, oz):
    re = im = 0.0
    for i in range(IMPULSES_COUNT):
        k = float(i * 3)
        dx, dy, dz = _orientation_3d(ox, oy, oz, isotropy, cx, cy, cz, k)
        # hash_float4_to_float3 of the kernel centre's seed (cx, cy, cz, k + 1)
        w = k + 1.0
        qx = px - hash_float4(cx, cy, cz, w)
        qy = py - hash_float4(cz, cx, w, cy)
        qz = pz - hash_float4(w, cz, cy, cx)
        d2 = qx * qx + qy * qy + qz * qz
        if d2 >= 1.0:
            continue
        weight = -1.0 if hash_float4(cx, cy, cz, k + 2.0) < 0.5 else 1.0
        a, b = _kernel(d2, 2.0 * math.pi * frequency * (qx * dx + qy * dy + qz * dz))
        re += weight * a
        im += weight * b
    return re, im


@device
def gabor_3d(x, y, z, frequency, isotropy, ox, oy, oz):
    fx, fy, fz = math.floor(x), math.floor(y), math.floor(z)
    lx, ly, lz = x - fx, y - fy, z - fz
    re = im = 0.0
    for k in range(-1, 2):
        for j in range(-1, 2):
            for i in range(-1, 2):
                a, b = _cell_3d(fx + i, fy + j, fz + k, lx - i, ly - j, lz - k, frequency,
                                isotropy, ox, oy, oz)
                re += a
                im += b
    return re, im


@function
def gabor_node(regs, b, c):
    """Inputs at regs[b:] (nodes.VALUE_NODES), Value, Phase and Intensity to regs[c:]."""
    scale = regs[b + _GB_SCALE]
    x, y, z = regs[b] * scale, regs[b + 1] * scale, regs[b + 2] * scale
    isotropy = 1.0 - min(max(regs[b + _GB_ANISOTROPY], 0.0), 1.0)
    frequency = max(0.001, regs[b + _GB_FREQUENCY])
    if int(regs[b + _GB_TYPE]) == GABOR_3D:
        ox, oy, oz = (regs[b + _GB_ORIENTATION_3D], regs[b + _GB_ORIENTATION_3D + 1],
                      regs[b + _GB_ORIENTATION_3D + 2])
        n = math.sqrt(ox * ox + oy * oy + oz * oz)      # normalize(): 0 / 0 is NaN, as in Cycles
        re, im = gabor_3d(x, y, z, frequency, isotropy, ox / n, oy / n, oz / n)
        norm = 6.0 * _STD_3D
    else:
        re, im = gabor_2d(x, y, frequency, isotropy, regs[b + _GB_ORIENTATION_2D])
        norm = 6.0 * _STD_2D
    regs[c + _GB_VALUE] = im / norm * 0.5 + 0.5
    regs[c + _GB_PHASE] = (math.atan2(im, re) + math.pi) / (2.0 * math.pi)
    regs[c + _GB_INTENSITY] = math.sqrt(re * re + im * im) / norm
