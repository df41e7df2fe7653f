"""Microfacet closures: GGX and Beckmann reflection, refraction and glass, as Cycles 5.0 has them.

Rows of type CT_MICROFACET (reflection only), CT_MICROFACET_REFRACTION (refraction only)
and CT_MICROFACET_GLASS (both, split by Fresnel) read these columns (``layout``): CL_AX,
CL_AY (alpha along the frame's +x and +y), CL_ETA (inside / outside, already inverted on
back faces), CL_DIST (MD_GGX or MD_BECKMANN), CL_FRESNEL and its parameters (CL_F0, CL_F90,
CL_EXPONENT, CL_RTINT, CL_TTINT), a thin film over the surface (CL_FILM_THICKNESS,
CL_FILM_IOR: ``thin_film``) and CL_ENERGY (the multiple-scattering scale, applied to GGX
only, as Cycles does).

The model (Walter et al. 2007; Heitz 2014) with Cycles' choices:

* D: GGX or Beckmann, anisotropic for reflection only (refraction and glass are isotropic,
  and a sampled or evaluated refraction always uses alpha^2 = alpha_x alpha_y);
* Smith Lambda: exact for GGX, Walter's rational fit for Beckmann (0 below
  alpha^2 tan^2 = 0.39); height-correlated G2 = 1 / (1 + Lambda_o + Lambda_i);
* sampling of visible normals: GGX by Heitz 2018 (hemisphere and disk), Beckmann by Heitz
  and d'Eon 2014 with Jakob's inversion of the slope CDF.  Cycles solves the latter with
  fast single-precision erf/erfinv approximations and at most 3 Newton steps; here the CDF
  equation is solved to double precision (math.erf, an erfinv refined by Halley steps,
  safeguarded Newton), so the samples follow the exact visible-normal density;
* reflection f cos = R D G2 / (4 mu_o); refraction f cos = T D G2 J / mu_o with
  J = eta^2 |h.wo| |h.wi| / |eta wi + wo|^2; glass picks reflection with probability
  P_R = avg(R) / avg(R + T) at the sampled microfacet;
* singular lobes: alpha_x alpha_y <= ROUGHNESS_SQ_THRESHOLD, or a sampled refraction with
  |eta - 1| < 1e-4, are only sampled (pdf 0, the weight R / P_R or T / P_T).

Like Cycles, the evaluation checks only that the view is above the surface and the lobe
exists on the light's side: it does not check that the refraction half vector is a
microfacet both directions see (Cycles' "TODO: check if the refraction configuration is
valid"), so ``microfacet_eval`` of a refraction also returns values for direction pairs
the sampler can never produce.  ``microfacet_refraction_valid`` says which pairs those are.

Directions are local: +z is the normal CL_N on the viewer's side, +x the tangent CL_T;
``wo`` points to the viewer, ``wi`` to the light or the sampled direction.
"""
from __future__ import annotations

import math

from ...jit import device, function
from ..scalar import saturate
from .fresnel import (
    F0_from_ior,
    f82_tint_B,
    fresnel_conductor,
    fresnel_conductor_Fss,
    fresnel_dielectric,
    fresnel_dielectric_Fss,
    fresnel_f82,
    fresnel_f82_Fss,
)
from .layout import (
    CL_ALBEDO,
    CL_AX,
    CL_AY,
    CL_DIST,
    CL_ENERGY,
    CL_ETA,
    CL_EXPONENT,
    CL_F0,
    CL_F90,
    CL_FILM_IOR,
    CL_FILM_THICKNESS,
    CL_FRESNEL,
    CL_RTINT,
    CL_SW,
    CL_TTINT,
    CL_TYPE,
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
    MD_GGX,
    ROUGHNESS_SQ_THRESHOLD,
)
from .tables import (
    GGX_E_3D,
    GGX_EAVG_2D,
    GGX_GEN_SCHLICK_IOR_S,
    GGX_GEN_SCHLICK_S,
    GGX_GLASS_E,
    GGX_GLASS_EAVG,
    GGX_GLASS_INV_E,
    GGX_GLASS_INV_EAVG,
    lookup_2d,
    lookup_3d,
)
from .thin_film import (
    THIN_FILM_CUTOFF,
    f82_conductor_ior,
    iridescence_conductor,
    schlick_iridescence,
)

# ``function`` (called, not inlined): the Beckmann sampler (and its erfinv) costs about 0.5 us,
# so a call costs nothing measurable.  The setup helpers (albedo estimate, energy
# compensation: table lookups) are inlined into the Fresnel set-ups, which the closure nodes
# call (``svm.closure_nodes``): four calls fewer per microfacet closure, about 7 % more paths
# per second on the default Principled BSDF (benchmarks/bench_cornell.py), for 5-10 % more
# compile time.

_INV_PI = 1.0 / math.pi
_SQRT_PI = math.sqrt(math.pi)
_ONE_BELOW_ONE = 1.0 - 2.0 ** -53      # the largest double below 1


# -- distribution and masking ---------------------------------------------------------------------
@device
def ggx_D(ax, ay, hx, hy, hz):
    """GGX density of normals h (unit, local frame), alpha ax along +x and ay along +y.

    D = 1 / (pi ax ay |(hx/ax, hy/ay, hz)|^4); with ax = ay = a this is
    a^2 / (pi (sin^2 + a^2 cos^2)^2).  Even in h.
    """
    x = hx / ax
    y = hy / ay
    s = x * x + y * y + hz * hz
    return _INV_PI / (ax * ay * s * s)


@device
def beckmann_D(ax, ay, hx, hy, hz):
    """Beckmann density of normals: exp(-((hx/ax)^2 + (hy/ay)^2) / hz^2) / (pi ax ay hz^4)."""
    c2 = hz * hz
    x = hx / ax
    y = hy / ay
    e = math.exp(-(x * x + y * y) / c2)
    return e * _INV_PI / (ax * ay * c2 * c2)


