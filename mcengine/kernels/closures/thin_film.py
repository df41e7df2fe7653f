"""Thin-film interference: the reflectance of a surface under a film, as Cycles 5.0 computes it.

A film of thickness d (nm) and index n_f over a substrate reflects light that is the sum of
the waves reflected at its top and bottom interfaces and of those bouncing inside it; their
phase differences make the reflectance oscillate with 1 / wavelength.  Belcour and Barla
("A Practical Extension to Microfacet Theory for the Modeling of Varying Iridescence", 2017)
write that sum as an Airy series and integrate each term against the colour matching
functions through their Fourier transform (``tables.THIN_FILM_RE``/``_IM``: RGB, normalised
to 1 at zero path difference), which gives the film's RGB reflectance directly.  As Cycles
(kernel/closure/bsdf_util.h, ``fresnel_iridescence``):

* the ambient medium has IOR 1 (relative), the film ``film_ior``; films thinner than 1 nm
  blend the film's IOR towards the ambient one with smoothstep(0, 1, d);
* the top interface's s- and p-reflectances and their phase (0 or pi) come from the
  dielectric Fresnel equations; total internal reflection there gives reflectance 1;
* the bottom interface is a dielectric (``iridescence_dielectric``: the substrate's IOR,
  total internal reflection there gives 1) or a conductor (``iridescence_conductor``:
  n + ik per channel, with complex phase; or, for the F82-tint model, the F82 reflectance
  with F0 recomputed for the film and the phase of the n, k estimated from F0 and F82);
* the optical path difference is 2 n_f d cos(theta_film); the series is summed to the third
  order, s and p separately, averaged and clamped to [0, 1].

Only the Fresnel term of a microfacet closure changes (``microfacet.microfacet_fresnel``):
sampling, energy compensation and the albedo tables stay those of the film-free closure, as
in Cycles.
"""
from __future__ import annotations

import math

from ...jit import device
from .fresnel import f82_B, fresnel_conductor_polarized, fresnel_dielectric_polarized, fresnel_f82
from .tables import THIN_FILM_IM, THIN_FILM_RE, lookup_row

THIN_FILM_CUTOFF = 0.1       # nm: thinner films are absent (Cycles' THINFILM_THICKNESS_CUTOFF)
_TABLE_OPD_NM = 60000.0      # x = 2 pi OPD / this: the table spans x in [0, 1]
_AIRY_ORDERS = 3             # terms of the series beyond the incoherent sum


@device
def _airy(channel, r12, r23, opd, phase_re, phase_im):
    """Channel ``channel`` of the film's reflectance for one polarisation.

    r12, r23: reflectances of the top and bottom interfaces; (phase_re, phase_im) the unit
    phasor of the phase shifts on reflection, exp(i (phi23 + phi21)).
    """
    t121 = 1.0 - r12
    r123 = r12 * r23
    amp = math.sqrt(r123)
    rs = t121 * t121 * r23 / (1.0 - r123)
    r = rs + r12
    cm = rs - t121
    acc_re, acc_im = phase_re, phase_im
    for m in range(1, _AIRY_ORDERS + 1):
        cm *= amp
        x = 2.0 * math.pi * m * opd / _TABLE_OPD_NM
        s_re = lookup_row(THIN_FILM_RE, channel, x)
        s_im = lookup_row(THIN_FILM_IM, channel, x)
        r += cm * 2.0 * (acc_re * s_re + acc_im * s_im)
        acc_re, acc_im = (acc_re * phase_re - acc_im * phase_im,
                          acc_re * phase_im + acc_im * phase_re)
    return r


@device
def _film_ior(thickness, film_ior):
    """Below 1 nm the film's IOR blends towards the ambient IOR 1 (smoothstep)."""
    if thickness < 1.0:
        t = max(thickness, 0.0)
        return 1.0 + (film_ior - 1.0) * (3.0 - 2.0 * t) * t * t
    return film_ior


@device
def _sat(x):
    return min(max(x, 0.0), 1.0)


@device
def _sign(x):
    return 1.0 if x >= 0.0 else -1.0


@device
def _top_interface(cos_i, thickness, film_ior):
    """(n_f, R_s, R_p, cos_film, phase_s, phase_p) of the film's top interface, seen from a
    medium of IOR 1: the film's IOR, the reflectances, the cosine inside the film and the
    sign of each amplitude.  R_s = R_p = 1 under total internal reflection."""
    nf = _film_ior(thickness, film_ior)
    r_s, r_p, cos_f = fresnel_dielectric_polarized(cos_i, nf)
    return nf, r_s * r_s, r_p * r_p, cos_f, _sign(r_s), _sign(r_p)


@device
def iridescence_dielectric(cos_i, thickness, film_ior, eta):
    """RGB reflectance of a film (thickness nm, IOR ``film_ior``) on a dielectric of relative
    IOR ``eta``, seen at incidence cosine ``cos_i`` from a medium of IOR 1."""
    nf, r12s, r12p, cos_2, ph12s, ph12p = _top_interface(cos_i, thickness, film_ior)
    if r12s == 1.0 and r12p == 1.0:
        return 1.0, 1.0, 1.0            # total internal reflection at the top
    a23s, a23p, _ = fresnel_dielectric_polarized(cos_2, eta / nf)
    r23s, r23p = a23s * a23s, a23p * a23p
    if r23s == 1.0 and r23p == 1.0:
        return 1.0, 1.0, 1.0            # ... at the bottom: the series sums to 1
    opd = 2.0 * nf * thickness * cos_2
    ps = -_sign(a23s) * ph12s
    pp = -_sign(a23p) * ph12p
    r = 0.5 * (_airy(0, r12s, r23s, opd, ps, 0.0) + _airy(0, r12p, r23p, opd, pp, 0.0))
    g = 0.5 * (_airy(1, r12s, r23s, opd, ps, 0.0) + _airy(1, r12p, r23p, opd, pp, 0.0))
    b = 0.5 * (_airy(2, r12s, r23s, opd, ps, 0.0) + _airy(2, r12p, r23p, opd, pp, 0.0))
    return _sat(r), _sat(g), _sat(b)


