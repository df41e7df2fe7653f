"""Every light type against closed-form irradiance, in Cycles' units.

The receiver is a white Lambert plane (albedo 1) seen from above by an
orthographic camera covering 2 cm around the origin; its radiance is E / pi.
Expected values are derived from the light's definition (cycles-conventions.md
section 1) and, where the reference quotes a Cycles measurement, match it.
"""
import math

import numpy as np
import pytest

from mcengine.scene import Geometry, Light, Link, Material, ShaderNode

from .expect import assert_mean, render
from .scenes import grid_plane, plane_scene, rotation_x, translation

P = 1000.0   # watts
H = 2.0      # light height above the plane


def lambert(irradiance):
    return irradiance / math.pi


def test_point_light_radius_zero_is_inverse_square():
    li = Light(type="POINT", matrix_world=translation(0, 0, H), strength=(P, P, P), radius=0.0)
    s = render(plane_scene(li))
    # Cycles measured 6.33159 for this set-up; closed form P/(4 pi^2 d^2) = 6.33257.
    assert_mean(s, lambert(P / (4 * math.pi * H * H)))


def test_point_light_sphere_has_inverse_square_irradiance():
    # A uniform sphere light gives E = P / (4 pi d^2) outside it, whatever its radius.
    li = Light(type="POINT", matrix_world=translation(0, 0, H), strength=(P, P, P), radius=1.0,
               soft_falloff=False)
    s = render(plane_scene(li, samples=256))
    assert_mean(s, lambert(P / (4 * math.pi * H * H)))


def test_point_light_soft_falloff_is_a_facing_disk():
    li = Light(type="POINT", matrix_world=translation(0, 0, H), strength=(P, P, P), radius=1.0,
               soft_falloff=True)
    s = render(plane_scene(li, samples=256))
    assert_mean(s, lambert(P / (4 * math.pi * (H * H + 1.0))))   # Cycles: 5.06606


def test_point_light_seen_directly_has_sphere_radiance():
    # Camera looking up at a visible sphere light: radiance P / (4 pi^2 r^2).
    r = 0.5
    li = Light(type="POINT", matrix_world=translation(0, 0, 10), strength=(P, P, P), radius=r,
               soft_falloff=False, visible_camera=True)
    scene = plane_scene(li, samples=4)
    scene.geometry = Geometry()
    scene.camera.matrix_world = rotation_x(math.pi)   # looks up +Z
    scene.camera.ortho_scale = 0.1
    s = render(scene)
    assert_mean(s, P / (4 * math.pi ** 2 * r * r))        # Cycles: 101.3212


@pytest.mark.parametrize("size,blend,angle_deg", [(math.radians(60), 0.0, 20.0),
                                                  (math.radians(60), 0.0, 40.0),
                                                  (math.radians(90), 0.5, 35.0)])
def test_spot_light_cone_and_blend(size, blend, angle_deg):
    # The receiver point sits at angle a off the spot axis (the spot points down).
    a = math.radians(angle_deg)
    x = H * math.tan(a)
    li = Light(type="SPOT", matrix_world=translation(-x, 0, H), strength=(P, P, P), radius=0.0,
               spot_size=size, spot_blend=blend)
    s = render(plane_scene(li, size=0.002))
    c = math.cos(size / 2)
    t = (math.cos(a) - c) / ((1 - c) * blend) if blend > 0 else (1.0 if math.cos(a) > c else 0.0)
    att = min(max(t, 0.0), 1.0)
    att = att * att * (3 - 2 * att) if blend > 0 else att
    d2 = H * H + x * x
    expected = lambert(P / (4 * math.pi * d2) * (H / math.sqrt(d2)) * att)
    if expected == 0.0:
        assert s.image()[..., :3].max() == 0.0
    else:
        assert_mean(s, expected, deterministic_tol=1e-3)


