"""Fresnel equations and the models fitted to them (closures/fresnel.py)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from mcengine.kernels.closures.fresnel import (
    F0_from_ior,
    f82_B,
    f82_tint_B,
    fresnel_conductor,
    fresnel_conductor_Fss,
    fresnel_dielectric,
    fresnel_dielectric_Fss,
    fresnel_f82,
    fresnel_f82_Fss,
    generalized_schlick_s,
    ior_from_F0,
    schlick_weight,
)


def fresnel_textbook(c: float, eta: float) -> float:
    """Unpolarised reflectance from Snell's law and the s/p amplitudes (independent form)."""
    s2 = (1.0 - c * c) / (eta * eta)
    if s2 >= 1.0:
        return 1.0
    ct = math.sqrt(1.0 - s2)
    rs = (c - eta * ct) / (c + eta * ct)
    rp = (eta * c - ct) / (eta * c + ct)
    return 0.5 * (rs * rs + rp * rp)


def fresnel_g_form(c: float, eta: float) -> float:
    """The g = sqrt(eta^2 - 1 + c^2) form (Walter et al. 2007, eq. 22)."""
    g2 = eta * eta - 1.0 + c * c
    if g2 <= 0.0:
        return 1.0
    g = math.sqrt(g2)
    a = (g - c) / (g + c)
    b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0)
    return 0.5 * a * a * (1.0 + b * b)


@pytest.mark.parametrize("eta", [1.0001, 1.33, 1.5, 2.4, 10.0, 1 / 1.5, 0.5, 0.1])
def test_dielectric_matches_two_independent_forms(eta):
    for c in np.linspace(1e-6, 1.0, 301):
        f, cos_t = fresnel_dielectric(c, eta)
        assert f == pytest.approx(fresnel_g_form(c, eta), abs=1e-12)
        assert f == pytest.approx(fresnel_textbook(c, eta), abs=1e-9)
        assert 0.0 <= f <= 1.0
        if f < 1.0:   # Snell: sin_t = sin_i / eta
            assert math.sqrt(max(0.0, 1.0 - cos_t * cos_t)) == pytest.approx(math.sqrt(1.0 - c * c) / eta, abs=1e-7)
            assert cos_t <= 1.0
        assert fresnel_dielectric(-c, eta) == (f, cos_t)    # the sign of cos_i is ignored


def test_total_internal_reflection_boundary():
    eta = 1 / 1.5
    c_crit = math.sqrt(1.0 - eta * eta)
    assert fresnel_dielectric(c_crit * (1 - 1e-12), eta) == (1.0, 0.0)
    f, cos_t = fresnel_dielectric(c_crit * (1 + 1e-9), eta)
    assert 0.99 < f <= 1.0 and 0.0 < cos_t < 1e-3
    assert fresnel_dielectric(0.5, 1.0) == (0.0, 0.5)        # index-matched: no reflection
    assert fresnel_dielectric(0.0, 1.0)[0] == 1.0             # ...except exactly at grazing (as Cycles)


def test_f0_and_ior_round_trip():
    for ior in [1.0, 1.01, 1.33, 1.5, 2.0, 4.0, 10.0]:
        f0 = F0_from_ior(ior)
        assert f0 == pytest.approx(fresnel_dielectric(1.0, ior)[0], abs=1e-15)
        assert ior_from_F0(f0) == pytest.approx(ior, rel=1e-12)
    assert ior_from_F0(1.0) == pytest.approx(ior_from_F0(0.99))      # clamped at 0.99, as Cycles
    assert ior_from_F0(-1.0) == 1.0


def test_Fss_fit_is_close_to_the_integral():
    """Kulla-Conty's fit (Cycles' fresnel_dielectric_Fss) of the integral of 2 cos F: within
    0.007 for IOR 1..3 (it is 0.0065 low at 1.2 and 0.006 high at 3) and 0.001 for 1/3..1."""
    for eta in np.concatenate([np.linspace(1.0, 3.0, 21), 1.0 / np.linspace(1.05, 3.0, 21)]):
        exact = quad(lambda c: 2.0 * c * fresnel_textbook(c, eta), 0.0, 1.0, limit=200,
                     points=[math.sqrt(max(0.0, 1 - eta * eta))] if eta < 1 else None)[0]
        assert fresnel_dielectric_Fss(eta) == pytest.approx(exact, abs=7e-3 if eta > 1.0 else 1e-3), eta


