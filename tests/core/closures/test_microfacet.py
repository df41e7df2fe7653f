"""Microfacet closures (closures/microfacet.py): consistency, reciprocity, energy, setup, Cycles' values."""
from __future__ import annotations

import math

import numpy as np
import pytest

from mcengine.kernels.closures import microfacet as mf
from mcengine.kernels.closures.layout import (
    CL_AX,
    CL_AY,
    CL_ENERGY,
    CL_ETA,
    CL_F90,
    CL_SW,
    CL_W,
    CT_MICROFACET,
    CT_MICROFACET_GLASS,
    CT_MICROFACET_REFRACTION,
    FR_CONDUCTOR,
    FR_DIELECTRIC,
    FR_F82,
    FR_NONE,
    FR_SCHLICK,
    LABEL_GLOSSY,
    LABEL_NONE,
    LABEL_REFLECT,
    LABEL_SINGULAR,
    LABEL_TRANSMIT,
    MD_BECKMANN,
    MD_GGX,
)
from mcengine.kernels.closures.tables import TABLES_LOADED

from .kernels import direction, evaluate, microfacet_row, refraction_valid, sample

POINT_LIGHT = 1000.0 / (4.0 * math.pi * 2.0 ** 2)    # 1000 W point light at 2 m: L = weight eval P/(4 pi d^2)
needs_tables = pytest.mark.skipif(not TABLES_LOADED, reason="data/*.npy not generated yet")

ROWS = {
    "ggx-reflect": dict(alpha=0.2),
    "beckmann-reflect": dict(alpha=0.2, dist=MD_BECKMANN),
    "ggx-aniso": dict(alpha=0.05, alpha_y=0.4),
    "beckmann-aniso": dict(alpha=0.4, alpha_y=0.05, dist=MD_BECKMANN),
    "ggx-f82": dict(alpha=0.3, fresnel=FR_F82, f0=(0.9, 0.6, 0.3), f90=(0.2, 0.1, -0.1)),
    # gold's complex IOR: n in the F0 columns, k in the F90 ones
    "ggx-conductor": dict(alpha=0.3, fresnel=FR_CONDUCTOR, f0=(0.18, 0.42, 1.37), f90=(3.42, 2.35, 1.77)),
    "ggx-schlick": dict(alpha=0.3, fresnel=FR_SCHLICK, f0=(0.1, 0.2, 0.05), f90=(1, 1, 1), eta=1.45,
                        rtint=(1, 0.5, 0.8)),
    "ggx-schlick-exp5": dict(alpha=0.3, fresnel=FR_SCHLICK, f0=(0.1, 0.2, 0.05), f90=(1, 0.9, 1), exponent=5.0),
    "ggx-refract": dict(ctype=CT_MICROFACET_REFRACTION, alpha=0.3, eta=1.45),
    "ggx-refract-inv": dict(ctype=CT_MICROFACET_REFRACTION, alpha=0.3, eta=1 / 1.45),
    "beckmann-refract": dict(ctype=CT_MICROFACET_REFRACTION, alpha=0.3, eta=1.45, dist=MD_BECKMANN),
    "ggx-glass": dict(ctype=CT_MICROFACET_GLASS, alpha=0.2, eta=1.5, fresnel=FR_DIELECTRIC),
    "ggx-glass-inv": dict(ctype=CT_MICROFACET_GLASS, alpha=0.2, eta=1 / 1.5, fresnel=FR_DIELECTRIC),
    "ggx-glass-tinted": dict(ctype=CT_MICROFACET_GLASS, alpha=0.2, eta=1.5, fresnel=FR_SCHLICK,
                             f0=(0.04, 0.04, 0.04), rtint=(1, 1, 1), ttint=(0.9, 0.5, 0.2)),
    "beckmann-glass": dict(ctype=CT_MICROFACET_GLASS, alpha=0.5, eta=1.33, fresnel=FR_DIELECTRIC,
                           dist=MD_BECKMANN),
}


