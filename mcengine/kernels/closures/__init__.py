"""Closures: how surfaces scatter light, as lists of weighted lobes (Cycles' closures).

A shading point's material evaluates (``kernels.svm``) to a short list of
closures in the array ``cl`` (layout and codes: ``layout``).  One module per
family computes a closure's ``eval`` (f·|cos θ_i| and pdf) and ``sample`` in
its local frame: ``diffuse`` (Lambert, Oren–Nayar, translucent),
``microfacet`` (GGX and Beckmann reflection, refraction and glass, with the
Fresnel models of ``fresnel`` and the energy-compensation ``tables``), ``sheen``,
``ashikhmin`` (Ashikhmin-Shirley and the velvet), ``toon`` (the Toon BSDF's two lobes),
``hair`` (the Hair BSDF's two) and ``bssrdf`` (subsurface scattering, which only picks the
way in).  This module combines
them as Cycles' surface_shader.h does:

* ``bsdf_eval``: F = Σ w_k·eval_k over the closures whose pdf is not zero
  (closures whose label a light excludes add nothing to F but keep their pdf),
  pdf = Σ sw_k·pdf_k / Σ sw_k — one-sample MIS with the balance heuristic, the
  transparent closure counting in Σ sw_k only;
* ``bsdf_sample_closure``: picks closure k with probability sw_k / Σ sw_k, samples it
  and returns the throughput weight F / pdf of the whole list (for a singular
  lobe: w_k·(eval / pdf)·Σ sw / sw_k), the mixture pdf (0 for singular lobes),
  the lobe's label and k.  A BSSRDF (``bssrdf``) has no value: it only counts in Σ sw, and
  when picked gives the direction into the object with weight w_k·Σ sw / sw_k and the
  label LABEL_SUBSURFACE (the path tracer then walks inside).  A Ray Portal has no value
  either: when picked it gives its direction with weight w_k·Σ sw / sw_k and the label
  LABEL_RAY_PORTAL (the path tracer then moves the ray to the portal's point).

Every closure whose normal differs from the point's smooth normal (a normal map,
Bump Map Correction's lift of a glossy normal) carries Cycles' bump shadowing
term (``bump_shadowing``), in ``closure_eval`` and ``closure_sample``; on an object
with a Shadow Terminator Shading Offset, every closure's value is also scaled by
``shift_cos_in`` there.

Directions passed here are in world space: ``wo`` towards the viewer, ``wi``
towards the light or the sampled direction.
"""
from __future__ import annotations

import math

from ...jit import device, function
from ..sampling import orthonormal_basis
from .ashikhmin import ashikhmin_shirley_eval, ashikhmin_shirley_sample, velvet_eval, velvet_sample
from .bssrdf import bssrdf_entry
from .diffuse import (
    lambert_eval,
    lambert_sample,
    oren_nayar_eval,
    oren_nayar_sample,
    translucent_eval,
    translucent_sample,
)
from .hair import hair_eval, hair_sample
from .layout import (
    CL_BUMP_CORRECTION,
    CL_N,
    CL_NS,
    CL_PORTAL_D,
    CL_SSS_METHOD,
    CL_SW,
    CL_T,
    CL_TERMINATOR,
    CL_TYPE,
    CL_W,
    CT_ASHIKHMIN_SHIRLEY,
    CT_BSSRDF,
    CT_DIFFUSE,
    CT_DIFFUSE_TOON,
    CT_GLOSSY_TOON,
    CT_HAIR_REFLECTION,
    CT_HAIR_TRANSMISSION,
    CT_MICROFACET,
    CT_MICROFACET_GLASS,
    CT_MICROFACET_REFRACTION,
    CT_NONE,
    CT_OREN_NAYAR,
    CT_RAY_PORTAL,
    CT_SHEEN,
    CT_TRANSLUCENT,
    CT_TRANSPARENT,
    CT_VELVET,
    LABEL_DIFFUSE,
    LABEL_GLOSSY,
    LABEL_NONE,
    LABEL_RAY_PORTAL,
    LABEL_REFLECT,
    LABEL_SINGULAR,
    LABEL_SUBSURFACE,
    LABEL_TRANSMIT,
    LABEL_TRANSPARENT,
    SSS_BURLEY,
)
from .microfacet import ggx_lambda_q, microfacet_eval, microfacet_sample
from .sheen import sheen_eval, sheen_sample
from .toon import diffuse_toon_eval, diffuse_toon_sample, glossy_toon_eval, glossy_toon_sample

