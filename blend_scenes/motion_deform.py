"""Motion blur of deforming meshes: a shape key, an armature and a modifier, animated.

Tests deformation motion as Cycles renders it: meshes with
``cycles.use_deform_motion`` keep their vertex positions (and normals) at the
object's motion steps, read from the evaluated mesh at each step's subframe,
and a ray meets the triangle interpolated linearly between the two steps
around its time.  `Morph` (a smooth sphere) stretches along x through a shape
key; `Bender` (a subdivided column) bends through a two-bone armature whose
upper bone turns 70 deg per frame; `Twister` (a box) twists through a Simple
Deform modifier whose angle is keyed, while it also slides sideways
(transform and deformation together); `Stiff` is like `Morph` with
deformation blur off (only its shape at the frame is seen).

Frame 1; shutter 1.0, CENTER; camera at (0, -7.5, 3.2) looking at
(0, 0, 0.9); `Key` area light 2.5 m, 350 W; world 0.06.

Run: .venv/bin/python blend_scenes/motion_deform.py
"""
import math

import _common as c
import bpy


def _shape_key_sphere(scene, name, location, color):
    sphere = c.add_uv_sphere(scene, name, 0.5, c.diffuse_material(name, color), location=location,
                             segments=48, rings=24)
    sphere.shape_key_add(name="Basis")
    stretch = sphere.shape_key_add(name="Stretch")
    for point in stretch.data:
        x, y, z = point.co
        point.co = (x * 1.8, y * 0.8, z)
    c.animate(stretch, "value", [(0, 0.0), (2, 1.0)])
    return sphere


def _bender(scene):
    verts, faces = [], []
    rings, sides, height = 12, 16, 2.0
    for r in range(rings + 1):
        for k in range(sides):
            a = 2 * math.pi * k / sides
            verts.append((0.2 * math.cos(a), 0.2 * math.sin(a), height * r / rings))
    for r in range(rings):
        for k in range(sides):
            a, b = r * sides + k, r * sides + (k + 1) % sides
            faces.append((a, b, b + sides, a + sides))
    column = c.add_mesh(scene, "Bender", verts, faces, c.diffuse_material("Bender", (0.2, 0.5, 0.8)),
                        smooth=True, location=(0.0, 0.3, 0.0))
    armature = bpy.data.objects.new("Rig", bpy.data.armatures.new("Rig"))
    armature.location = (0.0, 0.3, 0.0)
    scene.collection.objects.link(armature)
    bpy.context.view_layer.objects.active = armature
    bpy.ops.object.mode_set(mode="EDIT")
    lower = armature.data.edit_bones.new("Lower")
    lower.head, lower.tail = (0, 0, 0), (0, 0, 1.0)
    upper = armature.data.edit_bones.new("Upper")
    upper.head, upper.tail = (0, 0, 1.0), (0, 0, 2.0)
    upper.parent = lower
    bpy.ops.object.mode_set(mode="OBJECT")
    for bone in ("Lower", "Upper"):
        group = column.vertex_groups.new(name=bone)
        for i, (_, _, z) in enumerate(verts):
            w = min(max((z - 0.7) / 0.6, 0.0), 1.0)      # blend over 0.7 .. 1.3 m
            group.add([i], w if bone == "Upper" else 1.0 - w, "REPLACE")
    modifier = column.modifiers.new("Armature", "ARMATURE")
    modifier.object = armature
    column.parent = armature
    column.location = (0.0, 0.0, 0.0)
    pose = armature.pose.bones["Upper"]
    pose.rotation_mode = "XYZ"
    c.animate(pose, "rotation_euler", [(0, (0.0, math.radians(-70.0), 0.0)),
                                       (2, (0.0, math.radians(70.0), 0.0))])
    return column


def build(scene):
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = 1.0
    c.set_world(scene, (0.06, 0.06, 0.06))
    c.add_floor(scene)
    _shape_key_sphere(scene, "Morph", (-1.9, 0.0, 0.6), (0.8, 0.35, 0.2))
    stiff = _shape_key_sphere(scene, "Stiff", (-1.6, 1.8, 0.6), (0.7, 0.7, 0.25))
    stiff.cycles.use_deform_motion = False
    _bender(scene)
    twister = c.add_box(scene, "Twister", (0.5, 0.5, 1.4), c.diffuse_material("Twister", (0.3, 0.7, 0.35)),
                        location=(1.8, 0.0, 0.0))
    twist = twister.modifiers.new("Twist", "SIMPLE_DEFORM")
    twist.deform_method = "TWIST"
    twist.deform_axis = "Z"
    c.animate(twist, "angle", [(0, math.radians(-90.0)), (2, math.radians(90.0))])
    c.animate(twister, "location", [(0, (1.4, 0.0, 0.0)), (2, (2.2, 0.0, 0.0))])
    c.add_light(scene, "Key", "AREA", 350.0, (-1.5, -3.0, 4.0), target=(0.0, 0.3, 0.6), size=2.5)
    c.add_camera(scene, (0.0, -7.5, 3.2), (0.0, 0.0, 0.9))
    scene.frame_set(1)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
