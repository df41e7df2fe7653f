"""Samplers and warps: random numbers and the maps from [0,1)^2 to shapes.

Random numbers are counter-based: ``rand(key, dim)`` hashes a 64-bit path key
(made from the seed, the pixel and the sample index) with a dimension number.
The same (seed, pixel, sample, dimension) always gives the same number, in any
thread and any batch, which makes renders reproducible and lets tests compare
the wavefront kernels with scalar code.

Every warp returns points with a known density; ``*_pdf`` gives it (per unit
area for disks and triangles, per steradian for directions).  The disk warps
include the lecture's example: ``disk_polar(u1, u2)`` uses r = sqrt(u1), which
is uniform; r = u1 would crowd samples near the centre (tests check both).
"""
from __future__ import annotations

import math

import numpy as np

from ..jit import device

# -- dimensions ----------------------------------------------------------------
# Camera dimensions come first, then a block of DIMS_PER_BOUNCE numbers for
# every path vertex, so adding a use of randomness never shifts another one.
DIM_FILTER_X = 0
DIM_FILTER_Y = 1
DIM_LENS_U = 2
DIM_LENS_V = 3
DIM_TIME = 4
DIM_BOUNCE_BASE = 8
DIMS_PER_BOUNCE = 16
DIM_LIGHT_PICK = 0       # which light to sample
DIM_LIGHT_U = 1          # point on the light
DIM_LIGHT_V = 2
DIM_BSDF_LOBE = 3        # which BSDF lobe
DIM_BSDF_U = 4           # direction from the lobe
DIM_BSDF_V = 5
DIM_ROULETTE = 6         # Russian roulette
DIM_LIGHT_GROUP = 7      # which emissive triangle, once the group is picked
DIM_BSDF_W = 8           # third number of a BSDF sample (reflection or refraction)

_K_PIXEL = np.uint64(0x9E3779B97F4A7C15)    # golden-ratio increment (Weyl sequence)
_K_SAMPLE = np.uint64(0xD1B54A32D192ED03)
_K_DIM = np.uint64(0xAEF17502108EF2D9)
_M1 = np.uint64(0xBF58476D1CE4E5B9)         # splitmix64 finaliser constants
_M2 = np.uint64(0x94D049BB133111EB)
_INV_2_53 = 1.0 / 9007199254740992.0


@device
def mix64(x):
    """splitmix64 finaliser: a bijective 64-bit hash with full avalanche."""
    x = (x ^ (x >> np.uint64(30))) * _M1
    x = (x ^ (x >> np.uint64(27))) * _M2
    return x ^ (x >> np.uint64(31))


@device
def path_key(seed, pixel, sample):
    """64-bit key of one path sample: (seed, pixel index, sample index)."""
    k = mix64(np.uint64(seed) * _K_SAMPLE + np.uint64(0x632BE59BD9B4E019))
    k = mix64(k ^ (np.uint64(pixel) * _K_PIXEL))
    return mix64(k ^ (np.uint64(sample) * _K_SAMPLE))


@device
def rand(key, dim):
    """Uniform float64 in [0, 1) for dimension ``dim`` of the path ``key``."""
    h = mix64(key ^ (np.uint64(dim + 1) * _K_DIM))
    return float(h >> np.uint64(11)) * _INV_2_53


@device
def bounce_dim(bounce, which):
    return DIM_BOUNCE_BASE + bounce * DIMS_PER_BOUNCE + which


# -- warps -----------------------------------------------------------------------
@device
def disk_concentric(u1, u2):
    """Shirley-Chiu concentric map of [0,1)^2 to the unit disk (uniform, low distortion)."""
    a = 2.0 * u1 - 1.0
    b = 2.0 * u2 - 1.0
    if a == 0.0 and b == 0.0:
        return 0.0, 0.0
    if abs(a) > abs(b):
        r = a
        phi = (math.pi / 4.0) * (b / a)
    else:
        r = b
        phi = (math.pi / 2.0) - (math.pi / 4.0) * (a / b)
    return r * math.cos(phi), r * math.sin(phi)


@device
def disk_polar(u1, u2):
    """Uniform unit disk by polar coordinates: r = sqrt(u1), not r = u1."""
    r = math.sqrt(u1)
    phi = 2.0 * math.pi * u2
    return r * math.cos(phi), r * math.sin(phi)


@device
def regular_polygon(corners, rotation, u1, u2):
    """Uniform point in the regular polygon with ``corners`` vertices on the unit circle.

    Cycles' aperture-blade sampler (kernel/sample/mapping.h): ``u1`` picks one
    of the polygon's triangles (the centre and one edge) and is reused, with
    ``u2``, as a uniform point in that triangle; the polygon is turned by
    ``rotation`` (its first vertex lies at angle ``rotation + pi/corners``).
    """
    corner = math.floor(u1 * corners)
    u = u1 * corners - corner
    u = math.sqrt(u)              # uniform barycentrics in the triangle
    v = u2 * u
    u = 1.0 - u
    angle = math.pi / corners
    px = (u + v) * math.cos(angle)
    py = (u - v) * math.sin(angle)
    rotation += corner * 2.0 * angle
    cr = math.cos(rotation)
    sr = math.sin(rotation)
    return cr * px - sr * py, sr * px + cr * py


