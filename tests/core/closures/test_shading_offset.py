"""An object's Shadow Terminator Shading Offset on its closures, as Cycles applies it.

Closed form from Cycles 5.0.1 (kernel/closure/bsdf.h, shift_cos_in; scene/object.cpp): an
offset s is kept as the frequency f = 1 / (1 - s / 2), and a closure's value towards a
direction theta_i from its normal is multiplied by max(cos(f theta_i), 0) / cos(theta_i)
(on evaluation wherever cos(theta_i) >= 0, on sampling for all but transmitted samples).
The pdf is not changed.  What it renders beside Cycles: tests/nodes/test_bump_nodes.py.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from mcengine.kernels.closures import closure_eval, closure_sample
from mcengine.kernels.closures.layout import CL_TERMINATOR, CT_DIFFUSE, CT_TRANSLUCENT, LABEL_TRANSMIT

from .kernels import diffuse_row, direction, microfacet_row

WO = direction(30.0, 180.0)


def _frequency(offset):
    return 1.0 / (1.0 - 0.5 * offset)


@pytest.mark.parametrize("offset", [0.3, 1.0])
@pytest.mark.parametrize("theta", [0.0, 20.0, 44.0, 50.0, 80.0, 89.9])
def test_lambert_is_scaled_by_the_shifted_cosine(offset, theta):
    f = _frequency(offset)
    cl = diffuse_row(CT_DIFFUSE)
    plain = np.array(closure_eval(cl, 0, *WO, *direction(theta)))
    cl[0, CL_TERMINATOR] = f
    shifted = np.array(closure_eval(cl, 0, *WO, *direction(theta)))
    t = math.radians(theta)
    expected = max(math.cos(f * t), 0.0) / math.pi          # cos(theta) / pi times the factor
    np.testing.assert_allclose(shifted[:3], expected, rtol=1e-9, atol=1e-15)
    assert shifted[3] == plain[3]                            # the pdf is left alone


@pytest.mark.parametrize("row", [diffuse_row(CT_DIFFUSE), microfacet_row(alpha=0.3)],
                         ids=["diffuse", "glossy"])
def test_sampled_values_carry_the_same_factor_as_evaluation(row):
    """A sample's value (eval, not yet divided by the pdf) is what evaluation gives in its
    direction, the factor included; without it the factor would count on one route only."""
    row[0, CL_TERMINATOR] = _frequency(0.6)
    rng = np.random.default_rng(3)
    checked = 0
    for u1, u2, u3 in rng.random((64, 3)):
        x, y, z, r, g, b, pdf, label = closure_sample(row, 0, *WO, u1, u2, u3)
        if not pdf > 0.0:
            continue
        er, eg, eb, epdf = closure_eval(row, 0, *WO, x, y, z)
        np.testing.assert_allclose([r, g, b, pdf], [er, eg, eb, epdf], rtol=1e-9, atol=1e-15)
        checked += 1
    assert checked > 32


def test_transmitted_samples_keep_their_value():
    cl = diffuse_row(CT_TRANSLUCENT)
    plain = closure_sample(cl, 0, *WO, 0.3, 0.4, 0.5)
    cl[0, CL_TERMINATOR] = _frequency(1.0)
    shifted = closure_sample(cl, 0, *WO, 0.3, 0.4, 0.5)
    assert plain[7] & LABEL_TRANSMIT and shifted == plain
