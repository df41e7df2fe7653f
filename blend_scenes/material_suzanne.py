"""Suzanne: the default Principled BSDF on a curved, subdivided mesh.

Tests the Principled BSDF at Blender's defaults (roughness 0.5, IOR 1.5,
specular IOR level 0.5, multiscatter GGX) over a surface with every normal
direction and concave detail (Suzanne's eyes and ears), with smooth shading
of a Subdivision Surface modifier's output; the Diffuse BSDF at roughness 0.8
(Oren-Nayar) on the floor; an emissive mesh and a sun as the lights.

* ``Suzanne``: Blender's monkey head (``bmesh.ops.create_monkey``, 500 faces,
  2.7 m wide, facing -Y), Subdivision Surface level 2 (viewport and render),
  smooth, scaled 0.75, at (0.1, 0.2, 0.72), turned 25 deg towards the glow;
  Principled BSDF with Blender's defaults and base (0.8, 0.3, 0.2).
* ``Floor``: the stage floor with Diffuse BSDF (0.6, 0.6, 0.6), roughness 0.8.
* ``Glow``: a 64x32 UV sphere of radius 0.3, Emission (1, 0.85, 0.65) x 10,
  at (-1.05, -0.7, 1.25), in view.
* ``Sun``: 2 W/m^2, colour (0.8, 0.9, 1), angle 5 deg, from the right at 45 deg
  elevation.

World (0.02, 0.02, 0.025).  Bounces 4/4.

Run: .venv/bin/python blend_scenes/material_suzanne.py
"""
import math

import _common as c


def build(scene):
    c.set_world(scene, (0.02, 0.02, 0.025))
    c.add_floor(scene, c.node_material("Floor", "ShaderNodeBsdfDiffuse", color=(0.6, 0.6, 0.6),
                                       roughness=0.8))
    c.add_suzanne(scene, "Suzanne",
                  c.node_material("Suzanne", "ShaderNodeBsdfPrincipled", base_color=(0.8, 0.3, 0.2)),
                  subdivision_levels=2, location=(0.1, 0.2, 0.72),
                  rotation=(0.0, 0.0, math.radians(-25.0)), scale=(0.75, 0.75, 0.75))
    c.add_uv_sphere(scene, "Glow", 0.3, c.emission_material("Glow", (1.0, 0.85, 0.65), 10.0),
                    location=(-1.05, -0.7, 1.25))
    c.add_light(scene, "Sun", "SUN", 2.0, (3.0, 0.0, 3.0), target=(0.0, 0.0, 0.0),
                color=(0.8, 0.9, 1.0), angle=math.radians(5.0))
    c.add_camera(scene, (0.0, -4.2, 2.2), (0.0, 0.0, 0.6), lens_mm=50.0)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
