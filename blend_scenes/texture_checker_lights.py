"""A checker floor under every light type at once: the scene a new user makes first.

Tests a Checker texture into the Principled BSDF at Blender's defaults (roughness 0.5,
IOR 1.5, specular IOR level 0.5, multiscatter GGX), so that every lamp shows both in the
diffuse pattern and as a glossy highlight on the floor, with several lamps of different
types sampled together.

* ``Floor``: the stage floor with a UV map running 0 .. 1 over its 24 m (as Blender
  unwraps a plane), Principled defaults with Base Color from a Checker texture on UV
  (scale 48: 0.5 m squares, colours (0.8, 0.75, 0.65) and (0.1, 0.15, 0.25)).
* ``Cube``: a 1 m cube at (-1.0, 0.5, 0), turned 30 deg, Principled defaults with Base
  Color from a Checker on its Generated coordinates (Blender's default: scale 5,
  colours 0.8 and 0.2).
* ``Sphere``: a smooth 64x32 UV sphere r 0.55 at (0.9, 0.1, 0.55), Principled defaults
  (base 0.8).
* ``Point`` 150 W, warm (1, 0.7, 0.45), radius 0.1 m, at (-2.2, -0.8, 1.8);
  ``Spot`` 400 W, blue (0.45, 0.65, 1), 40 deg, blend 0.25, radius 0.1 m, from
  (2.2, -1.5, 3.0) aimed at (0.6, 0.2, 0); ``Area`` square 1.5 m, 120 W, green
  (0.7, 1, 0.6), above the back at (0, 2.5, 3) aimed at the sphere; ``Sun``
  1.2 W/m^2, (1, 0.95, 0.9), angle 2 deg, 35 deg up from the left rear;
  world (0.03, 0.035, 0.045).

Bounces 4/4.

Run: .venv/bin/python blend_scenes/texture_checker_lights.py
"""
import math

import _common as c

# The floor's UVs run 0 .. 1 over its side; checker squares of 0.5 m.
FLOOR_CHECKER_SCALE = 2.0 * c.STAGE_FLOOR_HALF_SIZE / 0.5


def _checkered(name, coordinates, **checker_values):
    """Principled BSDF at its defaults whose Base Color is a Checker texture read at
    ``coordinates`` ('UV' or 'Generated', from a Texture Coordinate node)."""
    material = c.node_material(name, "ShaderNodeBsdfPrincipled")
    tree = material.node_tree
    shader = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")
    coords = c.shader_node(tree, "ShaderNodeTexCoord", location=(-600.0, 0.0))
    checker = c.shader_node(tree, "ShaderNodeTexChecker", location=(-300.0, 0.0), **checker_values)
    tree.links.new(coords.outputs[coordinates], checker.inputs["Vector"])
    tree.links.new(checker.outputs["Color"], shader.inputs["Base Color"])
    return material


def build(scene):
    c.set_world(scene, (0.03, 0.035, 0.045))
    floor = c.add_floor(scene, _checkered("Floor", "UV", scale=FLOOR_CHECKER_SCALE,
                                          color1=(0.8, 0.75, 0.65), color2=(0.1, 0.15, 0.25)))
    mesh = floor.data
    layer = mesh.uv_layers.new(name="UVMap")
    h = c.STAGE_FLOOR_HALF_SIZE
    for loop in mesh.loops:
        co = mesh.vertices[loop.vertex_index].co
        layer.data[loop.index].uv = ((co.x + h) / (2.0 * h), (co.y + h) / (2.0 * h))
    c.add_box(scene, "Cube", (1.0, 1.0, 1.0), _checkered("Cube", "Generated"),
              location=(-1.0, 0.5, 0.0), rotation=(0.0, 0.0, math.radians(30.0)))
    c.add_uv_sphere(scene, "Sphere", 0.55, c.node_material("Sphere", "ShaderNodeBsdfPrincipled"),
                    location=(0.9, 0.1, 0.55))
    c.add_light(scene, "Point", "POINT", 150.0, (-2.2, -0.8, 1.8), color=(1.0, 0.7, 0.45),
                shadow_soft_size=0.1)
    c.add_light(scene, "Spot", "SPOT", 400.0, (2.2, -1.5, 3.0), target=(0.6, 0.2, 0.0),
                color=(0.45, 0.65, 1.0), spot_size=math.radians(40.0), spot_blend=0.25,
                shadow_soft_size=0.1)
    c.add_light(scene, "Area", "AREA", 120.0, (0.0, 2.5, 3.0), target=(0.9, 0.1, 0.55),
                color=(0.7, 1.0, 0.6), shape="SQUARE", size=1.5)
    c.add_light(scene, "Sun", "SUN", 1.2, (-3.0, 3.0, 3.0), target=(0.0, 0.0, 0.0),
                color=(1.0, 0.95, 0.9), angle=math.radians(2.0))
    c.add_camera(scene, c.STAGE_CAMERA_LOCATION, c.STAGE_CAMERA_TARGET)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
