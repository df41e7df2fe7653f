"""Instancing and modifiers: collection instances (with a lamp inside), linked
duplicates and the common generate modifiers.

Tests that the renderer sees the *evaluated* scene: every instance of a
collection with its own transform (including a mirrored one), a lamp inside
an instanced collection (one lamp per instance), meshes shared by several
objects, and geometry created by modifiers.  A floor, the light-scene camera,
a grey world of 0.03, one area light and:

* collection ``Lantern`` (not in the scene itself): a small box, a sphere on
  it and a warm point light (radius 0.1) above them; instanced by three empties
  ``LanternA`` (plain), ``LanternB`` (rotated 35 deg, scale 1.3) and
  ``LanternC`` (scale (-1.0, 1.0, 0.8), mirrored);
* ``PostA``, ``PostB``, ``PostC``: three objects sharing one mesh (linked
  duplicates), with different rotations and scales;
* ``ArrayRow``: a 0.3 m cube with an Array modifier (5 copies, relative
  offset 1.6 along X);
* ``MirrorArch``: half an arch mirrored into a whole one by a Mirror modifier
  about X;
* ``SubdivBlob``: a flat-shaded cube with Subdivision Surface (render level 3)
  and Bevel before it;
* ``SolidPanel``: a single quad made 0.15 m thick by a Solidify modifier,
  standing tilted.

Run: .venv/bin/python blend_scenes/instancing_modifiers.py
"""
import math

import _common as c
import bpy

ARCH_HALF_VERTICES = [(0.0, -0.1, 0.9), (0.0, 0.1, 0.9), (0.5, -0.1, 0.7), (0.5, 0.1, 0.7),
                      (0.6, -0.1, 0.0), (0.6, 0.1, 0.0), (0.4, -0.1, 0.0), (0.4, 0.1, 0.0),
                      (0.35, -0.1, 0.55), (0.35, 0.1, 0.55), (0.0, -0.1, 0.7), (0.0, 0.1, 0.7)]
ARCH_HALF_FACES = [(0, 2, 3, 1), (2, 4, 5, 3), (4, 6, 7, 5), (6, 8, 9, 7), (8, 10, 11, 9),
                   (0, 10, 8, 2), (2, 8, 6, 4), (1, 3, 9, 11), (3, 5, 7, 9)]


def _lantern_collection(scene):
    """The instanced collection: kept out of the scene, so only its instances render."""
    lantern = bpy.data.collections.new("Lantern")
    box = c.add_box(scene, "LanternBase", (0.4, 0.4, 0.25),
                    c.diffuse_material("LanternBase", (0.55, 0.4, 0.3)))
    ball = c.add_uv_sphere(scene, "LanternBall", 0.15,
                           c.diffuse_material("LanternBall", (0.9, 0.9, 0.8)),
                           location=(0.0, 0.0, 0.4))
    lamp = c.add_light(scene, "LanternLamp", "POINT", 40.0, (0.15, -0.2, 0.8),
                       color=(1.0, 0.7, 0.4), shadow_soft_size=0.1)
    for obj in (box, ball, lamp):
        scene.collection.objects.unlink(obj)
        lantern.objects.link(obj)
    return lantern


def _instance(scene, name, collection, **transform):
    empty = c.add_empty(scene, name, **transform)
    empty.instance_type = "COLLECTION"
    empty.instance_collection = collection
    return empty


def build(scene):
    c.set_world(scene, (0.03, 0.03, 0.03))
    h = c.STAGE_FLOOR_HALF_SIZE
    c.add_quad(scene, "Floor", [(-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0)],
               c.diffuse_material("Floor", (0.6, 0.6, 0.6)))
    c.add_camera(scene, c.STAGE_CAMERA_LOCATION, c.STAGE_CAMERA_TARGET)
    c.add_light(scene, "KeyArea", "AREA", 200.0, (-1.5, -2.0, 3.5), target=(0.0, 0.3, 0.0),
                shape="SQUARE", size=1.5)
    deg = math.radians

    lantern = _lantern_collection(scene)
    _instance(scene, "LanternA", lantern, location=(-1.9, 1.3, 0.0))
    _instance(scene, "LanternB", lantern, location=(-0.4, 1.9, 0.0),
              rotation=(0.0, 0.0, deg(35.0)), scale=(1.3, 1.3, 1.3))
    _instance(scene, "LanternC", lantern, location=(1.9, 1.4, 0.0), scale=(-1.0, 1.0, 0.8))

    post_material = c.lambert_principled_material("Post", (0.25, 0.45, 0.65))
    post = c.add_box(scene, "PostA", (0.25, 0.25, 0.9), post_material, location=(-2.1, -0.6, 0.0))
    for name, location, rotation, scale in (
            ("PostB", (-1.6, -0.2, 0.0), (0.0, 0.0, deg(30.0)), (1.0, 1.5, 0.7)),
            ("PostC", (-1.1, 0.2, 0.0), (0.0, deg(-20.0), deg(60.0)), (0.8, 0.8, 1.2))):
        duplicate = bpy.data.objects.new(name, post.data)  # shares the mesh
        duplicate.location, duplicate.scale = location, scale
        duplicate.rotation_euler = rotation
        scene.collection.objects.link(duplicate)

    row = c.add_box(scene, "ArrayRow", (0.3, 0.3, 0.3), c.diffuse_material("ArrayRow", (0.8, 0.3, 0.3)),
                    location=(-1.2, -1.6, 0.0), rotation=(0.0, 0.0, deg(10.0)))
    array = row.modifiers.new("Array", "ARRAY")
    array.count = 5
    array.relative_offset_displace = (1.6, 0.0, 0.0)

    arch = c.add_mesh(scene, "MirrorArch", ARCH_HALF_VERTICES, ARCH_HALF_FACES,
                      c.diffuse_material("MirrorArch", (0.85, 0.8, 0.6)),
                      location=(0.4, 0.2, 0.0), rotation=(0.0, 0.0, deg(-15.0)))
    mirror = arch.modifiers.new("Mirror", "MIRROR")
    mirror.use_axis = (True, False, False)
    mirror.use_clip = True

    blob = c.add_box(scene, "SubdivBlob", (0.7, 0.7, 0.7),
                     c.diffuse_material("SubdivBlob", (0.4, 0.75, 0.45)),
                     location=(1.5, -0.7, 0.0), rotation=(0.0, 0.0, deg(25.0)))
    bevel = blob.modifiers.new("Bevel", "BEVEL")
    bevel.width = 0.08
    bevel.segments = 2
    subdiv = blob.modifiers.new("Subdivision", "SUBSURF")
    subdiv.levels = 1
    subdiv.render_levels = 3

    panel = c.add_quad(scene, "SolidPanel", [(-0.4, 0.0, 0.0), (0.4, 0.0, 0.0),
                                             (0.4, 0.0, 0.8), (-0.4, 0.0, 0.8)],
                       c.diffuse_material("SolidPanel", (0.75, 0.75, 0.9)),
                       location=(0.6, -1.4, 0.0), rotation=(deg(-15.0), 0.0, deg(-30.0)))
    solidify = panel.modifiers.new("Solidify", "SOLIDIFY")
    solidify.thickness = 0.15


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
