"""Caustics and Cycles' Caustics Reflective / Refractive switches, against Cycles.

``blend_scenes/caustics.blend`` (a glass ball and a sharp mirror on a diffuse
floor, an area lamp and a sun with an angle) is compared with both switches
on in ``test_cycles_agreement``.  Here both engines render it with one switch
off, then both off (the same edit in each), and must agree at the CI setting;
MC Engine with the switches off against Cycles with them on must differ, darker
where the caustics fall, so the comparison does see the caustics.
"""
import numpy as np
import pytest

from mcengine.evaluation.comparison import build_comparison

from .conftest import options_for

SCENE = "caustics"


def _switches(reflective, refractive):
    def edit(scene):
        scene.cycles.caustics_reflective = reflective
        scene.cycles.caustics_refractive = refractive
    return edit


@pytest.mark.parametrize("reflective,refractive", [(False, True), (True, False), (False, False)])
def test_caustics_switches_agree_with_cycles(renders, reflective, refractive):
    variant = f"reflective {reflective}, refractive {refractive}"
    edit = _switches(reflective, refractive)
    options = options_for(SCENE)
    result = build_comparison(f"{SCENE} ({variant})", renders.runs(SCENE, "mcengine", variant, edit),
                              renders.runs(SCENE, "cycles", variant, edit), grid=options.grid,
                              alpha=options.alpha)
    assert result.verdict == "agree", result.agreement.summary()


def test_caustics_switched_off_are_seen_missing(renders):
    result = renders.compare(SCENE, "no caustics", _switches(False, False))
    a = result.agreement
    assert result.verdict == "differ"
    assert np.all(a.frame_rel_bias < 0)
    assert all(d["t"] < 0 for d in a.differing_blocks()), "switching caustics off only darkens"
