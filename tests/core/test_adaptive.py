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