__all__ = ["bsdf_eval", "bsdf_sample", "bsdf_sample_closure", "closure_eval", "closure_sample", "LABEL_DIFFUSE",
           "LABEL_GLOSSY", "LABEL_NONE", "LABEL_REFLECT", "LABEL_SINGULAR", "LABEL_TRANSMIT",
           "LABEL_TRANSPARENT"]


@device
def frame(cl, k):
    """(t, b, n) of closure k: its normal, its tangent and n x t."""
    nx, ny, nz = cl[k, CL_N], cl[k, CL_N + 1], cl[k, CL_N + 2]
    tx, ty, tz = cl[k, CL_T], cl[k, CL_T + 1], cl[k, CL_T + 2]
    if tx == 0.0 and ty == 0.0 and tz == 0.0:
        tx, ty, tz, bx, by, bz = orthonormal_basis(nx, ny, nz)
    else:
        bx, by, bz = ny * tz - nz * ty, nz * tx - nx * tz, nx * ty - ny * tx
    return tx, ty, tz, bx, by, bz, nx, ny, nz


@device
def is_diffuse(t):
    """Whether closures of type t are diffuse-like (Cycles' CLOSURE_IS_BSDF_DIFFUSE: sheen,
    translucent and diffuse toon included)."""
    return t == CT_DIFFUSE or t == CT_OREN_NAYAR or t == CT_SHEEN or t == CT_TRANSLUCENT \
        or t == CT_DIFFUSE_TOON


@device
def is_glossy_reflection(t):
    """Whether closures of type t only reflect, glossily (microfacet reflection,
    Ashikhmin-Shirley, glossy toon, hair reflection, and the velvet, which Cycles labels
    glossy)."""
    return t == CT_MICROFACET or t == CT_ASHIKHMIN_SHIRLEY or t == CT_VELVET or t == CT_GLOSSY_TOON \
        or t == CT_HAIR_REFLECTION


@device
def has_transmission(t):
    """Whether closures of type t send light through the surface (Cycles'
    SD_BSDF_HAS_TRANSMISSION: translucent, microfacet refraction and glass, hair
    transmission)."""
    return t == CT_TRANSLUCENT or t == CT_MICROFACET_REFRACTION or t == CT_MICROFACET_GLASS \
        or t == CT_HAIR_TRANSMISSION


@device
def free_side(t):
    """Whether directions sampled from closures of type t may leave to either side of the
    geometric surface (Cycles checks no side for hair and portals; the others' samples
    must leave to the side their label says: ``shading.leaves_correct_side``)."""
    return t == CT_HAIR_REFLECTION or t == CT_HAIR_TRANSMISSION or t == CT_RAY_PORTAL