@pytest.mark.parametrize("name", list(ROWS))
@pytest.mark.parametrize("theta", [5.0, 50.0, 85.0])
def test_sample_returns_eval_at_its_direction(name, theta):
    cl = microfacet_row(**ROWS[name], energy=1.3)
    wo = direction(theta, 30.0)
    s = sample(cl, wo, 4000, 11)
    ok = s[:, 7] != LABEL_NONE
    assert ok.sum() >= 100      # (refraction out of glass at 85 degrees is mostly TIR)
    e = evaluate(cl, wo, s[ok, :3])
    np.testing.assert_allclose(e[:, :3], s[ok, 3:6], rtol=1e-7, atol=1e-12)
    np.testing.assert_allclose(e[:, 3], s[ok, 6], rtol=1e-7, atol=1e-12)
    assert np.allclose(np.linalg.norm(s[ok, :3], axis=1), 1.0, atol=1e-12)
    labels = s[ok, 7].astype(int)
    below = s[ok, 2] < 0.0
    assert np.all((labels & LABEL_TRANSMIT != 0) == below)
    assert np.all((labels & LABEL_REFLECT != 0) == ~below)
    assert np.all(labels & LABEL_GLOSSY != 0)
    assert np.all(s[~ok, 3:7] == 0.0)


@pytest.mark.parametrize("ctype, fresnel, eta", [(CT_MICROFACET, FR_NONE, 1.5), (CT_MICROFACET, FR_F82, 1.0),
                                                 (CT_MICROFACET_GLASS, FR_DIELECTRIC, 1.5),
                                                 (CT_MICROFACET_REFRACTION, FR_NONE, 1.5)])
def test_singular_lobes(ctype, fresnel, eta):
    """alpha_x alpha_y <= 2e-10: a delta lobe, sampled with pdf 0 and weight R/P_R or T/P_T,
    never evaluated."""
    cl = microfacet_row(ctype=ctype, fresnel=fresnel, eta=eta, alpha=1e-5, f0=(0.5, 0.7, 0.9), f90=(0, 0, 0),
                        energy=1.0)
    wo = direction(40.0, 20.0)
    s = sample(cl, wo, 2000, 3)
    assert np.all(s[:, 7].astype(int) & LABEL_SINGULAR) and np.all(s[:, 6] == 0.0)
    refl = (s[:, 7].astype(int) & LABEL_REFLECT) != 0
    np.testing.assert_allclose(s[refl, :3], np.tile([-wo[0], -wo[1], wo[2]], (refl.sum(), 1)), atol=1e-12)
    cos_t = math.sqrt(1 - (1 - wo[2] ** 2) / eta ** 2)
    np.testing.assert_allclose(s[~refl, :3], np.tile([-wo[0] / eta, -wo[1] / eta, -cos_t], ((~refl).sum(), 1)),
                               atol=1e-12)
    if fresnel == FR_F82:     # no transmission: P_R = 1, the weight is F82 at the view (B = 0 here)
        from mcengine.kernels.closures.fresnel import fresnel_f82
        expected = [fresnel_f82(wo[2], f0, 0.0) for f0 in (0.5, 0.7, 0.9)]
        np.testing.assert_allclose(s[:, 3:6], np.tile(expected, (2000, 1)), rtol=1e-12)
    else:        # white Fresnel: R/P_R = T/P_T = 1
        np.testing.assert_allclose(s[:, 3:6], 1.0, rtol=1e-12)
    if ctype == CT_MICROFACET_GLASS:          # reflects with probability F
        from mcengine.kernels.closures.fresnel import fresnel_dielectric
        f = fresnel_dielectric(wo[2], eta)[0]
        assert abs(refl.mean() - f) < 4 * math.sqrt(f * (1 - f) / 2000)
    assert np.all(evaluate(cl, wo, s[:, :3]) == 0.0)