def test_f82_tint():
    for f0 in [0.0, 0.04, 0.5, 0.9, 1.0]:
        assert f82_tint_B(f0, 1.0) == 0.0
        assert fresnel_f82(1.0, f0, 0.3) == pytest.approx(f0)                # B vanishes at normal incidence
        for tint in [0.0, 0.3, 0.7, 1.0]:
            b = f82_tint_B(f0, tint)
            schlick = f0 + (1 - f0) * schlick_weight(1 / 7)
            assert fresnel_f82(1 / 7, f0, b) == pytest.approx(min(1.0, max(0.0, schlick * tint)), abs=1e-12)
            assert f82_B(f0, schlick * tint) == pytest.approx(b, abs=1e-12)
            # Fss is the exact integral of 2 cos F when F stays in [0, 1]
            vals = [f0 + (1 - f0) * (1 - c) ** 5 - b * c * (1 - c) ** 6 for c in np.linspace(0, 1, 101)]
            if min(vals) >= 0.0 and max(vals) <= 1.0:
                exact = quad(lambda c: 2 * c * fresnel_f82(c, f0, b), 0, 1)[0]
                assert fresnel_f82_Fss(f0, b) == pytest.approx(exact, abs=1e-9)


def test_generalized_schlick():
    for eta in [1.2, 1.5, 3.0]:
        f0 = F0_from_ior(eta)
        for c in np.linspace(0.01, 1.0, 50):
            s, cos_t, tir = generalized_schlick_s(c, eta, -1.0)
            # exponent < 0 with F0 = F0(eta), F90 = 1 is the exact Fresnel
            assert f0 + (1 - f0) * s == pytest.approx(fresnel_dielectric(c, eta)[0], abs=1e-12)
            assert cos_t == fresnel_dielectric(c, eta)[1] and not tir
            s5, _, _ = generalized_schlick_s(c, eta, 5.0)
            assert s5 == pytest.approx((1 - c) ** 5, abs=1e-15)
    # eta < 1 uses the refracted cosine; past the critical angle the exponent form flags TIR
    s, cos_t, tir = generalized_schlick_s(0.9, 1 / 1.5, 5.0)
    assert not tir and s == pytest.approx((1 - cos_t) ** 5)
    assert generalized_schlick_s(0.1, 1 / 1.5, 5.0) == (1.0, 0.0, True)
    assert generalized_schlick_s(0.1, 1 / 1.5, -1.0)[0] == 1.0          # remapped: F = 1 -> s = 1


def _conductor_textbook(c: float, n: float, k: float) -> float:
    """Unpolarised reflectance of a conductor from complex Snell's law and the s/p amplitudes
    (Python complex arithmetic, an independent form)."""
    eta = complex(n, k)
    cos_t = np.sqrt(1.0 - (1.0 - c * c) / eta ** 2)
    rs = (c - eta * cos_t) / (c + eta * cos_t)
    rp = (eta * c - cos_t) / (eta * c + cos_t)
    return 0.5 * (abs(rs) ** 2 + abs(rp) ** 2)


# Complex IORs at R, G, B: gold and copper (the Metallic BSDF's presets' kind), aluminium, and
# a dielectric (k = 0).
CONDUCTORS = [(0.18, 3.42), (0.42, 2.35), (1.37, 1.77), (0.27, 3.61), (1.22, 7.0), (1.5, 0.0)]


@pytest.mark.parametrize("n, k", CONDUCTORS)
def test_conductor_fresnel(n, k):
    for c in [1.0, 0.999, 0.7, 0.3, 1 / 7, 0.01, 1e-7]:
        assert fresnel_conductor(c, n, k) == pytest.approx(_conductor_textbook(c, n, k), rel=1e-9, abs=1e-12)
    assert fresnel_conductor(1.0, n, k) == pytest.approx(((n - 1) ** 2 + k * k) / ((n + 1) ** 2 + k * k))
    assert fresnel_conductor(0.0, n, k) == pytest.approx(1.0)
    if k == 0.0:
        for c in [1.0, 0.5, 0.1]:
            assert fresnel_conductor(c, n, 0.0) == pytest.approx(fresnel_dielectric(c, n)[0], abs=1e-12)


@pytest.mark.parametrize("n, k", CONDUCTORS)
def test_conductor_Fss_is_the_f82_fit_of_the_average(n, k):
    """Cycles' estimate: the F82 model through F(1) and F(1/7), averaged exactly; it stays
    close to the true average 2 int cos F (measured: 0.0009 to 0.0030 off for the metals,
    0.009 for n 1.37 + 1.77i, 0.0101 for the dielectric)."""
    f0, f82 = fresnel_conductor(1.0, n, k), fresnel_conductor(1 / 7, n, k)
    assert fresnel_conductor_Fss(n, k) == pytest.approx(fresnel_f82_Fss(f0, f82_B(f0, f82)), abs=1e-12)
    exact = quad(lambda c: 2 * c * fresnel_conductor(c, n, k), 0, 1)[0]
    assert fresnel_conductor_Fss(n, k) == pytest.approx(exact, abs=0.012)
