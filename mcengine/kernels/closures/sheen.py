"""Sheen: the microfibre model of Zeltner, Burley and Chiang 2022 (Cycles' Sheen BSDF).

The lobe is a linearly transformed cosine: in a frame whose +x points towards
the viewer's side, ``f|cos| = pdf = max(z, 0) (a / l)^2 / pi`` with
``l = (a x + b z)^2 + (a y)^2 + z^2``, and the closure's weight carries the
albedo rho.  a, b and rho depend on the view cosine and the roughness through
a 32 x 32 table (``data/sheen_ltc.npy``, measured from Cycles by
``tools/measure_sheen_ltc.py``), read bilinearly as Cycles reads it.
Sampling maps a uniform disk point through the inverse transform.
Cycles: kernel/closure/bsdf_sheen.h.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ...jit import device
from ..sampling import disk_concentric
from .layout import CL_N, CL_P0, CL_P1, CL_SW, CL_TYPE, CL_W, CT_NONE, LABEL_DIFFUSE, LABEL_REFLECT
from .tables import lookup_2d

_PATH = Path(__file__).resolve().parent / "data" / "sheen_ltc.npy"
# (a, b, rho) x (roughness, view cosine); NaN until measured.
SHEEN_LTC = (np.ascontiguousarray(np.load(_PATH), np.float64) if _PATH.exists()
             else np.full((3, 32, 32), np.nan))
SHEEN_A = np.ascontiguousarray(SHEEN_LTC[0])
SHEEN_B = np.ascontiguousarray(SHEEN_LTC[1])
SHEEN_RHO = np.ascontiguousarray(SHEEN_LTC[2])


@device
def sheen_setup(cl, k, wox, woy, woz, roughness):
    """Read the LTC for the view direction (world) into closure k, whose normal and
    frame are set (+x towards the viewer); weight and sample weight x rho.

    Returns False, leaving an empty closure, where the LTC is invalid (Cycles
    skips the closure when |a| < 1e-5 or rho < 1e-5).
    """
    r = min(max(roughness, 1e-3), 1.0)
    cos_no = wox * cl[k, CL_N] + woy * cl[k, CL_N + 1] + woz * cl[k, CL_N + 2]
    a = lookup_2d(SHEEN_A, cos_no, r)
    b = lookup_2d(SHEEN_B, cos_no, r)
    rho = lookup_2d(SHEEN_RHO, cos_no, r)
    if not (abs(a) >= 1e-5 and rho >= 1e-5):
        cl[k, CL_TYPE] = CT_NONE
        cl[k, CL_SW] = 0.0
        return False
    for c in range(3):
        cl[k, CL_W + c] *= rho
    cl[k, CL_SW] *= rho
    cl[k, CL_P0] = a
    cl[k, CL_P1] = b
    return True


@device
def _ltc(a, b, x, y, z):
    length2 = (a * x + b * z) ** 2 + (a * y) ** 2 + z * z
    return max(z, 0.0) * (a / length2) ** 2 / math.pi


@device
def sheen_eval(cl, k, wox, woy, woz, wix, wiy, wiz):
    """(f|cos| r, g, b, pdf) for local directions (the LTC is its own pdf)."""
    if wiz <= 0.0 or woz <= 0.0:
        return 0.0, 0.0, 0.0, 0.0
    v = _ltc(cl[k, CL_P0], cl[k, CL_P1], wix, wiy, wiz)
    return v, v, v, v


@device
def sheen_sample(cl, k, wox, woy, woz, u1, u2, u3):
    """Sample the LTC: a uniform disk point lifted to the hemisphere and transformed."""
    a, b = cl[k, CL_P0], cl[k, CL_P1]
    dx, dy = disk_concentric(u1, u2)
    dz = math.sqrt(max(1.0 - dx * dx - dy * dy, 0.0))
    x, y, z = dx - dz * b, dy, dz * a
    length = math.sqrt(x * x + y * y + z * z)
    x, y, z = x / length, y / length, z / length
    if z <= 0.0 or woz <= 0.0:
        return x, y, z, 0.0, 0.0, 0.0, 0.0, LABEL_REFLECT | LABEL_DIFFUSE
    v = _ltc(a, b, x, y, z)
    return x, y, z, v, v, v, v, LABEL_REFLECT | LABEL_DIFFUSE

