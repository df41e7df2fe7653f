"""Property-based tests of the core: random small scenes stay numerically sound.

Hypothesis draws scenes the way a careless or hostile user might make them:
a few random triangles (degenerate and nearly coplanar ones included) over a
floor, random materials (diffuse, mirror, glass with any index of refraction
from exactly 1 to 3, emission), lamps of every type with sizes and angles
from 0 to extreme, a random camera, all at scales from 0.1 mm to 100 km and
far from the origin.  Each is rendered at a few samples per pixel, and must:

* contain no NaN or infinity, and no negative value (all light is positive);
* be bit-identical for the same seed with one or two threads;
* (diffuse-only scenes) stay below the closed-form maximum: the brightest
  radiance a camera ray can meet directly, plus (bounces + 1) times the sum of
  every light's greatest irradiance at any point of the geometry, over pi.
  With albedos at most 1 no diffuse surface can be brighter than that.

The examples are derandomised (the same on every run, so CI is reproducible)
and bounded in number and time.  ``@example`` keeps the degenerate lights
found before (sun angles and sphere radii whose cones round to nothing).
"""
from __future__ import annotations

import math

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, example, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from mcengine.scene import Camera, Film, Geometry, Integrator, Light, Material, SceneDescription, World  # noqa: E402
from mcengine.session import RenderSession  # noqa: E402

FUZZ = settings(max_examples=500, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])

finite = dict(allow_nan=False, allow_infinity=False)
unit = st.floats(0.0, 1.0, **finite)
tiny_to_huge = st.one_of(st.just(0.0), st.floats(1e-30, 1e-6, **finite), st.floats(1e-6, 1e3, **finite))


@st.composite
def lights(draw, scale, center):
    kind = draw(st.sampled_from(["POINT", "SPOT", "SUN", "AREA"]))
    m = np.eye(4)
    # A random orientation (rows of a random rotation) and a position around the scene.
    q = draw(st.lists(st.floats(-1, 1, **finite), min_size=4, max_size=4))
    q = np.array(q) if np.linalg.norm(q) > 1e-3 else np.array([1.0, 0, 0, 0])
    w, x, y, z = q / np.linalg.norm(q)
    m[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    offset = draw(st.lists(st.floats(-3, 3, **finite), min_size=3, max_size=3))
    m[:3, 3] = center + scale * np.array(offset)
    p = draw(st.floats(0.0, 1e6, **finite))
    return Light(type=kind, matrix_world=m, strength=(p, p * draw(unit), p * draw(unit)),
                 radius=scale * draw(tiny_to_huge), soft_falloff=draw(st.booleans()),
                 spot_size=draw(st.floats(0.0, math.pi, **finite)), spot_blend=draw(unit),
                 angle=draw(st.one_of(tiny_to_huge.map(lambda a: min(a, math.pi)),
                                      st.floats(0.0, math.pi, **finite))),
                 shape=draw(st.sampled_from(["SQUARE", "RECTANGLE", "DISK", "ELLIPSE"])),
                 size_x=scale * draw(tiny_to_huge), size_y=scale * draw(tiny_to_huge),
                 spread=draw(st.floats(0.0, math.pi, **finite)), normalize=draw(st.booleans()),
                 visible_camera=draw(st.booleans()), use_mis=draw(st.booleans()))


@st.composite
def scenes(draw, diffuse_only=False):
    scale = 10.0 ** draw(st.floats(-4, 5, **finite))
    center = scale * 10.0 ** draw(st.floats(0, 4, **finite)) * np.array(
        draw(st.lists(st.floats(-1, 1, **finite), min_size=3, max_size=3)))
    tris = [center + scale * np.array([[-50, -50, -1], [50, -50, -1], [50, 50, -1]]),
            center + scale * np.array([[-50, -50, -1], [50, 50, -1], [-50, 50, -1]])]
    for _ in range(draw(st.integers(1, 6))):
        t = np.array(draw(st.lists(st.floats(-2, 2, **finite), min_size=9, max_size=9))).reshape(3, 3)
        how = draw(st.sampled_from(["random", "duplicate vertex", "collinear", "near coplanar"]))
        if how == "duplicate vertex":
            t[2] = t[0]
        elif how == "collinear":
            t[2] = t[0] + draw(st.floats(-3, 3, **finite)) * (t[1] - t[0])
        elif how == "near coplanar":
            t[:, 2] = t[0, 2] + 1e-7 * np.array(draw(st.lists(unit, min_size=3, max_size=3)))
        tris.append(center + scale * t)
    n_mat = draw(st.integers(1, 3))
    materials = []
    for _ in range(n_mat):
        lobes = {}
        if not diffuse_only:
            for name in ("mirror_color", "glass_color", "refraction_color"):
                if draw(st.booleans()):
                    lobes[name] = (draw(unit), draw(unit), draw(unit))
        emit = draw(st.sampled_from([0.0, 0.0, 1.0, 1e4])) * draw(unit)
        materials.append(Material(base_color=(draw(unit), draw(unit), draw(unit)),
                                  emission=(emit, emit, emit),
                                  ior=draw(st.one_of(st.just(1.0), st.floats(0.2, 3.0, **finite))),
                                  **lobes))
    geo = Geometry.from_triangles(np.array(tris),
                                  material_index=[draw(st.integers(0, n_mat - 1)) for _ in tris])
    target = center
    eye = center + scale * np.array(draw(st.lists(st.floats(-5, 5, **finite), min_size=3, max_size=3)))
    forward = target - eye
    if np.linalg.norm(forward) < 1e-3 * scale:
        forward = np.array([0.0, 0.0, -1.0]) * scale
    f = forward / np.linalg.norm(forward)
    up = np.array([0.0, 0.0, 1.0]) if abs(f[2]) < 0.99 else np.array([0.0, 1.0, 0.0])
    right = np.cross(f, up)
    right /= np.linalg.norm(right)
    cam = np.eye(4)
    cam[:3, 0], cam[:3, 1], cam[:3, 2], cam[:3, 3] = right, np.cross(right, f), -f, eye
    ortho = draw(st.booleans())
    w = draw(st.sampled_from([0.0, 0.0, 0.3, 5.0]))
    bounces = draw(st.integers(0, 4))
    return SceneDescription(
        geometry=geo, materials=materials,
        lights=[draw(lights(scale, center)) for _ in range(draw(st.integers(0, 3)))],
        camera=Camera(matrix_world=cam, type="ORTHO" if ortho else "PERSP",
                      lens=draw(st.floats(1.0, 500.0, **finite)), ortho_scale=scale * 4,
                      clip_start=scale * 1e-3, clip_end=scale * 1e4),
        world=World(color=(w, w * draw(unit), w)),
        film=Film(width=6, height=5, filter_type=draw(st.sampled_from(["BLACKMAN_HARRIS", "BOX"]))),
        integrator=Integrator(samples=3, seed=draw(st.integers(0, 2 ** 31 - 1)),
                              max_bounces=bounces, diffuse_bounces=bounces, glossy_bounces=bounces,
                              transmission_bounces=bounces))


def _render(scene, threads):
    session = RenderSession(scene, threads=threads, batch_size=4096).run()
    return session, session.image()


def _sun_scene(angle):
    """A floor under a sun: the degenerate sun angles once gave 1e16 times the light."""
    scene = SceneDescription(
        geometry=Geometry.from_triangles([[[-9, -9, 0], [9, -9, 0], [9, 9, 0]],
                                          [[-9, -9, 0], [9, 9, 0], [-9, 9, 0]]]),
        materials=[Material(base_color=(1.0, 1.0, 1.0))],
        lights=[Light(type="SUN", strength=(3.0,) * 3, angle=angle)],
        camera=Camera(matrix_world=np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 5], [0, 0, 0, 1.0]]),
                      type="ORTHO", ortho_scale=1.0),
        world=World(color=(0, 0, 0)), film=Film(width=6, height=5),
        integrator=Integrator(samples=3, max_bounces=0))
    return scene


