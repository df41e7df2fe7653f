"""The Principled BSDF's layers: nine spheres, one variant each.

Tests Cycles' Principled BSDF v2 (svm_node_closure_bsdf's layering): the
dielectric base (diffuse under a GGX/multiscatter specular with IOR and IOR
level), Oren-Nayar diffuse roughness, the F82-tint metal, the coat with its
tint and its own roughness, sheen, rough transmission, alpha (transparent
shadows and camera rays through a half-transparent surface) and the specular
tint of a dielectric.

A 3 x 3 grid of 64x32 smooth UV spheres of radius 0.42 on the stage floor,
1.05 m apart, seen from above at about 55 deg so that they fill the frame,
rows from the back (y = +1.05) to the front (y = -1.05), each a Principled
BSDF with Blender's defaults except:

* back row: ``Default`` (base 0.8, roughness 0.5, IOR 1.5, specular IOR
  level 0.5, multiscatter GGX); ``Metal`` (metallic 1, base (1, 0.78, 0.34),
  roughness 0.3); ``Transmission`` (transmission 1, roughness 0.15, IOR
  1.45, base (0.9, 1, 0.9)), in the corner away from the light so that its
  caustic falls on open floor;
* middle row: ``Coat`` (red base (0.8, 0.05, 0.04), coat weight 1, coat
  roughness 0.1, coat tint (0.8, 0.9, 1)); ``Sheen`` (dark blue base
  (0.03, 0.05, 0.25), sheen weight 1, sheen roughness 0.3); ``TintedMetal``
  (metallic 1, base (0.95, 0.64, 0.54), specular tint (0.9, 0.45, 0.3) as the
  F82 tint, roughness 0.55, GGX);
* front row: ``Alpha`` (base (0.8, 0.55, 0.15), alpha 0.5);
  ``RoughDiffuse`` (base (0.55, 0.7, 0.45), diffuse roughness 1, specular IOR
  level 0.2); ``Specular`` (base (0.15, 0.15, 0.18), specular IOR level 1,
  IOR 1.3, specular tint (1, 0.6, 0.6), roughness 0.3).

Lit by ``Key``, a 3 m square area light, 300 W, up front left, and a
blue-grey world (0.05, 0.06, 0.08).  Bounces 8, diffuse 4, glossy 8,
transmission 8 (the transmission sphere needs a few to be seen through).

Run: .venv/bin/python blend_scenes/material_principled.py
"""
import _common as c

PRINCIPLED = "ShaderNodeBsdfPrincipled"
RADIUS = 0.42
SPACING = 1.05

# (name, Principled inputs and properties), rows back to front, left to right.
VARIANTS = (
    ("Default", {}),
    ("Metal", dict(metallic=1.0, base_color=(1.0, 0.78, 0.34), roughness=0.3)),
    ("Transmission", dict(transmission_weight=1.0, roughness=0.15, ior=1.45,
                          base_color=(0.9, 1.0, 0.9))),
    ("Coat", dict(base_color=(0.8, 0.05, 0.04), coat_weight=1.0, coat_roughness=0.1,
                  coat_tint=(0.8, 0.9, 1.0))),
    ("Sheen", dict(base_color=(0.03, 0.05, 0.25), sheen_weight=1.0, sheen_roughness=0.3)),
    ("TintedMetal", dict(metallic=1.0, base_color=(0.95, 0.64, 0.54),
                         specular_tint=(0.9, 0.45, 0.3), roughness=0.55, distribution="GGX")),
    ("Alpha", dict(base_color=(0.8, 0.55, 0.15), alpha=0.5)),
    ("RoughDiffuse", dict(base_color=(0.55, 0.7, 0.45), diffuse_roughness=1.0,
                          specular_ior_level=0.2)),
    ("Specular", dict(base_color=(0.15, 0.15, 0.18), specular_ior_level=1.0, ior=1.3,
                      specular_tint=(1.0, 0.6, 0.6), roughness=0.3)),
)


def build(scene):
    c.set_world(scene, (0.05, 0.06, 0.08))
    c.set_bounces(scene, 8, 4, glossy=8, transmission=8)
    c.add_floor(scene)
    for (name, values), location in zip(VARIANTS, c.sphere_grid(len(VARIANTS), RADIUS, SPACING)):
        c.add_uv_sphere(scene, name, RADIUS, c.node_material(name, PRINCIPLED, **values),
                        location=location)
    c.add_light(scene, "Key", "AREA", 300.0, (-2.0, -2.2, 3.6), target=(0.0, 0.0, 0.3),
                shape="SQUARE", size=3.0)
    c.add_camera(scene, (0.0, -3.2, 4.9), (0.0, 0.0, 0.3), lens_mm=58.0)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
