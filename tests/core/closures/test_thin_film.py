"""Thin-film interference (``closures.thin_film``) against its physics, computed independently.

The reference is the spectral integral the Fourier table stands for: the exact Airy
reflectance of the film at every wavelength (the textbook closed form of a film between
two media, all orders, complex amplitudes), averaged over s and p, weighted by the working
space's RGB colour matching functions (``kernels.colorspace``'s 5-nm CIE 1931 table, not
the 1-nm data the Fourier table was made from, through XYZ_TO_RGB), divided by the CMF's
integral.  The kernel truncates the series after its third order (as Cycles) and reads the
CMFs' Fourier transform from a 512-entry table; the bounds below are about twice the largest
difference measured over the grid: dielectric substrates 4.3e-3; conductors 6e-3 at cosines
0.7 and 1 but 3.8e-2 at 0.3, where the top interface reflects more and the truncated orders
(r12 r23)^(m/2), m > 3, are no longer negligible (a 40-term sum per wavelength matches the
closed form to 1e-15, the 3-term one differs by 4e-3 already at 0.7).
"""
from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from mcengine.kernels.closures import tables as T
from mcengine.kernels.closures.fresnel import f82_B, fresnel_conductor, fresnel_dielectric, fresnel_f82
from mcengine.kernels.closures.thin_film import (
    f82_conductor_ior,
    iridescence_conductor,
    iridescence_dielectric,
    schlick_iridescence,
)
from mcengine.kernels.colorspace import CIE_XYZ, XYZ_TO_RGB

pytestmark = pytest.mark.skipif(not T.TABLES_LOADED, reason="data/*.npy not generated yet")

WAVELENGTHS = np.arange(380.0, 781.0, 5.0)          # CIE_XYZ's rows
RGB_CMF = CIE_XYZ @ XYZ_TO_RGB.T                    # (81, 3)


def exact_film_rgb(cos_i: float, thickness: float, film_ior: float, substrate) -> np.ndarray:
    """RGB reflectance of a film (IOR film_ior, thickness nm) on a substrate of complex IOR
    ``substrate`` (scalar or per channel), from a medium of IOR 1, by spectral integration."""
    n1, n2 = 1.0, complex(film_ior)
    sin1_sq = 1.0 - cos_i * cos_i
    cos2 = np.sqrt(1.0 - sin1_sq / (n2 * n2) + 0j)
    out = np.zeros(3)
    for c in range(3):
        n3 = complex(np.broadcast_to(substrate, 3)[c])
        cos3 = np.sqrt(1.0 - sin1_sq / (n3 * n3) + 0j)
        r12s = (n1 * cos_i - n2 * cos2) / (n1 * cos_i + n2 * cos2)
        r23s = (n2 * cos2 - n3 * cos3) / (n2 * cos2 + n3 * cos3)
        r12p = (n2 * cos_i - n1 * cos2) / (n2 * cos_i + n1 * cos2)
        r23p = (n3 * cos2 - n2 * cos3) / (n3 * cos2 + n2 * cos3)
        phase = np.exp(2j * (2.0 * math.pi / WAVELENGTHS) * n2 * thickness * cos2)
        rs = (r12s + r23s * phase) / (1.0 + r12s * r23s * phase)
        rp = (r12p + r23p * phase) / (1.0 + r12p * r23p * phase)
        reflectance = 0.5 * (np.abs(rs) ** 2 + np.abs(rp) ** 2)
        out[c] = np.sum(reflectance * RGB_CMF[:, c]) / np.sum(RGB_CMF[:, c])
    return np.clip(out, 0.0, 1.0)    # as the kernel: a saturated film colour leaves the gamut


GRID = list(itertools.product((1.0, 0.7, 0.3), (80.0, 250.0, 500.0, 900.0), (1.33, 1.8)))


