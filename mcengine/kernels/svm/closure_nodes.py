"""Closure nodes: how each BSDF node turns its inputs into closures (kernel/svm/closure.h).

``eval_closure_node`` is called by the evaluator for every ``OP_CLOSURE``
with the node's input registers and its mix weight; it appends the node's
closures to the closure list and returns the node's emission, transparency
and holdout.  The Principled BSDF follows Cycles' closure order and layering:
alpha -> sheen -> coat (with its tint) -> emission -> metallic -> transmission
-> dielectric specular -> diffuse and subsurface (a BSSRDF closure).  The
layers (sheen, coat, specular) pass weight x (1 - max(albedo / weight))
downward, the albedo being the layer's directional albedo at the view
direction; metallic and transmission mix instead.

Closures are not built when ``sd.allocate`` is false (terminated and shadow
paths, as Cycles' zero closure budget): then the layers do not attenuate the
emission below them, but alpha and the coat tint still do, as in Cycles 5.0.
"""
from __future__ import annotations

import math

from ...jit import device, function
from ..closures import microfacet as mf
from ..closures.ashikhmin import AS_MIN_ALPHA
from ..closures.bssrdf import BSSRDF_MIN_RADIUS, bssrdf_radius
from ..closures.diffuse import oren_nayar_setup
from ..closures.fresnel import F0_from_ior, ior_from_F0
from ..closures.hair import hair_setup
from ..closures.layout import (
    CL_ALBEDO,
    CL_ANISOTROPY,
    CL_AX,
    CL_AY,
    CL_BUMP_CORRECTION,
    CL_DIST,
    CL_ENERGY,
    CL_ETA,
    CL_EXPONENT,
    CL_F0,
    CL_F90,
    CL_FILM_IOR,
    CL_FILM_THICKNESS,
    CL_FRESNEL,
    CL_N,
    CL_NS,
    CL_PORTAL_D,
    CL_PORTAL_P,
    CL_RADIUS,
    CL_RTINT,
    CL_SSS_ALBEDO,
    CL_SSS_METHOD,
    CL_STRIDE,
    CL_SW,
    CL_T,
    CL_TTINT,
    CL_TYPE,
    CL_VELVET_INV_SIGMA2,
    CL_W,
    CLOSURE_WEIGHT_CUTOFF,
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
    FR_NONE,
    MAX_CLOSURES,
    MD_BECKMANN,
    MD_GGX,
    SSS_BURLEY,
    SSS_RANDOM_WALK_SKIN,
)
from ..closures.sheen import sheen_setup
from ..closures.thin_film import THIN_FILM_CUTOFF
from ..closures.toon import toon_setup
from ..sampling import orthonormal_basis
from ..scalar import saturate
from ..state import PF_DIFFUSE_ANCESTOR
from .math_nodes import rotate_around_axis
from .nodes import (
    COLOR_IN,
    D_NORMAL,
    D_ROUGHNESS,
    DIST_ASHIKHMIN,
    DIST_ASHIKHMIN_SHIRLEY,
    DIST_BECKMANN,
    DIST_MULTI_GGX,
    E_STRENGTH,
    FRESNEL_PHYSICAL_CONDUCTOR,
    G_ANISOTROPY,
    G_DISTRIBUTION,
    G_NORMAL,
    G_ROTATION,
    G_ROUGHNESS,
    G_TANGENT,
    GL_DISTRIBUTION,
    GL_IOR,
    GL_NORMAL,
    GL_ROUGHNESS,
    GL_THIN_FILM,
    GL_THIN_FILM_IOR,
    H_COMPONENT,
    H_IMPLICIT_TANGENT,
    H_OFFSET,
    H_ROUGHNESS_U,
    H_ROUGHNESS_V,
    H_TANGENT,
    HAIR_TRANSMISSION,
    K_BACKGROUND,
    K_DIFFUSE,
    K_EMISSION,
    K_GLASS,
    K_GLOSSY,
    K_HAIR,
    K_HOLDOUT,
    K_METALLIC,
    K_PRINCIPLED,
    K_RAY_PORTAL,
    K_REFRACTION,
    K_SHEEN,
    K_SUBSURFACE,
    K_TOON,
    K_TRANSLUCENT,
    K_TRANSPARENT,
    M_ANISOTROPY,
    M_BASE_COLOR,
    M_DISTRIBUTION,
    M_EDGE_TINT,
    M_EXTINCTION,
    M_FRESNEL,
    M_IOR,
    M_NORMAL,
    M_ROTATION,
    M_ROUGHNESS,
    M_TANGENT,
    M_THIN_FILM,
    M_THIN_FILM_IOR,
    P_ALPHA,
    P_ANISOTROPIC,
    P_ANISOTROPIC_ROTATION,
    P_BASE_COLOR,
    P_COAT_IOR,
    P_COAT_NORMAL,
    P_COAT_ROUGHNESS,
    P_COAT_TINT,
    P_COAT_WEIGHT,
    P_DIFFUSE_ROUGHNESS,
    P_DISTRIBUTION,
    P_EMISSION_COLOR,
    P_EMISSION_STRENGTH,
    P_IOR,
    P_METALLIC,
    P_NORMAL,
    P_ROUGHNESS,
    P_SHEEN_ROUGHNESS,
    P_SHEEN_TINT,
    P_SHEEN_WEIGHT,
    P_SPECULAR_LEVEL,
    P_SPECULAR_TINT,
    P_SUBSURFACE_ANISOTROPY,
    P_SUBSURFACE_IOR,
    P_SUBSURFACE_METHOD,
    P_SUBSURFACE_RADIUS,
    P_SUBSURFACE_SCALE,
    P_SUBSURFACE_WEIGHT,
    P_TANGENT,
    P_THIN_FILM,
    P_THIN_FILM_IOR,
    P_TRANSMISSION,
    R_DISTRIBUTION,
    R_IOR,
    R_NORMAL,
    R_ROUGHNESS,
    RP_DIRECTION,
    RP_POSITION,
    S_DISTRIBUTION,
    S_NORMAL,
    S_ROUGHNESS,
    SS_ANISOTROPY,
    SS_FALLOFF,
    SS_IOR,
    SS_NORMAL,
    SS_RADIUS,
    SS_ROUGHNESS,
    SS_SCALE,
    T_COMPONENT,
    T_NORMAL,
    T_SIZE,
    T_SMOOTH,
    TL_NORMAL,
    TOON_GLOSSY,
)


