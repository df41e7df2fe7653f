"""Cornell box: a 2 m diffuse room lit by a square area light, with 8 bounces.

Tests global illumination (colour bleeding from the red and green walls),
soft shadows from an area light, the Diffuse BSDF and the Lambert form of the
Principled BSDF (the two boxes), and a constant grey world seen through the
open front.

Geometry follows the original Cornell box scaled to 2 m: the room spans
x = -1..1 (red wall at x = -1, green at x = +1), y = -1..1 (open front at
y = -1, back wall at y = +1) and z = 0..2.  The camera looks along +Y through
the open front.  All surfaces are flat-shaded quads with normals facing into
the room.

Run: .venv/bin/python blend_scenes/cornell_box.py  (writes cornell_box.blend)
"""
import math

import _common as c

WHITE = (0.73, 0.73, 0.73)
RED = (0.63, 0.065, 0.05)
GREEN = (0.14, 0.45, 0.09)
WORLD_GREY = 0.05

LIGHT_SIZE = 0.5  # square side in metres
LIGHT_HEIGHT = 1.98  # just below the ceiling, so the ceiling does not clip it
LIGHT_POWER_W = 45.0  # walls at about 0.2-1.0 linear

# As in the original: about 40 deg field of view, 2.9 m in front of the opening.
CAMERA_LOCATION = (0.0, -3.9, 1.0)
CAMERA_TARGET = (0.0, 0.0, 1.0)


def build(scene):
    c.set_bounces(scene, total=8, diffuse=8, glossy=8, transmission=8)
    c.set_world(scene, (WORLD_GREY,) * 3)

    white = c.diffuse_material("White", WHITE)
    red = c.diffuse_material("Red", RED)
    green = c.diffuse_material("Green", GREEN)

    # Corners are listed counter-clockwise as seen from inside the room.
    c.add_quad(scene, "Floor", [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], white)
    c.add_quad(scene, "Ceiling", [(-1, -1, 2), (-1, 1, 2), (1, 1, 2), (1, -1, 2)], white)
    c.add_quad(scene, "BackWall", [(-1, 1, 0), (1, 1, 0), (1, 1, 2), (-1, 1, 2)], white)
    c.add_quad(scene, "LeftWall", [(-1, -1, 0), (-1, 1, 0), (-1, 1, 2), (-1, -1, 2)], red)
    c.add_quad(scene, "RightWall", [(1, -1, 0), (1, -1, 2), (1, 1, 2), (1, 1, 0)], green)

    # The two blocks use the Principled-as-Lambert path.
    box_white = c.lambert_principled_material("BoxWhite", WHITE)
    c.add_box(scene, "ShortBox", (0.6, 0.6, 0.6), box_white,
              location=(0.33, -0.38, 0.0), rotation=(0.0, 0.0, math.radians(-17.0)))
    c.add_box(scene, "TallBox", (0.6, 0.6, 1.2), box_white,
              location=(-0.32, 0.28, 0.0), rotation=(0.0, 0.0, math.radians(17.0)))

    # Area lights shine along local -Z, so the unrotated light points down.
    c.add_light(scene, "AreaLight", "AREA", LIGHT_POWER_W, (0.0, 0.0, LIGHT_HEIGHT),
                shape="SQUARE", size=LIGHT_SIZE)

    c.add_camera(scene, CAMERA_LOCATION, CAMERA_TARGET, lens_mm=50.0)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
