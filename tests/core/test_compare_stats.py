"""Tests of mcengine.evaluation.stats: the test that decides whether two renders agree.

Synthetic "renders" are a smooth ground-truth image times per-pixel
multiplicative lognormal noise of mean 1 (skewed and heavy-tailed, like Monte
Carlo pixel estimates), independent per pixel, channel and seed.  A lognormal
sigma of 0.1-0.25 gives a per-pixel relative standard deviation of 0.1-0.25:
a 128x128 path-traced render at ~256 spp with a per-sample relative
deviation of 1.6-4.  (Cycles' Cornell box in blend_scenes/ at 256 spp shows
a median of 0.04, so these tests are harsher than that scene.)

Rate checks use fixed seeds and state their binomial margin: with 200 trials
at a true rate of 0.05, more than 18 false alarms (rate > 0.09) has
probability 0.6 %, so a calibrated test passes, and one whose real rate is
0.13 or more fails with probability 95 %.
"""
import json
import math

import numpy as np
import pytest
from scipy import stats

from mcengine.evaluation.stats import (
    MAX_CORRELATION_LAG,
    _lag_correlation,
    block_edges,
    block_means,
    compare_stacks,
    holm_adjust,
    relmse,
    smape,
    student_t_isf,
    student_t_sf,
)

NULL_TRIALS = 200
MAX_FALSE_ALARM_RATE = 0.09   # binom.sf(18, 200, 0.05) = 0.006, see module docstring
# Kolmogorov-Smirnov: sqrt(n) * D exceeds 1.63 with probability 1 % for
# uniform samples (asymptotic Kolmogorov distribution).
KS_CRITICAL_1PCT = 1.63


# ----------------------------------------------------------------------------
# Synthetic renders
# ----------------------------------------------------------------------------

def smooth_truth(h=128, w=128):
    """(h, w, 3) positive image: a soft light blob over gradients (0.1 to 0.7)."""
    y, x = np.mgrid[0:h, 0:w] / np.array([h, w], float)[:, None, None]
    blob = 0.15 + 0.5 * np.exp(-((x - 0.3) ** 2 + (y - 0.4) ** 2) / 0.1)
    return np.stack([blob, 0.8 * blob + 0.1 * x, 0.6 * blob + 0.2 * y], axis=-1)


def render_stack(rng, truth, k, sigma, blur=False):
    """(k, h, w, 3) renders: truth x lognormal noise of mean 1.

    ``blur`` spreads each pixel's noise over its neighbours with the separable
    tent [1/4, 1/2, 1/4] (periodic edges), as a splatting pixel filter would.
    """
    noise = np.exp(sigma * rng.standard_normal((k,) + truth.shape) - sigma**2 / 2)
    if blur:
        for axis in (1, 2):
            noise = 0.5 * noise + 0.25 * (np.roll(noise, 1, axis) + np.roll(noise, -1, axis))
    return truth * noise


def null_trials(seed, n, h, sigma, ks=(2, 3, 4), blur=False, alpha=0.05):
    """Compare independent stacks of one truth ``n`` times; K cycles over ``ks``."""
    rng = np.random.default_rng(seed)
    truth = smooth_truth(h, h)
    return [compare_stacks(render_stack(rng, truth, ks[i % len(ks)], sigma, blur),
                           render_stack(rng, truth, ks[(i + 1) % len(ks)], sigma, blur),
                           alpha=alpha)
            for i in range(n)]


def false_alarm_rate(results):
    return np.mean([r.verdict == "differ" for r in results])


# ----------------------------------------------------------------------------
# Distributions, Holm, blocks
# ----------------------------------------------------------------------------

