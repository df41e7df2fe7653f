"""A Sky Texture world as the only light: Blender 5.0's default sky (Multiple Scattering).

Tests the Sky Texture node (the sky image precomputed from the atmosphere, the sun disc
with its limb darkening, the sky's XYZ converted to the working space), the world's
importance map holding a sun of 0.545 deg (the node's default size) combined with BSDF
sampling by MIS, sharp sun shadows and the sky seen above the horizon.

The stage (floor, cube, sphere, block) under a Sky Texture with its defaults but for the
sun: 20 deg up, rotation 250 deg (it lights the stage from the camera's left, out of the
frame), into a Background of strength 0.1.  Camera lowered as in ``world_hdri_sun`` so
that the sky above the horizon fills the top of the frame.  Bounces 4, diffuse 4.

Run: .venv/bin/python blend_scenes/world_sky.py
"""
import math

import _common as c

STRENGTH = 0.1


def build(scene):
    world = c.set_world(scene, (0.0, 0.0, 0.0), strength=STRENGTH)
    tree = world.node_tree
    sky = c.shader_node(tree, "ShaderNodeTexSky", location=(-300.0, 0.0),
                        sky_type="MULTIPLE_SCATTERING", sun_elevation=math.radians(20.0),
                        sun_rotation=math.radians(250.0))
    tree.links.new(sky.outputs["Color"], tree.nodes["Background"].inputs["Color"])
    c.set_bounces(scene, 4, 4)
    c.add_horizon_stage(scene)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
