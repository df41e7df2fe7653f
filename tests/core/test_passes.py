"""Render passes against closed forms (Cycles' definitions, kernel/film/*.h).

* Light passes recompose Combined pixel by pixel: Σ (direct + indirect) x colour
  + emission + environment, on a scene with every kind of closure (diffuse,
  glossy, glass, refraction, emission, and a bump-mapped mix of diffuse and
  glossy, where a sampled direction's value can differ from an evaluation's) and
  a visible world.
* Data passes: depth (planar), mist (each falloff), position, normal, UV,
  object and material index, colour passes, on a plane seen from above.
* Cryptomatte: ids are MurmurHash3 of the names as floats, coverage sums to 1
  over a pixel's ranks, ranks sorted by coverage; the hash agrees with known
  MurmurHash3_32 values.
* Denoising albedo and normal: the first non-specular surface's albedo, also
  seen through a mirror (times its colour), and the normal in camera space.
* A textured world (Environment Texture, sampled with its map): the sky's
  radiance goes to Environment and the denoising albedo, its light on a plane to
  Diffuse Direct, and the light passes still recompose Combined.
* Ambient occlusion: a floor under a square ceiling sees the sky in 1 minus the
  ceiling's form factor (cosine-weighted), times the floor's alpha; beyond the AO
  distance nothing occludes.
"""
import math

import numpy as np
import pytest

from mcengine import cryptomatte
from mcengine.passes import PASSES, RenderPasses
from mcengine.scene import (
    Camera,
    Denoising,
    Film,
    Geometry,
    Image,
    Integrator,
    Light,
    Link,
    Material,
    ObjectPassInfo,
    SceneDescription,
    ShaderNode,
    World,
)

from .expect import render
from .scenes import grid_plane, look_down, translation, uv_sphere

ALL = tuple(p.name for p in PASSES)
LIGHT_GROUPS = ("Diffuse", "Glossy", "Transmission")


def _glossy(rough):
    return Material(name=f"glossy{rough}", nodes=[ShaderNode("BsdfGlossy", {"Roughness": rough,
                                                                            "Color": (0.9, 0.7, 0.5)})],
                    surface=Link(0, "BSDF"))


def _bumped_mix():
    """Diffuse and rough glossy mixed, both bumped by a noise texture (strongly: the bumped
    normals lean far from the smooth one)."""
    return Material(name="bumped", nodes=[
        ShaderNode("TexNoise", {"Scale": 8.0}),
        ShaderNode("Bump", {"Height": Link(0, "Fac"), "Strength": 1.0, "Distance": 0.3}),
        ShaderNode("BsdfDiffuse", {"Color": (0.8, 0.5, 0.3), "Normal": Link(1, "Normal")}),
        ShaderNode("BsdfGlossy", {"Roughness": 0.4, "Normal": Link(1, "Normal")}),
        ShaderNode("MixShader", {"Fac": 0.5, "Shader": Link(2, "BSDF"), "Shader_001": Link(3, "BSDF")})],
        surface=Link(4, "Shader"))


