"""Chi-square goodness of fit of every closure sampler against the pdf its eval returns.

144 cases (the Sidak correction in ``chi2.ALPHA_SIDAK`` is over all of them, alpha = 0.01
overall): Lambert, translucent and Oren-Nayar; GGX and Beckmann reflection, refraction and
glass at eta 1.5 and 1/1.5; anisotropic GGX; GGX glass under a 400 nm thin film (coloured
reflectance: the lobe is picked by its average); views at 0, 45 and 89 degrees; roughness
0.05, 0.3 and 1 (alpha = roughness^2); Ashikhmin-Shirley (isotropic and anisotropic), the
Ashikhmin velvet, the Toon BSDF's two lobes and the Hair BSDF's two (the view in the plane of
the normal and the strand).  2^18 samples each, numpy Generator seeds fixed.
A representative subset runs by default, the whole grid with ``-m slow``.

Two properties of Cycles' pdf that are not properties of its sampler are accounted for,
and tested on their own below:

* Beckmann pdfs use Walter's rational fit of Smith's Lambda, while the visible-normal
  sampler draws the exact distribution: the sampler is tested against the pdf rescaled by
  (1 + Lambda_fit(wo)) / (1 + Lambda_exact(wo)), which the fit keeps within 0.32 %;
* refraction eval (and pdf) is not zero for light directions no microfacet can refract
  into (see ``microfacet_refraction_valid``), which the sampler never produces: those
  directions count as pdf 0 here.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import erfc

from mcengine.kernels.closures.layout import (
    CT_ASHIKHMIN_SHIRLEY,
    CT_DIFFUSE,
    CT_DIFFUSE_TOON,
    CT_GLOSSY_TOON,
    CT_HAIR_REFLECTION,
    CT_HAIR_TRANSMISSION,
    CT_MICROFACET,
    CT_MICROFACET_GLASS,
    CT_MICROFACET_REFRACTION,
    CT_OREN_NAYAR,
    CT_TRANSLUCENT,
    CT_VELVET,
    FR_DIELECTRIC,
    FR_NONE,
    FR_SCHLICK,
    MD_BECKMANN,
    MD_GGX,
)

from . import chi2
from .kernels import (
    ashikhmin_shirley_row,
    diffuse_row,
    direction,
    hair_row,
    microfacet_row,
    oren_nayar_row,
    toon_row,
    velvet_row,
)

N_SAMPLES = 1 << 18
THETAS = (0.0, 45.0, 89.0)
ROUGHNESS = (0.05, 0.3, 1.0)


def beckmann_lambda_exact(q: float) -> float:
    """Smith Lambda of the Beckmann distribution, q = alpha^2 tan^2(theta)."""
    if q <= 0.0:
        return 0.0
    a = 1.0 / math.sqrt(q)
    return 0.5 * (math.exp(-a * a) / (a * math.sqrt(math.pi)) - erfc(a))


def beckmann_lambda_fit(q: float) -> float:
    if q < 0.39:
        return 0.0
    a = 1.0 / math.sqrt(q)
    return ((0.396 * a - 1.259) * a + 1.0) / ((2.181 * a + 3.535) * a)


def beckmann_exact_scale(ax: float, ay: float, wo) -> float:
    """pdf_exact / pdf_Cycles = (1 + Lambda_fit(wo)) / (1 + Lambda_exact(wo))."""
    q = ((ax * wo[0]) ** 2 + (ay * wo[1]) ** 2) / wo[2] ** 2
    return (1.0 + beckmann_lambda_fit(q)) / (1.0 + beckmann_lambda_exact(q))


def _case_list():
    cases = []
    for theta in THETAS:
        cases.append(("lambert", dict(ctype=CT_DIFFUSE), theta, 0.0))
        cases.append(("translucent", dict(ctype=CT_TRANSLUCENT), theta, 0.0))
        for sigma in (0.5, 1.0):
            cases.append((f"oren_nayar-s{sigma}", dict(ctype=CT_OREN_NAYAR, sigma=sigma), theta, 0.0))
    for dist, dname in ((MD_GGX, "ggx"), (MD_BECKMANN, "beckmann")):
        for r in ROUGHNESS:
            for theta in THETAS:
                cases.append((f"{dname}-reflect-r{r}", dict(ctype=CT_MICROFACET, dist=dist, alpha=r * r), theta, 0.0))
                for eta in (1.5, 1.0 / 1.5):
                    for ctype, fresnel, tname in ((CT_MICROFACET_REFRACTION, FR_NONE, "refract"),
                                                  (CT_MICROFACET_GLASS, FR_DIELECTRIC, "glass")):
                        cases.append((f"{dname}-{tname}-r{r}-eta{eta:.3f}",
                                      dict(ctype=ctype, dist=dist, alpha=r * r, eta=eta, fresnel=fresnel),
                                      theta, 0.0))
    # anisotropic GGX: Glossy node anisotropy 0.5 at roughness 0.3 and 0.7, view azimuth 0 and 60
    for r in (0.3, 0.7):
        a = r * r
        for theta in THETAS:
            for phi in (0.0, 60.0):
                cases.append((f"ggx-aniso-r{r}", dict(ctype=CT_MICROFACET, dist=MD_GGX, alpha=a * 0.5,
                                                      alpha_y=a / 0.5), theta, phi))
    # Ashikhmin-Shirley (the Glossy node's): isotropic at roughness 0.3 and 1, anisotropic
    # (anisotropy 0.5 at roughness 0.5, view azimuth 60); the Ashikhmin velvet at roughness 0.5
    for theta in THETAS:
        for r in (0.3, 1.0):
            cases.append((f"ashikhmin-shirley-r{r}", dict(ctype=CT_ASHIKHMIN_SHIRLEY, alpha=r * r),
                          theta, 0.0))
        cases.append(("ashikhmin-shirley-aniso-r0.5", dict(ctype=CT_ASHIKHMIN_SHIRLEY, alpha=0.125,
                                                            alpha_y=0.5), theta, 60.0))
        cases.append(("velvet-r0.5", dict(ctype=CT_VELVET, sigma=0.5), theta, 0.0))
    # the Toon BSDF: diffuse (size 0.5, smooth 0.2) and glossy (size 0.2, smooth 0.1, its cone
    # about the reflected view cut by the horizon at grazing views)
    for theta in THETAS:
        cases.append(("toon-diffuse", dict(ctype=CT_DIFFUSE_TOON, size=0.5, smooth=0.2), theta, 0.0))
        cases.append(("toon-glossy", dict(ctype=CT_GLOSSY_TOON, size=0.2, smooth=0.1), theta, 0.0))
    # the Hair BSDF along +x, the view in the plane of the normal and the strand (where
    # Cycles' sampling and evaluation describe the same density: reflection up to
    # RoughnessV 0.5, transmission at any)
    for theta in THETAS:
        cases.append(("hair-reflection", dict(ctype=CT_HAIR_REFLECTION, r1=0.2, r2=0.45, offset=0.1),
                      theta, 0.0))
        cases.append(("hair-transmission", dict(ctype=CT_HAIR_TRANSMISSION, r1=0.3, r2=0.7,
                                                offset=-0.1), theta, 0.0))
    # GGX glass under a thin film (the Glass node's Thin Film Thickness 400, IOR 1.33)
    for eta in (1.5, 1.0 / 1.5):
        for theta in THETAS:
            f0 = ((eta - 1.0) / (eta + 1.0)) ** 2
            cases.append((f"ggx-film-glass-r0.3-eta{eta:.3f}",
                          dict(ctype=CT_MICROFACET_GLASS, dist=MD_GGX, alpha=0.09, eta=eta,
                               fresnel=FR_SCHLICK, f0=(f0, f0, f0), exponent=-1.5,
                               film=(400.0, 1.33 if eta > 1.0 else 1.33 * eta)), theta, 0.0))
    return cases


CASES = _case_list()
# The default run: one view per closure kind, the rest with -m slow.
FAST = {0, 1, 2, 3, 4, 5, 6, 7}


def _row(params: dict, wo) -> np.ndarray:
    p = dict(params)
    ctype = p.pop("ctype")
    if ctype in (CT_DIFFUSE, CT_TRANSLUCENT):
        return diffuse_row(ctype)
    if ctype == CT_OREN_NAYAR:
        return oren_nayar_row(p["sigma"], (0.8, 0.8, 0.8), cos_no=wo[2])
    if ctype == CT_ASHIKHMIN_SHIRLEY:
        return ashikhmin_shirley_row(p["alpha"], p.get("alpha_y"))
    if ctype == CT_VELVET:
        return velvet_row(p["sigma"])
    if ctype in (CT_DIFFUSE_TOON, CT_GLOSSY_TOON):
        return toon_row(ctype, p["size"], p["smooth"])
    if ctype in (CT_HAIR_REFLECTION, CT_HAIR_TRANSMISSION):
        return hair_row(ctype, (1.0, 0.0, 0.0), p["r1"], p["r2"], p["offset"])
    return microfacet_row(ctype=ctype, **p)


def run_case(params: dict, theta: float, phi: float, seed: int, pdf_scale=None) -> chi2.Chi2Result:
    wo = direction(theta, phi)
    cl = _row(params, wo)
    ctype = params["ctype"]
    valid_eta = params.get("eta") if ctype in (CT_MICROFACET_REFRACTION, CT_MICROFACET_GLASS) else None
    pdf = chi2.closure_pdf(cl, wo, valid_eta)
    scale = 1.0
    if params.get("dist") == MD_BECKMANN:
        ax = params["alpha"]
        ay = params.get("alpha_y", ax)
        scale = beckmann_exact_scale(ax, ay, wo)
    if pdf_scale is not None:
        scale *= pdf_scale
    return chi2.chi2_test(chi2.closure_sampler(cl, wo), lambda d: pdf(d) * scale, N_SAMPLES, seed)


def _params():
    out = []
    for i, (name, params, theta, phi) in enumerate(CASES):
        marks = () if (i in FAST or (name.endswith("r0.3") and theta == 45.0)
                       or (name.startswith(("velvet", "ashikhmin", "toon", "hair")) and theta == 45.0)
                       or ("r0.3-eta" in name and theta == 45.0)) else (pytest.mark.slow,)
        out.append(pytest.param(params, theta, phi, id=f"{name}-th{theta:g}-ph{phi:g}", marks=marks))
    return out


def test_case_count_matches_sidak_correction():
    assert len(CASES) == chi2.N_TESTS


@pytest.mark.parametrize("params, theta, phi", _params())
def test_sampler_matches_pdf(params, theta, phi):
    result = run_case(params, theta, phi, seed=1234)
    assert result.passed(), (f"chi2 {result.statistic:.1f} with {result.dof} dof, p = {result.p_value:.3g} "
                             f"< {chi2.ALPHA_SIDAK:.3g}; pdf integral {result.pdf_integral:.5f}, "
                             f"success {result.success:.5f}")
    assert result.pdf_integral <= 1.0 + 1e-3


def test_wrong_pdf_is_rejected():
    """The harness has power: the classic bug of taking Smith's masking of the sampled
    direction instead of the view in the pdf of GGX reflection (r 0.5, view at 45 degrees),
    and a pdf 5 % too large over half the sphere and 5 % too small over the other, both fail."""
    from .kernels import evaluate
    theta = 45.0
    wo = direction(theta)
    cl = microfacet_row(alpha=0.25)

    def lam(v):
        q = 0.0625 * (v[:, 0] ** 2 + v[:, 1] ** 2) / v[:, 2] ** 2
        return 0.5 * (np.sqrt(1.0 + q) - 1.0)

    wo_arr = np.array([wo])

    def wrong_masking(d):
        p = evaluate(cl, wo, d)[:, 3]
        with np.errstate(divide="ignore", invalid="ignore"):
            fixed = p * (1.0 + lam(wo_arr)) / (1.0 + lam(d))
        return np.where(d[:, 2] > 0.0, fixed, 0.0)

    bad = chi2.chi2_test(chi2.closure_sampler(cl, wo), wrong_masking, N_SAMPLES, 99)
    assert not bad.passed()

    def lopsided(d):
        p = evaluate(cl, wo, d)[:, 3]
        return p * np.where(d[:, 1] > 0.0, 1.05, 0.95)

    bad = chi2.chi2_test(chi2.closure_sampler(cl, wo), lopsided, N_SAMPLES, 99)
    assert not bad.passed()
    good = chi2.chi2_test(chi2.closure_sampler(cl, wo), lambda d: evaluate(cl, wo, d)[:, 3], N_SAMPLES, 99)
    assert good.passed()


def test_beckmann_lambda_fit_error_is_small():
    """Cycles' Beckmann pdf differs from its exact visible-normal density only by the
    Lambda fit, by at most 0.32 % for any alpha <= 1 and view up to 89.9 degrees."""
    worst = 0.0
    for alpha in np.linspace(0.01, 1.0, 40):
        for theta in np.linspace(0.0, 89.9, 200):
            s = beckmann_exact_scale(alpha, alpha, direction(theta))
            worst = max(worst, abs(s - 1.0))
    assert worst < 3.5e-3
