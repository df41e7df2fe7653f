"""The Hair BSDF's closures: reflection (CT_HAIR_REFLECTION) and transmission
(CT_HAIR_TRANSMISSION).

As Cycles 5.0 (kernel/closure/bsdf_hair.h, from Open Shading Language): a lobe about the
strand's tangent T, in the angle theta from the plane normal to T and the azimuth phi
about it.  In theta, a Cauchy-like lobe of width ``r1`` about the mirror angle (shifted by
twice the offset), sampled by inverting its arctangent; in phi, reflection is
cos(phi / 2) / 4 over phi in [-pi r2, pi r2] towards the viewer, transmission a Cauchy
lobe of width ``r2`` about the far side.  Every value is its own pdf: f·cos = pdf, so a
sample's weight is exactly 1.

Cycles' quirks are kept, as they decide what it renders: the sampled reflection's phi pdf
is cos(phi / 2) / (4 r2), not the cos(phi / (2 r2)) / (4 r2) of its evaluation; evaluation
rejects reflection below the surface and beyond phi = pi / 2 and transmission above it,
while sampling does not (the caller must not reject sampled directions by side either:
``closures.free_side``).

``hair_setup`` stores the tangent in the closure's local frame (CL_HAIR_T), so evaluation
and sampling work in local coordinates as the other closures do; the frame's normal is the
one the evaluation tests sides with.  The weight CL_W (the colour) is not included.
"""
from __future__ import annotations

import math

from ...jit import device
from ..scalar import safe_acos
from .layout import (
    CL_HAIR_OFFSET,
    CL_HAIR_R1,
    CL_HAIR_R2,
    CL_HAIR_T,
    CL_N,
    CL_T,
    LABEL_GLOSSY,
    LABEL_NONE,
    LABEL_REFLECT,
    LABEL_TRANSMIT,
)

_HALF_PI = 0.5 * math.pi
_POLE = 0.001        # directions closer than this (radians) to the strand are rejected


@device
def hair_setup(cl, k, tx, ty, tz, roughness1, roughness2, offset):
    """The strand's unit world tangent (tx, ty, tz), its roughnesses (clamped to [0.001, 1]
    as Cycles' setups do) and offset angle, for closure k whose frame is set."""
    nx, ny, nz = cl[k, CL_N], cl[k, CL_N + 1], cl[k, CL_N + 2]
    ax, ay, az = cl[k, CL_T], cl[k, CL_T + 1], cl[k, CL_T + 2]
    bx, by, bz = ny * az - nz * ay, nz * ax - nx * az, nx * ay - ny * ax
    cl[k, CL_HAIR_T] = tx * ax + ty * ay + tz * az
    cl[k, CL_HAIR_T + 1] = tx * bx + ty * by + tz * bz
    cl[k, CL_HAIR_T + 2] = tx * nx + ty * ny + tz * nz
    cl[k, CL_HAIR_R1] = min(max(roughness1, 0.001), 1.0)
    cl[k, CL_HAIR_R2] = min(max(roughness2, 0.001), 1.0)
    cl[k, CL_HAIR_OFFSET] = offset


@device
def _split(cl, k, x, y, z):
    """(component along T, unit component normal to it, ok) of direction (x, y, z)."""
    tx, ty, tz = cl[k, CL_HAIR_T], cl[k, CL_HAIR_T + 1], cl[k, CL_HAIR_T + 2]
    c = tx * x + ty * y + tz * z
    px, py, pz = x - c * tx, y - c * ty, z - c * tz
    length = math.sqrt(px * px + py * py + pz * pz)
    if not length > 0.0:
        return c, 0.0, 0.0, 0.0, False
    return c, px / length, py / length, pz / length, True


@device
def _theta(cl, k, theta_r):
    """(r1, offset, a, b): the theta lobe's width and offset and the arctangent bounds its
    inversion samples between."""
    r1, offset = cl[k, CL_HAIR_R1], cl[k, CL_HAIR_OFFSET]
    a = math.atan(((_HALF_PI + theta_r) * 0.5 - offset) / r1)
    b = math.atan(((-_HALF_PI + theta_r) * 0.5 - offset) / r1)
    return r1, offset, a, b


@device
def _theta_pdf(r1, t, a, b, cos_theta_i):
    return r1 / (2.0 * (t * t + r1 * r1) * (a - b) * cos_theta_i)


