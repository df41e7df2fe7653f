"""The shared scalar clamps of the kernels (mcengine.kernels.scalar) at their edges."""
from __future__ import annotations

import math

import pytest

from mcengine.kernels.scalar import safe_acos, saturate


@pytest.mark.parametrize("x, want", [(-2.0, 0.0), (-0.0, 0.0), (0.25, 0.25), (1.0, 1.0),
                                     (7.0, 1.0), (math.inf, 1.0), (-math.inf, 0.0),
                                     (math.nan, 0.0)])
def test_saturate_clamps_and_drops_nan(x, want):
    """Cycles' saturatef: fminf/fmaxf return the number when the other operand is NaN, so a
    NaN becomes 0 (a weight or roughness that went NaN must not spread)."""
    assert saturate(x) == want


@pytest.mark.parametrize("x, want", [(1.0 + 1e-12, 0.0), (-1.0 - 1e-12, math.pi), (5.0, 0.0),
                                     (0.5, math.acos(0.5)), (-0.5, math.acos(-0.5))])
def test_safe_acos_takes_cosines_past_one_as_one(x, want):
    assert safe_acos(x) == pytest.approx(want, abs=1e-15)
