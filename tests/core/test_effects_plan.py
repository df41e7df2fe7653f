"""The effects plan: what it decides for a scene, and that the work it skips was not needed.

Each scene below is rendered with its plan and again with every effect the plan
left off forced on, one at a time and all together, from the same seed: the
images must be identical bit for bit.  An effect the plan wrongly leaves off
(light that the scene has and the plan skips) makes the forced render differ, so
this is the test that the plan never drops something a scene calls for.  Scenes:
a point light of radius 0 over a floor (nothing can be hit, nothing to weigh),
glass and a mirror under an area light with a grey world (caustic paths), an
emissive quad behind a half-transparent card (transparent shadows, emission as the
only light), a world alone, and a camera-visible area lamp with MIS off (Cycles
tests no lamp at all then, so forcing lamp hits on must not show it).
"""
import numpy as np
import pytest

from mcengine.features import EFFECTS
from mcengine.scene import (
    Camera,
    Film,
    Geometry,
    Integrator,
    Light,
    Link,
    Material,
    SceneDescription,
    ShaderNode,
    World,
)
from mcengine.session import RenderSession

from .scenes import grid_plane, rotation_x, translation, uv_sphere


def _camera():
    m = translation(0.0, -4.0, 2.5)
    c, s = np.cos(np.radians(60.0)), np.sin(np.radians(60.0))
    m[1:3, 1:3] = [[c, -s], [s, c]]
    return Camera(matrix_world=m, lens=35.0)


def _scene(materials, parts, lights, world=(0.0, 0.0, 0.0), bounces=6):
    geometry = Geometry.concatenate([Geometry.from_triangles(t, material_index=[m] * len(t),
                                                             normals=n)
                                     for t, m, n in parts])
    return SceneDescription(geometry=geometry, materials=materials, lights=lights,
                            camera=_camera(), world=World(color=world),
                            film=Film(width=24, height=16),
                            integrator=Integrator(samples=3, seed=5, max_bounces=bounces,
                                                  diffuse_bounces=bounces, glossy_bounces=bounces,
                                                  transmission_bounces=bounces))


def _floor(material=0):
    return (grid_plane(12.0), material, None)


def point_over_floor():
    return _scene([Material(base_color=(0.7, 0.6, 0.5))], [_floor()],
                  [Light(type="POINT", matrix_world=translation(0.5, 0.0, 2.0),
                         strength=(300.0,) * 3, radius=0.0)])


def glass_and_mirror():
    tris, normals = uv_sphere(0.6, 24, 12, center=(0.0, 0.0, 0.7))
    mirror = np.array([[[-1, 1.5, 0], [1, 1.5, 0], [1, 1.5, 1.5]],
                       [[-1, 1.5, 0], [1, 1.5, 1.5], [-1, 1.5, 1.5]]], float)
    return _scene([Material(base_color=(0.6, 0.6, 0.6)), Material(glass_color=(1.0, 1.0, 1.0), ior=1.45),
                   Material(mirror_color=(0.9, 0.9, 0.9))],
                  [_floor(), (tris, 1, normals), (mirror, 2, None)],
                  [Light(type="AREA", matrix_world=translation(0.0, 0.0, 3.0), strength=(150.0,) * 3,
                         size_x=1.5, size_y=1.5)], world=(0.1, 0.1, 0.1))


def emission_through_a_card():
    glow = np.array([[[-0.5, 0.5, 1.2], [0.5, 0.5, 1.2], [0.5, 0.5, 2.0]],
                     [[-0.5, 0.5, 1.2], [0.5, 0.5, 2.0], [-0.5, 0.5, 2.0]]])
    card = np.array([[[-0.6, 0.0, 0.2], [0.6, 0.0, 0.2], [0.6, 0.0, 1.0]],
                     [[-0.6, 0.0, 0.2], [0.6, 0.0, 1.0], [-0.6, 0.0, 1.0]]])
    leaf = Material(name="leaf", nodes=[ShaderNode("BsdfDiffuse", {"Color": (0.2, 0.5, 0.1)}),
                                        ShaderNode("BsdfTransparent", {"Color": (0.7, 0.9, 0.5)}),
                                        ShaderNode("MixShader", {"Fac": 0.5, "Shader": Link(0, "BSDF"),
                                                                 "Shader_001": Link(1, "BSDF")})],
                    surface=Link(2, "Shader"))
    return _scene([Material(base_color=(0.7, 0.7, 0.7)), Material(base_color=(0, 0, 0), emission=(8.0, 6.0, 4.0)),
                   leaf], [_floor(), (glow, 1, None), (card, 2, None)], [])


