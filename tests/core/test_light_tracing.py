"""Path + Light Tracing: caustics path tracing cannot find, and the same image where it can.

Light tracing's pixels carry splats that the film's per-pixel variance does not
see, so the noise of a mean is measured from the spread of K renders with
different seeds (Student's t with K - 1 degrees of freedom, or Welch's for two
stacks).

* A point lamp of radius 0 and a sharp vertical mirror over a diffuse floor,
  seen from above: the floor's radiance is albedo / pi times the lamp's
  irradiance plus that of its mirror image (reflectance 0.9), a closed form.
  Path tracing renders the mirror's caustic black; Path + Light Tracing renders
  it, and agrees with the closed form.
* A glass ball and a mirror under an area lamp, where path tracing converges
  too: the two integrators agree block by block, although a large share of the
  caustics comes from light paths in one and from camera paths in the other.
* A holdout floor under the caustic: the camera sees only the floor, so the image is
  cleared film (RGB 0, alpha 0), the light paths' splats included.
* The splat's pixel filter is the density of the offsets camera rays draw
  (Cycles' table), so the two halves estimate the same filtered pixels.
"""
import math

import numpy as np
import pytest
from scipy import stats

from mcengine.kernels.importance import filter_density
from mcengine.kernels.sampling import filter_offset, filter_table
from mcengine.scene import (
    Camera,
    Film,
    Geometry,
    Integrator,
    Light,
    Material,
    MotionBlur,
    ObjectPassInfo,
    SceneDescription,
    World,
)
from mcengine.session import RenderSession

from .scenes import grid_plane, look_down, rotation_x, translation, uv_sphere

SEEDS = 4
T_LIMIT = 8.0      # |t| of a correct renderer exceeds it with probability ~4e-3 at 3 dof
ALBEDO = 0.5
MIRROR = 0.9
POWER = 40.0


def renders(scene, integrator, seeds=SEEDS):
    """(K, h, w, 3) images of K seeds, and the last session."""
    out = []
    scene.integrator.name = integrator
    for seed in range(1, seeds + 1):
        scene.integrator.seed = seed
        session = RenderSession(scene, threads=2).run()
        out.append(session.image()[..., :3].astype(np.float64))
    return np.array(out), session


def _quad(x0, x1, y, z0, z1):
    """A vertical quad in the plane y, facing -y."""
    return np.array([[[x0, y, z0], [x1, y, z1], [x1, y, z0]],
                     [[x0, y, z0], [x0, y, z1], [x1, y, z1]]], float)


def mirror_scene(samples=64, res=32):
    """Floor (albedo 0.5) at z = 0, a point lamp at (0, 0, 1), a mirror in the plane y = 1;
    an orthographic camera sees x in [-0.5, 0.5], y in [-0.2, 0.8] from above."""
    floor = grid_plane(20.0)
    geometry = Geometry.concatenate([
        Geometry.from_triangles(floor, material_index=[0] * len(floor)),
        Geometry.from_triangles(_quad(-3.0, 3.0, 1.0, 0.01, 3.0), material_index=[1, 1])])
    return SceneDescription(
        geometry=geometry,
        materials=[Material(base_color=(ALBEDO,) * 3),
                   Material(base_color=(0.0, 0.0, 0.0), mirror_color=(MIRROR,) * 3)],
        lights=[Light(type="POINT", matrix_world=translation(0.0, 0.0, 1.0),
                      strength=(POWER,) * 3, radius=0.0)],
        camera=Camera(matrix_world=look_down(5.0, 0.0, 0.3), type="ORTHO", ortho_scale=1.0,
                      clip_start=0.01, clip_end=100.0),
        world=World(color=(0.0, 0.0, 0.0)), film=Film(width=res, height=res),
        integrator=Integrator(samples=samples, max_bounces=1, diffuse_bounces=1, glossy_bounces=1,
                              transmission_bounces=1))


def mirror_closed_form(res=32):
    """(direct, caustic) radiance of the floor at the pixel centres (top row first)."""
    c = (np.arange(res) + 0.5) / res - 0.5
    x = c[None, :] * np.ones((res, 1))
    y = 0.3 - c[:, None] * np.ones((1, res))
    intensity = POWER / (4 * math.pi)
    d_direct = np.sqrt(x ** 2 + y ** 2 + 1.0)
    d_image = np.sqrt(x ** 2 + (2.0 - y) ** 2 + 1.0)     # the lamp's image at (0, 2, 1)
    direct = ALBEDO / math.pi * intensity / d_direct ** 3
    caustic = ALBEDO / math.pi * MIRROR * intensity / d_image ** 3
    return direct, caustic


