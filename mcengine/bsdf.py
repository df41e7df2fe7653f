"""BSDFs: how surfaces scatter light, in a local shading frame.

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

Materials are packed into one float64 table (``pack_materials``), a row per
material with the columns ``M_*``.  Functions take the table and a row index
(``mats, m``), not a row slice, which numba passes far more cheaply.

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


def material_features(table) -> dict:
    """Which lobe kinds occur in a packed material table."""
    return {"diffuse": bool(np.any(table[:, M_W_DIFFUSE] > 0)),
            "mirror": bool(np.any(table[:, M_W_MIRROR] > 0)),
            "glass": bool(np.any(table[:, M_W_GLASS] > 0)),
            "refraction": bool(np.any(table[:, M_W_REFRACT] > 0))}


@device
def bsdf_has_lobes(mats, m):
    return mats[m, M_W_TOTAL] > 0.0


@device
def bsdf_has_specular(mats, m):
    """True if the material has a mirror, glass or refraction lobe."""
    return mats[m, M_W_MIRROR] + mats[m, M_W_GLASS] + mats[m, M_W_REFRACT] > 0.0


@device
def fresnel_dielectric(cos_i, eta):
    """Unpolarised Fresnel reflectance and cos(theta_t) for relative IOR eta = n_t / n_i.

    Returns (F, cos_t) with F = 1 and cos_t = 0 under total internal reflection.
    """
    sin2_t = (1.0 - cos_i * cos_i) / (eta * eta)
    if sin2_t >= 1.0:
        return 1.0, 0.0
    cos_t = math.sqrt(1.0 - sin2_t)
    rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    return 0.5 * (rs * rs + rp * rp), cos_t


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
    k = total / mats[m, M_W_REFRACT]
    f, cos_t = fresnel_dielectric(woz, eta)
    if cos_t <= 0.0:
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE   # total internal reflection
    return (-wox / eta, -woy / eta, -cos_t, mats[m, M_REFRACT] * k, mats[m, M_REFRACT + 1] * k,
            mats[m, M_REFRACT + 2] * k, 0.0, LABEL_TRANSMIT | LABEL_SINGULAR)
