"""Closures: how surfaces scatter light, in a local shading frame.

A material (``kernels.materials``) is a sum of weighted lobes, as Cycles'
closures are; this package evaluates and samples them.  One file per family
of lobes (``fresnel`` holds the interface equations they share); this module
holds the labels and the dispatch over a material's lobes.

Contract (Mitsuba's): directions are unit vectors in the local frame where the
shading normal is +z and faces the viewer; ``wo`` points to the viewer, ``wi``
to the light.  ``backfacing`` says the ray arrived from the inside of the
surface (relative to its winding), which inverts the index of refraction.

* ``bsdf_eval(mats, m, wo, wi, exclude)`` returns ``f * |cos(theta_i)|`` per
  channel of the non-singular lobes and the pdf with which ``bsdf_sample``
  would have produced ``wi`` (solid angle).  Lobes whose label is in
  ``exclude`` (a light's ray visibility) add nothing to f but still count in
  the pdf, as in Cycles;
* ``bsdf_sample(mats, m, wo, backfacing, u_lobe, u1, u2)`` picks a lobe in
  proportion to its average colour (Cycles' closure sample weight) and
  returns ``wi``, the weight ``f * |cos| / pdf`` (one-sample MIS over the
  non-singular lobes), the pdf (0 for a singular lobe) and the lobe label
  (``LABEL_*``), which the integrator uses for bounce counting, light
  visibility and MIS.
"""
from __future__ import annotations

import math

from ...jit import device
from ..materials import (
    M_BASE,
    M_GLASS,
    M_IOR,
    M_MIRROR,
    M_REFRACT,
    M_W_DIFFUSE,
    M_W_GLASS,
    M_W_MIRROR,
    M_W_REFRACT,
    M_W_TOTAL,
)
from ..sampling import cosine_hemisphere
from .fresnel import fresnel_dielectric

# Lobe labels (bit flags), as Cycles' LABEL_* (kernel/closure/bsdf.h).
LABEL_NONE = 0
LABEL_REFLECT = 1
LABEL_TRANSMIT = 2
LABEL_DIFFUSE = 4
LABEL_GLOSSY = 8
LABEL_SINGULAR = 16


@device
def bsdf_eval(mats, m, wox, woy, woz, wix, wiy, wiz, exclude):
    """(f*|cos| r, g, b, pdf) of the non-singular lobes for local wo, wi."""
    wd = mats[m, M_W_DIFFUSE]
    if wd <= 0.0 or woz <= 0.0 or wiz <= 0.0:
        return 0.0, 0.0, 0.0, 0.0
    cos_pi = wiz / math.pi
    pdf = wd / mats[m, M_W_TOTAL] * cos_pi
    if exclude & LABEL_DIFFUSE:
        return 0.0, 0.0, 0.0, pdf
    return mats[m, M_BASE] * cos_pi, mats[m, M_BASE + 1] * cos_pi, mats[m, M_BASE + 2] * cos_pi, pdf


@device
def bsdf_sample(mats, m, wox, woy, woz, backfacing, u_lobe, u1, u2):
    """(wix, wiy, wiz, weight r, g, b, pdf, label) for local wo (woz > 0)."""
    total = mats[m, M_W_TOTAL]
    if total <= 0.0 or woz <= 0.0:
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
    u = u_lobe * total
    wd = mats[m, M_W_DIFFUSE]
    if u < wd:
        x, y, z = cosine_hemisphere(u1, u2)
        if z <= 0.0:
            return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
        k = total / wd    # 1 / probability of picking the diffuse lobe
        return (x, y, z, mats[m, M_BASE] * k, mats[m, M_BASE + 1] * k, mats[m, M_BASE + 2] * k,
                z / math.pi / k, LABEL_REFLECT | LABEL_DIFFUSE)
    u -= wd
    wm = mats[m, M_W_MIRROR]
    if u < wm:
        k = total / wm
        return (-wox, -woy, woz, mats[m, M_MIRROR] * k, mats[m, M_MIRROR + 1] * k,
                mats[m, M_MIRROR + 2] * k, 0.0, LABEL_REFLECT | LABEL_SINGULAR)
    u -= wm
    eta = mats[m, M_IOR]
    if backfacing:
        eta = 1.0 / eta
    wg = mats[m, M_W_GLASS]
    if u < wg:
        k = total / wg
        f, cos_t = fresnel_dielectric(woz, eta)
        # Reflect with probability F, refract with 1 - F: the Fresnel factor
        # cancels and both carry the glass colour.
        if u1 < f:
            return (-wox, -woy, woz, mats[m, M_GLASS] * k, mats[m, M_GLASS + 1] * k,
                    mats[m, M_GLASS + 2] * k, 0.0, LABEL_REFLECT | LABEL_SINGULAR)
        return (-wox / eta, -woy / eta, -cos_t, mats[m, M_GLASS] * k, mats[m, M_GLASS + 1] * k,
                mats[m, M_GLASS + 2] * k, 0.0, LABEL_TRANSMIT | LABEL_SINGULAR)
    wr = mats[m, M_W_REFRACT]
    if wr <= 0.0:
        # Rounding carried u past the last lobe with weight: no sample.
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
    k = total / wr
    f, cos_t = fresnel_dielectric(woz, eta)
    if cos_t <= 0.0:
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE   # total internal reflection
    return (-wox / eta, -woy / eta, -cos_t, mats[m, M_REFRACT] * k, mats[m, M_REFRACT + 1] * k,
            mats[m, M_REFRACT + 2] * k, 0.0, LABEL_TRANSMIT | LABEL_SINGULAR)