def assert_mean(images, expected, rel_se=0.01):
    means = images.mean(axis=(1, 2, 3))
    mean, se = means.mean(), means.std(ddof=1) / math.sqrt(len(means))
    assert se <= rel_se * expected, f"noise too large for a meaningful test: se {se:.3g}"
    # The closed form is taken at the pixel centres; the pixel filter's blur of the smooth
    # falloff moves a mean by about 2e-4 of it, which the Sobol sampler's tiny noise shows.
    tolerance = max(T_LIMIT * se, 1e-3 * expected)
    assert abs(mean - expected) < tolerance, f"mean {mean:.5f} vs {expected:.5f} (se {se:.2g})"


def test_point_lamp_in_a_mirror_closed_form():
    direct, caustic = mirror_closed_form()
    images, session = renders(mirror_scene(), "light")
    assert session.light_tables is not None and session.film.light_paths > 0
    assert_mean(images, float((direct + caustic).mean()))
    # The caustic half by half of the frame (it falls off towards the camera's bottom edge).
    half = images.shape[1] // 2
    for rows in (slice(0, half), slice(half, None)):
        assert_mean(images[:, rows], float((direct + caustic)[rows].mean()))


def test_an_ies_profile_weights_the_light_paths():
    """The lamp with a profile of k for every direction below 90 degrees from its nadir (0
    above 100): the floor's direct light (next-event estimation) and its caustic (light
    paths, which leave the lamp downwards towards the mirror) are both k times the closed
    form's; light paths that read the profile upside down would leave the caustic black."""
    from mcengine.ies import IESProfile
    v = np.arange(0, 181, 10)
    k = 2.5
    scene = mirror_scene()
    scene.lights[0].ies = IESProfile(
        h_angles=np.float32([0.0, 2.0 * math.pi]), v_angles=np.float32(np.radians(v)),
        intensity=np.float32([np.where(v <= 90, k, 0.0)] * 2))
    direct, caustic = mirror_closed_form()
    images, _ = renders(scene, "light")
    half = images.shape[1] // 2
    for rows in (slice(0, half), slice(half, None)):
        assert_mean(images[:, rows], k * float((direct + caustic)[rows].mean()))


def test_path_tracing_leaves_the_point_lamps_caustic_black():
    direct, caustic = mirror_closed_form()
    images, _ = renders(mirror_scene(samples=16), "path")
    assert_mean(images, float(direct.mean()))
    half = caustic.shape[0] // 2                      # what it misses is not small:
    assert caustic.mean() > 0.15 * direct.mean()      # 17 % of the frame,
    assert caustic[:half].mean() > 0.2 * direct[:half].mean()   # 26 % of its top half


def glass_scene(samples=128, res=32):
    """A glass ball (IOR 1.5) and a sharp mirror on a diffuse floor under a square area
    lamp, seen in perspective."""
    ball, normals = uv_sphere(0.45, 48, 24, center=(-0.3, 0.2, 0.47))
    floor = grid_plane(20.0)
    geometry = Geometry.concatenate([
        Geometry.from_triangles(floor, material_index=[0] * len(floor)),
        Geometry.from_triangles(ball, material_index=[1] * len(ball), normals=normals),
        Geometry.from_triangles(_quad(0.3, 1.6, 1.0, 0.01, 1.2), material_index=[2, 2])])
    camera = translation(0.2, -3.2, 2.6) @ rotation_x(math.radians(52.0))
    return SceneDescription(
        geometry=geometry,
        materials=[Material(base_color=(0.7, 0.7, 0.7)),
                   Material(base_color=(0.0, 0.0, 0.0), glass_color=(1.0, 1.0, 1.0), ior=1.5),
                   Material(base_color=(0.0, 0.0, 0.0), mirror_color=(MIRROR,) * 3)],
        lights=[Light(type="AREA", matrix_world=translation(-0.5, -0.3, 2.2), strength=(60.0,) * 3,
                      size_x=0.8, size_y=0.8)],
        camera=Camera(matrix_world=camera, lens=32.0),
        world=World(color=(0.0, 0.0, 0.0)), film=Film(width=res, height=res),
        integrator=Integrator(samples=samples, max_bounces=6, diffuse_bounces=4, glossy_bounces=6,
                              transmission_bounces=6))