@device
def cosine_hemisphere(u1, u2):
    """Direction around +z with density cos(theta)/pi (Malley's method)."""
    x, y = disk_concentric(u1, u2)
    z = math.sqrt(max(0.0, 1.0 - x * x - y * y))
    return x, y, z


@device
def uniform_cone(u1, u2, omc):
    """Direction around +z, uniform over the cap 1 - cos(theta) <= omc.

    The cap is given by ``omc`` = 1 - cos(half angle) rather than the cosine,
    which rounds to 1 for cones below about 1e-8 rad; its density is
    1/(2 pi omc) per steradian (:func:`uniform_cone_pdf`).
    """
    one_minus = omc * u1
    z = 1.0 - one_minus
    sin2 = one_minus * (2.0 - one_minus)
    r = math.sqrt(max(0.0, sin2))
    phi = 2.0 * math.pi * u2
    return r * math.cos(phi), r * math.sin(phi), z


@device
def uniform_cone_pdf(omc):
    """Density of :func:`uniform_cone` per steradian (omc > 0)."""
    return 1.0 / (2.0 * math.pi * omc)


@device
def uniform_triangle(u1, u2):
    """Barycentrics (b1, b2) uniform over a triangle (Heitz's low-distortion map)."""
    if u2 > u1:
        b1 = u1 * 0.5
        b2 = u2 - b1
    else:
        b2 = u2 * 0.5
        b1 = u1 - b2
    return b1, b2


@device
def orthonormal_basis(nx, ny, nz):
    """Two unit vectors t, b with (t, b, n) right-handed (Duff et al. 2017)."""
    sign = 1.0 if nz >= 0.0 else -1.0
    a = -1.0 / (sign + nz)
    b = nx * ny * a
    tx, ty, tz = 1.0 + sign * nx * nx * a, sign * b, -sign * nx
    bx, by, bz = b, sign + ny * ny * a, -ny
    return tx, ty, tz, bx, by, bz


@device
def power_heuristic(pdf_a, pdf_b):
    """MIS weight of strategy a against b (Veach's power heuristic, beta = 2)."""
    if pdf_a <= 0.0:
        return 0.0
    if pdf_b <= 0.0:
        return 1.0
    a2 = pdf_a * pdf_a
    return a2 / (a2 + pdf_b * pdf_b)


# -- pixel filter ------------------------------------------------------------------
FILTER_TABLE_SIZE = 1024


def filter_function(filter_type: str, width: float):
    """The 1-D filter as Cycles defines it (scene/film.cpp) and its half-support R."""
    if filter_type == "BOX":
        return (lambda x: np.ones_like(x)), 0.5
    if filter_type == "GAUSSIAN":
        return (lambda x: np.exp(-8.0 * x * x / (width * width))), 1.5 * width
    if filter_type == "BLACKMAN_HARRIS":
        full = 2.0 * width  # the window spans +-width pixels

        def bh(x):
            v = 2.0 * np.pi * (x / full + 0.5)
            return 0.35875 - 0.48829 * np.cos(v) + 0.14128 * np.cos(2 * v) - 0.01168 * np.cos(3 * v)
        return bh, width
    raise ValueError(f"unknown pixel filter {filter_type!r}")


def filter_table(filter_type: str, width: float, size: int = FILTER_TABLE_SIZE) -> np.ndarray:
    """Cycles' importance-sampling table of the pixel filter.

    ``table`` maps u in [0, 1] (linear interpolation over ``size`` entries)
    to a raster offset from the pixel's corner, 0.5 being its centre.  Every
    sample counts with weight 1 for its own pixel.  The table is built the
    way Cycles builds it, quirks included, so the two engines blur edges
    identically: the CDF of |f| over [0, R] is inverted with a one-sided
    interpolation, mirrored around the centre, and the last entry stays 0.
    """
    func, half = filter_function(filter_type, width)
    x = half * np.arange(size - 1) / (size - 2)
    cdf = np.concatenate([[0.0], np.cumsum(np.abs(func(x)))])
    cdf /= cdf[-1]
    table = np.zeros(size)
    mid = (size - 1) // 2
    for i in range(mid + 1):
        target = i / mid
        k = int(np.searchsorted(cdf, target, side="right"))
        if k < size - 1:
            frac = (target - cdf[k]) / (cdf[k + 1] - cdf[k])
        else:
            k, frac = size - 1, 0.0
        y = 2.0 * half * (k + frac) / (size - 1)
        table[mid + i] = 0.5 * (1.0 + y)
        table[mid - i] = 0.5 * (1.0 - y)
    return table


@device
def filter_offset(table, u):
    """Raster offset from the pixel corner for u in [0, 1), interpolated in ``table``."""
    x = u * (table.shape[0] - 1)
    i = min(int(x), table.shape[0] - 2)
    f = x - i
    return table[i] * (1.0 - f) + table[i + 1] * f
