"""Motion blur: ray times, interpolated transforms and the moving camera, as Cycles has them.

Cycles draws each camera sample's time from the inverted CDF of the shutter
curve (a 256-entry table read by linear interpolation) and interpolates the
decomposed transforms of the motion steps (slerp for rotations, lerp for the
rest) at that time.  The time sampler is checked by a chi-square test
against the density of its table (and a sampler that ignores the table fails
it); decomposition, interpolation and the moving camera against closed forms;
and a scene where nothing moves renders the same bits with the shutter open.
"""
import math

import numpy as np
import pytest
from numba import njit
from scipy.spatial.transform import Rotation, Slerp
from scipy.stats import chi2

from mcengine.kernels.camera import camera_rays, pack_camera, sample_time
from mcengine.kernels.motion import (
    SHUTTER_TABLE_SIZE,
    decompose_steps,
    motion_transform,
    moving_triangle,
    pack_motion,
    shutter_table,
)
from mcengine.scene import Camera, Film, MotionBlur

from .expect import render
from .scenes import inside_sphere_scene, translation

ALPHA = 1e-4


def affine(rotvec, scale_shear, t):
    m = np.eye(4)
    m[:3, :3] = Rotation.from_rotvec(rotvec).as_matrix() @ np.asarray(scale_shear, float)
    m[:3, 3] = t
    return m


@pytest.mark.parametrize("scale_shear", [
    np.diag([1.0, 1.0, 1.0]),
    [[1.3, 0.2, -0.1], [0.0, 0.7, 0.4], [0.0, 0.0, 2.0]],      # scale and shear
    np.diag([-1.5, 0.8, 1.2]),                                   # mirrored
])
def test_decomposed_transforms_compose_back(scale_shear):
    m = affine([0.3, -1.2, 0.8], scale_shear, [1.0, -2.0, 3.5])
    d = decompose_steps([m, m, m]).ravel()
    for time in (0.0, 0.3, 0.77, 1.0):
        np.testing.assert_allclose(np.reshape(motion_transform(d, 0, 3, time), (3, 4)), m[:3], atol=1e-13)


def test_rotation_is_slerped_and_the_rest_lerped_between_the_right_steps():
    # Five steps: 0, 0.25, 0.5, 0.75, 1 of the shutter.
    rotations = Rotation.from_rotvec([[0, 0, 0], [0, 0, 0.8], [0.5, 0, 1.6], [0.5, 0.4, 2.0], [0, 0, 2.9]])
    scales = [1.0, 1.5, 1.0, 0.5, 2.0]
    moves = [[0, 0, 0], [1, 0, 0], [1, 2, 0], [0, 2, 3], [4, 4, 4]]
    mats = [affine(r.as_rotvec(), np.eye(3) * s, t) for r, s, t in zip(rotations, scales, moves)]
    d = decompose_steps(mats).ravel()
    for time in (0.1, 0.3, 0.5, 0.6, 0.99):
        k = min(int(time * 4), 3)
        f = time * 4 - k
        rot = Slerp([0, 1], rotations[k:k + 2])(f).as_matrix()
        scale = (1 - f) * scales[k] + f * scales[k + 1]
        move = (1 - f) * np.array(moves[k]) + f * np.array(moves[k + 1])
        m = np.reshape(motion_transform(d, 0, 5, time), (3, 4))
        np.testing.assert_allclose(m[:, :3], rot * scale, atol=1e-12)
        np.testing.assert_allclose(m[:, 3], move, atol=1e-12)


def test_quaternions_take_the_short_way_round():
    # 350 degrees one way is 10 degrees the other: halfway is 5 degrees past the start.
    mats = [affine([0, 0, 0], np.eye(3), [0, 0, 0]), affine([0, 0, math.radians(350)], np.eye(3), [0, 0, 0])]
    d = decompose_steps(mats + mats[1:]).ravel()
    m = np.reshape(motion_transform(d, 0, 3, 0.25), (3, 4))
    np.testing.assert_allclose(m[:, :3], Rotation.from_rotvec([0, 0, math.radians(-5)]).as_matrix(), atol=1e-12)


def test_flat_shutter_table_is_cycles_table():
    """Cycles inverts a 255-point CDF into 256 entries: (i + 1/2) 255 / 256^2, not (i + 1/2) / 256."""
    i = np.arange(SHUTTER_TABLE_SIZE)
    np.testing.assert_allclose(shutter_table(), (i + 0.5) * 255 / 256 ** 2, rtol=1e-6)


@njit(cache=False)
def _times(cam, u, rows):
    out = np.empty(u.shape[0])
    for i in range(u.shape[0]):
        out[i] = sample_time(cam, u[i], rows[i])
    return out


