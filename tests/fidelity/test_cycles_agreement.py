"""Every scene in blend_scenes/ renders like Cycles, by a stated statistical test.

Test: each engine renders the scene at the CI setting (conftest: half the
stored resolution, 128 samples, two seeds; more samples for the scenes in
``STRONGER``) through ``bpy.ops.render.render``, as F12 does, under matched
unbiased settings (``mcengine_blender.batch.comparison``).  ``mcengine.evaluation.stats``
estimates each engine's noise per pixel from the seed-to-seed spread and
compares the frame means and the means of an 8x8 grid of blocks, per RGB
channel, with Welch t-tests; Holm-Bonferroni keeps the family-wise false
alarm rate at alpha = 1e-3.  The verdict must be "agree".

The test must also be able to fail: for every scene the frame noise must be
small enough that a 5 % brighter image is found with 95 % probability
(``detectable_bias``), and a light 5 % too bright is shown to be caught.
``test_discrimination`` has the other wrong renders.  The summary table of
the suite (Markdown and HTML) is written at the end, as ``mcengine compare
--suite`` writes it.
"""
import json

import numpy as np
import pytest

from mcengine.evaluation.comparison import POWER_BIAS, build_comparison, detectable_bias, suite_row
from mcengine.evaluation.output import write_comparison, write_suite

from .conftest import SCENES, options_for

# A frame POWER_BIAS (5 %) too bright must be found with 95 % probability: the
# report's criterion for saying that the frame means agree.

_comparisons = {}


def test_scenes_exist():
    names = {p.stem for p in SCENES}
    assert {"cornell_box", "light_point", "light_spot", "light_sun", "light_area",
            "light_emissive_mesh", "world_color",
            # added for the fidelity suite: every light parameter, transforms, cameras
            "light_area_spread", "light_point_large", "light_spot_shapes", "light_sun_wide",
            "transforms", "instancing_modifiers", "camera_sensor_fit", "camera_portrait_wide",
            "camera_ortho", "camera_dof", "camera_dof_ortho",
            "motion_transform", "motion_camera", "motion_deform",
            # textured scenes of issue 10
            "texture_checker_lights", "attribute_vertex_colors", "texture_suzanne_maps",
            "world_hdri_interior",
            # the tangents of anisotropic closures; thin-film interference
            "material_anisotropic", "material_thin_film",
            # holdout objects and collections; true displacement
            "holdout_objects", "material_displacement",
            # random-walk subsurface scattering; objects' ray visibility; light linking
            "material_subsurface", "ray_visibility", "light_linking",
            # IES light profiles; the Toon, Hair and Ray Portal BSDFs; the Preetham sky
            "light_ies", "material_toon", "material_hair", "material_ray_portal",
            "world_sky_preetham"} <= names


@pytest.mark.parametrize("blend", SCENES, ids=lambda p: p.stem)
def test_scene_agrees_with_cycles(blend, renders):
    result = renders.compare(blend.stem)
    _comparisons[blend.stem] = result
    a = result.agreement
    # The comparison must be sharp enough to see a 5 % error in the frame mean.
    rel_se = np.hypot(a.frame_se_a, a.frame_se_b) / a.frame_mean_b
    assert np.all(rel_se < 0.01), f"frame noise {rel_se} too large for a 5 % error to show"
    assert np.all(detectable_bias(a) <= POWER_BIAS), \
        f"a {100 * POWER_BIAS:.0f} % error would be missed: detectable {detectable_bias(a)}"
    assert result.verdict == "agree", a.summary() + " " + repr(a.differing_blocks()[:5])


def _shutter_at(position):
    def edit(scene):
        scene.render.motion_blur_position = position
    return edit


@pytest.mark.parametrize("position", ["START", "END"])
def test_motion_blur_agrees_at_every_shutter_position(renders, position):
    """motion_transform (CENTER in the suite) with the shutter opening at the frame or
    closing at it: both engines render the edited scene."""
    edit = _shutter_at(position)
    ours = renders.runs("motion_transform", "mcengine", position, edit)
    cycles = renders.runs("motion_transform", "cycles", position, edit)
    options = options_for("motion_transform", position)
    result = build_comparison(f"motion_transform ({position})", ours, cycles, grid=options.grid,
                              alpha=options.alpha)
    assert np.all(detectable_bias(result.agreement) <= POWER_BIAS)
    assert result.verdict == "agree", result.agreement.summary()


def _brighter(scene):
    for ob in scene.objects:
        if ob.type == "LIGHT":
            ob.data.energy *= 1.05


def test_five_percent_brighter_light_is_caught(renders):
    result = renders.compare("cornell_box", "lights x1.05", _brighter)
    a = result.agreement
    assert result.verdict == "differ"
    assert np.all(a.frame_rejected)
    assert np.allclose(a.frame_rel_bias, 0.05, atol=0.01)


def test_suite_summary_lists_every_scene(tmp_path):
    """The summary files of the scenes compared above (as ``--suite`` writes them)."""
    missing = sorted({p.stem for p in SCENES} - set(_comparisons))
    if missing:
        pytest.skip(f"scenes not compared in this run: {', '.join(missing)}")
    rows = []
    for name in sorted(_comparisons):
        write_comparison(_comparisons[name], tmp_path / name)
        rows.append(suite_row(_comparisons[name], name))
    paths = write_suite(rows, tmp_path)
    summary = json.loads(paths["summary.json"].read_text())
    assert summary["verdict"] == "agree"
    assert [s["scene"] for s in summary["scenes"]] == sorted(p.stem for p in SCENES)
    markdown, page = paths["summary.md"].read_text(), paths["summary.html"].read_text()
    for name in _comparisons:
        assert f"[{name}]({name}/report.md)" in markdown
        assert f'<img src="{name}/thumbnail.png"' in page
        assert (tmp_path / name / "thumbnail.png").is_file()