def world_only():
    tris, normals = uv_sphere(0.6, 24, 12, center=(0.0, 0.0, 0.6))
    return _scene([Material(base_color=(0.6, 0.6, 0.6)), Material(base_color=(0.8, 0.3, 0.2))],
                  [_floor(), (tris, 1, normals)], [], world=(0.3, 0.4, 0.6))


def visible_lamp_without_mis():
    return _scene([Material(base_color=(0.7, 0.7, 0.7))], [_floor()],
                  [Light(type="AREA", matrix_world=translation(0.0, 1.0, 1.0) @ rotation_x(-np.pi / 2),
                         strength=(80.0,) * 3, size_x=0.8, size_y=0.8, use_mis=False,
                         visible_camera=True)])     # faces the camera


SCENES = {f.__name__: f for f in (point_over_floor, glass_and_mirror, emission_through_a_card,
                                  world_only, visible_lamp_without_mis)}

EXPECTED_ON = {
    "point_over_floor": {"nee"},
    "glass_and_mirror": {"nee", "lamps_hit", "mis", "world", "caustics"},
    "emission_through_a_card": {"nee", "mis", "transparent_shadows"},
    "world_only": {"world"},
    "visible_lamp_without_mis": {"nee"},
}


def _render(scene, force=()):
    return RenderSession(scene, threads=1, force_effects=force).run()


@pytest.mark.parametrize("name", SCENES)
def test_plan_calls_for_what_the_scene_has(name):
    plan = RenderSession(SCENES[name](), threads=1).plan
    assert set(plan.effects_on()) == EXPECTED_ON[name], plan.summary()
    assert plan.forced == ()


@pytest.mark.parametrize("name", SCENES)
def test_forcing_on_an_effect_the_scene_lacks_changes_no_bit(name):
    scene = SCENES[name]()
    plan = _render(scene)
    reference = plan.image()
    assert np.isfinite(reference).all() and reference[..., :3].max() > 0.0
    off = [e for e in EFFECTS if e not in plan.plan.effects_on()]
    assert off, "every effect is on: nothing to force"
    for effect in off + ["all"]:
        forced = _render(scene, () if effect == "all" else (effect,))
        assert effect == "all" or forced.plan.forced == (effect,)
        assert np.array_equal(forced.image(), reference), f"forcing {effect} changed the image"


def test_an_effect_the_scene_needs_is_not_free():
    """The flags do gate work: the same scene with its world switched off by hand renders
    darker, so a plan that skipped a needed effect would be caught above."""
    scene = world_only()
    session = RenderSession(scene, threads=1)
    full = session.run().image()
    session = RenderSession(scene, threads=1)
    session.cfg[EFFECTS["world"][1]] = 0
    assert session.run().image()[..., :3].mean() < 0.5 * full[..., :3].mean()


def test_summary_lists_simulated_and_skipped_effects():
    line = RenderSession(glass_and_mirror(), threads=1, force_effects=("transparent_shadows",)).plan.summary()
    lights, on, off = line.split(" | ")
    assert lights.startswith("Lights: 1 area, world; surfaces: diffuse, sharp glossy, sharp glass")
    assert "transparent shadows (forced)" in on and "caustic paths" in on
    assert off == "skipped: subsurface walks, light linking"   # no subsurface, no links


def test_unknown_effect_is_refused():
    with pytest.raises(ValueError, match="unknown effect 'fog'"):
        RenderSession(point_over_floor(), threads=1, force_effects=("fog",))