def test_spot_light_on_axis_equals_point_light():
    li = Light(type="SPOT", matrix_world=translation(0, 0, H), strength=(P, P, P), radius=0.0,
               spot_size=math.radians(30), spot_blend=0.2)
    assert_mean(render(plane_scene(li)), lambert(P / (4 * math.pi * H * H)))


@pytest.mark.parametrize("angle_deg", [0.0, 10.0])
@pytest.mark.parametrize("tilt_deg", [0.0, 60.0])
def test_sun_irradiance_is_strength_times_cosine(angle_deg, tilt_deg):
    S = 3.0
    li = Light(type="SUN", matrix_world=rotation_x(math.radians(tilt_deg)), strength=(S, S, S),
               angle=math.radians(angle_deg))
    s = render(plane_scene(li, samples=256))
    # Cycles: 0.95493 = 3/pi at angle 0 and 10 deg; 0.47746 tilted 60 deg.
    assert_mean(s, lambert(S * math.cos(math.radians(tilt_deg))))


def _area_irradiance(size_x, size_y, ellipse, power, normalize=True, n=1500):
    """On-axis irradiance at distance H from a downward area light, by midpoint quadrature."""
    u = (np.arange(n) + 0.5) / n - 0.5
    x, y = np.meshgrid(u * size_x, u * size_y)
    inside = (4 * x * x / size_x ** 2 + 4 * y * y / size_y ** 2 <= 1.0) if ellipse else np.ones_like(x, bool)
    area = size_x * size_y * (math.pi / 4 if ellipse else 1.0)
    L = power / (math.pi * (area if normalize else 1.0))
    d2 = x * x + y * y + H * H
    dA = size_x * size_y / n / n
    return float(np.sum(inside * L * (H * H) / (d2 * d2)) * dA)


@pytest.mark.parametrize("shape,sx,sy,cycles", [("SQUARE", 1.0, 1.0, 2.33887),
                                                ("RECTANGLE", 2.0, 0.5, 2.16661),
                                                ("DISK", 1.0, 1.0, 2.38409),
                                                ("ELLIPSE", 2.0, 0.5, 2.24817)])
def test_area_light_shapes(shape, sx, sy, cycles):
    li = Light(type="AREA", matrix_world=translation(0, 0, H), strength=(100.0,) * 3, shape=shape,
               size_x=sx, size_y=sy)
    expected = lambert(_area_irradiance(sx, sy, shape in ("DISK", "ELLIPSE"), 100.0))
    assert expected == pytest.approx(cycles, rel=2e-4)   # the reference's Cycles measurement
    assert_mean(render(plane_scene(li, samples=256)), expected)


def test_area_light_is_one_sided():
    # Pointing up (rotated 180 deg about X), the light sends nothing down.
    li = Light(type="AREA", matrix_world=translation(0, 0, H) @ rotation_x(math.pi),
               strength=(100.0,) * 3, size_x=1.0)
    s = render(plane_scene(li))
    assert s.image()[..., :3].max() == 0.0


def test_area_light_object_scale_and_normalize():
    m = translation(0, 0, H) @ np.diag([2.0, 0.5, 1.0, 1.0])
    li = Light(type="AREA", matrix_world=m, strength=(100.0,) * 3, shape="SQUARE", size_x=1.0)
    assert_mean(render(plane_scene(li, samples=256)), lambert(_area_irradiance(2.0, 0.5, False, 100.0)))
    li = Light(type="AREA", matrix_world=translation(0, 0, H), strength=(100.0,) * 3,
               shape="SQUARE", size_x=2.0, normalize=False)
    assert_mean(render(plane_scene(li, samples=256)),
                lambert(_area_irradiance(2.0, 2.0, False, 100.0, normalize=False)))


