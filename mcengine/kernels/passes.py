"""Render passes in the kernels: what the path tracer writes besides Combined.

The film keeps, per pixel, one row of float64 accumulators for the enabled
passes (``Film.passes``); ``PassData.cfg[P_*]`` is a pass's first column in
that row, or -1 when the pass is off.  Cycles' definitions
(kernel/film/data_passes.h, light_passes.h, denoising_passes.h,
cryptomatte_passes.h) decide what is written where:

* **data passes**, at the surfaces a camera ray meets (also through
  transparent surfaces): depth, position, object and material index from the
  pixel's first sample (its centre), overwritten at each such surface;
  normal and UV once per sample, at the first surface opaque enough (alpha
  at least the view layer's alpha threshold); mist, the colour passes
  (closure albedo times throughput) and Cryptomatte (matte weight per id) at
  every such surface;
* **light passes**: each contribution added to Combined also goes to
  Emission or Environment while the path has not scattered yet, else to the
  diffuse, glossy and transmission passes, direct at the first bounce and
  indirect after, in the shares each closure type has of the first bounce's
  BSDF value (``pass weights``, ``split_eval``): in the light sample's
  direction for its direct light, in the sampled direction for everything
  that arrives through it (Cycles' bsdf_eval_pass_diffuse_weight and
  _glossy_weight, kept in the path state from the first bounce on);
* **denoising features**: at the first surface whose closures are not mostly
  specular (more than a quarter of the sample weight diffuse-like), the
  diffuse albedo times the product of the specular albedos before it, and
  the average closure normal in camera space;
* **ambient occlusion**: at the surfaces a camera ray meets, a ray in a
  cosine-distributed direction that looks as far as the world's AO distance
  and, unoccluded, adds the path's throughput times the surface's alpha.

The functions here are inlined into ``path``; a render with no pass enabled
skips them with one flag test per event, and its pass buffers are one
element long.  Readout (sums to images) is ``mcengine.passes``.
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from ..jit import device, function
from .closures import closure_eval, excluded, is_diffuse, is_glossy_reflection, portal_weight
from .closures.layout import (
    CL_AX,
    CL_AY,
    CL_N,
    CL_SW,
    CL_TYPE,
    CL_W,
    CT_ASHIKHMIN_SHIRLEY,
    CT_BSSRDF,
    CT_HAIR_TRANSMISSION,
    CT_MICROFACET,
    CT_MICROFACET_GLASS,
    CT_MICROFACET_REFRACTION,
    CT_NONE,
    CT_RAY_PORTAL,
    CT_TRANSPARENT,
    LABEL_REFLECT,
    ROUGHNESS_SQ_THRESHOLD,
)
from .closures.microfacet import microfacet_albedo
from .sampling import cosine_hemisphere, orthonormal_basis
from .shading import push_shadow, shader_normal
from .state import (
    PF_DENOISE,
    PF_FIRST_SAMPLE,
    PF_PASS_DONE,
    PF_SURFACE_PASS,
    PF_TRANSPARENT_BG,
    SK_AO,
    SK_DIRECT,
    SK_INDIRECT,
)

# -- pass slots: index into PassData.cfg, whose value is the pass's first film column -----------
P_DEPTH = 0
P_MIST = 1
P_POSITION = 2
P_NORMAL = 3
P_VECTOR = 4
P_UV = 5
P_OBJECT_ID = 6
P_MATERIAL_ID = 7
P_DIFFUSE_DIRECT = 8
P_DIFFUSE_INDIRECT = 9
P_DIFFUSE_COLOR = 10
P_GLOSSY_DIRECT = 11
P_GLOSSY_INDIRECT = 12
P_GLOSSY_COLOR = 13
P_TRANSMISSION_DIRECT = 14
P_TRANSMISSION_INDIRECT = 15
P_TRANSMISSION_COLOR = 16
P_EMISSION = 17
P_ENVIRONMENT = 18
P_AO = 19
P_CRYPTO_OBJECT = 20
P_CRYPTO_MATERIAL = 21
P_CRYPTO_ASSET = 22
P_DENOISING_ALBEDO = 23
P_DENOISING_NORMAL = 24
P_DENOISING_DEPTH = 25
P_COUNT = 26
# Further entries of PassData.cfg: what groups of work a render needs.
PC_DATA = P_COUNT          # some pass written at camera-ray surfaces
PC_LIGHT = P_COUNT + 1     # some light pass (light contributions split by kind)
PC_DENOISE = P_COUNT + 2   # denoising albedo or normal
PC_CRYPTO_SLOTS = P_COUNT + 3   # (id, weight) slots per Cryptomatte type (2 per RGBA pass)
PC_STRIDE = P_COUNT + 4    # film columns per pixel
PC_SPLIT = P_COUNT + 5     # some diffuse/glossy/transmission light pass: compute pass weights
PC_SIZE = P_COUNT + 6

# Float settings (PassData.fcfg).
PV_MIST_START = 0
PV_MIST_INV_DEPTH = 1
PV_MIST_FALLOFF = 2
PV_ALPHA_THRESHOLD = 3
PV_ORTHO = 4               # 1: orthographic camera (mist is the distance along the view axis)
PV_CAMERA = 5              # 12: world to camera (Cycles' camera space: +z forward), rows x, y, z
PV_RASTER = 17             # 3 x 12: world to raster (rows x, y, w) now, at the previous and the
                           # next frame (Vector pass; raster y points up, as Cycles')
PV_AO_DISTANCE = 53        # how far the Ambient Occlusion pass's rays look (the world's AO distance)
PV_SIZE = 54

# Kinds of light (light_pass).
LK_SURFACE = 0             # emission of a surface or a lamp
LK_BACKGROUND = 1          # the world


PassData = namedtuple("PassData", [
    "cfg",           # (PC_SIZE,) int64   film column of each pass (-1: off), then PC_* entries
    "fcfg",          # (PV_SIZE,) f64
    "tri_uv",        # (T, 3, 3) f32      UV at each corner, 1 if the mesh has UVs (UV pass)
    "tri_object",    # (T, 3) f32         object pass index, Cryptomatte object and asset ids
    "mat_info",      # (M, 2) f32         material pass index, Cryptomatte material id
    "tri_motion",    # (T, 2, 3, 3) f32   corners at the previous and the next frame (Vector)
])

PassBuffers = namedtuple("PassBuffers", [
    "pw",            # (B, 6) f64  path: diffuse and glossy pass weights of the first bounce
    "dn",            # (B, 3) f64  path: denoising feature throughput
    "sw",            # (S, 6) f64  shadow ray: its pass weights (S: the shadow queue's length)
])


def alloc_pass_buffers(n: int, n_shadow: int) -> PassBuffers:
    """Pass buffers for n paths and n_shadow shadow rays (1 and 1 when no light pass or
    denoising feature is on)."""
    return PassBuffers(pw=np.zeros((n, 6)), dn=np.zeros((n, 3)), sw=np.zeros((n_shadow, 6)))


# -- closures ------------------------------------------------------------------------------------
@function
def closure_albedo(cl, k, wox, woy, woz, reflection, transmission):
    """Cycles' bsdf_albedo: the closure's weight, times the estimated albedo of a microfacet."""
    t = cl[k, CL_TYPE]
    r, g, b = cl[k, CL_W], cl[k, CL_W + 1], cl[k, CL_W + 2]
    if t == CT_MICROFACET or t == CT_MICROFACET_REFRACTION or t == CT_MICROFACET_GLASS:
        cos_no = wox * cl[k, CL_N] + woy * cl[k, CL_N + 1] + woz * cl[k, CL_N + 2]
        ar, ag, ab = microfacet_albedo(cl, k, cos_no, reflection, transmission)
        r, g, b = r * ar, g * ag, b * ab
    return r, g, b


@device
def roughness_squared(cl, k):
    """Cycles' bsdf_get_specular_roughness_squared: ax * ay of a microfacet, 0 if singular
    (transparent and ray portal closures too), 1 for every other closure."""
    t = cl[k, CL_TYPE]
    if t == CT_TRANSPARENT or t == CT_RAY_PORTAL:
        return 0.0
    if t == CT_MICROFACET or t == CT_MICROFACET_REFRACTION or t == CT_MICROFACET_GLASS \
            or t == CT_ASHIKHMIN_SHIRLEY:
        r2 = cl[k, CL_AX] * cl[k, CL_AY]
        return 0.0 if r2 <= ROUGHNESS_SQ_THRESHOLD else r2
    return 1.0


@device
def _pass_kind(cl, k, t, wix, wiy, wiz):
    """Which light pass closure k of type t scatters towards wi in: 0 diffuse (Cycles'
    CLOSURE_IS_BSDF_DIFFUSE), 1 glossy (reflection, Ashikhmin-Shirley and velvet, and glass
    on the side of its normal), 2 transmission."""
    if is_diffuse(t):
        return 0
    if is_glossy_reflection(t) or (t == CT_MICROFACET_GLASS and (
            wix * cl[k, CL_N] + wiy * cl[k, CL_N + 1] + wiz * cl[k, CL_N + 2]) > 0.0):
        return 1
    return 2


@function
def split_eval(cl, n, wox, woy, woz, wix, wiy, wiz, exclude, pick, fr, fg, fb):
    r"""Diffuse and glossy pass weights of the BSDF from wo towards wi (Cycles'
    bsdf_eval_pass_diffuse_weight and _glossy_weight): the shares of F that diffuse
    closures, and glossy ones, contribute.  Returns (dr, dg, db, gr, gg, gb); transmission
    is the rest.

    For a light sample (``pick`` -1), F sums the closures as ``closures.bsdf_eval`` does (a
    closure the light ``exclude``\ s adds nothing).  For a direction sampled from closure
    ``pick``, F is the list's value there that sampling found, (fr, fg, fb) (the weight
    times the mixture pdf), and the picked closure's part is F less the other closures'
    evaluations: its value as sampled, as Cycles' surface_shader_bsdf_sample_closure
    keeps it (an evaluation can differ: bump shadowing rejects more directions).
    """
    dr = dg = db = gr = gg = gb = 0.0
    sr = sg = sb = 0.0
    for k in range(n):
        t = cl[k, CL_TYPE]
        if k == pick or t == CT_NONE or t == CT_TRANSPARENT or excluded(t, exclude):
            continue
        r, g, b, pdf = closure_eval(cl, k, wox, woy, woz, wix, wiy, wiz)
        if pdf == 0.0:
            continue
        r *= cl[k, CL_W]
        g *= cl[k, CL_W + 1]
        b *= cl[k, CL_W + 2]
        sr, sg, sb = sr + r, sg + g, sb + b
        kind = _pass_kind(cl, k, t, wix, wiy, wiz)
        if kind == 0:
            dr, dg, db = dr + r, dg + g, db + b
        elif kind == 1:
            gr, gg, gb = gr + r, gg + g, gb + b
    if pick >= 0:
        kind = _pass_kind(cl, pick, cl[pick, CL_TYPE], wix, wiy, wiz)
        if kind == 0:
            dr, dg, db = dr + fr - sr, dg + fg - sg, db + fb - sb
        elif kind == 1:
            gr, gg, gb = gr + fr - sr, gg + fg - sg, gb + fb - sb
    else:
        fr, fg, fb = sr, sg, sb
    return (_safe_div(dr, fr), _safe_div(dg, fg), _safe_div(db, fb),
            _safe_div(gr, fr), _safe_div(gg, fg), _safe_div(gb, fb))


@device
def _safe_div(a, b):
    return a / b if b != 0.0 else 0.0


# -- light passes ----------------------------------------------------------------------------
@device
def _add3(fp, pix, o, r, g, b):
    fp[pix, o] += r
    fp[pix, o + 1] += g
    fp[pix, o + 2] += b


@device
def split_light(pd, fp, pix, direct, dwr, dwg, dwb, gwr, gwg, gwb, r, g, b):
    """Light reaching the camera through a first bounce, split by its pass weights."""
    c = pd.cfg
    o = c[P_GLOSSY_DIRECT] if direct else c[P_GLOSSY_INDIRECT]
    if o >= 0:
        _add3(fp, pix, o, gwr * r, gwg * g, gwb * b)
    o = c[P_TRANSMISSION_DIRECT] if direct else c[P_TRANSMISSION_INDIRECT]
    if o >= 0:
        _add3(fp, pix, o, (1.0 - dwr - gwr) * r, (1.0 - dwg - gwg) * g, (1.0 - dwb - gwb) * b)
    o = c[P_DIFFUSE_DIRECT] if direct else c[P_DIFFUSE_INDIRECT]
    if o >= 0:
        _add3(fp, pix, o, dwr * r, dwg * g, dwb * b)


@device
def light_pass(pd, fp, pix, flags, bounce, pb, i, r, g, b, kind):
    """Emission (a surface's or a lamp's, ``LK_SURFACE``) or the world's light
    (``LK_BACKGROUND``) that path i just added to Combined (Cycles'
    film_write_emission_or_background_pass)."""
    c = pd.cfg
    if (flags & PF_DENOISE) and c[P_DENOISING_ALBEDO] >= 0:
        _add3(fp, pix, c[P_DENOISING_ALBEDO], pb.dn[i, 0] * r, pb.dn[i, 1] * g, pb.dn[i, 2] * b)
    if not (flags & PF_SURFACE_PASS):
        o = c[P_ENVIRONMENT] if kind == LK_BACKGROUND else c[P_EMISSION]
        if o >= 0:
            _add3(fp, pix, o, r, g, b)
        return
    split_light(pd, fp, pix, bounce == 1, pb.pw[i, 0], pb.pw[i, 1], pb.pw[i, 2],
                pb.pw[i, 3], pb.pw[i, 4], pb.pw[i, 5], r, g, b)


@device
def shadow_pass(pd, fp, pix, pb, s, kind, r, g, b):
    """The light of unoccluded shadow ray s, of kind SK_* (Cycles' film_write_direct_light)."""
    if kind == SK_DIRECT or kind == SK_INDIRECT:
        split_light(pd, fp, pix, kind == SK_DIRECT, pb.sw[s, 0], pb.sw[s, 1], pb.sw[s, 2],
                    pb.sw[s, 3], pb.sw[s, 4], pb.sw[s, 5], r, g, b)


# -- ambient occlusion -----------------------------------------------------------------------
@device
def queue_ao_ray(pd, sc, scratch, sq, n_shadow, i, ncl, sp, br, bg, bb, tr, tg, tb, u1, u2,
                 depths, transparent_left):
    """Queue the Ambient Occlusion pass's ray at a surface the camera sees (Cycles'
    integrate_surface_ao); returns the queue length.

    The ray leaves in a cosine-distributed direction around the diffuse closures' normal
    (their weights' averages weigh the normals; the shader's normal without diffuse
    closures), and looks as far as the world's AO distance.  Unoccluded, it adds the path's
    throughput (br, bg, bb) times the surface's alpha (1 - transparency (tr, tg, tb)) to the
    pass: Cycles' pass is the mean of that over the pixel's samples.
    """
    ar, ag, ab = br * min(max(1.0 - tr, 0.0), 1.0), bg * min(max(1.0 - tg, 0.0), 1.0), \
        bb * min(max(1.0 - tb, 0.0), 1.0)
    if ar == 0.0 and ag == 0.0 and ab == 0.0:
        return n_shadow
    cl = scratch.cl
    nx = ny = nz = 0.0
    for k in range(ncl):
        if is_diffuse(cl[k, CL_TYPE]):
            w = abs(cl[k, CL_W] + cl[k, CL_W + 1] + cl[k, CL_W + 2]) * (1.0 / 3.0)
            nx, ny, nz = nx + w * cl[k, CL_N], ny + w * cl[k, CL_N + 1], nz + w * cl[k, CL_N + 2]
    sx, sy, sz = shader_normal(sc, scratch.regs, sp)
    length = math.sqrt(nx * nx + ny * ny + nz * nz)
    if length > 0.0:
        nx, ny, nz = nx / length, ny / length, nz / length
    else:
        nx, ny, nz = sx, sy, sz
    x, y, z = cosine_hemisphere(u1, u2)
    tx, ty, tz, bx, by, bz = orthonormal_basis(nx, ny, nz)
    wix, wiy, wiz = x * tx + y * bx + z * nx, x * ty + y * by + z * ny, x * tz + y * bz + z * nz
    queued = push_shadow(sq, sc, n_shadow, i, sp, sx, sy, sz, wix, wiy, wiz,
                         pd.fcfg[PV_AO_DISTANCE], 0.0, 0.0, 0.0, ar, ag, ab, transparent_left,
                         depths)
    if queued > n_shadow:
        sq.kind[n_shadow] = SK_AO
    return queued


@device
def ao_pass(pd, fp, pix, r, g, b):
    """The throughput an unoccluded Ambient Occlusion ray carries (Cycles'
    film_write_direct_light for PATH_RAY_SHADOW_FOR_AO)."""
    _add3(fp, pix, pd.cfg[P_AO], r, g, b)


@device
def singular_weights(label):
    """Pass weights of a singular (perfectly smooth) sample: all glossy if it reflected,
    else all transmission.  (Cycles scales a singular lobe's value by 1e6 and adds the
    other closures' evaluations to it, so their share there is below 1e-5.)"""
    if label & LABEL_REFLECT:
        return 0.0, 0.0, 0.0, 1.0, 1.0, 1.0
    return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0


# -- data passes -------------------------------------------------------------------------------
@device
def _camera_z(pd, x, y, z):
    f = pd.fcfg
    k = PV_CAMERA + 8
    return f[k] * x + f[k + 1] * y + f[k + 2] * z + f[k + 3]


@device
def _camera_distance(pd, x, y, z):
    """Cycles' camera_distance: along the view axis for orthographic cameras, else Euclidean."""
    if pd.fcfg[PV_ORTHO] != 0.0:
        return abs(_camera_z(pd, x, y, z))
    f = pd.fcfg
    # The camera position from the world-to-camera rows: -R^T t.
    cx = -(f[PV_CAMERA] * f[PV_CAMERA + 3] + f[PV_CAMERA + 4] * f[PV_CAMERA + 7]
           + f[PV_CAMERA + 8] * f[PV_CAMERA + 11])
    cy = -(f[PV_CAMERA + 1] * f[PV_CAMERA + 3] + f[PV_CAMERA + 5] * f[PV_CAMERA + 7]
           + f[PV_CAMERA + 9] * f[PV_CAMERA + 11])
    cz = -(f[PV_CAMERA + 2] * f[PV_CAMERA + 3] + f[PV_CAMERA + 6] * f[PV_CAMERA + 7]
           + f[PV_CAMERA + 10] * f[PV_CAMERA + 11])
    return math.sqrt((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2)


@device
def _crypto_add(fp, pix, base, slots, ident, weight):
    """Cycles' film_write_cryptomatte_slots: add weight to id's slot (a new slot if the id
    has none yet; the last slot takes what does not fit)."""
    for s in range(slots):
        o = base + 2 * s
        if fp[pix, o] == 0.0:
            fp[pix, o] = ident
            fp[pix, o + 1] = weight
            return
        if fp[pix, o] == ident or s == slots - 1:
            fp[pix, o + 1] += weight
            return


@function
def surface_passes(pd, fp, pix, flags, hx, hy, hz, nsx, nsy, nsz, t_hit, p, b1, b2, m, cl, ncl,
                   br, bg, bb, tr, tg, tb, wox, woy, woz, pb, i):
    """Data passes and denoising features at a surface path i reached (after emission and
    Russian roulette, as in Cycles' shade_surface), where (tr, tg, tb) is the transparency
    of its closures; returns the path's new flags."""
    c = pd.cfg
    if c[PC_DATA] and (flags & PF_TRANSPARENT_BG):
        qr, qg, qb = portal_weight(cl, ncl)        # Cycles counts a portal as transparent
        tr, tg, tb = tr + qr, tg + qg, tb + qb
        flags = _data_passes(pd, fp, pix, flags, hx, hy, hz, nsx, nsy, nsz, p, b1, b2, m, cl,
                             ncl, br, bg, bb, tr, tg, tb, wox, woy, woz)
    if c[PC_DENOISE] and (flags & PF_DENOISE):
        flags = _denoising_features(pd, fp, pix, flags, nsx, nsy, nsz, t_hit, cl, ncl,
                                    wox, woy, woz, pb, i)
    return flags


@device
def _data_passes(pd, fp, pix, flags, hx, hy, hz, nsx, nsy, nsz, p, b1, b2, m, cl, ncl,
                 br, bg, bb, tr, tg, tb, wox, woy, woz):
    c = pd.cfg
    ar = min(max(1.0 - tr, 0.0), 1.0)
    ag = min(max(1.0 - tg, 0.0), 1.0)
    ab = min(max(1.0 - tb, 0.0), 1.0)
    if not (flags & PF_PASS_DONE):
        if flags & PF_FIRST_SAMPLE:
            if c[P_DEPTH] >= 0:
                fp[pix, c[P_DEPTH]] = _camera_z(pd, hx, hy, hz)
            if c[P_OBJECT_ID] >= 0:
                fp[pix, c[P_OBJECT_ID]] = pd.tri_object[p, 0]
            if c[P_MATERIAL_ID] >= 0:
                fp[pix, c[P_MATERIAL_ID]] = pd.mat_info[m, 0]
            if c[P_POSITION] >= 0:
                o = c[P_POSITION]
                fp[pix, o], fp[pix, o + 1], fp[pix, o + 2] = hx, hy, hz
        threshold = pd.fcfg[PV_ALPHA_THRESHOLD]
        transparent = tr != 0.0 or tg != 0.0 or tb != 0.0
        if not transparent or threshold == 0.0 or (ar + ag + ab) / 3.0 >= threshold:
            if c[P_NORMAL] >= 0:
                nx = ny = nz = 0.0
                for k in range(ncl):
                    t = cl[k, CL_TYPE]
                    if t == CT_NONE:
                        continue
                    w = abs(cl[k, CL_W] + cl[k, CL_W + 1] + cl[k, CL_W + 2]) / 3.0
                    if t == CT_TRANSPARENT:   # its normal is the shading normal
                        nx, ny, nz = nx + nsx * w, ny + nsy * w, nz + nsz * w
                    else:
                        nx += cl[k, CL_N] * w
                        ny += cl[k, CL_N + 1] * w
                        nz += cl[k, CL_N + 2] * w
                length = math.sqrt(nx * nx + ny * ny + nz * nz)
                if length > 0.0:
                    nx, ny, nz = nx / length, ny / length, nz / length
                else:
                    nx, ny, nz = nsx, nsy, nsz
                _add3(fp, pix, c[P_NORMAL], nx, ny, nz)
            if c[P_UV] >= 0:
                b0 = 1.0 - b1 - b2
                u = b0 * pd.tri_uv[p, 0, 0] + b1 * pd.tri_uv[p, 1, 0] + b2 * pd.tri_uv[p, 2, 0]
                v = b0 * pd.tri_uv[p, 0, 1] + b1 * pd.tri_uv[p, 1, 1] + b2 * pd.tri_uv[p, 2, 1]
                w = b0 * pd.tri_uv[p, 0, 2] + b1 * pd.tri_uv[p, 1, 2] + b2 * pd.tri_uv[p, 2, 2]
                _add3(fp, pix, c[P_UV], u * w, v * w, w)   # (0, 0, 0) without a UV map
            if c[P_VECTOR] >= 0:
                _motion_vector(pd, fp, pix, c[P_VECTOR], hx, hy, hz, p, b1, b2)
            flags |= PF_PASS_DONE
    slots = c[PC_CRYPTO_SLOTS]
    if slots > 0:
        matte = (br + bg + bb) / 3.0 * (1.0 - (tr + tg + tb) / 3.0)
        if matte > 0.0:
            if c[P_CRYPTO_OBJECT] >= 0:
                _crypto_add(fp, pix, c[P_CRYPTO_OBJECT], slots, pd.tri_object[p, 1], matte)
            if c[P_CRYPTO_MATERIAL] >= 0:
                _crypto_add(fp, pix, c[P_CRYPTO_MATERIAL], slots, pd.mat_info[m, 1], matte)
            if c[P_CRYPTO_ASSET] >= 0:
                _crypto_add(fp, pix, c[P_CRYPTO_ASSET], slots, pd.tri_object[p, 2], matte)
    if c[P_DIFFUSE_COLOR] >= 0 or c[P_GLOSSY_COLOR] >= 0 or c[P_TRANSMISSION_COLOR] >= 0:
        for k in range(ncl):
            t = cl[k, CL_TYPE]
            if is_diffuse(t) or t == CT_BSSRDF:    # Cycles' surface_shader_diffuse
                o, refl, trans = c[P_DIFFUSE_COLOR], True, True
            elif is_glossy_reflection(t):
                o, refl, trans = c[P_GLOSSY_COLOR], True, False
            elif t == CT_MICROFACET_REFRACTION or t == CT_HAIR_TRANSMISSION:
                o, refl, trans = c[P_TRANSMISSION_COLOR], False, True
            elif t == CT_MICROFACET_GLASS:
                # Glass adds its reflection to the glossy colour, its transmission to the other.
                if c[P_GLOSSY_COLOR] >= 0:
                    r, g, b = closure_albedo(cl, k, wox, woy, woz, True, False)
                    _add3(fp, pix, c[P_GLOSSY_COLOR], r * br, g * bg, b * bb)
                o, refl, trans = c[P_TRANSMISSION_COLOR], False, True
            else:
                continue
            if o >= 0:
                r, g, b = closure_albedo(cl, k, wox, woy, woz, refl, trans)
                _add3(fp, pix, o, r * br, g * bg, b * bb)
    if c[P_MIST] >= 0:
        f = pd.fcfg
        mist = min(max((_camera_distance(pd, hx, hy, hz) - f[PV_MIST_START]) * f[PV_MIST_INV_DEPTH],
                       0.0), 1.0)
        falloff = f[PV_MIST_FALLOFF]
        if falloff == 2.0:
            mist = mist * mist
        elif falloff == 0.5:
            mist = math.sqrt(mist)
        elif falloff != 1.0:
            mist = mist ** falloff
        # Summed as 1 - mist (background rays add nothing); readout takes 1 - mean.
        fp[pix, c[P_MIST]] += (1.0 - mist) * (br * ar + bg * ag + bb * ab) / 3.0
    return flags


@device
def _raster(f, k, x, y, z):
    """Raster position of a world point through the projection at ``fcfg[k:k + 12]``."""
    w = f[k + 8] * x + f[k + 9] * y + f[k + 10] * z + f[k + 11]
    return ((f[k] * x + f[k + 1] * y + f[k + 2] * z + f[k + 3]) / w,
            (f[k + 4] * x + f[k + 5] * y + f[k + 6] * z + f[k + 7]) / w)


@device
def _motion_vector(pd, fp, pix, o, hx, hy, hz, p, b1, b2):
    """Cycles' primitive_motion_vector, summed with a weight of 1: (previous - now, now -
    next) raster positions of the hit point, which moves with its triangle's corners."""
    f = pd.fcfg
    b0 = 1.0 - b1 - b2
    m = pd.tri_motion
    cx, cy = _raster(f, PV_RASTER, hx, hy, hz)
    for s in range(2):
        x = b0 * m[p, s, 0, 0] + b1 * m[p, s, 1, 0] + b2 * m[p, s, 2, 0]
        y = b0 * m[p, s, 0, 1] + b1 * m[p, s, 1, 1] + b2 * m[p, s, 2, 1]
        z = b0 * m[p, s, 0, 2] + b1 * m[p, s, 1, 2] + b2 * m[p, s, 2, 2]
        rx, ry = _raster(f, PV_RASTER + 12 * (s + 1), x, y, z)
        sign = 1.0 if s == 0 else -1.0
        fp[pix, o + 2 * s] += sign * (rx - cx)
        fp[pix, o + 2 * s + 1] += sign * (ry - cy)
    fp[pix, o + 4] += 1.0


@device
def background_passes(pd, fp, pix, flags):
    """An escaped camera ray: depth, indices and position of the first sample are 0
    (Cycles' film_write_data_passes_background)."""
    c = pd.cfg
    if not c[PC_DATA] or not (flags & PF_TRANSPARENT_BG) or (flags & PF_PASS_DONE) \
            or not (flags & PF_FIRST_SAMPLE):
        return
    for slot in (P_DEPTH, P_OBJECT_ID, P_MATERIAL_ID):
        if c[slot] >= 0:
            fp[pix, c[slot]] = 0.0
    if c[P_POSITION] >= 0:
        o = c[P_POSITION]
        fp[pix, o] = fp[pix, o + 1] = fp[pix, o + 2] = 0.0


# -- denoising features ---------------------------------------------------------------------------
DENOISE_ROUGHNESS_SQ = 0.075 * 0.075   # above it a closure counts as diffuse-like


@device
def _finite(x):
    return x if math.isfinite(x) else 0.0


@device
def _denoising_features(pd, fp, pix, flags, nsx, nsy, nsz, t_hit, cl, ncl, wox, woy, woz, pb, i):
    """Cycles' film_write_denoising_features_surface."""
    c = pd.cfg
    if c[P_DENOISING_DEPTH] >= 0:
        fp[pix, c[P_DENOISING_DEPTH]] += _finite((pb.dn[i, 0] + pb.dn[i, 1] + pb.dn[i, 2]) / 3.0
                                                 * t_hit)
    nx = ny = nz = 0.0
    sum_w = sum_diffuse = 0.0
    dr = dg = db = sr = sg = sb = 0.0
    for k in range(ncl):
        t = cl[k, CL_TYPE]
        if t == CT_NONE:
            continue
        sw = cl[k, CL_SW]
        if t == CT_TRANSPARENT:
            nx, ny, nz = nx + nsx * sw, ny + nsy * sw, nz + nsz * sw
            r, g, b = cl[k, CL_W], cl[k, CL_W + 1], cl[k, CL_W + 2]
        else:
            nx += cl[k, CL_N] * sw
            ny += cl[k, CL_N + 1] * sw
            nz += cl[k, CL_N + 2] * sw
            r, g, b = closure_albedo(cl, k, wox, woy, woz, True, True)
        sum_w += sw
        if roughness_squared(cl, k) > DENOISE_ROUGHNESS_SQ:
            dr, dg, db = dr + r, dg + g, db + b
            sum_diffuse += sw
        else:
            sr, sg, sb = sr + r, sg + g, sb + b
    if sum_w == 0.0 or sum_diffuse * 4.0 > sum_w:
        if sum_w != 0.0:
            nx, ny, nz = nx / sum_w, ny / sum_w, nz / sum_w
        if c[P_DENOISING_NORMAL] >= 0:
            f = pd.fcfg
            k = PV_CAMERA
            _add3(fp, pix, c[P_DENOISING_NORMAL],
                  _finite(f[k] * nx + f[k + 1] * ny + f[k + 2] * nz),
                  _finite(f[k + 4] * nx + f[k + 5] * ny + f[k + 6] * nz),
                  _finite(f[k + 8] * nx + f[k + 9] * ny + f[k + 10] * nz))
        if c[P_DENOISING_ALBEDO] >= 0:
            _add3(fp, pix, c[P_DENOISING_ALBEDO], _finite(pb.dn[i, 0] * dr),
                  _finite(pb.dn[i, 1] * dg), _finite(pb.dn[i, 2] * db))
        return flags & ~PF_DENOISE
    pb.dn[i, 0] *= sr
    pb.dn[i, 1] *= sg
    pb.dn[i, 2] *= sb
    return flags
