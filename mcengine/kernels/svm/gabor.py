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
from ..scalar import saturate
from .hash import float_bits, hash_bits3, hash_bits4
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

# The float32 bit patterns of each impulse's seeds 3i, 3i + 1, 3i + 2 (the last key of its
# orientation, centre and sign hashes).
_SEED_BITS = tuple(tuple(float_bits(float(3 * i + j)) for j in range(3)) for i in range(IMPULSES_COUNT))

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
    # The cell's keys as bit patterns once, not once per hash (float_bits is not free); the
    # kernel centre first, so that the impulses out of reach (most) skip the rest: the
    # same values as Cycles, which draws the orientation first.
    bx, by = float_bits(cx), float_bits(cy)
    re = im = 0.0
    for i in range(IMPULSES_COUNT):
        k, k1, k2 = _SEED_BITS[i]
        # hash_float3_to_float2 of the kernel centre's seed (cx, cy, 3i + 1)
        qx = px - hash_bits3(bx, by, k1)
        qy = py - hash_bits3(k1, bx, by)
        d2 = qx * qx + qy * qy
        if d2 >= 1.0:
            continue
        orientation = base_orientation + (hash_bits3(bx, by, k) - 0.5) * math.pi * isotropy
        weight = -1.0 if hash_bits3(bx, by, k2) < 0.5 else 1.0
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
def _base_angles(ox, oy, oz):
    """Inclination and azimuth of the unit base orientation (compute_3d_orientation)."""
    inclination = math.acos(oz)
    azimuth = (-1.0 if oy < 0.0 else 1.0) * math.acos(ox / math.sqrt(ox * ox + oy * oy))
    return inclination, azimuth


@device
def _cell_3d(cx, cy, cz, px, py, pz, frequency, isotropy, ox, oy, oz, inclination, azimuth):
    bx, by, bz = float_bits(cx), float_bits(cy), float_bits(cz)
    re = im = 0.0
    for i in range(IMPULSES_COUNT):
        k, w, k2 = _SEED_BITS[i]
        # hash_float4_to_float3 of the kernel centre's seed (cx, cy, cz, 3i + 1)
        qx = px - hash_bits4(bx, by, bz, w)
        qy = py - hash_bits4(bz, bx, w, by)
        qz = pz - hash_bits4(w, bz, by, bx)
        d2 = qx * qx + qy * qy + qz * qz
        if d2 >= 1.0:
            continue
        dx, dy, dz = ox, oy, oz
        if isotropy != 0.0:
            # the base turned by random angles in [0, pi] times the isotropy
            # (hash_float4_to_float2 of the seed (cx, cy, cz, 3i))
            t = inclination + hash_bits4(bx, by, bz, k) * math.pi * isotropy
            f = azimuth + hash_bits4(bz, bx, k, by) * math.pi * isotropy
            s = math.sin(t)
            dx, dy, dz = s * math.cos(f), s * math.sin(f), math.cos(t)
        weight = -1.0 if hash_bits4(bx, by, bz, k2) < 0.5 else 1.0
        a, b = _kernel(d2, 2.0 * math.pi * frequency * (qx * dx + qy * dy + qz * dz))
        re += weight * a
        im += weight * b
    return re, im


@device
def gabor_3d(x, y, z, frequency, isotropy, ox, oy, oz):
    fx, fy, fz = math.floor(x), math.floor(y), math.floor(z)
    lx, ly, lz = x - fx, y - fy, z - fz
    inclination, azimuth = _base_angles(ox, oy, oz)
    re = im = 0.0
    for k in range(-1, 2):
        for j in range(-1, 2):
            for i in range(-1, 2):
                a, b = _cell_3d(fx + i, fy + j, fz + k, lx - i, ly - j, lz - k, frequency,
                                isotropy, ox, oy, oz, inclination, azimuth)
                re += a
                im += b
    return re, im


@function
def gabor_node(regs, b, c):
    """Inputs at regs[b:] (nodes.VALUE_NODES), Value, Phase and Intensity to regs[c:]."""
    scale = regs[b + _GB_SCALE]
    x, y, z = regs[b] * scale, regs[b + 1] * scale, regs[b + 2] * scale
    isotropy = 1.0 - saturate(regs[b + _GB_ANISOTROPY])
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
