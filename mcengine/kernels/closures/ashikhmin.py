"""Ashikhmin's closures: the Ashikhmin-Shirley glossy lobe and the Ashikhmin velvet sheen.

The Glossy BSDF's Ashikhmin-Shirley distribution (Cycles' bsdf_ashikhmin_shirley.h): an
anisotropic Phong lobe of the half vector with exponents n = 2 / alpha^2 - 2 along the
tangent and the bitangent, alpha clamped to [1e-4, 1] (a perfect mirror at 1e-4), the
original paper's "pump" 1 / (|h.wo| max(cos_o, cos_i)), and the half vector sampled from
the lobe (by quadrant when anisotropic).  The Sheen BSDF's Ashikhmin distribution (Cycles'
bsdf_ashikhmin_velvet.h): a microfacet velvet D = exp(-cot^2 / sigma^2) / (pi sigma^2
sin^4) with G = min(1, 2 |n.h / h.wo| cos), sampled uniformly over the hemisphere.

Frames as every closure (``layout``): local z is the normal, wo points to the viewer, wi
to the light or the sampled direction; ``*_eval`` return f |cos_i| and the pdf.
"""
from __future__ import annotations

import math

from ...jit import device
from .layout import (
    CL_AX,
    CL_AY,
    CL_VELVET_INV_SIGMA2,
    LABEL_DIFFUSE,
    LABEL_GLOSSY,
    LABEL_NONE,
    LABEL_REFLECT,
    LABEL_SINGULAR,
)

AS_MIN_ALPHA = 1e-4        # Cycles clamps alpha to [1e-4, 1]; at 1e-4 the lobe is a mirror
_INV_PI = 1.0 / math.pi
_INV_2PI = 0.5 / math.pi


@device
def _exponent(alpha):
    return 2.0 / (alpha * alpha) - 2.0


@device
def ashikhmin_shirley_eval(cl, k, wox, woy, woz, wix, wiy, wiz):
    """(f cos_i r, g, b, pdf) of the Ashikhmin-Shirley lobe of closure k."""
    ax, ay = cl[k, CL_AX], cl[k, CL_AY]
    if max(ax, ay) <= AS_MIN_ALPHA or woz < 0.0 or wiz < 0.0:
        return 0.0, 0.0, 0.0, 0.0
    cos_o, cos_i = max(woz, 1e-6), max(wiz, 1e-6)
    hx, hy, hz = wox + wix, woy + wiy, woz + wiz
    length = math.sqrt(hx * hx + hy * hy + hz * hz)
    if not length > 0.0:
        return 0.0, 0.0, 0.0, 0.0
    hx, hy, hz = hx / length, hy / length, hz / length
    cos_ho = max(abs(hx * wox + hy * woy + hz * woz), 1e-6)
    cos_hn = max(hz, 1e-6)
    pump = 1.0 / max(1e-6, cos_ho * max(cos_o, cos_i))
    nx_, ny_ = _exponent(ax), _exponent(ay)
    if nx_ == ny_:
        lobe = cos_hn ** nx_
        norm = (nx_ + 1.0) / (8.0 * math.pi)
    else:
        if cos_hn < 1.0:
            lobe = cos_hn ** ((nx_ * hx * hx + ny_ * hy * hy) / (1.0 - cos_hn * cos_hn))
        else:
            lobe = 1.0
        norm = math.sqrt((nx_ + 1.0) * (ny_ + 1.0)) / (8.0 * math.pi)
    f = cos_i * norm * lobe * pump
    return f, f, f, norm * lobe / cos_ho


@device
def _first_quadrant(nx_, ny_, u1, u2):
    phi = math.atan(math.sqrt((nx_ + 1.0) / (ny_ + 1.0)) * math.tan(0.5 * math.pi * u1))
    c, s = math.cos(phi), math.sin(phi)
    return phi, u2 ** (1.0 / (nx_ * c * c + ny_ * s * s + 1.0))


