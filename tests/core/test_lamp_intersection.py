"""Rays against point lamps (kernels.lights.intersect_lamp): a lamp with a radius is a sphere,
or with Soft Falloff a disk through its centre facing the ray's origin (Cycles' point light).

Every ray is tested against every lamp it can hit, so the test rejects the lamps a ray
passes before any square root; these tests check that the rejection never drops a ray that
meets the lamp: rays aimed around the rim, inside and outside it, hit exactly where a direct
float64 test of the same shape says they do (rays within 10^-9 of the rim left out).
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit

from mcengine.kernels.lights import intersect_lamp, pack_lights
from mcengine.scene import Light

from .scenes import translation

CENTRE = np.array([0.3, -0.2, 1.5])
RADIUS = 0.1
_NO_IES = np.zeros(1)


@njit(cache=False)
def _hits(lamps, origins, directions):
    out = np.empty(origins.shape[0])
    for k in range(origins.shape[0]):
        o, d = origins[k], directions[k]
        out[k] = intersect_lamp(lamps, _NO_IES, 0, o[0], o[1], o[2], d[0], d[1], d[2], math.inf,
                                o[0], o[1], o[2])[0]
    return out


def _rays(n, rng):
    """Origins about 1 to 3 m from the lamp, each aimed at a point of the plane through the
    lamp's centre facing it, at a distance from the centre of ``RADIUS * s``: s in
    [0.5, 1.5] for most (around the rim), up to 100 for some (far misses), and some rays
    turned away from the lamp."""
    u = rng.normal(size=(n, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    origins = CENTRE + u * rng.uniform(1.0, 3.0, (n, 1))
    normal = (CENTRE - origins) / np.linalg.norm(CENTRE - origins, axis=1, keepdims=True)
    side = np.cross(normal, rng.normal(size=(n, 3)))
    side /= np.linalg.norm(side, axis=1, keepdims=True)
    s = np.where(rng.random(n) < 0.9, rng.uniform(0.5, 1.5, n), rng.uniform(1.5, 100.0, n))
    targets = CENTRE + side * (RADIUS * s)[:, None]
    directions = targets - origins
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    away = rng.random(n) < 0.1
    directions[away] *= -1.0
    return origins, directions, s, away


@pytest.mark.parametrize("soft_falloff", [False, True])
def test_rays_around_the_rim_hit_where_the_shape_says(soft_falloff):
    lamps = pack_lights([Light(type="POINT", matrix_world=translation(*CENTRE), strength=(10.0,) * 3,
                               radius=RADIUS, soft_falloff=soft_falloff)], 10.0)[0]
    rng = np.random.default_rng(5)
    origins, directions, s, away = _rays(20_000, rng)
    t = _hits(lamps, origins, directions)
    p = CENTRE - origins
    b = np.einsum("ij,ij->i", p, directions)
    d2 = np.einsum("ij,ij->i", p, p)
    if soft_falloff:       # the disk facing the origin: the point where the ray meets its plane
        cos_l = b / np.sqrt(d2)
        h = origins + directions * (np.sqrt(d2) / np.where(cos_l > 0, cos_l, 1.0))[:, None] - CENTRE
        miss_by = np.linalg.norm(h, axis=1) / RADIUS - 1.0
        expected = (cos_l > 0) & (miss_by < 0)
    else:                  # the sphere: the ray's closest approach to its centre
        miss_by = np.sqrt(np.maximum(d2 - b * b, 0.0)) / RADIUS - 1.0
        expected = (b > 0) & (miss_by < 0)
    clear = np.abs(miss_by) > 1e-9
    assert expected.sum() > 5000 and (~expected & ~away).sum() > 5000     # both sides of the rim
    np.testing.assert_array_equal(np.isfinite(t)[clear], expected[clear])
    assert np.all(t[np.isfinite(t)] > 0.0)