@pytest.mark.parametrize("eta", (1.5, 1.1, 2.4))
def test_film_on_a_dielectric_matches_the_spectral_integral(eta):
    worst = 0.0
    for cos_i, d, film in GRID:
        ours = np.array(iridescence_dielectric(cos_i, d, film, eta))
        exact = exact_film_rgb(cos_i, d, film, eta)
        worst = max(worst, float(np.max(np.abs(ours - exact))))
        assert ours == pytest.approx(exact, abs=8e-3), (cos_i, d, film)
    assert worst > 0.0


@pytest.mark.parametrize("n, k", [((0.18, 0.42, 1.37), (3.42, 2.35, 1.77)),     # gold
                                  ((2.76, 2.51, 2.23), (3.87, 3.40, 3.01))])    # the node's default
def test_film_on_a_conductor_matches_the_spectral_integral(n, k):
    """Cycles' conductor phase is that of the refractive index n + ik (exp(-i w t) waves)."""
    substrate = np.array(n) + 1j * np.array(k)
    for cos_i, d, film in GRID:
        ours = np.array(iridescence_conductor(cos_i, d, film, n, k, (-1.0,) * 3))
        bound = 1.2e-2 if cos_i >= 0.7 else 7e-2
        assert ours == pytest.approx(exact_film_rgb(cos_i, d, film, substrate), abs=bound), (cos_i, d, film)


def test_the_colours_are_those_of_the_film_not_an_average():
    """The test above can fail: a film's reflectance at 300 nm differs from the film-free
    Fresnel by far more than its bound, and a conjugated conductor phase moves it too."""
    exact = exact_film_rgb(1.0, 300.0, 1.33, 1.5)
    plain = fresnel_dielectric(1.0, 1.5)[0]
    assert np.max(np.abs(exact - plain)) > 0.02
    n, k = 0.18, 3.42
    wrong_phase = exact_film_rgb(0.7, 250.0, 1.8, n - 1j * k)[0]
    assert abs(iridescence_conductor(0.7, 250.0, 1.8, (n,) * 3, (k,) * 3, (-1.0,) * 3)[0]
               - wrong_phase) > 0.02


def test_an_index_matched_film_is_no_film():
    """A film of IOR 1 leaves the substrate's Fresnel; a film of the substrate's IOR is
    the substrate: both exactly, whatever the thickness."""
    for cos_i, d, eta in itertools.product((1.0, 0.5, 0.05), (50.0, 400.0), (1.5, 0.8)):
        plain = fresnel_dielectric(cos_i, eta)[0]
        assert iridescence_dielectric(cos_i, d, 1.0, eta) == pytest.approx((plain,) * 3, abs=1e-12)
        assert iridescence_dielectric(cos_i, d, eta, eta) == pytest.approx((plain,) * 3, abs=1e-12)
    for cos_i in (1.0, 0.5, 0.05):
        assert iridescence_conductor(cos_i, 300.0, 1.0, (0.2, 0.5, 1.5), (3.0, 2.0, 0.0), (-1.0,) * 3) == (
            pytest.approx([fresnel_conductor(cos_i, 0.2, 3.0), fresnel_conductor(cos_i, 0.5, 2.0),
                           fresnel_conductor(cos_i, 1.5, 0.0)], abs=1e-12))


def test_f82_metal_under_an_index_matched_film_keeps_its_f82_curve():
    """Cycles' F82 metal under a film: the bottom interface reflects as the F82 model, so a
    film of IOR 1 gives back that model; its n, k (for the phase) reproduce F0."""
    f0, f82 = 0.9, 0.8
    b = f82_B(f0, f82)
    n, k = f82_conductor_ior(f0, f82)
    assert fresnel_conductor(1.0, n, k) == pytest.approx(f0, abs=1e-12)
    for cos_i in (1.0, 0.6, 0.2):
        assert iridescence_conductor(cos_i, 300.0, 1.0, (n,) * 3, (k,) * 3, (f82,) * 3) == pytest.approx(
            (fresnel_f82(cos_i, f0, b),) * 3, abs=1e-12)