@device
def bump_shadowing(cl, k, diffuse, is_eval, wix, wiy, wiz):
    """Cycles' bump_shadowing_term: the factor on closure k's value towards wi when its normal
    N differs from the point's smooth normal Ns.

    0 when wi lies on the other side of Ns than N says (light leaking through the surface;
    on evaluation for every closure, on sampling for diffuse ones); diffuse closures of a
    material with Bump Map Correction are then darkened towards grazing wi by a GGX
    shadowing G1(alpha², |Ns·wi|) with alpha² = min(tan²(N, Ns) / 8, 1) (Conty et al.,
    "A Microfacet-Based Shadowing Function to Solve the Bump Terminator Problem").  The pdf
    is left alone, as in Cycles.
    """
    nx, ny, nz = cl[k, CL_N], cl[k, CL_N + 1], cl[k, CL_N + 2]
    sx, sy, sz = cl[k, CL_NS], cl[k, CL_NS + 1], cl[k, CL_NS + 2]
    if nx == sx and ny == sy and nz == sz:
        return 1.0
    cos_si = sx * wix + sy * wiy + sz * wiz
    cos_sn = sx * nx + sy * ny + sz * nz
    cos_ni = nx * wix + ny * wiy + nz * wiz
    if cos_si * cos_sn * cos_ni < 0.0 and (is_eval or diffuse):
        return 0.0
    if not diffuse or cl[k, CL_BUMP_CORRECTION] == 0.0:
        return 1.0
    cos_i, cos_d = abs(cos_si), abs(cos_sn)
    if cos_d >= 1.0 or cos_i >= 1.0:
        return 1.0
    if cos_i < 1e-6:
        return 0.0
    alpha2 = min(max(0.125 * (1.0 / (cos_d * cos_d) - 1.0), 0.0), 1.0)
    return 1.0 / (1.0 + ggx_lambda_q(alpha2 * max(1.0 / (cos_i * cos_i) - 1.0, 0.0)))


@device
def shift_cos_in(cos_in, frequency):
    """Cycles' shift_cos_in (from appleseed), the Shadow Terminator Shading Offset: the
    factor cos(frequency * theta_i) / cos(theta_i) on a closure's value towards a direction
    theta_i from its normal (frequency 1 / (1 - offset / 2) > 1 moves the diffuse terminator
    towards the light, where it is 0 from theta_i = pi / (2 frequency) on).  Cycles divides
    by a zero cosine; here a direction at or below the surface keeps its value."""
    if not cos_in > 0.0:
        return 1.0
    cos_in = min(cos_in, 1.0)
    return max(math.cos(math.acos(cos_in) * frequency), 0.0) / cos_in


@device
def diffuse_closure_eval(cl, k, t, wix, wiy, wiz):
    """``closure_eval`` of a Lambert or translucent closure k (type t): they read only the
    light's cosine to the normal, so no frame is built; inlined where closure lists are
    summed (``_eval_sum``), which saves the call for the commonest closure."""
    shadowing = bump_shadowing(cl, k, True, True, wix, wiy, wiz)
    if shadowing == 0.0:
        return 0.0, 0.0, 0.0, 0.0
    liz = cl[k, CL_N] * wix + cl[k, CL_N + 1] * wiy + cl[k, CL_N + 2] * wiz
    if t == CT_DIFFUSE:
        r, g, b, pdf = lambert_eval(cl, k, 0.0, 0.0, 0.0, 0.0, 0.0, liz)
    else:
        r, g, b, pdf = translucent_eval(cl, k, 0.0, 0.0, 0.0, 0.0, 0.0, liz)
    if cl[k, CL_TERMINATOR] > 1.0:
        shadowing *= shift_cos_in(liz, cl[k, CL_TERMINATOR])
    return r * shadowing, g * shadowing, b * shadowing, pdf


