"""Image textures on objects: an 8-bit sRGB texture read four ways, lit by an area light.

The texture is ``textures/tiles.png`` (64 x 64, 8-bit sRGB, opaque), made here:
a 4 x 4 grid of coloured tiles with a thin grey grout and a soft gradient. The
floor's Principled-as-Lambert base colour reads it through a planar UV map
repeated every 2 m (Linear interpolation, Repeat); the cube is box-projected
from its object coordinates with blend 0.2 (Cubic); the sphere reads it in
sphere projection of its generated coordinates (Closest) into a Diffuse BSDF; the
small block reads it at its object coordinates, mostly outside the image
(Extend).

Run: .venv/bin/python blend_scenes/texture_image.py
"""
import math

import _common as c
import numpy as np

N = 64
TILES = 4


def tile_pixels():
    """(N, N, 4) float in [0, 1], 8-bit values, bottom row first."""
    rng = np.random.default_rng(5)
    colors = rng.integers(40, 230, size=(TILES, TILES, 3))
    ij = np.arange(N)
    tile = ij * TILES // N
    px = np.zeros((N, N, 4))
    px[..., :3] = colors[tile[:, None], tile[None, :]]
    grout = (ij % (N // TILES) == 0)
    px[grout, :, :3] = 128
    px[:, grout, :3] = 128
    px[..., :3] *= (0.75 + 0.25 * ij / (N - 1))[:, None, None]
    px[..., 3] = 255
    return np.round(px) / 255.0


def _textured(name, image, shader="ShaderNodeBsdfPrincipled", vector=None, **tex_values):
    material, tree, output = c._new_material(name)
    tex = c.image_texture(tree, image, **tex_values)
    if shader == "ShaderNodeBsdfPrincipled":
        bsdf = c.shader_node(tree, shader, specular_ior_level=0.0)
        tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    else:
        bsdf = c.shader_node(tree, shader, roughness=0.0)
        tree.links.new(tex.outputs["Color"], bsdf.inputs["Color"])
    if vector is not None:
        coords = c.shader_node(tree, "ShaderNodeTexCoord", location=(-600.0, 0.0))
        tree.links.new(coords.outputs[vector], tex.inputs["Vector"])
    tree.links.new(bsdf.outputs[0], output.inputs["Surface"])
    return material


def build(scene):
    c.set_world(scene, (0.05, 0.05, 0.06))
    image = c.save_texture("tiles.png", tile_pixels())
    stage = c.add_stage(scene)
    stage["floor"].data.materials[0] = _textured("TiledFloor", image)
    c.set_planar_uvs(stage["floor"], scale=0.5)
    stage["cube"].data.materials[0] = _textured("BoxCube", image, vector="Object",
                                                 projection="BOX", projection_blend=0.2,
                                                 interpolation="Cubic")
    stage["sphere"].data.materials[0] = _textured("SphereMap", image, "ShaderNodeBsdfDiffuse",
                                                   vector="Generated", projection="SPHERE",
                                                   interpolation="Closest")
    block = _textured("Block", image, vector="Object", extension="EXTEND")
    stage["block"].data.materials[0] = block
    c.add_light(scene, "Key", "AREA", 400.0, (-2.5, -3.0, 4.0), target=(0.0, 0.0, 0.3),
                size=2.5)
    c.add_light(scene, "Sun", "SUN", 1.0, (0.0, 0.0, 6.0),
                rotation=(math.radians(35.0), 0.0, math.radians(50.0)), angle=0.05)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