# -- allocation and frames ------------------------------------------------------------------------
@device
def alloc(cl, n, wr, wg, wb, sd):
    """Append a closure of weight (wr, wg, wb) (negatives clamped to 0); returns (k, n).

    k = -1 when nothing is allocated: closures are off at this point, the weight
    is below Cycles' cutoff, or the list is full.
    """
    wr, wg, wb = max(wr, 0.0), max(wg, 0.0), max(wb, 0.0)
    sw = abs((wr + wg + wb) / 3.0)
    if not sd.allocate or not sw >= CLOSURE_WEIGHT_CUTOFF or n >= MAX_CLOSURES:
        return -1, n
    for c in range(CL_STRIDE):
        cl[n, c] = 0.0
    cl[n, CL_W], cl[n, CL_W + 1], cl[n, CL_W + 2] = wr, wg, wb
    cl[n, CL_SW] = sw
    cl[n, CL_ENERGY] = 1.0
    # What the bump shadowing term (closures.bump_shadowing) compares the closure's normal with.
    cl[n, CL_NS], cl[n, CL_NS + 1], cl[n, CL_NS + 2] = sd.nx, sd.ny, sd.nz
    cl[n, CL_BUMP_CORRECTION] = 1.0 if sd.bump_correction else 0.0
    return n, n + 1


@device
def input_normal(regs, off, sd):
    """A Normal input: the linked vector normalised, or the shading normal when unlinked."""
    x, y, z = regs[off], regs[off + 1], regs[off + 2]
    length = math.sqrt(x * x + y * y + z * z)
    if not length > 0.0:
        return sd.nx, sd.ny, sd.nz
    return x / length, y / length, z / length


@device
def set_frame(cl, k, nx, ny, nz, tx, ty, tz):
    """Normal and tangent of closure k; the tangent is made orthogonal to the normal
    (Cycles' make_orthonormals_tangent), or chosen freely when zero."""
    cl[k, CL_N], cl[k, CL_N + 1], cl[k, CL_N + 2] = nx, ny, nz
    # Y = normalize(N x T), X = Y x N.
    yx, yy, yz = ny * tz - nz * ty, nz * tx - nx * tz, nx * ty - ny * tx
    length = math.sqrt(yx * yx + yy * yy + yz * yz)
    if length > 0.0:
        yx, yy, yz = yx / length, yy / length, yz / length
        xx, xy, xz = yy * nz - yz * ny, yz * nx - yx * nz, yx * ny - yy * nx
    else:
        xx, xy, xz, _bx, _by, _bz = orthonormal_basis(nx, ny, nz)
    cl[k, CL_T], cl[k, CL_T + 1], cl[k, CL_T + 2] = xx, xy, xz


@device
def ensure_valid_reflection(sd, nx, ny, nz):
    """Cycles' maybe_ensure_valid_specular_reflection: if the mirror direction of the
    view about N falls below the geometric surface, tilt N towards Ng just enough."""
    ngx, ngy, ngz = sd.ngx, sd.ngy, sd.ngz
    if not sd.bump_correction or (nx == ngx and ny == ngy and nz == ngz):
        return nx, ny, nz
    ix, iy, iz = sd.wox, sd.woy, sd.woz
    ni = nx * ix + ny * iy + nz * iz
    rx, ry, rz = 2.0 * ni * nx - ix, 2.0 * ni * ny - iy, 2.0 * ni * nz - iz
    iz_ = ix * ngx + iy * ngy + iz * ngz
    threshold = min(0.9 * iz_, 0.01)
    if rx * ngx + ry * ngy + rz * ngz >= threshold:
        return nx, ny, nz
    d = nx * ngx + ny * ngy + nz * ngz
    xx, xy, xz = nx - d * ngx, ny - d * ngy, nz - d * ngz
    length = math.sqrt(xx * xx + xy * xy + xz * xz)
    if length > 0.0:
        xx, xy, xz = xx / length, xy / length, xz / length
    else:
        xx, xy, xz = nx, ny, nz
    ix_ = ix * xx + iy * xy + iz * xz
    a = ix_ * ix_ + iz_ * iz_
    b = 2.0 * (a + iz_ * threshold)
    c = (threshold + iz_) ** 2
    disc = math.sqrt(max(b * b - 4.0 * a * c, 0.0))
    nz2 = 0.25 * (b + disc) / a if ix_ < 0.0 else 0.25 * (b - disc) / a
    n_x = math.sqrt(max(1.0 - nz2, 0.0))
    n_z = math.sqrt(max(nz2, 0.0))
    return n_x * xx + n_z * ngx, n_x * xy + n_z * ngy, n_x * xz + n_z * ngz


# -- microfacet closures ------------------------------------------------------------------------
# The microfacet set-ups read several tables; they are called, not inlined, so that each
# is compiled once rather than into every closure node (see jit.function).
@function
def microfacet_setup_fresnel_constant(cl, k, cos_no, cr, cg, cb):
    mf.microfacet_setup_fresnel_constant(cl, k, cos_no, cr, cg, cb)


@function
def microfacet_setup_fresnel_dielectric(cl, k, cos_no):
    mf.microfacet_setup_fresnel_dielectric(cl, k, cos_no)