@device
def microfacet_D(dist, ax, ay, hx, hy, hz):
    if dist == MD_GGX:
        return ggx_D(ax, ay, hx, hy, hz)
    return beckmann_D(ax, ay, hx, hy, hz)


@device
def ggx_lambda_q(q):
    """GGX Smith Lambda from q = alpha^2 tan^2(theta): (sqrt(1 + q) - 1) / 2, no cancellation."""
    if q >= 1.0:
        return 0.5 * (math.sqrt(1.0 + q) - 1.0)       # also q = inf
    return 0.5 * q / (math.sqrt(1.0 + q) + 1.0)


@device
def beckmann_lambda_q(q):
    """Beckmann Smith Lambda from q = alpha^2 tan^2(theta), Walter et al.'s rational fit.

    0 for q < 0.39 (a = 1/sqrt(q) > 1.6); inf at grazing (q = inf).
    """
    if q < 0.39:
        return 0.0
    a = 1.0 / math.sqrt(q)
    return ((0.396 * a - 1.259) * a + 1.0) / ((2.181 * a + 3.535) * a)


@device
def microfacet_lambda(dist, ax, ay, vx, vy, vz):
    """Smith Lambda of direction v (local frame): q = ((ax vx)^2 + (ay vy)^2) / vz^2."""
    x = ax * vx
    y = ay * vy
    q = (x * x + y * y) / (vz * vz)
    if dist == MD_GGX:
        return ggx_lambda_q(q)
    return beckmann_lambda_q(q)


@device
def microfacet_G2(dist, ax, ay, wox, woy, woz, wix, wiy, wiz):
    """Height-correlated masking-shadowing 1 / (1 + Lambda(wo) + Lambda(wi))."""
    return 1.0 / (1.0 + microfacet_lambda(dist, ax, ay, wox, woy, woz)
                  + microfacet_lambda(dist, ax, ay, wix, wiy, wiz))


# -- visible-normal sampling ----------------------------------------------------------------------
@device
def _concentric_disk(u1, u2):
    a = 2.0 * u1 - 1.0
    b = 2.0 * u2 - 1.0
    if a == 0.0 and b == 0.0:
        return 0.0, 0.0
    if a * a > b * b:
        r = a
        phi = (math.pi / 4.0) * (b / a)
    else:
        r = b
        phi = (math.pi / 2.0) - (math.pi / 4.0) * (a / b)
    return r * math.cos(phi), r * math.sin(phi)


@device
def ggx_sample_vndf(vx, vy, vz, ax, ay, u1, u2):
    """A GGX normal h with density D_v(h) = G1(v) max(0, v.h) D(h) / v_z (Heitz 2018).

    v is the unit view direction (v_z > 0).  The view is stretched to the unit-roughness
    configuration, a point of the projected hemisphere is picked with the concentric disk
    (its lower half squeezed by (1 + cos) / 2), lifted onto the hemisphere and unstretched.
    """
    sx = ax * vx
    sy = ay * vy
    inv = 1.0 / math.sqrt(sx * sx + sy * sy + vz * vz)
    sx *= inv
    sy *= inv
    sz = vz * inv
    lensq = sx * sx + sy * sy
    if lensq > 1e-20:
        il = 1.0 / math.sqrt(lensq)
        t1x, t1y, t1z = -sy * il, sx * il, 0.0
        t2x, t2y, t2z = -sz * t1y, sz * t1x, sx * t1y - sy * t1x     # s x t1
    else:
        t1x, t1y, t1z = 1.0, 0.0, 0.0
        t2x, t2y, t2z = 0.0, 1.0, 0.0
    p1, p2 = _concentric_disk(u1, u2)
    w = 0.5 * (1.0 + sz)
    p2 = (1.0 - w) * math.sqrt(max(0.0, 1.0 - p1 * p1)) + w * p2
    p3 = math.sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2))
    hx = p1 * t1x + p2 * t2x + p3 * sx
    hy = p1 * t1y + p2 * t2y + p3 * sy
    hz = p1 * t1z + p2 * t2z + p3 * sz
    hx *= ax
    hy *= ay
    hz = max(0.0, hz)
    inv = 1.0 / math.sqrt(hx * hx + hy * hy + hz * hz)
    return hx * inv, hy * inv, hz * inv


@function
def erfinv(y):
    """Inverse error function to double precision, for y in (-1, 1) (clamped inside).

    Winitzki's closed-form approximation (relative error about 2e-3) refined by two
    Halley steps, with the residual taken through erfc in the tails so that it keeps its
    precision there.
    """
    sign = 1.0
    if y < 0.0:
        sign = -1.0
        y = -y
    if y >= 1.0:
        y = _ONE_BELOW_ONE
    if not y > 0.0:          # 0 or NaN
        return 0.0
    ln = math.log((1.0 - y) * (1.0 + y))
    t = 2.0 / (math.pi * 0.147) + 0.5 * ln
    x = math.sqrt(math.sqrt(t * t - ln / 0.147) - t)
    for _ in range(2):
        if y > 0.5:
            f = (1.0 - y) - math.erfc(x)       # erf(x) - y
        else:
            f = math.erf(x) - y
        d = (2.0 / _SQRT_PI) * math.exp(-x * x)
        x -= f / (d * (1.0 + x * f / d))
    return sign * x