@function
def closure_eval(cl, k, wox, woy, woz, wix, wiy, wiz):
    """(r, g, b, pdf) of closure k for world directions, without its weight (times the bump
    shadowing term; a direction it rejects has pdf 0)."""
    t = cl[k, CL_TYPE]
    if t == CT_DIFFUSE or t == CT_TRANSLUCENT:
        return diffuse_closure_eval(cl, k, t, wix, wiy, wiz)
    shadowing = bump_shadowing(cl, k, is_diffuse(t), True, wix, wiy, wiz)
    if shadowing == 0.0:
        return 0.0, 0.0, 0.0, 0.0
    tx, ty, tz, bx, by, bz, nx, ny, nz = frame(cl, k)
    lox, loy, loz = wox * tx + woy * ty + woz * tz, wox * bx + woy * by + woz * bz, wox * nx + woy * ny + woz * nz
    lix, liy, liz = wix * tx + wiy * ty + wiz * tz, wix * bx + wiy * by + wiz * bz, wix * nx + wiy * ny + wiz * nz
    if t == CT_OREN_NAYAR:
        r, g, b, pdf = oren_nayar_eval(cl, k, lox, loy, loz, lix, liy, liz)
    elif t == CT_ASHIKHMIN_SHIRLEY:
        r, g, b, pdf = ashikhmin_shirley_eval(cl, k, lox, loy, loz, lix, liy, liz)
    elif t == CT_VELVET:
        r, g, b, pdf = velvet_eval(cl, k, lox, loy, loz, lix, liy, liz)
    elif t == CT_SHEEN:
        r, g, b, pdf = sheen_eval(cl, k, lox, loy, loz, lix, liy, liz)
    elif t == CT_DIFFUSE_TOON:
        r, g, b, pdf = diffuse_toon_eval(cl, k, lox, loy, loz, lix, liy, liz)
    elif t == CT_GLOSSY_TOON:
        r, g, b, pdf = glossy_toon_eval(cl, k, lox, loy, loz, lix, liy, liz)
    elif t == CT_HAIR_REFLECTION or t == CT_HAIR_TRANSMISSION:
        r, g, b, pdf = hair_eval(cl, k, t == CT_HAIR_TRANSMISSION, lox, loy, loz, lix, liy, liz)
    elif t == CT_MICROFACET or t == CT_MICROFACET_REFRACTION or t == CT_MICROFACET_GLASS:
        r, g, b, pdf = microfacet_eval(cl, k, lox, loy, loz, lix, liy, liz)
    else:
        return 0.0, 0.0, 0.0, 0.0
    if cl[k, CL_TERMINATOR] > 1.0:
        shadowing *= shift_cos_in(liz, cl[k, CL_TERMINATOR])
    return r * shadowing, g * shadowing, b * shadowing, pdf


