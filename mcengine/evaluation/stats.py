"""Do two renderers agree?  Statistics on stacks of independent renders.

Concept
-------
Two renderers agree on a scene when their *expected* pixel values are equal.
We observe, for each renderer, a stack of ``K >= 2`` renders of the scene made
with different seeds, and test the null hypothesis "equal expected values"
region by region:

* Per pixel ``p`` the seed-to-seed sample variance ``s2_p`` (ddof=1) estimates
  the variance of one render's value there.
* Pixels of one render are independent (each pixel's samples are its own, as
  in Cycles, whose pixel filter is importance-sampled, not splatted), so the
  variance of a region mean of one render is ``sum_p s2_p / n**2`` and that of
  the K-seed average is that over ``K``.  This pools ``n (K - 1)`` degrees of
  freedom per region, so even ``K = 2`` gives a usable test.
* A splatting pixel filter or a denoiser correlates neighbouring pixels and
  would make that variance too small.  Each stack therefore measures the
  seed-to-seed variance of its block sums directly and compares it with the
  independent-pixel prediction; for the frame it also sums the residuals'
  covariance over pixel offsets up to ``MAX_CORRELATION_LAG`` (pairs that
  block edges cut).  These *pixel correlation factors* are 1 up to noise for
  independent pixels; variances are multiplied by ``max(1, factor)`` and the
  factor's own noise lowers the degrees of freedom.  Pooling over the image
  makes them precise enough for K = 2 (about 10 %).  Negative correlation
  (blue-noise sampling) is not credited, which is conservative.  A factor
  well above 1 is named in the summary: renders meant for this test should
  have denoising off.
* Regions are the whole frame and an 8x8 grid of blocks (edges from
  ``np.linspace``, so any image size works).  Per region and RGB channel,
  ``t = (mean_a - mean_b) / sqrt(se_a**2 + se_b**2)`` gets a two-sided p-value
  from Student's t with Welch-Satterthwaite degrees of freedom.  Those degrees
  of freedom are computed from the per-pixel variances, so a block whose
  variance is dominated by a few fireflies gets few degrees of freedom and wide
  tails instead of an overconfident normal p-value.
* The family-wise error over all (region, channel) tests is held at ``alpha``
  with Holm-Bonferroni.  The verdict is "differ" if any test is rejected.
  Regions without noise in either stack and equal to float precision (black
  areas, say) carry no information and are skipped.

The test is about expected values only: a biased estimator in *both*
renderers (Cycles' indirect clamp, say) cancels out, and a difference smaller
than the noise of the stacks goes unseen; the confidence interval on the
frame's relative bias states how small a difference could have been seen.

Conventions
-----------
Stacks are ``(K, h, w, C)`` float arrays of linear radiance, top row first,
``C`` = 3 or 4; only RGB is used (alpha is not radiance).  ``a`` is the render
under test, ``b`` the reference: relative differences are ``a / b - 1``.  The
two stacks may hold different numbers of seeds.

Pure numpy and the standard library (``math.erfc``, ``math.lgamma``), so it
runs inside Blender's Python, which has no scipy.  :func:`jsonable` (numpy to
plain, strict-JSON Python) is here because every result of the evaluation
package (:class:`Agreement`, the comparison report, the study summaries) is
made JSON-ready with it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "Agreement", "compare_stacks", "block_edges", "block_means",
    "student_t_sf", "student_t_isf", "holm_adjust", "relmse", "smape", "jsonable",
]

CHANNELS = "RGB"

# Noise-free regions (a directly seen constant background, say) have zero
# estimated variance; two engines still round differently on the way to a
# float32 pixel (eps 1.2e-7).  Means are treated as uncertain by at least
# ~100 ulp relative, or 1e-8 absolute (far below a half-float's smallest
# normal value, 6e-5), so rounding alone never reads as a difference.
FLOAT_TOLERANCE_REL = 1e-5
FLOAT_TOLERANCE_ABS = 1e-8

# Beyond this many degrees of freedom Student's t is the normal distribution
# to 2e-5 relative in the tail probability at |t| = 5 (the error grows as
# t**4 / (4 dof)), while the incomplete beta below loses digits to the
# cancelling lgamma terms (1e-8 relative at 1e8 dof).
DOF_NORMAL = 1e7

# A correlation factor more than this many of its standard deviations above 1
# means the renders' pixels are not independent: the summary says so, since a
# denoiser left on is the usual cause.  (At K = 2 on a 128x128 Cornell box
# the factor's standard deviation is about 0.2.)
CORRELATION_WARNING_SIGMAS = 4.0

# Incomplete-beta continued fraction: relative convergence tolerance (double
# precision) and a cap on iterations far above the few hundred it needs.
_CF_TOLERANCE = 1e-15
_CF_MAX_ITER = 10_000
_CF_TINY = 1e-300  # stands in for a zero denominator in Lentz's method

# Quantiles: Newton steps on the log survival function, doubling or bisection
# when a step leaves the bracket; 200 steps reach double precision even by
# bisection alone.
_ROOT_ITER = 200


# ----------------------------------------------------------------------------
# Distributions and multiple testing
# ----------------------------------------------------------------------------

_erfc_obj = np.frompyfunc(math.erfc, 1, 1)
_lgamma_obj = np.frompyfunc(math.lgamma, 1, 1)


def _erfc(x) -> np.ndarray:
    """Elementwise ``math.erfc`` (numpy has none)."""
    return np.asarray(_erfc_obj(x), dtype=np.float64)


def _lgamma(x) -> np.ndarray:
    """Elementwise ``math.lgamma``."""
    return np.asarray(_lgamma_obj(x), dtype=np.float64)


def _betainc_cf(x: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Continued fraction of the regularized incomplete beta function.

    Evaluates ``1 / (1 + d1 / (1 + d2 / (1 + ...)))`` elementwise with the
    modified Lentz method, so that ``I_x(a, b) = x**a (1-x)**b / (a B(a, b))``
    times the result.  Converges quickly for ``x < (a + 1) / (a + b + 2)``.
    """
    f = np.ones_like(x)
    c = np.ones_like(x)
    d = np.zeros_like(x)
    active = np.ones(np.shape(x), bool)     # elements whose fraction has not converged yet
    for m in range(_CF_MAX_ITER):
        # terms d_{2m} (from m = 1 on) and d_{2m+1}
        odd = -(a + m) * (a + b + m) * x / ((a + 2 * m) * (a + 2 * m + 1))
        even = m * (b - m) * x / ((a + 2 * m - 1) * (a + 2 * m)) if m else None
        for coef in (even, odd):
            if coef is None:
                continue
            d = 1.0 + coef * d
            d = 1.0 / np.where(np.abs(d) > _CF_TINY, d, _CF_TINY)
            c = 1.0 + coef / c
            c = np.where(np.abs(c) > _CF_TINY, c, _CF_TINY)
            delta = c * d
            f = np.where(active, f * delta, f)
        # An element stops once it has converged: its later steps only jitter by rounding,
        # which could keep a slower element's iteration from ever seeing all of them below
        # the tolerance at once.
        active &= ~(np.abs(delta - 1.0) < _CF_TOLERANCE)
        if not active.any():
            return 1.0 / f
    raise ArithmeticError("incomplete beta continued fraction did not converge")