@function
def microfacet_setup_fresnel_f82_tint(cl, k, cos_no, tr, tg, tb, preserve_energy):
    mf.microfacet_setup_fresnel_f82_tint(cl, k, cos_no, tr, tg, tb, preserve_energy)


@function
def microfacet_setup_fresnel_conductor(cl, k, cos_no, preserve_energy):
    mf.microfacet_setup_fresnel_conductor(cl, k, cos_no, preserve_energy)


@function
def microfacet_setup_fresnel_schlick(cl, k, cos_no, preserve_energy):
    mf.microfacet_setup_fresnel_schlick(cl, k, cos_no, preserve_energy)


@device
def microfacet(cl, k, ctype, distribution, ax, ay, eta, nx, ny, nz, tx, ty, tz, sd):
    """Fill the microfacet part of closure k (Fresnel FR_NONE until a setup below);
    returns the cosine between its normal and the view."""
    cl[k, CL_TYPE] = ctype
    cl[k, CL_DIST] = MD_BECKMANN if distribution == DIST_BECKMANN else MD_GGX
    cl[k, CL_AX] = ax
    cl[k, CL_AY] = ay
    cl[k, CL_ETA] = eta
    cl[k, CL_FRESNEL] = FR_NONE
    set_frame(cl, k, nx, ny, nz, tx, ty, tz)
    mf.microfacet_setup(cl, k)
    return sd.wox * nx + sd.woy * ny + sd.woz * nz


@device
def schlick(cl, k, cos_no, f0r, f0g, f0b, exponent, rtr, rtg, rtb, ttr, ttg, ttb, preserve_energy):
    """Generalized Schlick Fresnel with F90 = 1, then Cycles' setup of it."""
    cl[k, CL_F0], cl[k, CL_F0 + 1], cl[k, CL_F0 + 2] = f0r, f0g, f0b
    cl[k, CL_F90], cl[k, CL_F90 + 1], cl[k, CL_F90 + 2] = 1.0, 1.0, 1.0
    cl[k, CL_EXPONENT] = exponent
    cl[k, CL_RTINT], cl[k, CL_RTINT + 1], cl[k, CL_RTINT + 2] = rtr, rtg, rtb
    cl[k, CL_TTINT], cl[k, CL_TTINT + 1], cl[k, CL_TTINT + 2] = ttr, ttg, ttb
    microfacet_setup_fresnel_schlick(cl, k, cos_no, preserve_energy)


@device
def set_film(cl, k, thickness, ior):
    """A thin film over closure k: thickness in nm, IOR relative to the outside."""
    cl[k, CL_FILM_THICKNESS] = thickness
    cl[k, CL_FILM_IOR] = ior


@device
def layer_weight(cl, k, wr, wg, wb):
    """Weight left for the closures below layer k (Cycles' closure_layering_weight).

    Layer k is a reflection-only microfacet closure whose Fresnel setup stored its albedo
    estimate at the view in CL_ALBEDO (reflection only: the transmission part is zero).
    """
    ar = cl[k, CL_ALBEDO] * cl[k, CL_W]
    ag = cl[k, CL_ALBEDO + 1] * cl[k, CL_W + 1]
    ab = cl[k, CL_ALBEDO + 2] * cl[k, CL_W + 2]
    return _attenuate(ar, ag, ab, wr, wg, wb)


@device
def _attenuate(ar, ag, ab, wr, wg, wb):
    m = 0.0
    if wr != 0.0:
        m = max(m, ar / wr)
    if wg != 0.0:
        m = max(m, ag / wg)
    if wb != 0.0:
        m = max(m, ab / wb)
    f = saturate(1.0 - m)
    return wr * f, wg * f, wb * f