@pytest.mark.parametrize("dof", [0.7, 1, 2, 3.5, 10, 64, 1000, 1e5, 1e6, math.inf])
def test_student_t_tail_and_quantile_match_scipy(dof):
    ref = stats.norm if math.isinf(dof) else stats.t(dof)
    for t in [-3.0, 0.0, 0.3, 1.0, 2.5, 4.0, 6.0, 10.0, 30.0]:
        assert student_t_sf(t, dof) == pytest.approx(ref.sf(t), rel=1e-7, abs=1e-300)
    for p in [0.9, 0.5, 0.025, 1e-3, 1e-6, 1e-10]:
        assert student_t_isf(p, dof) == pytest.approx(ref.isf(p), rel=1e-8, abs=1e-12)
    # arrays in, arrays out
    np.testing.assert_allclose(student_t_sf(np.array([[1.0, 2.0]]), dof), ref.sf([[1.0, 2.0]]),
                               rtol=1e-7)


def test_student_t_tail_of_many_large_dof_at_once():
    """Elements whose continued fractions converge at different steps (these six, from a
    4-seed comparison of world_sky at 128 x 128, made it raise 'did not converge': each
    converged alone, never all at one step) give scipy's tails."""
    t = np.array([2.811671180049448, 2.5003665530142554, 2.205332214398314,
                  1.8934765151847923, 1.8777215307175346, 1.9070804737270555])
    dof = np.array([129522.62810844809, 139775.51805719384, 116852.49657157176,
                    111848.46191001231, 109913.38383366543, 129390.5126906115])
    np.testing.assert_allclose(student_t_sf(t, dof), stats.t(dof).sf(t), rtol=1e-7)


def test_holm_adjust_hand_example():
    # sorted: .005*4=.02, .01*3=.03, .03*2=.06, .04*1=.04 -> running max .06
    p = [0.01, 0.04, 0.03, 0.005]
    np.testing.assert_allclose(holm_adjust(p), [0.03, 0.06, 0.06, 0.02])
    np.testing.assert_allclose(holm_adjust([0.5, 0.9]), [1.0, 1.0])


def test_block_means_non_divisible_size_matches_loop():
    rng = np.random.default_rng(3)
    img = rng.random((37, 50, 3))
    ey, ex = block_edges(37, 8), block_edges(50, 7)
    assert ey[0] == 0 and ey[-1] == 37 and np.all(np.diff(ey) >= 4)
    expected = np.array([[img[ey[i]:ey[i + 1], ex[j]:ex[j + 1]].mean(axis=(0, 1))
                          for j in range(7)] for i in range(8)])
    np.testing.assert_allclose(block_means(img, (8, 7)), expected, rtol=1e-12)
    np.testing.assert_allclose(block_means(img[..., 0], (8, 7)), expected[..., 0], rtol=1e-12)


# ----------------------------------------------------------------------------
# Null hypothesis: independent renders of the same truth must agree
# ----------------------------------------------------------------------------

def test_null_false_alarm_rate_uniform_p_values_and_ci_coverage():
    results = null_trials(seed=11, n=NULL_TRIALS, h=64, sigma=0.5)
    assert false_alarm_rate(results) <= MAX_FALSE_ALARM_RATE

    # Frame p-values (3 independent channels per trial) are uniform.
    p = np.concatenate([r.frame_p for r in results])
    d = stats.kstest(p, "uniform").statistic
    assert math.sqrt(p.size) * d < KS_CRITICAL_1PCT

    # The 95 % interval on the relative bias covers 0 in >= 92 % of 600
    # cases (a calibrated interval falls below that with probability 0.06 %).
    lo, hi = np.concatenate([r.frame_rel_bias_ci for r in results]).T
    assert np.mean((lo <= 0) & (0 <= hi)) >= 0.92


def test_null_with_two_seeds_and_default_alpha_agrees():
    results = null_trials(seed=5, n=20, h=128, sigma=0.5, ks=(2,), alpha=1e-3)
    assert all(r.verdict == "agree" for r in results)
    # the seed-to-seed variance explains the noise: no hidden correlation
    corr = np.array([r.correlation for r in results])
    assert abs(corr[..., 0].mean() - 1.0) < 0.05 and abs(corr[..., 1].mean() - 1.0) < 0.1
    assert not any(r.pixels_correlated for r in results)


