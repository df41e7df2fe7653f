"""Anisotropic metals along the tangents Cycles gives them, on a grey floor.

Tests the tangent frame of anisotropic microfacet closures: the Tangent
input nothing is linked to (Cycles' Geometry Tangent: the circle about the
object's Z axis through its texture space's centre, as a normal of the object
transform, projected onto the shading plane) and the Tangent node (radial
about another axis, and along a UV map's MikkTSpace tangents).  Each object
is turned so that object and world axes differ; the highlights stretch along
or across those directions, so a wrong tangent moves light visibly.

* ``Sphere``: a 64x32 smooth UV sphere of radius 0.55 at (-1.05, 0.1, 0.55),
  turned (20, -15, 30) deg: Principled BSDF, base colour (0.9, 0.75, 0.5),
  Metallic 1, Roughness 0.35, Anisotropic 0.8, Rotation 0.1, Tangent unlinked.
* ``Cylinder``: radius 0.4, height 1.0, at (0.35, 0.45, 0), tipped (0, 12, 40)
  deg: Glossy BSDF (multiscatter GGX), colour (0.8, 0.82, 0.85), Roughness 0.4,
  Anisotropy -0.7, Tangent from a Tangent node, radial about X.
* ``Suzanne``: the monkey (subdivided twice, its own UV unwrap) scaled 0.45
  at (1.35, -0.55, 0.5), turned (0, 0, 25) deg: Metallic BSDF (F82 tint),
  base (0.95, 0.64, 0.54), edge tint (0.95, 0.8, 0.75), Roughness 0.3,
  Anisotropy 0.9, Tangent from a Tangent node along the UV map ``UVMap``.

Floor: the stage floor (Diffuse 0.6).  Lights: an area light 1.5 m square of
300 W at (1.5, -1.8, 3.2) aimed at (0, 0, 0.5), a point light of 250 W radius
0.1 m at (-2.5, -0.5, 2.5), and the world (0.15, 0.16, 0.18) for the
reflections' surroundings.  Camera at (0.1, -4.6, 2.2) aimed at (0.15, 0, 0.5),
42 mm.  Bounces: 6 total, diffuse 3, glossy 6.

Run: .venv/bin/python blend_scenes/material_anisotropic.py
"""
import math

import _common as c

DEG = math.radians


def _along_tangent_node(name, bl_idname, tangent, **values):
    """One BSDF node (``values``) whose Tangent input comes from a Tangent node (``tangent``:
    its settings)."""
    material = c.node_material(name, bl_idname, **values)
    tree = material.node_tree
    node = c.shader_node(tree, "ShaderNodeTangent", location=(-300.0, -300.0), **tangent)
    bsdf = next(n for n in tree.nodes if n.bl_idname == bl_idname)
    tree.links.new(node.outputs["Tangent"], bsdf.inputs["Tangent"])
    return material


def build(scene):
    c.set_world(scene, (0.15, 0.16, 0.18))
    c.set_bounces(scene, 6, 3, glossy=6)
    c.add_floor(scene)

    sphere = c.node_material("Sphere", "ShaderNodeBsdfPrincipled", base_color=(0.9, 0.75, 0.5, 1.0),
                             metallic=1.0, roughness=0.35, anisotropic=0.8, anisotropic_rotation=0.1)
    c.add_uv_sphere(scene, "Sphere", 0.55, sphere, location=(-1.05, 0.1, 0.55),
                    rotation=(DEG(20.0), DEG(-15.0), DEG(30.0)))
    glossy = _along_tangent_node("Cylinder", "ShaderNodeBsdfAnisotropic",
                                 dict(direction_type="RADIAL", axis="X"),
                                 color=(0.8, 0.82, 0.85, 1.0), roughness=0.4, anisotropy=-0.7,
                                 distribution="MULTI_GGX")
    c.add_cylinder(scene, "Cylinder", 0.4, 1.0, glossy,
                   location=(0.35, 0.45, 0.0), rotation=(0.0, DEG(12.0), DEG(40.0)))
    metallic = _along_tangent_node("Suzanne", "ShaderNodeBsdfMetallic",
                                   dict(direction_type="UV_MAP", uv_map="UVMap"), fresnel_type="F82",
                                   base_color=(0.95, 0.64, 0.54, 1.0), edge_tint=(0.95, 0.8, 0.75, 1.0),
                                   roughness=0.3, anisotropy=0.9)
    c.add_suzanne(scene, "Suzanne", metallic, uv_map=True,
                  location=(1.35, -0.55, 0.5), rotation=(0.0, 0.0, DEG(25.0)),
                  scale=(0.45, 0.45, 0.45))

    c.add_light(scene, "Area", "AREA", 300.0, (1.5, -1.8, 3.2), target=(0.0, 0.0, 0.5), size=1.5)
    c.add_light(scene, "Point", "POINT", 250.0, (-2.5, -0.5, 2.5), shadow_soft_size=0.1)
    c.add_camera(scene, (0.1, -4.6, 2.2), (0.15, 0.0, 0.5), lens_mm=42.0)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
