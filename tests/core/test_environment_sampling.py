"""The world's importance map (kernels.background): a valid distribution, unbiased with MIS,
and less noise than BSDF sampling alone on an HDRI with a small bright sun."""

import math

import numpy as np
import pytest

from mcengine.background import importance_map, map_size
from mcengine.scene import (
    Camera,
    Film,
    Geometry,
    Image,
    Integrator,
    Link,
    Material,
    SceneDescription,
    ShaderNode,
    World,
)

from .expect import Z_LIMIT, image_mean_and_se, render
from .scenes import grid_plane, look_down

SUN = 4000.0           # the sun texels' radiance; the sky's is about 0.3
W, H = 64, 32
ALBEDO = 0.8


def small_sun_hdri() -> np.ndarray:
    """A dim blue-grey sky with a sun of 2 x 1 texels (about 1e-3 of the sphere) 40 deg up."""
    rng = np.random.default_rng(3)
    px = np.empty((H, W, 4), np.float32)
    px[..., :3] = (0.2, 0.25, 0.35) * (0.8 + 0.4 * rng.random((H, W, 1)))
    px[..., 3] = 1.0
    row = int((0.5 + 40.0 / 180.0) * H)          # v = 0.5 is the horizon, v = 1 straight up
    px[row, 20:22, :3] = (SUN, 0.9 * SUN, 0.8 * SUN)
    return px


def hdri_scene(sampling: str, samples: int, seed: int = 0) -> SceneDescription:
    """A white diffuse plane lit by the HDRI alone, seen from above (every pixel sees the
    same point, so the image mean is one irradiance integral).  A Manual map has 512 x 256
    texels: finer than the image, so that it resolves the sun's bilinear footprint."""
    world = World(nodes=[ShaderNode("TexEnvironment", props={"image": "sky"}),
                         ShaderNode("Background", {"Color": Link(0, "Color"), "Strength": 1.0})],
                  surface=Link(1, "Background"), sampling=sampling, map_resolution=512)
    return SceneDescription(
        geometry=Geometry.from_triangles(grid_plane(200.0)),
        materials=[Material(base_color=(ALBEDO,) * 3)],
        camera=Camera(matrix_world=look_down(5.0), type="ORTHO", ortho_scale=0.02,
                      clip_start=0.01, clip_end=100.0),
        world=world, images={"sky": Image(small_sun_hdri(), "linear", "PREMUL")},
        film=Film(width=8, height=8, filter_type="BOX", filter_width=1.0),
        integrator=Integrator(samples=samples, max_bounces=0, seed=seed))


