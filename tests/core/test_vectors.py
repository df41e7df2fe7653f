"""Row-wise 3-vector helpers: the same bits as numpy's general routines."""
import numpy as np
import pytest

from mcengine.vectors import bounds, cross, lengths


def test_lengths_and_cross_give_numpys_bits():
    """Over vectors spanning 40 orders of magnitude (float32 squares overflow to inf alike),
    float64 and float32, broadcast shapes."""
    rng = np.random.default_rng(7)
    for dtype in (np.float64, np.float32):
        a = (rng.normal(size=(4000, 3)) * 10.0 ** rng.uniform(-20, 20, (4000, 1))).astype(dtype)
        b = rng.normal(size=(4000, 3)).astype(dtype)
        corners = a[:3999].reshape(-1, 3, 3)
        with np.errstate(over="ignore"):
            np.testing.assert_array_equal(lengths(a), np.linalg.norm(a, axis=-1))
            np.testing.assert_array_equal(cross(a, b), np.cross(a, b))
            np.testing.assert_array_equal(lengths(corners), np.linalg.norm(corners, axis=2))
            np.testing.assert_array_equal(cross(corners, b[0]), np.cross(corners, b[0]))


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_bounds_are_numpys_min_and_max_along_the_rows(dtype):
    """Each column's lowest and highest value, in the points' type, the extremes anywhere
    (first, middle, last row) and a single point."""
    rng = np.random.default_rng(11)
    points = rng.normal(size=(1001, 3)).astype(dtype)
    points[0, 0], points[500, 1], points[-1, 2] = -9.0, 7.0, 8.0
    for p in (points, points[:1], np.asarray(points[::-1])):
        lo, hi = bounds(p)
        assert lo.dtype == hi.dtype == dtype
        np.testing.assert_array_equal(lo, p.min(axis=0))
        np.testing.assert_array_equal(hi, p.max(axis=0))
