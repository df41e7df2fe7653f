"""The Hair BSDF's lobes (closures/hair.py) against Cycles' formulas and closed forms.

Cycles' bsdf_hair.h, rewritten here in numpy from its C (acos, atan, cos exact where Cycles
uses its fast approximations), is the reference for evaluation at random directions,
strands and settings.  Every value is its own pdf; in the angle theta from the plane
normal to the strand the pdf is an inverted arctangent lobe of mass 1 over (-pi/2, pi/2),
so with the view in the plane of the normal and the strand (where the side tests and the
azimuth limits coincide) the evaluated pdf integrates over the sphere to sin(min(pi / (4
r2), pi / 2)) for reflection and to exactly 1 for transmission.  Sampling reports its own
pdf and weight 1; where Cycles' sampled pdf is the evaluated one (transmission; reflection
at RoughnessV 1) the two agree.
"""
import math

import numpy as np
import pytest

from mcengine.kernels.closures.layout import CT_HAIR_REFLECTION, CT_HAIR_TRANSMISSION

from .kernels import direction, evaluate, hair_row, sample

HALF_PI = 0.5 * math.pi


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def cycles_hair_eval(transmission, tangent, r1, r2, offset, wo, wi):
    """bsdf_hair_reflection_eval / _transmission_eval (N = +z), vectorised over wi."""
    r1, r2 = min(max(r1, 0.001), 1.0), min(max(r2, 0.001), 1.0)
    T = np.asarray(tangent, float)
    wo = np.asarray(wo, float)
    iz = T @ wo
    locy = _unit(wo - T * iz)
    theta_r = HALF_PI - math.acos(iz)
    wo_z = wi @ T
    wo_y = _unit(wi - np.outer(wo_z, T))
    theta_i = HALF_PI - np.arccos(np.clip(wo_z, -1, 1))
    cos_phi = np.clip(wo_y @ locy, -1, 1)
    a = math.atan(((HALF_PI + theta_r) * 0.5 - offset) / r1)
    b = math.atan(((-HALF_PI + theta_r) * 0.5 - offset) / r1)
    t = (theta_i + theta_r) * 0.5 - offset
    theta_pdf = r1 / (2 * (t * t + r1 * r1) * (a - b) * np.cos(theta_i))
    if transmission:
        p = math.pi - np.arccos(cos_phi)
        c_tt = 2 * math.atan(HALF_PI / r2)
        pdf = r2 / (c_tt * (p * p + r2 * r2)) * theta_pdf
        bad = (wi[:, 2] >= 0.0) | (HALF_PI - np.abs(theta_i) < 0.001)
    else:
        phi = np.minimum(np.arccos(cos_phi) / r2, math.pi)
        pdf = np.cos(phi * 0.5) * 0.25 / r2 * theta_pdf
        bad = (wi[:, 2] < 0.0) | (HALF_PI - np.abs(theta_i) < 0.001) | (cos_phi < 0.0)
    return np.where(bad, 0.0, pdf)


def _sphere_about(tangent, n_theta=1500, n_phi=1500):
    """Midpoint grid over the sphere in (theta from the plane normal to the strand, azimuth
    about it): directions and their solid angles."""
    T = np.asarray(tangent, float)
    e1 = np.array([0.0, 0.0, 1.0])
    e2 = np.cross(T, e1)
    th = (np.arange(n_theta) + 0.5) / n_theta * math.pi - HALF_PI
    ph = (np.arange(n_phi) + 0.5) / n_phi * 2 * math.pi - math.pi
    TH, PH = np.meshgrid(th, ph, indexing="ij")
    d = (np.sin(TH)[..., None] * T + (np.cos(TH) * np.cos(PH))[..., None] * e1
         + (np.cos(TH) * np.sin(PH))[..., None] * e2)
    dw = np.cos(TH) * (math.pi / n_theta) * (2 * math.pi / n_phi)
    return d.reshape(-1, 3), dw.ravel()


@pytest.mark.parametrize("ctype", [CT_HAIR_REFLECTION, CT_HAIR_TRANSMISSION])
@pytest.mark.parametrize("r1,r2,offset", [(0.2, 0.6, 0.0), (0.05, 1.0, 0.1), (1.0, 0.3, -0.2),
                                          (0.0, 0.0, 0.0), (3.0, 2.0, 0.3)])
def test_evaluation_is_cycles_formula(ctype, r1, r2, offset):
    rng = np.random.default_rng(11)
    transmission = ctype == CT_HAIR_TRANSMISSION
    for _ in range(4):
        tangent = _unit(rng.normal(size=3))
        wo = _unit(rng.normal(size=3) * (1, 1, 0.3) + (0, 0, 0.8))
        wi = _unit(rng.normal(size=(3000, 3)))
        cl = hair_row(ctype, tuple(tangent), r1, r2, offset)
        got = evaluate(cl, wo, wi)
        want = cycles_hair_eval(transmission, tangent, r1, r2, offset, wo, wi)
        np.testing.assert_allclose(got[:, 3], want, rtol=1e-9, atol=1e-12)
        np.testing.assert_array_equal(got[:, 0], got[:, 3])      # f cos = pdf
        if r2 >= 0.05:                 # (a narrower reflection lobe is all but a line)
            assert np.count_nonzero(want) > 100


