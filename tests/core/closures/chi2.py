"""Pearson chi-square test of a direction sampler against its pdf (after Mitsuba's ChiSquareTest).

The sphere of directions is cut into cells by edges in mu = cos(theta) and in phi, so
every cell's solid angle is d(mu) d(phi) and the pdf is integrated over a cell by a
Gauss-Legendre rule in (mu, phi).  Sharp lobes (alpha down to 0.0025) would fall into a
single cell of a uniform grid, so the edges are placed at quantiles of a pilot run of the
sampler (another seed), merged with a uniform grid and with mu = 0 (the horizon, where
pdfs jump): cells are fine where the samples are, and the pdf is smooth inside each cell.
A sampler that fails (LABEL_NONE) adds to an extra cell whose expected count is
N (1 - integral of the pdf): a pdf that integrates to more than the sampler's success
rate, or to more than 1, cannot pass.

Expected counts below 5 are pooled into one cell (and that pool into the smallest cell if
it stays below 5); the statistic has (cells - 1) degrees of freedom.  A cell with
expected 0 but observed samples makes the statistic infinite.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.stats import chi2 as chi2_distribution

from .kernels import evaluate, refraction_valid, sample

ALPHA = 0.01
# Number of chi-square tests in tests/core/closures/test_chi2.py (Sidak correction over all
# of them; test_chi2.py asserts that this is the number of its parametrised cases).
N_TESTS = 144
ALPHA_SIDAK = 1.0 - (1.0 - ALPHA) ** (1.0 / N_TESTS)

_GL_X, _GL_W = np.polynomial.legendre.leggauss(5)
_QUANTILE_TAILS = 2.0 ** -np.arange(1, 16)       # extra quantile levels in both tails


@dataclass
class Chi2Result:
    statistic: float
    dof: int
    p_value: float
    pdf_integral: float       # integral of the pdf over the sphere (quadrature)
    success: float            # fraction of samples that were not LABEL_NONE

    def passed(self, alpha: float = ALPHA_SIDAK) -> bool:
        return self.p_value > alpha


def _spherical(dirs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    mu = np.clip(dirs[:, 2], -1.0, 1.0)
    phi = np.mod(np.arctan2(dirs[:, 1], dirs[:, 0]), 2.0 * math.pi)
    return mu, phi


def _edges(values: np.ndarray, lo: float, hi: float, n_quantile: int, n_uniform: int,
           extra=()) -> np.ndarray:
    """Quantiles of the pilot (uniform levels, and levels 2^-k from both ends so that the
    cells in a lobe's heavy tails hold geometrically falling masses), a uniform grid and
    the extra edges."""
    levels = np.concatenate([np.linspace(0.0, 1.0, n_quantile + 1), _QUANTILE_TAILS, 1.0 - _QUANTILE_TAILS])
    q = np.quantile(values, levels) if values.size and n_quantile > 0 else np.empty(0)
    e = np.concatenate([q, np.linspace(lo, hi, n_uniform + 1), np.asarray(extra, float)])
    e = np.unique(np.clip(e, lo, hi))
    keep = np.concatenate([[True], np.diff(e) > 1e-12])     # a cell must have a width
    e = e[keep]
    e[0], e[-1] = lo, hi
    return e


def _rect_integrals(pdf_func, m0, m1, p0, p1) -> np.ndarray:
    """Gauss-Legendre 5 x 5 integral of the pdf over (mu, phi) rectangles (solid angle d mu d phi)."""
    mus = (0.5 * (m0 + m1))[:, None] + (0.5 * (m1 - m0))[:, None] * _GL_X[None, :]
    phis = (0.5 * (p0 + p1))[:, None] + (0.5 * (p1 - p0))[:, None] * _GL_X[None, :]
    mu = mus[:, :, None]
    phi = phis[:, None, :]
    s = np.sqrt(np.maximum(0.0, 1.0 - mu * mu))
    dirs = np.stack(np.broadcast_arrays(s * np.cos(phi), s * np.sin(phi), mu), axis=-1).reshape(-1, 3)
    pdf = pdf_func(dirs).reshape(m0.size, _GL_X.size, _GL_X.size)
    w = _GL_W[None, :, None] * _GL_W[None, None, :]
    return (pdf * w).sum(axis=(1, 2)) * 0.25 * (m1 - m0) * (p1 - p0)


def cell_pdf_integrals(pdf_func, mu_edges: np.ndarray, phi_edges: np.ndarray, n: int,
                       max_depth: int = 7) -> np.ndarray:
    """Integral of the pdf over every (mu, phi) cell, adaptively: a rectangle is split in
    four until the children's sum agrees with it to 0.02 expected samples (n samples in
    all) or 0.2 % (pdfs jump at the horizon and where the microfacet a refraction needs
    passes below it; lobes are sharp)."""
    nm, nph = mu_edges.size - 1, phi_edges.size - 1
    im, ip = np.meshgrid(np.arange(nm), np.arange(nph), indexing="ij")
    im, ip = im.ravel(), ip.ravel()
    m0, m1, p0, p1 = mu_edges[im], mu_edges[im + 1], phi_edges[ip], phi_edges[ip + 1]
    cell = im * nph + ip
    est = _rect_integrals(pdf_func, m0, m1, p0, p1)
    result = np.zeros(nm * nph)
    for depth in range(max_depth):
        mm, pm = 0.5 * (m0 + m1), 0.5 * (p0 + p1)
        cm0 = np.concatenate([m0, m0, mm, mm])
        cm1 = np.concatenate([mm, mm, m1, m1])
        cp0 = np.concatenate([p0, pm, p0, pm])
        cp1 = np.concatenate([pm, p1, pm, p1])
        child = _rect_integrals(pdf_func, cm0, cm1, cp0, cp1)
        total = child.reshape(4, -1).sum(axis=0)
        done = np.abs(total - est) * n <= np.maximum(0.02, 2e-3 * total * n)
        if depth == max_depth - 1:
            done[:] = True
        np.add.at(result, cell[done], total[done])
        more = np.tile(~done, 4)
        m0, m1, p0, p1 = cm0[more], cm1[more], cp0[more], cp1[more]
        cell = np.tile(cell, 4)[more]
        est = child[more]
        if m0.size == 0:
            break
    return result.reshape(nm, nph)


def chi2_test(sample_func, pdf_func, n: int, seed: int, n_pilot: int = 1 << 15,
              n_mu: int = 24, n_phi: int = 32) -> Chi2Result:
    """sample_func(n, seed) -> (n, 8) samples; pdf_func(dirs (k, 3)) -> pdf per direction."""
    pilot = sample_func(n_pilot, seed + 7919)
    ok_pilot = pilot[:, 7] != 0
    pm, pp = _spherical(pilot[ok_pilot, :3])
    # quantiles per hemisphere: each hemisphere's lobe gets fine cells down both its tails
    upper = _edges(pm[pm > 0.0], 0.0, 1.0, n_mu, 4) if np.count_nonzero(pm > 0.0) > 20 else np.empty(0)
    lower = _edges(pm[pm < 0.0], -1.0, 0.0, n_mu, 4) if np.count_nonzero(pm < 0.0) > 20 else np.empty(0)
    mu_edges = _edges(np.empty(0), -1.0, 1.0, 0, 8, extra=np.concatenate([upper, lower, [0.0]]))
    phi_edges = _edges(pp, 0.0, 2.0 * math.pi, n_phi, 8)

    data = sample_func(n, seed)
    ok = data[:, 7] != 0
    mu, phi = _spherical(data[ok, :3])
    observed, _, _ = np.histogram2d(mu, phi, bins=(mu_edges, phi_edges))
    expected = cell_pdf_integrals(pdf_func, mu_edges, phi_edges, n) * n
    pdf_integral = expected.sum() / n

    obs = np.concatenate([observed.ravel(), [np.count_nonzero(~ok)]])
    exp = np.concatenate([expected.ravel(), [n - expected.sum()]])
    if exp[-1] < -max(5.0, 1e-4 * n):  # the pdf integrates to more than 1 (beyond quadrature error)
        return Chi2Result(math.inf, 1, 0.0, pdf_integral, ok.mean())
    exp[-1] = max(exp[-1], 0.0)

    order = np.argsort(exp)
    exp, obs = exp[order], obs[order]
    small = exp < 5.0
    pool_e, pool_o = exp[small].sum(), obs[small].sum()
    exp, obs = exp[~small], obs[~small]
    if pool_e > 0.0 or pool_o > 0:
        if pool_e < 5.0 and exp.size:
            exp[0] += pool_e
            obs[0] += pool_o
        else:
            exp = np.concatenate([[pool_e], exp])
            obs = np.concatenate([[pool_o], obs])
    with np.errstate(divide="ignore", invalid="ignore"):
        terms = np.where(exp > 0.0, (obs - exp) ** 2 / exp, np.where(obs > 0, np.inf, 0.0))
    stat = float(terms.sum())
    dof = max(exp.size - 1, 1)
    p = float(chi2_distribution.sf(stat, dof)) if math.isfinite(stat) else 0.0
    return Chi2Result(stat, dof, p, pdf_integral, ok.mean())


def closure_sampler(cl, wo):
    return lambda n, seed: sample(cl, wo, n, seed)


def closure_pdf(cl, wo, valid_eta: float | None = None):
    """The pdf of row 0 as ``*_eval`` returns it; with ``valid_eta``, refraction directions
    no microfacet can produce (which Cycles' eval does not exclude) count as pdf 0."""
    def pdf(dirs):
        p = evaluate(cl, wo, dirs)[:, 3]
        if valid_eta is not None:
            below = dirs[:, 2] < 0.0
            p = np.where(below, p * refraction_valid(valid_eta, wo, dirs), p)
        return p
    return pdf
