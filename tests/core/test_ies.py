"""IES light profiles: the file read as Cycles reads it (util/ies.cpp), the table looked up as
Cycles looks it up (kernel/util/ies.h), and lamps lit by them against closed forms.

The parser's cases are small files whose processed tables follow from Cycles' rules by hand
(symmetries mirrored, 90-270 files turned, a 360 column added, types A and B brought to type
C's frame, the multipliers); the lookup's are closed forms of Catmull-Rom interpolation (it
passes through the table's values and reproduces a linear function away from the edges) and
the frame (vertical angle 0 along the lamp's -Z, horizontal 0 along -Y, 90 along -X); the
renders are a Lambert plane under a lamp whose profile is constant around the direction to
the point seen, so that the irradiance is the profile's value times the lamp's without one.
Property tests feed the reader careless files; the lamps' samples, hits and light paths are
checked one by one against the same lamp without a profile times the profile along the light.
"""
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numba import njit

from mcengine.ies import CANDELA_TO_WATTS, IESError, IESProfile, parse_ies
from mcengine.kernels.emission import sample_emission
from mcengine.kernels.ies import ies_direction, ies_lookup
from mcengine.kernels.lights import intersect_lamp, pack_lights, pack_profiles, sample_lamp
from mcengine.scene import Light, SceneDescription

from .expect import Z_LIMIT, assert_mean, image_mean_and_se, render
from .scenes import plane_scene, translation

DEG = math.pi / 180.0


def ies_file(v, h, rows, kind=1, multiplier=1.0, ballast=1.0, tilt="TILT=NONE", sep=" "):
    """An LM-63 file: vertical angles v, horizontal angles h, rows[h][v] candela."""
    lines = ["IESNA:LM-63-2002", "[TEST] mcengine", tilt,
             sep.join(map(str, [1, -1, multiplier, len(v), len(h), kind, 2, 0, 0, 0])),
             sep.join(map(str, [ballast, 1.0, 0])),
             sep.join(map(str, v)), sep.join(map(str, h))]
    lines += [sep.join(map(str, row)) for row in rows]
    return "\n".join(lines) + "\n"


def deg(profile_angles):
    return np.round(np.asarray(profile_angles, np.float64) / DEG, 3).tolist()


# -- reading files ------------------------------------------------------------------------------
def test_one_horizontal_angle_is_round_and_values_are_scaled_to_cycles_units():
    p = parse_ies(ies_file([0, 90, 180], [0], [[100, 50, 0]], multiplier=2.0, ballast=0.5))
    assert deg(p.h_angles) == [0.0, 360.0]
    assert deg(p.v_angles) == [0.0, 90.0, 180.0]
    expected = np.float32(np.array([100, 50, 0]) * CANDELA_TO_WATTS)
    np.testing.assert_allclose(p.intensity, [expected, expected], rtol=1e-7)


def test_commas_and_tilt_include_are_read_as_cycles_reads_them():
    tilt = "TILT=INCLUDE\n1\n3\n0 45 90\n1 0.5 0.2"
    p = parse_ies(ies_file([0, 90], [0], [[7, 3]], tilt=tilt, sep=","))
    assert deg(p.v_angles) == [0.0, 90.0]
    np.testing.assert_allclose(p.intensity[0] / CANDELA_TO_WATTS, [7, 3], rtol=1e-6)


def test_a_quadrant_is_mirrored_to_the_full_circle():
    rows = [[10, 1], [20, 2], [30, 3]]
    p = parse_ies(ies_file([0, 90], [0, 45, 90], rows))
    assert deg(p.h_angles) == [0, 45, 90, 135, 180, 225, 270, 315, 360]
    first = np.round(p.intensity[:, 0] / CANDELA_TO_WATTS, 3).tolist()
    assert first == [10, 20, 30, 20, 10, 20, 30, 20, 10]


def test_a_half_is_mirrored_and_a_90_to_270_file_turned():
    p = parse_ies(ies_file([0, 90], [0, 90, 180], [[1, 0], [2, 0], [3, 0]]))
    assert deg(p.h_angles) == [0, 90, 180, 270, 360]
    assert np.round(p.intensity[:, 0] / CANDELA_TO_WATTS, 3).tolist() == [1, 2, 3, 2, 1]
    q = parse_ies(ies_file([0, 90], [90, 180, 270], [[1, 0], [2, 0], [3, 0]]))
    assert deg(q.h_angles) == [0, 90, 180, 270, 360]      # turned by -90, then mirrored