@function
def closure_sample(cl, k, wox, woy, woz, u1, u2, u3):
    """(wi world, r, g, b, pdf, label) from closure k (r, g, b: eval, or the weight
    eval / pdf of a singular lobe, which has pdf 0), without the closure's weight."""
    t = cl[k, CL_TYPE]
    tx, ty, tz, bx, by, bz, nx, ny, nz = frame(cl, k)
    lox, loy, loz = wox * tx + woy * ty + woz * tz, wox * bx + woy * by + woz * bz, wox * nx + woy * ny + woz * nz
    if t == CT_DIFFUSE:
        x, y, z, r, g, b, pdf, label = lambert_sample(cl, k, lox, loy, loz, u1, u2, u3)
    elif t == CT_OREN_NAYAR:
        x, y, z, r, g, b, pdf, label = oren_nayar_sample(cl, k, lox, loy, loz, u1, u2, u3)
    elif t == CT_TRANSLUCENT:
        x, y, z, r, g, b, pdf, label = translucent_sample(cl, k, lox, loy, loz, u1, u2, u3)
    elif t == CT_SHEEN:
        x, y, z, r, g, b, pdf, label = sheen_sample(cl, k, lox, loy, loz, u1, u2, u3)
    elif t == CT_MICROFACET or t == CT_MICROFACET_REFRACTION or t == CT_MICROFACET_GLASS:
        x, y, z, r, g, b, pdf, label = microfacet_sample(cl, k, lox, loy, loz, u1, u2, u3)
    elif t == CT_ASHIKHMIN_SHIRLEY:
        x, y, z, r, g, b, pdf, label = ashikhmin_shirley_sample(cl, k, lox, loy, loz, u1, u2, u3)
    elif t == CT_VELVET:
        x, y, z, r, g, b, pdf, label = velvet_sample(cl, k, lox, loy, loz, u1, u2, u3)
    elif t == CT_DIFFUSE_TOON:
        x, y, z, r, g, b, pdf, label = diffuse_toon_sample(cl, k, lox, loy, loz, u1, u2, u3)
    elif t == CT_GLOSSY_TOON:
        x, y, z, r, g, b, pdf, label = glossy_toon_sample(cl, k, lox, loy, loz, u1, u2, u3)
    elif t == CT_HAIR_REFLECTION or t == CT_HAIR_TRANSMISSION:
        x, y, z, r, g, b, pdf, label = hair_sample(cl, k, t == CT_HAIR_TRANSMISSION, lox, loy, loz,
                                                   u1, u2)
    elif t == CT_TRANSPARENT:
        return -wox, -woy, -woz, 1.0, 1.0, 1.0, 0.0, LABEL_TRANSMIT | LABEL_TRANSPARENT
    elif t == CT_RAY_PORTAL:
        return (cl[k, CL_PORTAL_D], cl[k, CL_PORTAL_D + 1], cl[k, CL_PORTAL_D + 2], 1.0, 1.0, 1.0,
                0.0, LABEL_TRANSMIT | LABEL_RAY_PORTAL)
    elif t == CT_BSSRDF:
        x, y, z, ok = bssrdf_entry(cl, k, lox, loy, loz, u1, u2)
        if not ok:
            return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
        # Christensen-Burley has no entry direction (so no side to check): its label is
        # LABEL_SUBSURFACE alone.
        label = LABEL_SUBSURFACE if cl[k, CL_SSS_METHOD] == SSS_BURLEY else LABEL_TRANSMIT | LABEL_SUBSURFACE
        return (x * tx + y * bx + z * nx, x * ty + y * by + z * ny, x * tz + y * bz + z * nz,
                1.0, 1.0, 1.0, 0.0, label)
    else:
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE
    wix, wiy, wiz = x * tx + y * bx + z * nx, x * ty + y * by + z * ny, x * tz + y * bz + z * nz
    if not (label & LABEL_TRANSMIT):     # Cycles leaves transmitted samples without these terms
        shadowing = bump_shadowing(cl, k, is_diffuse(t), False, wix, wiy, wiz)
        if cl[k, CL_TERMINATOR] > 1.0:
            shadowing *= shift_cos_in(z, cl[k, CL_TERMINATOR])
        r, g, b = r * shadowing, g * shadowing, b * shadowing
    return wix, wiy, wiz, r, g, b, pdf, label


@device
def portal_weight(cl, n):
    """The summed weight (r, g, b) of the Ray Portal closures among the first n: Cycles counts
    it in the transparency the data passes see (surface_shader_transparency)."""
    r = g = b = 0.0
    for k in range(n):
        if cl[k, CL_TYPE] == CT_RAY_PORTAL:
            r, g, b = r + cl[k, CL_W], g + cl[k, CL_W + 1], b + cl[k, CL_W + 2]
    return r, g, b


@device
def excluded(t, exclude):
    """Whether a light's ray-visibility switches (``exclude``, LABEL_* bits) hide
    closures of type t from it (Cycles' _surface_shader_exclude)."""
    if exclude == 0:
        return False
    if is_diffuse(t):
        return (exclude & LABEL_DIFFUSE) != 0
    if is_glossy_reflection(t):
        return (exclude & LABEL_GLOSSY) != 0
    if t == CT_MICROFACET_REFRACTION or t == CT_HAIR_TRANSMISSION:
        return (exclude & LABEL_TRANSMIT) != 0
    if t == CT_MICROFACET_GLASS:
        return (exclude & LABEL_GLOSSY) != 0 and (exclude & LABEL_TRANSMIT) != 0
    return False


