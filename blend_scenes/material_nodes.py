"""The BSDF nodes other than the Principled: glossy, glass, refraction, translucent,
transparent, sheen, Oren-Nayar diffuse, and the Mix and Add Shaders.

Tests each closure node on its own (Cycles' svm/closure.h): the Glossy BSDF
with the three microfacet distributions at the same roughness, rough Glass
and Refraction (Beckmann, the Refraction node's default), the Translucent
BSDF lit only through a thin screen, a Mix Shader of Diffuse and a coloured
Transparent BSDF (a coloured, partly transparent shadow), the microfibre
Sheen BSDF, the Diffuse BSDF at roughness 1 (Oren-Nayar), and an Add Shader
of Diffuse and Glossy (energy is not conserved: the two lobes add up).

Eight 64x32 smooth UV spheres of radius 0.4 on the stage floor, 1.05 m apart,
seen from above at about 50 deg so that they fill the frame:

* back row (y = +1.05): Glossy BSDF colour (0.9, 0.9, 0.9), roughness 0.2,
  ``GlossyGGX`` (GGX), ``GlossyBeckmann`` (BECKMANN), ``GlossyMulti``
  (MULTI_GGX);
* middle row (y = 0): ``OrenNayar`` (Diffuse BSDF (0.7, 0.6, 0.45),
  roughness 1), ``DiffusePlusGlossy`` (Add Shader of Diffuse (0.3, 0.45, 0.6)
  and Glossy (0.3, 0.3, 0.3) roughness 0.3 GGX), ``Sheen`` (Sheen BSDF
  microfibre, colour (0.9, 0.5, 0.7), roughness 0.4);
* front row (y = -1.05), where their caustics fall on open floor towards the
  camera: ``Glass`` (Glass BSDF roughness 0.25, IOR 1.5, colour
  (0.95, 0.95, 1), multiscatter GGX), ``Refraction`` (Refraction BSDF
  roughness 0.1, IOR 1.45, Beckmann, colour (1, 0.95, 0.9)), and ``Leaf``: a
  0.8 x 1.0 m card, Mix Shader (factor 0.5) of Diffuse (0.2, 0.45, 0.08) and
  Transparent (0.6, 0.95, 0.3): its shadow on the floor is green and half
  light;
* ``Screen``: a 3.2 x 1.0 m quad standing on the floor behind the spheres,
  Translucent BSDF (0.9, 0.8, 0.6); ``Backlight``, a point light of radius
  0.3 (soft falloff), 60 W, 0.6 m behind it, reaches the front only through
  it (and under its sides).

``Sun``: 1.5 W/m^2, angle 30 deg, from the left rear at 50 deg elevation (a
wide sun keeps the glass caustics smooth enough for the CI setting).  World
(0.12, 0.13, 0.15), a sky for the glossy spheres to reflect.  Bounces 8,
diffuse 4, glossy 8, transmission 8.

Run: .venv/bin/python blend_scenes/material_nodes.py
"""
import math

import _common as c

RADIUS = 0.4
SPACING = 1.05
GLOSSY = "ShaderNodeBsdfAnisotropic"   # the Glossy BSDF node since Blender 4.0
DIFFUSE = "ShaderNodeBsdfDiffuse"

SPHERES = (   # (name, column, row from the front, material)
    ("GlossyGGX", -1, 2, lambda n: c.node_material(
        n, GLOSSY, color=(0.9, 0.9, 0.9), roughness=0.2, distribution="GGX")),
    ("GlossyBeckmann", 0, 2, lambda n: c.node_material(
        n, GLOSSY, color=(0.9, 0.9, 0.9), roughness=0.2, distribution="BECKMANN")),
    ("GlossyMulti", 1, 2, lambda n: c.node_material(
        n, GLOSSY, color=(0.9, 0.9, 0.9), roughness=0.2, distribution="MULTI_GGX")),
    ("Glass", -1, 0, lambda n: c.node_material(
        n, "ShaderNodeBsdfGlass", color=(0.95, 0.95, 1.0), roughness=0.25, ior=1.5,
        distribution="MULTI_GGX")),
    ("Refraction", 0, 0, lambda n: c.node_material(
        n, "ShaderNodeBsdfRefraction", color=(1.0, 0.95, 0.9), roughness=0.1, ior=1.45,
        distribution="BECKMANN")),
    ("Sheen", 1, 1, lambda n: c.node_material(
        n, "ShaderNodeBsdfSheen", color=(0.9, 0.5, 0.7), roughness=0.4, distribution="MICROFIBER")),
    ("OrenNayar", -1, 1, lambda n: c.node_material(
        n, DIFFUSE, color=(0.7, 0.6, 0.45), roughness=1.0)),
    ("DiffusePlusGlossy", 0, 1, lambda n: c.combine_material(
        n, (DIFFUSE, dict(color=(0.3, 0.45, 0.6), roughness=0.0)),
        (GLOSSY, dict(color=(0.3, 0.3, 0.3), roughness=0.3, distribution="GGX")))),
)


def build(scene):
    c.set_world(scene, (0.12, 0.13, 0.15))
    c.set_bounces(scene, 8, 4, glossy=8, transmission=8)
    c.add_floor(scene)
    for name, column, row, material in SPHERES:
        c.add_uv_sphere(scene, name, RADIUS, material(name),
                        location=(column * SPACING, (row - 1) * SPACING, RADIUS))

    leaf = c.combine_material("Leaf", (DIFFUSE, dict(color=(0.2, 0.45, 0.08), roughness=0.0)),
                              ("ShaderNodeBsdfTransparent", dict(color=(0.6, 0.95, 0.3))),
                              fac=0.5)
    c.add_quad(scene, "Leaf", [(-0.4, 0.0, 0.0), (0.4, 0.0, 0.0), (0.4, 0.0, 1.0), (-0.4, 0.0, 1.0)],
               leaf, location=(1.1, -1.0, 0.05), rotation=(0.0, 0.0, math.radians(35.0)))

    screen = c.node_material("Screen", "ShaderNodeBsdfTranslucent", color=(0.9, 0.8, 0.6))
    c.add_quad(scene, "Screen", [(-1.6, 0.0, 0.0), (1.6, 0.0, 0.0), (1.6, 0.0, 1.0), (-1.6, 0.0, 1.0)],
               screen, location=(0.0, 1.9, 0.0))
    c.add_light(scene, "Backlight", "POINT", 60.0, (0.0, 2.5, 0.5), shadow_soft_size=0.3,
                use_soft_falloff=True)
    sun = c.add_light(scene, "Sun", "SUN", 1.5, (0.0, 0.0, 5.0), angle=math.radians(30.0))
    elevation, azimuth = math.radians(50.0), math.radians(135.0)   # from the left rear
    c.look_at(sun, (-math.cos(elevation) * math.cos(azimuth) + sun.location.x,
                    -math.cos(elevation) * math.sin(azimuth) + sun.location.y,
                    -math.sin(elevation) + sun.location.z))
    c.add_camera(scene, (0.0, -3.4, 4.6), (0.0, 0.35, 0.3), lens_mm=50.0)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
