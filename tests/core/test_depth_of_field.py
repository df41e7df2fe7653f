"""Depth of field: the aperture samplers' densities, the thin-lens geometry, and invariance.

Cycles (kernel/camera/camera.h) starts a lens ray at a point of the aperture,
a uniform disk or a uniform regular polygon of blades, squeezed horizontally
by the anamorphic ratio and scaled by the aperture radius, and aims it at the
point where the pinhole ray meets the plane of focus.  The samplers are
checked by Pearson chi-square tests on equal-area cells (with the lecture's
wrong r = u disk map, and a polygon map without the square root, as negative
controls that must fail); the geometry against closed forms; and an aperture
of zero must render the very same bits as a camera without depth of field.
"""
import math

import numpy as np
import pytest
from numba import njit
from scipy.stats import chi2

from mcengine.kernels.camera import C_APERTURE, aperture_point, camera_rays, pack_camera
from mcengine.scene import Camera, Film

from .expect import chi2_uniform_disk, render
from .scenes import inside_sphere_scene, translation

ALPHA = 1e-4          # false-alarm rate of each chi-square test
N = 200_000


def critical(dof):
    return chi2.ppf(1 - ALPHA, dof)


@njit(cache=False)
def _aperture_points(cam, u):
    out = np.empty((u.shape[0], 2))
    for i in range(u.shape[0]):
        out[i, 0], out[i, 1] = aperture_point(cam, u[i, 0], u[i, 1])
    return out


def packed(**kw):
    return pack_camera(Camera(**kw), Film(width=8, height=8))


def uniforms(seed=1):
    return np.random.default_rng(seed).random((N, 2))


def test_disk_aperture_is_uniform_and_the_lectures_map_is_not():
    u = uniforms()
    points = _aperture_points(packed(aperture_size=1.0), u)
    assert np.hypot(points[:, 0], points[:, 1]).max() <= 1.0 + 1e-12
    stat, dof = chi2_uniform_disk(points)
    assert stat < critical(dof), stat
    # The lecture's wrong disk sampling, angle and radius uniform (r = u), fails the same test.
    phi = 2 * math.pi * u[:, 1]
    naive = np.stack([u[:, 0] * np.cos(phi), u[:, 0] * np.sin(phi)], 1)
    stat, dof = chi2_uniform_disk(naive)
    assert stat > 100 * critical(dof), stat


def chi2_uniform_polygon(points, corners, rotation, rings=6, lanes=6):
    """Pearson chi-square of points against the uniform density on the regular polygon.

    The polygon (vertices on the unit circle at rotation + pi/corners + 2 pi k/corners)
    is cut into its ``corners`` triangles (centre and one edge); each triangle into
    ``rings`` bands of equal d^2, d being the distance to the centre over the apothem,
    and every band into ``lanes`` equal parts along the edge: all cells have equal area.
    """
    half = math.pi / corners
    angle = np.arctan2(points[:, 1], points[:, 0]) - rotation
    wedge = np.floor((angle + half) / (2 * half)).astype(int) % corners
    axis = rotation + 2 * half * wedge
    along = points[:, 0] * np.cos(axis) + points[:, 1] * np.sin(axis)
    across = -points[:, 0] * np.sin(axis) + points[:, 1] * np.cos(axis)
    d = along / math.cos(half)
    assert d.max() <= 1.0 + 1e-9, "a point outside the polygon"
    lateral = across / np.maximum(d * math.sin(half), 1e-300)
    ring = np.minimum((d * d * rings).astype(int), rings - 1)
    lane = np.clip(((lateral + 1) / 2 * lanes).astype(int), 0, lanes - 1)
    cells = corners * rings * lanes
    counts = np.bincount((wedge * rings + ring) * lanes + lane, minlength=cells)
    expected = len(points) / cells
    return ((counts - expected) ** 2 / expected).sum(), cells - 1


