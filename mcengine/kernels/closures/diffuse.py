"""Diffuse closures: Lambert (CT_DIFFUSE), translucent (CT_TRANSLUCENT) and Oren-Nayar (CT_OREN_NAYAR).

As Cycles 5.0 (kernel/closure/bsdf_diffuse.h, bsdf_oren_nayar.h):

* Lambert: f cos = max(cos_i, 0) / pi, sampled by the cosine (concentric disk) warp;
* translucent: the same on the far side of the surface, labelled TRANSMIT | DIFFUSE (it
  counts as a transmission bounce);
* Oren-Nayar: Fujii's "improved" Oren-Nayar with the OpenPBR energy-preserving
  multiple-scattering term, f cos = cos_i (A + B s + f_ms), sampled like Lambert.
  ``oren_nayar_setup`` stores A, B and the view-dependent part of f_ms in CL_P0..CL_P4.

The weight CL_W (the colour) is not included.  Like Cycles these lobes do not look at the
view direction's side (a shading normal may put the viewer below it); only the light side
matters.  The caller checks the geometric normal.
"""
from __future__ import annotations

import math

from ...jit import device
from ..sampling import cosine_hemisphere
from ..scalar import safe_acos
from .layout import (
    CL_P0,
    CL_P1,
    CL_P2,
    CL_P3,
    CL_P4,
    LABEL_DIFFUSE,
    LABEL_NONE,
    LABEL_REFLECT,
    LABEL_TRANSMIT,
)

_INV_PI = 1.0 / math.pi
_FLT_MIN = 1.1754943508222875e-38     # Cycles adds FLT_MIN to a denominator; kept for parity
_K_ON = 0.5 * math.pi - 2.0 / 3.0      # G(0), and (1 - pi A) / B
_C_ON = (2.0 * math.pi - 5.6) / 3.0    # the B coefficient of E_avg


# -- Lambert and translucent ----------------------------------------------------------------------
@device
def lambert_eval(cl, k, wox, woy, woz, wix, wiy, wiz):
    """(f cos r, g, b, pdf) of Lambert: max(cos_i, 0) / pi for all three, and the same pdf."""
    c = max(wiz, 0.0) * _INV_PI
    return c, c, c, c


@device
def lambert_sample(cl, k, wox, woy, woz, u1, u2, u3):
    """(wix, wiy, wiz, r, g, b, pdf, label): cosine-weighted direction above the surface."""
    x, y, z = cosine_hemisphere(u1, u2)
    if not z > 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
    c = z * _INV_PI
    return x, y, z, c, c, c, c, LABEL_REFLECT | LABEL_DIFFUSE


@device
def translucent_eval(cl, k, wox, woy, woz, wix, wiy, wiz):
    """(f cos r, g, b, pdf) of the translucent lobe: max(-cos_i, 0) / pi."""
    c = max(-wiz, 0.0) * _INV_PI
    return c, c, c, c


@device
def translucent_sample(cl, k, wox, woy, woz, u1, u2, u3):
    """(wix, wiy, wiz, r, g, b, pdf, label): cosine-weighted direction below the surface."""
    x, y, z = cosine_hemisphere(u1, u2)
    if not z > 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
    c = z * _INV_PI
    return x, y, -z, c, c, c, c, LABEL_TRANSMIT | LABEL_DIFFUSE


# -- Oren-Nayar ------------------------------------------------------------------------------------
@device
def oren_nayar_G(cos_t):
    """G(mu) = sin(theta - 2/3 - sin cos) + 2/3 tan (1 - sin^3), the B-term of the directional albedo.

    Below mu = 1e-6 the first-order expansion pi/2 - 2/3 - mu (as Cycles).
    """
    if cos_t < 1e-6:
        return (0.5 * math.pi - 2.0 / 3.0) - cos_t
    sin_t = math.sqrt(max(0.0, 1.0 - cos_t * cos_t))
    theta = safe_acos(cos_t)
    return sin_t * (theta - 2.0 / 3.0 - sin_t * cos_t) + (2.0 / 3.0) * (sin_t / cos_t) * (1.0 - sin_t * sin_t * sin_t)