def chi2_against_table(times, table, bins=32):
    """Pearson chi-square of times against the density of the piecewise-linear inverse CDF."""
    edges = np.linspace(table[0], table[-1], bins + 1)
    # The sampler's CDF at an edge: the u whose interpolated table value is that edge.
    u_nodes = np.linspace(0.0, 1.0, len(table))
    cdf = np.interp(edges, table, u_nodes)
    p = np.diff(cdf)
    counts = np.histogram(times, edges)[0]
    expected = p * len(times)
    return ((counts - expected) ** 2 / expected).sum(), bins - 1


def packed(motion_blur):
    return pack_camera(Camera(), Film(width=8, height=8), motion_blur)


@pytest.mark.parametrize("shape", ["flat", "ramp", "gate"])
def test_time_sampler_follows_the_shutter_curve(shape):
    x = np.arange(257) / 256
    curve = {"flat": None, "ramp": x, "gate": np.where(x > 0.5, 1.0, 0.05)}[shape]
    cam = packed(MotionBlur(shutter_curve=curve))
    u = np.random.default_rng(7).random(200_000)
    times = _times(cam, u, np.zeros(u.size))
    table = shutter_table(curve)
    stat, dof = chi2_against_table(times, table)
    assert stat < chi2.ppf(1 - ALPHA, dof), stat
    if shape != "flat":     # the same test fails a sampler that ignores the curve
        stat, dof = chi2_against_table(table[0] + (table[-1] - table[0]) * u, table)
        assert stat > 100 * chi2.ppf(1 - ALPHA, dof), stat
    if shape == "ramp":     # density grows linearly: mean time near 2/3
        assert times.mean() == pytest.approx(2 / 3, abs=0.01)


def test_closed_shutter_gives_time_one_half_and_rolling_shutter_reads_rows_top_down():
    assert _times(packed(None), np.array([0.1, 0.9]), np.zeros(2)).tolist() == [0.5, 0.5]
    cam = packed(MotionBlur(rolling_shutter=True, rolling_shutter_duration=0.0))
    rows = np.array([0.0, 3.0, 7.0])
    np.testing.assert_allclose(_times(cam, np.full(3, 0.3), rows), [1 / 8, 4 / 8, 1.0])
    cam = packed(MotionBlur(rolling_shutter=True, rolling_shutter_duration=0.25))
    flat = shutter_table()
    base = np.interp(0.3, np.linspace(0, 1, 256), flat)
    np.testing.assert_allclose(_times(cam, np.full(3, 0.3), rows),
                               (base - 0.5) * 0.25 + (np.array([1, 4, 8]) / 8 - 0.5) * 0.75 + 0.5)


def test_moving_camera_ray_follows_the_interpolated_transform():
    start = translation(0.0, -5.0, 1.0)
    end = translation(2.0, -5.0, 1.0)
    end[:3, :3] = Rotation.from_rotvec([0, 0, 0.6]).as_matrix()
    middle = translation(1.0, -5.0, 1.0)
    middle[:3, :3] = Rotation.from_rotvec([0, 0, 0.3]).as_matrix()
    cam = Camera(matrix_world=middle, motion=np.stack([start, middle, end]), clip_start=0.0)
    film = Film(width=16, height=16)
    for time in (0.0, 0.2, 0.5, 0.9):
        o, d, _ = camera_rays(cam, film, [3.0], [11.0], time=[time], motion_blur=MotionBlur())
        f = time * 2 - (time >= 0.5)
        rot = Rotation.from_rotvec([0, 0, 0.3 * (time * 2)]).as_matrix()
        pos = np.array([2.0 * time, -5.0, 1.0])
        still = Camera(matrix_world=np.block([[rot, pos[:, None]], [np.zeros((1, 3)), np.ones((1, 1))]]),
                       clip_start=0.0)
        o0, d0, _ = camera_rays(still, film, [3.0], [11.0])
        np.testing.assert_allclose(o, o0, atol=1e-12, err_msg=f"time {time} ({f})")
        np.testing.assert_allclose(d, d0, atol=1e-12)


def test_lens_change_during_the_shutter_scales_the_view_plane():
    cam = Camera(view_scale_motion=(0.5, 2.0), clip_start=0.0)
    film = Film(width=16, height=16)
    for time, k in ((0.0, 0.5), (0.25, 0.75), (0.5, 1.0), (0.75, 1.5), (1.0, 2.0)):
        _, d, _ = camera_rays(cam, film, [0.0], [0.0], time=[time], motion_blur=MotionBlur())
        half = 18.0 / 50.0 * k
        np.testing.assert_allclose(d[0], np.array([-half, half, -1.0]) / math.sqrt(2 * half * half + 1),
                                   atol=1e-12)


