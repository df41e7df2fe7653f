"""Materials against Cycles' own numbers: the same small set-ups rendered by both.

Each oracle of ``material_oracles.py`` (a material on a plane under a point
light seen at an angle, or in a white furnace) was rendered by Cycles 5.0.1
with ``tools/measure_material_oracles.py``; the values are in
``material_oracles.json``.  MC Engine renders the same set-up here.  Under a
point light (max_bounces 0) both renders are free of Monte Carlo noise up to
the pixel positions in a 2 cm patch, so they must agree to 2e-3 (Cycles'
float32 arithmetic and our float64, table interpolation of our own integrals
against theirs); in a furnace the bound is 5 standard errors of our mean plus
2e-3.  These cover the Principled BSDF's layers (specular, metallic with and
without multiple scattering, F82 tint, coat and its tint over emission, sheen,
transmission, alpha, rough diffuse) and every BSDF node.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

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
    ShaderNode,
    World,
)

from .expect import image_mean_and_se, render
from .material_oracles import (
    ALL_ORACLES,
    LIGHT_WATTS,
    ORACLES,
    SLAB_THICKNESS,
    camera_matrix,
    light_position,
)

MEASURED = json.loads((Path(__file__).with_name("material_oracles.json")).read_text())
TOLERANCE = 2e-3


def oracle_scene(name, samples=16):
    nodes, view, light = ALL_ORACLES[name]
    graph = []
    for kind, inputs, props in nodes:
        graph.append(ShaderNode(kind, {k: (Link(v[1], v[2] if len(v) > 2 else "BSDF")
                                           if isinstance(v, tuple) and v and v[0] == "link" else v)
                                       for k, v in inputs.items()},
                                dict(props)))
    s = 50.0
    plane = np.array([[[-s, -s, 0], [s, -s, 0], [s, s, 0]], [[-s, -s, 0], [s, s, 0], [-s, s, 0]]])
    if name in SLAB_THICKNESS:          # and the same below, facing down: a slab
        plane = np.concatenate([plane, plane[:, ::-1] - [0.0, 0.0, SLAB_THICKNESS[name]]])
    last = graph[-1].type
    material = Material(name=name, nodes=graph,
                        surface=Link(len(graph) - 1, "Shader" if last == "MixShader" else "BSDF"))
    bounces = 0 if light is not None else 64
    return SceneDescription(
        geometry=Geometry.from_triangles(plane), materials=[material],
        lights=([Light(type="POINT", matrix_world=_translation(light_position(*light)),
                       strength=(LIGHT_WATTS,) * 3)] if light is not None else []),
        camera=Camera(matrix_world=np.array(camera_matrix(view)), type="ORTHO", ortho_scale=0.02,
                      clip_start=0.01, clip_end=100.0),
        world=World(color=(1.0, 1.0, 1.0) if light is None else (0.0, 0.0, 0.0)),
        film=Film(width=8, height=8, filter_type="BOX", filter_width=1.0),
        integrator=Integrator(samples=samples, max_bounces=bounces, diffuse_bounces=bounces,
                              glossy_bounces=bounces, transmission_bounces=bounces))


def _translation(p):
    m = np.eye(4)
    m[:3, 3] = p
    return m


@pytest.mark.parametrize("name", [n for n, (_nodes, _view, light) in ORACLES.items()
                                  if light is not None])
def test_material_under_a_point_light_matches_cycles(name):
    expected = np.array(MEASURED[name]["rgba"])
    img = render(oracle_scene(name)).image().astype(np.float64)
    got = img.reshape(-1, 4).mean(axis=0)
    assert np.all(np.abs(got - expected) <= TOLERANCE * np.abs(expected) + 1e-6), (
        f"{name}: MC Engine {got.round(5)} vs Cycles {expected.round(5)}")


@pytest.mark.parametrize("name", [n for n, (_nodes, _view, light) in ORACLES.items()
                                  if light is None])
def test_material_in_a_white_furnace_matches_cycles(name):
    expected = MEASURED[name]["rgba"][0]
    session = render(oracle_scene(name, samples=8192))
    mean, se = image_mean_and_se(session)
    assert se < 2e-3
    assert abs(mean - expected) <= 5 * se + TOLERANCE, f"{name}: {mean:.5f} (se {se:.1e}) vs {expected:.5f}"


def test_oracles_were_measured_for_every_set_up():
    assert set(MEASURED) == set(ALL_ORACLES)
    assert all(math.isfinite(v) for m in MEASURED.values() for v in m["rgba"])


@pytest.mark.parametrize("transparent_shadow", [True, False])
def test_transparent_shadows_take_the_colour_of_the_surface_they_pass(transparent_shadow):
    """Cycles (measured, cycles-closures.md 7): a Transparent BSDF of colour (.5, .25, 1)
    between a 1000 W point light and a white plane 2 m below it lets colour x 6.33257 through
    (3.16627, 1.58313, 6.33253); with the material's Transparent Shadows off, nothing."""
    scene = oracle_scene("principled_white")
    scene.materials = [Material(name="white", base_color=(1.0, 1.0, 1.0)),
                       Material(name="filter", nodes=[ShaderNode("BsdfTransparent",
                                                                 {"Color": (0.5, 0.25, 1.0)})],
                                surface=Link(0, "BSDF"), use_transparent_shadow=transparent_shadow)]
    s = 0.3
    card = np.array([[[-s, -s, 1.0], [s, -s, 1.0], [s, s, 1.0]], [[-s, -s, 1.0], [s, s, 1.0], [-s, s, 1.0]]])
    plane = scene.geometry
    scene.geometry = Geometry.concatenate([plane, Geometry.from_triangles(card, material_index=[1, 1])])
    scene.camera.matrix_world = np.array(camera_matrix(20.0))   # the camera sees past the card
    img = render(scene).image().astype(np.float64).reshape(-1, 4).mean(axis=0)
    expected = np.array([0.5, 0.25, 1.0]) * 6.33257 * math.cos(0.0) if transparent_shadow else 0.0
    np.testing.assert_allclose(img[:3], expected, rtol=2e-3, atol=1e-6)
