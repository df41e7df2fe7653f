"""Lambert, translucent and Oren-Nayar closures (closures/diffuse.py)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from mcengine.kernels.closures.diffuse import oren_nayar_G
from mcengine.kernels.closures.layout import (
    CL_P0,
    CL_P1,
    CL_P2,
    CT_DIFFUSE,
    CT_TRANSLUCENT,
    LABEL_DIFFUSE,
    LABEL_NONE,
    LABEL_REFLECT,
    LABEL_TRANSMIT,
)

from .kernels import diffuse_row, direction, evaluate, oren_nayar_row, sample

POINT_LIGHT = 1000.0 / (4.0 * math.pi * 2.0 ** 2)


@pytest.mark.parametrize("ctype, label, sign", [(CT_DIFFUSE, LABEL_REFLECT | LABEL_DIFFUSE, 1.0),
                                                (CT_TRANSLUCENT, LABEL_TRANSMIT | LABEL_DIFFUSE, -1.0)])
def test_lambert_and_translucent(ctype, label, sign):
    cl = diffuse_row(ctype)
    wo = direction(35.0, 10.0)
    s = sample(cl, wo, 20000, 1)
    assert np.all(s[:, 7] == label)
    assert np.all(sign * s[:, 2] > 0.0)
    np.testing.assert_allclose(s[:, 3:7], np.repeat(sign * s[:, 2:3] / math.pi, 4, axis=1), rtol=1e-14)
    np.testing.assert_allclose(evaluate(cl, wo, s[:, :3]), s[:, 3:7], rtol=1e-14)
    # white furnace: the weight is exactly 1
    np.testing.assert_allclose(s[:, 3] / s[:, 6], 1.0, rtol=1e-14)
    # nothing on the other side; the view's side is not looked at (as Cycles)
    assert np.all(evaluate(cl, wo, np.array([[0.0, 0.0, -sign]])) == 0.0)
    assert evaluate(cl, (0.3, 0.0, -0.95), np.array([[0.0, 0.0, sign]]))[0, 3] == pytest.approx(1 / math.pi)


def test_oren_nayar_at_zero_roughness_is_lambert():
    cl = oren_nayar_row(0.0, (0.8, 0.8, 0.8), cos_no=0.7)
    assert cl[0, CL_P1] == 0.0 and cl[0, CL_P0] == pytest.approx(1 / math.pi)
    wi = np.array([direction(t, p) for t, p in [(10, 0), (50, 120), (85, 200)]])
    e = evaluate(cl, direction(45.0), wi)
    np.testing.assert_allclose(e, np.repeat(wi[:, 2:3] / math.pi, 4, axis=1), rtol=1e-14)


@pytest.mark.parametrize("mu", [1e-7, 0.01, 0.3, 0.7, 1.0])
@pytest.mark.parametrize("sigma", [0.3, 1.0])
def test_oren_nayar_directional_albedo_is_pi_A_plus_B_G(mu, sigma):
    """The single-scattering albedo of Fujii's model, integrated numerically, is pi A + B G(mu)."""
    cl = oren_nayar_row(sigma, (0.0, 0.0, 0.0), cos_no=mu)      # black: no multiple scattering
    a, b = cl[0, CL_P0], cl[0, CL_P1]
    wo = (math.sqrt(1 - mu * mu), 0.0, mu)

    x, w = np.polynomial.legendre.leggauss(200)
    cos_t = 0.5 * (x + 1.0)
    phi = (np.arange(600) + 0.5) * (2 * math.pi / 600)
    s = np.sqrt(1 - cos_t ** 2)[:, None]
    dirs = np.stack(np.broadcast_arrays(s * np.cos(phi), s * np.sin(phi), cos_t[:, None]), -1).reshape(-1, 3)
    f = evaluate(cl, wo, dirs)[:, 0].reshape(200, 600)
    e = (f.sum(axis=1) * (2 * math.pi / 600) * 0.5 * w).sum()
    assert e == pytest.approx(math.pi * a + b * oren_nayar_G(mu), abs=2e-5)