def test_null_few_pixels_per_block_is_not_overconfident():
    # 32x32 pixels, 8x8 grid: 16 pixels per block, 16 dof per block at K=2,
    # with very skewed noise.  A normal (z) p-value raises false alarms here
    # (measured 0.12 at these seeds); the Welch-Satterthwaite t does not.
    results = null_trials(seed=23, n=NULL_TRIALS, h=32, sigma=1.0, ks=(2,))
    assert false_alarm_rate(results) <= MAX_FALSE_ALARM_RATE


def test_lag_correlation_matches_direct_pair_sum():
    # noise correlated along one diagonal only, on a non-square image
    rng = np.random.default_rng(12)
    e = rng.standard_normal((3, 23, 31, 3))
    e[:, 1:, :-1] += 0.6 * e[:, :-1, 1:]
    e -= e.mean(axis=0)
    h, w, lag = 23, 31, MAX_CORRELATION_LAG
    cross = sum((e[:, :h - dy, max(0, -dx):w - max(0, dx)] * e[:, dy:, max(0, dx):w + min(0, dx)]).sum()
                for dy in range(lag + 1) for dx in range(-lag, lag + 1) if (dy, dx) > (0, 0))
    assert _lag_correlation(e) == pytest.approx(1 + 2 * cross / (e**2).sum(), rel=1e-12)


def expected_tent_correlation(block):
    """Variance ratio of a block mean under the tent blur vs independent pixels."""
    acf = {0: 0.375, 1: 0.25, 2: 0.0625}   # autocorrelation of [1/4, 1/2, 1/4]
    pair_sum = sum(acf[abs(i - j)] for i in range(block) for j in range(block)
                   if abs(i - j) <= 2)
    return (pair_sum / (block * acf[0])) ** 2   # separable in x and y


def test_correlated_pixels_are_measured_and_do_not_raise_false_alarms():
    results = null_trials(seed=17, n=NULL_TRIALS, h=64, sigma=0.5, blur=True)
    corr = np.array([r.correlation for r in results])          # (trials, a/b, block/frame)
    # 8x8-pixel blocks see 5.84 of the 6.95 the whole 64x64 frame sees
    # (pairs across the periodic image edge are not counted); per-stack
    # estimates scatter by ~8 %, their mean over 400 stacks by < 1 %.
    assert corr[..., 0].mean() == pytest.approx(expected_tent_correlation(8), rel=0.03)
    assert corr[..., 1].mean() == pytest.approx(expected_tent_correlation(64), rel=0.03)
    assert false_alarm_rate(results) <= MAX_FALSE_ALARM_RATE
    p = np.concatenate([r.frame_p for r in results])
    assert math.sqrt(p.size) * stats.kstest(p, "uniform").statistic < KS_CRITICAL_1PCT
    assert all(r.pixels_correlated for r in results)
    assert "pixels not independent" in results[0].summary()


# ----------------------------------------------------------------------------
# Power: real differences must be found, and located
# ----------------------------------------------------------------------------

def test_light_five_percent_too_bright_is_detected():
    rng = np.random.default_rng(2)
    truth = smooth_truth()
    for _ in range(10):
        r = compare_stacks(render_stack(rng, 1.05 * truth, 2, 0.25),
                           render_stack(rng, truth, 2, 0.25))
        assert r.verdict == "differ"
        assert np.all(r.frame_rejected)
        # frame t ~ 22 (se of a/b-1 ~ 0.25 / sqrt(128*128*2) * sqrt(2))
        assert np.all(r.frame_t > 10)
        np.testing.assert_allclose(r.frame_rel_bias, 0.05, atol=0.01)
        lo, hi = r.frame_rel_bias_ci.T
        assert np.all(lo < hi) and np.all(hi - lo < 0.02)