@device
def oren_nayar_setup(cl, k, cos_no, roughness, color_r, color_g, color_b):
    """A, B and the multiple-scattering factor of an Oren-Nayar row (Cycles' bsdf_oren_nayar_setup).

    sigma = clamp(roughness, 0, 1), A = 1 / (pi + sigma (pi/2 - 2/3)), B = sigma A.  With
    rho = clamp(colour, 0, 1), E_avg = pi A + B (2 pi - 5.6) / 3 and the view's albedo
    E(mu_o) = pi A + B G(mu_o):
        CL_P2..4 = rho^2 / pi * (E_avg / (1 - E_avg)) / (1 - rho (1 - E_avg)) * (1 - E(mu_o)),
    the part of OpenPBR's f_ms that does not depend on the light.  CL_P0 = A, CL_P1 = B.
    ``cos_no`` is the view's cosine to CL_N.  At sigma = 0 the row evaluates as Lambert.
    1 - E is computed as B (pi/2 - 2/3 - G), which equals it exactly (1 - pi A = B (pi/2 - 2/3))
    and keeps tiny sigma finite.
    """
    sigma = roughness
    if not sigma > 0.0:
        sigma = 0.0
    elif sigma > 1.0:
        sigma = 1.0
    a = 1.0 / (math.pi + sigma * (0.5 * math.pi - 2.0 / 3.0))
    b = sigma * a
    cl[k, CL_P0] = a
    cl[k, CL_P1] = b
    if b <= 0.0:
        cl[k, CL_P2] = 0.0
        cl[k, CL_P3] = 0.0
        cl[k, CL_P4] = 0.0
        return
    # 1 - E(mu) = B (k - G(mu)) and 1 - E_avg = B (k - c), k = pi/2 - 2/3, c = (2 pi - 5.6)/3,
    # since 1 - pi A = k B: Cycles' expression without its cancellation (sigma -> 0 gave 0/0).
    e_avg = 1.0 - b * (_K_ON - _C_ON)
    factor = e_avg * (_K_ON - oren_nayar_G(max(cos_no, 0.0))) / (_K_ON - _C_ON)
    for c in range(3):
        rho = color_r if c == 0 else (color_g if c == 1 else color_b)
        if not rho > 0.0:
            rho = 0.0
        elif rho > 1.0:
            rho = 1.0
        cl[k, CL_P2 + c] = _INV_PI * rho * rho * factor / (1.0 - rho * b * (_K_ON - _C_ON))


@device
def _oren_nayar_value(cl, k, wox, woy, woz, wix, wiy, wiz):
    nl = max(wiz, 0.0)
    b = cl[k, CL_P1]
    if b <= 0.0:
        c = nl * _INV_PI
        return c, c, c
    nv = max(woz, 0.0)
    t = wox * wix + woy * wiy + woz * wiz - nl * nv
    if t > 0.0:
        t /= max(nl, nv) + _FLT_MIN
    single = cl[k, CL_P0] + b * t
    ms = b * (_K_ON - oren_nayar_G(nl))          # 1 - E(mu_i)
    return (nl * (single + cl[k, CL_P2] * ms), nl * (single + cl[k, CL_P3] * ms),
            nl * (single + cl[k, CL_P4] * ms))


@device
def oren_nayar_eval(cl, k, wox, woy, woz, wix, wiy, wiz):
    """(f cos r, g, b, pdf) of Oren-Nayar: cos_i (A + B s + f_ms), pdf cos_i / pi; zero below.

    s = wo.wi - cos_o cos_i, divided by max(cos_o, cos_i) when positive.
    """
    if not wiz > 0.0:
        return 0.0, 0.0, 0.0, 0.0
    r, g, b = _oren_nayar_value(cl, k, wox, woy, woz, wix, wiy, wiz)
    return r, g, b, wiz * _INV_PI


@device
def oren_nayar_sample(cl, k, wox, woy, woz, u1, u2, u3):
    """(wix, wiy, wiz, r, g, b, pdf, label): cosine-weighted direction, Oren-Nayar's f cos."""
    x, y, z = cosine_hemisphere(u1, u2)
    if not z > 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
    r, g, b = _oren_nayar_value(cl, k, wox, woy, woz, x, y, z)
    return x, y, z, r, g, b, z * _INV_PI, LABEL_REFLECT | LABEL_DIFFUSE
