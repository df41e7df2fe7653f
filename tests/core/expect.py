"""Statistical assertions for Monte Carlo renders.

``assert_mean`` compares the mean over all pixels of a render with an exact
value.  Pixels are independent (each has its own samples), so the standard
error of the image mean is sqrt(sum of per-pixel variances of the mean) / n,
with the per-pixel variances estimated by the film from the samples.  The
test fails if the mean is more than Z standard errors away (|z| > 4.4 has a
two-sided probability of 1e-5 under a correct renderer), and also fails if
the standard error is too large for the test to mean anything: a test that
cannot tell a 1 % error apart from noise is not a test.
"""
from __future__ import annotations

import numpy as np

Z_LIMIT = 4.4


def render(scene, **kw):
    from mcengine.session import RenderSession
    return RenderSession(scene, **kw).run()


def image_mean_and_se(session, channel=0):
    img = session.image()[..., channel].astype(np.float64)
    var = session.variance()[..., channel].astype(np.float64)
    n = img.size
    if np.isinf(var).any():
        raise AssertionError("some pixels have fewer than 2 samples")
    return img.mean(), np.sqrt(var.sum()) / n


def assert_mean(session, expected, *, channel=0, max_rel_se=0.002, deterministic_tol=2e-4):
    """Image mean equals ``expected`` within Z_LIMIT standard errors.

    When the render has (almost) no noise, the comparison is relative to
    ``deterministic_tol`` (the residual is then sub-pixel position jitter).
    """
    mean, se = image_mean_and_se(session, channel)
    assert se <= max_rel_se * abs(expected) + 1e-12, (
        f"noise too large for a meaningful test: se {se:.3g} vs expected {expected:.6g}")
    tol = max(Z_LIMIT * se, deterministic_tol * abs(expected))
    assert abs(mean - expected) <= tol, (
        f"mean {mean:.6g} vs expected {expected:.6g} (se {se:.3g}, z {(mean - expected) / max(se, 1e-300):.2f})")
    return mean, se


def chi2_uniform_disk(points, rings=10, sectors=12):
    """Pearson chi-square of 2-D points against the uniform density on the unit disk.

    Cells are equal-area: rings of equal r^2 width times equal sectors.
    Returns ``(statistic, degrees of freedom)``.
    """
    points = np.asarray(points, float)
    r = np.hypot(points[:, 0], points[:, 1])
    ring = np.minimum((r * r * rings).astype(int), rings - 1)
    angle = np.arctan2(points[:, 1], points[:, 0]) + np.pi
    sector = (angle / (2 * np.pi) * sectors).astype(int) % sectors
    counts = np.bincount(ring * sectors + sector, minlength=rings * sectors)
    expected = len(points) / (rings * sectors)
    return ((counts - expected) ** 2 / expected).sum(), rings * sectors - 1