def _mixed_scene(samples=64, res=16, seed=0):
    """A floor (diffuse), spheres of rough glossy, glass and refraction, an emissive sphere,
    a bump-mapped one, a point light and a coloured world, seen in perspective."""
    parts, mats = [], []
    floor = Geometry.from_triangles(grid_plane(20.0, 2), material_index=np.zeros(8, int),
                                    object_names=["Floor"])
    parts.append(floor)
    spheres = [((-1.2, 0, 0.6), 1), ((0.0, 0, 0.6), 2), ((1.2, 0, 0.6), 3), ((0.6, 1.2, 0.5), 4),
               ((-0.7, -1.0, 0.4), 5)]
    for k, (center, m) in enumerate(spheres):
        tris, norms = uv_sphere(0.5, 24, 12, center=center)
        parts.append(Geometry.from_triangles(tris, normals=norms, material_index=np.full(len(tris), m),
                                             object_names=[f"Sphere{k}"]))
    mats = [Material(name="floor", base_color=(0.6, 0.5, 0.4)), _glossy(0.3),
            Material(name="glass", glass_color=(1.0, 0.9, 0.8), ior=1.45),
            Material(name="mix", nodes=[ShaderNode("BsdfDiffuse", {"Color": (0.2, 0.8, 0.3)}),
                                        ShaderNode("BsdfGlass", {"Roughness": 0.2, "IOR": 1.5}),
                                        ShaderNode("MixShader", {"Fac": 0.5, "Shader": Link(0, "BSDF"),
                                                                 "Shader_001": Link(1, "BSDF")})],
                     surface=Link(2, "Shader")),
            Material(name="lamp", base_color=(0.0, 0.0, 0.0), emission=(4.0, 3.0, 2.0)),
            _bumped_mix()]
    cam = translation(0.0, -5.0, 2.5) @ _rot_x(math.radians(65))
    return SceneDescription(
        geometry=Geometry.concatenate(parts), materials=mats,
        lights=[Light(type="POINT", matrix_world=translation(1.0, -1.0, 3.0), strength=(300.0,) * 3,
                      radius=0.1)],
        camera=Camera(matrix_world=cam, lens=30.0),
        world=World(color=(0.1, 0.15, 0.3)),
        film=Film(width=res, height=res),
        integrator=Integrator(samples=samples, seed=seed, max_bounces=6))


def _rot_x(angle):
    c, s = math.cos(angle), math.sin(angle)
    m = np.eye(4)
    m[1:3, 1:3] = [[c, -s], [s, c]]
    return m


def test_light_passes_recompose_combined():
    scene = _mixed_scene()
    scene.passes = RenderPasses(enabled=ALL)
    s = render(scene)
    combined = s.image()[..., :3].astype(np.float64)
    total = s.pass_image("Emission").astype(np.float64) + s.pass_image("Environment")
    for group in LIGHT_GROUPS:
        light = s.pass_image(f"{group} Direct").astype(np.float64) + s.pass_image(f"{group} Indirect")
        total += light * s.pass_image(f"{group} Color")
        assert s.pass_image(f"{group} Direct").max() > 0, group
        assert s.pass_image(f"{group} Indirect").max() > 0, group
    assert s.pass_image("Emission").max() > 1.0 and s.pass_image("Environment").max() > 0.05
    np.testing.assert_allclose(total, combined, rtol=2e-4, atol=2e-5)


def test_light_passes_follow_the_film_exposure():
    scene = _mixed_scene(samples=8, res=8)
    scene.passes = RenderPasses(enabled=("Diffuse Direct", "Diffuse Color", "Emission"))
    a = render(scene)
    before = {name: a.pass_image(name) for name in a.pass_names()}
    scene.film.exposure = 2.0    # (the session reads its scene's exposure when asked)
    b = render(scene)
    np.testing.assert_allclose(b.pass_image("Diffuse Direct"), 2 * before["Diffuse Direct"],
                               rtol=1e-6)
    np.testing.assert_allclose(b.pass_image("Emission"), 2 * before["Emission"], rtol=1e-6)
    np.testing.assert_array_equal(b.pass_image("Diffuse Color"), before["Diffuse Color"])


