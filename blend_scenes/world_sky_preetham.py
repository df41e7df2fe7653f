"""A Sky Texture world of the legacy Preetham type as the only light.

Tests the Preetham sky (Perez functions of the view's zenith angle and its angle from the
sun, fitted by turbidity; no sun disc) precomputed into the sky image, read by direction,
and importance-sampled from the world's map with MIS: a smooth sky that is brightest around
a low sun and towards the horizon, soft shadows, the sky seen above the horizon.

The stage (floor, cube, sphere, block) under a Preetham Sky Texture of turbidity 3 with its
sun 25 deg up, on the camera's left (Sun Direction normalised by Blender's sync), into a
Background of strength 1. Camera lowered as in ``world_sky`` so that the sky above the
horizon fills the top of the frame. Bounces 4, diffuse 4.

Run: .venv/bin/python blend_scenes/world_sky_preetham.py
"""
import math

import _common as c

ELEVATION = math.radians(25.0)
AZIMUTH = math.radians(340.0)


def build(scene):
    world = c.set_world(scene, (0.0, 0.0, 0.0), strength=1.0)
    tree = world.node_tree
    direction = (math.cos(ELEVATION) * math.cos(AZIMUTH), math.cos(ELEVATION) * math.sin(AZIMUTH),
                 math.sin(ELEVATION))
    sky = c.shader_node(tree, "ShaderNodeTexSky", location=(-300.0, 0.0),
                        sky_type="PREETHAM", turbidity=3.0, sun_direction=direction)
    tree.links.new(sky.outputs["Color"], tree.nodes["Background"].inputs["Color"])
    c.set_bounces(scene, 4, 4)
    c.add_horizon_stage(scene)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
