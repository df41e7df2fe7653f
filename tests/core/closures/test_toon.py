"""The Toon BSDF's lobes (closures/toon.py) against closed forms.

Cycles' toon lobes have intensity 1 within Size (times pi/2) of their axis, falling
linearly to 0 over Smooth, and a value f cos equal to the intensity times the pdf of the
uniform cone they are sampled in.  So the albedo is the intensity's mean over that cone,
(1 / (1 - cos a)) * integral_0^a I(t) sin t dt, exactly 1 without Smooth; a glossy lobe seen
from straight above is the diffuse lobe; sampled weights are f cos / pdf.  Directions below
the surface and degenerate settings give no light and no NaN.
"""
import math

import numpy as np
import pytest
from scipy.integrate import quad

from mcengine.kernels.closures.layout import CT_DIFFUSE_TOON, CT_GLOSSY_TOON

from .kernels import direction, evaluate, sample, toon_row


def _albedo(size, smooth):
    """The closed form: the intensity's mean over the sampled cone."""
    m, s = min(max(size, 1e-5), 1.0) * math.pi / 2, min(max(smooth, 0.0), 1.0) * math.pi / 2
    a = min(m + s, math.pi / 2)

    def intensity(t):
        return 1.0 if t < m else (1.0 - (t - m) / s if (s > 0 and t < m + s) else 0.0)
    integral = quad(lambda t: intensity(t) * math.sin(t), 0.0, a, points=[m], limit=200)[0]
    return integral / (2.0 * math.sin(0.5 * a) ** 2)      # 1 - cos a, without cancellation


@pytest.mark.parametrize("size,smooth", [(0.5, 0.0), (0.3, 0.4), (0.9, 0.5), (0.05, 1.0), (0.0, 0.0)])
def test_diffuse_toon_albedo_is_the_mean_intensity_over_its_cone(size, smooth):
    cl = toon_row(CT_DIFFUSE_TOON, size, smooth)
    s = sample(cl, direction(30.0), 200_000, seed=7)
    ok = s[:, 6] > 0
    weights = np.where(ok, s[:, 3] / np.where(ok, s[:, 6], 1.0), 0.0)
    assert np.all(np.isfinite(s)) and np.all(weights >= 0.0) and np.all(weights <= 1.0 + 1e-12)
    expected = _albedo(size, smooth)
    if smooth == 0.0:
        assert weights.mean() == pytest.approx(1.0, abs=1e-12)    # every sample carries 1
    se = weights.std() / math.sqrt(len(weights))
    assert abs(weights.mean() - expected) <= 5 * se + 1e-9, (weights.mean(), expected, se)


def test_values_are_intensity_times_the_cone_pdf_and_match_sampling():
    cl = toon_row(CT_DIFFUSE_TOON, 0.4, 0.3)
    s = sample(cl, direction(20.0), 2000, seed=3)
    s = s[s[:, 6] > 0]
    ev = evaluate(cl, direction(20.0), s[:, :3])
    np.testing.assert_allclose(ev[:, 0], s[:, 3], rtol=1e-9)
    np.testing.assert_allclose(ev[:, 3], s[:, 6], rtol=1e-9)
    omc = 1.0 - math.cos(0.7 * math.pi / 2)
    np.testing.assert_allclose(s[:, 6], 1.0 / (2.0 * math.pi * omc), rtol=1e-9)


def test_a_glossy_lobe_seen_from_above_is_the_diffuse_lobe_and_follows_the_reflection():
    d = toon_row(CT_DIFFUSE_TOON, 0.3, 0.2)
    g = toon_row(CT_GLOSSY_TOON, 0.3, 0.2)
    wi = sample(d, direction(0.0), 500, seed=4)[:, :3]
    np.testing.assert_allclose(evaluate(g, direction(0.0), wi), evaluate(d, direction(0.0), wi),
                               rtol=1e-12)
    # Seen at 60 degrees, the lobe (45 degrees wide) is about the mirror direction, not the
    # normal (60 degrees from it).
    mirror = np.array([direction(60.0, 180.0)])
    normal = np.array([direction(0.0)])
    assert evaluate(g, direction(60.0), mirror)[0, 0] > 0.0
    assert evaluate(g, direction(60.0), normal)[0, 0] == 0.0


@pytest.mark.parametrize("ctype", [CT_DIFFUSE_TOON, CT_GLOSSY_TOON])
@pytest.mark.parametrize("size,smooth", [(0.0, 0.0), (1.0, 1.0), (1e-9, 0.0), (2.0, -1.0)])
@pytest.mark.parametrize("theta", [0.0, 60.0, 89.99999, 90.0, 120.0])
def test_degenerate_settings_and_grazing_views_stay_finite(ctype, size, smooth, theta):
    cl = toon_row(ctype, size, smooth)
    s = sample(cl, direction(theta), 4000, seed=5)
    assert np.all(np.isfinite(s)) and np.all(s[:, 3:7] >= 0.0)
    below = s[:, 6] > 0
    assert np.all(s[below, 2] > 0.0)                 # nothing below the surface
    wi = np.random.default_rng(1).normal(size=(2000, 3))
    ev = evaluate(cl, direction(theta), wi / np.linalg.norm(wi, axis=1)[:, None])
    assert np.all(np.isfinite(ev)) and np.all(ev >= 0.0)


@pytest.mark.parametrize("component,kind", [("DIFFUSE", "diffuse"), ("GLOSSY", "rough glossy")])
def test_the_effects_plan_counts_toon_as_diffuse_or_glossy(component, kind):
    from mcengine.features import surface_kinds
    from mcengine.scene import Link, Material, ShaderNode
    material = Material(nodes=[ShaderNode("BsdfToon", {}, {"component": component})],
                        surface=Link(0, "BSDF"))
    assert surface_kinds(material) == {kind}
