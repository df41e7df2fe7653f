"""Light linking: lights and an emissive panel that light only some objects (Object >
Shading > Light Linking > Receiver Collection).

Tests that each light reaches the objects its receiver collection lets it reach, and only
them, through its light samples and through the rays that find it, as Cycles renders
Blender's light sets: an Exclude link, Include links (the light then reaches nothing
else), a child collection whose entry's state applies to its objects, two lights sharing a
collection, an emissive mesh linked like a lamp, and a sun with an angle (found by rays
too).  Unlinked light still bounces: a ball lit by one light only lights the floor by its
bounce light.

On the stage floor (Diffuse 0.6, ``_common.add_floor``), three smooth spheres r 0.4 on a
row: ``Red`` (0.8, 0.15, 0.1) at x = -1.1, ``Green`` (0.2, 0.7, 0.25) at x = 0, ``Blue``
(0.15, 0.3, 0.85) at x = 1.1; a sharp Glossy ``Mirror`` (0.9) 4 x 1.4 m standing at y = 1.3
behind them.  Lights and their receiver collections:

* ``Key``: a 1.5 m square area light of 250 W up front left; collection ``NotBlue``:
  ``Blue`` excluded (it lights everything else);
* ``Rim`` and ``Rim2``: spot lights of 400 W and 200 W behind the row (radius 0.1), sharing
  collection ``BlueOnly``: ``Blue`` included (they light it alone);
* ``Glow``: a 1.2 x 0.4 m quad at z = 2.0 over the middle, Emission (1, 0.85,
  0.7) x 5; collection ``NoRedGreen`` whose child
  collection ``RedGreen`` (``Red``, ``Green``) is excluded by its entry's state (the
  objects' own entries in the child say Include);
* ``Sun``: 0.6 W/m^2 with a 10 degree angle from the right; collection ``FloorOnly``: the
  floor included.

The world is (0.05, 0.05, 0.06).  Bounces 6, diffuse 4, glossy 6; Caustics off (the mirror
would throw the lights' caustics on the floor, fireflies that would drown the comparison).

Run: .venv/bin/python blend_scenes/light_linking.py
"""
import _common as c
import bpy


def _receivers(name, *links):
    """A receiver collection of (object or collection, link state) entries."""
    collection = bpy.data.collections.new(name)
    for item, state in links:
        if isinstance(item, bpy.types.Collection):
            collection.children.link(item)
            collection.collection_children[len(collection.children) - 1].light_linking.link_state = state
        else:
            collection.objects.link(item)
            collection.collection_objects[len(collection.objects) - 1].light_linking.link_state = state
    return collection


def build(scene):
    c.set_world(scene, (0.05, 0.05, 0.06))
    c.set_bounces(scene, 6, 4, glossy=6, transmission=6, caustics=False)
    floor = c.add_floor(scene)
    diffuse = c.diffuse_material
    red = c.add_uv_sphere(scene, "Red", 0.4, diffuse("Red", (0.8, 0.15, 0.1)),
                          location=(-1.1, 0.0, 0.4))
    green = c.add_uv_sphere(scene, "Green", 0.4, diffuse("Green", (0.2, 0.7, 0.25)),
                            location=(0.0, 0.0, 0.4))
    blue = c.add_uv_sphere(scene, "Blue", 0.4, diffuse("Blue", (0.15, 0.3, 0.85)),
                           location=(1.1, 0.0, 0.4))
    mirror = c.node_material("Mirror", "ShaderNodeBsdfGlossy", color=(0.9, 0.9, 0.9), roughness=0.0)
    c.add_quad(scene, "Mirror", [(-2.0, 1.3, 0.0), (2.0, 1.3, 0.0), (2.0, 1.3, 1.4), (-2.0, 1.3, 1.4)],
               mirror)

    key = c.add_light(scene, "Key", "AREA", 250.0, (-2.0, -2.2, 3.2), target=(0.0, 0.0, 0.3),
                      shape="SQUARE", size=1.5)
    key.light_linking.receiver_collection = _receivers("NotBlue", (blue, "EXCLUDE"))
    blue_only = _receivers("BlueOnly", (blue, "INCLUDE"))
    for name, energy, x in (("Rim", 400.0, 1.6), ("Rim2", 200.0, 0.4)):
        rim = c.add_light(scene, name, "SPOT", energy, (x, 2.6, 1.8), target=(1.1, 0.0, 0.4),
                          spot_size=0.8, spot_blend=0.3, shadow_soft_size=0.1)
        rim.light_linking.receiver_collection = blue_only
    glow = c.add_quad(scene, "Glow", [(-0.6, 0.2, 2.0), (-0.6, -0.2, 2.0), (0.6, -0.2, 2.0),
                                      (0.6, 0.2, 2.0)],
                      c.emission_material("Glow", (1.0, 0.85, 0.7), 5.0))
    red_green = _receivers("RedGreen", (red, "INCLUDE"), (green, "INCLUDE"))
    glow.light_linking.receiver_collection = _receivers("NoRedGreen", (red_green, "EXCLUDE"))
    sun = c.add_light(scene, "Sun", "SUN", 0.6, (3.0, -1.0, 3.0), target=(0.0, 0.0, 0.0),
                      angle=0.17453)
    sun.light_linking.receiver_collection = _receivers("FloorOnly", (floor, "INCLUDE"))
    c.add_camera(scene, (0.0, -4.6, 1.8), (0.0, 0.3, 0.5), lens_mm=36.0)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
