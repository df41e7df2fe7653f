"""The samplers in the renderer: unbiased against closed forms, less noise with Sobol,
independent renders for the comparison, and the setting wired through.

With the Sobol sampler a pixel's sample variance overstates the error of its
mean (its samples are stratified), so the bounds here do not use the film's
variance: in these scenes every pixel has the same expected value and pixels
are independent (each has its own scrambling), so the spread over pixels gives
the standard error of the image mean exactly.
"""
import math

import numpy as np
import pytest
from scipy import stats

from mcengine import samplers
from mcengine.evaluation.stats import compare_stacks
from mcengine.kernels.sampling import SAMPLER_INDEPENDENT, SAMPLER_SOBOL
from mcengine.packing import pack_scene
from mcengine.scene import (
    Camera,
    Film,
    Geometry,
    Integrator,
    Light,
    Material,
    SceneDescription,
    SceneError,
    World,
)

from .expect import Z_LIMIT, render
from .scenes import grid_plane, inside_sphere_scene, plane_scene, translation

H = 2.0


def _pixel_mean(session):
    """Image mean (red) and its standard error from the spread over pixels."""
    img = session.image()[..., 0].astype(np.float64).ravel()
    return img.mean(), img.std(ddof=1) / math.sqrt(img.size), img.std(ddof=1)


def _square_light_radiance(power, size, height):
    """Radiance of a white Lambert plane below the centre of a square area light (Cycles'
    units: radiance P / (pi A)), from the form factor of a point to a rectangle."""
    a = size / 2 / height
    q = math.sqrt(1 + a * a)
    corner = (2 * a / q * math.atan(a / q)) / (2 * math.pi)   # one quarter of the square
    radiance = power / (math.pi * size * size)
    return radiance * 4 * corner        # E / pi = L x form factor


def _area_scene(sampler, samples=64, res=16, shape="SQUARE"):
    li = Light(type="AREA", matrix_world=translation(0, 0, H), strength=(100.0,) * 3,
               shape=shape, size_x=1.0)
    scene = plane_scene(li, samples=samples, res=res)
    scene.integrator.sampler = sampler
    return scene


def test_square_light_closed_form_matches_cycles():
    assert _square_light_radiance(100.0, 1.0, H) == pytest.approx(2.33887, rel=2e-5)


@pytest.mark.parametrize("scene,expected", [
    (lambda: _area_scene("sobol"), _square_light_radiance(100.0, 1.0, H)),
    # emissive furnace, albedo 1/2, 3 bounces: 1 + 1/2 + ... + 1/16 (every bounce's sets)
    (lambda: inside_sphere_scene(albedo=0.5, emission=1.0, max_bounces=3, samples=32), 1.9375),
    # pbrt's point light in a sphere with Russian roulette: radiance 1
    (lambda: inside_sphere_scene(
        albedo=0.5, light=Light(type="POINT", matrix_world=np.eye(4),
                                strength=(4 * math.pi ** 2,) * 3, radius=0.0),
        max_bounces=1024, diffuse_bounces=1024, samples=64, res=24), 1.0 - 0.5 ** 1025),
], ids=["area_light", "emissive_furnace", "point_light_furnace"])
def test_sobol_renders_are_unbiased(scene, expected):
    """Within Z_LIMIT (4.4) standard errors from the pixel spread, which must be below
    0.3 % of the value for the test to mean something."""
    sc = scene()
    assert sc.integrator.sampler == "sobol"
    mean, se, _ = _pixel_mean(render(sc))
    assert se < 3e-3 * expected, se
    assert abs(mean - expected) <= Z_LIMIT * se, (mean, expected, se)


def test_sobol_lowers_the_noise_of_direct_light():
    """The same render with both samplers: the pixels' spread around the (uniform)
    expected value.  Direct light from a disk light, which is sampled by area, is a smooth
    2D integral, which Sobol points at 64 samples integrate with far less error (measured:
    6.5 times less standard deviation); restarting a pixel's sequence in each pass, or
    drawing the light sample's two numbers from different sets, would lose most of that.
    (A square light is sampled by solid angle: its estimates vary only with the receiver's
    cosine, and both samplers' spreads are far smaller.)"""
    _, _, sd_sobol = _pixel_mean(render(_area_scene("sobol", shape="DISK")))
    _, _, sd_indep = _pixel_mean(render(_area_scene("independent", shape="DISK")))
    assert sd_sobol < sd_indep / 5, (sd_sobol, sd_indep)


def _shadow_scene(seed):
    """A plane lit by an area light, with a box casting a soft shadow and one bounce."""
    c = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (0, 1.0)])
    box = []
    for f in ((0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)):
        a, b, cc, d = (c[i] for i in f)
        box += [[a, b, cc], [a, cc, d]]
    tris = np.concatenate([grid_plane(20.0), np.array(box)])
    light = Light(type="AREA", matrix_world=translation(0.3, 0, 3), strength=(300.0,) * 3,
                  size_x=1.5)
    return SceneDescription(
        geometry=Geometry.from_triangles(tris), materials=[Material(base_color=(0.8, 0.8, 0.8))],
        lights=[light], camera=Camera(matrix_world=translation(0, 0, 6), type="ORTHO",
                                      ortho_scale=4.0),
        world=World(color=(0.05, 0.05, 0.05)), film=Film(width=32, height=32),
        integrator=Integrator(samples=16, seed=seed, max_bounces=1))