def test_index_matched_refraction_is_singular():
    """A sampled refraction with |eta - 1| < 1e-4 passes straight through, weight T / P_T."""
    for eta in (1.0, 1.00005):
        cl = microfacet_row(ctype=CT_MICROFACET_GLASS, fresnel=FR_DIELECTRIC, eta=eta, alpha=0.25)
        wo = direction(30.0)
        s = sample(cl, wo, 500, 5)
        t = (s[:, 7].astype(int) & LABEL_TRANSMIT) != 0
        assert t.mean() > 0.95
        assert np.all(s[t, 7].astype(int) & LABEL_SINGULAR) and np.all(s[t, 6] == 0.0)
        np.testing.assert_allclose(s[t, :3], np.tile(-np.array(wo), (t.sum(), 1)), atol=3e-4)
        np.testing.assert_allclose(s[t, 3:6], 1.0, rtol=1e-9)


def _pairs(n, seed, lower=False):
    rng = np.random.default_rng(seed)
    v = rng.normal(size=(n, 2, 3))
    v /= np.linalg.norm(v, axis=2, keepdims=True)
    v[:, 0, 2] = np.abs(v[:, 0, 2])
    v[:, 1, 2] = -np.abs(v[:, 1, 2]) if lower else np.abs(v[:, 1, 2])
    return v[:, 0], v[:, 1]


@pytest.mark.parametrize("name", ["ggx-reflect", "beckmann-reflect", "ggx-aniso", "beckmann-aniso", "ggx-f82"])
def test_reflection_is_reciprocal(name):
    cl = microfacet_row(**ROWS[name])
    a, b = _pairs(300, 1)
    for wo, wi in zip(a, b):
        f_ab = evaluate(cl, wo, wi[None])[0, :3] / wi[2]
        f_ba = evaluate(cl, wi, wo[None])[0, :3] / wo[2]
        np.testing.assert_allclose(f_ab, f_ba, rtol=1e-9, atol=1e-300)


@pytest.mark.parametrize("dist", [MD_GGX, MD_BECKMANN])
@pytest.mark.parametrize("eta", [1.5, 1 / 1.33])
def test_refraction_obeys_generalized_reciprocity(dist, eta):
    """f(wo -> wi) / eta_i^2 = f(wi -> wo) / eta_o^2 across the interface: with the light
    inside (index eta) and the view outside, f_t(wo, wi; eta) = eta^2 f_t(wi', wo'; 1/eta)
    for the mirrored pair seen from the inside."""
    cl = microfacet_row(ctype=CT_MICROFACET_REFRACTION, alpha=0.3, eta=eta, dist=dist)
    cl_back = microfacet_row(ctype=CT_MICROFACET_REFRACTION, alpha=0.3, eta=1 / eta, dist=dist)
    a, b = _pairs(300, 2, lower=True)
    for wo, wi in zip(a, b):
        f = evaluate(cl, wo, wi[None])[0, 0] / -wi[2]
        wo2 = np.array([wi[0], wi[1], -wi[2]])          # the light's direction, seen from inside
        wi2 = np.array([wo[0], wo[1], -wo[2]])
        f2 = evaluate(cl_back, wo2, wi2[None])[0, 0] / -wi2[2]
        np.testing.assert_allclose(f, eta * eta * f2, rtol=1e-9, atol=1e-300)


def _furnace(cl, wo, n=1 << 17, seed=0):
    """Mean of f cos / pdf (or the singular weight) per channel, and its standard error."""
    s = sample(cl, wo, n, seed)
    w = np.zeros((n, 3))
    ok = s[:, 7] != LABEL_NONE
    sing = ok & ((s[:, 7].astype(int) & LABEL_SINGULAR) != 0)
    reg = ok & ~sing
    w[reg] = s[reg, 3:6] / s[reg, 6:7]
    w[sing] = s[sing, 3:6]
    return w.mean(axis=0), w.std(axis=0) / math.sqrt(n), w


