"""Adaptive sampling: converged pixels stop, noisy ones go on, and the error promise holds.

A plane lit by an area light with a box casting a soft shadow, seen from
above with direct light only.  Flat, evenly lit regions converge fast; the
penumbra is noisy.  With a noise threshold t, every pixel stops once its
estimated relative error (the standard error of its mean, normalised by
brightness as Cycles does) is below t, so the measured error against a
converged reference must satisfy mean(e^2) <= t^2 over the image.
"""
import numpy as np
import pytest

from mcengine.adaptive import Adaptive
from mcengine.scene import Camera, Film, Geometry, Integrator, Light, Material, SceneDescription, World
from mcengine.session import RenderSession

from .scenes import grid_plane, translation

THRESHOLD = 0.05


def _box(size=1.0):
    c = np.array([[x, y, z] for x in (-size / 2, size / 2) for y in (-size / 2, size / 2) for z in (0, size)])
    tris = []
    for f in ((0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)):
        a, b, cc, d = (c[i] for i in f)
        tris += [[a, b, cc], [a, cc, d]]
    return np.array(tris)


def _scene(samples, adaptive):
    tris = np.concatenate([grid_plane(20.0), _box()])
    light = Light(type="AREA", matrix_world=translation(0.3, 0, 3), strength=(300.0,) * 3, size_x=1.5)
    return SceneDescription(
        geometry=Geometry.from_triangles(tris), materials=[Material(base_color=(0.8, 0.8, 0.8))],
        lights=[light], camera=Camera(matrix_world=translation(0, 0, 6), type="ORTHO", ortho_scale=4.0),
        world=World(color=(0.0, 0.0, 0.0)), film=Film(width=24, height=24),
        integrator=Integrator(samples=samples, max_bounces=0, use_adaptive_sampling=adaptive,
                              adaptive_threshold=THRESHOLD))


@pytest.fixture(scope="module")
def renders():
    reference = RenderSession(_scene(4096, False)).run()
    adaptive = RenderSession(_scene(2048, True)).run()
    return reference, adaptive


def test_flat_regions_take_fewer_samples_than_the_penumbra(renders):
    reference, adaptive = renders
    n = adaptive.sample_counts()
    min_samples = adaptive.adaptive.min_samples
    # Flat, lit floor: the image corners; penumbra: where the reference's
    # brightness is between 20 % and 80 % of the lit floor's.
    lum = reference.image()[..., :3].sum(-1)
    lit = np.median(lum[:4, :4])
    penumbra = (lum > 0.2 * lit) & (lum < 0.8 * lit)
    assert penumbra.sum() >= 10
    assert np.median(n[:4, :4]) <= 2 * min_samples
    assert np.median(n[penumbra]) >= 4 * np.median(n[:4, :4])
    assert n.max() <= 2048 and n.min() >= min_samples


def test_error_promise_of_the_threshold(renders):
    reference, adaptive = renders
    r = reference.image()[..., :3].astype(np.float64)
    x = adaptive.image()[..., :3].astype(np.float64)
    total = r.sum(-1)
    scale = np.where(total < 1.0, np.sqrt(total), total) + 1e-4
    e2 = ((x - r) ** 2).sum(-1) / scale ** 2
    # The reference's own noise is included (it only makes the test stricter).
    assert e2.mean() <= THRESHOLD ** 2, e2.mean() / THRESHOLD ** 2
    # And the render stopped early somewhere: adaptivity saved work.
    assert adaptive.sample_counts().mean() < 0.25 * 2048


def _film(seed=3):
    """A 40 x 30 film of random sums, with pixels of 0, 1 and 2 samples, negative variance
    estimates (rounding) and a -0 channel among them."""
    from mcengine.film import Film as Sums
    rng = np.random.default_rng(seed)
    film = Sums(40, 30)
    n = film.count.size
    film.count[:] = rng.integers(0, 40, n)
    film.count[:30] = [0, 1, 2] * 10
    film.sum[:] = rng.random((n, 4)) * film.count[:, None] * rng.choice([0.01, 1.0, 5.0], (n, 1))
    film.sum_sq[:] = film.sum[:, :3] ** 2 / np.maximum(film.count, 1)[:, None] * rng.uniform(0.999, 1.5, (n, 3))
    film.sum[5, 1] = -0.0
    return film


def test_the_relative_error_is_the_documented_formula_to_the_bit(monkeypatch):
    """``Adaptive.error`` (and the film's variance beneath it) works block by block and
    channel by channel for speed; it must give the bits of the formula computed on whole
    arrays: the standard error of the mean, summed over RGB in quadrature, over sqrt(sum RGB)
    below 1 and sum RGB above, inf below two samples. Small blocks, so several are used."""
    import mcengine.adaptive as adaptive_module
    monkeypatch.setattr(adaptive_module, "BLOCK_PIXELS", 256)
    film = _film()
    n = film.count[:, None].astype(np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        mean = film.sum[:, :3] / n
        var = np.where(n >= 2, np.maximum((film.sum_sq - n * mean * mean) / (n - 1.0), 0.0) / n, np.inf)
        total = (film.sum[:, :3] / np.maximum(film.count, 1)[:, None]).sum(axis=1)
        scale = np.where(total < 1.0, np.sqrt(np.maximum(total, 0.0)), total)
        expected = np.sqrt(var.sum(axis=1)) / (1e-4 + scale)
    got = Adaptive(0.05, 4).error(film)
    assert np.array_equal(got.view(np.uint64), expected.view(np.uint64))
    assert np.isinf(got[:2]).all() and np.isfinite(got[2]) and (var < 0).sum() == 0
    assert np.array_equal(film.variance(), var.reshape(30, 40, 3).astype(np.float32))


def test_remaining_samples_count_down_from_the_last_check():
    """The samples still to take, for the render's ETA: all of them before the first check;
    after it each pixel left sampling needs n (error / threshold)^2 in all, estimated at the
    check, not recomputed after every pass (the film's error took 1.5 s a pass at 4K)."""
    film = _film()
    ad = Adaptive(0.05, 4)
    everyone = ad.unconverged(film, 2)          # before the minimum: no check
    assert ad.remaining_samples(film, everyone, 64) == np.maximum(64 - film.count, 0).sum()
    err = ad.error(film)
    active = ad.unconverged(film, 16)
    assert 0 < active.size < film.count.size
    n = film.count[active].astype(np.float64)
    with np.errstate(invalid="ignore"):
        needed = np.where(np.isfinite(err[active]), n * (err[active] / 0.05) ** 2, np.inf)
    needed = np.clip(np.maximum(needed, 4), 0, 64)
    film.count[active] += 3                     # a pass: the error is not looked at again
    ad.error = None
    assert ad.remaining_samples(film, active, 64) == pytest.approx(
        np.maximum(needed - film.count[active], 0).sum(), rel=1e-12)