def test_comparison_false_alarm_rate_with_sobol_renders():
    """The comparison (``mcengine compare``) of Sobol renders with seeds 1, 2 against
    seeds 3, 4, and so on: 40 comparisons of two renders each at alpha = 0.05.  Seeds
    give independent renders and pixels are independent, so the false alarms follow
    Binomial(40, 0.05): 8 or more has probability 0.3 %.  The frame p-values are uniform
    (Kolmogorov-Smirnov at 1 %).  A seed that did not reach the scrambling would give
    equal renders.  Pixels are independent: the correlation of neighbouring pixels'
    standardised deviations over the 160 renders is 0 within 4 standard errors
    (0.0025); numbers shared between pixels would correlate them."""
    trials = 40
    renders = np.array([render(_shadow_scene(seed)).image()
                        for seed in range(1, 4 * trials + 1)])
    stacks = renders.reshape(2 * trials, 2, 32, 32, 4)
    results = [compare_stacks(stacks[2 * t], stacks[2 * t + 1], alpha=0.05) for t in range(trials)]
    alarms = sum(r.verdict == "differ" for r in results)
    assert alarms < 8, alarms
    p = np.array([r.frame_p[0] for r in results])
    assert math.sqrt(p.size) * stats.kstest(p, "uniform").statistic < 1.63
    assert all(np.all(r.frame_se_a > 0) for r in results)
    dev = renders[..., 0] - renders[..., 0].mean(axis=0)
    z = dev / dev.std(axis=0)
    for a, b in ((z[:, :, :-1], z[:, :, 1:]), (z[:, :-1, :], z[:, 1:, :])):
        assert abs(np.mean(a * b)) < 4 / math.sqrt(a.size), np.mean(a * b)


def test_sobol_and_independent_renders_agree_in_mean():
    """The soft-shadow scene (direct light, penumbra, one bounce) rendered with both
    samplers, 12 seeds each: the comparison finds no difference in the frame or in any
    of its 8 x 8 blocks (alpha 1e-3, Holm over regions and channels), and the frame means
    agree within Z_LIMIT standard errors of their seed-to-seed spread, which must be
    below 0.5 % for the test to see a bias of a few percent."""
    stacks = {}
    for sampler in ("sobol", "independent"):
        renders = []
        for seed in range(1, 13):
            scene = _shadow_scene(100 * seed)
            scene.integrator.sampler = sampler
            renders.append(render(scene).image())
        stacks[sampler] = np.array(renders)
    result = compare_stacks(stacks["sobol"], stacks["independent"], alpha=1e-3)
    assert result.verdict != "differ", result.verdict
    means = {k: v[..., :3].mean(axis=(1, 2, 3)) for k, v in stacks.items()}
    se = math.sqrt(sum(m.var(ddof=1) / m.size for m in means.values()))
    diff = means["sobol"].mean() - means["independent"].mean()
    assert se < 5e-3 * means["independent"].mean(), se
    assert abs(diff) <= Z_LIMIT * se, (diff, se)


def test_sampler_setting_is_validated_and_reaches_the_kernels():
    scene = _area_scene("sobol", samples=100)
    _, cfg, _, _ = pack_scene(scene)
    from mcengine.kernels.state import CFG_SAMPLER, CFG_SOBOL_MASK
    assert cfg[CFG_SAMPLER] == SAMPLER_SOBOL and cfg[CFG_SOBOL_MASK] == 0xFE000000  # 128, reversed
    scene.integrator.sampler = "independent"
    assert pack_scene(scene).cfg[CFG_SAMPLER] == SAMPLER_INDEPENDENT
    scene.integrator.sampler = "halton"
    with pytest.raises(SceneError, match="unknown sampler 'halton'"):
        scene.validate()


def test_kernel_codes_agree_with_the_registry():
    assert {name: info.kernel_code for name, info in samplers.SAMPLERS.items()} == {
        "sobol": SAMPLER_SOBOL, "independent": SAMPLER_INDEPENDENT}
    assert samplers.DEFAULT == "sobol" and Integrator().sampler == "sobol"


@pytest.mark.parametrize("pattern", ["AUTOMATIC", "TABULATED_SOBOL", "SOBOL_BURLEY", "BLUE_NOISE",
                                     "BLUE_NOISE_FIRST", "BLUE_NOISE_ROUND"])
def test_every_cycles_pattern_maps_to_sobol(pattern):
    assert samplers.from_cycles_pattern(pattern).name == "sobol"


def test_classic_integrators_draw_independent_numbers_whatever_the_setting():
    images = []
    for sampler in samplers.NAMES:
        scene = _area_scene(sampler, samples=8, res=8)
        scene.integrator.name = "distribution"
        scene.integrator.depth = 2
        images.append(render(scene).image())
    np.testing.assert_array_equal(images[0], images[1])
