"""Bump mapping under light: a Bump node into a BSDF's Normal, and the material output's
Displacement rendered as bump (Cycles' default 'Bump Only' method).

* ``Suzanne``: Blender's monkey head, Subdivision Surface level 2, smooth, scaled 0.7,
  at (-0.55, 0.25, 0.68), turned 20 deg; Principled BSDF, base (0.75, 0.55, 0.35),
  roughness 0.35, whose Normal comes from a Bump node (Distance 0.2, Strength 1) of a
  Noise texture's Fac on Generated coordinates (scale 3, detail 2).
* ``Ball``: a smooth 64x32 UV sphere r 0.5 at (0.75, -0.1, 0.5), Diffuse BSDF
  (0.6, 0.7, 0.8); the output's Displacement is a Displacement node (object space,
  midlevel 0.5, scale 0.04) of a Wave texture's Fac (bands along Z, scale 3,
  distortion 4, detail 2): rendered as a bump, the sphere is not displaced.
* ``Sun`` 2.5 W/m^2, angle 5 deg, from the right at 35 deg elevation; ``Key`` square
  area light 2 m, 150 W, front left; world (0.04, 0.045, 0.05).  Bounces 4/4.

Run: .venv/bin/python blend_scenes/texture_bump.py
"""
import math

import _common as c


def _bumped_suzanne():
    material = c.node_material("Suzanne", "ShaderNodeBsdfPrincipled", base_color=(0.75, 0.55, 0.35),
                               roughness=0.35)
    tree = material.node_tree
    shader = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")
    noise = c.shader_node(tree, "ShaderNodeTexNoise", location=(-600.0, 0.0), scale=3.0, detail=2.0)
    bump = c.shader_node(tree, "ShaderNodeBump", location=(-300.0, 0.0), distance=0.2, strength=1.0)
    tree.links.new(noise.outputs["Fac"], bump.inputs["Height"])
    tree.links.new(bump.outputs["Normal"], shader.inputs["Normal"])
    return material


def _displaced_ball():
    material = c.node_material("Ball", "ShaderNodeBsdfDiffuse", color=(0.6, 0.7, 0.8))
    material.displacement_method = "BUMP"
    tree = material.node_tree
    output = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputMaterial")
    wave = c.shader_node(tree, "ShaderNodeTexWave", location=(-600.0, -300.0), bands_direction="Z",
                         scale=3.0, distortion=4.0, detail=2.0)
    disp = c.shader_node(tree, "ShaderNodeDisplacement", location=(-300.0, -300.0), midlevel=0.5,
                         scale=0.04, space="OBJECT")
    tree.links.new(wave.outputs["Fac"], disp.inputs["Height"])
    tree.links.new(disp.outputs["Displacement"], output.inputs["Displacement"])
    return material


def build(scene):
    c.set_world(scene, (0.04, 0.045, 0.05))
    c.add_floor(scene)
    c.add_suzanne(scene, "Suzanne", _bumped_suzanne(), subdivision_levels=2,
                  location=(-0.55, 0.25, 0.68), rotation=(0.0, 0.0, math.radians(-20.0)),
                  scale=(0.7, 0.7, 0.7))
    c.add_uv_sphere(scene, "Ball", 0.5, _displaced_ball(), location=(0.75, -0.1, 0.5))
    c.add_light(scene, "Sun", "SUN", 2.5, (3.0, -1.0, 2.1), target=(0.0, 0.0, 0.0),
                angle=math.radians(5.0))
    c.add_light(scene, "Key", "AREA", 150.0, (-2.0, -2.2, 2.8), target=(0.0, 0.0, 0.4), size=2.0)
    c.add_camera(scene, (0.0, -4.0, 2.0), (0.1, 0.0, 0.55), lens_mm=50.0)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