def _textured_world_scene(res=16, samples=16):
    """A grey-blue plane to the horizon under a world whose colour varies with the azimuth
    (an Environment Texture of a ramp, importance-sampled), seen by a level camera: the
    top half of the frame is sky."""
    w, h = 32, 16
    sky = np.ones((h, w, 4), np.float32)
    sky[..., 0] = 0.2 + np.linspace(0.0, 1.0, w)[None, :]
    sky[..., 1] = 0.5
    sky[..., 2] = 1.0 - 0.5 * np.linspace(0.0, 1.0, w)[None, :]
    world = World(nodes=[ShaderNode("TexEnvironment", props={"image": "sky"}),
                         ShaderNode("Background", {"Color": Link(0, "Color"), "Strength": 1.0})],
                  surface=Link(1, "Background"), sampling="MANUAL", map_resolution=64)
    return SceneDescription(
        geometry=Geometry.from_triangles(grid_plane(200.0), object_names=["Plane"]),
        materials=[Material(base_color=(0.3, 0.5, 0.7))],
        camera=Camera(matrix_world=translation(0.0, 0.0, 1.0) @ _rot_x(math.pi / 2)),
        world=world, images={"sky": Image(sky, "linear", "PREMUL")},
        film=Film(width=res, height=res, filter_type="BOX", filter_width=1.0),
        integrator=Integrator(samples=samples, max_bounces=1),
        passes=RenderPasses(enabled=ALL, denoising_data=True))


def test_textured_world_in_the_environment_pass_and_the_denoising_guides():
    s = render(_textured_world_scene())
    combined = s.image()[..., :3].astype(np.float64)
    env, albedo = s.pass_image("Environment"), s.pass_image("Denoising Albedo")
    # Sky (rows above the horizon): Combined is the world's radiance, all of it in
    # Environment and in the albedo guide (Cycles adds the background there), no normal.
    sky = slice(0, 8)
    np.testing.assert_allclose(env[sky], combined[sky], rtol=1e-5, atol=1e-7)
    np.testing.assert_allclose(albedo[sky], combined[sky], rtol=1e-5, atol=1e-7)
    assert np.all(s.pass_image("Denoising Normal")[sky] == 0.0)
    assert np.ptp(env[sky][..., 0]) > 0.05 and np.ptp(env[sky][..., 2]) > 0.02   # it varies
    # Ground (rows well below the horizon): lit by the world through Diffuse Direct.
    ground = slice(10, 16)
    assert np.all(env[ground] == 0.0)
    np.testing.assert_allclose(albedo[ground], np.broadcast_to([0.3, 0.5, 0.7], (6, 16, 3)),
                               rtol=1e-5)
    assert s.pass_image("Diffuse Direct")[ground].min() > 0.1
    total = s.pass_image("Emission").astype(np.float64) + env
    for group in LIGHT_GROUPS:
        light = s.pass_image(f"{group} Direct").astype(np.float64) + s.pass_image(f"{group} Indirect")
        total += light * s.pass_image(f"{group} Color")
    np.testing.assert_allclose(total, combined, rtol=2e-4, atol=2e-5)


def _plane_scene(height=4.0, ortho=True, albedo=(0.3, 0.5, 0.7), res=8, samples=4, **passes):
    geo = Geometry.from_triangles(grid_plane(40.0), uvs=np.tile([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]],
                                                               (2, 1, 1)),
                                  object_names=["Plane"])
    geo.object_passes = [ObjectPassInfo("Plane", "Rig")]
    geo.object_info = np.array([[0.0, 7.0, 0.0, 0.0, 0.0, 0.0]])     # pass index 7
    return SceneDescription(
        geometry=geo, materials=[Material(name="Paint", base_color=albedo, pass_index=3)],
        lights=[Light(type="SUN", strength=(2.0,) * 3)],
        camera=Camera(matrix_world=look_down(height), type="ORTHO" if ortho else "PERSP",
                      ortho_scale=2.0, clip_start=0.01, clip_end=100.0),
        world=World(color=(0.0, 0.0, 0.0)),
        film=Film(width=res, height=res, filter_type="BOX", filter_width=1.0),
        integrator=Integrator(samples=samples, max_bounces=0),
        passes=RenderPasses(**passes))


