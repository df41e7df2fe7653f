"""The scene of the scale benchmark: a bumpy ground of N triangles in a three-walled room.

A smooth-shaded height field (a grid of quads, each split into two triangles by
Blender) of 4 x 4 m fills the floor of an open room with a back wall and two side
walls, lit by a 1 m square area light and the 0.05 grey world, seen from the open
side, with 8 bounces and the unbiased settings of blend_scenes/_common.py.  Almost
every triangle is the ground, so the triangle count is what grows; the walls keep
paths bouncing as in the Cornell box.

The mesh is built with ``foreach_set`` from numpy arrays (``from_pydata`` takes
minutes for millions of faces) and saved to a temporary .blend, which is not kept.

With IMAGES > 0 the ground and then the walls (up to four surfaces) each take their colour
from an 8-bit image of SIZE x SIZE texels (default 4096), packed into the .blend: smooth
colour waves with a straight alpha below 1 in places, so a render loads and converts each
image as it would a photograph's (sRGB decoding, association of the alpha). The ground's
UV map spans its image once; the walls have none (their colour is the texel at UV (0, 0),
but their images are loaded whole all the same).

Run on its own: python benchmarks/scale_scene.py TRIANGLES OUT.blend [IMAGES [SIZE]]
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
GROUND_SIZE = 4.0       # metres
BUMP_HEIGHT = 0.15      # metres, amplitude of the height field
BUMP_WAVES = 6.0        # bumps across the ground


def grid_side(triangles: int) -> int:
    """Quads per side of the grid whose 2 n^2 triangles come closest to ``triangles``."""
    return max(1, round(math.sqrt(triangles / 2.0)))


MAX_IMAGES = 4          # the ground and the three walls


def build(triangles: int, path: Path, images: int = 0, image_size: int = 4096) -> int:
    """Write the scene with about ``triangles`` ground triangles (and ``images`` textured
    surfaces, see the module docstring) to ``path``; returns the total triangle count
    (ground and walls)."""
    sys.path.insert(0, str(REPO / "blend_scenes"))
    import _common as c
    import bpy

    scene = c.new_scene()
    c.set_bounces(scene, total=8, diffuse=8, glossy=8, transmission=8)
    c.set_world(scene, (0.05, 0.05, 0.05))
    white = c.diffuse_material("White", (0.73, 0.73, 0.73))
    red = c.diffuse_material("Red", (0.63, 0.065, 0.05))
    green = c.diffuse_material("Green", (0.14, 0.45, 0.09))
    n = grid_side(triangles)
    ground = _height_field(bpy, n)
    ground.materials.append(white)
    scene.collection.objects.link(bpy.data.objects.new("Ground", ground))
    h = GROUND_SIZE / 2
    c.add_quad(scene, "BackWall", [(-h, h, 0), (h, h, 0), (h, h, 2), (-h, h, 2)], white)
    c.add_quad(scene, "LeftWall", [(-h, -h, 0), (-h, h, 0), (-h, h, 2), (-h, -h, 2)], red)
    c.add_quad(scene, "RightWall", [(h, -h, 0), (h, -h, 2), (h, h, 2), (h, h, 0)], green)
    surfaces = [white, white, red, green]           # ground, back, left and right walls
    if images:
        _ground_uvs(ground, n)
        for k in range(min(images, MAX_IMAGES)):
            surfaces[k] = _textured(c, f"Textured {k}", _image(bpy, f"waves {k}", image_size, k))
        ground.materials[0] = surfaces[0]
        for wall, material in zip(("BackWall", "LeftWall", "RightWall"), surfaces[1:]):
            bpy.data.objects[wall].data.materials[0] = material
    c.add_light(scene, "AreaLight", "AREA", 200.0, (0.0, 0.0, 3.0), shape="SQUARE", size=1.0)
    c.add_camera(scene, (0.0, -6.5, 3.0), (0.0, 0.0, 0.3), lens_mm=35.0)
    bpy.context.view_layer.update()
    bpy.ops.wm.save_as_mainfile(filepath=str(path), compress=False, copy=True)
    return 2 * n * n + 6


def _ground_uvs(mesh, n: int) -> None:
    """A UV map spanning the ground's grid once."""
    side = np.linspace(0.0, 1.0, n + 1, dtype=np.float32)
    u, v = np.meshgrid(side, side, indexing="xy")
    uv = np.stack([u, v], axis=-1).reshape(-1, 2)
    corners = np.empty(len(mesh.loops), np.int32)
    mesh.loops.foreach_get("vertex_index", corners)
    mesh.uv_layers.new(name="UVMap").data.foreach_set("uv", uv[corners].reshape(-1))


def _image(bpy, name: str, size: int, k: int):
    """A packed 8-bit RGBA image of smooth colour waves (``k`` shifts their phase)."""
    t = np.linspace(0.0, 2.0 * math.pi, size, dtype=np.float32)
    u, v = np.meshgrid(t, t, indexing="xy")
    rgba = np.empty((size, size, 4), np.float32)
    for ch in range(3):
        rgba[..., ch] = 0.5 + 0.4 * np.sin(3.0 * u + 2.0 * ch + k) * np.cos(2.0 * v - ch)
    rgba[..., 3] = np.clip(1.2 + 0.5 * np.sin(5.0 * v + k), 0.0, 1.0)
    image = bpy.data.images.new(name, size, size, alpha=True)
    image.pixels.foreach_set(rgba.reshape(-1))
    image.pack()
    return image


def _textured(c, name: str, image):
    """A Diffuse BSDF whose colour is ``image`` at the surface's UV map."""
    material = c.node_material(name, "ShaderNodeBsdfDiffuse", roughness=0.0)
    tree = material.node_tree
    bsdf = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeBsdfDiffuse")
    tree.links.new(c.image_texture(tree, image).outputs["Color"], bsdf.inputs["Color"])
    return material


def _height_field(bpy, n: int):
    """An n x n grid of smooth-shaded quads over GROUND_SIZE, displaced by a sum of sines."""
    side = np.linspace(-GROUND_SIZE / 2, GROUND_SIZE / 2, n + 1)
    x, y = np.meshgrid(side, side, indexing="xy")
    k = 2.0 * math.pi * BUMP_WAVES / GROUND_SIZE
    z = BUMP_HEIGHT * (1.0 + np.sin(k * x) * np.cos(k * y))
    co = np.stack([x, y, z], axis=-1).reshape(-1, 3).astype(np.float32)
    i = np.arange(n)
    a = (i[None, :] + (n + 1) * i[:, None]).reshape(-1)       # lower-left corner of each quad
    corners = np.stack([a, a + 1, a + n + 2, a + n + 1], axis=1).astype(np.int32)
    me = bpy.data.meshes.new("Ground")
    me.vertices.add(len(co))
    me.vertices.foreach_set("co", co.reshape(-1))
    me.loops.add(corners.size)
    me.loops.foreach_set("vertex_index", corners.reshape(-1))
    me.polygons.add(len(corners))
    me.polygons.foreach_set("loop_start", np.arange(0, corners.size, 4, dtype=np.int32))
    me.update(calc_edges=True)
    me.shade_smooth()
    return me


if __name__ == "__main__":
    if not 3 <= len(sys.argv) <= 5:
        sys.exit(__doc__.strip().splitlines()[-1])
    print(build(int(sys.argv[1]), Path(sys.argv[2]), *(int(a) for a in sys.argv[3:])))
