"""The subsurface scattering closure (Cycles' Bssrdf, kernel/closure/bssrdf.h).

A BSSRDF row has no value towards a light: it counts only in the closure pick (its sample
weight is |average weight| x its channels with a radius) and in the MIS sum.  When it is
picked, ``bssrdf_entry`` samples the direction into the object (Cycles'
subsurface_entry_bounce, kernel/integrator/subsurface.h) and the path tracer walks
inside (``kernels.subsurface``); a Christensen-Burley BSSRDF instead probes the surface
around the point along a disk sampled from its reflectance profile (``burley_*``,
``disk_*``).  ``bssrdf_radius`` turns the node's radius into the walk's mean free path
as ``bssrdf_setup_radius`` does.
"""
from __future__ import annotations

import math

from ...jit import device
from ..sampling import cosine_hemisphere
from .layout import CL_AX, CL_ETA, CL_SSS_METHOD, SSS_BURLEY, SSS_RANDOM_WALK_SKIN
from .microfacet import ggx_sample_vndf

BSSRDF_MIN_RADIUS = 1e-8     # Cycles' BSSRDF_MIN_RADIUS: smaller channels are diffuse instead
_QUARTER_OVER_PI = 0.25 / math.pi
BURLEY_TRUNCATE = 16.0                       # the profile is cut at 16 radii (Cycles')
BURLEY_TRUNCATE_CDF = 0.9963790093708328     # its CDF there


@device
def _dipole_rd(alpha_prime, fourthird_a):
    s = math.sqrt(3.0 * (1.0 - alpha_prime))
    return 0.5 * alpha_prime * (1.0 + math.exp(-fourthird_a * s)) * math.exp(-s)


@device
def dipole_alpha_prime(rd, fourthird_a):
    """The single-scattering albedo whose dipole reflectance is ``rd`` (Cycles'
    bssrdf_dipole_compute_alpha_prime: 12 bisection steps)."""
    if rd < 1e-4:
        return 0.0
    if rd >= 0.995:
        return 0.999999
    x0, x1 = 0.0, 1.0
    xmid = 0.5
    for _ in range(12):
        xmid = 0.5 * (x0 + x1)
        if _dipole_rd(xmid, fourthird_a) < rd:
            x0 = xmid
        else:
            x1 = xmid
    return xmid


@device
def bssrdf_radius(radius, albedo, ior, method):
    """One channel's walk radius from the node's (Radius x Scale): divided by 4 pi for
    Random Walk (and Christensen-Burley), scaled by the dipole's sqrt(3 (1 - alpha')) for
    Random Walk (Skin)."""
    if method != SSS_RANDOM_WALK_SKIN:
        return radius * _QUARTER_OVER_PI
    inv_eta = 1.0 / ior
    f_dr = inv_eta * (-1.440 * inv_eta + 0.710) + 0.668 + 0.0636 * ior
    fourthird_a = (4.0 / 3.0) * (1.0 + f_dr) / (1.0 - f_dr)
    return radius * math.sqrt(3.0 * (1.0 - dipole_alpha_prime(albedo, fourthird_a)))


@device
def bssrdf_entry(cl, k, wox, woy, woz, u1, u2):
    """(wi x, y, z, ok): the direction into the object in closure k's frame (normal +z),
    for the way back to the viewer wo.  Random Walk refracts through a GGX microfacet of the
    closure's alpha with the closure's IOR (no Fresnel or shadowing weight, as Cycles);
    Skin takes a cosine-weighted direction below the surface half of the time and refracts
    with alpha 1 otherwise."""
    method = cl[k, CL_SSS_METHOD]
    if method == SSS_BURLEY:
        return 0.0, 0.0, -1.0, True      # no entry direction: the disk probes the surface
    if method == SSS_RANDOM_WALK_SKIN:
        if u1 < 0.5:
            x, y, z = cosine_hemisphere(2.0 * u1, u2)
            return x, y, -z, True
        u1 = 2.0 * (u1 - 0.5)
    if not woz > 0.0:
        return 0.0, 0.0, 0.0, False
    alpha = cl[k, CL_AX]
    hx, hy, hz = ggx_sample_vndf(wox, woy, woz, alpha, alpha, u1, u2)
    neta = 1.0 / cl[k, CL_ETA]
    cos_hi = hx * wox + hy * woy + hz * woz
    dnp = max(math.sqrt(max(1.0 - neta * neta * (1.0 - cos_hi * cos_hi), 0.0)), 1e-7)
    nk = neta * cos_hi - dnp
    return -neta * wox + nk * hx, -neta * woy + nk * hy, -neta * woz + nk * hz, True


# -- Christensen-Burley (kernel/closure/bssrdf.h) -------------------------------------------
@device
def burley_eval(d, r):
    """Burley's normalised diffusion profile of radius d at distance r (times 2 pi r dr it
    integrates to 1), 0 from the truncation on."""
    if r >= BURLEY_TRUNCATE * d:
        return 0.0
    e3 = math.exp(-r / (3.0 * d))
    return (e3 * e3 * e3 + e3) / (4.0 * d)


@device
def burley_pdf(d, r):
    return 0.0 if r == 0.0 else burley_eval(d, r) / BURLEY_TRUNCATE_CDF


@device
def burley_root(xi):
    """The distance (in radii) where the profile's CDF reaches xi (Newton, as Cycles)."""
    r = math.exp(xi * xi * 2.4) - 1.0 if xi <= 0.9 else 15.0
    for _ in range(10):
        e3 = math.exp(-r / 3.0)
        e = e3 * e3 * e3
        f = 1.0 - 0.25 * e - 0.75 * e3 - xi
        df = 0.25 * e + 0.25 * e3
        if abs(f) < 1e-6 or df == 0.0:
            break
        r = max(r - f / df, 0.0)
    return r


@device
def disk_sample(rr, rg, rb, xi):
    """(r, h): a disk radius from the profile of one channel with a radius (picked
    uniformly, xi reused) and the half height of the probe there, sqrt(Rm^2 - r^2)."""
    channels = (1 if rr > 0.0 else 0) + (1 if rg > 0.0 else 0) + (1 if rb > 0.0 else 0)
    xi *= channels
    d = 0.0
    total = 0.0
    for c in range(3):
        radius = rr if c == 0 else (rg if c == 1 else rb)
        if radius > 0.0:
            if xi < total + 1.0:
                xi -= total
                d = radius
                break
            total += 1.0
    rm = BURLEY_TRUNCATE * d
    r = burley_root(xi * BURLEY_TRUNCATE_CDF) * d
    return r, math.sqrt(max(rm * rm - r * r, 0.0))


@device
def disk_weight(rr, rg, rb, disk_r, r):
    """The profile at distance r over the disk's sampling pdf at disk_r (Cycles'
    subsurface_disk_eval), per channel."""
    channels = (1 if rr > 0.0 else 0) + (1 if rg > 0.0 else 0) + (1 if rb > 0.0 else 0)
    pdf = (burley_pdf(rr, disk_r) + burley_pdf(rg, disk_r) + burley_pdf(rb, disk_r)) / channels
    if not pdf > 0.0:
        return 0.0, 0.0, 0.0
    return burley_pdf(rr, r) / pdf, burley_pdf(rg, r) / pdf, burley_pdf(rb, r) / pdf