@pytest.mark.parametrize("name", ["ggx-reflect", "beckmann-reflect", "ggx-aniso", "ggx-refract", "ggx-refract-inv",
                                  "beckmann-refract", "ggx-glass", "ggx-glass-inv", "beckmann-glass"])
def test_single_scattering_weights_never_exceed_one(name):
    """With a white Fresnel every sample's weight is G2/G1 <= 1 (R/P_R = T/P_T = 1 for
    glass): the albedo is at most 1 for every view, not just on average.  Beckmann's
    Lambda fit dips to -6e-5 just above its cut at alpha^2 tan^2 = 0.39, so there the
    weight may exceed 1 by 1e-4 (as in Cycles)."""
    cl = microfacet_row(**{k: v for k, v in ROWS[name].items() if k not in ("f0", "f90", "rtint", "ttint")})
    for theta in (0.0, 30.0, 60.0, 80.0, 89.5):
        mean, _, w = _furnace(cl, direction(theta, 10.0), n=1 << 14, seed=4)
        tol = 1e-4 if ROWS[name].get("dist") == MD_BECKMANN else 1e-12
        assert np.all(w <= 1.0 + tol) and np.all(w >= 0.0)
        assert np.all(mean <= 1.0 + tol)


def test_ggx_single_scattering_albedo_at_roughness_one():
    """Cycles measured a furnace of 0.3070 for GGX (no multiscatter) at roughness 1, F = 1,
    and an independent estimate of height-correlated GGX at mu = 1 gives 0.3071."""
    mean, err, _ = _furnace(microfacet_row(alpha=1.0), (0.0, 0.0, 1.0), n=1 << 18)
    assert abs(mean[0] - 0.3070) < 4 * err[0] + 2e-4


@needs_tables
@pytest.mark.parametrize("rough", [0.1, 0.3, 0.5, 0.77, 1.0])
@pytest.mark.parametrize("mu", [0.07, 0.4, 1.0])
def test_multiscatter_ggx_is_white(rough, mu):
    """Multiscatter GGX (Glossy, white): E(mu) x energy scale = 1 up to the tables'
    interpolation (Cycles measured 1.0006 for a metallic sphere at roughness 1)."""
    cl = microfacet_row(alpha=rough * rough)
    mf.microfacet_setup(cl, 0)
    mf.microfacet_setup_fresnel_constant(cl, 0, mu, 1.0, 1.0, 1.0)
    assert cl[0, CL_ENERGY] >= 1.0
    assert np.all(cl[0, CL_W:CL_W + 3] == 1.0)           # white: no darkening
    mean, err, _ = _furnace(cl, (math.sqrt(1 - mu * mu), 0.0, mu), n=1 << 16)
    assert abs(mean[0] - 1.0) < 4 * err[0] + 4e-3


@needs_tables
@pytest.mark.parametrize("eta", [1.5, 1 / 1.5, 1.1])
@pytest.mark.parametrize("rough", [0.2, 0.5, 1.0])
def test_multiscatter_glass_is_white(eta, rough):
    """Multiscatter GGX glass (Glass node, white): E_glass x energy scale = 1."""
    mu = 0.6
    cl = microfacet_row(ctype=CT_MICROFACET_GLASS, alpha=rough * rough, eta=eta, fresnel=FR_SCHLICK,
                        f0=(((eta - 1) / (eta + 1)) ** 2,) * 3, exponent=-eta)
    mf.microfacet_setup(cl, 0)
    mf.microfacet_setup_fresnel_schlick(cl, 0, mu, True)
    mean, err, _ = _furnace(cl, (math.sqrt(1 - mu * mu), 0.0, mu), n=1 << 16)
    assert abs(mean[0] - 1.0) < 4 * err[0] + 4e-3


