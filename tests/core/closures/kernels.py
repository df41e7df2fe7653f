"""Test helpers: closure rows, and compiled loops that sample or evaluate one closure many times.

The loops call the closure families' device functions directly (in the closure's local
frame, row 0 of ``cl``), dispatching on CL_TYPE, so every test shares two compiled kernels.
"""
from __future__ import annotations

import math

import numpy as np

from mcengine.jit import kernel
from mcengine.kernels.closures.ashikhmin import (
    ashikhmin_shirley_eval,
    ashikhmin_shirley_sample,
    velvet_eval,
    velvet_sample,
)
from mcengine.kernels.closures.diffuse import (
    lambert_eval,
    lambert_sample,
    oren_nayar_eval,
    oren_nayar_sample,
    oren_nayar_setup,
    translucent_eval,
    translucent_sample,
)
from mcengine.kernels.closures.hair import hair_eval, hair_sample, hair_setup
from mcengine.kernels.closures.layout import (
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
    CL_N,
    CL_RTINT,
    CL_STRIDE,
    CL_SW,
    CL_T,
    CL_TTINT,
    CL_TYPE,
    CL_VELVET_INV_SIGMA2,
    CL_W,
    CT_ASHIKHMIN_SHIRLEY,
    CT_DIFFUSE,
    CT_DIFFUSE_TOON,
    CT_GLOSSY_TOON,
    CT_HAIR_REFLECTION,
    CT_HAIR_TRANSMISSION,
    CT_MICROFACET,
    CT_OREN_NAYAR,
    CT_TRANSLUCENT,
    CT_VELVET,
    FR_NONE,
    MAX_CLOSURES,
    MD_GGX,
)
from mcengine.kernels.closures.microfacet import (
    microfacet_eval,
    microfacet_refraction_valid,
    microfacet_sample,
)
from mcengine.kernels.closures.toon import (
    diffuse_toon_eval,
    diffuse_toon_sample,
    glossy_toon_eval,
    glossy_toon_sample,
    toon_setup,
)


def empty_row(ctype: int) -> np.ndarray:
    cl = np.zeros((MAX_CLOSURES, CL_STRIDE))
    cl[0, CL_TYPE] = ctype
    cl[0, CL_W:CL_W + 3] = 1.0
    cl[0, CL_SW] = 1.0
    cl[0, CL_N + 2] = 1.0
    cl[0, CL_T] = 1.0
    return cl


def diffuse_row(ctype: int = CT_DIFFUSE) -> np.ndarray:
    return empty_row(ctype)


def oren_nayar_row(sigma: float, color=(1.0, 1.0, 1.0), cos_no: float = 1.0) -> np.ndarray:
    cl = empty_row(CT_OREN_NAYAR)
    oren_nayar_setup(cl, 0, cos_no, sigma, *color)
    return cl


def microfacet_row(ctype: int = CT_MICROFACET, dist: int = MD_GGX, alpha: float = 0.25,
                   alpha_y: float | None = None, eta: float = 1.5, fresnel: int = FR_NONE,
                   f0=(0.04, 0.04, 0.04), f90=(1.0, 1.0, 1.0), exponent: float = -1.0,
                   rtint=(1.0, 1.0, 1.0), ttint=(1.0, 1.0, 1.0), energy: float = 1.0,
                   film=(0.0, 1.0)) -> np.ndarray:
    cl = empty_row(ctype)
    cl[0, CL_DIST] = dist
    cl[0, CL_AX] = alpha
    cl[0, CL_AY] = alpha if alpha_y is None else alpha_y
    cl[0, CL_ETA] = eta
    cl[0, CL_FRESNEL] = fresnel
    cl[0, CL_F0:CL_F0 + 3] = f0
    cl[0, CL_F90:CL_F90 + 3] = f90
    cl[0, CL_EXPONENT] = exponent
    cl[0, CL_RTINT:CL_RTINT + 3] = rtint
    cl[0, CL_TTINT:CL_TTINT + 3] = ttint
    cl[0, CL_ENERGY] = energy
    cl[0, CL_FILM_THICKNESS], cl[0, CL_FILM_IOR] = film
    return cl


def ashikhmin_shirley_row(alpha: float, alpha_y: float | None = None) -> np.ndarray:
    cl = empty_row(CT_ASHIKHMIN_SHIRLEY)
    cl[0, CL_AX] = alpha
    cl[0, CL_AY] = alpha if alpha_y is None else alpha_y
    return cl


def velvet_row(roughness: float) -> np.ndarray:
    cl = empty_row(CT_VELVET)
    cl[0, CL_VELVET_INV_SIGMA2] = 1.0 / max(roughness, 0.01) ** 2
    return cl


def toon_row(ctype: int, size: float, smooth: float) -> np.ndarray:
    cl = empty_row(ctype)
    toon_setup(cl, 0, size, smooth)
    return cl


def hair_row(ctype: int, tangent=(1.0, 0.0, 0.0), roughness_u: float = 0.2,
             roughness_v: float = 0.5, offset: float = 0.0) -> np.ndarray:
    """A Hair BSDF row in the frame N = +z, T = +x, its strand along ``tangent`` (unit)."""
    cl = empty_row(ctype)
    hair_setup(cl, 0, *tangent, roughness_u, roughness_v, offset)
    return cl


def direction(theta_deg: float, phi_deg: float = 0.0) -> tuple[float, float, float]:
    t = math.radians(theta_deg)
    p = math.radians(phi_deg)
    return math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)