def test_a_missing_360_column_is_added_when_the_spacing_shows_it():
    p = parse_ies(ies_file([0, 90], [0, 120, 240], [[1, 0], [2, 0], [3, 0]]))
    assert deg(p.h_angles) == [0, 120, 240, 360]
    assert p.intensity[-1, 0] == p.intensity[0, 0]
    q = parse_ies(ies_file([0, 90], [0, 100, 250], [[1, 0], [2, 0], [3, 0]]))
    assert deg(q.h_angles) == [0, 100, 250]              # no regular spacing: left open


def test_type_a_and_b_are_brought_to_type_c():
    a = parse_ies(ies_file([0, 45, 90], [0, 30], [[1, 2, 3], [4, 5, 6]], kind=3))
    assert deg(a.v_angles) == [90, 135, 180]
    assert deg(a.h_angles) == [150, 180, 210]
    assert np.round(a.intensity[:, 0] / CANDELA_TO_WATTS, 3).tolist() == [4, 1, 4]
    b = parse_ies(ies_file([0, 30], [-90, 0, 90], [[1, 2], [3, 4], [5, 6]], kind=2))
    # Transposed: horizontal = the file's vertical angles mirrored about 90, vertical = the
    # file's horizontal shifted by 90.
    assert deg(b.h_angles) == [60, 90, 120]
    assert deg(b.v_angles) == [0, 90, 180]
    assert np.round(b.intensity / CANDELA_TO_WATTS, 3).tolist() == [[2, 4, 6], [1, 3, 5], [2, 4, 6]]


@pytest.mark.parametrize("text,why", [
    ("TILT=NONE\n1 -1 1 1 1 1 2 0 0 0 1 1 0 0 0 5\n", "TILT"),                 # on the first line
    ("IESNA\nTILT=NONE\n1 -1 1 1 1 4 2 0 0 0 1 1 0 0 0 5\n", "photometric type 4"),
    ("IESNA\nTILT=NONE\n1 -1 1 2 2 1 2 0 0 0 1 1 0 0 90 0 90 1 2\n", "ends"),   # values missing
    ("IESNA\nTILT=NONE\n1 -1 1 0 1 1 2 0 0 0 1 1 0\n", "0 vertical"),
    ("IESNA\nlamp without a tilt line\n", "TILT"),
])
def test_files_cycles_cannot_read_are_errors(text, why):
    with pytest.raises(IESError, match=why):
        parse_ies(text)


finite = dict(allow_nan=False, allow_infinity=False)
angles = st.lists(st.floats(-400.0, 400.0, **finite), min_size=1, max_size=7)


@settings(max_examples=300, deadline=None, derandomize=True, database=None)
@given(v=angles, h=angles, kind=st.sampled_from([1, 2, 3]), data=st.data(),
       cut=st.one_of(st.none(), st.integers(0, 400)))
def test_any_file_is_read_or_refused_and_its_lookups_stay_finite(v, h, kind, data, cut):
    """Files as careless exporters write them (angles unsorted, repeated, out of range,
    negative candela, cut off anywhere): the reader gives a profile or an IESError, never
    another exception, and the lookup of a profile is finite and not negative everywhere
    (a repeated angle, where Cycles divides by zero, reads the lower one)."""
    rows = [[data.draw(st.floats(-1e6, 1e6, **finite)) for _ in v] for _ in h]
    text = ies_file(v, h, rows, kind=kind)
    if cut is not None:
        text = text[:cut]
    try:
        p = parse_ies(text)
    except IESError:
        return
    assert p.intensity.shape == (len(p.h_angles), len(p.v_angles))
    packed = p.packed()
    rng = np.random.default_rng(0)
    for a, b in zip(rng.uniform(-1.0, 7.5, 60), rng.uniform(-0.5, 3.7, 60)):
        value = ies_lookup(packed, 0, a, b)
        assert math.isfinite(value) and value >= 0.0
    for a in p.h_angles[:3]:
        for b in p.v_angles[:3]:
            value = ies_lookup(packed, 0, float(a), float(b))
            assert math.isfinite(value) and value >= 0.0


