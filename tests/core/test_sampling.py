"""The lecture's Monte Carlo examples, run on the renderer's own random numbers.

Estimating pi from points in the unit square: 4 x the fraction inside the
quarter circle.  Each point is a Bernoulli trial with p = pi/4, so the
estimate's standard deviation is 4 sqrt(p (1 - p) / N): the error shrinks
as 1/sqrt(N).  Checked statistically over many independent keys (seeds):
the mean of the estimates is pi, and their spread matches the formula at
every N (a chi-square test on the sample variance).
"""
import math

import numpy as np
from numba import njit
from scipy import stats

from mcengine.kernels.sampling import path_key, rand


@njit(cache=False)
def _estimate_pi(seed, n):
    inside = 0
    for i in range(n):
        key = path_key(seed, i, 0)
        x, y = rand(key, 0), rand(key, 1)
        if x * x + y * y < 1.0:
            inside += 1
    return 4.0 * inside / n


def test_pi_estimate_error_shrinks_as_one_over_sqrt_n():
    p = math.pi / 4
    seeds = 200
    for n in (100, 1_000, 10_000, 100_000):
        est = np.array([_estimate_pi(seed, n) for seed in range(seeds)])
        sigma = 4 * math.sqrt(p * (1 - p) / n)
        # Unbiased: |mean - pi| within 4.4 standard errors of the mean.
        assert abs(est.mean() - math.pi) < 4.4 * sigma / math.sqrt(seeds), (n, est.mean())
        # Spread as the formula says: (k-1) s^2 / sigma^2 ~ chi2(k-1).
        chi = (seeds - 1) * est.var(ddof=1) / sigma ** 2
        lo, hi = stats.chi2.ppf([1e-4, 1 - 1e-4], seeds - 1)
        assert lo < chi < hi, (n, est.std(ddof=1), sigma)


@njit(cache=False)
def _numbers(n, dims):
    out = np.empty((n, dims))
    for i in range(n):
        key = path_key(7, i, 3)
        for d in range(dims):
            out[i, d] = rand(key, d)
    return out


def test_random_numbers_are_uniform_and_independent_across_dimensions():
    u = _numbers(20_000, 4)
    for d in range(4):
        assert stats.kstest(u[:, d], "uniform").pvalue > 1e-4
    corr = np.corrcoef(u.T)
    assert np.all(np.abs(corr - np.eye(4)) < 4.4 / math.sqrt(len(u)))
