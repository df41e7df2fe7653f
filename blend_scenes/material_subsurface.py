"""Subsurface scattering: random walks in closed meshes of every thickness.

Tests the Principled BSDF's Subsurface Weight (Random Walk and Random Walk (Skin)) and
the Subsurface Scattering node (Christensen-Burley, which turns Lambert after a diffuse
bounce: the floor's light on the slab) on closed objects, where light walks through thin parts
(Suzanne's ears, the slab) and comes back out of thick ones, lit from the front and from
behind (translucency), next to a Diffuse floor; mean free paths from 1 mm to several cm.

* ``Suzanne``: Blender's monkey head, Subdivision Surface level 2, smooth, scaled 0.6, at
  (-0.55, 0.2, 0.6), turned 20 deg towards the camera; Principled BSDF base (0.9, 0.55,
  0.4), Subsurface Weight 1, Radius (1, 0.4, 0.2), Scale 0.2, Roughness 0.4 (Random Walk).
* ``Skin``: a UV sphere of radius 0.35 at (0.25, 0.45, 0.35); Principled base (0.8, 0.6,
  0.5), Subsurface Weight 0.8, Scale 0.1, Subsurface IOR 1.4, Anisotropy 0.5, Random Walk
  (Skin).
* ``Slab``: a 0.8 x 0.05 x 0.6 box standing at (0.95, -0.1, 0), turned 60 deg; the Subsurface
  Scattering node, Christensen-Burley, colour (0.9, 0.8, 0.3), Scale 0.08.
* ``Floor``: the stage floor with Diffuse BSDF (0.5, 0.5, 0.5).
* ``Key``: an area light, 1 m square, 80 W, from the front left; ``Back``: a point light of
  radius 0.1, 100 W, behind the objects, for the light through them.

World (0.05, 0.05, 0.06).  Bounces 6/4.

Run: .venv/bin/python blend_scenes/material_subsurface.py
"""
import math

import _common as c


def build(scene):
    c.set_world(scene, (0.05, 0.05, 0.06))
    c.set_bounces(scene, 6, 4)
    c.add_floor(scene, c.diffuse_material("Floor", (0.5, 0.5, 0.5)))
    c.add_suzanne(scene, "Suzanne",
                  c.node_material("Suzanne", "ShaderNodeBsdfPrincipled", base_color=(0.9, 0.55, 0.4),
                                  subsurface_weight=1.0, subsurface_radius=(1.0, 0.4, 0.2),
                                  subsurface_scale=0.2, roughness=0.4),
                  subdivision_levels=2, location=(-0.55, 0.2, 0.6),
                  rotation=(0.0, 0.0, math.radians(20.0)), scale=(0.6, 0.6, 0.6))
    c.add_uv_sphere(scene, "Skin", 0.35,
                    c.node_material("Skin", "ShaderNodeBsdfPrincipled",
                                    subsurface_method="RANDOM_WALK_SKIN", base_color=(0.8, 0.6, 0.5),
                                    subsurface_weight=0.8, subsurface_scale=0.1,
                                    subsurface_ior=1.4, subsurface_anisotropy=0.5),
                    location=(0.25, 0.45, 0.35))
    c.add_box(scene, "Slab", (0.8, 0.05, 0.6),
              c.node_material("Slab", "ShaderNodeSubsurfaceScattering", falloff="BURLEY",
                              color=(0.9, 0.8, 0.3), scale=0.08),
              location=(0.95, -0.1, 0.0), rotation=(0.0, 0.0, math.radians(60.0)))
    c.add_light(scene, "Key", "AREA", 80.0, (-1.5, -2.0, 2.2), target=(0.0, 0.0, 0.4), size=1.0)
    c.add_light(scene, "Back", "POINT", 100.0, (0.3, 1.6, 1.0), shadow_soft_size=0.1)
    c.add_camera(scene, (0.0, -3.6, 1.6), (0.0, 0.0, 0.4), lens_mm=45.0)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
