"""Precomputed BSDF tables (energy compensation, albedo estimates) and their lookups.

The tables have Cycles' names, sizes, axes and node placement (scene/shader.tables) but are
our own numerical integrals of this package's GGX sampler (``tools/make_bsdf_tables.py``
writes them to ``data/*.npy``; its docstring says how and how accurately).  Node i of an
axis of n nodes lies at i / (n - 1), clamped at the ends to [1e-4, 1] for roughness and
cosine and [1e-4, 0.99] for the IOR coordinate z; the first axis listed varies fastest,
i.e. it is the *last* numpy index:

=====================  ==============  =====  ==============================================
name                   axes            shape  value
=====================  ==============  =====  ==============================================
GGX_E                  (r, mu)         32^2   albedo of GGX reflection with F = 1
GGX_EAVG               (r)             32     its average, integral of 2 mu E(mu)
GGX_GLASS_E            (r, mu, z)      16^3   albedo of GGX glass (dielectric Fresnel), IOR > 1
GGX_GLASS_EAVG         (r, z)          16^2   its average over mu
GGX_GLASS_INV_E        (r, mu, z)      16^3   the same at 1 / IOR
GGX_GLASS_INV_EAVG     (r, z)          16^2   its average over mu
GGX_GEN_SCHLICK_IOR_S  (r, mu, z)      16^3   mean F0 -> F90 factor s, exact Fresnel remapped
GGX_GEN_SCHLICK_S      (r, mu, z)      16^3   mean s of (1 - cos)^e, z = 1 / (0.2 e + 1)
=====================  ==============  =====  ==============================================

r = (alpha_x alpha_y)^(1/4) is the Roughness value, mu the cosine of the view direction and
z = sqrt(|(ior - 1) / (ior + 1)|) (so ior = (1 + z^2) / (1 - z^2)).

The arrays are module globals: numba freezes them into every compiled function that reads
them (as constants, stored in the on-disk cache too), so a kernel never receives them as
arguments.  A missing data file (before ``tools/make_bsdf_tables.py`` has run) leaves that
table filled with NaN and ``TABLES_LOADED`` False.

The thin-film table (Belcour and Barla's Fourier-transformed colour matching functions) is
not an integral of a closure: ``tools/make_thin_film_table.py`` writes the transform of the
CIE 1931 XYZ CMFs to ``data/thin_film_cmf.npy``, and here, as Cycles'
``ShaderManager::compute_thin_film_table`` does at scene load, each entry is turned into the
working space's RGB (``kernels.colorspace.XYZ_TO_RGB``) and divided by the channel's value at
optical path difference 0: ``THIN_FILM_RE`` and ``THIN_FILM_IM``, shape (3, 512), RGB rows,
read with ``lookup_row`` at x = 2 pi OPD / 60000 nm.

``lookup_1d/2d/3d`` reproduce Cycles' kernel/util/lookup_table.h: each coordinate is
clamped to [0, 1] (NaN reads as 0), scaled to [0, n - 1], and the table is interpolated
linearly between the two nearest nodes along each axis (multilinear).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ...jit import device
from ..colorspace import XYZ_TO_RGB

DATA_DIR = Path(__file__).resolve().parent / "data"

# name: shape (numpy order: slowest axis first)
TABLE_SHAPES = {
    "ggx_E": (32, 32),
    "ggx_Eavg": (32,),
    "ggx_glass_E": (16, 16, 16),
    "ggx_glass_Eavg": (16, 16),
    "ggx_glass_inv_E": (16, 16, 16),
    "ggx_glass_inv_Eavg": (16, 16),
    "ggx_gen_schlick_ior_s": (16, 16, 16),
    "ggx_gen_schlick_s": (16, 16, 16),
}
THIN_FILM_SHAPE = (2, 3, 512)     # real and imaginary parts of X, Y, Z at 512 path differences


def _load(name: str, shape: tuple[int, ...] | None = None) -> tuple[np.ndarray, bool]:
    path = DATA_DIR / f"{name}.npy"
    shape = shape or TABLE_SHAPES[name]
    if not path.exists():
        return np.full(shape, np.nan), False
    table = np.ascontiguousarray(np.load(path), dtype=np.float64)
    if table.shape != shape:
        raise ValueError(f"{path}: shape {table.shape}, expected {shape}")
    return table, True


GGX_E, _ok0 = _load("ggx_E")
GGX_EAVG, _ok1 = _load("ggx_Eavg")
GGX_GLASS_E, _ok2 = _load("ggx_glass_E")
GGX_GLASS_EAVG, _ok3 = _load("ggx_glass_Eavg")
GGX_GLASS_INV_E, _ok4 = _load("ggx_glass_inv_E")
GGX_GLASS_INV_EAVG, _ok5 = _load("ggx_glass_inv_Eavg")
GGX_GEN_SCHLICK_IOR_S, _ok6 = _load("ggx_gen_schlick_ior_s")
GGX_GEN_SCHLICK_S, _ok7 = _load("ggx_gen_schlick_s")
_THIN_FILM_XYZ, _ok8 = _load("thin_film_cmf", THIN_FILM_SHAPE)
TABLES_LOADED = all((_ok0, _ok1, _ok2, _ok3, _ok4, _ok5, _ok6, _ok7, _ok8))
_thin_film_rgb = np.einsum("rx,pxj->prj", XYZ_TO_RGB, _THIN_FILM_XYZ)
THIN_FILM_RE = np.ascontiguousarray(_thin_film_rgb[0] / _thin_film_rgb[0, :, :1])
THIN_FILM_IM = np.ascontiguousarray(_thin_film_rgb[1] / _thin_film_rgb[0, :, :1])
# GGX_E and GGX_EAVG with a leading axis of one node, so that a single lookup_3d / lookup_2d
# site reads either them (z = 0) or the glass tables.
GGX_E_3D = np.ascontiguousarray(GGX_E[None])
GGX_EAVG_2D = np.ascontiguousarray(GGX_EAVG[None])


@device
def _axis(x, n):
    """Index of the lower node, weight of the upper one and the upper index, for x in [0, 1]."""
    if not x > 0.0:          # also NaN
        x = 0.0
    elif x > 1.0:
        x = 1.0
    x *= n - 1
    i = min(int(x), n - 1)
    return i, x - i, min(i + 1, n - 1)


@device
def lookup_1d(table, x):
    """table[x] for a 1-D table, linear between nodes, x clamped to [0, 1]."""
    i, t, j = _axis(x, table.shape[0])
    if t == 0.0:
        return table[i]
    return (1.0 - t) * table[i] + t * table[j]


@device
def lookup_row(table, row, x):
    """table[row, x] for a 2-D table, linear along its last axis, x clamped to [0, 1]."""
    i, t, j = _axis(x, table.shape[1])
    if t == 0.0:
        return table[row, i]
    return (1.0 - t) * table[row, i] + t * table[row, j]


@device
def lookup_2d(table, x, y):
    """Bilinear lookup; x indexes the last (fastest) axis, y the first."""
    nx = table.shape[1]
    i, t, j = _axis(y, table.shape[0])
    xi, xt, xj = _axis(x, nx)
    a = table[i, xi] if xt == 0.0 else (1.0 - xt) * table[i, xi] + xt * table[i, xj]
    if t == 0.0:
        return a
    b = table[j, xi] if xt == 0.0 else (1.0 - xt) * table[j, xi] + xt * table[j, xj]
    return (1.0 - t) * a + t * b


@device
def _row(table, zi, yi, xi, xt, xj):
    if xt == 0.0:
        return table[zi, yi, xi]
    return (1.0 - xt) * table[zi, yi, xi] + xt * table[zi, yi, xj]


@device
def lookup_3d(table, x, y, z):
    """Trilinear lookup; x indexes the last (fastest) axis, z the first."""
    zi, zt, zj = _axis(z, table.shape[0])
    yi, yt, yj = _axis(y, table.shape[1])
    xi, xt, xj = _axis(x, table.shape[2])
    a = _row(table, zi, yi, xi, xt, xj)
    if yt != 0.0:
        a = (1.0 - yt) * a + yt * _row(table, zi, yj, xi, xt, xj)
    if zt == 0.0:
        return a
    b = _row(table, zj, yi, xi, xt, xj)
    if yt != 0.0:
        b = (1.0 - yt) * b + yt * _row(table, zj, yj, xi, xt, xj)
    return (1.0 - zt) * a + zt * b