def test_area_light_spread_keeps_flux():
    # Narrow spread (30 deg): on axis the radiance is boosted by tan(s/2)/(tan(s/2) - s/2).
    s_half = math.radians(15)
    li = Light(type="AREA", matrix_world=translation(0, 0, H), strength=(100.0,) * 3,
               shape="DISK", size_x=0.05, spread=2 * s_half)
    n = 400
    r = (np.arange(n) + 0.5) / n * 0.025
    theta = np.arctan(r / H)
    factor = np.maximum(math.tan(s_half) - np.tan(theta), 0) / (math.tan(s_half) - s_half)
    L = 100.0 / (math.pi * math.pi * 0.025 ** 2)
    E = float(np.sum(L * factor * H * H / (r * r + H * H) ** 2 * 2 * math.pi * r) * (0.025 / n))
    # A 2 mm receiver patch: the spread factor changes fast across the plane.
    assert_mean(render(plane_scene(li, samples=256, size=0.002)), lambert(E))


@pytest.mark.parametrize("facing", ["down", "up"])
def test_emissive_mesh_is_two_sided(facing):
    # A 1 m emissive square 2 m above the plane, emission colour x strength = 5.
    quad = grid_plane(1.0, z=H)
    if facing == "down":
        quad = quad[:, ::-1]
    # The camera hangs between the plane and the emitter, looking down.
    scene = plane_scene(Light(strength=(0.0,) * 3), samples=64, cam_height=1.0)
    geo = Geometry.concatenate([
        scene.geometry,
        Geometry.from_triangles(quad, material_index=np.ones(len(quad), np.int32))])
    scene.geometry = geo
    scene.lights = []
    scene.materials = [Material(base_color=(1, 1, 1)), Material(base_color=(0, 0, 0), emission=(5, 5, 5))]
    # Same quadrature as an area light of radiance 5 (power 5 * pi * A).
    expected = lambert(_area_irradiance(1.0, 1.0, False, 5.0 * math.pi))
    assert_mean(render(scene), expected)


def test_world_colour_lights_a_plane():
    scene = plane_scene(Light(strength=(0.0,) * 3), world=(0.2, 0.4, 0.6), samples=16, albedo=0.5)
    scene.lights = []
    s = render(scene)
    for c, w in enumerate((0.2, 0.4, 0.6)):
        # Under a uniform sky of radiance w, E = pi w; every cosine-sampled BSDF
        # ray escapes, so each sample is exactly 0.5 w (up to float32 rounding).
        assert_mean(s, 0.5 * w, channel=c, deterministic_tol=1e-6)


def _tilted_panel():
    a = math.radians(35)
    rot = np.array([[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]])
    quad = np.array([[-1, -0.4, 0], [1, -0.4, 0], [1, 0.4, 0], [-1, 0.4, 0]]) @ rot.T + [0.3, 1.3, 1.8]
    return quad, np.array([[quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]])


def _panel_irradiance(quad, p, n=800):
    """Irradiance at floor point p from a two-sided quad of radiance 1 (midpoint rule)."""
    u = (np.arange(n) + 0.5) / n
    uu, vv = np.meshgrid(u, u)
    q = quad[0] + uu[..., None] * (quad[1] - quad[0]) + vv[..., None] * (quad[3] - quad[0])
    nq = np.cross(quad[1] - quad[0], quad[3] - quad[0])
    area = np.linalg.norm(nq)
    d = q - p
    r2 = (d * d).sum(-1)
    cos_r = np.maximum(d[..., 2], 0) / np.sqrt(r2)
    cos_l = np.abs(d @ (nq / area)) / np.sqrt(r2)
    return float((cos_r * cos_l / r2).sum() * area / n / n)


