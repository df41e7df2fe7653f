"""The Hair BSDF on meshes: its reflection and transmission components.

Cycles' Hair BSDF (bsdf_hair.h) scatters about a strand's tangent: a lobe in the angle from
the plane normal to the tangent (width RoughnessU, centred on the mirror angle shifted by
twice the Offset) and in the azimuth about it (RoughnessV).  On a mesh with nothing linked
to Tangent, Cycles takes the triangle's dPdv (its third corner less its first) and ignores
the Offset, so the sphere's highlights follow its triangles' edges; with a Tangent linked
the Offset tilts the lobe.  Neither component is checked against the surface's side when
sampled, so rays go on into the objects, as in Cycles.  The cube and the block stand 1 cm
above the floor: where a transmitting face lies in the floor's plane, Cycles starts the ray
through it at the very point (and meets the floor there) while MC Engine's origin offset
passes under the floor, so a contact is where the two would differ, by construction.

* ``Sphere``: the stage's smooth sphere, reflection (0.85, 0.6, 0.35), RoughnessU 0.2,
  RoughnessV 0.6, Tangent unlinked;
* ``Cube``: the stage's cube, reflection (0.9, 0.9, 0.9) RoughnessU 0.15, RoughnessV 0.4 plus
  transmission (0.3, 0.5, 0.9) RoughnessU 0.3, RoughnessV 0.8 (an Add Shader), both along a
  Tangent node radial about Z, Offset 0.1 rad;
* ``Block``: the stage's small box, transmission (0.9, 0.45, 0.2), RoughnessU 0.4,
  RoughnessV 0.3, Tangent unlinked.

``Key``: an area lamp 1.2 m square, 150 W, warm, at (-2.0, -2.2, 3.2) aimed at the objects;
``Fill``: a point lamp 120 W, radius 0.2, bluish, at (2.5, -1.0, 2.0); world (0.1, 0.1,
0.11).  Bounces 6, diffuse 3, glossy 4, transmission 6.

Run: .venv/bin/python blend_scenes/material_hair.py
"""
import _common as c

LIFT = 0.01     # the transmitting boxes stand this high above the floor


def _hair(component, color, roughness_u, roughness_v, offset=0.0):
    return ("ShaderNodeBsdfHair", {"component": component, "color": color,
                                   "RoughnessU": roughness_u, "RoughnessV": roughness_v,
                                   "offset": offset})


def _radial_hair(name, first, second):
    """An Add Shader of two Hair BSDFs whose Tangent is a Tangent node's, radial about Z."""
    material = c.combine_material(name, first, second)
    tree = material.node_tree
    tangent = c.shader_node(tree, "ShaderNodeTangent", location=(-600.0, 0.0),
                            direction_type="RADIAL", axis="Z")
    for node in tree.nodes:
        if node.bl_idname == "ShaderNodeBsdfHair":
            tree.links.new(tangent.outputs["Tangent"], node.inputs["Tangent"])
    return material


def build(scene):
    c.set_world(scene, (0.1, 0.1, 0.11))
    c.set_bounces(scene, 6, 3, glossy=4, transmission=6)
    stage = c.add_stage(scene)
    kind, values = _hair("Reflection", (0.85, 0.6, 0.35), 0.2, 0.6)
    stage["sphere"].data.materials[0] = c.node_material("SphereHair", kind, **values)
    stage["cube"].data.materials[0] = _radial_hair(
        "CubeHair", _hair("Reflection", (0.9, 0.9, 0.9), 0.15, 0.4, 0.1),
        _hair("Transmission", (0.3, 0.5, 0.9), 0.3, 0.8, 0.1))
    kind, values = _hair("Transmission", (0.9, 0.45, 0.2), 0.4, 0.3)
    stage["block"].data.materials[0] = c.node_material("BlockHair", kind, **values)
    for name in ("cube", "block"):       # off the floor: see the module docstring
        stage[name].location.z = LIFT
    c.add_material_lights(scene)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
