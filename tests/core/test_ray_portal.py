"""The Ray Portal BSDF in light transport, against closed forms.

Cycles (integrate_surface_ray_portal, shade_shadow.h): a picked portal closure moves the ray
to its Position and sends it along its Direction, with weight Color x (sum of sample
weights) / its own; the pass is a transparent bounce that keeps the path's flags (a camera
ray stays one: a transparent film counts the world it then finds), and shadow rays stop at
portals.  The scenes: an orthographic camera looking straight down at a plane that fills
the frame, under a grey world W and no lamps unless said.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from mcengine.scene import Geometry, Light, Link, Material, ShaderNode

from .expect import assert_mean, render
from .scenes import grid_plane, plane_scene, rotation_x

WORLD = 0.4
COLOR = (0.5, 0.25, 1.0)


def _portal(position, direction, color=COLOR) -> ShaderNode:
    return ShaderNode("BsdfRayPortal", {"Color": color, "Position": position, "Direction": direction})


def _scene(material: Material, samples=16, film_transparent=False):
    scene = plane_scene(Light(), samples=samples, res=8, bounces=4, world=(WORLD,) * 3)
    scene.lights = []
    scene.materials = [material]
    scene.film.transparent = film_transparent
    return scene


def _rgba(session):
    image = session.image()
    return image[..., :3].mean(axis=(0, 1)), image[..., 3].mean()


def test_a_portal_sends_camera_rays_on_from_its_point_in_its_direction():
    """Up from z = 10: the world, times the Color; to the film a camera ray still, so a
    transparent film clears it by the throughput it carries."""
    material = Material(nodes=[_portal((0.0, 0.0, 10.0), (0.0, 0.0, 1.0))], surface=Link(0, "BSDF"))
    rgb, alpha = _rgba(render(_scene(material)))
    np.testing.assert_allclose(rgb, np.array(COLOR) * WORLD, rtol=1e-6)
    assert alpha == pytest.approx(1.0)
    rgb, alpha = _rgba(render(_scene(material, film_transparent=True)))
    np.testing.assert_allclose(rgb, 0.0, atol=1e-7)
    assert alpha == pytest.approx(1.0 - np.mean(COLOR), abs=1e-6)


def test_a_portal_back_into_itself_ends_at_the_transparent_bounce_limit():
    """From z = 2 straight down onto the plane again, which also emits 1: every pass is a
    transparent bounce, and the one that reaches Transparent Max Bounces (8) ends the path at
    the next surface, after its emission (Cycles' PATH_RAY_TERMINATE_ON_NEXT_SURFACE).  So
    the emission is collected 9 times, the k-th times Color^k: (1 - c^9) / (1 - c), 9 where
    c = 1; without the limit the blue channel would count every pass the kernel allows."""
    material = Material(nodes=[_portal((0.0, 0.0, 2.0), (0.0, 0.0, -1.0)),
                               ShaderNode("Emission", {"Color": (1.0, 1.0, 1.0), "Strength": 1.0}),
                               ShaderNode("AddShader", {"Shader": Link(0, "BSDF"),
                                                        "Shader_001": Link(1, "Emission")})],
                        surface=Link(2, "Shader"))
    scene = _scene(material)
    assert scene.integrator.transparent_max_bounces == 8
    rgb, _ = _rgba(render(scene))
    expected = [sum(c ** k for k in range(9)) for c in COLOR]
    np.testing.assert_allclose(rgb, expected, rtol=1e-6)


def test_a_portal_mixed_with_a_diffuse_surface_keeps_the_estimate_unbiased():
    """Mix 0.5 of white Lambert (under the world's upper half: W) and a white portal up to
    the world (W): W, whichever closure each sample picks and however the light samples
    weigh the diffuse part against the portal's share of the sample weights."""
    material = Material(nodes=[ShaderNode("BsdfDiffuse", {"Color": (1.0, 1.0, 1.0)}),
                               _portal((0.0, 0.0, 1.0), (0.0, 0.0, 1.0), (1.0, 1.0, 1.0)),
                               ShaderNode("MixShader", {"Fac": 0.5, "Shader": Link(0, "BSDF"),
                                                        "Shader_001": Link(1, "BSDF")})],
                        surface=Link(2, "Shader"))
    assert_mean(render(_scene(material, samples=1024)), WORLD, max_rel_se=0.003)


def _floor_under_sheet(kind, samples):
    """A white Lambert floor at z = 0 seen through a white sheet at z = 1 of BSDF ``kind``,
    which lets camera rays straight on."""
    scene = _scene(Material(base_color=(1.0, 1.0, 1.0)), samples=samples)
    floor, sheet = grid_plane(200.0), grid_plane(200.0, z=1.0)
    scene.geometry = Geometry.from_triangles(np.concatenate([floor, sheet]),
                                             material_index=[0] * len(floor) + [1] * len(sheet),
                                             object_index=[0] * len(floor) + [1] * len(sheet),
                                             object_names=["Floor", "Sheet"])
    node = ShaderNode(kind, {"Color": (1.0, 1.0, 1.0)})
    scene.materials = [Material(base_color=(1.0, 1.0, 1.0)), Material(nodes=[node], surface=Link(0, "BSDF"))]
    return scene


@pytest.mark.parametrize("kind,expected", [("BsdfRayPortal", 0.0), ("BsdfTransparent", 0.5 / math.pi)])
def test_portals_stop_shadow_rays(kind, expected):
    """The floor under a sun of 0.5 W/m^2 from straight above and a black world: a portal
    sheet casts a full shadow (Cycles does not let shadow rays through portals), a
    Transparent BSDF none (E / pi)."""
    scene = _floor_under_sheet(kind, samples=64)
    scene.world.color = (0.0, 0.0, 0.0)
    scene.lights = [Light(type="SUN", matrix_world=rotation_x(0.0), strength=(0.5,) * 3)]
    rgb, _ = _rgba(render(scene))
    np.testing.assert_allclose(rgb, expected, rtol=1e-5, atol=1e-9)


@pytest.mark.parametrize("kind", ["BsdfRayPortal", "BsdfTransparent"])
def test_light_found_through_a_portal_has_full_weight(kind):
    """The floor under the world W alone: W either way.  Through a portal no light sample
    reaches the world, so the floor's BSDF rays must count it without MIS weights (with
    them it would come out darker); through a Transparent BSDF both kinds of sample do."""
    assert_mean(render(_floor_under_sheet(kind, samples=1024)), WORLD, max_rel_se=0.003)


@pytest.mark.parametrize("name", ["raycast", "whitted", "distribution"])
def test_the_classic_integrators_say_they_do_not_follow_portals(name):
    from mcengine.session import RenderSession

    material = Material(nodes=[_portal((0.0, 0.0, 10.0), (0.0, 0.0, 1.0))], surface=Link(0, "BSDF"))
    scene = _scene(material)
    assert not [w for w in RenderSession(scene).warnings if "Ray Portal" in w]   # path tracing
    scene.integrator = dataclasses.replace(scene.integrator, name=name, depth=2)
    assert [w for w in RenderSession(scene).warnings if "Ray Portal" in w]


@pytest.mark.parametrize("kind", ["BsdfRayPortal", "BsdfTransparent"])
def test_data_passes_look_through_portals(kind):
    """Cycles writes the data passes at the first surface at least as opaque as the view
    layer's alpha threshold, counting a portal as transparent: the Depth pass of the floor
    seen through the sheet is the floor's, 5 m (the sheet's would be 4)."""
    from mcengine.passes import RenderPasses
    from mcengine.session import RenderSession

    scene = _floor_under_sheet(kind, samples=4)
    scene.passes = RenderPasses(enabled=("Depth",))
    session = RenderSession(scene)
    session.run()
    np.testing.assert_allclose(session.pass_image("Depth"), 5.0, rtol=1e-6)
