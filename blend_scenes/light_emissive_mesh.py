"""Emissive meshes as the only lights: a glowing sphere and a glowing quad.

Tests mesh emission (Emission shader, radiance = colour x strength, no factor
pi, emitted from both sides), light sampling of emissive triangles, and their
direct visibility.  No lamps; world black.

* ``GlowSphere``: UV sphere 64x32 of radius 0.25, orange, strength 20.
* ``GlowPanel``: a 2.0 x 0.8 m quad 1.8 m up, tilted 35 deg, white-blue,
  strength 12; the camera sees its upper (back) side, which emits too.

Run: .venv/bin/python blend_scenes/light_emissive_mesh.py
"""
import math

import _common as c


def build(scene):
    c.set_world(scene, (0.0, 0.0, 0.0))
    c.add_stage(scene)
    c.add_uv_sphere(scene, "GlowSphere", 0.25,
                    c.emission_material("GlowSphere", (1.0, 0.55, 0.2), 20.0),
                    location=(-0.2, -0.4, 0.45))
    c.add_quad(scene, "GlowPanel", [(-1.0, -0.4, 0.0), (1.0, -0.4, 0.0),
                                    (1.0, 0.4, 0.0), (-1.0, 0.4, 0.0)],
               c.emission_material("GlowPanel", (0.8, 0.9, 1.0), 12.0),
               location=(0.3, 1.3, 1.8), rotation=(math.radians(35.0), 0.0, 0.0))


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