@pytest.mark.parametrize("blades,rotation,ratio", [(3, 0.0, 1.0), (5, 0.4, 1.0), (6, -1.1, 1.7)])
def test_polygon_aperture_is_uniform_over_the_blades(blades, rotation, ratio):
    u = uniforms(blades)
    points = _aperture_points(packed(aperture_size=1.0, aperture_blades=blades,
                                     aperture_rotation=rotation, aperture_ratio=ratio), u)
    points[:, 0] *= ratio                    # undo the anamorphic squeeze
    stat, dof = chi2_uniform_polygon(points, blades, rotation)
    assert stat < critical(dof), stat
    # The farthest points are the polygon's vertices, where Cycles puts them.
    far = points[np.argsort(-np.hypot(points[:, 0], points[:, 1]))[:blades * 20]]
    vertex = (np.arctan2(far[:, 1], far[:, 0]) - rotation - math.pi / blades) % (2 * math.pi / blades)
    off = np.minimum(vertex, 2 * math.pi / blades - vertex)
    assert off.max() < 0.02
    # Without the square root the triangle's points crowd its far edge: the test fails.
    corner = np.floor(u[:, 0] * blades)
    a = u[:, 0] * blades - corner
    v = u[:, 1] * a
    b = 1 - a
    px, py = (b + v) * math.cos(math.pi / blades), (b - v) * math.sin(math.pi / blades)
    turn = rotation + corner * 2 * math.pi / blades
    wrong = np.stack([np.cos(turn) * px - np.sin(turn) * py, np.sin(turn) * px + np.cos(turn) * py], 1)
    stat, dof = chi2_uniform_polygon(wrong, blades, rotation)
    assert stat > 100 * critical(dof), stat


def test_anamorphic_ratio_squeezes_the_lens_horizontally():
    points = _aperture_points(packed(aperture_size=0.5, aperture_ratio=2.0), uniforms(9))
    assert np.abs(points[:, 0]).max() == pytest.approx(0.25, rel=1e-3)
    assert np.abs(points[:, 1]).max() == pytest.approx(0.5, rel=1e-3)


def camera_space(cam, points):
    m = cam.matrix_world
    return (points - m[:3, 3]) @ m[:3, :3] * np.array([1.0, 1.0, -1.0])


@pytest.mark.parametrize("kind", ["PERSP", "ORTHO"])
def test_lens_rays_of_a_pixel_meet_the_pinhole_ray_on_the_plane_of_focus(kind):
    m = translation(0.3, -2.0, 1.5)
    m[:3, :3] = [[1, 0, 0], [0, 0, -1], [0, 1, 0]]      # looking along +Y
    common = dict(matrix_world=m, type=kind, lens=35.0, ortho_scale=4.0, shift_x=0.1,
                  clip_start=0.2, clip_end=80.0)
    pinhole = Camera(**common)
    lens = Camera(**common, aperture_size=0.3, focal_distance=4.5, aperture_blades=7,
                  aperture_rotation=0.3, aperture_ratio=1.4)
    film = Film(width=40, height=30)
    u = uniforms(4)[:500]
    rx, ry = np.full(500, 31.3), np.full(500, 7.9)
    o0, d0, t0 = camera_rays(pinhole, film, rx[:1], ry[:1])
    o, d, tmax = camera_rays(lens, film, rx, ry, u[:, 0], u[:, 1])
    oc, dc, oc0, dc0 = (camera_space(lens, o), d @ m[:3, :3] * [1, 1, -1],
                        camera_space(pinhole, o0), d0 @ m[:3, :3] * [1, 1, -1])
    # Every lens ray crosses the plane of focus where the pinhole ray does.
    focus = oc + ((4.5 - oc[:, 2]) / dc[:, 2])[:, None] * dc
    pin = oc0 + ((4.5 - oc0[:, 2]) / dc0[:, 2])[:, None] * dc0
    np.testing.assert_allclose(focus, np.broadcast_to(pin, focus.shape), atol=1e-12)
    # The rays leave the aperture: back at the lens plane (depth 0) they lie on the
    # squeezed heptagon of radius 0.3 around the pinhole ray's origin there.
    start = oc - (oc[:, 2] / dc[:, 2])[:, None] * dc
    centre = oc0 - (oc0[:, 2] / dc0[:, 2])[:, None] * dc0
    lens_xy = (start - centre)[:, :2]
    lens_xy[:, 0] *= 1.4
    assert np.hypot(lens_xy[:, 0], lens_xy[:, 1]).max() <= 0.3 + 1e-12
    assert np.hypot(lens_xy[:, 0], lens_xy[:, 1]).max() > 0.29
    assert np.allclose(np.linalg.norm(d, axis=1), 1.0)
    # Clipping: Cycles' offsets of the pinhole ray, applied along the lens ray.
    if kind == "PERSP":
        cos = dc0[0, 2]
        np.testing.assert_allclose(np.linalg.norm(o - (start @ (m[:3, :3] * [1, 1, -1]).T
                                                       + m[:3, 3]), axis=1), 0.2 / cos)
        np.testing.assert_allclose(tmax, (80.0 - 0.2) / cos)
    else:
        np.testing.assert_allclose(oc[:, 2], 0.2, atol=1e-12)
        np.testing.assert_allclose(tmax, 80.0 - 0.2)