def _point_scene(radius):
    """...and a small sphere lamp once gave no light at all."""
    scene = _sun_scene(0.0)
    scene.lights = [Light(type="POINT", matrix_world=np.array(
        [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 2], [0, 0, 0, 1.0]]), strength=(1000.0,) * 3,
        radius=radius, soft_falloff=False)]
    return scene


@FUZZ
@example(_sun_scene(1e-8))
@example(_sun_scene(2e-9))
@example(_point_scene(1e-9))
@given(scenes())
def test_random_scenes_render_finite_positive_and_reproducible(scene):
    session, image = _render(scene, threads=1)
    assert np.all(np.isfinite(image)), "NaN or infinite pixels"
    assert image.min() >= 0.0, f"negative radiance {image.min()}"
    assert session.stats.nonfinite == 0, f"{session.stats.nonfinite} non-finite samples dropped"
    _, again = _render(scene, threads=2)
    assert np.array_equal(image, again), "not reproducible across thread counts"


@FUZZ
@example(_sun_scene(1e-8))
@example(_point_scene(1e-9))
@given(scenes(diffuse_only=True))
def test_diffuse_scenes_stay_below_the_closed_form_maximum(scene):
    bound = _brightness_bound(scene)
    if not math.isfinite(bound):
        return   # a lamp touches the geometry: no finite bound exists
    session, image = _render(scene, threads=2)
    rgb = image[..., :3].astype(np.float64)
    se = np.sqrt(np.nan_to_num(session.variance().astype(np.float64), posinf=0.0).sum()) / rgb[..., 0].size
    assert rgb.mean() <= bound * (1 + 1e-9) + 6 * se, f"frame mean {rgb.mean():.6g} above {bound:.6g}"