@device
def ashikhmin_shirley_sample(cl, k, wox, woy, woz, u1, u2, u3):
    """(wi x, y, z, r, g, b, pdf, label): reflection about a half vector from the lobe;
    a mirror (weight 1, pdf 0, singular) at alpha 1e-4."""
    if not woz > 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
    ax, ay = cl[k, CL_AX], cl[k, CL_AY]
    nx_, ny_ = _exponent(ax), _exponent(ay)
    if nx_ == ny_:
        phi = 2.0 * math.pi * u1
        cos_t = u2 ** (1.0 / (nx_ + 1.0))
    elif u1 < 0.25:
        phi, cos_t = _first_quadrant(nx_, ny_, 4.0 * u1, u2)
    elif u1 < 0.5:
        phi, cos_t = _first_quadrant(nx_, ny_, 4.0 * (0.5 - u1), u2)
        phi = math.pi - phi
    elif u1 < 0.75:
        phi, cos_t = _first_quadrant(nx_, ny_, 4.0 * (u1 - 0.5), u2)
        phi = math.pi + phi
    else:
        phi, cos_t = _first_quadrant(nx_, ny_, 4.0 * (1.0 - u1), u2)
        phi = 2.0 * math.pi - phi
    sin_t = math.sqrt(max(1.0 - cos_t * cos_t, 0.0))
    hx, hy, hz = sin_t * math.cos(phi), sin_t * math.sin(phi), cos_t
    cos_ho = hx * wox + hy * woy + hz * woz
    if cos_ho < 0.0:
        hx, hy, hz, cos_ho = -hx, -hy, -hz, -cos_ho
    x, y, z = -wox + 2.0 * cos_ho * hx, -woy + 2.0 * cos_ho * hy, -woz + 2.0 * cos_ho * hz
    if z < 0.0:                 # below the surface (Cycles tests the geometric normal)
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
    if max(ax, ay) <= AS_MIN_ALPHA:
        return x, y, z, 1.0, 1.0, 1.0, 0.0, LABEL_REFLECT | LABEL_SINGULAR
    r, g, b, pdf = ashikhmin_shirley_eval(cl, k, wox, woy, woz, x, y, z)
    return x, y, z, r, g, b, pdf, LABEL_REFLECT | LABEL_GLOSSY


@device
def velvet_eval(cl, k, wox, woy, woz, wix, wiy, wiz):
    """(f cos_i r, g, b, pdf) of the Ashikhmin velvet of closure k (pdf: uniform over the
    hemisphere)."""
    if not (woz > 0.0 and wiz > 0.0):
        return 0.0, 0.0, 0.0, 0.0
    f = _velvet(cl[k, CL_VELVET_INV_SIGMA2], wox, woy, woz, wix, wiy, wiz)
    if f < 0.0:
        return 0.0, 0.0, 0.0, 0.0
    return f, f, f, _INV_2PI


@device
def _velvet(inv_sigma2, wox, woy, woz, wix, wiy, wiz):
    """D G / (4 cos_o), or -1 where Cycles rejects the pair (h along the normal, or
    grazing h.wo)."""
    hx, hy, hz = wox + wix, woy + wiy, woz + wiz
    length = math.sqrt(hx * hx + hy * hy + hz * hz)
    if not length > 0.0:
        return -1.0
    cos_nh = hz / length
    cos_ho = abs(hx * wox + hy * woy + hz * woz) / length
    if not (abs(cos_nh) < 1.0 - 1e-5 and cos_ho > 1e-5):
        return -1.0
    ratio = max(cos_nh / cos_ho, 1e-5)
    g = min(1.0, 2.0 * abs(ratio * woz), 2.0 * abs(ratio * wiz))
    sin2 = 1.0 - cos_nh * cos_nh
    d = math.exp(-(cos_nh * cos_nh / sin2) * inv_sigma2) * inv_sigma2 * _INV_PI / (sin2 * sin2)
    return 0.25 * d * g / woz


@device
def velvet_sample(cl, k, wox, woy, woz, u1, u2, u3):
    """(wi, r, g, b, pdf, label): a direction uniform over the hemisphere (a diffuse label,
    as Cycles')."""
    z = u1
    r = math.sqrt(max(1.0 - z * z, 0.0))
    phi = 2.0 * math.pi * u2
    x, y = r * math.cos(phi), r * math.sin(phi)
    if not woz > 1e-5:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
    f = _velvet(cl[k, CL_VELVET_INV_SIGMA2], wox, woy, woz, x, y, z)
    if f < 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
    return x, y, z, f, f, f, _INV_2PI, LABEL_REFLECT | LABEL_DIFFUSE