def test_wall_colour_off_by_0_02_in_one_block_is_detected_and_named():
    # Block (row 2, col 5) of the 8x8 grid is pixels [32:48, 80:96]; its green
    # mean is 0.274, so +0.02 is +7 %; at K=2, sigma 0.1 its t is ~11
    # (power measured 100 % in 100 trials; 98 % at K=4, sigma 0.2, t ~7.8).
    rng = np.random.default_rng(4)
    truth = smooth_truth()
    wrong = truth.copy()
    wrong[32:48, 80:96, 1] += 0.02
    for _ in range(10):
        r = compare_stacks(render_stack(rng, wrong, 2, 0.1), render_stack(rng, truth, 2, 0.1))
        assert r.verdict == "differ"
        named = [(d["row"], d["col"], d["channel"]) for d in r.differing_blocks()]
        assert named == [(2, 5, "G")]
        # the relative difference is right to within 4 of its standard errors
        se_rel = r.block_se[2, 5, 1] / r.block_mean_b[2, 5, 1]
        assert abs(r.differing_blocks()[0]["rel_diff"] - 0.02 / 0.274) < 4 * se_rel


def test_missing_light_darkens_a_quadrant_and_is_located():
    rng = np.random.default_rng(6)
    truth = smooth_truth()
    missing = truth.copy()
    missing[64:, 64:] *= 0.8         # the light of the lower-right quadrant is gone
    for _ in range(5):
        r = compare_stacks(render_stack(rng, missing, 2, 0.25), render_stack(rng, truth, 2, 0.25))
        assert r.verdict == "differ"
        differ = r.block_rejected.any(axis=-1)
        assert differ[4:, 4:].all() and differ.sum() == 16
        assert r.share_blocks_differ == pytest.approx(16 / 64)


# ----------------------------------------------------------------------------
# Special regions, inputs and report
# ----------------------------------------------------------------------------

def test_black_regions_skipped_and_float_rounding_is_not_a_difference():
    rng = np.random.default_rng(8)
    truth = smooth_truth(64, 64)
    truth[:32] = 0.0                 # black upper half: 4 block rows x 8 x 3 channels
    a, b = render_stack(rng, truth, 2, 0.3), render_stack(rng, truth, 2, 0.3)
    a[:, :8, :, :] = 0.5 * (1 + 1e-7)   # noise-free background, rounded differently
    b[:, :8, :, :] = 0.5
    r = compare_stacks(a, b)
    assert r.verdict == "agree"
    # rows 1-3 are black, row 0 noise free and equal to float precision:
    # all skipped; the frame and the noisy lower half are tested
    assert r.n_skipped == 4 * 8 * 3
    assert r.n_tests == 3 + 4 * 8 * 3
    assert np.isnan(r.block_p[:4]).all() and not np.isnan(r.block_p[4:]).any()

    a[:, :8, :, :] = 0.5 * (1 + 1e-3)   # a real, noise-free difference
    r = compare_stacks(a, b)
    assert r.verdict == "differ" and r.n_skipped == 3 * 8 * 3
    assert {d["row"] for d in r.differing_blocks()} == {0}


def test_alpha_channel_ignored_and_seed_counts_may_differ():
    rng = np.random.default_rng(9)
    truth = smooth_truth(48, 40)
    a = np.concatenate([render_stack(rng, truth, 3, 0.3), np.ones((3, 48, 40, 1))], -1)
    b = np.concatenate([render_stack(rng, truth, 2, 0.3), np.zeros((2, 48, 40, 1))], -1)
    r = compare_stacks(a, b)
    assert r.verdict == "agree" and r.seeds == (3, 2)
    assert r.block_t.shape == (8, 8, 3)


