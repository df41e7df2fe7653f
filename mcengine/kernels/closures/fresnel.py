"""Fresnel equations: the share of light an interface reflects, and the models Cycles fits to it.

All functions are scalar (one colour channel); ``eta`` is the relative index of refraction
n_t / n_i across the interface (below 1 when leaving a denser medium).

* ``fresnel_dielectric`` is the exact unpolarised reflectance of a smooth dielectric
  interface, as the average of the s- and p-polarised reflectances of
  ``fresnel_dielectric_polarized`` (their signed amplitudes, as Cycles' function of that
  name), with the cosine of the refracted direction;
* ``F0_from_ior``/``ior_from_F0`` convert between the IOR and the reflectance at normal
  incidence; ``fresnel_dielectric_Fss`` is Kulla and Conty's fit of its cosine-weighted
  hemispherical average (the single-scattering Fresnel of energy compensation);
* the F82-tint conductor model (Kutz et al., "Novel aspects of the Adobe Standard
  Material"): Schlick's curve minus ``B cos (1 - cos)^6``, with B chosen from a tint of
  the value at cos = 1/7 (about 82 degrees);
* the conductor Fresnel of a complex IOR n + ik (``fresnel_conductor``: Born and Wolf's
  s- and p-polarised reflectances of ``fresnel_conductor_polarized``, averaged, as Cycles'
  ``fresnel_conductor``), and its average through the F82 model fitted at cos = 1 and 1/7
  (``fresnel_conductor_Fss``);
* the generalized Schlick model: the interpolation factor s between F0 and F90, either
  ``(1 - cos)^exponent`` or, for a negative exponent, the exact dielectric Fresnel
  remapped from [F0(eta), 1] to [0, 1] (what every Blender 5.0 node uses).
"""
from __future__ import annotations

import math

from ...jit import device


@device
def fresnel_dielectric_polarized(cos_i, eta):
    """(r_s, r_p, cos_t): the s- and p-polarised amplitude ratios of a dielectric interface of
    relative IOR eta = n_t / n_i, and the cosine of the refracted direction.

    ``cos_i`` is the cosine between the incident direction and the normal; its sign is
    ignored (Cycles takes |cos_i| too).  The amplitudes carry their sign (a phase shift of 0
    or pi on reflection, which thin films need); their squares are the reflectances.
    cos_t >= 0 is the refracted cosine on the far side.  Under total internal reflection
    (when eta^2 - 1 + cos_i^2 <= 0, exactly Cycles' test): (1, 1, 0).
    """
    c = abs(cos_i)
    eta_cos_t_sq = eta * eta - 1.0 + c * c    # (eta cos_t)^2, without cancellation near grazing
    if eta_cos_t_sq <= 0.0:
        return 1.0, 1.0, 0.0
    eta_cos_t = math.sqrt(eta_cos_t_sq)
    r_s = (c - eta_cos_t) / (c + eta_cos_t)
    r_p = (eta * eta * c - eta_cos_t) / (eta * eta * c + eta_cos_t)
    return r_s, r_p, min(eta_cos_t / eta, 1.0)


@device
def fresnel_dielectric(cos_i, eta):
    """Unpolarised Fresnel reflectance and cos(theta_t) for relative IOR eta = n_t / n_i.

    Returns (F, cos_t), F the mean of the s- and p-polarised reflectances of
    ``fresnel_dielectric_polarized``: F = 1, cos_t = 0 under total internal reflection.
    """
    r_s, r_p, cos_t = fresnel_dielectric_polarized(cos_i, eta)
    return 0.5 * (r_s * r_s + r_p * r_p), cos_t


@device
def F0_from_ior(ior):
    """Reflectance at normal incidence of a dielectric: ((ior - 1) / (ior + 1))^2."""
    r = (ior - 1.0) / (ior + 1.0)
    return r * r


@device
def ior_from_F0(f0):
    """The IOR whose normal-incidence reflectance is f0 (f0 clamped to [0, 0.99], as Cycles)."""
    s = math.sqrt(min(max(f0, 0.0), 0.99))
    return (1.0 + s) / (1.0 - s)


@device
def fresnel_dielectric_Fss(eta):
    """Average single-scattering Fresnel, the integral of 2 cos F(cos, eta) over cos in [0, 1].

    Kulla and Conty's polynomial/rational fit ("Revisiting Physically Based Shading at
    Imageworks"), the one Cycles' ``fresnel_dielectric_Fss`` uses, for eta below and above 1.
    """
    if eta < 1.0:
        return 0.997118 + eta * (0.1014 - eta * (0.965241 + eta * 0.130607))
    return (eta - 1.0) / (4.08567 + 1.00071 * eta)


@device
def schlick_weight(cos_i):
    """(1 - cos)^5, with 1 - cos clamped to [0, 1]."""
    m = min(max(1.0 - cos_i, 0.0), 1.0)
    m2 = m * m
    return m2 * m2 * m


# Schlick's curve at cos = 1/7, where the F82 model puts its tint: (6/7)^5 and (6/7)^6.
_F82_S5 = (6.0 / 7.0) ** 5
_F82_S6 = (6.0 / 7.0) ** 6