# -- the nodes ---------------------------------------------------------------------------------
@device
def eval_closure_node(kind, regs, b, w, cl, n, sd):
    """Build node ``kind``'s closures from its inputs at regs[b:]; weight w.

    Returns (n, emission RGB, transparency RGB, holdout).
    """
    if kind == K_PRINCIPLED:
        return principled(regs, b, w, cl, n, sd)
    cr, cg, cb = regs[b + COLOR_IN] * w, regs[b + COLOR_IN + 1] * w, regs[b + COLOR_IN + 2] * w
    if kind == K_EMISSION or kind == K_BACKGROUND:
        s = regs[b + E_STRENGTH]
        return n, cr * s, cg * s, cb * s, 0.0, 0.0, 0.0, 0.0
    if kind == K_HOLDOUT:
        return n, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, w
    if kind == K_TRANSPARENT:
        n = transparent(cl, n, cr, cg, cb, sd)
        return n, 0.0, 0.0, 0.0, max(cr, 0.0), max(cg, 0.0), max(cb, 0.0), 0.0
    if kind == K_DIFFUSE:
        k, n = alloc(cl, n, cr, cg, cb, sd)
        if k >= 0:
            nx, ny, nz = input_normal(regs, b + D_NORMAL, sd)
            diffuse(cl, k, sd, nx, ny, nz, regs[b + D_ROUGHNESS],
                    saturate(regs[b + COLOR_IN]), saturate(regs[b + COLOR_IN + 1]), saturate(regs[b + COLOR_IN + 2]))
    elif kind == K_TRANSLUCENT:
        k, n = alloc(cl, n, cr, cg, cb, sd)
        if k >= 0:
            nx, ny, nz = input_normal(regs, b + TL_NORMAL, sd)
            nx, ny, nz = ensure_valid_reflection(sd, nx, ny, nz)
            cl[k, CL_TYPE] = CT_TRANSLUCENT
            set_frame(cl, k, nx, ny, nz, 0.0, 0.0, 0.0)
    elif kind == K_SHEEN:
        k, n = alloc(cl, n, cr, cg, cb, sd)
        if k >= 0:
            nx, ny, nz = input_normal(regs, b + S_NORMAL, sd)
            if regs[b + S_DISTRIBUTION] == DIST_ASHIKHMIN:
                cl[k, CL_TYPE] = CT_VELVET
                set_frame(cl, k, nx, ny, nz, 0.0, 0.0, 0.0)
                cl[k, CL_VELVET_INV_SIGMA2] = 1.0 / max(saturate(regs[b + S_ROUGHNESS]), 0.01) ** 2
            else:
                sheen(cl, k, sd, nx, ny, nz, saturate(regs[b + S_ROUGHNESS]))
    elif kind == K_TOON:
        glossy_lobe = regs[b + T_COMPONENT] == TOON_GLOSSY
        if sd.reflective_caustics or not glossy_lobe:
            k, n = alloc(cl, n, cr, cg, cb, sd)
            if k >= 0:
                nx, ny, nz = input_normal(regs, b + T_NORMAL, sd)
                cl[k, CL_TYPE] = CT_GLOSSY_TOON if glossy_lobe else CT_DIFFUSE_TOON
                set_frame(cl, k, nx, ny, nz, 0.0, 0.0, 0.0)
                toon_setup(cl, k, regs[b + T_SIZE], regs[b + T_SMOOTH])
    elif kind == K_HAIR:
        k, n = alloc(cl, n, cr, cg, cb, sd)
        if k >= 0:
            nx, ny, nz = ensure_valid_reflection(sd, sd.nx, sd.ny, sd.nz)
            tx, ty, tz = regs[b + H_TANGENT], regs[b + H_TANGENT + 1], regs[b + H_TANGENT + 2]
            length = math.sqrt(tx * tx + ty * ty + tz * tz)
            if length > 0.0:
                tx, ty, tz = tx / length, ty / length, tz / length
            implicit = regs[b + H_IMPLICIT_TANGENT] != 0.0
            cl[k, CL_TYPE] = CT_HAIR_TRANSMISSION if regs[b + H_COMPONENT] == HAIR_TRANSMISSION \
                else CT_HAIR_REFLECTION
            set_frame(cl, k, nx, ny, nz, tx, ty, tz)
            hair_setup(cl, k, tx, ty, tz, regs[b + H_ROUGHNESS_U], regs[b + H_ROUGHNESS_V],
                       0.0 if implicit else -regs[b + H_OFFSET])
    elif kind == K_RAY_PORTAL:
        k, n = alloc(cl, n, cr, cg, cb, sd)
        if k >= 0:
            cl[k, CL_TYPE] = CT_RAY_PORTAL
            set_frame(cl, k, sd.nx, sd.ny, sd.nz, 0.0, 0.0, 0.0)
            for c in range(3):
                cl[k, CL_PORTAL_P + c] = regs[b + RP_POSITION + c]
            dx, dy, dz = regs[b + RP_DIRECTION], regs[b + RP_DIRECTION + 1], regs[b + RP_DIRECTION + 2]
            length = math.sqrt(dx * dx + dy * dy + dz * dz)
            if not length > 0.0:        # no direction: straight on
                dx, dy, dz, length = -sd.wox, -sd.woy, -sd.woz, 1.0
            cl[k, CL_PORTAL_D], cl[k, CL_PORTAL_D + 1], cl[k, CL_PORTAL_D + 2] = \
                dx / length, dy / length, dz / length
    elif kind == K_SUBSURFACE:
        scale = regs[b + SS_SCALE]
        nx, ny, nz = input_normal(regs, b + SS_NORMAL, sd)
        nx, ny, nz = ensure_valid_reflection(sd, nx, ny, nz)
        n = bssrdf(cl, n, sd, cr, cg, cb, regs[b + SS_RADIUS] * scale,
                   regs[b + SS_RADIUS + 1] * scale, regs[b + SS_RADIUS + 2] * scale,
                   regs[b + COLOR_IN], regs[b + COLOR_IN + 1], regs[b + COLOR_IN + 2],
                   nx, ny, nz, saturate(regs[b + SS_ROUGHNESS]),
                   regs[b + SS_IOR], regs[b + SS_ANISOTROPY], regs[b + SS_FALLOFF])
    elif kind == K_GLOSSY:
        if sd.reflective_caustics:
            n = glossy(regs, b, cl, n, sd, cr, cg, cb)
    elif kind == K_METALLIC:
        if sd.reflective_caustics:
            n = metallic(regs, b, w, cl, n, sd)
    elif kind == K_GLASS:
        n = glass(regs, b, w, cl, n, sd)
    elif kind == K_REFRACTION:
        if sd.refractive_caustics:
            k, n = alloc(cl, n, cr, cg, cb, sd)
            if k >= 0:
                nx, ny, nz = input_normal(regs, b + R_NORMAL, sd)
                nx, ny, nz = ensure_valid_reflection(sd, nx, ny, nz)
                ior = max(regs[b + R_IOR], 1e-5)
                a = regs[b + R_ROUGHNESS] ** 2
                microfacet(cl, k, CT_MICROFACET_REFRACTION, regs[b + R_DISTRIBUTION], a, a,
                           1.0 / ior if sd.backfacing else ior, nx, ny, nz, 0.0, 0.0, 0.0, sd)
    return n, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0