@device
def _eval_sum(cl, n, skip, wox, woy, woz, wix, wiy, wiz, exclude, fr, fg, fb, sum_pdf, sum_sw):
    """Add every closure but ``skip`` to (F, Σ sw·pdf, Σ sw)."""
    for k in range(n):
        if k == skip:
            continue
        t = cl[k, CL_TYPE]
        if t == CT_NONE:
            continue
        sw = cl[k, CL_SW]
        sum_sw += sw
        if t == CT_TRANSPARENT or t == CT_RAY_PORTAL:
            continue
        if t == CT_DIFFUSE or t == CT_TRANSLUCENT:
            r, g, b, pdf = diffuse_closure_eval(cl, k, t, wix, wiy, wiz)
        else:
            r, g, b, pdf = closure_eval(cl, k, wox, woy, woz, wix, wiy, wiz)
        if pdf != 0.0:
            if not excluded(t, exclude):
                fr += cl[k, CL_W] * r
                fg += cl[k, CL_W + 1] * g
                fb += cl[k, CL_W + 2] * b
            sum_pdf += pdf * sw
    return fr, fg, fb, sum_pdf, sum_sw


@function
def bsdf_eval(cl, n, wox, woy, woz, wix, wiy, wiz, exclude):
    """(F r, g, b, pdf): the closure list's f·|cos| towards wi and its mixture pdf."""
    fr, fg, fb, sum_pdf, sum_sw = _eval_sum(cl, n, -1, wox, woy, woz, wix, wiy, wiz, exclude,
                                            0.0, 0.0, 0.0, 0.0, 0.0)
    return fr, fg, fb, (sum_pdf / sum_sw if sum_sw > 0.0 else 0.0)


@function
def bsdf_sample_closure(cl, n, wox, woy, woz, u_pick, u1, u2, u3):
    """Sample the closure list: (wi world, weight r, g, b, pdf, label, the row of the
    closure sampled (-1: none)).

    The weight is the path throughput factor F / pdf; pdf is the mixture pdf
    (0 for a singular lobe, which other closures cannot produce).  The row gives light
    tracing a singular lobe's normal and index of refraction, and the light passes the
    closure whose sampled value is part of F.
    """
    total = 0.0
    for k in range(n):
        if cl[k, CL_TYPE] != CT_NONE:
            total += cl[k, CL_SW]
    if not total > 0.0:
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE, -1
    target = u_pick * total
    acc = 0.0
    pick = -1
    for k in range(n):
        if cl[k, CL_TYPE] == CT_NONE:
            continue
        sw = cl[k, CL_SW]
        if sw > 0.0:
            pick = k
            if target < acc + sw:
                break
            acc += sw
    if pick < 0:
        return 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, LABEL_NONE, -1
    sw = cl[pick, CL_SW]
    wix, wiy, wiz, r, g, b, pdf, label = closure_sample(cl, pick, wox, woy, woz, u1, u2, u3)
    if label == LABEL_NONE:
        return wix, wiy, wiz, 0.0, 0.0, 0.0, 0.0, LABEL_NONE, pick
    if label & (LABEL_SINGULAR | LABEL_TRANSPARENT | LABEL_SUBSURFACE | LABEL_RAY_PORTAL):
        # A BSSRDF's weight: Cycles' surface_shader_bssrdf_sample_weight.
        k = total / sw
        return (wix, wiy, wiz, cl[pick, CL_W] * r * k, cl[pick, CL_W + 1] * g * k,
                cl[pick, CL_W + 2] * b * k, 0.0, label, pick)
    if not pdf > 0.0:
        return wix, wiy, wiz, 0.0, 0.0, 0.0, 0.0, LABEL_NONE, pick
    fr, fg, fb, sum_pdf, sum_sw = _eval_sum(cl, n, pick, wox, woy, woz, wix, wiy, wiz, 0,
                                            cl[pick, CL_W] * r, cl[pick, CL_W + 1] * g,
                                            cl[pick, CL_W + 2] * b, pdf * sw, sw)
    # sum_sw now counts every closure once (the picked one was given as the start).
    mix_pdf = sum_pdf / sum_sw
    if not (mix_pdf > 0.0 and math.isfinite(mix_pdf)):
        return wix, wiy, wiz, 0.0, 0.0, 0.0, 0.0, LABEL_NONE, pick
    return wix, wiy, wiz, fr / mix_pdf, fg / mix_pdf, fb / mix_pdf, mix_pdf, label, pick
