"""Thin-film interference on every node that has it: six spheres under coloured light.

Tests the Thin Film Thickness and Thin Film IOR inputs (Belcour and Barla's Airy series
over the CMFs' Fourier transform, as Cycles): a film on the Principled BSDF's dielectric
specular (with IOR level 0, so that only the film reflects), its metal (F82 tint:
n and k estimated from F0 and F82) and its transmission, on the Glass BSDF (film IOR
divided by the IOR inside), and on the Metallic BSDF with both Fresnel types.

A 3 x 2 grid of 64x32 smooth UV spheres of radius 0.42 on the stage floor, 1.05 m apart,
seen from above at about 50 deg, rows from the back (y = +0.525) to the front:

* back: ``Bubble`` (Principled, base (0.02, 0.02, 0.03), roughness 0.15, specular IOR
  level 0, film 380 nm, film IOR 1.33); ``FilmMetal`` (Principled metallic 1, base (0.92, 0.92, 0.9), roughness
  0.25, film 520 nm, film IOR 1.5); ``FilmGlass`` (Glass BSDF, roughness 0.1, IOR 1.5,
  film 300 nm, film IOR 1.35, multiscatter GGX);
* front: ``FilmGold`` (Metallic BSDF, Physical Conductor, gold n (0.18, 0.42, 1.37) and k
  (3.42, 2.35, 1.77), roughness 0.3, film 250 nm, film IOR 1.8); ``FilmF82`` (Metallic
  BSDF, F82 Tint with its default colours, roughness 0.4, GGX, film 650 nm, film IOR
  1.33); ``FilmTransmission`` (Principled transmission 1, roughness 0.2, IOR 1.45,
  specular IOR level 0.5, specular tint (1, 0.8, 0.8), film 450 nm, film IOR 1.3).

Lit by ``Key``, a 3 m square area light of 300 W up front left, and a white-ish world
(0.35, 0.35, 0.38) that the films reflect.  Bounces 8, diffuse 4, glossy 8, transmission 8.

Run: .venv/bin/python blend_scenes/material_thin_film.py
"""
import _common as c

PRINCIPLED = "ShaderNodeBsdfPrincipled"
METALLIC = "ShaderNodeBsdfMetallic"
RADIUS = 0.42
SPACING = 1.05

# (name, node, inputs and properties), back row then front row, left to right.
VARIANTS = (
    ("Bubble", PRINCIPLED, dict(base_color=(0.02, 0.02, 0.03), roughness=0.15,
                                specular_ior_level=0.0, thin_film_thickness=380.0,
                                thin_film_ior=1.33)),
    ("FilmMetal", PRINCIPLED, dict(metallic=1.0, base_color=(0.92, 0.92, 0.9), roughness=0.25,
                                   thin_film_thickness=520.0, thin_film_ior=1.5)),
    ("FilmGlass", "ShaderNodeBsdfGlass", dict(roughness=0.1, ior=1.5, distribution="MULTI_GGX",
                                              thin_film_thickness=300.0, thin_film_ior=1.35)),
    ("FilmGold", METALLIC, dict(fresnel_type="PHYSICAL_CONDUCTOR", ior=(0.18, 0.42, 1.37),
                                extinction=(3.42, 2.35, 1.77), roughness=0.3,
                                thin_film_thickness=250.0, thin_film_ior=1.8)),
    ("FilmF82", METALLIC, dict(roughness=0.4, distribution="GGX",
                               thin_film_thickness=650.0, thin_film_ior=1.33)),
    ("FilmTransmission", PRINCIPLED, dict(transmission_weight=1.0, roughness=0.2, ior=1.45,
                                          specular_tint=(1.0, 0.8, 0.8),
                                          thin_film_thickness=450.0, thin_film_ior=1.3)),
)


def build(scene):
    c.set_world(scene, (0.35, 0.35, 0.38))
    c.set_bounces(scene, 8, 4, glossy=8, transmission=8)
    c.add_floor(scene)
    for (name, node, values), location in zip(VARIANTS, c.sphere_grid(len(VARIANTS), RADIUS, SPACING)):
        c.add_uv_sphere(scene, name, RADIUS, c.node_material(name, node, **values), location=location)
    c.add_light(scene, "Key", "AREA", 300.0, (-2.0, -2.2, 3.6), target=(0.0, 0.0, 0.3),
                shape="SQUARE", size=3.0)
    c.add_camera(scene, (0.0, -3.3, 3.6), (0.0, 0.0, 0.35), lens_mm=55.0)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