@function
def beckmann_sample_vndf(vx, vy, vz, ax, ay, u1, u2):
    """A Beckmann normal h with density G1(v) max(0, v.h) D(h) / v_z (Heitz & d'Eon 2014).

    In the stretched configuration the view makes angle theta with the normal; the slope
    along the view's azimuth has the marginal CDF (Jakob's form)
        C(x) = (1 + erf(x) + K exp(-x^2)) / (1 + erf(cot) + K exp(-cot^2)),  K = tan / sqrt(pi);
    the other slope is Gaussian.  The equation is solved in x by Newton steps kept inside a
    shrinking bracket (bisection when a step leaves it), to 1e-13.  Slopes are rotated to
    the view's azimuth, unstretched and turned into a normal.
    """
    sx = ax * vx
    sy = ay * vy
    inv = 1.0 / math.sqrt(sx * sx + sy * sy + vz * vz)
    sx *= inv
    sy *= inv
    sz = vz * inv
    sin_t = math.sqrt(sx * sx + sy * sy)
    if sin_t < 1e-9:
        # normal incidence: the visible slopes are those of D, a unit Gaussian
        r = math.sqrt(-math.log(max(1.0 - u1, 1e-300)))
        phi = 2.0 * math.pi * u2
        slope_x = r * math.cos(phi)
        slope_y = r * math.sin(phi)
        cos_phi, sin_phi = 1.0, 0.0
    else:
        tan_t = sin_t / sz
        cot_t = sz / sin_t
        erf_a = math.erf(cot_t)
        k = tan_t / _SQRT_PI
        target = u1 * (1.0 + erf_a + k * math.exp(-cot_t * cot_t))
        # First guess from exp(-erfinv(b)^2) ~ 1 - b^2, i.e. K b^2 - b + target - 1 - K = 0
        # in b = erf(x), then safeguarded Newton steps on
        # h(x) = erfc(-x) + K exp(-x^2) - target (erfc(-x) = 1 + erf(x) without cancellation),
        # increasing on x <= cot, h' = 2/sqrt(pi) exp(-x^2) (1 - x tan).
        if k > 0.0:
            disc = 0.25 + k * (k + 1.0 - u1 * (1.0 + erf_a + k * (1.0 - erf_a * erf_a)))
            b = (0.5 - math.sqrt(max(disc, 0.0))) / k
        else:
            b = target - 1.0
        x = erfinv(min(max(b, -1.0), erf_a))
        lo = -9.0
        hi = cot_t
        x = min(max(x, lo), hi)
        for _ in range(60):
            e = math.exp(-x * x)
            h = math.erfc(-x) + k * e - target
            if h > 0.0:
                hi = x
            elif h < 0.0:
                lo = x
            else:
                break
            dh = (2.0 / _SQRT_PI) * e * (1.0 - x * tan_t)
            nx = x - h / dh if dh > 0.0 else 0.5 * (lo + hi)
            if not (nx > lo and nx < hi):
                nx = 0.5 * (lo + hi)
            done = abs(nx - x) <= 1e-13 * (1.0 + abs(x))
            x = nx
            if done or hi - lo <= 1e-13 * (1.0 + abs(x)):
                break
        slope_x = x
        slope_y = erfinv(2.0 * u2 - 1.0)
        cos_phi = sx / sin_t
        sin_phi = sy / sin_t
    rx = (cos_phi * slope_x - sin_phi * slope_y) * ax
    ry = (sin_phi * slope_x + cos_phi * slope_y) * ay
    inv = 1.0 / math.sqrt(rx * rx + ry * ry + 1.0)
    return -rx * inv, -ry * inv, inv