def test_data_passes_of_a_plane_seen_from_above():
    scene = _plane_scene(enabled=ALL)
    s = render(scene)
    np.testing.assert_allclose(s.pass_image("Depth"), 4.0, rtol=1e-6)
    np.testing.assert_allclose(s.pass_image("Normal"), np.broadcast_to([0, 0, 1], (8, 8, 3)), atol=1e-6)
    np.testing.assert_allclose(s.pass_image("Diffuse Color"), np.broadcast_to([0.3, 0.5, 0.7], (8, 8, 3)),
                               rtol=1e-6)
    assert s.pass_image("Glossy Color").max() == 0.0
    assert np.all(s.pass_image("Object Index") == 7.0)
    assert np.all(s.pass_image("Material Index") == 3.0)
    # Position: the first sample is at the pixel centre; ortho_scale 2 over 8 pixels.
    pos = s.pass_image("Position")
    centres = -1.0 + (np.arange(8) + 0.5) * 0.25
    np.testing.assert_allclose(pos[..., 0], np.broadcast_to(centres, (8, 8)), atol=1e-6)
    np.testing.assert_allclose(pos[..., 1], np.broadcast_to(centres[::-1, None], (8, 8)), atol=1e-6)
    np.testing.assert_allclose(pos[..., 2], 0.0, atol=1e-6)
    # UV: the plane's two triangles map (x, y) in [-20, 20]^2 affinely onto the UV square's
    # lower-right half and its mirror; the third channel is 1 wherever a UV was written.
    uv = s.pass_image("UV")
    assert np.all(uv[..., 2] == 1.0) and 0.4 < uv[..., 0].mean() < 0.6
    assert s.pass_image("Vector").max() == 0.0
    np.testing.assert_allclose(s.pass_image("Ambient Occlusion"), 1.0)    # nothing above
    # A sun of 2 W/m^2 at normal incidence: radiance albedo x 2/pi, diffuse light 2/pi.
    np.testing.assert_allclose(s.pass_image("Diffuse Direct"), 2.0 / math.pi, rtol=1e-6)
    for name in ("Glossy Direct", "Transmission Direct", "Diffuse Indirect", "Emission"):
        assert s.pass_image(name).max() == 0.0, name


def test_glossy_light_goes_to_the_glossy_passes():
    scene = _plane_scene(enabled=ALL, samples=16)
    scene.materials = [_glossy(0.4)]
    scene.lights = [Light(type="SUN", strength=(2.0,) * 3, angle=0.3)]
    scene.integrator.max_bounces = 2
    s = render(scene)
    assert s.pass_image("Glossy Direct").min() > 0.1
    for name in ("Diffuse Direct", "Diffuse Indirect", "Transmission Direct", "Transmission Indirect",
                 "Diffuse Color"):
        assert s.pass_image(name).max() == 0.0, name


def test_uv_pass_is_zero_without_a_uv_map():
    scene = _plane_scene(enabled=("UV",))
    scene.geometry.object_passes = [ObjectPassInfo("Plane", "Plane", has_uv=False)]
    assert np.all(render(scene).pass_image("UV") == 0.0)


@pytest.mark.parametrize("falloff,shape", [("LINEAR", lambda m: m), ("QUADRATIC", lambda m: m * m),
                                           ("INVERSE_QUADRATIC", np.sqrt)])
def test_mist_is_the_camera_distance_through_the_falloff(falloff, shape):
    scene = _plane_scene(height=6.0, ortho=False, enabled=("Mist", "Depth"), mist_start=2.0,
                         mist_depth=8.0, mist_falloff=falloff)
    scene.camera.lens = 80.0
    scene.integrator.samples = 1        # one sample: the pixel centre
    s = render(scene)
    # Perspective: depth is planar (6), mist uses the Euclidean distance to the camera.
    np.testing.assert_allclose(s.pass_image("Depth"), 6.0, rtol=1e-6)
    pos = scene.camera  # the camera at (0, 0, 6) looking down; ray to each pixel centre
    from mcengine.kernels.camera import camera_rays
    ys, xs = np.mgrid[0:8, 0:8] + 0.5
    _o, d, _t = camera_rays(pos, scene.film, xs.ravel(), ys.ravel())
    distance = 6.0 / np.abs(d[:, 2])
    expected = shape(np.clip((distance - 2.0) / 8.0, 0.0, 1.0)).reshape(8, 8)
    np.testing.assert_allclose(s.pass_image("Mist")[..., 0], expected, rtol=2e-5)


