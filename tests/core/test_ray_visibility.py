"""Objects' Ray Visibility (Object > Visibility > Ray Visibility), against closed forms.

Cycles' BVH skips an object whose visibility shares no bit with the ray's: camera rays
(also after transparent surfaces), diffuse, glossy or transmission rays by the lobe that
made them, shadow rays; an emissive object lights only the lobes whose rays see it, and is
no light at all when no diffuse, glossy, transmission or volume ray does.  The scenes: an
orthographic camera looking straight down at a white Lambert plane (object "Floor") that
fills the frame; above it a second plane (object "Cover") with a visibility under test.
Against Cycles, with every switch and an instanced cover: ``blend_scenes/ray_visibility``.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from mcengine.kernels.intersect import Accel
from mcengine.kernels.state import (
    VIS_ALL,
    VIS_CAMERA,
    VIS_DIFFUSE,
    VIS_GLOSSY,
    VIS_SCATTER,
    VIS_SHADOW,
    VIS_TRANSMISSION,
)
from mcengine.packing import pack_scene
from mcengine.scene import (
    Geometry,
    Light,
    Link,
    Material,
    SceneDescription,
    SceneError,
    ShaderNode,
    World,
)

from .expect import assert_mean, render
from .scenes import grid_plane, plane_scene, rotation_x

SUN = 3.0                      # W/m^2, straight down
COVER_HEIGHT = 1.0
COVER_HALF = 100.0             # the cover's half-size: it hides the whole frame
EMISSION = 2.0                 # the emissive cover's radiance


def _scene(cover: Material, visibility: int, *, sun: bool = True, samples: int = 64):
    """Floor at z = 0 under the cover at z = COVER_HEIGHT (whose rays see it: visibility)."""
    scene = plane_scene(Light(type="SUN", strength=(SUN,) * 3, matrix_world=np.eye(4), angle=0.0),
                        samples=samples, res=8, bounces=4)
    if not sun:
        scene.lights = []
    floor = grid_plane(200.0)
    top = grid_plane(2.0 * COVER_HALF, z=COVER_HEIGHT)[:, ::-1]       # facing down
    scene.geometry = Geometry.from_triangles(np.concatenate([floor, top]),
                                             material_index=[0, 0, 1, 1],
                                             object_index=[0, 0, 1, 1],
                                             object_names=["Floor", "Cover"])
    scene.geometry.object_visibility = np.array([VIS_ALL, visibility], np.uint8)
    scene.materials = [Material(base_color=(1.0,) * 3), cover]
    return scene


BLACK = Material(base_color=(0.0,) * 3)


def _emitter() -> Material:
    return Material(nodes=[ShaderNode("Emission", {"Color": (1.0,) * 3, "Strength": EMISSION})],
                    surface=Link(0, "Emission"))


def _view_factor(half: float, height: float) -> float:
    """Share of a Lambert point's irradiance that a parallel square of half-size ``half``
    centred ``height`` above it gives (four corner rectangles of the classic formula)."""
    a = half / height
    s = math.sqrt(1.0 + a * a)
    return 4.0 / (2.0 * math.pi) * 2.0 * (a / s) * math.atan(a / s)


def test_a_cover_hidden_from_the_camera_still_casts_its_shadow():
    """Seen by every ray the black cover is what the camera sees (0); hidden from camera
    rays the camera sees the floor, in the cover's shadow (0); hidden from camera and shadow
    rays the floor in full sun: S / pi."""
    lit = SUN / math.pi
    assert render(_scene(BLACK, VIS_ALL)).image()[..., 0].max() == 0.0
    assert render(_scene(BLACK, VIS_ALL & ~VIS_CAMERA)).image()[..., 0].max() == 0.0
    assert_mean(render(_scene(BLACK, VIS_ALL & ~(VIS_CAMERA | VIS_SHADOW))), lit)


def test_camera_rays_stay_camera_rays_through_transparent_surfaces():
    """A Transparent BSDF sheet above a black cover hidden from camera and shadow rays: the
    camera ray that passed the sheet still does not see the cover (Cycles keeps
    PATH_RAY_CAMERA on transparent bounces) but the floor in full sun, S / pi (0 if it saw
    the cover)."""
    scene = _scene(BLACK, VIS_ALL & ~(VIS_CAMERA | VIS_SHADOW))
    g = scene.geometry
    scene.geometry = Geometry.from_triangles(
        np.concatenate([g.vertices[g.triangles].astype(float), grid_plane(200.0, z=2.0)]),
        material_index=[0, 0, 1, 1, 2, 2], object_index=[0, 0, 1, 1, 2, 2],
        object_names=["Floor", "Cover", "Sheet"])
    scene.geometry.object_visibility = np.array([VIS_ALL, g.object_visibility[1], VIS_ALL], np.uint8)
    scene.materials.append(Material(nodes=[ShaderNode("BsdfTransparent", {"Color": (1.0,) * 3})],
                                    surface=Link(0, "BSDF")))
    assert_mean(render(scene), SUN / math.pi)


@pytest.mark.parametrize("visibility, expected", [
    (VIS_ALL & ~VIS_CAMERA, 1.0),                                  # lights the floor
    (VIS_ALL & ~(VIS_CAMERA | VIS_DIFFUSE), 0.0),                 # not the diffuse floor
    (VIS_CAMERA | VIS_DIFFUSE, 1.0),                               # diffuse rays are enough
])
def test_an_emissive_cover_lights_only_the_lobes_whose_rays_see_it(visibility, expected):
    """The floor under a camera-hidden emissive cover (no sun) receives pi L F (its view
    factor F) when diffuse rays see the cover, and nothing when they do not: next-event
    estimation leaves out the lobes the emitter is hidden from (Cycles' SHADER_EXCLUDE_*
    of a mesh light), as the rays pass through it."""
    scene = _scene(_emitter(), visibility & ~VIS_CAMERA, sun=False, samples=128)
    s = render(scene)
    if expected == 0.0:
        assert s.image()[..., :3].max() == 0.0
    else:
        assert_mean(s, EMISSION * _view_factor(COVER_HALF, COVER_HEIGHT))


def test_an_emitter_no_scattering_ray_sees_is_no_light():
    """Hidden from diffuse, glossy, transmission and volume rays, an emissive object leaves
    the light list (Cycles' Object::usable_as_light); volume rays alone keep it there."""
    hidden = VIS_CAMERA | VIS_SHADOW
    sc = pack_scene(_scene(_emitter(), hidden, sun=False))[0]
    assert len(sc.emit_tri) == 0
    sc = pack_scene(_scene(_emitter(), hidden | VIS_SCATTER, sun=False))[0]
    assert len(sc.emit_tri) == 2


def test_rays_pass_through_what_their_mask_does_not_see():
    """The BVH with masks: three stacked quads of different visibility, hit from above by
    rays of each kind; triangle ids come back in the caller's numbering whatever the order
    Embree groups them in."""
    quads = [grid_plane(2.0, z=z) for z in (3.0, 2.0, 1.0)]
    g = Geometry.from_triangles(np.concatenate(quads))
    tris_vis = np.repeat([VIS_GLOSSY | VIS_SHADOW, VIS_CAMERA, VIS_ALL], 2).astype(np.uint32)
    accel = Accel(g.vertices, g.triangles, visibility=tris_vis)
    assert accel.masked
    n = 4
    o = np.tile(np.array([[0.1, 0.2, 10.0]], np.float32), (n, 1))
    d = np.tile(np.array([[0.0, 0.0, -1.0]], np.float32), (n, 1))
    t = np.full(n, 1e30, np.float32)
    masks = np.array([VIS_CAMERA, VIS_DIFFUSE, VIS_GLOSSY, VIS_TRANSMISSION], np.uint32)
    prim = accel.closest(o, d, t, mask=masks)
    assert list(prim // 2) == [1, 2, 0, 2]
    assert list(accel.closest(o, d, t) // 2) == [0, 0, 0, 0]              # no mask: all seen
    t_short = np.full(n, 8.5, np.float32)                                  # ends above z = 1.5
    assert list(accel.occluded(o, d, t_short, mask=VIS_SHADOW)) == [True] * n
    assert list(accel.occluded(o, d, np.full(n, 7.5, np.float32), mask=VIS_DIFFUSE)) == [False] * n


def test_the_visibility_is_saved_and_checked(tmp_path):
    scene = _scene(BLACK, VIS_CAMERA | VIS_DIFFUSE)
    path = tmp_path / "s.npz"
    scene.save(path)
    assert list(SceneDescription.load(path).geometry.object_visibility) == [VIS_ALL, VIS_CAMERA | VIS_DIFFUSE]
    scene.geometry.object_visibility = np.array([VIS_ALL, 64], np.uint8)
    with pytest.raises(SceneError, match="object_visibility"):
        scene.validate()


def test_the_classic_integrators_say_they_do_not_honour_it():
    import dataclasses

    from mcengine.session import RenderSession

    scene = _scene(BLACK, VIS_ALL & ~VIS_CAMERA)
    scene.integrator = dataclasses.replace(scene.integrator, name="whitted")
    assert any("Ray Visibility" in w for w in RenderSession(scene).warnings)
    scene = _scene(BLACK, VIS_ALL)
    scene.integrator = dataclasses.replace(scene.integrator, name="whitted")
    assert not any("Ray Visibility" in w for w in RenderSession(scene).warnings)


def test_a_sun_tilted_past_a_hidden_cover_lights_what_it_would_shadow():
    """Sanity of the shadow mask with an oblique sun (30 deg): S cos / pi under a cover that
    shadow rays do not see."""
    tilt = math.radians(30.0)
    scene = _scene(BLACK, VIS_ALL & ~(VIS_CAMERA | VIS_SHADOW))
    scene.lights = [Light(type="SUN", strength=(SUN,) * 3, matrix_world=rotation_x(tilt), angle=0.0)]
    assert_mean(render(scene), SUN * math.cos(tilt) / math.pi)


@pytest.mark.parametrize("visibility, expected", [
    (VIS_ALL & ~VIS_CAMERA, 0.0),                     # unseen, but it shadows the floor
    (VIS_ALL & ~(VIS_CAMERA | VIS_SHADOW), 1.0),      # neither seen nor shadowing
])
def test_a_moving_cover_keeps_its_visibility(visibility, expected):
    """The cover sliding 1 m during the shutter (its triangles in the motion BVH, not
    Embree's): camera rays pass it, shadow rays pass it only when its Shadow is off."""
    from mcengine.scene import MotionBlur, ObjectMotion

    scene = _scene(BLACK, visibility, samples=16)
    shift = np.eye(4)
    shift[0, 3] = 1.0
    scene.motion_blur = MotionBlur(objects=[ObjectMotion(object=1, vertices=(6, 6),
                                                         matrices=np.stack([np.eye(4), np.eye(4), shift]))])
    s = render(scene)
    if expected == 0.0:
        assert s.image()[..., :3].max() == 0.0
    else:
        assert_mean(s, SUN / math.pi)


# -- the world's Ray Visibility (World > Settings > Ray Visibility) ----------------------------
WORLD = 0.5


def _world_lit(material: Material, varying: bool = False, **visibility):
    """The floor of ``material`` under a constant world W alone (no lamp, no cover), or a
    world that varies (a Gradient texture along x as its colour: sampled by next-event
    estimation from its importance map, which a constant world is not)."""
    scene = plane_scene(Light(), samples=64, res=8, bounces=4, world=(WORLD,) * 3)
    scene.lights = []
    scene.materials = [material]
    if varying:
        scene.world = World(nodes=[ShaderNode("TexGradient"),
                                   ShaderNode("Background", {"Color": Link(0, "Color")})],
                            surface=Link(1, "Background"))
    for ray, on in visibility.items():
        setattr(scene.world, f"visible_{ray}", on)
    return scene


MIRROR = Material(nodes=[ShaderNode("BsdfGlossy", {"Color": (1.0,) * 3, "Roughness": 0.0})],
                  surface=Link(0, "BSDF"))


@pytest.mark.parametrize("material, visibility, expected", [
    (Material(base_color=(1.0,) * 3), {}, WORLD),                       # Lambert: W
    (Material(base_color=(1.0,) * 3), {"diffuse": False}, 0.0),
    (Material(base_color=(1.0,) * 3), {"glossy": False, "transmission": False}, WORLD),
    (MIRROR, {}, WORLD),                                                 # a mirror shows W
    (MIRROR, {"glossy": False}, 0.0),
    (MIRROR, {"diffuse": False}, WORLD),
])
def test_the_world_lights_only_the_lobes_whose_rays_see_it(material, visibility, expected):
    """A white Lambert floor or a white mirror under a constant world: W, or nothing when
    the world is hidden from the rays of its lobe (its light samples leave that lobe out,
    the lobe's rays that escape find nothing)."""
    s = render(_world_lit(material, **visibility))
    if expected == 0.0:
        assert s.image()[..., :3].max() == 0.0
    else:
        assert_mean(s, expected)


@pytest.mark.parametrize("hidden", ["diffuse", "glossy"])
def test_a_world_sampled_as_a_light_lights_only_the_lobes_whose_rays_see_it(hidden):
    """A varying world, which next-event estimation samples: the Lambert floor gets nothing
    when the world is hidden from diffuse rays (its light samples leave the diffuse lobe
    out), and its light otherwise."""
    s = render(_world_lit(Material(base_color=(1.0,) * 3), varying=True, **{hidden: False}))
    if hidden == "diffuse":
        assert s.image()[..., :3].max() == 0.0
    else:
        assert s.image()[..., :3].min() > 0.05