@device
def _unit(re, im):
    mag = math.sqrt(re * re + im * im)
    if mag == 0.0:
        return 1.0, 0.0
    return re / mag, im / mag


@device
def _conductor_channel(channel, nf, r12s, r12p, c, ph12s, ph12p, thickness, n, k, f82):
    """Channel ``channel`` of a film on a conductor of IOR n + ik, given its top interface
    (``_top_interface``; c the cosine inside the film)."""
    r23s, r23p, u, v = fresnel_conductor_polarized(c, nf, n, k)
    if f82 >= 0.0:
        rn = n / nf
        rk_sq = (k / nf) ** 2
        f0 = ((rn - 1.0) ** 2 + rk_sq) / ((rn + 1.0) ** 2 + rk_sq)
        r23s = r23p = fresnel_f82(c, f0, f82_B(f0, f82))
    n2, k2 = n * n, k * k
    uv2 = u * u + v * v
    ph23s_re, ph23s_im = _unit(nf * nf * c * c - uv2, -2.0 * nf * c * v)
    ph23p_re, ph23p_im = _unit(((n2 + k2) * c) ** 2 - nf * nf * uv2,
                               2.0 * nf * c * (2.0 * n * k * u - (n2 - k2) * v))
    opd = 2.0 * nf * thickness * c
    rs = _airy(channel, r12s, r23s, opd, -ph12s * ph23s_re, -ph12s * ph23s_im)
    rp = _airy(channel, r12p, r23p, opd, -ph12p * ph23p_re, -ph12p * ph23p_im)
    return _sat(0.5 * (rs + rp))


@device
def iridescence_conductor(cos_i, thickness, film_ior, n, k, f82):
    """RGB reflectance of a film on a conductor; ``n``, ``k`` and ``f82`` are RGB triples.

    Per channel, the bottom interface is the conductor n + ik seen from the film (Born and
    Wolf); with ``f82 >= 0`` it reflects as the F82 model whose F0 is that of n + ik seen
    from the film and whose value at cos = 1/7 is ``f82`` (Cycles' F82-tint metal); the
    phase always comes from n + ik.
    """
    nf, r12s, r12p, c, ph12s, ph12p = _top_interface(cos_i, thickness, film_ior)
    if r12s == 1.0 and r12p == 1.0:
        return 1.0, 1.0, 1.0
    return (_conductor_channel(0, nf, r12s, r12p, c, ph12s, ph12p, thickness, n[0], k[0], f82[0]),
            _conductor_channel(1, nf, r12s, r12p, c, ph12s, ph12p, thickness, n[1], k[1], f82[1]),
            _conductor_channel(2, nf, r12s, r12p, c, ph12s, ph12p, thickness, n[2], k[2], f82[2]))


@device
def f82_conductor_ior(f0, f82):
    """(n, k) of a conductor whose reflectance is f0 at normal incidence and f82 at cos = 1/7
    (Gulbrandsen's "Artist Friendly Metallic Fresnel", reading F0 as r and F82 as g), as
    Cycles estimates them for a film on an F82-tint metal; f0 is clamped to 0.999."""
    r = min(f0, 0.999)
    sr = math.sqrt(r)
    n_min = (1.0 - r) / (1.0 + r)
    n_max = (1.0 + sr) / (1.0 - sr)
    n = n_max + (n_min - n_max) * f82
    k_sq = (r * (n + 1.0) ** 2 - (n - 1.0) ** 2) / (1.0 - r)
    return n, math.sqrt(max(k_sq, 0.0))


@device
def schlick_iridescence(cos_i, thickness, film_ior, eta, f0_r, f0_g, f0_b):
    """RGB reflectance of a film on a dielectric closure whose F0 (Specular IOR Level and
    Tint) may differ from that of its IOR: the film's reflectance F, each channel scaled by
    mix(1, F0 / F0(eta), s) with s = (F - 1) / (F0(eta) - 1) clamped (Cycles' artistic
    F0 control for films, generalized Schlick with exponent < 0).

    The result is clamped to 1, where Cycles lets it exceed 1 (and the transmittance 1 - F
    turn negative): a film whose F0 is tinted far above that of its IOR (F0 = 1 at IOR 2
    reflects F = 0.5 as 2.75), which would add light.
    """
    r, g, b = iridescence_dielectric(cos_i, thickness, film_ior, eta)
    x = (eta - 1.0) / (eta + 1.0)
    f0_real = x * x
    if f0_real > 1e-5 and not (r == 1.0 and g == 1.0 and b == 1.0):
        d = f0_real - 1.0
        r = min(r * (1.0 + (f0_r / f0_real - 1.0) * _sat((r - 1.0) / d)), 1.0)
        g = min(g * (1.0 + (f0_g / f0_real - 1.0) * _sat((g - 1.0) / d)), 1.0)
        b = min(b * (1.0 + (f0_b / f0_real - 1.0) * _sat((b - 1.0) / d)), 1.0)
    return r, g, b