@pytest.mark.parametrize("receiver", [(-0.5, -1.0), (-1.5, 0.0), (0.3, 3.0)])
def test_emissive_panel_seen_at_grazing_angles(receiver):
    """A tilted emissive quad lighting floor points from its back side, nearly edge-on.

    At (-0.5, -1.0) the floor point lies 0.15 m behind the panel's plane, so
    every shadow ray meets the panel at a grazing angle: a shadow ray shifted
    off the floor but still aimed along the unshifted direction hits the
    panel's plane before its end and the light is lost.
    """
    quad, tris = _tilted_panel()
    x, y = receiver
    scene = plane_scene(Light(strength=(0.0,) * 3), samples=1024, size=0.002, cam_height=0.5)
    scene.camera.matrix_world = translation(x, y, 0.5)
    scene.lights = []
    scene.geometry = Geometry.concatenate([
        Geometry.from_triangles(grid_plane(40.0)),
        Geometry.from_triangles(tris, material_index=np.ones(2, np.int32))])
    scene.materials = [Material(base_color=(1, 1, 1)), Material(base_color=(0, 0, 0), emission=(1, 1, 1))]
    expected = lambert(_panel_irradiance(quad, np.array([x, y, 0.0])))
    assert_mean(render(scene), expected, max_rel_se=0.003)


def test_lights_picked_per_point_add_up_to_the_sum_of_each_light():
    """Several lights at once: next-event estimation picks one per sample by its
    estimated irradiance at the point (a spot aimed away is almost never picked,
    an area light facing away never).  The mean must still be the sum of every
    light's irradiance: picking changes noise only."""
    P1, P2, Pa = 1000.0, 500.0, 100.0
    lights = [
        Light(type="POINT", matrix_world=translation(0, 0, H), strength=(P1,) * 3),
        Light(type="POINT", matrix_world=translation(3.0, 0, 1.0), strength=(P2,) * 3),
        Light(type="SPOT", matrix_world=translation(0, 0, 3.0) @ rotation_x(math.pi),
              strength=(5000.0,) * 3, spot_size=math.radians(40)),          # points up
        Light(type="AREA", matrix_world=translation(0, 0, H), strength=(Pa,) * 3, size_x=1.0),
        Light(type="AREA", matrix_world=translation(0, 0, 1.0) @ rotation_x(math.pi),
              strength=(800.0,) * 3, size_x=1.0),                          # faces up
    ]
    scene = plane_scene(lights[0], samples=512, size=0.002)
    scene.lights = lights
    d2 = 3.0 ** 2 + 1.0
    E = (P1 / (4 * math.pi * H * H) + P2 / (4 * math.pi * d2) * (1.0 / math.sqrt(d2))
         + _area_irradiance(1.0, 1.0, False, Pa))
    s = render(scene)
    from mcengine.kernels.state import CFG_LOCAL_LIGHTS
    assert s.cfg[CFG_LOCAL_LIGHTS] == 1      # this scene picks lights per point
    assert_mean(s, lambert(E), max_rel_se=0.003)


@pytest.mark.parametrize("shape,spread_deg", [("RECTANGLE", 20.0), ("ELLIPSE", 20.0),
                                              ("RECTANGLE", 140.0)])
def test_spread_sampling_window_is_unbiased(shape, spread_deg):
    """A 2 x 1.2 m light with spread, 2 m above a receiver off its centre.

    At 20 deg only a window of the light (a circle of radius 2 tan 10 deg
    around the receiver's foot point) can reach the receiver, and the light
    sampler draws from that window alone; at 140 deg the window is the whole
    light.  The mean must equal the integral over the whole light of the
    spread-attenuated radiance."""
    sx, sy, s_half = 2.0, 1.2, math.radians(spread_deg / 2)
    rx, ry = 0.5, 0.3
    li = Light(type="AREA", matrix_world=translation(0, 0, H), strength=(100.0,) * 3, shape=shape,
               size_x=sx, size_y=sy, spread=2 * s_half)
    scene = plane_scene(li, samples=2048, size=0.002)
    scene.camera.matrix_world = translation(rx, ry, 5.0)
    n = 1200
    u = (np.arange(n) + 0.5) / n - 0.5
    x, y = np.meshgrid(u * sx, u * sy)
    inside = (4 * x * x / sx ** 2 + 4 * y * y / sy ** 2 <= 1.0) if shape == "ELLIPSE" else np.ones_like(x, bool)
    area = sx * sy * (math.pi / 4 if shape == "ELLIPSE" else 1.0)
    d2 = (x - rx) ** 2 + (y - ry) ** 2 + H * H
    tan_t = np.sqrt((x - rx) ** 2 + (y - ry) ** 2) / H
    factor = np.maximum(math.tan(s_half) - tan_t, 0) / (math.tan(s_half) - s_half)
    E = float(np.sum(inside * factor * 100.0 / (math.pi * area) * H * H / (d2 * d2)) * sx * sy / n / n)
    assert_mean(render(scene), lambert(E), max_rel_se=0.004)