def test_setup_clamps_alpha_and_makes_transmission_isotropic():
    cl = microfacet_row(alpha=1.7, alpha_y=-0.2)
    mf.microfacet_setup(cl, 0)
    assert (cl[0, CL_AX], cl[0, CL_AY], cl[0, CL_ENERGY]) == (1.0, 0.0, 1.0)
    for ctype in (CT_MICROFACET_GLASS, CT_MICROFACET_REFRACTION):
        cl = microfacet_row(ctype=ctype, alpha=0.3, alpha_y=0.1, energy=2.0)
        mf.microfacet_setup(cl, 0)
        assert (cl[0, CL_AX], cl[0, CL_AY], cl[0, CL_ENERGY]) == (0.3, 0.3, 1.0)


@needs_tables
def test_preserve_energy_darkening_is_kulla_conty():
    from mcengine.kernels.closures.fresnel import fresnel_f82_Fss
    mu = 0.8
    cl = microfacet_row(alpha=0.36, fresnel=FR_F82, f0=(0.9, 0.5, 0.2))
    cl[0, CL_W:CL_W + 3] = (0.5, 0.5, 0.5)
    mf.microfacet_setup(cl, 0)
    mf.microfacet_setup_fresnel_f82_tint(cl, 0, mu, 0.8, 1.0, 0.6, True)
    e, e_avg = mf.microfacet_albedo_tables(cl, 0, mu)
    assert cl[0, CL_ENERGY] == pytest.approx(1.0 / e)
    for c, f0 in enumerate((0.9, 0.5, 0.2)):
        fss = fresnel_f82_Fss(f0, cl[0, CL_F90 + c])
        fms = fss * e_avg / (1 - fss * (1 - e_avg))
        assert cl[0, CL_W + c] == pytest.approx(0.5 * (1 + fms * (1 - e) / e) * e)
    # a white tint leaves B = 0 exactly
    cl2 = microfacet_row(alpha=0.36, fresnel=FR_F82, f0=(0.9, 0.5, 0.2))
    mf.microfacet_setup_fresnel_f82_tint(cl2, 0, mu, 1.0, 1.0, 1.0, False)
    assert np.all(cl2[0, CL_F90:CL_F90 + 3] == 0.0) and cl2[0, CL_ENERGY] == 1.0


@needs_tables
@pytest.mark.parametrize("fss", [(0.5, 0.5, 0.5), (1.0, 1.0, 0.5), (0.3, 0.6, 0.6), (0.2, 0.7, 0.2),
                                 (0.9, 0.4, 0.1)])
def test_preserve_energy_darkens_each_channel_by_its_own_fss(fss):
    """Channels of equal Fss share one evaluation; each still gets Kulla-Conty's factor of
    its own Fss, and the sample weight their mean."""
    mu = 0.6
    cl = microfacet_row(alpha=0.3)
    cl[0, CL_W:CL_W + 3] = (0.5, 0.25, 1.0)
    cl[0, CL_SW] = 0.8
    mf.microfacet_preserve_energy(cl, 0, mu, *fss)
    e, e_avg = mf.microfacet_albedo_tables(cl, 0, mu)
    dark = [(1 + f * e_avg / (1 - f * (1 - e_avg)) * (1 - e) / e) * e for f in fss]
    assert cl[0, CL_W:CL_W + 3] == pytest.approx(np.array([0.5, 0.25, 1.0]) * dark, rel=1e-12)
    assert cl[0, CL_SW] == pytest.approx(0.8 * np.mean(dark), rel=1e-12)