def _betainc(x: np.ndarray, x1: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Regularized incomplete beta ``I_x(a, b)``, given ``x`` and ``x1 = 1 - x``.

    ``x1`` is passed separately so callers can form it without cancellation.
    Arrays of one shape.
    """
    swap = x >= (a + 1.0) / (a + b + 2.0)     # use I_x(a, b) = 1 - I_{1-x}(b, a)
    xs, as_, bs = np.where(swap, x1, x), np.where(swap, b, a), np.where(swap, a, b)
    lbeta = _lgamma(a + b) - _lgamma(a) - _lgamma(b)
    with np.errstate(divide="ignore"):
        log_front = a * np.log(x) + b * np.log(x1) + lbeta
    part = np.exp(log_front) * _betainc_cf(xs, as_, bs) / as_
    return np.where(x <= 0, 0.0, np.where(x1 <= 0, 1.0, np.where(swap, 1.0 - part, part)))


def _scalar_or_array(out: np.ndarray, like: np.ndarray):
    """``out`` as a float if ``like`` is 0-d (scalar in, scalar out)."""
    return float(out) if like.ndim == 0 else out


def student_t_sf(t, dof):
    """Upper tail ``P(T > t)`` of Student's t with ``dof`` degrees of freedom.

    Parameters
    ----------
    t : float or array
    dof : float or array, broadcast against ``t``
        Positive, may be fractional; ``inf`` (or above ``DOF_NORMAL``) gives
        the standard normal tail ``erfc(t / sqrt 2) / 2``.

    Returns
    -------
    float or array of the broadcast shape
        Accurate to about 1e-15 absolute and, for ``t > 0``, about 1e-9
        relative in the tail.
    """
    t, dof = np.broadcast_arrays(np.asarray(t, np.float64), np.asarray(dof, np.float64))
    if np.isnan(t).any() or np.isnan(dof).any() or (dof <= 0).any():
        raise ValueError("student_t_sf needs numbers t and dof > 0")
    at = np.abs(t)
    with np.errstate(divide="ignore", invalid="ignore"):
        # P(|T| > t) = I_x(dof/2, 1/2) with x = dof/(dof+t^2); both forms
        # stay exact at t = 0 and t = inf.
        x = 1.0 / (1.0 + at * at / dof)
        x1 = 1.0 / (1.0 + dof / (at * at))
    normal = dof > DOF_NORMAL
    half = np.empty_like(at)
    half[normal] = 0.5 * _erfc(at[normal] / math.sqrt(2.0))
    n = dof[~normal]
    half[~normal] = 0.5 * _betainc(x[~normal], x1[~normal], 0.5 * n, np.full_like(n, 0.5))
    return _scalar_or_array(np.where(t < 0, 1.0 - half, half), t)


def _student_t_pdf(t: np.ndarray, dof: np.ndarray) -> np.ndarray:
    """Density of Student's t (normal above ``DOF_NORMAL``), same-shape arrays."""
    normal = dof > DOF_NORMAL
    nu = np.where(normal, 1.0, dof)           # placeholder where the normal is used
    log_c = _lgamma(0.5 * (nu + 1)) - _lgamma(0.5 * nu) - 0.5 * np.log(nu * math.pi)
    student = np.exp(log_c - 0.5 * (nu + 1) * np.log1p(t * t / nu))
    return np.where(normal, np.exp(-0.5 * t * t) / math.sqrt(2 * math.pi), student)


def student_t_isf(p, dof):
    """Inverse of :func:`student_t_sf`: the ``t`` with ``P(T > t) = p``.

    ``dof = inf`` gives the standard normal quantile.  Newton's method on
    ``log P(T > t)``, safeguarded by bisection; as accurate as
    :func:`student_t_sf` allows (1e-12 relative at moderate ``dof``).
    """
    p, dof = np.broadcast_arrays(np.asarray(p, np.float64), np.asarray(dof, np.float64))
    if not np.all((0.0 < p) & (p < 1.0)):
        raise ValueError("student_t_isf needs 0 < p < 1")
    upper = np.minimum(p, 1.0 - p)          # solve in the upper tail, then mirror
    # Start at the normal tail bound sqrt(-2 ln p) (above the normal quantile,
    # below heavy-tailed ones); [lo, hi] brackets the root as it is learned.
    t = np.sqrt(-2.0 * np.log(upper))
    lo, hi = np.zeros_like(t), np.full_like(t, np.inf)
    for _ in range(_ROOT_ITER):
        sf = student_t_sf(t, dof)
        left_of_root = sf > upper
        lo, hi = np.where(left_of_root, t, lo), np.where(left_of_root, hi, t)
        with np.errstate(divide="ignore", invalid="ignore"):
            newton = t + (np.log(sf) - np.log(upper)) * sf / _student_t_pdf(t, dof)
        inside = (newton > lo) & (newton < hi)
        fallback = np.where(np.isinf(hi), 2.0 * t, 0.5 * (lo + hi))
        t_next = np.where(inside, newton, fallback)
        done = np.all(np.abs(t_next - t) <= 1e-12 * np.maximum(t_next, 1.0))
        t = t_next
        if done:
            break
    return _scalar_or_array(np.where(p > 0.5, -t, t), p)


def holm_adjust(p) -> np.ndarray:
    """Holm-Bonferroni adjusted p-values.

    Test ``i`` is rejected at family-wise level ``alpha`` exactly when its
    adjusted p-value is ``<= alpha``.

    Parameters
    ----------
    p : (m,) float
        Unadjusted p-values.

    Returns
    -------
    (m,) float
        ``max_{j <= rank(i)} min(1, (m - j) p_(j))`` with ``p_(j)`` sorted
        ascending (0-based ranks), in the input order.
    """
    p = np.asarray(p, dtype=np.float64).ravel()
    m = p.size
    order = np.argsort(p, kind="stable")
    scaled = np.minimum(1.0, (m - np.arange(m)) * p[order])
    adjusted = np.empty(m)
    adjusted[order] = np.maximum.accumulate(scaled)
    return adjusted


# ----------------------------------------------------------------------------
# Blocks
# ----------------------------------------------------------------------------

def block_edges(size: int, n: int) -> np.ndarray:
    """Edges of ``n`` near-equal blocks covering ``range(size)``.

    Returns
    -------
    (n + 1,) int
        ``floor(linspace(0, size, n + 1))``; block ``i`` is ``[e[i], e[i+1])``.
        Every block is non-empty when ``size >= n``.
    """
    if n < 1 or size < n:
        raise ValueError(f"cannot split {size} pixels into {n} blocks")
    return np.floor(np.linspace(0, size, n + 1)).astype(np.int64)


def _block_sums(x: np.ndarray, ey: np.ndarray, ex: np.ndarray) -> np.ndarray:
    """Sum ``x`` of shape ``(..., h, w, C)`` over blocks -> ``(..., gy, gx, C)``."""
    rows = np.add.reduceat(x, ey[:-1], axis=-3)
    return np.add.reduceat(rows, ex[:-1], axis=-2)


def _block_counts(ey: np.ndarray, ex: np.ndarray) -> np.ndarray:
    """Pixels per block, ``(gy, gx, 1)`` float."""
    return (np.diff(ey)[:, None] * np.diff(ex)[None, :]).astype(np.float64)[..., None]


def block_means(img, grid=(8, 8)) -> np.ndarray:
    """Mean of an image over a ``grid = (rows, cols)`` of blocks.

    Parameters
    ----------
    img : (h, w) or (h, w, C) float
    grid : (int, int)
        Block rows and columns; edges as in :func:`block_edges`.

    Returns
    -------
    (rows, cols) or (rows, cols, C) float64
    """
    img = np.asarray(img, dtype=np.float64)
    flat = img.ndim == 2
    if flat:
        img = img[..., None]
    if img.ndim != 3:
        raise ValueError(f"block_means needs an (h, w) or (h, w, C) image, got shape {img.shape}")
    ey, ex = block_edges(img.shape[0], grid[0]), block_edges(img.shape[1], grid[1])
    means = _block_sums(img, ey, ex) / _block_counts(ey, ex)
    return means[..., 0] if flat else means


# ----------------------------------------------------------------------------
# Per-stack moments
# ----------------------------------------------------------------------------

@dataclass
class _RegionMoments:
    """One stack's estimate for each region (frame or blocks) and channel.

    mean      K-seed average of the region mean
    var       variance of ``mean`` (pixel correlation factor applied)
    dof_term  ``var``'s Welch-Satterthwaite denominator term, ``Var-hat(var)/2``
    noisy     True where any pixel of the region varies between seeds
    """

    mean: np.ndarray
    var: np.ndarray
    dof_term: np.ndarray
    noisy: np.ndarray


# Pixel correlation at the frame scale is summed over lags up to this many
# pixels in x and y: a splatted Blackman-Harris filter of width 1.5 px (the
# Blender default) correlates pixels up to 3 px apart, a Gaussian of width
# 1.5 px up to 4.5 px.  Longer-range correlation (a denoiser) shows in the
# block factor instead.
MAX_CORRELATION_LAG = 4


def _block_correlation(seed_block_sums: np.ndarray, total_pixel_var: float):
    """Measured over independent-pixel variance of the block sums.

    Parameters
    ----------
    seed_block_sums : (K, gy, gx, 3) float
        Block sums of each render.
    total_pixel_var : float
        ``sum_p s2_p`` over all pixels and channels: what ``sum_b Var(S_b)``
        would be for independent pixels.

    Returns
    -------
    factor : float
        ``sum_b Var_k(S_b) / sum_p s2_p``: 1 up to noise (about
        ``sqrt(2 / (n_blocks * 3 * (K - 1)))``) for independent pixels.
    dof : float
        Welch-Satterthwaite degrees of freedom of the numerator, which carries
        nearly all of the factor's noise (relative variance ``2 / dof``).
    """
    k = seed_block_sums.shape[0]
    v = seed_block_sums.var(axis=0, ddof=1)
    if total_pixel_var <= 0 or not v.any():
        return 1.0, math.inf
    return float(v.sum()) / total_pixel_var, float(v.sum() ** 2 / (v**2).sum() * (k - 1))


def _fft_size(n: int) -> int:
    """Smallest ``2**i 3**j 5**k >= n`` (a size numpy's FFT handles fast)."""
    best = 2 * n
    p5 = 1
    while p5 < best:
        p35 = p5
        while p35 < best:
            p = p35
            while p < n:
                p *= 2
            best = min(best, p)
            p35 *= 3
        p5 *= 5
    return best


def _lag_correlation(residuals: np.ndarray, max_lag: int = MAX_CORRELATION_LAG) -> float:
    """Variance of a large region's sum over its independent-pixel value.

    Parameters
    ----------
    residuals : (K, h, w, 3) float
        Each render minus the stack's per-pixel mean.
    max_lag : int
        Largest pixel offset in x and y whose covariance is counted.

    Returns
    -------
    float
        ``1 + sum_{0 < |l| <= max_lag} sum_p e(p) e(p + l) / sum_p e(p)**2``
        pooled over seeds and channels (pairs inside the image only): 1 up to
        noise (about ``2 max_lag / sqrt(h w 3 (K - 1))``) for independent
        pixels.  The lag sums come from one zero-padded FFT autocorrelation.
    """
    h, w = residuals.shape[1:3]
    lag_y, lag_x = min(max_lag, h - 1), min(max_lag, w - 1)
    size = (_fft_size(h + lag_y), _fft_size(w + lag_x))   # padding: no wrap-around
    spectrum = np.fft.rfft2(residuals, s=size, axes=(1, 2))
    acf = np.fft.irfft2((spectrum.real**2 + spectrum.imag**2).sum(axis=(0, 3)), s=size)
    power = acf[0, 0]
    if power <= 0:
        return 1.0
    # offsets (0, 1..L), (1..L, 0..L) and (1..L, -L..-1): each pair once
    cross = (acf[0, 1:lag_x + 1].sum() + acf[1:lag_y + 1, :lag_x + 1].sum()
             + acf[1:lag_y + 1, size[1] - lag_x:].sum())
    return float(1.0 + 2.0 * cross / power)


def _stack_moments(stack: np.ndarray, ey: np.ndarray, ex: np.ndarray):
    """Frame and block moments of one stack, and its pixel correlation factors.

    Parameters
    ----------
    stack : (K, h, w, 3) float64
    ey, ex : block edges

    Returns
    -------
    frame : _RegionMoments with (3,) arrays
    blocks : _RegionMoments with (gy, gx, 3) arrays
    correlation : (2,) float
        :func:`_block_correlation` and :func:`_lag_correlation`.  Block
        variances are multiplied by ``max(1, block)``, frame variances by
        ``max(1, block, lag)``: the lag factor also counts the pairs that
        block edges cut.
    corr_dof : float
        Degrees of freedom of the block factor (relative variance ``2 / dof``).
    """
    k = stack.shape[0]
    pixel_mean = stack.mean(axis=0)
    pixel_var = stack.var(axis=0, ddof=1)
    counts = _block_counts(ey, ex)
    var_sum = _block_sums(pixel_var, ey, ex)                        # sum_p s2_p
    block_corr, corr_dof = _block_correlation(_block_sums(stack, ey, ex), float(var_sum.sum()))
    lag_corr = _lag_correlation(stack - pixel_mean)
    block_inflation = max(1.0, block_corr)
    frame_inflation = max(1.0, block_corr, lag_corr)

    def moments(mean_sum, var_sum, var2_sum, n, noisy, inflation):
        # var of the K-average of a region mean: inflation * sum s2 / (n^2 K).
        # Its estimate's variance (halved, for Welch-Satterthwaite): each s2_p
        # has K-1 dof, so Var-hat(s2_p) = 2 s2_p^2 / (K-1); an estimated
        # inflation adds its relative variance 2 / corr_dof.  The lag factor
        # is taken to be no noisier than the block factor (measured: less
        # noisy at 128x128 px, equal at 64x64).
        scale = inflation / (n**2 * k)
        var = scale * var_sum
        dof_term = scale**2 * var2_sum / (k - 1)
        if inflation > 1.0:
            dof_term = dof_term + var**2 / corr_dof
        return _RegionMoments(mean=mean_sum / n, var=var, dof_term=dof_term, noisy=noisy)

    n_frame = float(pixel_mean.shape[0] * pixel_mean.shape[1])
    frame = moments(pixel_mean.sum(axis=(0, 1)), pixel_var.sum(axis=(0, 1)),
                    (pixel_var**2).sum(axis=(0, 1)), n_frame, pixel_var.max(axis=(0, 1)) > 0,
                    frame_inflation)
    noisy_blocks = np.maximum.reduceat(np.maximum.reduceat(pixel_var, ey[:-1], axis=0),
                                       ex[:-1], axis=1) > 0
    blocks = moments(_block_sums(pixel_mean, ey, ex), var_sum,
                     _block_sums(pixel_var**2, ey, ex), counts, noisy_blocks, block_inflation)
    return frame, blocks, np.array([block_corr, lag_corr]), corr_dof


@dataclass
class _Tests:
    """Two-sample t tests of one set of regions; arrays share one shape."""

    t: np.ndarray
    dof: np.ndarray
    p: np.ndarray
    se: np.ndarray
    skipped: np.ndarray


def _two_sample(a: _RegionMoments, b: _RegionMoments) -> _Tests:
    """Welch t tests of ``a.mean == b.mean`` with the float-rounding floor."""
    diff = a.mean - b.mean
    floor = np.maximum(FLOAT_TOLERANCE_REL * np.maximum(np.abs(a.mean), np.abs(b.mean)),
                       FLOAT_TOLERANCE_ABS)
    var = a.var + b.var + floor**2
    se = np.sqrt(var)
    # The floor is a known constant (infinite dof): it adds to var only.
    dof_den = a.dof_term + b.dof_term
    with np.errstate(divide="ignore", invalid="ignore"):
        dof = np.where(dof_den > 0, var**2 / dof_den, np.inf)
    t = diff / se
    skipped = ~(a.noisy | b.noisy) & (np.abs(diff) <= floor)
    p = np.where(skipped, np.nan, 2.0 * student_t_sf(np.abs(t), dof))
    return _Tests(t=t, dof=dof, p=p, se=se, skipped=skipped)


# ----------------------------------------------------------------------------
# Result
# ----------------------------------------------------------------------------

def _relative(a, b):
    """``a / b - 1``, NaN where ``b == 0``."""
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(b != 0, a / np.where(b != 0, b, 1.0) - 1.0, np.nan)


def jsonable(x):
    """numpy -> plain Python with NaN/inf as None (strict JSON has neither)."""
    if isinstance(x, dict):
        return {k: jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return jsonable(x.tolist())
    if isinstance(x, (np.bool_, bool)):
        return bool(x)
    if isinstance(x, (np.integer, int)):
        return int(x)
    if isinstance(x, (np.floating, float)):
        return float(x) if math.isfinite(x) else None
    return x


@dataclass
class Agreement:
    """Outcome of :func:`compare_stacks`.

    Channel axes are RGB.  ``a`` is the render under test, ``b`` the reference.

    verdict             "agree" or "differ" (any Holm-rejected test)
    alpha               family-wise error rate of the whole comparison
    confidence          level of ``frame_rel_bias_ci``
    shape               (h, w) of the images
    seeds               (K_a, K_b) renders per stack
    n_tests, n_skipped  tests run; regions x channels without noise nor difference
    correlation         (2, 2) pixel correlation factors, rows a and b, columns
                        block scale (measured) and frame scale (from lags up
                        to MAX_CORRELATION_LAG); 1 = independent pixels
    correlation_dof     (2,) degrees of freedom of a's and b's block factor
    edges_y, edges_x    (gy + 1,), (gx + 1,) int block edges in pixels
    frame_mean_a/_b     (3,) frame means
    frame_se_a/_b       (3,) their standard errors
    frame_t, frame_dof, frame_p, frame_p_holm   (3,) test statistic ("bias over
                        its noise"), its degrees of freedom, two-sided p-value,
                        Holm-adjusted p-value
    frame_rel_bias      (3,) frame_mean_a / frame_mean_b - 1
    frame_rel_bias_ci   (3, 2) its confidence interval (delta method)
    block_mean_a/_b     (gy, gx, 3) block means
    block_se            (gy, gx, 3) standard error of the difference
    block_t, block_dof, block_p, block_p_holm   (gy, gx, 3); p NaN where skipped
    block_rel_diff      (gy, gx, 3) block_mean_a / block_mean_b - 1
    """

    verdict: str
    alpha: float
    confidence: float
    shape: tuple
    seeds: tuple
    n_tests: int
    n_skipped: int
    correlation: np.ndarray
    correlation_dof: np.ndarray
    edges_y: np.ndarray
    edges_x: np.ndarray
    frame_mean_a: np.ndarray
    frame_mean_b: np.ndarray
    frame_se_a: np.ndarray
    frame_se_b: np.ndarray
    frame_t: np.ndarray
    frame_dof: np.ndarray
    frame_p: np.ndarray
    frame_p_holm: np.ndarray
    frame_rel_bias: np.ndarray
    frame_rel_bias_ci: np.ndarray
    block_mean_a: np.ndarray
    block_mean_b: np.ndarray
    block_se: np.ndarray
    block_t: np.ndarray
    block_dof: np.ndarray
    block_p: np.ndarray
    block_p_holm: np.ndarray
    block_rel_diff: np.ndarray

    @property
    def frame_rejected(self) -> np.ndarray:
        """(3,) bool: frame channels that differ."""
        return np.nan_to_num(self.frame_p_holm, nan=1.0) <= self.alpha

    @property
    def block_rejected(self) -> np.ndarray:
        """(gy, gx, 3) bool: block channels that differ."""
        return np.nan_to_num(self.block_p_holm, nan=1.0) <= self.alpha

    @property
    def pixels_correlated(self) -> bool:
        """True if either stack's pixels are measurably not independent."""
        sd = np.sqrt(2.0 / self.correlation_dof)
        return bool(np.any(self.correlation.max(axis=1) > 1.0 + CORRELATION_WARNING_SIGMAS * sd))

    @property
    def share_blocks_differ(self) -> float:
        """Share of tested blocks with at least one differing channel."""
        tested = ~np.isnan(self.block_p).all(axis=-1)
        n = int(tested.sum())
        return float(self.block_rejected.any(axis=-1).sum() / n) if n else 0.0

    def differing_blocks(self) -> list:
        """Differing (block, channel) pairs, largest ``|t|`` first.

        Returns
        -------
        list of dict
            ``row``, ``col`` (grid coordinates, row 0 at the top), ``channel``
            ("R", "G" or "B"), ``t``, ``rel_diff``, ``p_holm``.
        """
        rows, cols, chans = np.nonzero(self.block_rejected)
        found = [dict(row=int(r), col=int(c), channel=CHANNELS[ch],
                      t=float(self.block_t[r, c, ch]),
                      rel_diff=float(self.block_rel_diff[r, c, ch]),
                      p_holm=float(self.block_p_holm[r, c, ch]))
                 for r, c, ch in zip(rows, cols, chans)]
        return sorted(found, key=lambda d: -abs(d["t"]))

    def summary(self) -> str:
        """One line: verdict, frame bias per channel, blocks that differ."""
        frame = ", ".join(
            f"{ch} {100 * rb:+.2f}% [{100 * lo:+.2f}, {100 * hi:+.2f}] t={t:+.1f}"
            for ch, rb, (lo, hi), t in zip(CHANNELS, self.frame_rel_bias,
                                           self.frame_rel_bias_ci, self.frame_t))
        n_blocks = self.block_p.shape[0] * self.block_p.shape[1]
        n_differ = int(self.block_rejected.any(axis=-1).sum())
        return (f"{self.verdict}: frame a/b-1 {frame}; {n_differ}/{n_blocks} blocks differ; "
                f"alpha={self.alpha:g} over {self.n_tests} tests ({self.n_skipped} skipped), "
                f"K={self.seeds[0]}/{self.seeds[1]}, pixel correlation "
                f"{self.correlation[0].max():.2f}/{self.correlation[1].max():.2f}"
                + (" (pixels not independent: denoiser or splatting filter on?)"
                   if self.pixels_correlated else ""))

    def to_dict(self) -> dict:
        """Plain JSON-ready dict of every field plus ``differing_blocks``,
        ``share_blocks_differ`` and ``summary`` (NaN and inf become None)."""
        out = {name: getattr(self, name) for name in self.__dataclass_fields__}
        out.update(frame_rejected=self.frame_rejected, block_rejected=self.block_rejected,
                   pixels_correlated=self.pixels_correlated,
                   share_blocks_differ=self.share_blocks_differ,
                   differing_blocks=self.differing_blocks(), summary=self.summary())
        return jsonable(out)


# ----------------------------------------------------------------------------
# Entry point
# ----------------------------------------------------------------------------

def _as_stack(x, name: str) -> np.ndarray:
    """Validate a ``(K, h, w, C)`` stack and return its RGB as float64."""
    x = np.asarray(x)
    if x.ndim != 4 or x.shape[-1] not in (3, 4):
        raise ValueError(f"stack {name} must have shape (K, h, w, 3 or 4), got {x.shape}")
    if x.shape[0] < 2:
        raise ValueError(f"stack {name} has {x.shape[0]} render(s); at least 2 seeds are needed "
                         "to estimate the noise")
    rgb = np.asarray(x[..., :3], dtype=np.float64)
    bad = int(np.count_nonzero(~np.isfinite(rgb)))
    if bad:
        raise ValueError(f"stack {name} has {bad} non-finite (NaN or inf) RGB values")
    return rgb


def compare_stacks(a, b, grid=(8, 8), alpha: float = 1e-3,
                   confidence: float = 0.95) -> Agreement:
    """Test whether two stacks of renders have the same expected pixel values.

    Parameters
    ----------
    a : (K_a, h, w, C) float
        Independent renders (different seeds) under test; C = 3 or 4, RGB used.
    b : (K_b, h, w, C) float
        Independent renders of the reference.  K_a, K_b >= 2.
    grid : (int, int)
        Block rows and columns tested besides the whole frame.
    alpha : float
        Family-wise error rate over all (region, channel) tests (Holm).
    confidence : float
        Level of the confidence interval on the frame's relative bias.

    Returns
    -------
    Agreement

    Raises
    ------
    ValueError
        On shapes that do not match, fewer than 2 seeds, non-finite values,
        an image smaller than the grid or ``alpha``/``confidence`` outside (0, 1).
    """
    if not (0 < alpha < 1 and 0 < confidence < 1):
        raise ValueError(f"alpha and confidence must lie in (0, 1), got {alpha}, {confidence}")
    a, b = _as_stack(a, "a"), _as_stack(b, "b")
    if a.shape[1:] != b.shape[1:]:
        raise ValueError(f"image sizes differ: a is {a.shape[2]}x{a.shape[1]}, "
                         f"b is {b.shape[2]}x{b.shape[1]} (width x height)")
    h, w = a.shape[1:3]
    if h < grid[0] or w < grid[1]:
        raise ValueError(f"image {w}x{h} is smaller than the {grid[1]}x{grid[0]} block grid")
    ey, ex = block_edges(h, grid[0]), block_edges(w, grid[1])

    frame_a, blocks_a, corr_a, corr_dof_a = _stack_moments(a, ey, ex)
    frame_b, blocks_b, corr_b, corr_dof_b = _stack_moments(b, ey, ex)
    frame, blocks = _two_sample(frame_a, frame_b), _two_sample(blocks_a, blocks_b)

    p_all = np.concatenate([frame.p.ravel(), blocks.p.ravel()])
    tested = ~np.isnan(p_all)
    p_holm = np.full(p_all.shape, np.nan)
    p_holm[tested] = holm_adjust(p_all[tested])
    verdict = "differ" if np.any(p_holm[tested] <= alpha) else "agree"

    rel_bias = _relative(frame_a.mean, frame_b.mean)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = frame_a.mean / frame_b.mean
        se_rel = np.sqrt(frame_a.var + ratio**2 * frame_b.var) / np.abs(frame_b.mean)
    q = student_t_isf(0.5 * (1 - confidence), frame.dof)
    ci = np.stack([rel_bias - q * se_rel, rel_bias + q * se_rel], axis=-1)

    return Agreement(
        verdict=verdict, alpha=alpha, confidence=confidence, shape=(h, w),
        seeds=(a.shape[0], b.shape[0]), n_tests=int(tested.sum()),
        n_skipped=int((~tested).sum()), correlation=np.stack([corr_a, corr_b]),
        correlation_dof=np.array([corr_dof_a, corr_dof_b]),
        edges_y=ey, edges_x=ex,
        frame_mean_a=frame_a.mean, frame_mean_b=frame_b.mean,
        frame_se_a=np.sqrt(frame_a.var), frame_se_b=np.sqrt(frame_b.var),
        frame_t=frame.t, frame_dof=frame.dof, frame_p=frame.p, frame_p_holm=p_holm[:3],
        frame_rel_bias=rel_bias, frame_rel_bias_ci=ci,
        block_mean_a=blocks_a.mean, block_mean_b=blocks_b.mean, block_se=blocks.se,
        block_t=blocks.t, block_dof=blocks.dof, block_p=blocks.p,
        block_p_holm=p_holm[3:].reshape(blocks.p.shape),
        block_rel_diff=_relative(blocks_a.mean, blocks_b.mean),
    )


# ----------------------------------------------------------------------------
# Error metrics against a reference image
# ----------------------------------------------------------------------------

def _paired(img, ref):
    """Both images as float64 ``(h, w, c)``, RGB only, same shape."""
    img, ref = np.asarray(img, np.float64), np.asarray(ref, np.float64)
    if img.shape != ref.shape:
        raise ValueError(f"image shape {img.shape} differs from reference shape {ref.shape}")
    if img.ndim == 2:
        img, ref = img[..., None], ref[..., None]
    if img.ndim != 3:
        raise ValueError(f"expected an (h, w) or (h, w, C) image, got shape {img.shape}")
    if img.shape[-1] == 4:
        img, ref = img[..., :3], ref[..., :3]
    return img, ref


def relmse(img, ref, trim: float = 0.001, eps: float = 1e-2) -> float:
    """Relative mean squared error, outlier-trimmed.

    Per pixel the error is the mean over channels of ``(x - r)**2 / (r**2 + eps)``;
    the ``floor(trim * n_pixels)`` largest pixel errors are dropped (rendering
    papers drop the top 0.1 % so a few fireflies do not decide the score) and
    the rest averaged.

    Parameters
    ----------
    img, ref : (h, w) or (h, w, C) float
        Image and reference; C = 4 uses RGB only.
    trim : float
        Share of pixels dropped, in [0, 1).
    eps : float
        Keeps dark reference pixels from dominating.

    Returns
    -------
    float
    """
    if not 0 <= trim < 1:
        raise ValueError(f"trim must lie in [0, 1), got {trim}")
    img, ref = _paired(img, ref)
    per_pixel = ((img - ref) ** 2 / (ref**2 + eps)).mean(axis=-1).ravel()
    keep = per_pixel.size - int(math.floor(trim * per_pixel.size))
    return float(np.partition(per_pixel, keep - 1)[:keep].mean())


def smape(img, ref, eps: float = 1e-3) -> float:
    """Symmetric mean absolute percentage error, in [0, 1].

    Mean over pixels and channels of ``|x - r| / (|x| + |r| + eps)`` (the
    denoising literature's form, without a factor 2).

    Parameters
    ----------
    img, ref : (h, w) or (h, w, C) float
        Image and reference; C = 4 uses RGB only.
    eps : float
        Keeps black pixels defined.

    Returns
    -------
    float
    """
    img, ref = _paired(img, ref)
    return float((np.abs(img - ref) / (np.abs(img) + np.abs(ref) + eps)).mean())