@device
def fresnel_f82(cos_i, f0, b):
    """F82 conductor reflectance: clamp(Schlick(f0, cos) - b cos (1 - cos)^6, 0, 1)."""
    s = min(max(1.0 - cos_i, 0.0), 1.0)
    s5 = s * s * s * s * s
    f = f0 + (1.0 - f0) * s5 - b * cos_i * s5 * s
    return min(max(f, 0.0), 1.0)


@device
def f82_tint_B(f0, tint):
    """The B term of the F82 model that makes F(1/7) = Schlick(f0, 1/7) * tint.

    Solving Schlick(1/7) - B (1/7)(6/7)^6 = Schlick(1/7) tint gives
    B = 7 Schlick(1/7) (1 - tint) / (6/7)^6 (Cycles' ``fresnel_f82tint_B``); B = 0 at tint 1.
    """
    f_schlick = f0 + (1.0 - f0) * _F82_S5
    return f_schlick * (7.0 / _F82_S6) * (1.0 - tint)


@device
def f82_B(f0, f82):
    """The B term of the F82 model from the reflectance ``f82`` wanted at cos = 1/7."""
    f_schlick = f0 + (1.0 - f0) * _F82_S5
    return (7.0 / _F82_S6) * (f_schlick - f82)


@device
def fresnel_f82_Fss(f0, b):
    """Average single-scattering F82 reflectance, integral of 2 cos F over cos in [0, 1].

    Exact for the unclamped model: 2 int c (1-c)^5 dc = 1/21 and 2 int c^2 (1-c)^6 dc = 1/126.
    """
    return f0 + (1.0 - f0) * (1.0 / 21.0) - b * (1.0 / 126.0)


@device
def generalized_schlick_s(cos_i, eta, exponent):
    """Interpolation factor s of the generalized Schlick model F = mix(F0, F90, s).

    Returns (s, cos_t, tir).  For ``exponent < 0`` (Principled, Glass), s is the exact
    dielectric Fresnel of ``eta`` remapped from [F0(eta), 1] to [0, 1] and clamped; total
    internal reflection gives s = 1 (F = F90) and is not flagged.  For ``exponent >= 0``,
    s = (1 - cos)^exponent with the cosine on the side of the lower IOR (the refracted one
    when eta < 1); there total internal reflection is flagged (tir = True, s = 1), as
    Cycles then returns the reflection tint alone.  cos_t >= 0 is the refracted cosine
    (0 under total internal reflection).
    """
    c = abs(cos_i)
    if exponent < 0.0:
        f_real, cos_t = fresnel_dielectric(c, eta)
        f0 = F0_from_ior(eta)
        s = (f_real - f0) / (1.0 - f0)
        return min(max(s, 0.0), 1.0), cos_t, False
    cos_t_sq = 1.0 - (1.0 - c * c) / (eta * eta)
    if cos_t_sq <= 0.0:
        return 1.0, 0.0, True
    cos_t = math.sqrt(cos_t_sq)
    angle = cos_t if eta < 1.0 else c
    return (1.0 - angle) ** exponent, cos_t, False


@device
def fresnel_conductor_polarized(cos_i, eta_i, n, k):
    """(R_s, R_p, u, v) of a conductor of complex IOR n + ik under a dielectric of IOR eta_i,
    at incidence cosine cos_i (Born and Wolf; Cycles' fresnel_conductor_polarized).

    R_s and R_p are the s- and p-polarised reflectances; u + iv = sqrt((n + ik)^2 -
    eta_i^2 sin^2 theta_i), the complex refracted cosine times n + ik, from which thin films
    take the phase of the reflected waves.
    """
    c = min(cos_i, 1.0)
    n2, k2 = n * n, k * k
    t1 = n2 - k2 - eta_i * eta_i * (1.0 - c * c)
    t2 = math.sqrt(t1 * t1 + 4.0 * n2 * k2)
    u = math.sqrt(max(0.5 * (t2 + t1), 0.0))
    v = math.sqrt(max(0.5 * (t2 - t1), 0.0))
    ec = eta_i * c
    den = (ec + u) * (ec + u) + v * v
    r_s = ((ec - u) * (ec - u) + v * v) / den if den != 0.0 else 0.0
    t3 = (n2 - k2) * c
    t4 = 2.0 * n * k * c
    den = (t3 + eta_i * u) * (t3 + eta_i * u) + (t4 + eta_i * v) * (t4 + eta_i * v)
    r_p = (((t3 - eta_i * u) * (t3 - eta_i * u) + (t4 - eta_i * v) * (t4 - eta_i * v)) / den
           if den != 0.0 else 0.0)
    return r_s, r_p, u, v


@device
def fresnel_conductor(cos_i, n, k):
    """Unpolarised reflectance of a conductor of complex IOR n + ik seen from a medium of
    IOR 1, at incidence cosine cos_i (Cycles' fresnel_conductor_polarized, averaged)."""
    r_s, r_p, _, _ = fresnel_conductor_polarized(cos_i, 1.0, n, k)
    return 0.5 * (r_s + r_p)


@device
def fresnel_conductor_Fss(n, k):
    """Average single-scattering reflectance of a conductor, as Cycles estimates it: the F82
    model through its values at cos = 1 and 1/7, averaged exactly (clamped to [0, 1])."""
    f0 = fresnel_conductor(1.0, n, k)
    b = f82_B(f0, fresnel_conductor(1.0 / 7.0, n, k))
    return min(max(fresnel_f82_Fss(f0, b), 0.0), 1.0)
