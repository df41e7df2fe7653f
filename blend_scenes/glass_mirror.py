"""Sharp glass and a mirror: singular reflection and refraction, as in Whitted ray tracing.

Tests the Glass BSDF at roughness 0 (exact dielectric Fresnel, colour tinting
both lobes, IOR inverted inside), the Glossy BSDF at roughness 0 (a mirror
whose colour is its reflectance) and a Mix Shader of diffuse and mirror.
Lit by a grey sky and a large area light, so the caustics under the glass
sphere are smooth enough to compare at a few hundred samples.

* ``GlassSphere``: UV sphere 64x32 of radius 0.6, smooth, Glass BSDF IOR 1.45,
  faint green tint.
* ``Mirror``: a 2 x 1.2 m quad standing behind the objects, Glossy BSDF,
  colour 0.9.
* ``Cube``: Mix Shader of its Lambert Principled BSDF (0.7) and a mirror (0.3).
* ``Panel``: area light 2 m square, 150 W, 3 m up.

Run: .venv/bin/python blend_scenes/glass_mirror.py
"""
import math

import _common as c


def sharp_material(name, bl_idname, color, ior=None):
    material, tree, output = c._new_material(name)
    node = tree.nodes.new(bl_idname)
    node.inputs["Color"].default_value = (*color, 1.0)
    node.inputs["Roughness"].default_value = 0.0
    if ior is not None:
        node.inputs["IOR"].default_value = ior
    tree.links.new(node.outputs[0], output.inputs["Surface"])
    return material


def mix_with_mirror(material, fac):
    tree = material.node_tree
    output = tree.nodes["Material Output"]
    shader = output.inputs["Surface"].links[0].from_node
    mirror = tree.nodes.new("ShaderNodeBsdfAnisotropic")     # the Glossy BSDF node
    mirror.inputs["Roughness"].default_value = 0.0
    mirror.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    mix = tree.nodes.new("ShaderNodeMixShader")
    mix.inputs[0].default_value = fac
    tree.links.new(shader.outputs[0], mix.inputs[1])
    tree.links.new(mirror.outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], output.inputs["Surface"])


def build(scene):
    c.set_world(scene, (0.15, 0.15, 0.15))
    c.set_bounces(scene, 8, 4, glossy=8, transmission=8)
    stage = c.add_stage(scene)
    stage["sphere"].data.materials[0] = sharp_material("GlassSphere", "ShaderNodeBsdfGlass",
                                                       (0.9, 1.0, 0.92), ior=1.45)
    mix_with_mirror(stage["cube"].data.materials[0], 0.3)
    c.add_quad(scene, "Mirror", [(-1.0, 0.0, -0.6), (1.0, 0.0, -0.6), (1.0, 0.0, 0.6), (-1.0, 0.0, 0.6)],
               sharp_material("Mirror", "ShaderNodeBsdfAnisotropic", (0.9, 0.9, 0.9)),
               location=(0.2, 1.8, 0.9), rotation=(0.0, 0.0, math.radians(-10.0)))
    c.add_light(scene, "Panel", "AREA", 150.0, (0.0, -0.5, 3.0), shape="SQUARE", size=2.0)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
