"""Cycles' bump shadowing term on closures whose normal differs from the smooth normal.

Closed forms from Cycles 5.0.1 (kernel/closure/bsdf.h, bump_shadowing_term): a closure
of normal N at a point of smooth normal Ns gets 0 towards wi when
(Ns.wi)(Ns.N)(N.wi) < 0 (on evaluation for every closure, on sampling for diffuse
ones), and a diffuse closure with Bump Map Correction is multiplied by the GGX
G1(alpha2, |Ns.wi|) = 2 / (1 + sqrt(1 + alpha2 tan^2)) with
alpha2 = min(tan^2(N, Ns) / 8, 1).  The pdf is not changed.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from mcengine.kernels.closures import closure_eval, closure_sample
from mcengine.kernels.closures.layout import (
    CL_BUMP_CORRECTION,
    CL_N,
    CL_NS,
    CL_T,
    CT_DIFFUSE,
    CT_MICROFACET,
    CT_TRANSLUCENT,
    LABEL_TRANSMIT,
)

from .kernels import diffuse_row, direction, microfacet_row

TILT = 35.0          # degrees between the mapped normal N and the smooth normal Ns = +z


def _tilted(cl, correction=True):
    """Row 0 with N tilted by TILT about y (towards +x), Ns = +z."""
    t = math.radians(TILT)
    cl[0, CL_N:CL_N + 3] = (math.sin(t), 0.0, math.cos(t))
    cl[0, CL_T:CL_T + 3] = (math.cos(t), 0.0, -math.sin(t))
    cl[0, CL_NS:CL_NS + 3] = (0.0, 0.0, 1.0)
    cl[0, CL_BUMP_CORRECTION] = 1.0 if correction else 0.0
    return cl


def _g1(cos_i):
    """Cycles' softening factor for the tilt TILT and |Ns.wi| = cos_i."""
    alpha2 = min(0.125 * math.tan(math.radians(TILT)) ** 2, 1.0)
    tan2 = 1.0 / cos_i ** 2 - 1.0
    return 2.0 / (1.0 + math.sqrt(1.0 + alpha2 * tan2))


def _eval(cl, wo, wi):
    return np.array(closure_eval(cl, 0, *wo, *wi))


WO = direction(20.0, 180.0)


@pytest.mark.parametrize("theta", [10.0, 60.0, 80.0, 88.0])
def test_diffuse_is_darkened_towards_grazing_light(theta):
    cl = _tilted(diffuse_row(CT_DIFFUSE))
    wi = direction(theta, 90.0)                  # above Ns and N, across the tilt
    n = cl[0, CL_N:CL_N + 3]
    cos_n = float(np.dot(n, wi))
    r, g, b, pdf = _eval(cl, WO, wi)
    assert pdf == pytest.approx(cos_n / math.pi, rel=1e-12)
    assert r == pytest.approx(cos_n / math.pi * _g1(math.cos(math.radians(theta))), rel=1e-9)
    assert r == g == b
    if theta >= 80.0:
        assert r < 0.9 * pdf                     # a visible darkening near the terminator


def test_without_bump_map_correction_diffuse_is_not_darkened():
    cl = _tilted(diffuse_row(CT_DIFFUSE), correction=False)
    wi = direction(80.0, 90.0)
    r, _, _, pdf = _eval(cl, WO, wi)
    assert r == pdf == pytest.approx(float(np.dot(cl[0, CL_N:CL_N + 3], wi)) / math.pi, rel=1e-12)


@pytest.mark.parametrize("row", [lambda: diffuse_row(CT_DIFFUSE),
                                 lambda: microfacet_row(CT_MICROFACET, alpha=0.6)],
                         ids=["diffuse", "glossy"])
def test_light_below_the_smooth_normal_is_rejected_on_evaluation(row):
    cl = _tilted(row())
    wi = direction(95.0, 0.0)                    # below Ns, above N (tilted towards +x)
    assert np.dot(cl[0, CL_N:CL_N + 3], wi) > 0.1
    assert tuple(_eval(cl, direction(30.0, 0.0), wi)) == (0.0, 0.0, 0.0, 0.0)


def test_glossy_is_not_darkened():
    cl = _tilted(microfacet_row(CT_MICROFACET, alpha=0.6))
    same = cl.copy()
    same[0, CL_NS:CL_NS + 3] = same[0, CL_N:CL_N + 3]   # no term at all
    wo, wi = direction(30.0, 180.0), direction(80.0, 90.0)
    assert np.array_equal(_eval(cl, wo, wi), _eval(same, wo, wi))


def _samples(cl, n=4000, seed=3):
    u = np.random.default_rng(seed).random((n, 3))
    return np.array([closure_sample(cl, 0, *WO, *row) for row in u])


def test_diffuse_samples_carry_the_term():
    cl = _tilted(diffuse_row(CT_DIFFUSE))
    s = _samples(cl)
    ok = s[:, 6] > 0.0
    wi, r, pdf = s[ok, :3], s[ok, 3], s[ok, 6]
    cos_s = wi[:, 2]
    below = cos_s < 0.0                          # under Ns while above N: rejected
    assert below.sum() > 100
    assert np.all(r[below] == 0.0)
    expect = pdf[~below] * np.array([_g1(c) for c in cos_s[~below]])
    np.testing.assert_allclose(r[~below], expect, rtol=1e-9)


def test_transmitted_samples_are_left_alone():
    cl = _tilted(diffuse_row(CT_TRANSLUCENT))
    s = _samples(cl)
    ok = s[:, 6] > 0.0
    assert np.all(s[ok, 7].astype(int) & LABEL_TRANSMIT)
    np.testing.assert_array_equal(s[ok, 3], s[ok, 6])