# -- Fresnel of a microfacet closure --------------------------------------------------------------
@device
def microfacet_fresnel(cl, k, cos_hi):
    """Reflectance RGB, transmittance RGB and cos(theta_t) at a microfacet (Cycles' microfacet_fresnel).

    ``cos_hi`` is the cosine between the view and the microfacet normal.  Returns
    (Rr, Rg, Rb, Tr, Tg, Tb, cos_t), cos_t >= 0 the refracted cosine (0 when no refraction
    is computed or under total internal reflection).  R is zero for CT_MICROFACET_REFRACTION,
    T zero for CT_MICROFACET.

    * FR_NONE: R = T = 1, T = 0 under total internal reflection (the colour is in the weight);
    * FR_DIELECTRIC: F = exact dielectric Fresnel at CL_ETA, R = F, T = 1 - F (untinted, as
      Cycles' DIELECTRIC, the coat's model);
    * FR_SCHLICK: F = mix(F0, F90, s) with s from ``generalized_schlick_s`` (CL_EXPONENT),
      R = F x CL_RTINT, T = (1 - F) x CL_TTINT; with exponent >= 0 total internal
      reflection gives R = CL_RTINT, T = 0;
    * FR_F82: R = F82(F0 = CL_F0, B = CL_F90), T = 0;
    * FR_CONDUCTOR: R = the conductor Fresnel of n = CL_F0, k = CL_F90, T = 0.

    With a thin film (CL_FILM_THICKNESS above THIN_FILM_CUTOFF) FR_SCHLICK (exponent < 0,
    what every node uses), FR_F82 and FR_CONDUCTOR take the film's reflectance instead
    (``thin_film``; F82: on the n + ik estimated from F0 and F82).
    """
    ctype = int(cl[k, CL_TYPE])
    has_r = 1.0 if ctype != CT_MICROFACET_REFRACTION else 0.0
    has_t = 1.0 if ctype != CT_MICROFACET else 0.0
    model = int(cl[k, CL_FRESNEL])
    eta = cl[k, CL_ETA]
    # the exact dielectric Fresnel, computed once (cheap) and used by three of the models
    f_real, cos_t = fresnel_dielectric(cos_hi, eta)
    film = cl[k, CL_FILM_THICKNESS]
    if film > THIN_FILM_CUTOFF and model != FR_DIELECTRIC and model != FR_NONE:
        return _film_fresnel(cl, k, cos_hi, film, model, eta, cos_t, has_r, has_t)
    if model == FR_DIELECTRIC:
        rr = rg = rb = f_real
        tr = tg = tb = 1.0 - f_real
    elif model == FR_SCHLICK:
        e = cl[k, CL_EXPONENT]
        if e < 0.0:
            f0 = F0_from_ior(eta)
            s = min(max((f_real - f0) / (1.0 - f0), 0.0), 1.0)
        else:
            c = abs(cos_hi)
            cos_t_sq = 1.0 - (1.0 - c * c) / (eta * eta)
            if cos_t_sq <= 0.0:          # total internal reflection: the reflection tint alone
                return (cl[k, CL_RTINT] * has_r, cl[k, CL_RTINT + 1] * has_r, cl[k, CL_RTINT + 2] * has_r,
                        0.0, 0.0, 0.0, 0.0)
            cos_t = math.sqrt(cos_t_sq)
            s = (1.0 - (cos_t if eta < 1.0 else c)) ** e
        fr = cl[k, CL_F0] + (cl[k, CL_F90] - cl[k, CL_F0]) * s
        fg = cl[k, CL_F0 + 1] + (cl[k, CL_F90 + 1] - cl[k, CL_F0 + 1]) * s
        fb = cl[k, CL_F0 + 2] + (cl[k, CL_F90 + 2] - cl[k, CL_F0 + 2]) * s
        rr = fr * cl[k, CL_RTINT]
        rg = fg * cl[k, CL_RTINT + 1]
        rb = fb * cl[k, CL_RTINT + 2]
        tr = (1.0 - fr) * cl[k, CL_TTINT]
        tg = (1.0 - fg) * cl[k, CL_TTINT + 1]
        tb = (1.0 - fb) * cl[k, CL_TTINT + 2]
    elif model == FR_F82 or model == FR_CONDUCTOR:
        rr = rg = rb = 0.0
        for c in range(3):
            if model == FR_F82:
                v = fresnel_f82(cos_hi, cl[k, CL_F0 + c], cl[k, CL_F90 + c])
            else:
                v = fresnel_conductor(cos_hi, cl[k, CL_F0 + c], cl[k, CL_F90 + c])
            if c == 0:
                rr = v
            elif c == 1:
                rg = v
            else:
                rb = v
        tr = tg = tb = 0.0
    else:
        rr = rg = rb = 1.0
        tr = tg = tb = 1.0 if f_real < 1.0 else 0.0      # no transmission under TIR
    return (rr * has_r, rg * has_r, rb * has_r, tr * has_t, tg * has_t, tb * has_t, cos_t)


@function
def _film_fresnel(cl, k, cos_hi, film, model, eta, cos_t, has_r, has_t):
    """``microfacet_fresnel`` of a row under a thin film (called: a rare, long path)."""
    film_ior = cl[k, CL_FILM_IOR]
    c = abs(cos_hi)
    if model == FR_SCHLICK:
        fr, fg, fb = schlick_iridescence(c, film, film_ior, eta,
                                         cl[k, CL_F0], cl[k, CL_F0 + 1], cl[k, CL_F0 + 2])
        return (fr * cl[k, CL_RTINT] * has_r, fg * cl[k, CL_RTINT + 1] * has_r,
                fb * cl[k, CL_RTINT + 2] * has_r, (1.0 - fr) * cl[k, CL_TTINT] * has_t,
                (1.0 - fg) * cl[k, CL_TTINT + 1] * has_t, (1.0 - fb) * cl[k, CL_TTINT + 2] * has_t,
                cos_t)
    if model == FR_F82:
        n_r, k_r, f82_r = _f82_conductor(cl[k, CL_F0], cl[k, CL_F90])
        n_g, k_g, f82_g = _f82_conductor(cl[k, CL_F0 + 1], cl[k, CL_F90 + 1])
        n_b, k_b, f82_b = _f82_conductor(cl[k, CL_F0 + 2], cl[k, CL_F90 + 2])
    else:
        n_r, n_g, n_b = cl[k, CL_F0], cl[k, CL_F0 + 1], cl[k, CL_F0 + 2]
        k_r, k_g, k_b = cl[k, CL_F90], cl[k, CL_F90 + 1], cl[k, CL_F90 + 2]
        f82_r = f82_g = f82_b = -1.0
    rr, rg, rb = iridescence_conductor(c, film, film_ior, (n_r, n_g, n_b), (k_r, k_g, k_b),
                                       (f82_r, f82_g, f82_b))
    return rr * has_r, rg * has_r, rb * has_r, 0.0, 0.0, 0.0, cos_t


@device
def _f82_conductor(f0, b):
    """(n, k, F82) of the F82 row channel with F0 = f0 and B = b: its value at cos = 1/7 and
    the n + ik estimated from the two (what a film on an F82-tint metal reflects on)."""
    f82 = fresnel_f82(1.0 / 7.0, f0, b)
    n, k = f82_conductor_ior(f0, f82)
    return n, k, f82


@device
def microfacet_refraction_valid(eta, wox, woy, woz, wix, wiy, wiz):
    """Whether a refraction pair (wo above, wi below) has a microfacet that produces it.

    With h = -(eta wi + wo) / |eta wi + wo| turned to the upper hemisphere, the view must
    see its front (h.wo > 0) and the light leave through its back (h.wi < 0).  The sampler
    produces only such pairs; Cycles' (and ``microfacet_eval``'s) refraction also evaluates
    the others.
    """
    hx = -(eta * wix + wox)
    hy = -(eta * wiy + woy)
    hz = -(eta * wiz + woz)
    if hz < 0.0:
        hx, hy, hz = -hx, -hy, -hz
    return hx * wox + hy * woy + hz * woz > 0.0 and hx * wix + hy * wiy + hz * wiz < 0.0