def test_a_static_scene_renders_the_same_bits_with_the_shutter_open():
    scene = inside_sphere_scene(albedo=0.6, emission=0.4, samples=8, res=12)
    plain = render(scene).image()
    scene.motion_blur = MotionBlur(shutter_curve=np.linspace(0, 1, 257), rolling_shutter=True)
    scene.camera.motion = np.stack([scene.camera.matrix_world] * 3)
    assert np.array_equal(render(scene).image(), plain)
    scene.camera.motion[0] = translation(0.0, 0.0, 0.3)      # the test can fail: a moving camera
    assert not np.array_equal(render(scene).image(), plain)


# -- moving geometry ---------------------------------------------------------------------------
def _mt(o, d, tri):
    """Möller-Trumbore distances of rays (n, 3) to triangles (m, 3, 3): (n, m), inf for misses."""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    e1, e2 = b - a, c - a
    p = np.cross(d[:, None, :], e2[None])
    det = np.einsum("mk,nmk->nm", e1, p)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        t_ = o[:, None, :] - a[None]
        u = np.einsum("nmk,nmk->nm", t_, p) * inv
        q = np.cross(t_, e1[None])
        v = np.einsum("nk,nmk->nm", d, q) * inv
        t = np.einsum("mk,nmk->nm", e2, q) * inv
    ok = (u >= 0) & (u <= 1) & (v >= 0) & (u + v <= 1) & (t > 0) & np.isfinite(t)
    return np.where(ok, t, np.inf)


def moving_scene():
    """Three objects: a rigid one turning, moving and growing over 5 steps, a deforming
    one (3 steps, vertices moving apart), and a still one; returns (Geometry, motions,
    world triangles at a time)."""
    from mcengine.scene import Geometry, ObjectMotion
    rng = np.random.default_rng(11)
    rigid = rng.normal(size=(6, 3, 3)) * 0.6
    soft = rng.normal(size=(6, 3, 3)) * 0.6 + [0.0, 2.5, 0.0]
    still = rng.normal(size=(6, 3, 3)) * 0.6 + [0.0, -2.5, 0.0]
    g = Geometry.concatenate([Geometry.from_triangles(t, object_names=[n])
                              for t, n in ((rigid, "Rigid"), (soft, "Soft"), (still, "Still"))])
    rots = Rotation.from_rotvec([[0, 0, 0], [0.3, 0, 0.5], [0.4, 0.2, 1.1], [0.2, 0.6, 1.8], [0, 0, 2.6]])
    moves = [[-1.0, 0, 0], [-0.5, 0.2, 0], [0, 0, 0], [0.6, -0.2, 0.3], [1.2, 0, 0.5]]
    scales = [0.8, 0.9, 1.0, 1.2, 1.5]
    mats = np.stack([affine(r.as_rotvec(), np.eye(3) * s, t) for r, s, t in zip(rots, scales, moves)])
    centre = mats[2]
    verts = g.vertices.astype(np.float64)
    soft_rest = verts[18:36]
    spread = np.array([-0.3, 0.0, 0.5])[:, None, None]       # shrinks, then spreads out
    soft_steps = soft_rest[None] + spread * (soft_rest - soft_rest.mean(axis=0))[None]
    normals = np.broadcast_to(g.corner_normals()[6:12], (3, 6, 3, 3)).astype(np.float32)
    motions = [ObjectMotion(object=0, vertices=(0, 18), matrices=mats),
               ObjectMotion(object=1, vertices=(18, 18), positions=soft_steps.astype(np.float32),
                            normals=normals)]
    inv_centre = np.linalg.inv(centre)

    def world(time):
        k = min(int(time * 4), 3)
        f = time * 4 - k
        m = np.eye(4)
        m[:3, :3] = Slerp([0, 1], rots[k:k + 2])(f).as_matrix() * ((1 - f) * scales[k] + f * scales[k + 1])
        m[:3, 3] = (1 - f) * np.array(moves[k]) + f * np.array(moves[k + 1])
        a = m @ inv_centre
        r = verts[:18] @ a[:3, :3].T + a[:3, 3]
        k2 = min(int(time * 2), 1)
        f2 = time * 2 - k2
        s = (1 - f2) * soft_steps[k2] + f2 * soft_steps[k2 + 1]
        return np.concatenate([r, s, verts[36:]])[g.triangles]
    return g, motions, world


