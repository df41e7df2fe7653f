"""The Perlin lattice gradients (kernels/svm/noise.py) against Cycles' definitions
(kernel/svm/noise.h, grad1..grad4), written out with branches: every hash value, coordinates
of both signs and zeros, the same bits."""
import numpy as np
import pytest

from mcengine.kernels.svm.noise import _grad1, _grad2, _grad3, _grad4


def _neg(v, bit):
    return -v if bit else v


def grad1(h, x):
    h &= 15
    return _neg(1.0 + (h & 7), h & 8) * x


def grad2(h, x, y):
    h &= 7
    u, v = (x, 2.0 * y) if h < 4 else (y, 2.0 * x)
    return _neg(u, h & 1) + _neg(v, h & 2)


def grad3(h, x, y, z):
    h &= 15
    u = x if h < 8 else y
    v = y if h < 4 else (x if h in (12, 14) else z)
    return _neg(u, h & 1) + _neg(v, h & 2)


def grad4(h, x, y, z, w):
    h &= 31
    u = x if h < 24 else y
    v = y if h < 16 else z
    s = z if h < 8 else w
    return _neg(u, h & 1) + _neg(v, h & 2) + _neg(s, h & 4)


POINTS = [(0.25, -0.5, 0.75, -1.0), (-0.0, 0.0, -0.3, 0.9), (0.1, 0.2, 0.3, 0.4)]


@pytest.mark.parametrize("point", POINTS)
def test_gradients_are_cycles_bit_for_bit(point):
    x, y, z, w = point
    for h in range(64):          # the functions mask the hash: higher bits must not matter
        assert np.float64(_grad1(h, x)).tobytes() == np.float64(grad1(h, x)).tobytes()
        assert np.float64(_grad2(h, x, y)).tobytes() == np.float64(grad2(h, x, y)).tobytes()
        assert np.float64(_grad3(h, x, y, z)).tobytes() == np.float64(grad3(h, x, y, z)).tobytes()
        assert (np.float64(_grad4(h, x, y, z, w)).tobytes()
                == np.float64(grad4(h, x, y, z, w)).tobytes())