def test_specular_tint_scales_the_film_towards_F0():
    """Principled's Specular Tint / IOR Level under a film: where the film reflects F0(eta),
    the tint scales it fully; where it reflects 1 (grazing), not at all."""
    eta, f0 = 1.5, 0.04
    plain = iridescence_dielectric(1.0, 400.0, 1.0, eta)
    tinted = schlick_iridescence(1.0, 400.0, 1.0, eta, f0 * 0.5, f0, f0 * 2.0)
    assert tinted == pytest.approx((plain[0] * 0.5, plain[1], plain[2] * 2.0), rel=1e-12)
    assert schlick_iridescence(0.0, 400.0, 1.33, eta, 0.0, 0.0, 0.0) == (1.0, 1.0, 1.0)


def test_a_tint_far_above_the_iors_F0_does_not_add_light():
    """Specular Tint can raise F0 to 1 on an IOR whose F0 is 0.11: Cycles' scaling would make
    a film reflecting 0.5 reflect 2.75 (and transmit -1.75); MC Engine clamps at 1."""
    eta = 2.0
    f0_real = ((eta - 1.0) / (eta + 1.0)) ** 2
    above = 0
    for cos_i, d in itertools.product(np.linspace(0.05, 1.0, 12), np.linspace(100.0, 900.0, 17)):
        film = np.array(iridescence_dielectric(cos_i, d, 1.6, eta))
        s = np.clip((film - 1.0) / (f0_real - 1.0), 0.0, 1.0)
        unclamped = film * (1.0 + (1.0 / f0_real - 1.0) * s)
        ours = np.array(schlick_iridescence(cos_i, d, 1.6, eta, 1.0, 1.0, 1.0))
        assert ours == pytest.approx(np.minimum(unclamped, 1.0), abs=1e-12)
        above += int(np.any(unclamped > 1.0))
    assert above > 0


def test_the_table_is_the_fourier_transform_of_the_cmfs():
    """THIN_FILM_RE/IM at x = 2 pi OPD / 60 um against a fresh quadrature of
    int cmf(l) exp(-2 pi i OPD / l) dl / int cmf(l) dl over the 5-nm CIE table.  Measured
    within 9.4e-3: the table is a sum over wavenumbers 0.052 per um apart (Cycles' grid,
    about 25 nodes across the visible range), a percent from the continuous transform."""
    for opd in (0.0, 200.0, 550.0, 1200.0, 3000.0):
        weight = np.exp(-2j * math.pi * opd / WAVELENGTHS)
        x = 2.0 * math.pi * opd / 60000.0
        for c in range(3):
            want = np.sum(RGB_CMF[:, c] * weight) / np.sum(RGB_CMF[:, c])
            got = complex(T.lookup_row(T.THIN_FILM_RE, c, x), T.lookup_row(T.THIN_FILM_IM, c, x))
            assert abs(got - want) < 2e-2, (opd, c, got, want)


def test_hazards_stay_finite_and_in_range():
    """Grazing and normal views, films from the cutoff to 20 um (past the table's end),
    film IORs from 1e-5 to 10, substrates from 1e-5 to 10 and through total internal
    reflection: reflectances are finite and in [0, 1]."""
    for cos_i, d, film, eta in itertools.product((1e-7, 0.01, 0.5, 1.0), (0.1001, 0.5, 1.0, 300.0, 2e4),
                                                 (1e-5, 1.0, 1.33, 10.0), (1e-5, 0.67, 1.0, 1.5, 10.0)):
        rgb = iridescence_dielectric(cos_i, d, film, eta)
        assert all(0.0 <= v <= 1.0 for v in rgb), (cos_i, d, film, eta, rgb)
        rgb = iridescence_conductor(cos_i, d, film, (eta,) * 3, (3.0 * eta,) * 3, (-1.0,) * 3)
        assert all(0.0 <= v <= 1.0 for v in rgb), (cos_i, d, film, eta, rgb)
        n, k = f82_conductor_ior(min(eta, 1.0), 0.5)
        rgb = iridescence_conductor(cos_i, d, film, (n,) * 3, (k,) * 3, (0.5,) * 3)
        assert all(0.0 <= v <= 1.0 for v in rgb), (cos_i, d, film, eta, rgb)
