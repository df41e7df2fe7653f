"""The Toon BSDF's closures: diffuse toon (CT_DIFFUSE_TOON) and glossy toon (CT_GLOSSY_TOON).

As Cycles 5.0 (kernel/closure/bsdf_toon.h, from Open Shading Language): a lobe of constant
intensity 1 within ``size`` of its axis (the normal, or for glossy toon the view reflected
about it), falling linearly to 0 over ``smooth`` beyond, and sampled uniformly in the cone
of half angle min(size + smooth, pi/2) about the axis.  Its value f·cos is the intensity
times that cone's pdf, 1 / (2 pi (1 - cos)), so an intensity of 1 everywhere in the cone
reflects everything.  ``toon_setup`` stores Cycles' angles: size clamped to [1e-5, 1] and
smooth to [0, 1], both times pi/2, in CL_P0 and CL_P1.

Diffuse toon does not look at the view direction; glossy toon needs both directions above
the surface.  The weight CL_W (the colour) is not included; the caller checks the
geometric normal.
"""
from __future__ import annotations

import math

from ...jit import device
from ..sampling import around, uniform_cone, uniform_cone_pdf
from ..scalar import safe_acos, saturate
from .layout import CL_P0, CL_P1, LABEL_DIFFUSE, LABEL_GLOSSY, LABEL_NONE, LABEL_REFLECT

_HALF_PI = 0.5 * math.pi


@device
def toon_setup(cl, k, size, smooth):
    """Cycles' bsdf_toon_setup_common: the lobe's angles from the node's Size and Smooth."""
    cl[k, CL_P0] = min(max(size, 1e-5), 1.0) * _HALF_PI
    cl[k, CL_P1] = min(max(smooth, 0.0), 1.0) * _HALF_PI


@device
def _intensity(max_angle, smooth, angle):
    if angle < max_angle:
        return 1.0
    if angle < max_angle + smooth and smooth != 0.0:
        return 1.0 - (angle - max_angle) / smooth
    return 0.0


@device
def _cone(cl, k):
    """(size, smooth, 1 - cos of the sampled cone's half angle) of closure k."""
    max_angle, smooth = cl[k, CL_P0], cl[k, CL_P1]
    half = min(max_angle + smooth, _HALF_PI)
    return max_angle, smooth, 2.0 * math.sin(0.5 * half) ** 2


@device
def _lobe(cl, k, cos_axis):
    """(f cos, pdf) of a direction at cosine ``cos_axis`` from the lobe's axis."""
    max_angle, smooth, omc = _cone(cl, k)
    angle = math.acos(saturate(cos_axis))
    if not angle < min(max_angle + smooth, _HALF_PI):
        return 0.0, 0.0
    pdf = uniform_cone_pdf(omc)
    return pdf * _intensity(max_angle, smooth, angle), pdf


@device
def diffuse_toon_eval(cl, k, wox, woy, woz, wix, wiy, wiz):
    """(f cos r, g, b, pdf): the lobe about the normal, towards wi above the surface."""
    if not wiz >= 0.0:
        return 0.0, 0.0, 0.0, 0.0
    f, pdf = _lobe(cl, k, wiz)
    return f, f, f, pdf


@device
def diffuse_toon_sample(cl, k, wox, woy, woz, u1, u2, u3):
    """(wix, wiy, wiz, r, g, b, pdf, label): uniform in the cone about the normal."""
    max_angle, smooth, omc = _cone(cl, k)
    x, y, z = uniform_cone(u1, u2, omc)
    if not z > 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
    pdf = uniform_cone_pdf(omc)
    f = pdf * _intensity(max_angle, smooth, safe_acos(z))
    return x, y, z, f, f, f, pdf, LABEL_REFLECT | LABEL_DIFFUSE


@device
def glossy_toon_eval(cl, k, wox, woy, woz, wix, wiy, wiz):
    """(f cos r, g, b, pdf): the lobe about the view reflected about the normal, both
    directions above the surface."""
    if not (woz > 0.0 and wiz > 0.0):
        return 0.0, 0.0, 0.0, 0.0
    f, pdf = _lobe(cl, k, -wox * wix - woy * wiy + woz * wiz)
    return f, f, f, pdf


@device
def glossy_toon_sample(cl, k, wox, woy, woz, u1, u2, u3):
    """(wix, wiy, wiz, r, g, b, pdf, label): uniform in the cone about the reflected view,
    kept above the surface."""
    if not woz > 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
    rx, ry, rz = -wox, -woy, woz
    max_angle, smooth, omc = _cone(cl, k)
    x, y, z = uniform_cone(u1, u2, omc)
    wx, wy, wz = around(rx, ry, rz, x, y, z)
    if not wz > 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
    pdf = uniform_cone_pdf(omc)
    f = pdf * _intensity(max_angle, smooth, safe_acos(z))
    return wx, wy, wz, f, f, f, pdf, LABEL_GLOSSY | LABEL_REFLECT