def test_moving_objects_are_hit_where_they_are_at_each_rays_time():
    from mcengine.kernels.intersect import Accel
    g, motions, world = moving_scene()
    accel = Accel(g.vertices, g.triangles, pack_motion(g, motions))
    rng = np.random.default_rng(3)
    n = 3000
    times = np.concatenate([rng.random(n - 5), [0.0, 0.25, 0.5, 0.75, 1.0]])
    # Aim at a random point of a random triangle where it is at the ray's time.
    bary = rng.dirichlet([1, 1, 1], size=n)
    tri = rng.integers(0, g.num_triangles, size=n)
    target = np.array([bary[i] @ world(times[i])[tri[i]] for i in range(n)])
    o = rng.normal(size=(n, 3)) * 6
    d = target - o
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    o32, d32 = o.astype(np.float32), d.astype(np.float32)
    tfar = np.full(n, 1e30, np.float32)
    prim = accel.closest(o32, d32, tfar, times)
    blocked = accel.occluded(o32, d32, np.full(n, 20.0, np.float32), times)
    expect_prim = np.full(n, -1)
    expect_t = np.full(n, np.inf)
    for i in range(n):
        t = _mt(o32[i:i + 1].astype(np.float64), d32[i:i + 1].astype(np.float64), world(times[i]))[0]
        if np.isfinite(t.min()):
            expect_prim[i], expect_t[i] = int(np.argmin(t)), t.min()
    # Rays that graze an edge may go either way; elsewhere the hit is the same triangle.
    assert np.mean(prim == expect_prim) > 0.998, np.mean(prim == expect_prim)
    assert ((expect_prim >= 0) & (expect_prim < 36)).sum() > n // 2      # mostly moving objects
    np.testing.assert_array_equal(blocked, expect_t < 20.0)
    # Frozen at the frame's time, the objects would be hit elsewhere: the test can fail.
    frozen = _mt(o32.astype(np.float64), d32.astype(np.float64), world(0.5)).argmin(axis=1)
    assert np.mean((frozen == expect_prim) | (expect_prim < 0)) < 0.9


@njit(cache=False)
def _corners(md, verts, tris, prims, time):
    out = np.empty((prims.shape[0], 9))
    for i in range(prims.shape[0]):
        c = moving_triangle(md, verts, tris, prims[i], time)
        for k in range(9):
            out[i, k] = c[k]
    return out


def test_moving_triangles_are_placed_as_cycles_interpolates():
    """Corners of moving triangles at any time: slerp, lerp and linear deformation steps."""
    g, motions, world = moving_scene()
    md = pack_motion(g, motions)
    verts = g.vertices.astype(np.float64)
    prims = np.arange(12, dtype=np.int64)
    for time in (0.0, 0.1, 0.37, 0.5, 0.62, 0.9, 1.0):
        got = _corners(md, verts, g.triangles, prims, time).reshape(-1, 3, 3)
        np.testing.assert_allclose(got, world(time)[:12], atol=1e-9, err_msg=f"time {time}")


def test_the_effects_plan_names_depth_of_field_and_what_moves():
    from mcengine.features import camera_effects
    from mcengine.scene import ObjectMotion, SceneDescription
    g, motions, _ = moving_scene()
    scene = SceneDescription(geometry=g)
    assert camera_effects(scene) == ()
    still = ObjectMotion(object=2, vertices=(36, 18), matrices=np.stack([np.eye(4)] * 3))
    scene.motion_blur = MotionBlur(objects=[*motions, still])      # the still one does not count
    assert camera_effects(scene) == ("motion blur (2 moving objects)",)
    scene.camera.motion = np.stack([translation(0.0, 0.0, 0.1), scene.camera.matrix_world,
                                    scene.camera.matrix_world])
    scene.camera.aperture_size = 0.05
    assert camera_effects(scene) == ("depth of field", "motion blur (camera, 2 moving objects)")


def test_a_saved_moving_scene_renders_the_same_bits(tmp_path):
    """Save and load keep the shutter, the curve, the moving camera and every object's
    transform and deformation steps (dtypes and shapes included)."""
    from mcengine.scene import SceneDescription

    from .expect import render
    g, motions, _ = moving_scene()
    scene = SceneDescription(geometry=g, camera=Camera(matrix_world=translation(0.0, -9.0, 0.0)
                                                       @ _looking_along_y(), clip_start=0.1))
    scene.film = Film(width=12, height=12)
    scene.integrator.samples = 4
    scene.camera.motion = np.stack([translation(0.0, 0.0, 0.2) @ scene.camera.matrix_world,
                                    scene.camera.matrix_world, scene.camera.matrix_world])
    scene.motion_blur = MotionBlur(objects=motions, shutter_curve=np.linspace(0.2, 1.0, 257),
                                   rolling_shutter=True)
    scene.save(tmp_path / "moving.npz")
    loaded = SceneDescription.load(tmp_path / "moving.npz")
    for om, back in zip(motions, loaded.motion_blur.objects):
        for name in ("matrices", "positions", "normals"):
            a, b = getattr(om, name), getattr(back, name)
            assert (a is None and b is None) or (a.dtype == b.dtype and np.array_equal(a, b))
    image = render(scene).image()
    assert image[..., :3].max() > 0.0
    assert np.array_equal(image, render(loaded).image())


def _looking_along_y():
    """A camera's rotation looking along +y, z up."""
    m = np.eye(4)
    m[:3, :3] = Rotation.from_rotvec([np.pi / 2, 0, 0]).as_matrix()
    return m
