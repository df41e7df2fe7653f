"""The material table: one row of float64 columns per material, read by the closures.

A material is a sum of closures, as in Cycles: a Lambertian diffuse lobe and
three singular (perfectly sharp) lobes, each with its own colour weight:

* diffuse     ``base_color``        Diffuse BSDF (roughness 0), Principled with
                                    Specular IOR Level 0
* mirror      ``mirror_color``      Glossy BSDF at roughness 0 (F = 1: the colour
                                    is the reflectance)
* glass       ``glass_color``, IOR  Glass BSDF at roughness 0: exact dielectric
                                    Fresnel; the colour tints reflection and
                                    refraction alike (kernel/closure/bsdf_microfacet.h)
* refraction  ``refraction_color``  Refraction BSDF at roughness 0: refraction
                                    only, no Fresnel reflection

``pack_materials`` builds the table, a row per material with the columns
``M_*``.  Kernel functions take the table and a row index (``mats, m``), not a
row slice, which numba passes far more cheaply.
"""
from __future__ import annotations

import numpy as np

from ..jit import device

# Material table columns.
M_BASE = 0           # 3: diffuse reflectance
M_EMISSION = 3       # 3: emitted radiance (two-sided)
M_MIRROR = 6         # 3: mirror reflectance
M_GLASS = 9          # 3: glass tint
M_REFRACT = 12       # 3: refraction tint
M_IOR = 15           # index of refraction of glass and refraction lobes
M_W_DIFFUSE = 16     # lobe sample weights: average colour of each lobe
M_W_MIRROR = 17
M_W_GLASS = 18
M_W_REFRACT = 19
M_W_TOTAL = 20       # sum of the sample weights (0: the material does not scatter)
M_EMISSIVE = 21      # 1.0 if the material emits
MATERIAL_STRIDE = 22


def _color(value) -> np.ndarray:
    return np.clip(np.asarray(value, float).reshape(3), 0.0, None)


def pack_materials(materials) -> np.ndarray:
    """(M, MATERIAL_STRIDE) float64 table from ``scene.Material`` objects."""
    table = np.zeros((max(len(materials), 1), MATERIAL_STRIDE))
    for i, m in enumerate(materials):
        row = table[i]
        lobes = ((M_BASE, M_W_DIFFUSE, m.base_color), (M_MIRROR, M_W_MIRROR, m.mirror_color),
                 (M_GLASS, M_W_GLASS, m.glass_color), (M_REFRACT, M_W_REFRACT, m.refraction_color))
        for col, wcol, value in lobes:
            c = _color(value)
            row[col:col + 3] = c
            row[wcol] = c.mean()
        row[M_W_TOTAL] = row[M_W_DIFFUSE] + row[M_W_MIRROR] + row[M_W_GLASS] + row[M_W_REFRACT]
        row[M_IOR] = float(m.ior)
        emit = _color(m.emission)
        row[M_EMISSION:M_EMISSION + 3] = emit
        row[M_EMISSIVE] = 1.0 if emit.max() > 0.0 else 0.0
    return table


@device
def bsdf_has_lobes(mats, m):
    return mats[m, M_W_TOTAL] > 0.0