@kernel
def sample_batch(cl, wox, woy, woz, u, out):
    """out[i] = (wi x, y, z, r, g, b, pdf, label) of row 0 for the uniforms u[i]."""
    t = int(cl[0, CL_TYPE])
    for i in range(u.shape[0]):
        if t == CT_DIFFUSE:
            res = lambert_sample(cl, 0, wox, woy, woz, u[i, 0], u[i, 1], u[i, 2])
        elif t == CT_TRANSLUCENT:
            res = translucent_sample(cl, 0, wox, woy, woz, u[i, 0], u[i, 1], u[i, 2])
        elif t == CT_OREN_NAYAR:
            res = oren_nayar_sample(cl, 0, wox, woy, woz, u[i, 0], u[i, 1], u[i, 2])
        elif t == CT_ASHIKHMIN_SHIRLEY:
            res = ashikhmin_shirley_sample(cl, 0, wox, woy, woz, u[i, 0], u[i, 1], u[i, 2])
        elif t == CT_VELVET:
            res = velvet_sample(cl, 0, wox, woy, woz, u[i, 0], u[i, 1], u[i, 2])
        elif t == CT_DIFFUSE_TOON:
            res = diffuse_toon_sample(cl, 0, wox, woy, woz, u[i, 0], u[i, 1], u[i, 2])
        elif t == CT_GLOSSY_TOON:
            res = glossy_toon_sample(cl, 0, wox, woy, woz, u[i, 0], u[i, 1], u[i, 2])
        elif t == CT_HAIR_REFLECTION or t == CT_HAIR_TRANSMISSION:
            res = hair_sample(cl, 0, t == CT_HAIR_TRANSMISSION, wox, woy, woz, u[i, 0], u[i, 1])
        else:
            res = microfacet_sample(cl, 0, wox, woy, woz, u[i, 0], u[i, 1], u[i, 2])
        out[i, 0], out[i, 1], out[i, 2] = res[0], res[1], res[2]
        out[i, 3], out[i, 4], out[i, 5] = res[3], res[4], res[5]
        out[i, 6], out[i, 7] = res[6], res[7]


@kernel
def eval_batch(cl, wox, woy, woz, wi, out):
    """out[i] = (r, g, b, pdf) of row 0 for the view wo and the light directions wi[i]."""
    t = int(cl[0, CL_TYPE])
    for i in range(wi.shape[0]):
        if t == CT_DIFFUSE:
            res = lambert_eval(cl, 0, wox, woy, woz, wi[i, 0], wi[i, 1], wi[i, 2])
        elif t == CT_TRANSLUCENT:
            res = translucent_eval(cl, 0, wox, woy, woz, wi[i, 0], wi[i, 1], wi[i, 2])
        elif t == CT_OREN_NAYAR:
            res = oren_nayar_eval(cl, 0, wox, woy, woz, wi[i, 0], wi[i, 1], wi[i, 2])
        elif t == CT_ASHIKHMIN_SHIRLEY:
            res = ashikhmin_shirley_eval(cl, 0, wox, woy, woz, wi[i, 0], wi[i, 1], wi[i, 2])
        elif t == CT_VELVET:
            res = velvet_eval(cl, 0, wox, woy, woz, wi[i, 0], wi[i, 1], wi[i, 2])
        elif t == CT_DIFFUSE_TOON:
            res = diffuse_toon_eval(cl, 0, wox, woy, woz, wi[i, 0], wi[i, 1], wi[i, 2])
        elif t == CT_GLOSSY_TOON:
            res = glossy_toon_eval(cl, 0, wox, woy, woz, wi[i, 0], wi[i, 1], wi[i, 2])
        elif t == CT_HAIR_REFLECTION or t == CT_HAIR_TRANSMISSION:
            res = hair_eval(cl, 0, t == CT_HAIR_TRANSMISSION, wox, woy, woz, wi[i, 0], wi[i, 1], wi[i, 2])
        else:
            res = microfacet_eval(cl, 0, wox, woy, woz, wi[i, 0], wi[i, 1], wi[i, 2])
        out[i, 0], out[i, 1], out[i, 2], out[i, 3] = res


@kernel
def refraction_valid_batch(eta, wox, woy, woz, wi, out):
    for i in range(wi.shape[0]):
        out[i] = 1.0 if microfacet_refraction_valid(eta, wox, woy, woz, wi[i, 0], wi[i, 1], wi[i, 2]) else 0.0


def sample(cl, wo, n: int, seed: int) -> np.ndarray:
    """(n, 8) samples of row 0 at view wo from numpy's Generator(seed)."""
    u = np.random.default_rng(seed).random((n, 3))
    out = np.empty((n, 8))
    sample_batch(cl, float(wo[0]), float(wo[1]), float(wo[2]), u, out)
    return out


def evaluate(cl, wo, wi: np.ndarray) -> np.ndarray:
    wi = np.ascontiguousarray(wi, dtype=np.float64)
    out = np.empty((wi.shape[0], 4))
    eval_batch(cl, float(wo[0]), float(wo[1]), float(wo[2]), wi, out)
    return out


def refraction_valid(eta: float, wo, wi: np.ndarray) -> np.ndarray:
    wi = np.ascontiguousarray(wi, dtype=np.float64)
    out = np.empty(wi.shape[0])
    refraction_valid_batch(float(eta), float(wo[0]), float(wo[1]), float(wo[2]), wi, out)
    return out
