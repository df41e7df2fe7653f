"""The Light Falloff, Wireframe, Gabor Texture, Normal and Vector Displacement nodes in
light transport: as light, under light samples, seen in a mirror and through bounces.

``tests/nodes`` compares each node with Cycles at pixel centres, under camera rays; this
scene takes them where the rays come from elsewhere: a Light Falloff emitter found by
light samples (its ray length is the sample's distance) and by bounce rays, a Wireframe
whose Pixel Size follows the ray differential of reflected rays, procedural patterns in
a mirror, a displaced surface lit by a sun.

On the stage floor (Diffuse 0.6, ``_common.add_floor``):

* ``Panel``: a 1.4 x 0.5 m quad at z = 2.2 facing down over the middle, Emission (1, 0.9,
  0.75) whose Strength is a Light Falloff's Linear output (Strength 4, Smooth 0.5): the
  floor under it sees a light that falls as 1/d, not 1/d^2;
* ``Gabor``: a smooth UV sphere r 0.45 at (-1.1, 0, 0.45), Principled BSDF, roughness 0.45,
  Base Color from a Color Ramp (dark red to warm white) of a 3D Gabor Texture's Value
  (scale 4, frequency 2.5, anisotropy 0.6) on Object coordinates;
* ``Wire``: a smooth 12x6 UV sphere r 0.45 at (0, 0, 0.45), a Mix Shader of Diffuse (0.2, 0.35,
  0.7) and Diffuse (0.95, 0.9, 0.8) by a Wireframe (Pixel Size, Size 0.5): lines half a
  pixel wide in the image, as the mirror shows them and as bounce light carries them;
* ``Dented``: a 1.0 x 1.0 m quad (planar UVs) on a Simple Subdivision Surface (level 5) at
  (1.2, 0, 0.02), 'Displacement Only' by a Vector Displacement (tangent space, midlevel 0.5, scale
  0.25) of three noises' Fac (scales 3, 5, 2) on Generated coordinates; Diffuse (0.75, 0.7,
  0.6) whose colour is mixed towards (0.3, 0.5, 0.8) by a Normal node's Dot (direction
  (0.3, -0.5, 0.8)) with the displaced surface's normal;
* ``Mirror``: a sharp Glossy (0.9) 4 x 1.4 m standing at y = 1.3 behind them.

``Sun`` 1.2 W/m^2, angle 5 deg, from the front left; world (0.04, 0.045, 0.05).  Bounces
6, diffuse 4, glossy 6; Caustics off (the mirror's caustics of the panel on the floor would
be fireflies).

Run: .venv/bin/python blend_scenes/material_nodes_extra.py
"""
import math

import _common as c


def _panel_material():
    material, tree, output = c._new_material("Panel")
    emission = c.shader_node(tree, "ShaderNodeEmission", color=(1.0, 0.9, 0.75))
    falloff = c.shader_node(tree, "ShaderNodeLightFalloff", location=(-300.0, 0.0), strength=4.0,
                            smooth=0.5)
    tree.links.new(falloff.outputs["Linear"], emission.inputs["Strength"])
    tree.links.new(emission.outputs["Emission"], output.inputs["Surface"])
    return material


def _gabor_material():
    material, tree, output = c._new_material("Gabor")
    bsdf = c.shader_node(tree, "ShaderNodeBsdfPrincipled", roughness=0.45)
    coords = c.shader_node(tree, "ShaderNodeTexCoord", location=(-900.0, 0.0))
    gabor = c.shader_node(tree, "ShaderNodeTexGabor", location=(-600.0, 0.0), gabor_type="3D",
                          scale=4.0, frequency=2.5, anisotropy=0.6)
    ramp = c.shader_node(tree, "ShaderNodeValToRGB", location=(-300.0, 0.0))
    ramp.color_ramp.elements[0].color = (0.35, 0.05, 0.03, 1.0)
    ramp.color_ramp.elements[1].color = (0.95, 0.85, 0.7, 1.0)
    tree.links.new(coords.outputs["Object"], gabor.inputs["Vector"])
    tree.links.new(gabor.outputs["Value"], ramp.inputs["Fac"])
    tree.links.new(ramp.outputs["Color"], bsdf.inputs["Base Color"])
    tree.links.new(bsdf.outputs["BSDF"], output.inputs["Surface"])
    return material


