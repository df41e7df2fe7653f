"""Rectangular area lights sampled by solid angle (kernels.lights: rect_solid_angle,
rect_sample_point), as Cycles samples them (area.h, after Urena et al. 2013).

The renders of test_lights_analytic.py check that the light arrives unbiased; these tests
check the sampler itself: its solid angle against a quadrature, its points against their
solid angles (Pearson chi-square), the pdf that a BSDF ray through the same point is
given for MIS (intersect_lamp), the fallback to area sampling, and the noise it removes.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit
from scipy.stats import chi2

from mcengine.kernels.lights import (
    L_AX,
    L_AY,
    L_AZ,
    L_POS,
    RECT_MIN_SOLID_ANGLE,
    intersect_lamp,
    pack_lights,
    rect_solid_angle,
    sample_lamp,
    spherical_rectangle,
    spread_window,
)
from mcengine.scene import Light

from .scenes import rotation_x, translation

SX, SY = 0.5, 0.3          # the lamp's size (m); it hangs at z = 2, tilted by 30 deg about x
TILT = math.radians(30.0)
CELLS = 8                  # chi-square cells per side of the window


def lamp_table(spread=math.pi) -> np.ndarray:
    m = translation(0.1, -0.2, 2.0) @ rotation_x(TILT)
    light = Light(type="AREA", matrix_world=m, strength=(10.0,) * 3, shape="RECTANGLE",
                  size_x=SX, size_y=SY, spread=spread)
    return pack_lights([light], 10.0)[0]


# Receivers, in the lamp's frame (x, y along its sides, t in front of it), nearer than
# RECT_NEAR = 2 half-diagonals (0.58 m) to its centre: below it, just beside it, to the
# side, nearly in its plane.
POINTS = {"below": (0.05, -0.03, 0.4), "near": (0.4, 0.1, 0.2), "side": (-0.45, 0.3, 0.1),
          "grazing": (0.5, 0.0, 0.01)}


def receiver(lamps, x, y, t) -> tuple:
    """The point (x, y, t) of the lamp's frame, in world coordinates."""
    r = lamps[0]
    return tuple(r[L_POS:L_POS + 3] + x * r[L_AX:L_AX + 3] + y * r[L_AY:L_AY + 3]
                 - t * r[L_AZ:L_AZ + 3])


_NO_IES = np.zeros(1)     # the lamp has no IES profile


@njit(cache=False)
def _draw(lamps, px, py, pz, u):
    """sample_lamp for each (u1, u2) row: (N, 8) of direction, distance, radiance (red),
    pdf, and the pdf and radiance (red) intersect_lamp gives the ray from p along it."""
    out = np.zeros((u.shape[0], 8))
    for k in range(u.shape[0]):
        wx, wy, wz, dist, lr, lg, lb, pdf = sample_lamp(lamps, _NO_IES, 0, px, py, pz, u[k, 0], u[k, 1])
        t, hr, hg, hb, hpdf = intersect_lamp(lamps, _NO_IES, 0, px, py, pz, wx, wy, wz, 1e30, px, py, pz)
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = wx, wy, wz, dist
        out[k, 4], out[k, 5], out[k, 6], out[k, 7] = lr, pdf, hpdf, hr
    return out


def local_points(lamps, p, draws):
    """The sampled points in the lamp's own coordinates (metres from its centre)."""
    q = np.asarray(p) + draws[:, :3] * draws[:, 3:4]
    rel = q - lamps[0, L_POS:L_POS + 3]
    return rel @ lamps[0, L_AX:L_AX + 3], rel @ lamps[0, L_AY:L_AY + 3], rel @ lamps[0, L_AZ:L_AZ + 3]


def solid_angle_by_quadrature(lamps, p, x0, x1, y0, y1, n=1500):
    """The integral of cos / d^2 over the window, by the midpoint rule."""
    u = (np.arange(n) + 0.5) / n
    x, y = np.meshgrid(x0 + u * (x1 - x0), y0 + u * (y1 - y0))
    q = (lamps[0, L_POS:L_POS + 3] + x[..., None] * lamps[0, L_AX:L_AX + 3]
         + y[..., None] * lamps[0, L_AY:L_AY + 3])
    d = q - np.asarray(p)
    d2 = (d * d).sum(-1)
    cos = np.abs(d @ lamps[0, L_AZ:L_AZ + 3]) / np.sqrt(d2)
    return float((cos / d2).mean() * (x1 - x0) * (y1 - y0))


@pytest.mark.parametrize("where", ["below", "near", "side", "grazing"])
def test_solid_angle_equals_the_quadrature(where):
    lamps = lamp_table()
    p = receiver(lamps, *POINTS[where])
    s = rect_solid_angle(lamps, 0, *p, -SX / 2, SX / 2, -SY / 2, SY / 2)[0]
    assert s > RECT_MIN_SOLID_ANGLE
    assert s == pytest.approx(solid_angle_by_quadrature(lamps, p, -SX / 2, SX / 2, -SY / 2, SY / 2),
                              rel=1e-5)


@pytest.mark.parametrize("where,spread_deg", [("below", 180.0), ("near", 180.0), ("side", 180.0),
                                              ("grazing", 180.0), ("below", 60.0)])