# -- eval and sample ------------------------------------------------------------------------------
@device
def microfacet_eval(cl, k, wox, woy, woz, wix, wiy, wiz):
    """(f cos r, g, b, pdf) of a microfacet row for view wo and light wi (Cycles' bsdf_microfacet_eval).

    Without the weight CL_W; GGX includes CL_ENERGY (Cycles' energy_scale).  Zero when the
    view is below the surface, the lobe is singular, or the light is on the side of a lobe
    the closure lacks.  The pdf is that of ``microfacet_sample`` (P_R or P_T times the
    visible-normal density mapped to directions).
    """
    ax = cl[k, CL_AX]
    ay = cl[k, CL_AY]
    if not woz > 0.0 or not ax * ay > ROUGHNESS_SQ_THRESHOLD:
        return 0.0, 0.0, 0.0, 0.0
    ctype = int(cl[k, CL_TYPE])
    is_t = wiz < 0.0
    if (is_t and ctype == CT_MICROFACET) or (not is_t and ctype == CT_MICROFACET_REFRACTION):
        return 0.0, 0.0, 0.0, 0.0
    eta = cl[k, CL_ETA]
    if is_t:
        hx = -(eta * wix + wox)
        hy = -(eta * wiy + woy)
        hz = -(eta * wiz + woz)
    else:
        hx = wox + wix
        hy = woy + wiy
        hz = woz + wiz
    len2 = hx * hx + hy * hy + hz * hz
    if not len2 > 0.0:
        return 0.0, 0.0, 0.0, 0.0
    inv_len = 1.0 / math.sqrt(len2)
    hx *= inv_len
    hy *= inv_len
    hz *= inv_len
    cos_hi = hx * wox + hy * woy + hz * woz
    rr, rg, rb, tr, tg, tb, _ = microfacet_fresnel(cl, k, cos_hi)
    avg_r = (rr + rg + rb) * (1.0 / 3.0)
    avg_t = (tr + tg + tb) * (1.0 / 3.0)
    if not avg_r + avg_t > 0.0:
        return 0.0, 0.0, 0.0, 0.0
    dist = int(cl[k, CL_DIST])
    if is_t:
        ax = ay = math.sqrt(ax * ay)      # transmission is isotropic
    d = microfacet_D(dist, ax, ay, hx, hy, hz)
    lam_o = microfacet_lambda(dist, ax, ay, wox, woy, woz)
    lam_i = microfacet_lambda(dist, ax, ay, wix, wiy, wiz)
    p_r = avg_r / (avg_r + avg_t)
    if is_t:
        ei = eta * inv_len
        common = d / woz * ei * ei * abs(cos_hi * (hx * wix + hy * wiy + hz * wiz))
        lobe = 1.0 - p_r
        cr, cg, cb = tr, tg, tb
    else:
        common = d / woz * 0.25
        lobe = p_r
        cr, cg, cb = rr, rg, rb
    pdf = common * lobe / (1.0 + lam_o)
    f = common / (1.0 + lam_o + lam_i)
    if dist == MD_GGX:
        f *= cl[k, CL_ENERGY]
    return cr * f, cg * f, cb * f, pdf


@device
def microfacet_sample(cl, k, wox, woy, woz, u1, u2, u3):
    """(wix, wiy, wiz, r, g, b, pdf, label) of a microfacet row (Cycles' bsdf_microfacet_sample).

    u1, u2 pick the visible normal, u3 reflection (u3 < P_R) or refraction.  Non-singular:
    (r, g, b) = f cos as ``microfacet_eval`` returns it and pdf its pdf.  Singular: pdf = 0
    and (r, g, b) = R / P_R or T / P_T (times CL_ENERGY for GGX).  LABEL_NONE and zeros when
    the view is below the surface, the Fresnel leaves nothing, or the direction lands on
    the wrong side of the shading normal.
    """
    if not woz > 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
    ax = cl[k, CL_AX]
    ay = cl[k, CL_AY]
    singular = not ax * ay > ROUGHNESS_SQ_THRESHOLD
    dist = int(cl[k, CL_DIST])
    if singular:
        hx, hy, hz = 0.0, 0.0, 1.0
    elif dist == MD_GGX:
        hx, hy, hz = ggx_sample_vndf(wox, woy, woz, ax, ay, u1, u2)
    else:
        hx, hy, hz = beckmann_sample_vndf(wox, woy, woz, ax, ay, u1, u2)
    cos_hi = hx * wox + hy * woy + hz * woz
    rr, rg, rb, tr, tg, tb, cos_t = microfacet_fresnel(cl, k, cos_hi)
    avg_r = (rr + rg + rb) * (1.0 / 3.0)
    avg_t = (tr + tg + tb) * (1.0 / 3.0)
    if not avg_r + avg_t > 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
    p_r = avg_r / (avg_r + avg_t)
    refract = u3 >= p_r
    eta = cl[k, CL_ETA]
    if refract:
        inv_eta = 1.0 / eta if eta != 0.0 else 0.0
        a = inv_eta * cos_hi - cos_t
        wix = a * hx - inv_eta * wox
        wiy = a * hy - inv_eta * woy
        wiz = a * hz - inv_eta * woz
    else:
        a = 2.0 * cos_hi
        wix = a * hx - wox
        wiy = a * hy - woy
        wiz = a * hz - woz
    if (wiz < 0.0) != refract:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
    if refract:
        cr, cg, cb = tr, tg, tb
        lobe = 1.0 - p_r
        singular = singular or abs(eta - 1.0) < 1e-4
        label = LABEL_TRANSMIT
    else:
        cr, cg, cb = rr, rg, rb
        lobe = p_r
        label = LABEL_REFLECT
    energy = cl[k, CL_ENERGY] if dist == MD_GGX else 1.0
    if singular:
        # R / P_R, divided last: with a subnormal R (and P_R), 1 / P_R alone overflows.
        return (wix, wiy, wiz, cr * energy / lobe, cg * energy / lobe, cb * energy / lobe, 0.0,
                label | LABEL_SINGULAR)
    if refract:
        ax = ay = math.sqrt(ax * ay)      # transmission is isotropic
    d = microfacet_D(dist, ax, ay, hx, hy, hz)
    lam_o = microfacet_lambda(dist, ax, ay, wox, woy, woz)
    lam_i = microfacet_lambda(dist, ax, ay, wix, wiy, wiz)
    if refract:
        den = inv_eta * cos_hi - cos_t
        common = d / woz * abs(cos_hi * cos_t) / (den * den)
    else:
        common = d / woz * 0.25
    pdf = common * lobe / (1.0 + lam_o)
    f = common / (1.0 + lam_o + lam_i) * energy
    return wix, wiy, wiz, cr * f, cg * f, cb * f, pdf, label | LABEL_GLOSSY


