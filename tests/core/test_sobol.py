"""The Sobol sampler: its points, their stratification, their independence, their error.

* The unscrambled points are the Sobol sequence (scipy's, Joe-Kuo directions).
* Stratification: the first 2^m samples of a pixel in one dimension set put
  exactly one point in every elementary interval of volume 2^-m in 1D and in
  the first two dimensions, two in volume 2^(1-m) in three and eight in
  2^(3-m) in four ((0, m, 2)-, (1, m, 3)- and (3, m, 4)-nets), whatever the
  pixel, seed, set or index mask, and every prefix of a longer run keeps it.
* Independence: numbers of different dimension sets (bounces, light and
  BSDF, the pixel filter) pair up as if drawn independently, pixel by pixel.
* Unbiasedness: a fixed sample's numbers are uniform over pixels (each
  pixel's scrambling is random), and the N-sample estimates of a closed-form
  integral average to it.
* Error: the lecture's plot.  For a smooth 2D integrand the RMSE of the Sobol
  sampler falls as N^-1.5 (slope below -1) against N^-0.5 for independent
  numbers; for an integrand with a discontinuity (a disk) as N^-0.75.
"""
import math
from itertools import product

import numba
import numpy as np
import pytest
from scipy import stats
from scipy.stats import qmc

from mcengine.kernels.sampling import (
    SAMPLER_INDEPENDENT,
    SAMPLER_SOBOL,
    SET_BSDF,
    SET_FILTER,
    SET_LIGHT,
    bounce_set,
    sample_1d,
    sample_2d,
    sample_4d,
    sample_key,
)
from mcengine.kernels.sobol import DIRECTIONS, INDEX_BITS, TABLES, index_mask

FULL_MASK = index_mask(1 << INDEX_BITS)     # the largest index mask (2^24 samples)


@numba.njit
def _points(sampler, seed, first_pixel, pixels, n, dim_set, mask, dims):
    """(pixels, n, 4) numbers of samples 0..n-1 of consecutive pixels from one set,
    drawn through the 1D, 2D or 4D call (``dims``; the unused columns stay 0)."""
    out = np.zeros((pixels, n, 4))
    m = np.uint64(mask)
    for p in range(pixels):
        for s in range(n):
            key = sample_key(sampler, seed, first_pixel + p, s)
            if dims == 1:
                out[p, s, 0] = sample_1d(sampler, key, dim_set, m)
            elif dims == 2:
                out[p, s, 0], out[p, s, 1] = sample_2d(sampler, key, dim_set, m)
            else:
                a, b, c, d = sample_4d(sampler, key, dim_set, m)
                out[p, s, 0], out[p, s, 1], out[p, s, 2], out[p, s, 3] = a, b, c, d
    return out


def _raw_sobol(n):
    """The unscrambled points 0..n-1 (index order) from the direction numbers."""
    pts = np.zeros((n, 4))
    for i in range(n):
        r = [0] * 4
        for b in range(32):
            if i >> b & 1:
                r = [r[d] ^ int(DIRECTIONS[d, b]) for d in range(4)]
        pts[i] = [int(f"{x:032b}"[::-1], 2) / 2.0 ** 32 for x in r]
    return pts


def test_unscrambled_points_are_the_sobol_sequence():
    n = 256
    gray = np.arange(n) ^ (np.arange(n) >> 1)      # scipy enumerates in Gray-code order
    np.testing.assert_array_equal(_raw_sobol(n)[gray], qmc.Sobol(4, scramble=False).random(n))