@function
def bssrdf(cl, n, sd, wr, wg, wb, rr, rg, rb, ar, ag, ab, nx, ny, nz, alpha, ior,
           anisotropy, method):
    """Append a BSSRDF closure (Cycles' bssrdf_alloc and bssrdf_setup); returns the new count.

    Channels whose radius is below BSSRDF_MIN_RADIUS go to a Lambert closure of their weight
    instead (Cycles' own zero-radius limit), and so do all of a Christensen-Burley BSSRDF's
    after a diffuse bounce; the BSSRDF's sample weight is |average weight| times its
    remaining channels.  The IOR is clamped to [1.01, 3.8], the anisotropy to [0, 0.9];
    Skin refracts with alpha 1.
    """
    k, n = alloc(cl, n, wr, wg, wb, sd)
    if k < 0:
        return n
    ior = min(max(ior, 1.01), 3.8)
    if method == SSS_RANDOM_WALK_SKIN:
        alpha = 1.0
    rr, rg, rb = max(rr, 0.0), max(rg, 0.0), max(rb, 0.0)
    wr, wg, wb = cl[k, CL_W], cl[k, CL_W + 1], cl[k, CL_W + 2]
    dr = dg = db = 0.0
    channels = 3
    if method == SSS_BURLEY and (sd.path_flags & PF_DIFFUSE_ANCESTOR):
        rr = rg = rb = 0.0          # all three channels go to the Lambert closure below
    if rr < BSSRDF_MIN_RADIUS:
        dr, wr, rr, channels = wr, 0.0, 0.0, channels - 1
    if rg < BSSRDF_MIN_RADIUS:
        dg, wg, rg, channels = wg, 0.0, 0.0, channels - 1
    if rb < BSSRDF_MIN_RADIUS:
        db, wb, rb, channels = wb, 0.0, 0.0, channels - 1
    if channels > 0:
        cl[k, CL_TYPE] = CT_BSSRDF
        cl[k, CL_W], cl[k, CL_W + 1], cl[k, CL_W + 2] = wr, wg, wb
        cl[k, CL_SW] = abs((wr + wg + wb) / 3.0) * channels
        set_frame(cl, k, nx, ny, nz, 0.0, 0.0, 0.0)
        cl[k, CL_RADIUS] = bssrdf_radius(rr, ar, ior, method)
        cl[k, CL_RADIUS + 1] = bssrdf_radius(rg, ag, ior, method)
        cl[k, CL_RADIUS + 2] = bssrdf_radius(rb, ab, ior, method)
        cl[k, CL_SSS_ALBEDO], cl[k, CL_SSS_ALBEDO + 1], cl[k, CL_SSS_ALBEDO + 2] = ar, ag, ab
        cl[k, CL_AX] = cl[k, CL_AY] = alpha
        cl[k, CL_ETA] = ior
        cl[k, CL_ANISOTROPY] = min(max(anisotropy, 0.0), 0.9)
        cl[k, CL_SSS_METHOD] = method
    else:
        cl[k, CL_TYPE] = CT_NONE
        cl[k, CL_W] = cl[k, CL_W + 1] = cl[k, CL_W + 2] = cl[k, CL_SW] = 0.0
    if channels < 3:
        j, n = alloc(cl, n, dr, dg, db, sd)
        if j >= 0:
            cl[j, CL_TYPE] = CT_DIFFUSE
            set_frame(cl, j, nx, ny, nz, 0.0, 0.0, 0.0)
    return n


@device
def transparent(cl, n, wr, wg, wb, sd):
    """Add to the one transparent closure (Cycles merges them); built even when other
    closures are not, since shadow and terminated paths still pass through it."""
    sw = abs((wr + wg + wb) / 3.0)
    if not sw >= CLOSURE_WEIGHT_CUTOFF:
        return n
    for k in range(n):
        if cl[k, CL_TYPE] == CT_TRANSPARENT:
            cl[k, CL_W] += wr
            cl[k, CL_W + 1] += wg
            cl[k, CL_W + 2] += wb
            cl[k, CL_SW] += sw
            return n
    if n >= MAX_CLOSURES:
        return n
    for c in range(CL_STRIDE):
        cl[n, c] = 0.0
    cl[n, CL_TYPE] = CT_TRANSPARENT
    cl[n, CL_W], cl[n, CL_W + 1], cl[n, CL_W + 2] = wr, wg, wb
    cl[n, CL_SW] = sw
    cl[n, CL_ENERGY] = 1.0
    cl[n, CL_N], cl[n, CL_N + 1], cl[n, CL_N + 2] = sd.nx, sd.ny, sd.nz
    return n + 1


@function
def diffuse(cl, k, sd, nx, ny, nz, roughness, albedo_r, albedo_g, albedo_b):
    """Lambert below roughness 1e-5, else Oren-Nayar with the (saturated) colour."""
    set_frame(cl, k, nx, ny, nz, 0.0, 0.0, 0.0)
    if roughness < CLOSURE_WEIGHT_CUTOFF:
        cl[k, CL_TYPE] = CT_DIFFUSE
    else:
        cl[k, CL_TYPE] = CT_OREN_NAYAR
        oren_nayar_setup(cl, k, nx * sd.wox + ny * sd.woy + nz * sd.woz, roughness,
                         albedo_r, albedo_g, albedo_b)


@function
def sheen(cl, k, sd, nx, ny, nz, roughness):
    """Microfibre sheen; returns False (and removes the weight) where its LTC is invalid."""
    cl[k, CL_TYPE] = CT_SHEEN
    set_frame(cl, k, nx, ny, nz, 0.0, 0.0, 0.0)
    return sheen_setup(cl, k, sd.wox, sd.woy, sd.woz, roughness)