# -- lights of vanishing size: the extended and the delta form must agree -------------------------
SIZES = [1.0, 1e-3, 1e-6, 3e-8, 1e-8, 2e-9, 1e-12, 1e-30, 1e-200, 0.0]


@pytest.mark.parametrize("angle", SIZES)
def test_sun_of_any_angle_gives_strength_times_cosine(angle):
    """Down to an angle of 0 (a delta direction) a sun gives E = S cos(theta).

    Angles below ~2e-8 rad once made cos(angle/2) round to 1, so the sampler
    treated the sun as a delta direction while its radiance was still divided
    by pi sin^2(angle/2): images 1e16 times too bright."""
    S, tilt = 3.0, math.radians(30.0)
    li = Light(type="SUN", matrix_world=rotation_x(tilt), strength=(S, S, S), angle=angle)
    assert_mean(render(plane_scene(li, samples=16 if angle < 1e-3 else 256)),
                lambert(S * math.cos(tilt)))


@pytest.mark.parametrize("radius", SIZES)
@pytest.mark.parametrize("soft_falloff", [False, True])
def test_point_light_of_any_radius_is_exact(radius, soft_falloff):
    """A point lamp of radius r: sphere E = P/(4 pi d^2); facing disk P/(4 pi (d^2 + r^2)).

    A sphere of radius <= 1e-8 m once gave no light at all (its cone pdf
    divided by 1 - cos = 0)."""
    li = Light(type="POINT", matrix_world=translation(0, 0, H), strength=(P, P, P), radius=radius,
               soft_falloff=soft_falloff)
    d2 = H * H + (radius * radius if soft_falloff else 0.0)
    assert_mean(render(plane_scene(li, samples=16 if radius < 1e-3 else 256)),
                lambert(P / (4 * math.pi * d2)))


def test_negative_lamps_remove_light_as_in_cycles():
    """Cycles renders a lamp of negative strength as negative light (measured with bpy
    5.0.1: a 1000 W and a -500 W point lamp together give half the 1000 W image, a
    -1000 W lamp alone its negative).  Lights are picked by |strength|, so the two
    lamps' samples are +-1.5 times the mean: the bound is looser than usual, and a
    dropped or sign-flipped lamp is still 200 % off."""
    E = P / (4 * math.pi * H * H)
    scene = plane_scene(Light(type="POINT", matrix_world=translation(0, 0, H),
                              strength=(-P,) * 3), samples=4096)
    assert_mean(render(scene), lambert(-E))
    scene.lights.append(Light(type="POINT", matrix_world=translation(0, 0, H),
                              strength=(2 * P,) * 3))
    assert_mean(render(scene), lambert(E), max_rel_se=0.01)


def _relative_pixel_sd(session):
    """Mean over pixels of each pixel's standard deviation of one sample, over its mean."""
    img = session.image()[..., 0].astype(np.float64)
    var = session.variance()[..., 0].astype(np.float64) * session.pass_samples
    return float(np.mean(np.sqrt(var) / img))


