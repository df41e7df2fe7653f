"""A rough glass cylinder in a small room of rough diffuse walls.

Tests the rough Glass BSDF (multiscatter GGX at roughness 0.3: rough
reflection and refraction, the light it focuses onto the floor, the room seen
blurred through it), the Diffuse BSDF at roughness 0.5 (Oren-Nayar) on every
wall, with colour bleeding between them, a Mix Shader of Diffuse and
Transparent (a card half see-through, its shadow half light), and an
emissive sphere inside the room as the only strong light.

The room spans x = -1.2..1.2, y = -1.2..1.2 (open at the front, y = -1.2)
and z = 0..2; its quads face inwards, all Diffuse BSDF roughness 0.5:
``Floor`` (0.7, 0.68, 0.62), ``Ceiling`` 0.75, ``BackWall`` (0.35, 0.45, 0.7),
``LeftWall`` (0.75, 0.4, 0.15), ``RightWall`` (0.2, 0.6, 0.5); the floor
runs on to y = -2.6 in front of the room, so the camera sees no edge.

* ``GlassCylinder``: radius 0.3, height 0.9, 64 segments, smooth side and flat
  caps, Glass BSDF roughness 0.3, IOR 1.5, colour (0.95, 1, 0.97),
  multiscatter GGX, at (-0.35, 0.25), 2 mm above the floor (a cap coplanar
  with the floor is ill-posed: the engines resolve the coincident surfaces
  differently, which showed as a bright line at the cylinder's foot).
* ``Card``: a 0.7 x 0.9 m quad standing at (0.55, -0.35), turned 25 deg, Mix
  Shader (factor 0.6) of Diffuse (0.8, 0.75, 0.7) and Transparent (0.9, 0.9, 0.9).
* ``Glow``: a 64x32 UV sphere of radius 0.3, Emission (1, 0.9, 0.75) x 12,
  at (0.35, 0.45, 1.45).

World (0.02, 0.02, 0.02), seen through the open front only in reflections.
Bounces 6, diffuse 3, glossy 6, transmission 6 (a closed room: cheaper).

Run: .venv/bin/python blend_scenes/material_rough_glass.py
"""
import math

import _common as c

DIFFUSE = "ShaderNodeBsdfDiffuse"
WALLS = {   # name: (colour, corners counter-clockwise seen from inside)
    "Floor": ((0.7, 0.68, 0.62), [(-1.2, -2.6, 0), (1.2, -2.6, 0), (1.2, 1.2, 0), (-1.2, 1.2, 0)]),
    "Ceiling": ((0.75, 0.75, 0.75), [(-1.2, -1.2, 2), (-1.2, 1.2, 2), (1.2, 1.2, 2), (1.2, -1.2, 2)]),
    "BackWall": ((0.35, 0.45, 0.7), [(-1.2, 1.2, 0), (1.2, 1.2, 0), (1.2, 1.2, 2), (-1.2, 1.2, 2)]),
    "LeftWall": ((0.75, 0.4, 0.15), [(-1.2, -1.2, 0), (-1.2, 1.2, 0), (-1.2, 1.2, 2), (-1.2, -1.2, 2)]),
    "RightWall": ((0.2, 0.6, 0.5), [(1.2, -1.2, 0), (1.2, -1.2, 2), (1.2, 1.2, 2), (1.2, 1.2, 0)]),
}


def build(scene):
    c.set_world(scene, (0.02, 0.02, 0.02))
    c.set_bounces(scene, 6, 3, glossy=6, transmission=6)
    for name, (color, corners) in WALLS.items():
        c.add_quad(scene, name, corners, c.node_material(name, DIFFUSE, color=color, roughness=0.5))

    glass = c.node_material("GlassCylinder", "ShaderNodeBsdfGlass", color=(0.95, 1.0, 0.97),
                            roughness=0.3, ior=1.5, distribution="MULTI_GGX")
    c.add_cylinder(scene, "GlassCylinder", 0.3, 0.9, glass, location=(-0.35, 0.25, 0.002))

    card = c.combine_material("Card", (DIFFUSE, dict(color=(0.8, 0.75, 0.7), roughness=0.0)),
                              ("ShaderNodeBsdfTransparent", dict(color=(0.9, 0.9, 0.9))), fac=0.6)
    c.add_quad(scene, "Card", [(-0.35, 0.0, 0.0), (0.35, 0.0, 0.0), (0.35, 0.0, 0.9), (-0.35, 0.0, 0.9)],
               card, location=(0.55, -0.35, 0.0), rotation=(0.0, 0.0, math.radians(25.0)))

    c.add_uv_sphere(scene, "Glow", 0.3, c.emission_material("Glow", (1.0, 0.9, 0.75), 12.0),
                    location=(0.35, 0.45, 1.45))
    c.add_camera(scene, (0.0, -3.9, 1.1), (0.0, 0.0, 0.8), lens_mm=42.0)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
