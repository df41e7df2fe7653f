"""Ray casting, Whitted and distribution ray tracing: the lecture's ray counts and their answers.

* Distribution ray tracing with branching b and depth r casts
  1 + b + ... + b^(r-1) closest-hit rays per camera sample when every ray
  hits something (camera inside a closed sphere).
* Whitted ray tracing casts 2^r - 1 rays per camera sample when every hit is
  glass (camera at the centre of nested glass shells): reflection and
  refraction at every level.
* Distribution ray tracing of depth r has the expected value of path tracing
  with r - 1 bounces; ray casting and Whitted leave out the light that
  reaches surfaces indirectly, which is the bias the lecture trades for time.
"""
import math

import numpy as np
import pytest

from mcengine.scene import (
    Camera,
    Film,
    Geometry,
    Integrator,
    Light,
    Link,
    Material,
    SceneDescription,
    SceneError,
    ShaderNode,
    World,
)
from mcengine.session import RenderSession

from .expect import assert_mean, render
from .scenes import inside_sphere_scene, plane_scene, translation, uv_sphere


def _rays_per_sample(session):
    st = session.stats
    return (st.camera_rays + st.bounce_rays) / st.camera_rays


@pytest.mark.parametrize("b,r", [(3, 4), (2, 5), (5, 2)])
def test_distribution_ray_count_is_the_sum_of_b_to_the_k(b, r):
    scene = inside_sphere_scene(albedo=0.5, samples=2, res=8)   # flat facets: no ray is lost
    scene.integrator.name = "distribution"
    scene.integrator.branching, scene.integrator.depth = b, r
    s = RenderSession(scene).run()
    assert _rays_per_sample(s) == sum(b ** k for k in range(r))


@pytest.mark.parametrize("r", [1, 3, 5])
def test_whitted_ray_count_is_two_to_the_r_minus_one(r):
    shells = [uv_sphere(2.0 ** k, 24, 12) for k in range(r)]
    tris = np.concatenate([t for t, _ in shells])
    scene = SceneDescription(
        geometry=Geometry.from_triangles(tris),
        materials=[Material(base_color=(0, 0, 0), glass_color=(1, 1, 1), ior=1.5)],
        camera=Camera(matrix_world=np.eye(4), lens=20.0, clip_start=1e-3),
        world=World(color=(1.0, 1.0, 1.0)),
        film=Film(width=8, height=8),
        integrator=Integrator(name="whitted", depth=r, samples=2))
    s = RenderSession(scene).run()
    assert _rays_per_sample(s) == 2 ** r - 1


def test_raycast_casts_one_ray_and_one_shadow_ray_per_light():
    li = [Light(type="POINT", matrix_world=translation(x, 0, 2), strength=(100.0,) * 3)
          for x in (-1.0, 1.0)]
    scene = plane_scene(li[0], samples=4)
    scene.lights = li
    scene.integrator.name = "raycast"
    s = RenderSession(scene).run()
    assert _rays_per_sample(s) == 1
    assert s.stats.shadow_rays == 2 * s.stats.camera_rays


@pytest.mark.parametrize("name", ["raycast", "whitted", "distribution"])
def test_direct_light_is_exact_for_every_integrator(name):
    P, H = 1000.0, 2.0
    li = Light(type="POINT", matrix_world=translation(0, 0, H), strength=(P, P, P))
    scene = plane_scene(li)
    scene.integrator.name = name
    scene.integrator.depth = 2
    assert_mean(render(scene), P / (4 * math.pi * H * H) / math.pi)


@pytest.mark.parametrize("b,r", [(2, 3), (4, 2)])
def test_distribution_equals_path_tracing_with_r_minus_one_bounces(b, r):
    # Inside an emissive sphere of albedo 1/2: path tracing with N bounces
    # gives sum_{k<=N+1} 1/2^k, so depth r gives sum_{k<=r} 1/2^k.
    scene = inside_sphere_scene(albedo=0.5, emission=1.0, samples=32)
    scene.integrator.name = "distribution"
    scene.integrator.branching, scene.integrator.depth = b, r
    assert_mean(render(scene), sum(0.5 ** k for k in range(r + 1)))


