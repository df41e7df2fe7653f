"""Scalar helpers of Cycles' util/math.h that many kernels share: clamps that stay finite."""
from __future__ import annotations

import math

from ..jit import device


@device
def saturate(x):
    """x clamped to [0, 1]; NaN gives 0, as Cycles' saturatef (fminf/fmaxf drop a NaN)."""
    if x > 1.0:
        return 1.0
    return x if x > 0.0 else 0.0


@device
def safe_acos(x):
    """acos of x clamped to [-1, 1] (Cycles' safe_acosf), for cosines that rounding has
    pushed just past one."""
    return math.acos(min(max(x, -1.0), 1.0))
