"""Light linking (Object > Shading > Light Linking), against closed forms.

Cycles lights a receiver with an emitter only if the emitter's light-set mask holds the
receiver's light set: next-event estimation at a point of object R skips emitters that do
not light R's set, and a ray that left R counts only the lamps and emission of such emitters
(the receiver is the object the ray last scattered on, not a transparent surface it
passed); camera rays see every emitter (kernel/light/light.h, integrator/shade_surface.h).
The scenes: an orthographic camera looking straight down at a white Lambert floor (object
"Floor", receiver set 1) that fills the frame, lit by a sun, an area lamp or an emissive
cover above it (object "Cover", hidden from camera rays).  Against Cycles:
``blend_scenes/light_linking``.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from mcengine.kernels.lights import LIGHT_SETS_ALL
from mcengine.kernels.state import VIS_ALL, VIS_CAMERA, VIS_SHADOW
from mcengine.scene import Geometry, Light, Link, Material, SceneError, ShaderNode

from .expect import assert_mean, render
from .scenes import grid_plane, plane_scene

SUN = 3.0                      # W/m^2, straight down
FLOOR_SET = 1                  # the floor's light set
ONLY_FLOOR = 1 << FLOOR_SET
ALL_BUT_FLOOR = LIGHT_SETS_ALL & ~ONLY_FLOOR
COVER_HEIGHT = 1.0
COVER_HALF = 100.0
EMISSION = 2.0


def _emitter() -> Material:
    return Material(nodes=[ShaderNode("Emission", {"Color": (1.0,) * 3, "Strength": EMISSION})],
                    surface=Link(0, "Emission"))


def _view_factor(half: float, height: float) -> float:
    """Share of a Lambert point's irradiance that a parallel square of half-size ``half``
    centred ``height`` above it gives."""
    a = half / height
    s = math.sqrt(1.0 + a * a)
    return 4.0 / (2.0 * math.pi) * 2.0 * (a / s) * math.atan(a / s)


def _scene(light=None, *, cover=None, cover_sets=LIGHT_SETS_ALL, sheet=False, samples=64):
    """The floor (receiver set FLOOR_SET) with ``light``, optionally under an emissive cover
    lighting ``cover_sets`` and with a Transparent BSDF sheet (light set 2) between them."""
    scene = plane_scene(light or Light(type="SUN", strength=(SUN,) * 3, angle=0.0),
                        samples=samples, res=8, bounces=4)
    if light is None:
        scene.lights = []
    planes = [grid_plane(200.0)]
    names, materials = ["Floor"], [Material(base_color=(1.0,) * 3)]
    if sheet:
        planes.append(grid_plane(200.0, z=0.5))
        names.append("Sheet")
        materials.append(Material(nodes=[ShaderNode("BsdfTransparent", {"Color": (1.0,) * 3})],
                                  surface=Link(0, "BSDF")))
    if cover is not None:
        planes.append(grid_plane(2.0 * COVER_HALF, z=COVER_HEIGHT)[:, ::-1])     # facing down
        names.append("Cover")
        materials.append(cover)
    k = len(planes)
    scene.geometry = Geometry.from_triangles(np.concatenate(planes),
                                             material_index=np.repeat(np.arange(k), 2),
                                             object_index=np.repeat(np.arange(k), 2),
                                             object_names=names)
    scene.materials = materials
    g = scene.geometry
    g.object_receiver_set = np.array([FLOOR_SET, 2, 3][:k], np.uint8)
    g.object_light_sets = np.full(k, LIGHT_SETS_ALL, np.uint64)
    g.object_visibility = np.full(k, VIS_ALL, np.uint8)
    if cover is not None:
        g.object_light_sets[-1] = cover_sets
        g.object_visibility[-1] = VIS_ALL & ~(VIS_CAMERA | VIS_SHADOW)
    return scene


@pytest.mark.parametrize("angle", [0.0, math.radians(10.0)], ids=["delta", "10deg"])
@pytest.mark.parametrize("sets, expected", [(ONLY_FLOOR, 1.0), (ALL_BUT_FLOOR, 0.0),
                                            (LIGHT_SETS_ALL, 1.0)],
                         ids=["floor-only", "all-but-floor", "all"])
def test_a_sun_lights_only_its_light_sets(sets, expected, angle):
    """A sun (a delta one: next-event estimation only; one with an angle: also found by the
    floor's rays, MIS) lights the floor with S / pi when its light sets hold the floor's,
    and not at all when they do not."""
    s = render(_scene(Light(type="SUN", strength=(SUN,) * 3, angle=angle, light_sets=sets)))
    if expected == 0.0:
        assert s.image()[..., :3].max() == 0.0
    else:
        assert_mean(s, SUN / math.pi)


@pytest.mark.parametrize("sets, expected", [(ONLY_FLOOR, 1.0), (ALL_BUT_FLOOR, 0.0)],
                         ids=["floor-only", "all-but-floor"])
def test_an_area_lamp_lights_only_its_light_sets(sets, expected):
    """A large area lamp facing down above the floor: its light reaches the floor through
    both light samples and the rays that hit it (MIS), or, unlinked, through neither."""
    matrix = np.eye(4)
    matrix[2, 3] = COVER_HEIGHT
    lamp = Light(type="AREA", size_x=2 * COVER_HALF, size_y=2 * COVER_HALF, strength=(1.0,) * 3,
                 normalize=False, matrix_world=matrix, light_sets=sets)
    s = render(_scene(lamp, samples=512))
    if expected == 0.0:
        assert s.image()[..., :3].max() == 0.0
    else:
        assert_mean(s, (1.0 / math.pi) * _view_factor(COVER_HALF, COVER_HEIGHT))


@pytest.mark.parametrize("sets, expected", [(ONLY_FLOOR, 1.0), (ALL_BUT_FLOOR, 0.0)],
                         ids=["floor-only", "all-but-floor"])
def test_an_emissive_object_lights_only_its_light_sets(sets, expected):
    """An emissive cover lights the floor with L F when it links to the floor, and not at
    all otherwise: neither its light samples nor the floor's rays that hit it count."""
    s = render(_scene(cover=_emitter(), cover_sets=sets, samples=128))
    if expected == 0.0:
        assert s.image()[..., :3].max() == 0.0
    else:
        assert_mean(s, EMISSION * _view_factor(COVER_HALF, COVER_HEIGHT))


def test_the_receiver_is_the_last_scattering_surface_not_a_transparent_one():
    """Between floor and cover a Transparent sheet of another light set: the floor's rays
    that pass it and hit the cover still count for the floor (the receiver is the object
    they left, Cycles' mis_ray_object), so the floor gets the whole L F (its light samples
    alone, weighted by MIS, would give less)."""
    scene = _scene(cover=_emitter(), cover_sets=ONLY_FLOOR, sheet=True, samples=128)
    scene.geometry.object_visibility[1] = VIS_ALL & ~VIS_CAMERA
    assert_mean(render(scene), EMISSION * _view_factor(COVER_HALF, COVER_HEIGHT))


def test_camera_rays_see_every_emitter():
    """An emissive floor that lights no light set at all is still seen by the camera (L)."""
    scene = _scene()
    scene.materials[0] = _emitter()
    scene.geometry.object_light_sets[0] = 0
    assert_mean(render(scene, threads=1), EMISSION)


def test_the_plan_names_it_only_where_a_light_is_linked():
    from mcengine.packing import pack_scene

    linked = pack_scene(_scene(Light(type="SUN", strength=(SUN,) * 3, light_sets=ONLY_FLOOR)))
    plain = pack_scene(_scene(Light(type="SUN", strength=(SUN,) * 3)))
    assert linked.plan.light_linking and "light linking" in linked.plan.summary()
    assert not plain.plan.light_linking


def test_the_links_are_saved_and_checked(tmp_path):
    from mcengine.scene import SceneDescription

    scene = _scene(Light(type="SUN", strength=(SUN,) * 3, light_sets=ONLY_FLOOR),
                   cover=_emitter(), cover_sets=ALL_BUT_FLOOR)
    scene.save(tmp_path / "s.npz")
    back = SceneDescription.load(tmp_path / "s.npz")
    assert back.lights[0].light_sets == ONLY_FLOOR
    assert back.geometry.light_sets().tolist() == [LIGHT_SETS_ALL, ALL_BUT_FLOOR]
    assert back.geometry.receiver_sets().tolist() == [FLOOR_SET, 2]
    scene.geometry.object_receiver_set = np.array([FLOOR_SET, 64], np.uint8)
    with pytest.raises(SceneError, match="object_receiver_set"):
        scene.validate()
    scene.geometry.object_receiver_set = None
    scene.lights[0].light_sets = -1
    with pytest.raises(SceneError, match="light_sets"):
        scene.validate()


def test_the_classic_integrators_say_they_do_not_honour_it():
    import dataclasses

    from mcengine.session import RenderSession

    scene = _scene(Light(type="SUN", strength=(SUN,) * 3, light_sets=ONLY_FLOOR))
    scene.integrator = dataclasses.replace(scene.integrator, name="whitted")
    assert any("light linking" in w for w in RenderSession(scene).warnings)


def test_a_linked_lamp_leaves_its_caustics_to_path_tracing():
    """Path + Light Tracing with a point lamp over a floor before a mirror, the lamp linked
    to the floor alone: its light reaches the mirror first on the caustic path, so there is
    no caustic (light tracing, which does not test links, leaves the lamp to path tracing):
    the floor's direct light alone."""
    from .test_light_tracing import assert_mean as assert_seeds_mean
    from .test_light_tracing import mirror_closed_form, mirror_scene, renders

    scene = mirror_scene()
    scene.geometry.object_receiver_set = np.array([FLOOR_SET, 0], np.uint8)
    scene.lights[0].light_sets = ONLY_FLOOR
    images, session = renders(scene, "light")
    assert session.light_tables is None
    direct, _ = mirror_closed_form()
    assert_seeds_mean(images, float(direct.mean()))


def test_light_set_masks_are_exact_in_the_float_tables():
    """Every bit of a 64-bit mask survives the kernels' float table (two 32-bit halves),
    whether the masks come as Python integers of any size mix or as a uint64 array."""
    from mcengine.kernels.lights import in_light_sets, light_set_columns

    masks = [LIGHT_SETS_ALL, 1 << 63, (1 << 32) | (1 << 31) | 1, 0, 0xDEADBEEFCAFEF00D]
    for table in (light_set_columns(masks), light_set_columns(np.array(masks, np.uint64))):
        for row, mask in enumerate(masks):
            assert [bool(in_light_sets(table, row, 0, s)) for s in range(64)] == \
                [bool(mask >> s & 1) for s in range(64)]
