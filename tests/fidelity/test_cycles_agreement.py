"""Every scene in blend_scenes/ renders like Cycles, by a stated statistical test.

Test: each engine renders the scene at 128x128 with SAMPLES samples and two
seeds (through ``bpy.ops.render.render``, as F12 does).  ``mcengine.compare``
estimates each engine's noise per pixel from the seed-to-seed spread and
compares the frame means and the means of an 8x8 grid of blocks, per RGB
channel, with Welch t-tests; Holm-Bonferroni keeps the family-wise false
alarm rate at ALPHA = 1e-3.  The verdict must be "agree".

The test must also be able to fail: a light 5 % too bright must be caught
(``test_five_percent_brighter_light_is_caught``), and the frame-mean noise
is asserted to be small enough that a 5 % error is many standard errors.
"""
from pathlib import Path

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

from mcengine.compare import compare_stacks  # noqa: E402
from mcengine_blender.batch import render_file  # noqa: E402

SCENES_DIR = Path(__file__).resolve().parents[2] / "blend_scenes"
SCENES = sorted(SCENES_DIR.glob("*.blend"))
SAMPLES = 256
SEEDS = (1, 2)
RESOLUTION = (128, 128)
ALPHA = 1e-3

_cache = {}


def stack(blend, engine, edit=None, tag=""):
    key = (blend.name, engine, tag)
    if key not in _cache:
        renders = [render_file(blend, engine, samples=SAMPLES, seed=s, resolution=RESOLUTION,
                               edit=edit) for s in SEEDS]
        _cache[key] = np.stack([r.image for r in renders])
    return _cache[key]


def test_scenes_exist():
    names = {p.stem for p in SCENES}
    assert {"cornell_box", "light_point", "light_spot", "light_sun", "light_area",
            "light_emissive_mesh", "world_color"} <= names


@pytest.mark.parametrize("blend", SCENES, ids=lambda p: p.stem)
def test_scene_agrees_with_cycles(blend):
    ours, cycles = stack(blend, "mcengine"), stack(blend, "cycles")
    result = compare_stacks(ours, cycles, grid=(8, 8), alpha=ALPHA)
    # The comparison must be sharp enough to see a 5 % error in the frame mean.
    rel_se = np.hypot(result.frame_se_a, result.frame_se_b) / result.frame_mean_b
    assert np.all(rel_se < 0.01), f"frame noise {rel_se} too large for a 5 % error to show"
    assert result.verdict == "agree", result.summary() + " " + repr(result.differing_blocks()[:5])


def _brighter(scene):
    for ob in scene.objects:
        if ob.type == "LIGHT":
            ob.data.energy *= 1.05


def test_five_percent_brighter_light_is_caught():
    blend = SCENES_DIR / "cornell_box.blend"
    brighter = stack(blend, "mcengine", edit=_brighter, tag="x1.05")
    result = compare_stacks(brighter, stack(blend, "cycles"), grid=(8, 8), alpha=ALPHA)
    assert result.verdict == "differ"
    assert np.all(result.frame_rejected)
    assert np.allclose(result.frame_rel_bias, 0.05, atol=0.01)