def test_area_lamp_caustics_agree_with_path_tracing():
    scene = glass_scene()
    ours, session = renders(scene, "light")
    theirs, _ = renders(scene, "path")
    assert session.light_tables is not None
    # The light paths' share of the image: a large part of the caustics.
    film = session.film
    splat = (film.splat / film.light_paths).reshape(film.height, film.width, 3)
    k = 4
    h, w = ours.shape[1] // k, ours.shape[2] // k

    def blocks(a):
        return a[..., :k * h, :k * w, :].reshape(a.shape[0], k, h, k, w, 3).mean(axis=(2, 4, 5))
    a, b = blocks(ours), blocks(theirs)
    share = blocks(splat[None])[0] / np.maximum(a.mean(axis=0), 1e-12)
    assert share.max() > 0.15, f"light tracing adds little here: {share.max():.2f}"
    diff = a.mean(axis=0) - b.mean(axis=0)
    se = np.sqrt(a.var(axis=0, ddof=1) / SEEDS + b.var(axis=0, ddof=1) / SEEDS)
    t = diff / np.maximum(se, 1e-300)
    assert np.all(np.abs(t) < T_LIMIT), f"blocks differ: t = {np.round(t, 1)}"
    frame = ours.mean(axis=(1, 2, 3)).mean() - theirs.mean(axis=(1, 2, 3)).mean()
    frame_se = math.hypot(ours.mean(axis=(1, 2, 3)).std(ddof=1), theirs.mean(axis=(1, 2, 3)).std(ddof=1))
    assert abs(frame) < T_LIMIT * frame_se / math.sqrt(SEEDS)
    assert frame_se / math.sqrt(SEEDS) < 0.01 * theirs.mean()


def test_light_paths_do_not_light_a_holdout_floor():
    """Floor and mirror as objects, the floor a holdout: camera rays that reach it clear the
    film, and the light paths that end on it must not splat their caustic there (before
    the fix, up to 0.72 in a pixel; the floor not held out averages 0.45).  RGB exactly 0."""
    scene = mirror_scene(samples=16, res=16)
    scene.geometry.object_names = ["Floor", "Mirror"]
    scene.geometry.object_index = np.array([0] * (scene.geometry.num_triangles - 2) + [1, 1], np.int32)
    scene.geometry.object_passes = [ObjectPassInfo("Floor", "Floor", holdout=True),
                                    ObjectPassInfo("Mirror", "Mirror")]
    images, session = renders(scene, "light", seeds=1)
    assert session.film.light_paths > 0
    assert float(np.abs(images).max()) == 0.0
    assert float(session.image()[..., 3].max()) == 0.0
    scene.geometry.object_passes[0].holdout = False
    images, _ = renders(scene, "light", seeds=1)
    assert float(images.mean()) > 0.3


def test_caustics_switches_off_render_as_path_tracing():
    scene = glass_scene(samples=4, res=8)
    scene.integrator.caustics_refractive = False
    scene.integrator.name = "light"
    session = RenderSession(scene, threads=1)
    assert session.light_tables is None
    assert any("Caustics" in w for w in session.warnings)
    image = session.run().image()
    scene.integrator.name = "path"
    assert np.array_equal(image, RenderSession(scene, threads=1).run().image())


def test_motion_blur_renders_as_path_tracing_only_where_something_moves():
    scene = glass_scene(samples=4, res=8)
    scene.integrator.name = "light"
    scene.motion_blur = MotionBlur()            # the shutter open, nothing moving
    assert RenderSession(scene, threads=1).light_tables is not None
    frame = scene.camera.matrix_world
    scene.camera.motion = np.stack([translation(-0.1, 0.0, 0.0) @ frame, frame,
                                    translation(0.1, 0.0, 0.0) @ frame])
    session = RenderSession(scene, threads=1)
    assert session.light_tables is None
    assert any("motion blur" in w for w in session.warnings)


@pytest.mark.parametrize("filter_type,width", [("BLACKMAN_HARRIS", 1.5), ("GAUSSIAN", 1.5), ("BOX", 1.0)])
def test_splat_filter_is_the_density_camera_rays_draw(filter_type, width):
    table = filter_table(filter_type, width)
    u = (np.arange(400000) + 0.5) / 400000
    offsets = np.array([filter_offset(table, x) for x in u[::8]])
    lo, hi = offsets.min(), offsets.max()
    edges = np.linspace(lo, hi, 41)
    counts, _ = np.histogram(offsets, edges)
    mids = 0.5 * (edges[1:] + edges[:-1])
    fine = np.linspace(lo, hi, 40001)
    dens = np.array([filter_density(table, o) for o in fine])
    integral = dens[:-1].sum() * (fine[1] - fine[0])
    assert abs(integral - 1.0) < 2e-3, integral
    expected = np.array([dens[(fine >= a) & (fine < b)].mean() for a, b in zip(edges[:-1], edges[1:])])
    expected *= offsets.size * (edges[1] - edges[0])
    ok = expected > 5
    chi2 = float((((counts - expected) ** 2)[ok] / expected[ok]).sum())
    assert stats.chi2.sf(chi2, ok.sum() - 1) > 1e-3, (chi2, mids[ok])