def test_background_reads_depth_1e10_and_mist_1():
    scene = _plane_scene(enabled=("Depth", "Mist", "Object Index", "Normal"))
    scene.geometry = Geometry()
    s = render(scene)
    assert np.all(s.pass_image("Depth") == 1e10)
    assert np.all(s.pass_image("Mist") == 1.0)
    assert np.all(s.pass_image("Object Index") == 0.0) and np.all(s.pass_image("Normal") == 0.0)


def test_memory_estimate_counts_the_pass_sums():
    from mcengine import memory
    from mcengine.session import RenderSession
    session = RenderSession(_plane_scene(enabled=("Depth", "Diffuse Direct"),
                                         cryptomatte=("CryptoObject",)))
    stride = session.pass_layout.stride
    assert stride == 1 + 3 + 3 + 12           # depth, diffuse direct and colour, 3 crypto passes
    film = sum(a.nbytes for a in session.film.arrays) + session.active.nbytes
    assert memory.estimate(64, 0, 0, pass_bytes_per_pixel=8 * stride).film == film + session.film.passes.nbytes


def test_no_pass_costs_no_film_memory_or_path_buffers():
    from mcengine.session import RenderSession
    plain = RenderSession(_plane_scene())
    assert plain.film.passes.size == 1 and plain.pass_names() == []
    data = RenderSession(_plane_scene(enabled=("Depth", "Normal")))
    # The workers' buffers: (classic integrator, per-path pass buffers, a second shadow ray).
    assert data.film.passes.shape == (64, 4) and data._buffers == (False, False, False)
    light = RenderSession(_plane_scene(enabled=("Diffuse Direct",)))
    assert light.film.passes.shape == (64, 6) and light._buffers == (False, True, False)
    ao = RenderSession(_plane_scene(enabled=("Ambient Occlusion",)))
    assert ao.film.passes.shape == (64, 3) and ao._buffers == (False, False, True)


# -- Cryptomatte ---------------------------------------------------------------------------------
def test_murmur3_matches_known_values():
    # Reference values of MurmurHash3_x86_32 with seed 0 (as in the mmh3 and smhasher tests).
    assert cryptomatte.murmur3_32(b"") == 0
    assert cryptomatte.murmur3_32(b"hello") == 0x248BFA47
    assert cryptomatte.murmur3_32(b"foo") == 0xF6A5C420
    assert cryptomatte.murmur3_32(b"hello, world") == 0x149BBB7F
    assert cryptomatte.murmur3_32(b"The quick brown fox jumps over the lazy dog") == 0x2E4FF723


def test_hash_to_float_keeps_the_exponent_finite():
    for h in (0, 0xFFFFFFFF, 0x7F800000, 0x00000001, 0x80000000):
        f = cryptomatte.hash_to_float(h)
        assert math.isfinite(f) and f != 0.0
    assert cryptomatte.hash_to_float(0x3F800000) == 1.0