def _point_triangle_distance(p, tri) -> float:
    """Distance from point p to a (possibly degenerate) triangle."""
    a, b, c = tri
    n = np.cross(b - a, c - a)
    best = math.inf
    for u, v in ((a, b), (b, c), (c, a)):       # edges (degenerate triangles are edges)
        d = v - u
        t = np.clip(np.dot(p - u, d) / np.dot(d, d), 0.0, 1.0) if np.dot(d, d) > 0 else 0.0
        best = min(best, float(np.linalg.norm(p - (u + t * d))))
    nn = float(np.dot(n, n))
    if nn > 0:
        q = p - np.dot(p - a, n) / nn * n                  # projection on the plane
        w0 = np.dot(np.cross(b - a, q - a), n)
        w1 = np.dot(np.cross(c - b, q - b), n)
        w2 = np.dot(np.cross(a - c, q - c), n)
        if (w0 >= 0 and w1 >= 0 and w2 >= 0) or (w0 <= 0 and w1 <= 0 and w2 <= 0):
            best = min(best, abs(float(np.dot(p - a, n))) / math.sqrt(nn))
    return best


def _brightness_bound(scene) -> float:
    """Largest expected pixel value a diffuse-only scene (albedo <= 1) can produce."""
    verts = scene.geometry.vertices.astype(np.float64)[scene.geometry.triangles]
    seen = max(scene.world.color)                      # radiance a camera ray can meet
    irradiance = math.pi * max(scene.world.color)      # greatest irradiance anywhere
    emit = max(max(scene.materials[i].emission) for i in set(scene.geometry.material_index.tolist()))
    seen = max(seen, emit)
    irradiance += math.pi * emit
    for li in scene.lights:
        p = max(abs(x) for x in li.strength)
        if li.type == "SUN":
            half = li.angle / 2
            irradiance += p
            if half > 0:    # a sun small enough for sin^2 to underflow: no finite bound
                solid = math.pi * math.sin(half) ** 2
                seen = max(seen, p / solid if solid > 0 else math.inf)
        elif li.type == "AREA":
            sx, sy = li.size_x, li.size_x if li.shape in ("SQUARE", "DISK") else li.size_y
            scale = np.linalg.norm(np.asarray(li.matrix_world)[:3, :2], axis=0)
            area = sx * sy * scale[0] * scale[1] * (math.pi / 4 if li.shape in ("DISK", "ELLIPSE") else 1)
            if area <= 0:
                continue
            peak = 1.0
            if li.spread < math.pi - 1e-6:
                h = max(li.spread, 1e-4) / 2
                peak = math.tan(h) / (math.tan(h) - h) if h >= 0.05 else math.tan(h) / (
                    h * h * h * (1 / 3 + h * h * (2 / 15 + h * h * 17 / 315)))
            radiance = p / (math.pi * (area if li.normalize else 1.0)) * peak
            seen = max(seen, radiance)
            irradiance += math.pi * radiance
        else:
            pos = np.asarray(li.matrix_world)[:3, 3]
            d = min(_point_triangle_distance(pos, t) for t in verts)
            if d <= li.radius or d <= 0:
                return math.inf
            irradiance += p / (4 * math.pi * d * d)
            if li.radius > 0:
                seen = max(seen, p / (4 * math.pi ** 2 * li.radius ** 2))
    bounces = scene.integrator.max_bounces
    return seen + (bounces + 1) * irradiance / math.pi


@FUZZ
@example(kind="SUN", size=1e-8, height=1.0, tilt=0.5)
@example(kind="SPHERE", size=1e-9, height=2.0, tilt=0.0)
@given(kind=st.sampled_from(["SUN", "SPHERE", "DISK"]),
       size=st.one_of(st.just(0.0), st.floats(1e-300, 1.0, **finite)),
       height=st.floats(1.5, 100.0, **finite), tilt=st.floats(0.0, 1.2, **finite))
def test_lamps_of_any_size_give_their_closed_form_irradiance(kind, size, height, tilt):
    """A sun of any angle (above the horizon) gives E = S cos(tilt); a sphere lamp of any radius r at height h
    P / (4 pi h^2), a facing disk P / (4 pi (h^2 + r^2)); the floor is white Lambert."""
    scene = _sun_scene(0.0)
    scene.integrator.samples = 64
    scene.camera.ortho_scale = 1e-3     # the floor right below the lamp
    if kind == "SUN":
        c, s = math.cos(tilt), math.sin(tilt)
        m = np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])
        # The whole sun disk stays above the horizon (else E is not S cos).
        angle = 2 * size * (math.pi / 2 - tilt) * 0.999
        scene.lights = [Light(type="SUN", matrix_world=m, strength=(3.0,) * 3, angle=angle)]
        expected = 3.0 * c / math.pi
    else:
        r = size * (height - 1.0)
        scene.lights = [Light(type="POINT", matrix_world=np.array(
            [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, height], [0, 0, 0, 1.0]]), strength=(1000.0,) * 3,
            radius=r, soft_falloff=kind == "DISK")]
        d2 = height * height + (r * r if kind == "DISK" else 0.0)
        expected = 1000.0 / (4 * math.pi * d2) / math.pi
    session, image = _render(scene, threads=2)
    mean = float(image[..., 0].mean())
    se = math.sqrt(float(session.variance()[..., 0].astype(np.float64).sum())) / image[..., 0].size
    assert abs(mean - expected) <= 6 * se + 1e-3 * expected, f"{mean:.6g} vs {expected:.6g} (se {se:.2g})"