@pytest.mark.parametrize("a_shape, b_shape, kwargs, message", [
    ((1, 16, 16, 3), (2, 16, 16, 3), {}, "at least 2 seeds"),
    ((2, 16, 16, 3), (2, 16, 17, 3), {}, "image sizes differ"),
    ((2, 16, 16, 2), (2, 16, 16, 2), {}, "must have shape"),
    ((2, 6, 16, 3), (2, 6, 16, 3), {}, "smaller than the 8x8 block grid"),
    ((2, 16, 16, 3), (2, 16, 16, 3), {"alpha": 0.0}, "alpha and confidence"),
])
def test_bad_input_raises_one_clear_error(a_shape, b_shape, kwargs, message):
    with pytest.raises(ValueError, match=message):
        compare_stacks(np.ones(a_shape), np.ones(b_shape), **kwargs)


def test_non_finite_values_are_refused():
    a = np.ones((2, 16, 16, 3))
    a[1, 3, 4, 2] = np.nan
    with pytest.raises(ValueError, match="stack a has 1 non-finite"):
        compare_stacks(a, np.ones((2, 16, 16, 3)))


def test_report_is_json_and_one_line():
    rng = np.random.default_rng(10)
    truth = smooth_truth(64, 64)
    r = compare_stacks(render_stack(rng, 1.1 * truth, 2, 0.2), render_stack(rng, truth, 2, 0.2))
    line = r.summary()
    assert "\n" not in line and line.startswith("differ: frame a/b-1 R +")
    assert "not independent" not in line
    d = json.loads(json.dumps(r.to_dict(), allow_nan=False))
    assert d["verdict"] == "differ" and d["seeds"] == [2, 2]
    assert len(d["block_t"]) == 8 and len(d["block_t"][0][0]) == 3
    assert d["differing_blocks"][0].keys() == {"row", "col", "channel", "t", "rel_diff", "p_holm"}
    assert d["frame_rel_bias"][0] == pytest.approx(0.1, abs=0.02)


# ----------------------------------------------------------------------------
# Error metrics
# ----------------------------------------------------------------------------

def test_relmse_by_hand():
    ref = np.ones((2, 2, 3))
    img = np.array([[[1, 1, 1], [3, 1, 1]], [[2, 2, 2], [1, 1, 11]]], float)
    # eps = 1: per-value (x-1)^2/2; per-pixel means 0, 2/3, 1/2, 50/3
    assert relmse(img, ref, trim=0.0, eps=1.0) == pytest.approx((2 / 3 + 1 / 2 + 50 / 3) / 4)
    # 0.1 % of 4 pixels drops none; 25 % drops the worst one
    assert relmse(img, ref, eps=1.0) == pytest.approx((2 / 3 + 1 / 2 + 50 / 3) / 4)
    assert relmse(img, ref, trim=0.25, eps=1.0) == pytest.approx((2 / 3 + 1 / 2) / 3)
    # default eps on one value; RGBA uses RGB only
    one = relmse(np.full((1, 1, 4), 0.5), np.array([[[0.25, 0.25, 0.25, 9.0]]]))
    assert one == pytest.approx(0.0625 / (0.0625 + 0.01))


def test_relmse_trims_the_top_tenth_of_a_percent():
    ref = np.ones((50, 40))               # 2000 pixels -> 2 dropped
    img = ref.copy()
    img[0, :3] = [101.0, 51.0, 2.0]       # errors 1e4/1.01, 2500/1.01, 1/1.01
    assert relmse(img, ref) == pytest.approx(1 / 1.01 / 1998)


def test_smape_by_hand():
    img = np.array([[1.0, 0.0, 3.0]])
    ref = np.array([[1.0, 2.0, 1.0]])
    assert smape(img, ref, eps=0.0) == pytest.approx((0 + 1 + 0.5) / 3)
    assert smape(img, ref) == pytest.approx((2 / 2.001 + 2 / 4.001) / 3)
    with pytest.raises(ValueError, match="differs from reference shape"):
        smape(img, ref[:, :2])