def test_cryptomatte_ranks_and_coverage_on_a_split_frame():
    left = grid_plane(4.0, 1, center=(-2.0, 0.0))     # wider than the frame and its filter
    right = grid_plane(4.0, 1, center=(2.0, 0.0))
    geo = Geometry.concatenate([Geometry.from_triangles(left, object_names=["Left"]),
                                Geometry.from_triangles(right, material_index=[1, 1],
                                                        object_names=["Right"])])
    scene = _plane_scene(res=8, samples=64, cryptomatte=("CryptoObject", "CryptoMaterial"),
                         cryptomatte_depth=4)
    scene.geometry = geo
    scene.materials = [Material(name="Red"), Material(name="Blue")]
    scene.film.filter_type, scene.film.filter_width = "BLACKMAN_HARRIS", 1.5
    s = render(scene)
    assert s.pass_names() == ["CryptoObject00", "CryptoObject01", "CryptoMaterial00",
                              "CryptoMaterial01"]
    r0, r1 = s.pass_image("CryptoObject00"), s.pass_image("CryptoObject01")
    coverage = r0[..., 1] + r0[..., 3] + r1[..., 1] + r1[..., 3]
    np.testing.assert_allclose(coverage, 1.0, atol=1e-6)
    assert np.all(r0[..., 1] >= r0[..., 3]) and np.all(r0[..., 3] >= r1[..., 1])
    left_id, right_id = cryptomatte.name_id("Left"), cryptomatte.name_id("Right")
    assert np.all(r0[:, :3, 0] == np.float32(left_id)) and np.all(r0[:, 5:, 0] == np.float32(right_id))
    # Pixels beside the seam see both objects through the pixel filter.
    assert np.all(r0[:, 3:5, 3] > 0.05)
    m0 = s.pass_image("CryptoMaterial00")
    assert np.all(m0[:, 5:, 0] == np.float32(cryptomatte.name_id("Blue")))


def test_cryptomatte_manifest_metadata():
    from mcengine.passes import cryptomatte_metadata
    fields = cryptomatte_metadata(RenderPasses(cryptomatte=("CryptoObject",), view_layer="VL"),
                                  [ObjectPassInfo("Cube", "Rig"), ObjectPassInfo("Cube", "Rig")], [])
    key = f"{cryptomatte.murmur3_32(b'VL.CryptoObject'):08x}"[:7]
    assert fields[f"cryptomatte/{key}/name"] == "VL.CryptoObject"
    assert fields[f"cryptomatte/{key}/hash"] == "MurmurHash3_32"
    assert fields[f"cryptomatte/{key}/conversion"] == "uint32_to_float32"
    assert fields[f"cryptomatte/{key}/manifest"] == (
        '{"Cube":"%08x"}' % cryptomatte.murmur3_32(b"Cube"))


# -- denoising features ------------------------------------------------------------------------
def test_denoising_albedo_and_normal_of_a_diffuse_plane():
    scene = _plane_scene(denoising_data=True)
    s = render(scene)
    np.testing.assert_allclose(s.pass_image("Denoising Albedo"),
                               np.broadcast_to([0.3, 0.5, 0.7], (8, 8, 3)), rtol=1e-6)
    # World +Z seen by a camera looking down -Z: towards the camera, -z in camera space.
    np.testing.assert_allclose(s.pass_image("Denoising Normal"),
                               np.broadcast_to([0, 0, -1], (8, 8, 3)), atol=1e-6)
    np.testing.assert_allclose(s.pass_image("Denoising Depth"), 4.0 - 0.01, rtol=1e-5)


def test_denoising_albedo_is_found_through_a_mirror():
    """A smooth mirror above the plane, seen from below: the albedo is the plane's behind
    the mirror's colour (Cycles multiplies the specular albedo in and waits)."""
    mirror = Geometry.from_triangles(grid_plane(40.0, z=2.0)[:, ::-1], object_names=["Mirror"],
                                     material_index=[1, 1])
    floor = Geometry.from_triangles(grid_plane(40.0, z=-2.0), object_names=["Floor"])
    scene = _plane_scene(denoising_data=True)
    scene.geometry = Geometry.concatenate([floor, mirror])
    scene.materials = [Material(base_color=(0.3, 0.5, 0.7)),
                       Material(name="mirror", mirror_color=(0.5, 0.5, 0.5), base_color=(0, 0, 0))]
    scene.camera.matrix_world = translation(0, 0, 0) @ _rot_x(math.pi)   # looking up at the mirror
    scene.integrator.max_bounces = 2    # (a terminated path writes no features, as in Cycles)
    s = render(scene)
    np.testing.assert_allclose(s.pass_image("Denoising Albedo"),
                               np.broadcast_to([0.15, 0.25, 0.35], (8, 8, 3)), rtol=1e-5)


