"""Holdout objects (Object > Visibility > Holdout), against closed forms.

A camera ray that reaches a holdout object clears the film there by the object's opacity
(1 - its transparency) and keeps only its transparent closure, without emission (Cycles'
surface_shader_apply_holdout); rays that are not camera rays (or that left the camera
path through an opaque bounce) see the object as it is (against Cycles, with shadows and a
mirror: ``blend_scenes/holdout_objects``).  The scenes here: an orthographic camera looking
straight down at a plane that fills the frame, lit only by a grey world W.
"""
from __future__ import annotations

import pytest

from mcengine.scene import Geometry, Light, Link, Material, ObjectPassInfo, ShaderNode

from .expect import render
from .scenes import grid_plane, plane_scene

WORLD = 0.4


def _scene(material: Material, holdout: bool, film_transparent: bool = False):
    """The plane (one object, ``holdout`` or not) under the world W alone."""
    scene = plane_scene(Light(), samples=64, res=8, bounces=4, world=(WORLD,) * 3)
    scene.lights = []
    scene.geometry = Geometry.from_triangles(grid_plane(200.0))
    scene.geometry.object_names = ["Plane"]
    scene.geometry.object_passes = [ObjectPassInfo("Plane", "Plane", holdout=holdout)]
    scene.materials = [material]
    scene.film.transparent = film_transparent
    return scene


def _half_transparent_emitter() -> Material:
    """Mix 0.5 of an emission of 3 (two-sided) and a white Transparent BSDF."""
    return Material(nodes=[ShaderNode("Emission", {"Color": (1.0, 1.0, 1.0), "Strength": 3.0}),
                           ShaderNode("BsdfTransparent", {"Color": (1.0, 1.0, 1.0)}),
                           ShaderNode("MixShader", {"Fac": 0.5, "Shader": Link(0, "Emission"),
                                                    "Shader_001": Link(1, "BSDF")})],
                    surface=Link(2, "Shader"))


def _mean_rgba(session):
    image = session.image()
    return image[..., :3].mean(), image[..., 3].mean()


def test_an_opaque_holdout_object_is_cleared_film():
    """Opaque: alpha 0 and no colour, whatever it emits or reflects."""
    emitter = Material(nodes=[ShaderNode("Emission", {"Color": (1.0, 0.5, 0.2), "Strength": 5.0})],
                       surface=Link(0, "Emission"))
    rgb, alpha = _mean_rgba(render(_scene(emitter, holdout=True)))
    assert rgb == 0.0 and alpha == 0.0
    rgb, alpha = _mean_rgba(render(_scene(emitter, holdout=False)))       # the same, not held out
    assert alpha == pytest.approx(1.0) and rgb > 1.0


def test_a_half_transparent_holdout_object_keeps_only_what_is_seen_through_it():
    """Transparency 0.5: alpha 0.5 (the held-out half), its emission gone, the world seen
    through the transparent half: RGB 0.5 W.  With a transparent film the world adds to the
    transparency too: alpha 0, RGB 0.  Not held out: 0.5 x 3 + 0.5 W, alpha 1."""
    rgb, alpha = _mean_rgba(render(_scene(_half_transparent_emitter(), holdout=True)))
    assert alpha == pytest.approx(0.5, abs=1e-6) and rgb == pytest.approx(0.5 * WORLD, rel=1e-6)
    rgb, alpha = _mean_rgba(render(_scene(_half_transparent_emitter(), holdout=True,
                                          film_transparent=True)))
    assert alpha == pytest.approx(0.0, abs=1e-6) and rgb == pytest.approx(0.0, abs=1e-6)
    rgb, alpha = _mean_rgba(render(_scene(_half_transparent_emitter(), holdout=False)))
    assert alpha == pytest.approx(1.0, abs=1e-6) and rgb == pytest.approx(1.5 + 0.5 * WORLD, rel=1e-6)


@pytest.mark.parametrize("name", ["raycast", "whitted", "distribution"])
def test_the_classic_integrators_say_they_do_not_render_holdouts(name):
    """They shade a holdout as an ordinary surface; the session's warnings say so (for a
    holdout object and for a Holdout shader), and say nothing without either."""
    import dataclasses

    from mcengine.session import RenderSession

    emitter = Material(nodes=[ShaderNode("Emission", {"Color": (1.0, 1.0, 1.0), "Strength": 1.0})],
                       surface=Link(0, "Emission"))
    shader = Material(nodes=[ShaderNode("Holdout")], surface=Link(0, "Holdout"))
    for material, holdout, warned in ((emitter, True, True), (shader, False, True),
                                      (emitter, False, False)):
        scene = _scene(material, holdout=holdout)
        scene.integrator = dataclasses.replace(scene.integrator, name=name, depth=2)
        notes = [w for w in RenderSession(scene).warnings if "holdout" in w]
        assert bool(notes) == warned, (name, holdout, notes)
    scene = _scene(shader, holdout=True)
    assert not [w for w in RenderSession(scene).warnings if "holdout" in w]    # path tracing
