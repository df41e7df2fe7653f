"""BSDFs: how surfaces scatter light, in a local shading frame.

Materials are packed into one float64 table (``pack_materials``), a row per
material with the columns ``M_*``.  The kernels dispatch on the lobes a row
enables, in this module only.  Functions take the table and a row index
(``mats, m``), not a row slice, which numba passes far more cheaply.

Contract (Mitsuba's): directions are unit vectors in the local frame where the
shading normal is +z; ``wo`` points to the viewer, ``wi`` to the light.

* ``bsdf_eval(mats, m, wo, wi, exclude)`` returns ``f * |cos(theta_i)|`` per
  channel and the pdf with which ``bsdf_sample`` would have produced ``wi``
  (solid angle).  Lobes whose label is in ``exclude`` (a light's ray
  visibility) add nothing to f but still count in the pdf, as in Cycles;
* ``bsdf_sample(mats, m, wo, u_lobe, u1, u2)`` returns ``wi``, the weight
  ``f * |cos| / pdf``, the pdf and the lobe label (``LABEL_*``), which the
  integrator uses for bounce counting and light visibility.

Lobes so far: Lambertian diffuse (reflectance ``base_color``, Cycles' Diffuse
BSDF at roughness 0 and Principled BSDF with Specular IOR Level 0), and
emission (handled by the integrator, not a lobe).  Glossy and transmissive
lobes plug in as new ``M_*`` columns, ``LABEL_*`` values and branches in the
three functions below; the integrator needs no change beyond the labels.
"""
from __future__ import annotations

import math

import numpy as np
from .jit import device

from .sampling import cosine_hemisphere

# Lobe labels (bit flags), as Cycles' LABEL_* (kernel/closure/bsdf.h).
LABEL_NONE = 0
LABEL_REFLECT = 1
LABEL_TRANSMIT = 2
LABEL_DIFFUSE = 4
LABEL_GLOSSY = 8
LABEL_SINGULAR = 16

# Material table columns.
M_BASE = 0           # 3: diffuse reflectance
M_EMISSION = 3       # 3: emitted radiance (two-sided)
M_DIFFUSE_WEIGHT = 6  # max channel of the diffuse reflectance (0: no diffuse lobe)
M_EMISSIVE = 7       # 1.0 if the material emits
MATERIAL_STRIDE = 8


def pack_materials(materials) -> np.ndarray:
    """(M, MATERIAL_STRIDE) float64 table from ``scene.Material`` objects."""
    table = np.zeros((max(len(materials), 1), MATERIAL_STRIDE))
    for i, m in enumerate(materials):
        base = np.clip(np.asarray(m.base_color, float), 0.0, None)
        emit = np.clip(np.asarray(m.emission, float), 0.0, None)
        table[i, M_BASE:M_BASE + 3] = base
        table[i, M_EMISSION:M_EMISSION + 3] = emit
        table[i, M_DIFFUSE_WEIGHT] = base.max()
        table[i, M_EMISSIVE] = 1.0 if emit.max() > 0.0 else 0.0
    return table


@device
def bsdf_has_lobes(mats, m):
    return mats[m, M_DIFFUSE_WEIGHT] > 0.0


@device
def bsdf_labels(mats, m):
    """Labels of all lobes of the material (what light visibility checks against)."""
    return LABEL_REFLECT | LABEL_DIFFUSE if mats[m, M_DIFFUSE_WEIGHT] > 0.0 else LABEL_NONE


@device
def bsdf_eval(mats, m, wox, woy, woz, wix, wiy, wiz, exclude):
    """(f*|cos| r, g, b, pdf) for local directions wo, wi."""
    if mats[m, M_DIFFUSE_WEIGHT] <= 0.0 or woz <= 0.0 or wiz <= 0.0:
        return 0.0, 0.0, 0.0, 0.0
    pdf = wiz / math.pi
    if exclude & LABEL_DIFFUSE:
        return 0.0, 0.0, 0.0, pdf
    return mats[m, M_BASE] * pdf, mats[m, M_BASE + 1] * pdf, mats[m, M_BASE + 2] * pdf, pdf


@device
def bsdf_sample(mats, m, wox, woy, woz, u_lobe, u1, u2):
    """(wix, wiy, wiz, weight r, g, b, pdf, label) for local wo."""
    if mats[m, M_DIFFUSE_WEIGHT] <= 0.0 or woz <= 0.0:
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
    x, y, z = cosine_hemisphere(u1, u2)
    if z <= 0.0:
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
    return x, y, z, mats[m, M_BASE], mats[m, M_BASE + 1], mats[m, M_BASE + 2], z / math.pi, LABEL_REFLECT | LABEL_DIFFUSE