def test_denoised_image_keeps_alpha_and_needs_no_guides():
    scene = _plane_scene(samples=2)
    scene.denoising = Denoising(enabled=True, input_passes="RGB")
    s = render(scene)
    out = s.denoised()
    assert out.shape == (8, 8, 4) and np.all(out[..., 3] == s.image()[..., 3])
    np.testing.assert_allclose(out[..., :3].mean(), s.image()[..., :3].mean(), rtol=0.05)


def _corner_form_factor(x, y):
    """Form factor from a point to a parallel X x Y rectangle (in units of its height) with
    one corner straight above it."""
    ax, ay = math.sqrt(1.0 + x * x), math.sqrt(1.0 + y * y)
    return (x / ax * math.atan(y / ax) + y / ay * math.atan(x / ay)) / (2.0 * math.pi)


@pytest.mark.parametrize("alpha", [1.0, 0.7])
@pytest.mark.parametrize("distance", [0.9, 10.0])
def test_ambient_occlusion_under_a_square_ceiling(alpha, distance):
    """A floor under a 2 x 2 ceiling at height 1, seen (orthographic, 8 x 8 pixels over 2 cm)
    from between them straight below the ceiling's centre: cosine-weighted AO rays meet
    the ceiling with the probability of its form factor, 4 F(1, 1) = 0.5541 (a uniform
    hemisphere would give 0.216), so the pass is alpha x 0.4459; with an AO distance
    below the height it is alpha.  A floor mixing Transparent at 0.3 has alpha 0.7 (were the
    ceiling so too, 0.3 of the light it blocks would pass: the pass would be 0.428).  The
    independent sampler makes each sample a Bernoulli trial: the bound is 4.4 of its
    standard errors."""
    floor = Geometry.from_triangles(grid_plane(40.0), material_index=np.zeros(2, int),
                                    object_names=["Floor"])
    ceiling = Geometry.from_triangles(grid_plane(2.0, z=1.0), material_index=np.ones(2, int),
                                      object_names=["Ceiling"])
    paint = Material(name="Paint", nodes=[
        ShaderNode("BsdfDiffuse", {"Color": (0.5, 0.5, 0.5)}),
        ShaderNode("BsdfTransparent", {}),
        ShaderNode("MixShader", {"Fac": 1.0 - alpha, "Shader": Link(0, "BSDF"),
                                 "Shader_001": Link(1, "BSDF")})], surface=Link(2, "Shader"))
    res, samples = 8, 256
    scene = SceneDescription(
        geometry=Geometry.concatenate([floor, ceiling]), materials=[paint, Material(name="Opaque")],
        lights=[], camera=Camera(matrix_world=look_down(0.5), type="ORTHO", ortho_scale=0.02,
                                 clip_start=0.01, clip_end=100.0),
        world=World(color=(0.0, 0.0, 0.0)),
        film=Film(width=res, height=res),
        integrator=Integrator(samples=samples, max_bounces=0, sampler="independent"),
        passes=RenderPasses(enabled=("Ambient Occlusion",), ao_distance=distance))
    ao = render(scene).pass_image("Ambient Occlusion").astype(np.float64)
    assert np.all(ao[..., 0] == ao[..., 2])
    if distance < 1.0:
        np.testing.assert_allclose(ao, alpha, rtol=1e-6)
        return
    open_sky = 1.0 - 4.0 * _corner_form_factor(1.0, 1.0)
    n = res * res * samples
    se = alpha * math.sqrt(open_sky * (1.0 - open_sky) / n)
    assert abs(ao.mean() - alpha * open_sky) < 4.4 * se, (ao.mean(), alpha * open_sky, se)
