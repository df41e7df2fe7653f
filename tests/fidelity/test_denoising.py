"""Denoising lowers the error against a converged reference, on the fidelity scenes.

Each scene is exported by the add-on with Cycles' denoising settings (Open Image
Denoise, albedo and normal guides, accurate prefilter) at 64 x 64 pixels,
rendered by MC Engine at 16 samples, denoised, and compared with a 1024-sample
render (relMSE, ``mcengine.evaluation.stats.relmse``).  Measured (bpy 5.0.1,
OIDN 2.5.1, seeds 1 and 2) with the independent sampler, relMSE noisy -> denoised:

    cornell_box          0.0701 -> 0.00559  (x 12.5; colour only 0.00851, albedo only 0.00800)
    glass_mirror         0.0631 -> 0.00876  (x 7.2;  colour only 0.00939)
    material_principled  0.0910 -> 0.0133   (x 6.8;  colour only 0.0129)
    light_area           0.0268 -> 0.00433  (x 6.2;  colour only 0.00467)

With the Sobol sampler (main since c8e60c7) the 16-sample images are less noisy and the
gain smaller: light_area 0.00958 -> 0.00284 (x 3.4); the other three scenes still gain
more than 4.  The test asks for ``MIN_FACTOR`` on every scene, and for the guides to beat
the colour alone where they clearly do (cornell_box: 35 % lower); on the other scenes the
three inputs are within 10 % of each other at this size.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")

from mcengine.denoise import Denoising  # noqa: E402
from mcengine.evaluation.stats import relmse  # noqa: E402
from mcengine.session import RenderSession  # noqa: E402
from mcengine_blender.batch.render import ensure_registered, open_scene  # noqa: E402

SCENES_DIR = Path(__file__).resolve().parents[2] / "blend_scenes"
SCENES = ["cornell_box", "glass_mirror", "material_principled", "light_area"]
SIZE, NOISY, REFERENCE = 64, 16, 1024
MIN_FACTOR = 3.0
GUIDES_HELP = {"cornell_box"}
MEASURED = {}   # scene -> (noisy relMSE, denoised relMSE), filled in as the tests run


def _export(name: str):
    ensure_registered()
    from mcengine_blender import export
    scene = open_scene(SCENES_DIR / f"{name}.blend")
    scene.render.resolution_x = scene.render.resolution_y = SIZE
    scene.render.resolution_percentage = 100
    scene.cycles.use_denoising = True
    scene.cycles.denoising_input_passes = "RGB_ALBEDO_NORMAL"
    scene.cycles.denoising_prefilter = "ACCURATE"
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.sample_clamp_direct = scene.cycles.sample_clamp_indirect = 0.0
    scene.cycles.blur_glossy = 0.0
    depsgraph = bpy.context.evaluated_depsgraph_get()
    return export.export(depsgraph).scene


@pytest.mark.parametrize("name", SCENES)
def test_denoising_lowers_relmse_against_a_converged_reference(name):
    desc = _export(name)
    assert desc.denoising == Denoising(enabled=True)
    desc.integrator.seed = 1
    desc.integrator.samples = REFERENCE
    reference = RenderSession(desc).run().image()
    desc.integrator.seed = 2
    desc.integrator.samples = NOISY
    noisy_session = RenderSession(desc).run()
    noisy = relmse(noisy_session.image(), reference)
    denoised = relmse(noisy_session.denoised(), reference)
    MEASURED[name] = (noisy, denoised)
    assert denoised * MIN_FACTOR < noisy, f"{name}: relMSE {noisy:.4g} noisy, {denoised:.4g} denoised"
    assert np.isfinite(noisy_session.denoised()).all()
    if name in GUIDES_HELP:
        noisy_session.scene.denoising = Denoising(enabled=True, input_passes="RGB")
        colour_only = relmse(noisy_session.denoised(), reference)
        assert denoised < 0.8 * colour_only, f"{name}: guides {denoised:.4g}, colour only " \
                                             f"{colour_only:.4g}"