# -- setup ------------------------------------------------------------------------------------------
@device
def microfacet_setup(cl, k):
    """Clamp alpha to [0, 1]; refraction and glass rows become isotropic (alpha_y = alpha_x); CL_ENERGY = 1.

    Cycles' bsdf_microfacet_{ggx,beckmann}{,_refraction,_glass}_setup.  Call it after
    filling CL_AX, CL_AY and CL_TYPE, before any of the Fresnel setups below.
    """
    ax = saturate(cl[k, CL_AX])
    cl[k, CL_AX] = ax
    if int(cl[k, CL_TYPE]) == CT_MICROFACET:
        cl[k, CL_AY] = saturate(cl[k, CL_AY])
    else:
        cl[k, CL_AY] = ax
    cl[k, CL_ENERGY] = 1.0


@device
def _ior_z(eta):
    return math.sqrt(abs((eta - 1.0) / (eta + 1.0)))


@device
def _smooth_fresnel_unused(cl, k, with_reflection, with_transmission):
    """Whether ``microfacet_albedo`` would discard the smooth Fresnel at the view: an FR_SCHLICK
    row with exponent < 0, no film and no transmission asked for, whose reflection is not zero
    in some channel (RTINT, F0 and F90 all positive there, so mix(F0, F90, s) > 0 for every s):
    its albedo is the table's reflection alone."""
    if not with_reflection or int(cl[k, CL_FRESNEL]) != FR_SCHLICK or not cl[k, CL_EXPONENT] < 0.0:
        return False
    ctype = int(cl[k, CL_TYPE])
    if ctype != CT_MICROFACET and (ctype != CT_MICROFACET_GLASS or with_transmission):
        return False
    if cl[k, CL_FILM_THICKNESS] > THIN_FILM_CUTOFF:
        return False
    for c in range(3):
        if cl[k, CL_RTINT + c] != 0.0 and cl[k, CL_F0 + c] > 0.0 and cl[k, CL_F90 + c] > 0.0:
            return True
    return False


@device
def microfacet_albedo(cl, k, cos_no, with_reflection, with_transmission):
    """Estimated albedo RGB (R + T, without CL_W) for a view at cosine cos_no (Cycles' bsdf_microfacet_estimate_albedo).

    The smooth-surface Fresnel at cos_no, except for the reflection of FR_SCHLICK
    (mix(F0, F90, s) x CL_RTINT with s from GGX_GEN_SCHLICK_IOR_S for exponent < 0, else
    GGX_GEN_SCHLICK_S at z = 1 / (0.2 exponent + 1)), FR_F82 (mix(F0, 1, s), s from
    GGX_GEN_SCHLICK_S at z = 0.5, B ignored) and FR_DIELECTRIC with eta > 1
    (mix(F0(eta), 1, s) from GGX_GEN_SCHLICK_IOR_S), all read at r = (ax ay)^(1/4),
    whatever the distribution.  Transmission is always the smooth (1 - F) x tint (and the
    conductor's reflection, and any reflection under a thin film, the smooth Fresnel:
    Cycles has no table for them).  The smooth Fresnel is not computed where none of it
    would be used (``_smooth_fresnel_unused``: the Principled's specular layer).
    """
    model = int(cl[k, CL_FRESNEL])
    eta = cl[k, CL_ETA]
    if _smooth_fresnel_unused(cl, k, with_reflection, with_transmission):
        tr = tg = tb = 0.0
    else:
        rr, rg, rb, tr, tg, tb, _ = microfacet_fresnel(cl, k, cos_no)
        if not with_reflection:
            rr = rg = rb = 0.0
        if not with_transmission:
            tr = tg = tb = 0.0
        if rr == 0.0 and rg == 0.0 and rb == 0.0:
            return tr, tg, tb
        if cl[k, CL_FILM_THICKNESS] > THIN_FILM_CUTOFF and model != FR_DIELECTRIC:
            return rr + tr, rg + tg, rb + tb
        if not (model == FR_SCHLICK or model == FR_F82 or (model == FR_DIELECTRIC and eta > 1.0)):
            return rr + tr, rg + tg, rb + tb
    if model == FR_SCHLICK:
        e = cl[k, CL_EXPONENT]
        table = GGX_GEN_SCHLICK_IOR_S if e < 0.0 else GGX_GEN_SCHLICK_S
        z = _ior_z(eta) if e < 0.0 else 1.0 / (0.2 * e + 1.0)
    elif model == FR_F82:
        table = GGX_GEN_SCHLICK_S
        z = 0.5
    else:
        table = GGX_GEN_SCHLICK_IOR_S
        z = _ior_z(eta)
    s = lookup_3d(table, math.sqrt(math.sqrt(cl[k, CL_AX] * cl[k, CL_AY])), cos_no, z)
    if model == FR_SCHLICK:
        rr = (cl[k, CL_F0] + (cl[k, CL_F90] - cl[k, CL_F0]) * s) * cl[k, CL_RTINT]
        rg = (cl[k, CL_F0 + 1] + (cl[k, CL_F90 + 1] - cl[k, CL_F0 + 1]) * s) * cl[k, CL_RTINT + 1]
        rb = (cl[k, CL_F0 + 2] + (cl[k, CL_F90 + 2] - cl[k, CL_F0 + 2]) * s) * cl[k, CL_RTINT + 2]
    elif model == FR_F82:
        rr = cl[k, CL_F0] + (1.0 - cl[k, CL_F0]) * s
        rg = cl[k, CL_F0 + 1] + (1.0 - cl[k, CL_F0 + 1]) * s
        rb = cl[k, CL_F0 + 2] + (1.0 - cl[k, CL_F0 + 2]) * s
    else:
        f0 = F0_from_ior(eta)
        rr = rg = rb = f0 + (1.0 - f0) * s
    return rr + tr, rg + tg, rb + tb