@device
def _c_tt(r2):
    return 2.0 * math.atan(_HALF_PI / r2)


@device
def hair_eval(cl, k, transmission, wox, woy, woz, wix, wiy, wiz):
    """(f cos r, g, b, pdf) of reflection (transmission False) or transmission, from the
    viewer wo towards wi (local frame)."""
    if transmission:
        if wiz >= 0.0:
            return 0.0, 0.0, 0.0, 0.0
    elif wiz < 0.0:
        return 0.0, 0.0, 0.0, 0.0
    iz, lx, ly, lz, ok_o = _split(cl, k, wox, woy, woz)
    oz, yx, yy, yz, ok_i = _split(cl, k, wix, wiy, wiz)
    if not (ok_o and ok_i):
        return 0.0, 0.0, 0.0, 0.0
    theta_r = _HALF_PI - safe_acos(iz)
    theta_i = _HALF_PI - safe_acos(oz)
    cos_phi = yx * lx + yy * ly + yz * lz
    if _HALF_PI - abs(theta_i) < _POLE or (not transmission and cos_phi < 0.0):
        return 0.0, 0.0, 0.0, 0.0
    r1, offset, a, b = _theta(cl, k, theta_r)
    r2 = cl[k, CL_HAIR_R2]
    t = (theta_i + theta_r) * 0.5 - offset
    theta_pdf = _theta_pdf(r1, t, a, b, math.cos(theta_i))
    if transmission:
        p = math.pi - safe_acos(cos_phi)
        phi_pdf = r2 / (_c_tt(r2) * (p * p + r2 * r2))
    else:
        phi = min(safe_acos(cos_phi) / r2, math.pi)
        phi_pdf = math.cos(phi * 0.5) * 0.25 / r2
    pdf = phi_pdf * theta_pdf
    if not (pdf > 0.0 and math.isfinite(pdf)):
        return 0.0, 0.0, 0.0, 0.0
    return pdf, pdf, pdf, pdf


@device
def hair_sample(cl, k, transmission, wox, woy, woz, u1, u2):
    """(wix, wiy, wiz, r, g, b, pdf, label): theta by inverting its lobe, phi by Cycles'
    warps; the value is the pdf (weight 1)."""
    iz, lx, ly, lz, ok = _split(cl, k, wox, woy, woz)
    if not ok:
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
    tx, ty, tz = cl[k, CL_HAIR_T], cl[k, CL_HAIR_T + 1], cl[k, CL_HAIR_T + 2]
    # locx = locy x T
    xx, xy, xz = ly * tz - lz * ty, lz * tx - lx * tz, lx * ty - ly * tx
    theta_r = _HALF_PI - safe_acos(iz)
    r1, offset, a, b = _theta(cl, k, theta_r)
    r2 = cl[k, CL_HAIR_R2]
    t = r1 * math.tan(u1 * (a - b) + b)
    theta_i = 2.0 * (t + offset) - theta_r
    sin_t, cos_t = math.sin(theta_i), math.cos(theta_i)
    if transmission:
        c_tt = _c_tt(r2)
        p = r2 * math.tan(c_tt * (u2 - 0.5))
        phi = p + math.pi
        phi_pdf = r2 / (c_tt * (p * p + r2 * r2))
        label = LABEL_TRANSMIT | LABEL_GLOSSY
    else:
        phi = 2.0 * math.asin(min(max(1.0 - 2.0 * u2, -1.0), 1.0)) * r2
        phi_pdf = math.cos(phi * 0.5) * 0.25 / r2
        label = LABEL_REFLECT | LABEL_GLOSSY
    pdf = abs(phi_pdf * _theta_pdf(r1, t, a, b, cos_t))
    if _HALF_PI - abs(theta_i) < _POLE or not (pdf > 0.0 and math.isfinite(pdf)):
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
    sp, cp = math.sin(phi), math.cos(phi)
    wx = cp * cos_t * lx - sp * cos_t * xx + sin_t * tx
    wy = cp * cos_t * ly - sp * cos_t * xy + sin_t * ty
    wz = cp * cos_t * lz - sp * cos_t * xz + sin_t * tz
    return wx, wy, wz, pdf, pdf, pdf, pdf, label
