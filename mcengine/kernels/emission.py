"""Light leaving the lamps: where light tracing starts its paths.

Path tracing meets lights from the receiving end (``light_sampling``); light
tracing (``light_tracing``) starts paths *at* the lamps.  ``sample_emission``
picks a lamp in proportion to its power among the lamps light tracing
emits from, draws a point on it and a direction, and returns the path's first
weight, Le |cos| / (pick pmf x pdf of the point x pdf of the direction), in
Cycles' units (``lights``):

* point and spot lamps of radius 0: a point of intensity I (the lamp table's
  ``L_RADIANCE``) times the spot attenuation; directions uniform over the
  sphere, or over the cone that bounds the spot (``spot_cones``);
* area lamps: a uniform point on the rectangle or ellipse, a cosine-weighted
  direction about -Z, the radiance times the spread attenuation.

Lamps with a radius, suns, emissive triangles and the world are not emitted:
path tracing reaches their caustics from the receivers.
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from ..jit import device
from .light_sampling import pick_light
from .lights import (
    L_AREA,
    L_AX,
    L_AY,
    L_AZ,
    L_ELLIPSE,
    L_HALF_X,
    L_HALF_Y,
    L_POS,
    L_RADIANCE,
    L_SPOT_COS,
    L_SPOT_INV,
    L_TYPE,
    LT_AREA,
    LT_SPOT,
    area_spread,
    lamp_profile,
    spot_attenuation,
)
from .sampling import around, cosine_hemisphere, disk_concentric, uniform_cone

Emission = namedtuple("Emission", [
    "ok",                  # False: nothing emitted
    "idx",                 # the lamp's row
    "px", "py", "pz",      # the point on the lamp
    "dx", "dy", "dz",      # the unit direction of the emitted ray
    "br", "bg", "bb",      # Le |cos| / (pick pmf * pdf_pos * pdf_dir): the path's first weight
])


def emitter_distribution(power, emits) -> tuple[np.ndarray, np.ndarray]:
    """(cdf, pmf) over the lamps: in proportion to ``power`` among those that ``emits``
    says light tracing starts paths from; all zero if there is none."""
    pmf = np.where(np.asarray(emits, bool), np.abs(np.asarray(power, np.float64)), 0.0)
    total = pmf.sum()
    if not total > 0.0:
        return np.zeros(len(pmf) + 1), np.zeros(len(pmf))
    pmf /= total
    cdf = np.concatenate([[0.0], np.cumsum(pmf)])
    cdf[-1] = 1.0
    return cdf, pmf


def spot_cones(lamps) -> np.ndarray:
    """1 - cos of the half angle of a cone about each spot's axis that holds all its light
    (2: the whole sphere, for other lamps and for sheared spots).

    A spot's cone is elliptical under non-uniform object scale; its widest half angle
    has tan = tan(size / 2) * max(|x|, |y|) / |z| with x, y, z the scaled object axes
    (Cycles' cos_half_larger_spread).
    """
    out = np.full(len(lamps), 2.0)
    for i, row in enumerate(lamps):
        if int(row[L_TYPE]) != LT_SPOT:
            continue
        c = row[L_SPOT_COS]
        inv = row[L_SPOT_INV:L_SPOT_INV + 9].reshape(3, 3)
        if c <= 0.0 or abs(np.linalg.det(inv)) == 0.0:
            continue
        m = np.linalg.inv(inv)
        x, y, z = m[:, 0], m[:, 1], m[:, 2]
        unit = m / np.linalg.norm(m, axis=0)
        if max(abs(unit[:, 0] @ unit[:, 1]), abs(unit[:, 0] @ unit[:, 2]),
               abs(unit[:, 1] @ unit[:, 2])) > 1e-9:
            continue                                  # sheared: keep the sphere
        tan2 = (1.0 - c * c) / (c * c) * max(x @ x, y @ y) / (z @ z)
        root = math.sqrt(1.0 + tan2)
        out[i] = tan2 / (root * (root + 1.0))          # 1 - 1 / root, without cancellation
    return out


@device
def _none():
    return Emission(False, -1, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)


@device
def sample_emission(lamps, ies, emit_cdf, emit_pmf, cones, u_pick, u1, u2, u3, u4):
    """A lamp picked by power, a point on it and a direction (an :class:`Emission`), its
    power weighted by the lamp's IES profile along the direction."""
    if emit_cdf.shape[0] < 2 or not emit_cdf[emit_cdf.shape[0] - 1] > 0.0:
        return _none()
    idx = int(pick_light(emit_cdf, u_pick))
    pmf = emit_pmf[idx]
    if not pmf > 0.0:
        return _none()
    cx, cy, cz = lamps[idx, L_POS], lamps[idx, L_POS + 1], lamps[idx, L_POS + 2]
    if int(lamps[idx, L_TYPE]) == LT_AREA:
        area = lamps[idx, L_AREA]
        if not area > 0.0:
            return _none()
        if lamps[idx, L_ELLIPSE] > 0.0:
            a, b = disk_concentric(u1, u2)
        else:
            a, b = 2.0 * u1 - 1.0, 2.0 * u2 - 1.0
        hx, hy = lamps[idx, L_HALF_X], lamps[idx, L_HALF_Y]
        px = cx + a * hx * lamps[idx, L_AX] + b * hy * lamps[idx, L_AY]
        py = cy + a * hx * lamps[idx, L_AX + 1] + b * hy * lamps[idx, L_AY + 1]
        pz = cz + a * hx * lamps[idx, L_AX + 2] + b * hy * lamps[idx, L_AY + 2]
        x, y, z = cosine_hemisphere(u3, u4)
        if not z > 0.0:
            return _none()
        dx, dy, dz = around(-lamps[idx, L_AZ], -lamps[idx, L_AZ + 1], -lamps[idx, L_AZ + 2], x, y, z)
        k = area_spread(lamps, idx, z) * math.pi * area / pmf   # L cos / (pmf / A * cos / pi)
        k *= lamp_profile(lamps, ies, idx, dx, dy, dz)
        return Emission(True, idx, px, py, pz, dx, dy, dz, lamps[idx, L_RADIANCE] * k,
                        lamps[idx, L_RADIANCE + 1] * k, lamps[idx, L_RADIANCE + 2] * k)
    # A point: uniform directions over the sphere, or over the cone bounding the spot.
    omc = cones[idx]
    x, y, z = uniform_cone(u3, u4, omc)
    if omc < 2.0:
        dx, dy, dz = around(-lamps[idx, L_AZ], -lamps[idx, L_AZ + 1], -lamps[idx, L_AZ + 2], x, y, z)
    else:
        dx, dy, dz = x, y, z
    att = spot_attenuation(lamps, idx, dx, dy, dz) if int(lamps[idx, L_TYPE]) == LT_SPOT else 1.0
    k = att * 2.0 * math.pi * omc / pmf                      # I / (pmf * pdf_dir)
    k *= lamp_profile(lamps, ies, idx, dx, dy, dz)
    return Emission(True, idx, cx, cy, cz, dx, dy, dz, lamps[idx, L_RADIANCE] * k,
                    lamps[idx, L_RADIANCE + 1] * k, lamps[idx, L_RADIANCE + 2] * k)