def test_raycast_misses_indirect_light_and_whitted_finds_mirrors():
    """Under a white sky, a mirror sphere: ray casting sees it black (the sky is
    not a light it samples), Whitted follows the reflection to the sky."""
    tris, norms = uv_sphere(1.0, 64, 32)
    scene = SceneDescription(
        geometry=Geometry.from_triangles(tris, normals=norms),
        materials=[Material(base_color=(0, 0, 0), mirror_color=(0.7, 0.7, 0.7))],
        camera=Camera(matrix_world=translation(0, 0, 4), type="ORTHO", ortho_scale=1.0),
        world=World(color=(1.0, 1.0, 1.0)),
        film=Film(width=8, height=8, filter_type="BOX", filter_width=1.0),
        integrator=Integrator(name="raycast", samples=4))
    assert np.all(render(scene).image()[..., :3] == 0.0)
    scene.integrator.name, scene.integrator.depth = "whitted", 2
    assert np.allclose(render(scene).image()[..., :3], 0.7, atol=1e-5)


def test_whitted_glass_sphere_conserves_energy_under_a_uniform_sky():
    tris, norms = uv_sphere(1.0, 96, 48)
    scene = SceneDescription(
        geometry=Geometry.from_triangles(tris, normals=norms),
        materials=[Material(base_color=(0, 0, 0), glass_color=(1, 1, 1), ior=1.5)],
        camera=Camera(matrix_world=translation(0, 0, 4), type="ORTHO", ortho_scale=0.8),
        world=World(color=(1.0, 1.0, 1.0)),
        film=Film(width=8, height=8, filter_type="BOX", filter_width=1.0),
        integrator=Integrator(name="whitted", depth=10, samples=2))
    img = render(scene).image()[..., 0]
    # Fresnel splits every ray into reflected and refracted parts whose weights
    # sum to 1; only chains longer than 10 levels (F^9 < 1e-12 here) are lost.
    assert np.allclose(img, 1.0, atol=1e-5)


def test_too_wide_a_ray_tree_is_a_clear_error():
    scene = inside_sphere_scene(samples=1)
    scene.integrator.name = "distribution"
    scene.integrator.branching, scene.integrator.depth = 64, 5
    with pytest.raises(SceneError, match="exceed the batch"):
        RenderSession(scene)


ALL_SMOOTH = {"Roughness": 0.0, "Metallic": 0.5, "Transmission Weight": 0.5, "Coat Weight": 0.5,
              "Coat Roughness": 0.0, "Alpha": 0.5}


@pytest.mark.parametrize("inputs,width", [
    ({}, 2),                       # the default Principled BSDF is rough: it spawns no ray
    ({"Roughness": 0.0}, 2),       # its smooth specular: one mirror ray (the tree stays binary)
    ({"Alpha": 0.3}, 2),           # one ray through its transparency
    (ALL_SMOOTH, 6),               # coat, metallic, specular, glass (2) and alpha
    ("textured", 6),               # roughness from a texture: the most the node can spawn
])
def test_whitted_chunks_are_sized_by_the_rays_the_materials_can_spawn(inputs, width):
    """A chunk holds batch / width^(depth - 1) camera rays, width the most rays one hit
    spawns: counted from a constant material's inputs (a rough one spawns none), else the
    node's most. Counting six for the default Principled BSDF made chunks of depth 5 hold
    101 camera rays and Whitted's time grow with the square of the samples."""
    if inputs == "textured":
        nodes = [ShaderNode("TexChecker"), ShaderNode("BsdfPrincipled", {"Roughness": Link(0, "Fac")})]
    else:
        nodes = [ShaderNode("BsdfPrincipled", inputs)]
    scene = inside_sphere_scene(samples=1, res=4)
    scene.materials = [Material(nodes=nodes, surface=Link(len(nodes) - 1, "BSDF"))]
    scene.integrator.name, scene.integrator.depth = "whitted", 5
    session = RenderSession(scene)
    assert session.roots_per_chunk == session.batch_size // width ** 4
    if inputs == ALL_SMOOTH:      # the tree of the widest case fits: it renders
        scene.integrator.depth = 3
        assert np.isfinite(RenderSession(scene).run().image()).all()


def test_kernel_codes_agree_with_the_registry():
    from mcengine.integrators import INTEGRATORS
    from mcengine.kernels import classic
    # Path + Light Tracing runs the path tracer's kernels (code 0) and adds light paths.
    assert {name: info.kernel_code for name, info in INTEGRATORS.items()} == {
        "path": 0, "light": 0, "raycast": classic.CODE_RAYCAST, "whitted": classic.CODE_WHITTED,
        "distribution": classic.CODE_DISTRIBUTION}
    assert INTEGRATORS["light"].light_tracing and not INTEGRATORS["path"].light_tracing