@settings(max_examples=200, deadline=None, derandomize=True, database=None)
@given(st.binary(max_size=300))
def test_any_bytes_are_read_or_refused(blob):
    try:
        parse_ies(b"IESNA\nTILT=NONE\n" + blob)
    except IESError:
        pass


# -- looking up -----------------------------------------------------------------------------------
def _grid(f, h_deg, v_deg):
    h = np.array(h_deg, np.float64) * DEG
    v = np.array(v_deg, np.float64) * DEG
    table = np.array([[f(a, b) for b in v] for a in h], np.float32)
    return IESProfile(np.float32(h), np.float32(v), table)


def test_the_lookup_passes_through_the_table_and_is_linear_where_the_table_is():
    h_deg, v_deg = list(range(0, 361, 30)), list(range(0, 181, 15))
    p = _grid(lambda a, b: 3.0 + 2.0 * a + 5.0 * b, h_deg, v_deg)
    data = p.packed()
    rng = np.random.default_rng(3)
    for _ in range(200):
        # Away from the first and last intervals, where Cycles' Catmull-Rom has no neighbour.
        a = rng.uniform(30, 330) * DEG
        b = rng.uniform(15, 165) * DEG
        assert ies_lookup(data, 0, a, b) == pytest.approx(3.0 + 2.0 * a + 5.0 * b, rel=1e-5)
    for i in (2, 7):
        for j in (3, 9):
            got = ies_lookup(data, 0, float(p.h_angles[i]), float(p.v_angles[j]))
            assert got == pytest.approx(float(p.intensity[i, j]), rel=1e-6)


def test_outside_the_table_is_dark_and_the_value_never_negative():
    # A profile for the lower hemisphere only; a sharp step rings below 0 in Catmull-Rom.
    p = _grid(lambda a, b: 10.0 if b < 40 * DEG else 0.0, range(0, 361, 90), range(0, 91, 10))
    data = p.packed()
    assert ies_direction(data, 0, 0.3, 0.2, 0.5) == 0.0          # above the horizon
    values = [ies_lookup(data, 0, 1.0, b * DEG) for b in np.linspace(0, 89.9, 500)]
    assert min(values) == 0.0 and max(values) > 10.0              # clamped, overshoot kept


@pytest.mark.parametrize("direction,lit", [((-0.1, -0.4, -1.0), True),    # h 14 deg: near -y
                                           ((-0.4, -0.1, -1.0), False),   # h 76 deg: near -x
                                           ((0.3, -0.3, -1.0), False),
                                           ((-0.3, 0.3, -1.0), False),
                                           ((0.3, 0.3, -1.0), False),
                                           ((-0.1, -0.4, 1.0), False)])   # above
def test_the_profile_frame_is_cycles(direction, lit):
    # Lit for horizontal angles 0-40 (from -Y towards -X) and vertical below 60 degrees.
    p = _grid(lambda a, b: 1.0 if a < 50 * DEG and b < 70 * DEG else 0.0,
              range(0, 361, 10), range(0, 181, 10))
    value = ies_direction(p.packed(), 0, *direction)
    assert (value == pytest.approx(1.0, rel=1e-6)) if lit else value == 0.0


def test_packed_wrap_flags_are_cycles_float32_ones():
    p = _grid(lambda a, b: 1.0, range(0, 361, 90), range(0, 181, 90))
    head = p.packed()[:5]
    # 360 and 180 degrees round to exactly 2 pi and pi in float32: no wrap at the top ends.
    assert head.tolist() == [5, 3, 0.0, 1.0, 0.0]


# -- the lamps' sampling and hits -----------------------------------------------------------------
@njit(cache=False)
def _lamp_draws(lamps, ies, px, py, pz, u):
    """Per (u1, u2): the sampled direction, its radiance (red) and that of the ray from p
    along it meeting the lamp (red), from sample_lamp and intersect_lamp."""
    out = np.zeros((u.shape[0], 5))
    for k in range(u.shape[0]):
        wx, wy, wz, dist, lr, lg, lb, pdf = sample_lamp(lamps, ies, 0, px, py, pz, u[k, 0], u[k, 1])
        t, hr, hg, hb, hpdf = intersect_lamp(lamps, ies, 0, px, py, pz, wx, wy, wz, 1e30, px, py, pz)
        out[k, 0], out[k, 1], out[k, 2], out[k, 3], out[k, 4] = wx, wy, wz, lr, hr
    return out