@function
def glossy(regs, b, cl, n, sd, cr, cg, cb):
    """Glossy BSDF: microfacet reflection, F = 1, Color as the weight; Multiscatter GGX
    compensates energy with Fss = Color (Cycles' bsdf_microfacet_setup_fresnel_constant)."""
    k, n = alloc(cl, n, cr, cg, cb, sd)
    if k < 0:
        return n
    nx, ny, nz = input_normal(regs, b + G_NORMAL, sd)
    nx, ny, nz = ensure_valid_reflection(sd, nx, ny, nz)
    a = saturate(regs[b + G_ROUGHNESS]) ** 2
    aniso = min(max(regs[b + G_ANISOTROPY], -0.99), 0.99)
    tx, ty, tz = regs[b + G_TANGENT], regs[b + G_TANGENT + 1], regs[b + G_TANGENT + 2]
    ax = ay = a
    if (tx != 0.0 or ty != 0.0 or tz != 0.0) and abs(aniso) > 1e-4:
        rot = regs[b + G_ROTATION]
        if rot != 0.0:
            tx, ty, tz = rotate_around_axis(tx, ty, tz, nx, ny, nz, rot * 2.0 * math.pi)
        if aniso < 0.0:
            ax, ay = a / (1.0 + aniso), a * (1.0 + aniso)
        else:
            ax, ay = a * (1.0 - aniso), a / (1.0 - aniso)
    else:
        tx = ty = tz = 0.0
    dist = regs[b + G_DISTRIBUTION]
    if dist == DIST_ASHIKHMIN_SHIRLEY:
        cl[k, CL_TYPE] = CT_ASHIKHMIN_SHIRLEY
        set_frame(cl, k, nx, ny, nz, tx, ty, tz)
        cl[k, CL_AX] = min(max(ax, AS_MIN_ALPHA), 1.0)
        cl[k, CL_AY] = min(max(ay, AS_MIN_ALPHA), 1.0)
        return n
    cos_no = microfacet(cl, k, CT_MICROFACET, dist, ax, ay, 1.0, nx, ny, nz, tx, ty, tz, sd)
    if dist == DIST_MULTI_GGX:
        microfacet_setup_fresnel_constant(cl, k, cos_no, max(regs[b + COLOR_IN], 0.0),
                                          max(regs[b + COLOR_IN + 1], 0.0), max(regs[b + COLOR_IN + 2], 0.0))
    return n


@function
def metallic(regs, b, w, cl, n, sd):
    """Metallic BSDF: microfacet reflection weighted by the mix weight alone, its colour in
    the Fresnel: F82 tint of the clamped Base Color and Edge Tint, or the conductor Fresnel of
    IOR + i Extinction (both clamped >= 0); anisotropy stretches alpha by
    sqrt(1 - 0.9 anisotropy) as the Principled's; Multiscatter GGX compensates energy."""
    k, n = alloc(cl, n, w, w, w, sd)
    if k < 0:
        return n
    inx, iny, inz = input_normal(regs, b + M_NORMAL, sd)
    nx, ny, nz = ensure_valid_reflection(sd, inx, iny, inz)
    a = saturate(regs[b + M_ROUGHNESS]) ** 2
    aniso = saturate(regs[b + M_ANISOTROPY])
    tx, ty, tz = regs[b + M_TANGENT], regs[b + M_TANGENT + 1], regs[b + M_TANGENT + 2]
    ax = ay = a
    if aniso > 0.0 and (tx != 0.0 or ty != 0.0 or tz != 0.0):
        aspect = math.sqrt(1.0 - 0.9 * aniso)
        ax, ay = a / aspect, a * aspect
        rot = regs[b + M_ROTATION]
        if rot != 0.0:
            # about the input normal, as Cycles (the Glossy BSDF turns about the valid one)
            tx, ty, tz = rotate_around_axis(tx, ty, tz, inx, iny, inz, rot * 2.0 * math.pi)
    else:
        tx = ty = tz = 0.0
    dist = regs[b + M_DISTRIBUTION]
    cos_no = microfacet(cl, k, CT_MICROFACET, dist, ax, ay, 1.0, nx, ny, nz, tx, ty, tz, sd)
    set_film(cl, k, max(regs[b + M_THIN_FILM], 1e-5), max(regs[b + M_THIN_FILM_IOR], 1e-5))
    multiscatter = dist == DIST_MULTI_GGX
    if regs[b + M_FRESNEL] == FRESNEL_PHYSICAL_CONDUCTOR:
        for c in range(3):
            cl[k, CL_F0 + c] = max(regs[b + M_IOR + c], 0.0)
            cl[k, CL_F90 + c] = max(regs[b + M_EXTINCTION + c], 0.0)
        microfacet_setup_fresnel_conductor(cl, k, cos_no, multiscatter)
    else:
        for c in range(3):
            cl[k, CL_F0 + c] = saturate(regs[b + M_BASE_COLOR + c])
        microfacet_setup_fresnel_f82_tint(cl, k, cos_no, saturate(regs[b + M_EDGE_TINT]),
                                          saturate(regs[b + M_EDGE_TINT + 1]), saturate(regs[b + M_EDGE_TINT + 2]),
                                          multiscatter)
    return n


@function
def glass(regs, b, w, cl, n, sd):
    """Glass BSDF: rough dielectric, Schlick remap of the real Fresnel (exact at F0 of the
    IOR), Color tinting reflection and refraction; Multiscatter GGX compensates energy."""
    refl, refr = sd.reflective_caustics, sd.refractive_caustics
    if not (refl or refr):
        return n
    k, n = alloc(cl, n, w, w, w, sd)
    if k < 0:
        return n
    nx, ny, nz = input_normal(regs, b + GL_NORMAL, sd)
    nx, ny, nz = ensure_valid_reflection(sd, nx, ny, nz)
    ior = max(regs[b + GL_IOR], 1e-5)
    a = saturate(regs[b + GL_ROUGHNESS]) ** 2
    dist = regs[b + GL_DISTRIBUTION]
    cos_no = microfacet(cl, k, CT_MICROFACET_GLASS, dist, a, a, 1.0 / ior if sd.backfacing else ior,
                        nx, ny, nz, 0.0, 0.0, 0.0, sd)
    film_ior = max(regs[b + GL_THIN_FILM_IOR], 1e-5)
    set_film(cl, k, regs[b + GL_THIN_FILM], film_ior / ior if sd.backfacing else film_ior)
    cr, cg, cb = max(regs[b + COLOR_IN], 0.0), max(regs[b + COLOR_IN + 1], 0.0), max(regs[b + COLOR_IN + 2], 0.0)
    f0 = F0_from_ior(ior)
    schlick(cl, k, cos_no, f0, f0, f0, -ior,
            cr if refl else 0.0, cg if refl else 0.0, cb if refl else 0.0,
            cr if refr else 0.0, cg if refr else 0.0, cb if refr else 0.0, dist == DIST_MULTI_GGX)
    return n