@pytest.mark.parametrize("sigma", [0.2, 0.5, 1.0])
@pytest.mark.parametrize("rho", [1.0, 0.8, 0.3])
@pytest.mark.parametrize("theta", [0.0, 60.0, 89.0])
def test_oren_nayar_furnace(sigma, rho, theta):
    """With the OpenPBR term the albedo (before the weight rho) is
    E(mu) + rho^2 E_avg (1 - E(mu)) / (1 - rho (1 - E_avg)), exactly 1 when rho = 1
    (Cycles measured 1.0000 for a white Diffuse BSDF at roughness 1)."""
    wo = direction(theta, 0.0)
    cl = oren_nayar_row(sigma, (rho,) * 3, cos_no=wo[2])
    a, b = cl[0, CL_P0], cl[0, CL_P1]
    e_mu = math.pi * a + b * oren_nayar_G(wo[2])
    e_avg = math.pi * a + (2 * math.pi - 5.6) / 3 * b
    expected = e_mu + rho * rho * e_avg * (1 - e_mu) / (1 - rho * (1 - e_avg))
    n = 1 << 17
    s = sample(cl, wo, n, 8)
    assert np.all(s[:, 7] == LABEL_REFLECT | LABEL_DIFFUSE)
    w = s[:, 3] / s[:, 6]
    assert abs(w.mean() - expected) < 4 * w.std() / math.sqrt(n) + 1e-4
    if rho == 1.0:
        assert expected == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(evaluate(cl, wo, s[:, :3]), s[:, 3:7], rtol=1e-12)


def test_oren_nayar_is_reciprocal():
    """f(wo, wi) = f(wi, wo) when the multiple-scattering factor is set up for each view."""
    rng = np.random.default_rng(3)
    for _ in range(200):
        v = rng.normal(size=(2, 3))
        v /= np.linalg.norm(v, axis=1, keepdims=True)
        v[:, 2] = np.abs(v[:, 2])
        wo, wi = v
        sigma = rng.uniform(0.05, 1.0)
        c1 = oren_nayar_row(sigma, (0.7, 0.4, 0.9), cos_no=wo[2])
        c2 = oren_nayar_row(sigma, (0.7, 0.4, 0.9), cos_no=wi[2])
        f12 = evaluate(c1, wo, wi[None])[0, :3] / wi[2]
        f21 = evaluate(c2, wi, wo[None])[0, :3] / wo[2]
        np.testing.assert_allclose(f12, f21, rtol=1e-9)


def test_oren_nayar_G_near_grazing():
    """Below mu = 1e-6 Cycles' first-order form pi/2 - 2/3 - mu; it joins the exact form."""
    assert oren_nayar_G(0.0) == pytest.approx(math.pi / 2 - 2 / 3)
    assert oren_nayar_G(0.999999e-6) == pytest.approx(oren_nayar_G(1.000001e-6), abs=1e-6)
    assert oren_nayar_G(1.0) == pytest.approx(0.0, abs=1e-7)
    assert math.isfinite(oren_nayar_G(1e-300))


@pytest.mark.parametrize("sigma, light_phi, cycles", [(1.0, 0.0, 3.90095), (0.5, 180.0, 1.66860)])
def test_cycles_measured_oren_nayar(sigma, light_phi, cycles):
    """cycles-closures.md section 10: Diffuse BSDF colour .8, view at 45 degrees, a 1000 W
    point light at 2 m and 60 degrees on the view's side (phi 0) or the opposite one."""
    wo = direction(45.0, 0.0)
    cl = oren_nayar_row(sigma, (0.8,) * 3, cos_no=wo[2])
    value = 0.8 * evaluate(cl, wo, np.array([direction(60.0, light_phi)]))[0, 0] * POINT_LIGHT
    assert value == pytest.approx(cycles, rel=1e-4)


def test_samples_below_the_disk_edge_are_rejected():
    """u on the unit disk's rim gives cos = 0: no sample rather than a zero pdf."""
    for cl in (diffuse_row(), diffuse_row(CT_TRANSLUCENT), oren_nayar_row(0.5)):
        out = sample(cl, (0.0, 0.0, 1.0), 4, 0)
        assert np.all(out[:, 6] > 0.0)
        from .kernels import sample_batch
        u = np.array([[1.0, 0.5, 0.5], [0.5, 1.0, 0.5]])
        res = np.empty((2, 8))
        sample_batch(cl, 0.0, 0.0, 1.0, u, res)
        assert np.all(res[:, 7] == LABEL_NONE) and np.all(res[:, 3:7] == 0.0)
        assert cl[0, CL_P2] >= 0.0