@njit(cache=False)
def _emissions(lamps, ies, u):
    """Per row of u: the direction light tracing leaves the lamp in, and its weight (red)."""
    out = np.zeros((u.shape[0], 4))
    cdf, pmf, cones = np.array([0.0, 1.0]), np.array([1.0]), np.array([2.0])
    for k in range(u.shape[0]):
        em = sample_emission(lamps, ies, cdf, pmf, cones, 0.5, u[k, 0], u[k, 1], u[k, 2], u[k, 3])
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = em.dx, em.dy, em.dz, em.br
    return out


def _profile_along(light, directions):
    """The profile's value for light leaving along each direction (N, 3): the direction taken
    into the lamp's frame by the transpose of its matrix (Cycles' normal transform)."""
    local = directions @ np.asarray(light.matrix_world)[:3, :3]
    data = light.ies.packed()
    return np.array([ies_direction(data, 0, *d) for d in local])


@pytest.mark.parametrize("kind,settings", [("POINT", {"radius": 0.3}),
                                           ("POINT", {"radius": 0.4, "soft_falloff": False}),
                                           ("AREA", {"shape": "DISK", "size_x": 1.5})])
def test_lamp_samples_and_hits_carry_the_profile_along_the_light(kind, settings):
    """A lamp turned and stretched, with an asymmetric profile: each light sample's radiance
    and that of the ray meeting the lamp along it are the lamp's without the profile times
    the profile along -wi, from the sampled point."""
    m = translation(0.3, -0.2, H)
    turn = np.array([[0.8, -0.6, 0.0], [0.6, 0.8, 0.0], [0.0, 0.0, 1.0]])
    m[:3, :3] = turn @ np.diag([1.0, 1.3, 0.9])
    profile = _grid(lambda a, b: (1.0 + math.cos(a) ** 2 + a) * (1.0 + b), range(0, 361, 30),
                    range(0, 181, 10))
    light = Light(type=kind, matrix_world=m, strength=(P, P, P), ies=profile, **settings)
    plain = Light(type=kind, matrix_world=m, strength=(P, P, P), **settings)
    with_table, _ = pack_lights([light], 10.0)
    ies = pack_profiles([light], with_table)
    plain_table, _ = pack_lights([plain], 10.0)
    u = np.random.default_rng(5).random((300, 2))
    p = (0.1, 0.4, 0.0)
    got = _lamp_draws(with_table, ies, *p, u)
    ref = _lamp_draws(plain_table, np.zeros(1), *p, u)
    np.testing.assert_allclose(got[:, :3], ref[:, :3])
    factor = _profile_along(light, -got[:, :3])
    assert np.ptp(factor) > 0.1 * factor.mean()               # the profile varies over the draws
    np.testing.assert_allclose(got[:, 3], ref[:, 3] * factor, rtol=1e-9)
    np.testing.assert_allclose(got[:, 4], ref[:, 4] * factor, rtol=1e-9)


def test_light_tracing_weighs_its_paths_by_the_profile_along_them():
    m = translation(0.0, 0.0, H)
    m[:3, :3] = np.array([[0.8, -0.6, 0.0], [0.6, 0.8, 0.0], [0.0, 0.0, 1.0]])
    profile = _grid(lambda a, b: 1.0 + a + b, range(0, 361, 30), range(0, 181, 10))
    light = Light(type="POINT", matrix_world=m, strength=(P, P, P), radius=0.0, ies=profile)
    with_table, _ = pack_lights([light], 10.0)
    ies = pack_profiles([light], with_table)
    plain_table, _ = pack_lights([Light(type="POINT", matrix_world=m, strength=(P, P, P))], 10.0)
    u = np.random.default_rng(6).random((300, 4))
    got, ref = _emissions(with_table, ies, u), _emissions(plain_table, np.zeros(1), u)
    factor = _profile_along(light, got[:, :3])
    np.testing.assert_allclose(got[:, 3], ref[:, 3] * factor, rtol=1e-9)