@function
def principled(regs, b, mix_weight, cl, n, sd):
    """The Principled BSDF v2 (svm_node_closure_bsdf, CLOSURE_BSDF_PRINCIPLED_ID)."""
    base_r = max(regs[b + P_BASE_COLOR], 0.0)
    base_g = max(regs[b + P_BASE_COLOR + 1], 0.0)
    base_b = max(regs[b + P_BASE_COLOR + 2], 0.0)
    cbase_r, cbase_g, cbase_b = min(base_r, 1.0), min(base_g, 1.0), min(base_b, 1.0)
    ior = max(regs[b + P_IOR], 1e-5)
    roughness = saturate(regs[b + P_ROUGHNESS])
    metallic = saturate(regs[b + P_METALLIC])
    alpha = saturate(regs[b + P_ALPHA])
    nx, ny, nz = input_normal(regs, b + P_NORMAL, sd)
    rnx, rny, rnz = ensure_valid_reflection(sd, nx, ny, nz)
    cx, cy, cz = regs[b + P_COAT_NORMAL], regs[b + P_COAT_NORMAL + 1], regs[b + P_COAT_NORMAL + 2]
    clen = math.sqrt(cx * cx + cy * cy + cz * cz)
    if clen > 0.0:
        cnx, cny, cnz = cx / clen, cy / clen, cz / clen
    else:
        cnx, cny, cnz = nx, ny, nz
    dist = regs[b + P_DISTRIBUTION]
    multiscatter = dist == DIST_MULTI_GGX
    diffuse_roughness = saturate(regs[b + P_DIFFUSE_ROUGHNESS])
    specular_level = max(regs[b + P_SPECULAR_LEVEL], 0.0)
    st_r = max(regs[b + P_SPECULAR_TINT], 0.0)
    st_g = max(regs[b + P_SPECULAR_TINT + 1], 0.0)
    st_b = max(regs[b + P_SPECULAR_TINT + 2], 0.0)
    es = regs[b + P_EMISSION_STRENGTH]
    em_r, em_g, em_b = (regs[b + P_EMISSION_COLOR] * es, regs[b + P_EMISSION_COLOR + 1] * es,
                        regs[b + P_EMISSION_COLOR + 2] * es)
    anisotropic = saturate(regs[b + P_ANISOTROPIC])
    thin_film = regs[b + P_THIN_FILM]
    film_ior = max(regs[b + P_THIN_FILM_IOR], 1e-5) if thin_film > THIN_FILM_CUTOFF else 0.0
    subsurface = saturate(regs[b + P_SUBSURFACE_WEIGHT])
    coat_weight = max(regs[b + P_COAT_WEIGHT], 0.0)
    sheen_weight = max(regs[b + P_SHEEN_WEIGHT], 0.0)
    transmission = saturate(regs[b + P_TRANSMISSION])
    wr = wg = wb = mix_weight
    tr = tg = tb = 0.0
    refl, refr = sd.reflective_caustics, sd.refractive_caustics

    ax = ay = roughness * roughness
    tx = ty = tz = 0.0
    ttx, tty, ttz = regs[b + P_TANGENT], regs[b + P_TANGENT + 1], regs[b + P_TANGENT + 2]
    if anisotropic > 0.0 and (ttx != 0.0 or tty != 0.0 or ttz != 0.0):
        tx, ty, tz = ttx, tty, ttz
        aspect = math.sqrt(1.0 - anisotropic * 0.9)
        ax /= aspect
        ay *= aspect
        rot = regs[b + P_ANISOTROPIC_ROTATION]
        if rot != 0.0:
            tx, ty, tz = rotate_around_axis(tx, ty, tz, nx, ny, nz, rot * 2.0 * math.pi)

    # Alpha: a transparent closure of 1 - alpha, everything else x alpha.
    if alpha < 1.0:
        a = mix_weight * (1.0 - alpha)
        n = transparent(cl, n, a, a, a, sd)
        tr = tg = tb = max(a, 0.0)
        wr, wg, wb = wr * alpha, wg * alpha, wb * alpha

    # Sheen layer.
    if sheen_weight > CLOSURE_WEIGHT_CUTOFF:
        sw = sheen_weight
        k, n = alloc(cl, n, sw * max(regs[b + P_SHEEN_TINT], 0.0) * wr,
                     sw * max(regs[b + P_SHEEN_TINT + 1], 0.0) * wg,
                     sw * max(regs[b + P_SHEEN_TINT + 2], 0.0) * wb, sd)
        if k >= 0:
            f = saturate(coat_weight)
            sx, sy, sz = nx + (cnx - nx) * f, ny + (cny - ny) * f, nz + (cnz - nz) * f
            slen = math.sqrt(sx * sx + sy * sy + sz * sz)
            if slen > 0.0:
                sx, sy, sz = sx / slen, sy / slen, sz / slen
            if sheen(cl, k, sd, sx, sy, sz, saturate(regs[b + P_SHEEN_ROUGHNESS])):
                wr, wg, wb = _attenuate(cl[k, CL_W], cl[k, CL_W + 1], cl[k, CL_W + 2], wr, wg, wb)

    # Coat layer and its tint.
    if coat_weight > CLOSURE_WEIGHT_CUTOFF:
        coat_ior = max(regs[b + P_COAT_IOR], 1.0)
        vcx, vcy, vcz = ensure_valid_reflection(sd, cnx, cny, cnz)
        if refl:
            k, n = alloc(cl, n, coat_weight * wr, coat_weight * wg, coat_weight * wb, sd)
            if k >= 0:
                ca = saturate(regs[b + P_COAT_ROUGHNESS]) ** 2
                cos_no = microfacet(cl, k, CT_MICROFACET, 0.0, ca, ca, coat_ior, vcx, vcy, vcz,
                                    0.0, 0.0, 0.0, sd)
                microfacet_setup_fresnel_dielectric(cl, k, cos_no)
                wr, wg, wb = layer_weight(cl, k, wr, wg, wb)
        ct_r = max(regs[b + P_COAT_TINT], 0.0)
        ct_g = max(regs[b + P_COAT_TINT + 1], 0.0)
        ct_b = max(regs[b + P_COAT_TINT + 2], 0.0)
        if ct_r != 1.0 or ct_g != 1.0 or ct_b != 1.0:
            cos_ni = sd.wox * vcx + sd.woy * vcy + sd.woz * vcz
            cos_nt = math.sqrt(max(1.0 - (1.0 / coat_ior) ** 2 * (1.0 - cos_ni * cos_ni), 0.0))
            depth = 1.0 / cos_nt
            f = coat_weight
            wr *= 1.0 + (ct_r ** depth - 1.0) * f
            wg *= 1.0 + (ct_g ** depth - 1.0) * f
            wb *= 1.0 + (ct_b ** depth - 1.0) * f

    # Emission, under the sheen and the coat.
    er, eg, eb = em_r * wr, em_g * wg, em_b * wb

    # Metallic: an F82-tint conductor.
    if metallic > CLOSURE_WEIGHT_CUTOFF:
        if refl:
            k, n = alloc(cl, n, metallic * wr, metallic * wg, metallic * wb, sd)
            if k >= 0:
                cos_no = microfacet(cl, k, CT_MICROFACET, dist, ax, ay, 1.0, rnx, rny, rnz,
                                    tx, ty, tz, sd)
                cl[k, CL_F0], cl[k, CL_F0 + 1], cl[k, CL_F0 + 2] = cbase_r, cbase_g, cbase_b
                set_film(cl, k, thin_film, film_ior)
                microfacet_setup_fresnel_f82_tint(cl, k, cos_no, min(st_r, 1.0), min(st_g, 1.0),
                                                  min(st_b, 1.0), multiscatter)
        wr, wg, wb = wr * (1.0 - metallic), wg * (1.0 - metallic), wb * (1.0 - metallic)

    # Transmission: rough glass with the raw IOR, refraction tinted by sqrt(base colour).
    if transmission > CLOSURE_WEIGHT_CUTOFF:
        if refl or refr:
            k, n = alloc(cl, n, transmission * wr, transmission * wg, transmission * wb, sd)
            if k >= 0:
                a = roughness * roughness
                cos_no = microfacet(cl, k, CT_MICROFACET_GLASS, dist, a, a,
                                    1.0 / ior if sd.backfacing else ior, rnx, rny, rnz,
                                    0.0, 0.0, 0.0, sd)
                set_film(cl, k, thin_film, film_ior / ior if sd.backfacing else film_ior)
                f0 = F0_from_ior(ior)
                t_r = math.sqrt(cbase_r) if refr else 0.0
                t_g = math.sqrt(cbase_g) if refr else 0.0
                t_b = math.sqrt(cbase_b) if refr else 0.0
                r_t = 1.0 if refl else 0.0
                schlick(cl, k, cos_no, f0 * st_r, f0 * st_g, f0 * st_b, -ior, r_t, r_t, r_t,
                        t_r, t_g, t_b, multiscatter)
        wr, wg, wb = wr * (1.0 - transmission), wg * (1.0 - transmission), wb * (1.0 - transmission)

    # Dielectric specular, with Specular IOR Level adjusting F0 (and so the IOR).
    eta = ior
    f0 = F0_from_ior(eta)
    if specular_level != 0.5:
        f0 *= 2.0 * specular_level
        eta = ior_from_F0(f0)
        if ior < 1.0:
            eta = 1.0 / eta
    if refl and (eta != 1.0 or thin_film > THIN_FILM_CUTOFF):
        k, n = alloc(cl, n, wr, wg, wb, sd)
        if k >= 0:
            cos_no = microfacet(cl, k, CT_MICROFACET, dist, ax, ay, eta, rnx, rny, rnz, tx, ty, tz, sd)
            set_film(cl, k, thin_film, film_ior)
            schlick(cl, k, cos_no, f0 * st_r, f0 * st_g, f0 * st_b, -eta, 1.0, 1.0, 1.0,
                    0.0, 0.0, 0.0, multiscatter)
            wr, wg, wb = layer_weight(cl, k, wr, wg, wb)

    # Subsurface: a BSSRDF of the clamped colour, radius Radius x Scale.
    if subsurface > CLOSURE_WEIGHT_CUTOFF:
        method = regs[b + P_SUBSURFACE_METHOD]
        scale = regs[b + P_SUBSURFACE_SCALE]
        o = b + P_SUBSURFACE_RADIUS
        n = bssrdf(cl, n, sd, cbase_r * subsurface * wr, cbase_g * subsurface * wg,
                   cbase_b * subsurface * wb, regs[o] * scale, regs[o + 1] * scale,
                   regs[o + 2] * scale, cbase_r, cbase_g, cbase_b, rnx, rny, rnz,
                   roughness * roughness,
                   regs[b + P_SUBSURFACE_IOR] if method == SSS_RANDOM_WALK_SKIN else eta,
                   regs[b + P_SUBSURFACE_ANISOTROPY], method)

    # Diffuse, with the unclamped base colour.
    k, n = alloc(cl, n, base_r * (1.0 - subsurface) * wr, base_g * (1.0 - subsurface) * wg,
                 base_b * (1.0 - subsurface) * wb, sd)
    if k >= 0:
        diffuse(cl, k, sd, nx, ny, nz, diffuse_roughness, base_r, base_g, base_b)
    return n, er, eg, eb, tr, tg, tb, 0.0