def _wire_material():
    material, tree, output = c._new_material("Wire")
    wire = c.shader_node(tree, "ShaderNodeWireframe", location=(-600.0, 200.0), size=0.5,
                         use_pixel_size=True)
    faces = c.shader_node(tree, "ShaderNodeBsdfDiffuse", location=(-300.0, 100.0),
                          color=(0.2, 0.35, 0.7), roughness=0.0)
    lines = c.shader_node(tree, "ShaderNodeBsdfDiffuse", location=(-300.0, -100.0),
                          color=(0.95, 0.9, 0.8), roughness=0.0)
    mix = c.shader_node(tree, "ShaderNodeMixShader")
    tree.links.new(wire.outputs["Fac"], mix.inputs["Fac"])
    tree.links.new(faces.outputs["BSDF"], mix.inputs[1])
    tree.links.new(lines.outputs["BSDF"], mix.inputs[2])
    tree.links.new(mix.outputs["Shader"], output.inputs["Surface"])
    return material


def _dented_material():
    material, tree, output = c._new_material("Dented")
    material.displacement_method = "DISPLACEMENT"
    coords = c.shader_node(tree, "ShaderNodeTexCoord", location=(-1200.0, -300.0))
    combine = c.shader_node(tree, "ShaderNodeCombineXYZ", location=(-600.0, -300.0))
    for k, scale in enumerate((3.0, 5.0, 2.0)):
        noise = c.shader_node(tree, "ShaderNodeTexNoise", location=(-900.0, -200.0 - 150.0 * k),
                              scale=scale, detail=2.0)
        tree.links.new(coords.outputs["Generated"], noise.inputs["Vector"])
        tree.links.new(noise.outputs["Fac"], combine.inputs[k])
    disp = c.shader_node(tree, "ShaderNodeVectorDisplacement", location=(-300.0, -300.0),
                         midlevel=0.5, scale=0.25, space="TANGENT")
    tree.links.new(combine.outputs["Vector"], disp.inputs["Vector"])
    tree.links.new(disp.outputs["Displacement"], output.inputs["Displacement"])
    geometry = c.shader_node(tree, "ShaderNodeNewGeometry", location=(-900.0, 300.0))
    normal = c.shader_node(tree, "ShaderNodeNormal", location=(-600.0, 300.0))
    normal.outputs["Normal"].default_value = (0.3, -0.5, 0.8)
    tree.links.new(geometry.outputs["Normal"], normal.inputs["Normal"])
    c.diffuse_between(tree, output, normal.outputs["Dot"], (0.75, 0.7, 0.6), (0.3, 0.5, 0.8),
                      location=(-300.0, 200.0))
    return material


def build(scene):
    c.set_world(scene, (0.04, 0.045, 0.05))
    c.set_bounces(scene, 6, 4, glossy=6, transmission=6, caustics=False)
    c.add_floor(scene)
    c.add_quad(scene, "Panel", [(-0.7, 0.25, 2.2), (-0.7, -0.25, 2.2), (0.7, -0.25, 2.2),
                                (0.7, 0.25, 2.2)], _panel_material())
    c.add_uv_sphere(scene, "Gabor", 0.45, _gabor_material(), location=(-1.1, 0.0, 0.45))
    c.add_uv_sphere(scene, "Wire", 0.45, _wire_material(), segments=12, rings=6,
                    location=(0.0, 0.0, 0.45))
    dented = c.add_mesh(scene, "Dented", [(-0.5, -0.5, 0.0), (0.5, -0.5, 0.0), (0.5, 0.5, 0.0),
                                          (-0.5, 0.5, 0.0)], [(0, 1, 2, 3)], _dented_material(),
                        smooth=True, location=(1.2, 0.0, 0.02))
    c.set_planar_uvs(dented)         # tangent space: along its UV map's tangents
    modifier = dented.modifiers.new("Subdivision", "SUBSURF")
    modifier.subdivision_type = "SIMPLE"
    modifier.levels = modifier.render_levels = 5
    mirror = c.node_material("Mirror", "ShaderNodeBsdfGlossy", color=(0.9, 0.9, 0.9), roughness=0.0)
    c.add_quad(scene, "Mirror", [(-2.0, 1.3, 0.0), (2.0, 1.3, 0.0), (2.0, 1.3, 1.4), (-2.0, 1.3, 1.4)],
               mirror)
    c.add_light(scene, "Sun", "SUN", 1.2, (-3.0, -2.5, 2.5), target=(0.0, 0.0, 0.0),
                angle=math.radians(5.0))
    c.add_camera(scene, (0.0, -3.3, 1.7), (0.0, 0.15, 0.55), lens_mm=32.0)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