@needs_tables
def test_albedo_estimate():
    """Cycles' bsdf_microfacet_estimate_albedo: tables for the Schlick/F82/dielectric
    reflection, smooth (1 - F) tint for the transmission; the sample weight follows it."""
    from mcengine.kernels.closures.fresnel import F0_from_ior, fresnel_dielectric
    from mcengine.kernels.closures.tables import GGX_GEN_SCHLICK_IOR_S, lookup_3d
    mu, eta = 0.5, 1.5
    cl = microfacet_row(ctype=CT_MICROFACET_GLASS, alpha=0.25, eta=eta, fresnel=FR_DIELECTRIC)
    r, g, b = mf.microfacet_albedo(cl, 0, mu, True, True)
    s = lookup_3d(GGX_GEN_SCHLICK_IOR_S, 0.5, mu, math.sqrt(0.5 / 2.5))
    f0 = F0_from_ior(eta)
    assert r == pytest.approx(f0 + (1 - f0) * s + 1 - fresnel_dielectric(mu, eta)[0])
    assert mf.microfacet_albedo(cl, 0, mu, True, False)[0] == pytest.approx(f0 + (1 - f0) * s)
    assert mf.microfacet_albedo(cl, 0, mu, False, True)[0] == pytest.approx(1 - fresnel_dielectric(mu, eta)[0])
    mf.microfacet_setup_sample_weight(cl, 0, mu)
    assert cl[0, CL_SW] == pytest.approx(r)
    # the estimate of the reflection is close to its real albedo (the tables ignore G2/G1)
    refl = microfacet_row(alpha=0.25, eta=eta, fresnel=FR_SCHLICK, f0=(f0,) * 3, exponent=-eta,
                          ttint=(0, 0, 0))
    mean, _, _ = _furnace(refl, (math.sqrt(1 - mu * mu), 0, mu), n=1 << 15)
    est = mf.microfacet_albedo(refl, 0, mu, True, True)[0]
    assert est == pytest.approx(mean[0] / mf.microfacet_albedo_tables(refl, 0, mu)[0], rel=0.05)


@needs_tables
@pytest.mark.parametrize("f0, rtint, mu", [
    ((0.04, 0.04, 0.04), (1.0, 1.0, 1.0), 0.5),    # the Principled's specular layer: the table
    ((0.0, 0.3, 0.1), (1.0, 0.0, 1.0), 0.3),       # one channel without F0, one without tint
    ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0), 0.5),       # F0 = 0: the smooth reflection is s > 0
    ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0), 1.0),       # ... and exactly 0 at normal incidence
    ((0.04, 0.04, 0.04), (0.0, 0.0, 0.0), 0.5),    # no tint: no reflection
])
@pytest.mark.parametrize("ctype, transmission", [(CT_MICROFACET, True), (CT_MICROFACET_GLASS, False)])
def test_albedo_estimate_of_a_reflection_without_its_smooth_fresnel(f0, rtint, mu, ctype, transmission):
    """``microfacet_albedo`` skips the smooth Fresnel where it would discard it (FR_SCHLICK,
    exponent < 0, reflection only); the result is still Cycles': nothing where the smooth
    reflection is zero in every channel, else the table's mix(F0, F90, s) x tint."""
    from mcengine.kernels.closures.fresnel import F0_from_ior, fresnel_dielectric
    from mcengine.kernels.closures.tables import GGX_GEN_SCHLICK_IOR_S, lookup_3d
    eta = 1.5
    cl = microfacet_row(ctype=ctype, alpha=0.25, eta=eta, fresnel=FR_SCHLICK, f0=f0, exponent=-eta,
                        rtint=rtint, ttint=(0.0, 0.0, 0.0) if ctype == CT_MICROFACET else (1.0, 1.0, 1.0))
    f0_eta = F0_from_ior(eta)
    s_smooth = min(max((fresnel_dielectric(mu, eta)[0] - f0_eta) / (1.0 - f0_eta), 0.0), 1.0)
    smooth = [(f + (1.0 - f) * s_smooth) * t for f, t in zip(f0, rtint)]
    s = lookup_3d(GGX_GEN_SCHLICK_IOR_S, 0.5, mu, math.sqrt(0.5 / 2.5))
    expected = [0.0] * 3 if not any(smooth) else [(f + (1.0 - f) * s) * t for f, t in zip(f0, rtint)]
    assert mf.microfacet_albedo(cl, 0, mu, True, transmission) == pytest.approx(expected, rel=1e-12, abs=0)


