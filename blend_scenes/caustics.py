"""Caustics: light focused by a glass ball and thrown by a mirror onto a diffuse floor.

Tests the light paths that go from a light through sharp glass or off a sharp
mirror to a diffuse surface (Cycles' Caustics Refractive and Reflective, both
on here; ``tests/fidelity/test_caustics.py`` also renders them off), lit by an
area light and by a sun with an angle, both wide enough that path tracing finds
their caustics at the CI setting.

* ``Floor``: the stage floor, Diffuse BSDF 0.7.
* ``GlassBall``: a 64x32 smooth UV sphere of radius 0.5, Glass BSDF roughness 0,
  IOR 1.5, white, at (-0.6, 0.3), 2 mm above the floor.  Under the area light
  it focuses a bright spot just beside its foot; the low sun draws a long
  caustic on the floor behind it.
* ``Mirror``: a 1.4 x 0.9 m quad, Glossy BSDF roughness 0, colour 0.9, standing at
  (1.3, 0.9), turned to throw the sun onto the floor in front of it.
* ``Key``: square area light 0.6 m, 90 W, 2.6 m above the ball.
* ``Sun``: 2.5 W/m^2, angle 25 deg, from (-4, -2.6, 3) towards the origin (31 deg up).

World black.  Bounces 8, diffuse 4, glossy 8, transmission 8.

Run: .venv/bin/python blend_scenes/caustics.py
"""
import math

import _common as c


def stage(scene):
    """World, bounces, floor, glass ball, mirror and camera (shared with caustics_point)."""
    c.set_world(scene, (0.0, 0.0, 0.0))
    c.set_bounces(scene, 8, 4, glossy=8, transmission=8)
    c.add_floor(scene, c.diffuse_material("Floor", (0.7, 0.7, 0.7)))
    glass = c.node_material("GlassBall", "ShaderNodeBsdfGlass", color=(1.0, 1.0, 1.0),
                            roughness=0.0, ior=1.5, distribution="MULTI_GGX")
    c.add_uv_sphere(scene, "GlassBall", 0.5, glass, location=(-0.6, 0.3, 0.502))
    mirror = c.node_material("Mirror", "ShaderNodeBsdfAnisotropic", color=(0.9, 0.9, 0.9),
                             roughness=0.0, distribution="GGX")
    c.add_quad(scene, "Mirror", [(-0.7, 0.0, 0.0), (0.7, 0.0, 0.0), (0.7, 0.0, 0.9), (-0.7, 0.0, 0.9)],
               mirror, location=(1.3, 0.9, 0.01), rotation=(0.0, 0.0, math.radians(-35.0)))
    c.add_camera(scene, (0.2, -4.4, 3.2), (0.1, 0.3, 0.2), lens_mm=40.0)


def build(scene):
    stage(scene)
    c.add_light(scene, "Key", "AREA", 90.0, (-0.6, 0.3, 2.6), shape="SQUARE", size=0.6)
    c.add_light(scene, "Sun", "SUN", 2.5, (-4.0, -2.6, 3.0), target=(0.0, 0.0, 0.0),
                angle=math.radians(25.0))


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