@pytest.mark.parametrize("r2", [0.3, 0.5, 0.8, 1.0])
@pytest.mark.parametrize("theta", [0.0, 40.0, 80.0])
def test_evaluated_pdf_integrates_to_its_closed_form(r2, theta):
    wo = direction(theta)          # in the plane of the normal and the strand (+x)
    d, dw = _sphere_about((1.0, 0.0, 0.0))
    for ctype, expected in ((CT_HAIR_REFLECTION, math.sin(min(math.pi / (4 * r2), HALF_PI))),
                            (CT_HAIR_TRANSMISSION, 1.0)):
        cl = hair_row(ctype, (1.0, 0.0, 0.0), 0.15, r2, 0.05)
        total = float(evaluate(cl, wo, d)[:, 3] @ dw)
        assert total == pytest.approx(expected, abs=2e-3), (ctype, total, expected)


@pytest.mark.parametrize("ctype,r2", [(CT_HAIR_REFLECTION, 1.0), (CT_HAIR_TRANSMISSION, 0.4),
                                      (CT_HAIR_TRANSMISSION, 1.0)])
@pytest.mark.parametrize("theta", [0.0, 50.0, 85.0])
def test_sampling_weight_is_one_and_its_pdf_the_evaluated_one(ctype, r2, theta):
    wo = direction(theta)
    cl = hair_row(ctype, (1.0, 0.0, 0.0), 0.3, r2, 0.1)
    s = sample(cl, wo, 20000, seed=21)
    ok = s[:, 6] > 0
    assert ok.mean() > 0.99
    np.testing.assert_array_equal(s[ok, 3], s[ok, 6])          # weight exactly 1
    np.testing.assert_allclose(np.linalg.norm(s[ok, :3], axis=1), 1.0, rtol=1e-12)
    ev = evaluate(cl, wo, s[ok, :3])
    if ctype == CT_HAIR_REFLECTION:
        ok2 = ev[:, 3] > 0           # Cycles' evaluation drops azimuths beyond 90 degrees
        assert ok2.mean() > 0.4
        np.testing.assert_allclose(ev[ok2, 3], s[ok, 6][ok2], rtol=1e-7)
    else:
        assert np.all(s[ok, 2] < 0.0)
        np.testing.assert_allclose(ev[:, 3], s[ok, 6], rtol=1e-7)


def test_sampled_reflection_pdf_keeps_cycles_azimuth_term():
    """Cycles' sampled reflection reports cos(phi / 2) / (4 r2) in azimuth where its
    evaluation has cos(phi / (2 r2)) / (4 r2): kept, as it sets the MIS weights Cycles uses."""
    wo = direction(0.0)
    cl = hair_row(CT_HAIR_REFLECTION, (1.0, 0.0, 0.0), 0.3, 0.4, 0.0)
    s = sample(cl, wo, 2000, seed=3)
    s = s[s[:, 6] > 0]
    ev = evaluate(cl, wo, s[:, :3])[:, 3]
    phi = np.arctan2(-s[:, 1], s[:, 2])          # azimuth from locy = +z about the strand (+x)
    ratio = np.cos(phi / 2) / np.cos(phi / (2 * 0.4))
    keep = ev > 0
    np.testing.assert_allclose(s[keep, 6], ev[keep] * ratio[keep], rtol=1e-7)


@pytest.mark.parametrize("ctype", [CT_HAIR_REFLECTION, CT_HAIR_TRANSMISSION])
@pytest.mark.parametrize("tangent", [(0.0, 0.0, 1.0), (1.0, 0.0, 0.0), (0.0, 0.0, 0.0)])
@pytest.mark.parametrize("theta", [0.0, 89.99999, 90.0, 150.0])
def test_degenerate_strands_and_views_stay_finite(ctype, tangent, theta):
    for r1, r2 in ((0.0, 0.0), (1e-9, 5.0), (1.0, 1.0)):
        cl = hair_row(ctype, tangent, r1, r2, 0.3)
        s = sample(cl, direction(theta), 3000, seed=5)
        assert np.all(np.isfinite(s)) and np.all(s[:, 3:7] >= 0.0)
        wi = _unit(np.random.default_rng(1).normal(size=(2000, 3)))
        ev = evaluate(cl, direction(theta), wi)
        assert np.all(np.isfinite(ev)) and np.all(ev >= 0.0)
    # The view along the strand itself has no azimuth: nothing, not NaN.
    cl = hair_row(ctype, (0.0, 0.0, 1.0), 0.2, 0.5, 0.0)
    assert np.all(sample(cl, direction(0.0), 100, seed=2)[:, 3:7] == 0.0)


def test_the_effects_plan_names_hair_and_ray_portals():
    from mcengine.features import surface_kinds
    from mcengine.scene import Link, Material, ShaderNode
    for kind, name in (("BsdfHair", "hair"), ("BsdfRayPortal", "ray portal")):
        material = Material(nodes=[ShaderNode(kind, {}, {})], surface=Link(0, "BSDF"))
        assert surface_kinds(material) == {name}