# -- Cycles' measured values -----------------------------------------------------------------------
# cycles-closures.md section 10: a 1000 W point light at 2 m, orthographic camera on the normal.
@pytest.mark.parametrize("row, light, cycles", [
    (dict(alpha=0.25), direction(40.0), 3.30223),                                  # Glossy GGX r .5
    (dict(alpha=0.25, dist=MD_BECKMANN), direction(40.0), 3.90105),                # Glossy Beckmann r .5
    (dict(alpha=0.125, alpha_y=0.5), direction(20.0, 0.0), 3.01124),               # aniso .5, light along +X
    (dict(alpha=0.125, alpha_y=0.5), direction(20.0, 90.0), 21.12715),             # ... along +Y
    (dict(alpha=0.25 / math.sqrt(0.55), alpha_y=0.25 * math.sqrt(0.55), fresnel=FR_F82, f0=(1, 1, 1)),
     direction(20.0, 0.0), 16.53987),                                              # Principled metallic aniso .5
    (dict(alpha=0.25 / math.sqrt(0.55), alpha_y=0.25 * math.sqrt(0.55), fresnel=FR_F82, f0=(1, 1, 1)),
     direction(20.0, 90.0), 7.41664),
])
def test_cycles_measured_point_light_values(row, light, cycles):
    """These renders used plain GGX (no energy scale); the Glossy node's Fresnel is 1 and the
    metallic's F82 with F0 = 1 is 1 too.  Cycles renders in float32: 1e-4."""
    cl = microfacet_row(**row)
    value = evaluate(cl, (0.0, 0.0, 1.0), np.array([light]))[0, 0] * POINT_LIGHT
    assert value == pytest.approx(cycles, rel=1e-4)


def test_cycles_evaluates_refraction_no_microfacet_produces():
    """Measured with bpy 5.0.1 (Cycles CPU): a plane at z = 0 with a Glass BSDF (GGX, IOR 1.5,
    white), an orthographic camera on +z, a 1000 W point light of radius 0 at 2 m below the
    plane at angle theta from +z, max bounces 0, 16 samples, 4 x 4 pixels.  At 120 and 100
    degrees no microfacet refracts the view towards the light (the refraction needs the
    light within 48.2 degrees of -z), yet Cycles lights the plane: its eval has no validity
    check and ours mirrors it.  Ratios to the 140 degree render (a valid pair) remove the
    light's units and Cycles' sample-0 quirk (its first sample of each pixel adds nothing
    through transmission, 63/64 of the value at 16 samples)."""
    cycles = {(140, 0.5): 0.06218060338869691, (120, 0.5): 0.04703716281801462,
              (100, 0.5): 0.11406806949526072, (120, 1.0): 0.48972091637551785}
    wo = (0.0, 0.0, 1.0)

    def value(theta, rough):
        cl = microfacet_row(ctype=CT_MICROFACET_GLASS, fresnel=FR_DIELECTRIC, eta=1.5, alpha=rough * rough)
        return evaluate(cl, wo, np.array([direction(theta)]))[0, 0]

    ref = value(140, 0.5)
    assert ref * POINT_LIGHT * 63 / 64 == pytest.approx(cycles[(140, 0.5)], rel=2e-4)
    for (theta, rough), measured in cycles.items():
        assert value(theta, rough) / ref == pytest.approx(measured / cycles[(140, 0.5)], rel=2e-4)
        assert refraction_valid(1.5, wo, np.array([direction(theta)]))[0] == (theta == 140)


def test_eta_row_value_is_used_as_given():
    """CL_ETA is inside / outside as the caller sets it (1/IOR on back faces): eta and 1/eta
    give different refractions."""
    a = microfacet_row(ctype=CT_MICROFACET_REFRACTION, alpha=0.1, eta=1.5)
    b = microfacet_row(ctype=CT_MICROFACET_REFRACTION, alpha=0.1, eta=1 / 1.5)
    assert a[0, CL_ETA] != b[0, CL_ETA]
    sa = sample(a, direction(20.0), 10, 1)
    sb = sample(b, direction(20.0), 10, 1)
    assert not np.allclose(sa[:, :3], sb[:, :3])