def test_points_are_uniform_in_solid_angle(where, spread_deg):
    """Pearson chi-square of the sampled points over an 8 x 8 grid of the window (the part
    of the lamp that can light p: with a 60 deg spread, a square of it), each cell
    expected in proportion to its solid angle; every pdf is 1 / S, and a ray from p along
    each sampled direction meets the lamp with that pdf and the same radiance."""
    lamps = lamp_table(math.radians(spread_deg))
    p = receiver(lamps, *POINTS[where])
    x0, x1, y0, y1, _ = spread_window(lamps, 0, *p)
    s = rect_solid_angle(lamps, 0, *p, x0, x1, y0, y1)[0]
    n = 200_000
    draws = _draw(lamps, *p, np.random.default_rng(7).random((n, 2)))
    lit = draws[:, 4] > 0.0           # (the window's corners lie outside a spread's circle)
    assert lit.all() if spread_deg == 180.0 else 0.5 < lit.mean() < 1.0
    np.testing.assert_allclose(draws[:, 5], 1.0 / s, rtol=1e-12)
    np.testing.assert_allclose(draws[:, 6], draws[:, 5], rtol=1e-9)
    np.testing.assert_allclose(draws[:, 7], draws[:, 4], rtol=1e-12)
    x, y, z = local_points(lamps, p, draws)
    assert np.abs(z).max() < 1e-9
    edges_x = np.linspace(x0, x1, CELLS + 1)
    edges_y = np.linspace(y0, y1, CELLS + 1)
    observed = np.histogram2d(x, y, bins=(edges_x, edges_y))[0]
    expected = np.array([[spherical_rectangle(lamps, 0, *p, edges_x[i], edges_x[i + 1], edges_y[j],
                                              edges_y[j + 1])[0] for j in range(CELLS)]
                         for i in range(CELLS)]) / s * n
    assert expected.sum() == pytest.approx(n, rel=1e-9)
    stat = float(((observed - expected) ** 2 / expected).sum())
    p_value = chi2.sf(stat, CELLS * CELLS - 1)
    print(f"{where}: S = {s:.4g} sr, chi2 = {stat:.1f}, p = {p_value:.3f}")
    assert p_value > 0.001


@pytest.mark.parametrize("where", ["far", "edge-on"])
def test_far_or_edge_on_lamps_are_sampled_by_area(where):
    """From 3 half-diagonals away (beyond RECT_NEAR), and from 1e-7 m in front of the
    lamp's plane, 0.25 m beside it (seen edge-on: RECT_MAX_NZ2), the lamp is sampled
    uniformly over its area, with the area pdf d^2 / (A cos), which intersect_lamp gives
    the same direction (to 1e-6: cos is 2e-7 there)."""
    lamps = lamp_table()
    p = receiver(lamps, *{"far": (0.3, 0.4, 0.7), "edge-on": (0.5, 0.0, 1e-7)}[where])
    assert rect_solid_angle(lamps, 0, *p, -SX / 2, SX / 2, -SY / 2, SY / 2)[0] == 0.0
    draws = _draw(lamps, *p, np.random.default_rng(8).random((20_000, 2)))
    assert (draws[:, 4] > 0.0).all()
    x, y, _ = local_points(lamps, p, draws)
    counts = np.histogram2d(x, y, bins=(np.linspace(-SX / 2, SX / 2, 5),
                                        np.linspace(-SY / 2, SY / 2, 5)))[0]
    assert chi2.sf(float(((counts - 1250.0) ** 2 / 1250.0).sum()), 15) > 0.001
    d2 = draws[:, 3] ** 2
    cos = draws[:, :3] @ lamps[0, L_AZ:L_AZ + 3]
    np.testing.assert_allclose(draws[:, 5], d2 / (SX * SY * cos), rtol=1e-6)
    np.testing.assert_allclose(draws[:, 6], draws[:, 5], rtol=1e-6)


def test_solid_angle_sampling_removes_the_noise_of_a_near_lamp():
    """Direct light at a point on a wall just beside the lamp (0.2 m from its edge, 0.1 m in
    front of its plane, facing it), where sampling by area is noisy (cos and 1 / d^2 vary
    over the lamp): the estimates L cos / pdf by solid angle keep only the receiver's
    cosine's spread, a relative variance under 0.01 (by area: 0.95), and their mean is the
    quadrature's irradiance."""
    lamps = lamp_table()
    p, n = receiver(lamps, 0.45, 0.0, 0.1), -lamps[0, L_AX:L_AX + 3]
    draws = _draw(lamps, *p, np.random.default_rng(9).random((100_000, 2)))
    est = draws[:, 4] * np.maximum(draws[:, :3] @ n, 0.0) / draws[:, 5]
    u = (np.arange(1500) + 0.5) / 1500
    x, y = np.meshgrid((u - 0.5) * SX, (u - 0.5) * SY)
    q = (lamps[0, L_POS:L_POS + 3] + x[..., None] * lamps[0, L_AX:L_AX + 3]
         + y[..., None] * lamps[0, L_AY:L_AY + 3])
    d = q - np.asarray(p)
    d2 = (d * d).sum(-1)
    w = d / np.sqrt(d2)[..., None]
    exact = float((draws[0, 4] * np.maximum(w @ n, 0.0) * np.maximum(w @ lamps[0, L_AZ:L_AZ + 3], 0.0)
                   / d2).mean() * SX * SY)
    print(f"relative variance {est.var() / est.mean() ** 2:.4f}")
    assert est.var() / est.mean() ** 2 < 0.01
    assert est.mean() == pytest.approx(exact, rel=4 * est.std() / est.mean() / math.sqrt(len(est)))