def expected_radiance() -> np.ndarray:
    """The plane's radiance, albedo / pi x the irradiance of the bilinearly interpolated
    HDRI (Repeat at the edges, as Cycles reads environment images), by the midpoint rule
    on 32 x 32 points per texel of the upper hemisphere."""
    img = small_sun_hdri()[..., :3].astype(np.float64)
    n = 32
    u = (np.arange(W * n) + 0.5) / (W * n)
    v = 0.5 + (np.arange(H * n // 2) + 0.5) / (H * n)          # the upper hemisphere
    s, t = u * W - 0.5, v * H - 0.5
    i, j = np.floor(s).astype(int), np.floor(t).astype(int)
    fx, fy = (s - i)[None, :, None], (t - j)[:, None, None]
    i0, i1, j0, j1 = i % W, (i + 1) % W, j % H, (j + 1) % H
    radiance = ((1 - fy) * ((1 - fx) * img[j0][:, i0] + fx * img[j0][:, i1])
                + fy * ((1 - fx) * img[j1][:, i0] + fx * img[j1][:, i1]))
    theta = np.pi * (1.0 - v)                                  # from the zenith
    d_omega = (2 * np.pi / (W * n)) * (np.pi / (H * n)) * np.sin(theta)
    irradiance = (radiance * (np.cos(theta) * d_omega)[:, None, None]).sum(axis=(0, 1))
    return ALBEDO / np.pi * irradiance


def test_map_size_follows_the_world_settings():
    images = {"sky": Image(small_sun_hdri(), "linear", "PREMUL")}
    world = hdri_scene("AUTOMATIC", 1).world
    assert map_size(world, images) == (W, H)
    world.sampling = "MANUAL"
    world.map_resolution = 256
    assert map_size(world, images) == (256, 128)
    world.sampling = "NONE"
    assert map_size(world, images) is None


def test_sampled_directions_have_the_pdf_the_map_states():
    """E[1 / pdf] over sampled directions is the sphere's 4 pi, and the pdf of a sampled
    direction recomputed from the direction alone is the pdf the sampler returned."""
    from mcengine.kernels.background import background_pdf, sample_background
    radiance = small_sun_hdri()[..., :3].astype(np.float64)
    marginal, conditional, mean = importance_map(radiance)
    assert mean > 0
    rng = np.random.default_rng(1)
    inv, agree = [], []
    for u1, u2 in rng.random((20000, 2)):
        x, y, z, pdf = sample_background(marginal, conditional, u1, u2)
        assert pdf > 0 and abs(x * x + y * y + z * z - 1.0) < 1e-9
        inv.append(1.0 / pdf)
        agree.append(background_pdf(marginal, conditional, x, y, z) / pdf)
    inv = np.array(inv)
    assert abs(inv.mean() - 4 * math.pi) < Z_LIMIT * inv.std() / math.sqrt(len(inv))
    assert np.quantile(np.abs(np.array(agree) - 1.0), 0.999) < 1e-6


@pytest.fixture(scope="module")
def renders():
    """The scene lit through BSDF sampling alone (Sampling None, 16384 samples per pixel)
    and with the importance map and MIS (Manual, 1024)."""
    return {"NONE": render(hdri_scene("NONE", 16384)), "MANUAL": render(hdri_scene("MANUAL", 1024))}


@pytest.mark.parametrize("sampling", ["NONE", "MANUAL"])
def test_irradiance_of_the_hdri(renders, sampling):
    """Both strategies find the irradiance integral of the interpolated image (which also
    checks the equirectangular mapping end to end: a flipped or shifted image moves the sun)."""
    expected = expected_radiance()
    for channel in range(3):
        mean, se = image_mean_and_se(renders[sampling], channel)
        assert abs(mean - expected[channel]) < Z_LIMIT * se + 1e-4 * expected[channel], (
            channel, mean, se, expected[channel])


def test_importance_sampling_lowers_the_noise(renders):
    """Variance per sample, BSDF sampling alone over the importance map with MIS: measured
    2125, and 2175 after the rebase onto the render passes (README); the bound leaves room
    for the noise of the variance estimates."""
    se_uniform = image_mean_and_se(renders["NONE"])[1]
    se_map = image_mean_and_se(renders["MANUAL"])[1]
    ratio = (se_uniform ** 2 * 16384) / (se_map ** 2 * 1024)
    print(f"variance ratio per sample, BSDF sampling / importance map: {ratio:.0f}")
    assert ratio > 300.0


def test_the_map_baked_in_bands_of_rows_is_the_map_baked_in_one(monkeypatch):
    """``bake_world`` splits the rows among threads, each with its own shader registers: the
    map is the one a single band bakes, texel for texel (and the sun is in it)."""
    import mcengine.background as background
    from mcengine.kernels.state import CFG_SIZE, CFG_WORLD_SHADER, alloc_scratch
    from mcengine.packing import pack_scene

    sc = pack_scene(hdri_scene("MANUAL", 1)).sc
    cfg = np.zeros(CFG_SIZE, np.int64)
    cfg[CFG_WORLD_SHADER] = 1
    one = np.zeros((H, W, 3))
    background.bake_background(sc, cfg, alloc_scratch(sc), one, 0, H)
    for cores in (2, 3, 7):
        monkeypatch.setattr(background.os, "cpu_count", lambda cores=cores: cores)
        banded = np.full((H, W, 3), np.nan)
        background.bake_world(sc, cfg, banded)
        np.testing.assert_array_equal(banded, one)
    assert one.max() > 0.5 * SUN


def test_the_map_is_kept_while_the_bake_reads_the_same(monkeypatch):
    """``background.world_map`` bakes once for renders of the same world (another material
    does not matter) and again when the world's strength, its image's texels, the map size
    or, for a world that reads the camera, the camera change."""
    import dataclasses

    import mcengine.background as background
    from mcengine.kernels.state import FCFG_WORLD_IMPORTANCE
    from mcengine.packing import pack_scene

    bakes = []
    real = background.bake_world
    monkeypatch.setattr(background, "bake_world", lambda *a: (bakes.append(1), real(*a)))
    background.clear()
    scene = hdri_scene("MANUAL", 1)
    first = pack_scene(scene)
    again = pack_scene(scene)
    assert len(bakes) == 1 and again.sc.bg_conditional is first.sc.bg_conditional
    pack_scene(dataclasses.replace(scene, materials=[Material(base_color=(0.3, 0.5, 0.7))]))
    moved = dataclasses.replace(scene.camera, matrix_world=look_down(7.0))
    pack_scene(dataclasses.replace(scene, camera=moved))
    assert len(bakes) == 1

    def world(strength=1.0, resolution=512, vector=None):
        env = ShaderNode("TexEnvironment", {} if vector is None else {"Vector": vector},
                         props={"image": "sky"})
        nodes = [env, ShaderNode("Background", {"Color": Link(0, "Color"), "Strength": strength})]
        if vector is not None:
            nodes.append(ShaderNode("TexCoord"))
        return World(nodes=nodes, surface=Link(1, "Background"), sampling="MANUAL",
                     map_resolution=resolution)

    brighter = pack_scene(dataclasses.replace(scene, world=world(strength=2.0)))
    assert len(bakes) == 2
    assert brighter.fcfg[FCFG_WORLD_IMPORTANCE] == pytest.approx(2 * first.fcfg[FCFG_WORLD_IMPORTANCE])
    pack_scene(scene)                                       # (each change from the first)
    sky = small_sun_hdri()
    sky[:, :, :3] = np.roll(sky[:, :, :3], 16, axis=1)      # the sun a quarter turn on
    turned = pack_scene(dataclasses.replace(scene, images={"sky": Image(sky, "linear", "PREMUL")}))
    assert len(bakes) == 4
    assert not np.array_equal(turned.sc.bg_conditional, first.sc.bg_conditional)
    pack_scene(scene)
    coarser = pack_scene(dataclasses.replace(scene, world=world(resolution=256)))
    assert len(bakes) == 6 and coarser.sc.bg_conditional.shape == (128, 257)
    # A world that reads the camera's coordinates is baked again when the camera moves.
    camera_world = dataclasses.replace(scene, world=world(vector=Link(2, "Camera")))
    pack_scene(camera_world)
    pack_scene(camera_world)
    assert len(bakes) == 7
    pack_scene(dataclasses.replace(camera_world, camera=moved))
    assert len(bakes) == 8