@device
def microfacet_albedo_tables(cl, k, cos_no):
    """(E, E_avg) of the energy-compensation tables for this row (1, 1 when it has none).

    GGX reflection: GGX_E(r, mu), GGX_EAVG(r).  GGX glass: GGX_GLASS_E(r, mu, z),
    GGX_GLASS_EAVG(r, z), or the _INV_ tables read at 1/eta when eta < 1.  Everything else
    (Beckmann, refraction) is not compensated, as in Cycles.
    """
    if int(cl[k, CL_DIST]) != MD_GGX:
        return 1.0, 1.0
    ctype = int(cl[k, CL_TYPE])
    if ctype == CT_MICROFACET:
        e_table, avg_table, z = GGX_E_3D, GGX_EAVG_2D, 0.0
    elif ctype == CT_MICROFACET_GLASS:
        eta = cl[k, CL_ETA]
        if eta < 1.0:
            e_table, avg_table, z = GGX_GLASS_INV_E, GGX_GLASS_INV_EAVG, _ior_z(1.0 / eta)
        else:
            e_table, avg_table, z = GGX_GLASS_E, GGX_GLASS_EAVG, _ior_z(eta)
    else:
        return 1.0, 1.0
    rough = math.sqrt(math.sqrt(cl[k, CL_AX] * cl[k, CL_AY]))
    return lookup_3d(e_table, rough, cos_no, z), lookup_2d(avg_table, rough, z)


@device
def microfacet_preserve_energy(cl, k, cos_no, fss_r, fss_g, fss_b):
    """Multiple-scattering compensation (Cycles' microfacet_ggx_preserve_energy).

    CL_ENERGY = 1 + (1 - E) / E with E the albedo table at the view cosine cos_no.  If the
    single-scattering Fresnel Fss is not 1, the multiple scattering is darkened/saturated
    (Kulla-Conty): Fms = Fss E_avg / (1 - Fss (1 - E_avg)), and CL_W *= (1 + Fms (1 - E) / E)
    / CL_ENERGY per channel, CL_SW *= the mean of that factor.
    """
    e, e_avg = microfacet_albedo_tables(cl, k, cos_no)
    missing = (1.0 - e) / e
    energy = 1.0 + missing
    cl[k, CL_ENERGY] = energy
    if fss_r == 1.0 and fss_g == 1.0 and fss_b == 1.0:
        return
    inv_energy = 1.0 / energy
    # channels of equal Fss (a white tint: the Principled's specular) share one evaluation
    dark_r = _darkening(fss_r, e_avg, missing, inv_energy)
    dark_g = dark_r if fss_g == fss_r else _darkening(fss_g, e_avg, missing, inv_energy)
    dark_b = dark_g if fss_b == fss_g else _darkening(fss_b, e_avg, missing, inv_energy)
    cl[k, CL_W] *= dark_r
    cl[k, CL_W + 1] *= dark_g
    cl[k, CL_W + 2] *= dark_b
    cl[k, CL_SW] *= (dark_r + dark_g + dark_b) * (1.0 / 3.0)


@device
def _darkening(fss, e_avg, missing, inv_energy):
    """Kulla-Conty: (1 + Fms (1 - E) / E) / energy with Fms = Fss E_avg / (1 - Fss (1 - E_avg))."""
    fms = fss * e_avg / (1.0 - fss * (1.0 - e_avg))
    return (1.0 + fms * missing) * inv_energy


microfacet_estimate_albedo = microfacet_albedo     # Cycles' name


@device
def microfacet_setup_sample_weight(cl, k, cos_no):
    """CL_SW *= the mean albedo estimate R + T at the view (what every Cycles Fresnel setup does
    first); the estimate is kept in CL_ALBEDO for the layering of the closures below."""
    r, g, b = microfacet_albedo(cl, k, cos_no, True, True)
    cl[k, CL_SW] *= (r + g + b) * (1.0 / 3.0)
    cl[k, CL_ALBEDO], cl[k, CL_ALBEDO + 1], cl[k, CL_ALBEDO + 2] = r, g, b


@device
def f82_tint_b(cl, k, tint_r, tint_g, tint_b):
    """Write the F82 B term for CL_F0 and a tint (Principled: min(Specular Tint, 1)) into CL_F90.

    B = 0 exactly when the tint is white (Cycles skips fresnel_f82tint_B then).
    """
    white = tint_r == 1.0 and tint_g == 1.0 and tint_b == 1.0
    for c in range(3):
        tint = tint_r if c == 0 else (tint_g if c == 1 else tint_b)
        cl[k, CL_F90 + c] = 0.0 if white else f82_tint_B(cl[k, CL_F0 + c], tint)


