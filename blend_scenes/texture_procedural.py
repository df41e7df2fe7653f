"""Procedural textures driving lit materials: Noise, Voronoi, Brick and Wave under light.

Tests the texture nodes where they meet light transport: a pattern into a
BSDF's colour, a noise into a roughness, textures on default (Generated)
coordinates of meshes of different bounding boxes.

* ``Floor``: the stage floor, Diffuse BSDF whose colour is a Brick texture
  (scale 40 over the 24 m floor, offset 0.5, mortar (0.15, 0.15, 0.15),
  colours (0.75, 0.45, 0.3) and (0.55, 0.5, 0.45), bias 0.1).
* ``Ball``: a smooth 64x32 UV sphere r 0.6 at (0.8, 0.1, 0.6), Principled BSDF with
  Base Color from a Voronoi texture (F1, scale 6, its Color) and Roughness from a
  Noise texture's Fac (fBm, scale 8, detail 4, roughness 0.6).
* ``Block``: a 0.9 m cube at (-1.0, 0.3, 0), turned 30 deg, Diffuse BSDF whose colour
  is a 4D Noise's Color (W 0.3, scale 3, distortion 0.5).
* ``Rings``: a 0.7 m square standing at (-0.1, -1.2), Emission from a Wave texture
  (rings, spherical, saw profile, distortion 2) x 1.5.
* ``Key``: square area light 2.5 m, 250 W, front left at 3.2 m; world (0.05, 0.06, 0.08).

Bounces 4/4.

Run: .venv/bin/python blend_scenes/texture_procedural.py
"""
import math

import _common as c


def _textured(name, bsdf, links, **bsdf_values):
    """A ``bsdf`` material whose inputs come from texture nodes.

    ``links`` maps an input of the BSDF to ``(texture idname, output, {inputs and
    properties})``.
    """
    material = c.node_material(name, bsdf, **bsdf_values)
    tree = material.node_tree
    shader = next(n for n in tree.nodes if n.bl_idname == bsdf)
    for k, (socket, (kind, output, values)) in enumerate(links.items()):
        texture = c.shader_node(tree, kind, location=(-300.0, 200.0 - 300.0 * k), **values)
        tree.links.new(texture.outputs[output], shader.inputs[socket])
    return material


def build(scene):
    c.set_world(scene, (0.05, 0.06, 0.08))
    c.add_floor(scene, _textured("Floor", "ShaderNodeBsdfDiffuse", {
        "Color": ("ShaderNodeTexBrick", "Color", dict(
            scale=40.0, color1=(0.75, 0.45, 0.3), color2=(0.55, 0.5, 0.45),
            mortar=(0.15, 0.15, 0.15), bias=0.1, offset=0.5)),
    }))
    c.add_uv_sphere(scene, "Ball", 0.6, _textured("Ball", "ShaderNodeBsdfPrincipled", {
        "Base Color": ("ShaderNodeTexVoronoi", "Color", dict(scale=6.0)),
        "Roughness": ("ShaderNodeTexNoise", "Fac", dict(scale=8.0, detail=4.0, roughness=0.6)),
    }), location=(0.8, 0.1, 0.6))
    c.add_box(scene, "Block", (0.9, 0.9, 0.9), _textured("Block", "ShaderNodeBsdfDiffuse", {
        "Color": ("ShaderNodeTexNoise", "Color", dict(
            noise_dimensions="4D", w=0.3, scale=3.0, distortion=0.5)),   # 4D first: shows W
    }), location=(-1.0, 0.3, 0.0), rotation=(0.0, 0.0, math.radians(30.0)))
    rings = _textured("Rings", "ShaderNodeEmission", {
        "Color": ("ShaderNodeTexWave", "Color", dict(
            wave_type="RINGS", rings_direction="SPHERICAL", wave_profile="SAW",
            distortion=2.0, scale=3.0)),
    }, strength=1.5)
    c.add_quad(scene, "Rings", [(-0.35, 0.0, 0.0), (0.35, 0.0, 0.0), (0.35, 0.0, 0.7),
                                (-0.35, 0.0, 0.7)], rings, location=(-0.1, -1.2, 0.02))
    c.add_light(scene, "Key", "AREA", 250.0, (-2.0, -2.0, 3.2), target=(0.0, 0.0, 0.3),
                size=2.5)
    c.add_camera(scene, c.STAGE_CAMERA_LOCATION, c.STAGE_CAMERA_TARGET)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
