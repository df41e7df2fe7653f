"""Samplers and warps: random numbers and the maps from [0,1)^2 to shapes.

Random numbers are counter-based: a path carries a 64-bit key made from the
seed, the pixel and the sample index, and ``sample_1d/2d/4d`` turn the key
and a *dimension set* into numbers.  Two samplers exist:

* the independent sampler: ``rand(key, dim)`` hashes the key with a dimension
  number, so every number is independent of every other (the lecture's
  sampler: the error of N samples falls exactly as 1/sqrt(N));
* the Sobol sampler (``sobol``): each pixel's samples are Owen-scrambled,
  shuffled Sobol points, stratified within each dimension set, as Cycles
  samples; unbiased, and its error falls faster for smooth integrands.

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
from .sobol import INDEX_BITS, reversed_index, shuffled_index, sobol_1d, sobol_2d, sobol_4d

# -- samplers and dimensions ------------------------------------------------------
# Which numbers a path draws (``sample_key`` and ``sample_1d/2d/4d``):
SAMPLER_INDEPENDENT = 0   # every number an independent hash (the lecture's sampler)
SAMPLER_SOBOL = 1         # Owen-scrambled, shuffled Sobol points per pixel (``sobol``)

# Numbers come in *dimension sets* of up to four, as Cycles assigns them
# (kernel/types.h, PRNG_*): the camera's sets first, then SETS_PER_BOUNCE sets
# for every path vertex (scattering or transparent), so adding a use of
# randomness never shifts another one.  With the Sobol sampler the numbers of
# one set are stratified together (put the most important pair first) and
# different sets are independent; the independent sampler draws number k of
# set s as dimension 4 s + k.
SET_FILTER = 0           # 2: pixel filter x, y
SET_LENS_TIME = 1        # 3: lens u, v and shutter time
SETS_PER_BOUNCE = 16
SET_TERMINATE = 0        # 1: Russian roulette
SET_LIGHT = 1            # 4: point on the light u, v; which light; which emissive triangle
SET_BSDF = 3             # 4: direction u, v; which closure; the lobe's third number
SET_AO = 4               # 2: the Ambient Occlusion pass's direction u, v

SAMPLE_BITS = INDEX_BITS   # sample index bits of a Sobol path key (Cycles' limit, 2^24 samples)
_SAMPLE_MASK = np.uint64((1 << SAMPLE_BITS) - 1)

_K_PIXEL = np.uint64(0x9E3779B97F4A7C15)    # golden-ratio increment (Weyl sequence)
_K_SAMPLE = np.uint64(0xD1B54A32D192ED03)
_K_DIM = np.uint64(0xAEF17502108EF2D9)
_M1 = np.uint64(0xBF58476D1CE4E5B9)         # splitmix64 finaliser constants
_M2 = np.uint64(0x94D049BB133111EB)
_M32 = np.uint64(0xFFFFFFFF)
_INV_2_53 = 1.0 / 9007199254740992.0
_K_SEED_B = np.uint64(0x5851F42D4C957F2D)   # any odd 64-bit constants
_K_SEED_C = np.uint64(0x14057B7EF767814F)
_K_WALK = np.uint64(0x2545F4914F6CDD1D)
_K_WALK_SETS = np.uint64(0x9FB21C651E98DF25)
_K_NODES = np.uint64(0xD6E8FEB86659FD93)


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
def walk_key(key, vertex):
    """Key of the numbers of a subsurface walk from path vertex ``vertex`` (its dimension sets
    start again at 0): other scrambles (the key's high bits) than the path's and than the
    exit's, the same sample index (low bits), so the Sobol sampler stays stratified over the
    pixel's samples at every step of the walk."""
    h = mix64((key >> np.uint64(SAMPLE_BITS)) ^ (np.uint64(vertex + 1) * _K_WALK_SETS))
    return key ^ (h << np.uint64(SAMPLE_BITS))


@device
def exit_key(key, vertex):
    """The key a path continues with after a subsurface walk from vertex ``vertex``: the
    walk's exit is shaded as a vertex of the same number, so its numbers (and those of the
    vertices after it) need other scrambles (the key's high bits); the sample index (low
    bits) stays, so the Sobol sampler stays stratified over the pixel's samples."""
    h = mix64((key >> np.uint64(SAMPLE_BITS)) ^ (np.uint64(vertex + 1) * _K_WALK))
    return key ^ (h << np.uint64(SAMPLE_BITS))


@device
def node_key(key, vertex):
    """Key of the numbers that ray-traced shader nodes (Bevel, Ambient Occlusion) draw at path
    vertex ``vertex``: a hash of the path's key (its sample index included), so every sample
    has its own."""
    return mix64(key ^ (np.uint64(vertex + 1) * _K_NODES))


@device
def branched_2d(key, branch):
    """Point ``branch`` of a set of 2D points drawn at one shading point (a node's samples),
    the set stratified as Cycles' path_branched_rng_2D stratifies it: the first points of an
    Owen-scrambled Sobol (0, 2)-sequence, scrambled by seeds hashed from ``key``."""
    h = mix64(key ^ _K_SEED_B)
    j = reversed_index(branch) << np.uint64(32 - INDEX_BITS)
    return sobol_2d(j, h & _M32, h >> np.uint64(32))


@device
def bounce_set(vertex, which):
    """Dimension set ``which`` (SET_TERMINATE, ...) of path vertex ``vertex`` (0: first hit)."""
    return SETS_PER_BOUNCE * (vertex + 1) + which


@device
def sample_key(sampler, seed, pixel, sample):
    """The key a path carries.  Independent: a hash of (seed, pixel, sample).  Sobol: a
    hash of (seed, pixel) in the high bits, the bit-reversed sample index in the low
    SAMPLE_BITS."""
    if sampler == SAMPLER_SOBOL:
        return (path_key(seed, pixel, 0) & ~_SAMPLE_MASK) | reversed_index(sample)
    return path_key(seed, pixel, sample)


@device
def _set_seeds(key, dim_set):
    """Five 32-bit scrambling seeds of a Sobol key's pixel and a dimension set: the index
    shuffle's, then one per dimension.  Each is hashed on its own: seeds that differ by
    fixed bits (one hash XORed with constants) correlate the dimensions' scrambles and
    bias the estimates (tests/core/test_sobol.py finds it)."""
    h = (key >> np.uint64(SAMPLE_BITS)) ^ (np.uint64(dim_set + 1) * _K_DIM)
    a = mix64(h)
    b = mix64(h ^ _K_SEED_B)     # three hashes of one input, computed side by side
    c = mix64(h ^ _K_SEED_C)
    return a & _M32, a >> np.uint64(32), b & _M32, b >> np.uint64(32), c & _M32


@device
def sample_1d(sampler, key, dim_set, mask):
    """The first number of dimension set ``dim_set``; ``mask`` is the Sobol index mask."""
    if sampler == SAMPLER_SOBOL:
        s, s0, _, _, _ = _set_seeds(key, dim_set)
        return sobol_1d(shuffled_index(key & _SAMPLE_MASK, s, mask), s0)
    return rand(key, 4 * dim_set)


@device
def sample_2d(sampler, key, dim_set, mask):
    """The first two numbers of dimension set ``dim_set`` (stratified together with Sobol)."""
    if sampler == SAMPLER_SOBOL:
        s, s0, s1, _, _ = _set_seeds(key, dim_set)
        return sobol_2d(shuffled_index(key & _SAMPLE_MASK, s, mask), s0, s1)
    return rand(key, 4 * dim_set), rand(key, 4 * dim_set + 1)


@device
def sample_4d(sampler, key, dim_set, mask):
    """The four numbers of dimension set ``dim_set``."""
    if sampler == SAMPLER_SOBOL:
        s, s0, s1, s2, s3 = _set_seeds(key, dim_set)
        return sobol_4d(shuffled_index(key & _SAMPLE_MASK, s, mask), s0, s1, s2, s3)
    d = 4 * dim_set
    return rand(key, d), rand(key, d + 1), rand(key, d + 2), rand(key, d + 3)


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
def around(ax, ay, az, x, y, z):
    """(x, y, z) given in a frame whose third axis is the unit vector a
    (``orthonormal_basis``), in world coordinates."""
    tx, ty, tz, bx, by, bz = orthonormal_basis(ax, ay, az)
    return x * tx + y * bx + z * ax, x * ty + y * by + z * ay, x * tz + y * bz + z * az


@device
def make_orthonormals(nx, ny, nz):
    """Cycles' make_orthonormals: a = normalize((1, 1, 1) x n) (or (-1, 1, 1) x n when the
    components are equal), b = n x a.  Where Cycles builds a frame this way and the result
    depends on how the frame turns about n (the Bump node's tangents, the three-axis disk
    probes of subsurface scattering and Bevel), this frame is used, not ``orthonormal_basis``."""
    if nx != ny or nx != nz:
        ax, ay, az = nz - ny, nx - nz, ny - nx
    else:
        ax, ay, az = nz - ny, nx + nz, -ny - nx
    n = math.sqrt(ax * ax + ay * ay + az * az)
    if n != 0.0:
        inv = 1.0 / n
        ax, ay, az = ax * inv, ay * inv, az * inv
    return ax, ay, az, ny * az - nz * ay, nz * ax - nx * az, nx * ay - ny * ax


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
    target = np.arange(mid + 1) / mid
    k = np.searchsorted(cdf, target, side="right")
    inside = k < size - 1
    kk = np.where(inside, k, 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        frac = np.where(inside, (target - cdf[kk]) / (cdf[kk + 1] - cdf[kk]), 0.0)
    k = np.where(inside, k, size - 1)
    y = 2.0 * half * (k + frac) / (size - 1)
    table[mid:mid + mid + 1] = 0.5 * (1.0 + y)
    table[mid::-1] = 0.5 * (1.0 - y)
    return table


@device
def filter_offset(table, u):
    """Raster offset from the pixel corner for u in [0, 1), interpolated in ``table``."""
    x = u * (table.shape[0] - 1)
    i = min(int(x), table.shape[0] - 2)
    f = x - i
    return table[i] * (1.0 - f) + table[i + 1] * f