# -- lamps ------------------------------------------------------------------------------------------
P = 1000.0
H = 2.0


def _quadrant_profile():
    """1000 cd for horizontal angles 0-110 and vertical 0-70 degrees, 0 elsewhere."""
    v = list(range(0, 181, 10))
    h = list(range(0, 361, 10))
    rows = [[1000.0 if (a <= 110 and b <= 70) else 0.0 for b in v] for a in h]
    return parse_ies(ies_file(v, h, rows))


def _lamp_at(x, y, kind="POINT", turn=0.0, **kw):
    m = translation(x, y, H)
    c, s = math.cos(turn), math.sin(turn)
    m[:2, :2] = [[c, -s], [s, c]]
    return Light(type=kind, matrix_world=m, strength=(P, P, P), ies=_quadrant_profile(), **kw)


def _point_irradiance(x, y, value):
    d2 = x * x + y * y + H * H
    return P * value / (4 * math.pi * d2) * (H / math.sqrt(d2))


@pytest.mark.parametrize("turn_deg,lit", [(0, True), (60, True), (90, False), (180, False)])
def test_a_point_lamp_shines_by_its_profile_and_turns_with_the_lamp(turn_deg, lit):
    # The lamp is at (+1, +1.2, H): the plane's origin lies along -x, -y and down (h 40 deg,
    # v 38 deg), inside the profile's lit region; a turn of the lamp by t about Z moves the
    # direction to h 40 + t in the lamp's frame: lit at 100, dark at 130 and 220 (and at
    # 340 for a lamp turned the other way round).
    turn = math.radians(turn_deg)
    li = _lamp_at(1.0, 1.2, turn=turn, radius=0.0)
    s = render(plane_scene(li))
    expected = _point_irradiance(1.0, 1.2, 1000.0 * CANDELA_TO_WATTS) / math.pi
    if lit:
        assert_mean(s, expected, deterministic_tol=1e-4)
    else:
        assert s.image()[..., :3].max() == 0.0


def test_a_spot_with_a_profile_multiplies_both():
    li = _lamp_at(0.5, 0.6, kind="SPOT", radius=0.0, spot_size=math.radians(90), spot_blend=0.0)
    s = render(plane_scene(li))
    expected = _point_irradiance(0.5, 0.6, 1000.0 * CANDELA_TO_WATTS) / math.pi
    assert_mean(s, expected, deterministic_tol=1e-4)


def test_a_disk_lamp_reads_the_profile_from_its_sampled_points():
    # A soft-falloff point lamp of radius 0.3: from every point of its disk the plane's origin
    # lies inside the lit region, so the image is the profile's value times the image of the
    # same lamp without a profile (two renders: within their combined standard error).
    li = _lamp_at(1.0, 1.2, radius=0.3)
    plain = Light(type="POINT", matrix_world=li.matrix_world, strength=li.strength, radius=0.3)
    value = 1000.0 * CANDELA_TO_WATTS
    m1, se1 = image_mean_and_se(render(plane_scene(li, samples=256)))
    m2, se2 = image_mean_and_se(render(plane_scene(plain, samples=256)))
    assert se2 < 0.002 * m2
    assert abs(m1 / value - m2) <= Z_LIMIT * math.hypot(se1 / value, se2)


def test_the_effects_plan_names_the_profiled_lamps():
    scene = plane_scene(_lamp_at(1.0, 1.2, radius=0.0))
    scene.lights.append(Light(type="SPOT", matrix_world=translation(0, 0, H)))
    from mcengine.session import RenderSession
    line = RenderSession(scene, threads=1).plan.summary()
    assert line.startswith("Lights: 1 point, 1 spot (1 with an IES profile); "), line


def test_a_profile_survives_saving_the_scene(tmp_path):
    li = _lamp_at(1.0, 1.2, radius=0.0)
    scene = plane_scene(li)
    scene.save(tmp_path / "scene.npz")
    loaded = SceneDescription.load(tmp_path / "scene.npz").lights[0].ies
    np.testing.assert_array_equal(loaded.intensity, li.ies.intensity)
    np.testing.assert_array_equal(loaded.h_angles, li.ies.h_angles)