@device
def microfacet_setup_fresnel_dielectric(cl, k, cos_no):
    """FR_DIELECTRIC (Cycles' bsdf_microfacet_setup_fresnel_dielectric, the coat).

    CL_SW *= mean albedo estimate; energy is always preserved, with Fss =
    fresnel_dielectric_Fss(CL_ETA).
    """
    cl[k, CL_FRESNEL] = FR_DIELECTRIC
    microfacet_setup_sample_weight(cl, k, cos_no)
    fss = fresnel_dielectric_Fss(cl[k, CL_ETA])
    microfacet_preserve_energy(cl, k, cos_no, fss, fss, fss)


@device
def microfacet_setup_fresnel_schlick(cl, k, cos_no, preserve_energy):
    """FR_SCHLICK (Cycles' bsdf_microfacet_setup_fresnel_generalized_schlick).

    Expects CL_F0, CL_F90, CL_EXPONENT, CL_RTINT, CL_TTINT, CL_ETA filled.  F0 is clamped
    to [0, 1], CL_SW *= mean albedo estimate.  With ``preserve_energy``: Fss = CL_TTINT if
    the transmission tint is not zero, else CL_RTINT x mix(F0, F90, s) with
    s = clamp((Fss_dielectric(eta) - F0(eta)) / (1 - F0(eta))) for exponent < 0 and
    s = 2 / ((e + 3) e + 2) (the integral of 2 cos (1 - cos)^e) otherwise.
    """
    for c in range(3):
        cl[k, CL_F0 + c] = saturate(cl[k, CL_F0 + c])
    cl[k, CL_FRESNEL] = FR_SCHLICK
    microfacet_setup_sample_weight(cl, k, cos_no)
    if not preserve_energy:
        return
    if cl[k, CL_TTINT] == 0.0 and cl[k, CL_TTINT + 1] == 0.0 and cl[k, CL_TTINT + 2] == 0.0:
        e = cl[k, CL_EXPONENT]
        if e < 0.0:
            eta = cl[k, CL_ETA]
            f0 = F0_from_ior(eta)
            s = saturate((fresnel_dielectric_Fss(eta) - f0) / (1.0 - f0))
        else:
            s = 2.0 / ((e + 3.0) * e + 2.0)
        fr = cl[k, CL_RTINT] * (cl[k, CL_F0] + (cl[k, CL_F90] - cl[k, CL_F0]) * s)
        fg = cl[k, CL_RTINT + 1] * (cl[k, CL_F0 + 1] + (cl[k, CL_F90 + 1] - cl[k, CL_F0 + 1]) * s)
        fb = cl[k, CL_RTINT + 2] * (cl[k, CL_F0 + 2] + (cl[k, CL_F90 + 2] - cl[k, CL_F0 + 2]) * s)
    else:
        fr, fg, fb = cl[k, CL_TTINT], cl[k, CL_TTINT + 1], cl[k, CL_TTINT + 2]
    microfacet_preserve_energy(cl, k, cos_no, fr, fg, fb)


@device
def microfacet_setup_fresnel_f82_tint(cl, k, cos_no, tint_r, tint_g, tint_b, preserve_energy):
    """FR_F82 (Cycles' bsdf_microfacet_setup_fresnel_f82_tint).

    Expects CL_F0 filled; writes B = f82_tint_B(F0, tint) to CL_F90 (0 when the tint is
    exactly white), CL_SW *= mean albedo estimate, and with ``preserve_energy`` compensates
    with Fss = fresnel_f82_Fss(F0, B).
    """
    f82_tint_b(cl, k, tint_r, tint_g, tint_b)
    cl[k, CL_FRESNEL] = FR_F82
    microfacet_setup_sample_weight(cl, k, cos_no)
    if preserve_energy:
        microfacet_preserve_energy(cl, k, cos_no,
                                   fresnel_f82_Fss(cl[k, CL_F0], cl[k, CL_F90]),
                                   fresnel_f82_Fss(cl[k, CL_F0 + 1], cl[k, CL_F90 + 1]),
                                   fresnel_f82_Fss(cl[k, CL_F0 + 2], cl[k, CL_F90 + 2]))


@device
def microfacet_setup_fresnel_conductor(cl, k, cos_no, preserve_energy):
    """FR_CONDUCTOR (Cycles' bsdf_microfacet_setup_fresnel_conductor).

    Expects n in CL_F0 and k in CL_F90; CL_SW *= mean albedo estimate, and with
    ``preserve_energy`` compensates with Fss = fresnel_conductor_Fss(n, k).
    """
    cl[k, CL_FRESNEL] = FR_CONDUCTOR
    microfacet_setup_sample_weight(cl, k, cos_no)
    if preserve_energy:
        microfacet_preserve_energy(cl, k, cos_no,
                                   fresnel_conductor_Fss(cl[k, CL_F0], cl[k, CL_F90]),
                                   fresnel_conductor_Fss(cl[k, CL_F0 + 1], cl[k, CL_F90 + 1]),
                                   fresnel_conductor_Fss(cl[k, CL_F0 + 2], cl[k, CL_F90 + 2]))


@device
def microfacet_setup_fresnel_constant(cl, k, cos_no, color_r, color_g, color_b):
    """Energy compensation of an FR_NONE row whose colour is in its weight.

    Cycles' bsdf_microfacet_setup_fresnel_constant.

    The Multiscatter GGX Glossy BSDF: Fss = the node's Color (clamped >= 0 by the caller),
    not the mixed weight.  The Fresnel model (FR_NONE) and the sample weight are left alone.
    """
    microfacet_preserve_energy(cl, k, cos_no, color_r, color_g, color_b)
