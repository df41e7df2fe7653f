"""The Bevel and Ambient Occlusion nodes: rounded edges on flat-shaded boxes, under a lamp, in
a mirror and as a colour, on a floor darkened where the boxes stand.

Both nodes trace rays of their own: Bevel against its own object (the normals of the
surfaces within its Radius, averaged), for camera rays and after sharp bounces, not after
diffuse or rough ones (Cycles' "blurry indirect rays"); Ambient Occlusion against the scene
(the fraction of its rays that nothing stops within its Distance), after any bounce.

On the floor, a 24 m quad at z = 0 (``Floor``: Diffuse whose colour is a Mix from (0.15, 0.12,
0.1) to (0.6, 0.6, 0.6) by an Ambient Occlusion's AO, Distance 0.6, 16 samples: dark where
the boxes stand, seen by the camera, in the mirror and through bounces):

* ``Block``: a flat-shaded 0.8 m cube turned 30 deg about z at (-0.75, 0, 0), Principled BSDF
  (Base Color (0.7, 0.35, 0.2), roughness 0.3) whose Normal is a Bevel's (Radius 0.08, 8
  samples): the lamp's highlight runs along its rounded edges;
* ``Rim``: a flat-shaded 0.7 m cube turned -20 deg at (0.8, 0.1, 0), Diffuse BSDF whose colour is
  the bevelled normal mapped to 0.5 n + 0.5 (Vector Math Multiply Add), the Bevel (Radius 0.12,
  4 samples) taking the normal of a Bump (strength 0.4) of a Noise Texture: a linked Normal
  input is bent by the bevel (Cycles: normalize(Normal + bevel - N));
* ``Mirror``: a sharp Glossy (0.9) 4 x 1.5 m standing at y = 1.2 behind them: the boxes'
  rounded backs, seen after a sharp bounce.

``Key``: an area lamp 1.2 m square, 120 W, at (-1.5, -2.0, 3.0) aimed at the blocks; world
(0.05, 0.055, 0.06).  Bounces 6, diffuse 3, glossy 4; Caustics off.

Run: .venv/bin/python blend_scenes/material_bevel_ao.py
"""
import math

import _common as c


def _block_material():
    material, tree, output = c._new_material("Block")
    bsdf = c.shader_node(tree, "ShaderNodeBsdfPrincipled", base_color=(0.7, 0.35, 0.2),
                         roughness=0.3)
    bevel = c.shader_node(tree, "ShaderNodeBevel", location=(-300.0, -300.0), radius=0.08,
                          samples=8)
    tree.links.new(bevel.outputs["Normal"], bsdf.inputs["Normal"])
    tree.links.new(bsdf.outputs["BSDF"], output.inputs["Surface"])
    return material


def _rim_material():
    material, tree, output = c._new_material("Rim")
    noise = c.shader_node(tree, "ShaderNodeTexNoise", location=(-1200.0, 0.0), scale=6.0)
    bump = c.shader_node(tree, "ShaderNodeBump", location=(-900.0, 0.0), strength=0.4)
    bevel = c.shader_node(tree, "ShaderNodeBevel", location=(-600.0, 0.0), radius=0.12,
                          samples=4)
    shift = c.shader_node(tree, "ShaderNodeVectorMath", location=(-300.0, 0.0),
                          operation="MULTIPLY_ADD")
    shift.inputs[1].default_value = (0.5, 0.5, 0.5)
    shift.inputs[2].default_value = (0.5, 0.5, 0.5)
    bsdf = c.shader_node(tree, "ShaderNodeBsdfDiffuse", roughness=0.0)
    tree.links.new(noise.outputs["Fac"], bump.inputs["Height"])
    tree.links.new(bump.outputs["Normal"], bevel.inputs["Normal"])
    tree.links.new(bevel.outputs["Normal"], shift.inputs[0])
    tree.links.new(shift.outputs["Vector"], bsdf.inputs["Color"])
    tree.links.new(bsdf.outputs["BSDF"], output.inputs["Surface"])
    return material


def _floor_material():
    material, tree, output = c._new_material("Floor")
    ao = c.shader_node(tree, "ShaderNodeAmbientOcclusion", location=(-600.0, 0.0), distance=0.6,
                       samples=16)
    c.diffuse_between(tree, output, ao.outputs["AO"], (0.15, 0.12, 0.1), (0.6, 0.6, 0.6))
    return material


def build(scene):
    c.set_world(scene, (0.05, 0.055, 0.06))
    c.set_bounces(scene, 6, 3, glossy=4, transmission=6, caustics=False)
    c.add_floor(scene, _floor_material())
    c.add_box(scene, "Block", (0.8, 0.8, 0.8), _block_material(), location=(-0.75, 0.0, 0.0),
              rotation=(0.0, 0.0, math.radians(30.0)))
    c.add_box(scene, "Rim", (0.7, 0.7, 0.7), _rim_material(), location=(0.8, 0.1, 0.0),
              rotation=(0.0, 0.0, math.radians(-20.0)))
    mirror = c.node_material("Mirror", "ShaderNodeBsdfGlossy", color=(0.9, 0.9, 0.9), roughness=0.0)
    c.add_quad(scene, "Mirror", [(-2.0, 1.2, 0.0), (2.0, 1.2, 0.0), (2.0, 1.2, 1.5), (-2.0, 1.2, 1.5)],
               mirror)
    c.add_light(scene, "Key", "AREA", 120.0, (-1.5, -2.0, 3.0), target=(0.0, 0.0, 0.4), size=1.2)
    c.add_camera(scene, (0.3, -3.2, 1.9), (0.0, 0.2, 0.4), lens_mm=35.0)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
