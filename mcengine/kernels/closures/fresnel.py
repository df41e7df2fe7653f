"""Fresnel equations: the share of light a smooth interface reflects."""
from __future__ import annotations

import math

from ...jit import device


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