def test_lights_behind_an_opaque_surface_are_never_picked():
    """Cycles' light-tree facing term: a light wholly behind the surface (a strong point
    lamp under the plane, a sun shining from below) lights nothing there, and next-event
    estimation never picks it, so the noise is that of the lamp above alone.  Without the
    term the lamp below, 20 times the estimated irradiance, would take ~95 % of the samples
    and the noise would be several times larger.  The mean stays the lamp above's."""
    above = Light(type="POINT", matrix_world=translation(0, 0, H), strength=(P,) * 3, radius=0.5)
    below = [Light(type="POINT", matrix_world=translation(0.3, 0, -1.0), strength=(20 * P,) * 3),
             Light(type="SUN", matrix_world=rotation_x(math.pi), strength=(3.0,) * 3,
                   angle=math.radians(10))]
    alone = plane_scene(above, samples=256, size=0.5)
    both = plane_scene(above, samples=256, size=0.5)
    both.lights = [above] + below
    s_alone, s_both = render(alone), render(both)
    from mcengine.kernels.state import CFG_LOCAL_LIGHTS
    assert s_both.cfg[CFG_LOCAL_LIGHTS] == 1
    assert_mean(s_both, float(s_alone.image()[..., 0].mean()), max_rel_se=0.01)
    ratio = _relative_pixel_sd(s_both) / _relative_pixel_sd(s_alone)
    assert ratio < 1.15, f"noise {ratio:.2f} times that of the lamp above alone"


def test_a_translucent_surface_picks_lights_on_both_sides():
    """A surface that transmits (Cycles' SD_BSDF_HAS_TRANSMISSION) has no facing term: a
    Translucent plane lit by a point lamp below it glows on top with that lamp's irradiance
    x colour / pi (a point lamp is never hit by a ray: were it left out of the picking, the
    plane would stay black); a lamp above adds nothing to its transmitted light."""
    lamp_below = Light(type="POINT", matrix_world=translation(0, 0, -H), strength=(P,) * 3)
    lamp_above = Light(type="POINT", matrix_world=translation(0, 0, H), strength=(P,) * 3)
    scene = plane_scene(lamp_below, samples=512)
    scene.lights = [lamp_below, lamp_above]
    scene.materials = [Material(name="translucent",
                                nodes=[ShaderNode("BsdfTranslucent", {"Color": (0.5, 0.5, 0.5)})],
                                surface=Link(0, "BSDF"))]
    s = render(scene)
    assert_mean(s, 0.5 * lambert(P / (4 * math.pi * H * H)), max_rel_se=0.01)


def test_lights_are_picked_by_the_normal_a_displacement_bump_set():
    """Cycles picks lights by the facing term of sd->N, the normal after the material's
    Displacement (rendered as bump) has moved it.  A white plane whose Displacement is a
    ramp (height tan 60 deg x y) shades with N' = (0, -sin 60, cos 60); a sun from straight
    above and a sun 2 deg above the horizon on the -y side light it with cosines 0.5 and
    0.883 about N'.  Picked by N' the two suns' importances are their contributions, so
    every sample is the mean; picked by the plane's interpolated normal the low sun would
    get 3 % of the samples for 64 % of the light (a relative noise of about 3)."""
    slope = math.tan(math.radians(60.0))
    suns = [Light(type="SUN", matrix_world=rotation_x(t), strength=(1.0,) * 3, angle=0.0)
            for t in (0.0, math.radians(88.0))]
    scene = plane_scene(suns[0], samples=64)
    scene.lights = suns
    scene.materials = [Material(
        name="ramp",
        nodes=[ShaderNode("NewGeometry"), ShaderNode("SeparateXYZ", {"Vector": Link(0, "Position")}),
               ShaderNode("Displacement", {"Height": Link(1, "Y"), "Midlevel": 0.0, "Scale": slope}),
               ShaderNode("BsdfDiffuse", {"Color": (1.0, 1.0, 1.0)})],
        surface=Link(3, "BSDF"), displacement=Link(2, "Displacement"), displacement_method="BUMP")]
    s = render(scene)
    tilt = math.radians(60.0)
    cos_high = math.cos(tilt)
    cos_low = math.sin(tilt) * math.sin(math.radians(88.0)) + math.cos(tilt) * math.cos(math.radians(88.0))
    assert_mean(s, lambert(cos_high + cos_low), max_rel_se=0.01)
    assert _relative_pixel_sd(s) < 1e-3