def test_tables_hold_the_direction_numbers():
    for d in range(4):
        for b in range(INDEX_BITS):       # index bit b is bit 7 - b % 8 of reversed byte b // 8
            assert TABLES[d, b // 8, 1 << (7 - b % 8)] == DIRECTIONS[d, b]
        assert TABLES[d, 1, 0x81] == DIRECTIONS[d, 8] ^ DIRECTIONS[d, 15]
    with pytest.raises(ValueError, match="at most 2"):
        index_mask((1 << INDEX_BITS) + 1)
    assert index_mask(1) == 0 and index_mask(100) == 0xFE000000


def _is_net(points, m, t):
    """Whether every elementary interval of volume 2^(t-m) holds exactly 2^t points."""
    s = points.shape[1]
    for ks in product(range(m - t + 1), repeat=s):
        if sum(ks) != m - t:
            continue
        cell = np.zeros(len(points), np.int64)
        for d, k in enumerate(ks):
            cell = cell * (1 << k) + np.floor(points[:, d] * (1 << k)).astype(np.int64)
        if not np.all(np.bincount(cell, minlength=1 << (m - t)) == 1 << t):
            return False
    return True


@pytest.mark.parametrize("m", [1, 3, 6, 9])
@pytest.mark.parametrize("seed,pixel,dim_set", [(0, 0, bounce_set(0, SET_BSDF)),
                                                (1, 12345, bounce_set(3, SET_LIGHT)),
                                                (7, 99, bounce_set(40, SET_BSDF))])
def test_every_elementary_interval_holds_its_share(m, seed, pixel, dim_set):
    n = 1 << m
    for mask in (index_mask(n), index_mask(3 * n), FULL_MASK):
        p = _points(SAMPLER_SOBOL, seed, pixel, 1, n, dim_set, mask, 4)[0]
        assert all(_is_net(p[:, [d]], m, 0) for d in range(4))
        assert _is_net(p[:, :2], m, 0)
        assert _is_net(p[:, :3], m, min(1, m))
        assert _is_net(p, m, min(3, m))
    # The 1D and 2D calls (Russian roulette, the pixel filter) are stratified too.
    assert _is_net(_points(SAMPLER_SOBOL, seed, pixel, 1, n, SET_FILTER, index_mask(n), 2)[0, :, :2],
                   m, 0)
    assert _is_net(_points(SAMPLER_SOBOL, seed, pixel, 1, n, dim_set, index_mask(n), 1)[0, :, :1],
                   m, 0)


def test_every_power_of_two_prefix_of_a_long_run_is_a_net():
    # A pixel that stops early (adaptive sampling, a time limit) or renders in passes of
    # any size has taken a prefix of its sequence: each power-of-two prefix is a net.
    p = _points(SAMPLER_SOBOL, 3, 777, 1, 1024, bounce_set(1, SET_BSDF), index_mask(1000), 4)[0]
    for m in range(11):
        assert _is_net(p[:1 << m, :2], m, 0), m


def test_independent_numbers_are_not_stratified():
    # The check above can fail: independent numbers almost never form a net.
    p = _points(SAMPLER_INDEPENDENT, 0, 0, 1, 64, bounce_set(0, SET_BSDF), 0, 4)[0]
    assert not _is_net(p[:, :2], 6, 0)


def _pairing_chi2(a, b, cells):
    """Per pixel, the chi-square of the (a, b) counts on a cells x cells grid."""
    n = a.shape[1]
    ia = np.floor(a * cells).astype(np.int64)
    ib = np.floor(b * cells).astype(np.int64)
    expected = n / cells ** 2
    out = np.empty(a.shape[0])
    for p in range(a.shape[0]):
        counts = np.bincount(ia[p] * cells + ib[p], minlength=cells * cells)
        out[p] = ((counts - expected) ** 2 / expected).sum()
    return out


@pytest.mark.parametrize("set_a,set_b", [
    (bounce_set(0, SET_BSDF), bounce_set(1, SET_BSDF)),      # consecutive bounces
    (bounce_set(2, SET_LIGHT), bounce_set(2, SET_BSDF)),     # light and BSDF at one vertex
    (SET_FILTER, bounce_set(0, SET_BSDF)),                   # camera and first bounce
])
def test_dimension_sets_pair_up_as_independent_sequences(set_a, set_b):
    """Within a pixel, each set's 16 numbers are stratified (4 in each quarter), so the
    counts of (a, b) on a 4 x 4 grid form a table with margins of 4, whose chi-square
    measures how the two sets' samples are paired.  Two sets must pair up like two
    independent sequences, e.g. the same set of two different pixels (independently
    shuffled: chi-square 12 on average); sets that shared their index order (no
    shuffle) put the points on a diagonal pattern (chi-square 48), as does the same
    set twice.  4000 pixels: each mean has a standard error of about 0.12."""
    n, pixels = 16, 4000
    a = _points(SAMPLER_SOBOL, 5, 0, pixels, n, set_a, index_mask(n), 4)
    b = _points(SAMPLER_SOBOL, 5, 0, pixels, n, set_b, index_mask(n), 4)
    other = _points(SAMPLER_SOBOL, 5, pixels, pixels, n, set_a, index_mask(n), 4)
    for d in (0, 1):
        independent = _pairing_chi2(a[..., d], other[..., d], 4).mean()
        assert 10 < independent < 14
        assert abs(_pairing_chi2(a[..., d], b[..., d], 4).mean() - independent) < 0.7, d
        assert abs(np.corrcoef(a[..., d].ravel(), b[..., d].ravel())[0, 1]) < 0.03
    # within one set the first two dimensions are a net: every cell holds 1
    assert np.all(_pairing_chi2(a[..., 0], a[..., 1], 4) == 0.0)
    assert _pairing_chi2(a[..., 0], a[..., 0], 4).mean() == 48.0


def test_a_fixed_sample_is_uniform_over_pixels_and_seeds():
    """Owen scrambling makes every single point uniform: sample 5 of set BSDF, dimension
    by dimension, over 20000 pixels (Kolmogorov-Smirnov at 1e-4, four tests)."""
    p = _points(SAMPLER_SOBOL, 11, 0, 20000, 8, bounce_set(1, SET_BSDF), index_mask(8), 4)
    for d in range(4):
        assert stats.kstest(p[:, 5, d], "uniform").pvalue > 1e-4
    # and a different seed changes every pixel's scrambling
    q = _points(SAMPLER_SOBOL, 12, 0, 20000, 8, bounce_set(1, SET_BSDF), index_mask(8), 4)
    assert abs(np.corrcoef(p[:, 5, 0], q[:, 5, 0])[0, 1]) < 4 / math.sqrt(20000)


def _smooth(x, y):
    return np.exp(x + y)                   # integral (e - 1)^2


def _disk(x, y):
    return ((x - 0.5) ** 2 + (y - 0.45) ** 2 < 0.16).astype(np.float64)   # pi 0.16


SMOOTH_INTEGRAL = (math.e - 1) ** 2
DISK_INTEGRAL = math.pi * 0.16


def _rmse_by_n(sampler, f, exact, ns, replicates=256, dim_set=bounce_set(0, SET_BSDF)):
    """RMSE of the N-sample estimate of f over [0, 1)^2, over independent pixels."""
    out = []
    for n in ns:
        p = _points(sampler, 2, 0, replicates, n, dim_set, index_mask(n), 2)
        est = f(p[..., 0], p[..., 1]).mean(axis=1)
        out.append(math.sqrt(np.mean((est - exact) ** 2)))
    return np.array(out)


def _slope(ns, rmse):
    return np.polyfit(np.log(ns), np.log(rmse), 1)[0]


NS = 2 ** np.arange(2, 11)


def test_estimates_are_unbiased():
    """The mean of 4096 pixels' 16-sample estimates is the integral within 4.4 of its
    standard errors (from the spread over pixels, which are independent)."""
    p = _points(SAMPLER_SOBOL, 9, 0, 4096, 16, bounce_set(5, SET_LIGHT), index_mask(16), 4)
    for f, exact, (i, j) in ((_smooth, SMOOTH_INTEGRAL, (0, 1)), (_disk, DISK_INTEGRAL, (2, 3)),
                             (_disk, DISK_INTEGRAL, (0, 3))):
        est = f(p[..., i], p[..., j]).mean(axis=1)
        se = est.std(ddof=1) / math.sqrt(est.size)
        assert abs(est.mean() - exact) < 4.4 * se, (i, j, est.mean(), exact, se)


def test_lecture_error_against_samples():
    """RMSE against N on log-log axes: slope -0.5 for independent numbers (the 1/sqrt(N)
    law), below -1 for Sobol points on a smooth integrand (theory: -1.5) and about -0.75
    on a disk's indicator (theory: -0.75).  256 replicates per N give each RMSE to
    about 5 %, the slopes to about 0.03."""
    indep = _slope(NS, _rmse_by_n(SAMPLER_INDEPENDENT, _smooth, SMOOTH_INTEGRAL, NS))
    sobol = _slope(NS, _rmse_by_n(SAMPLER_SOBOL, _smooth, SMOOTH_INTEGRAL, NS))
    disk = _slope(NS, _rmse_by_n(SAMPLER_SOBOL, _disk, DISK_INTEGRAL, NS))
    assert abs(indep + 0.5) < 0.08, indep
    assert sobol < -1.2, sobol
    assert -0.9 < disk < -0.6, disk