def test_blur_circle_of_a_point_off_the_plane_of_focus():
    """A point at 2 m seen with focus at 1 m: its image is the aperture scaled by
    |z - f| / (f z) at unit distance (cycles-conventions.md: 22.2 px at f/0.1, 128 px wide)."""
    f, z, a = 1.0, 2.0, 0.05 / (2 * 0.1)        # 50 mm lens at f/0.1: radius 0.25 m
    cam = Camera(aperture_size=a, focal_distance=f, lens=50.0)
    film = Film(width=128, height=128)
    u = uniforms(5)[:4000]
    rx = ry = np.full(len(u), 64.0)
    o, d, _ = camera_rays(cam, film, rx, ry, u[:, 0], u[:, 1])
    hit = o + ((-z - o[:, 2]) / d[:, 2])[:, None] * d        # the plane 2 m in front
    radius_px = np.hypot(hit[:, 0], hit[:, 1]).max() / z * 50.0 / 36.0 * 128
    expected = a * abs(z - f) / (f * z) * 50.0 / 36.0 * 128
    assert radius_px == pytest.approx(expected, rel=2e-3)
    assert expected == pytest.approx(22.22, abs=0.01)


def test_aperture_zero_renders_the_same_bits_as_a_pinhole_camera():
    base = inside_sphere_scene(albedo=0.6, emission=0.4, samples=8, res=12)
    plain = render(base).image()
    base.camera.focal_distance, base.camera.aperture_blades = 0.3, 6
    base.camera.aperture_rotation, base.camera.aperture_ratio = 0.7, 2.0
    assert pack_camera(base.camera, base.film)[C_APERTURE] == 0.0
    assert np.array_equal(render(base).image(), plain)
    base.camera.aperture_size = 0.05       # the test can fail: a lens changes the bits
    assert not np.array_equal(render(base).image(), plain)


def test_depth_of_field_settings_survive_a_saved_scene(tmp_path):
    from mcengine.scene import SceneDescription
    scene = inside_sphere_scene(samples=1, res=4)
    scene.camera.aperture_size, scene.camera.focal_distance = 0.02, 1.5
    scene.camera.aperture_blades, scene.camera.aperture_ratio = 5, 1.3
    scene.save(tmp_path / "dof.npz")
    camera = SceneDescription.load(tmp_path / "dof.npz").camera
    assert (camera.aperture_size, camera.focal_distance, camera.aperture_blades,
            camera.aperture_ratio) == (0.02, 1.5, 5, 1.3)
