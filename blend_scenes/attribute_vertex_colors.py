"""Vertex colours: colour attributes of both kinds read by the Color Attribute and
Attribute nodes into lit materials.

The two kinds of colour attribute Blender users have: byte colours on face corners (what
Vertex Paint creates: stored as 8-bit sRGB, decoded to linear per corner before
interpolation) and float colours on points (what geometry nodes' Store Named Attribute
writes: linear, shared by the faces around a vertex).

* ``Floor``: the stage floor as a 24 x 24 grid of 1 m quads with a float point-domain
  colour attribute ``Tint`` (a smooth warm/cool gradient with ripples, linear values in
  0.1 .. 0.8), read by an Attribute node (Geometry, ``Tint``, its Color) into a Diffuse
  BSDF.
* ``Painted``: a smooth 64x32 UV sphere r 0.6 at (0.85, 0.1, 0.6) whose default colour
  attribute ``Color`` is a byte corner-domain one painted in patches (8 x 4 patches of
  saturated colours, every corner of a face slightly different) with alpha in 0.2 .. 1;
  a Color Attribute node with no name (the mesh's default attribute) gives the Principled
  BSDF (defaults) its Base Color, and the Alpha output its Roughness.
* ``Block``: a 1 m cube at (-1.0, 0.4, 0), turned 30 deg, with a byte corner-domain
  attribute ``Paint`` (every face a colour, each corner a shade of it), read by name by an
  Attribute node into a Diffuse BSDF.
* ``Key`` square area light 2.5 m, 250 W, front left; world (0.15, 0.17, 0.2).

Bounces 4/4.

Run: .venv/bin/python blend_scenes/attribute_vertex_colors.py
"""
import math

import _common as c

FLOOR_CELLS = 24


def _attribute_material(name, bsdf, node_type, **node_values):
    """``bsdf`` whose colour comes from an attribute node's Color output (a Principled
    BSDF also takes its Roughness from the node's Alpha)."""
    material = c.node_material(name, bsdf)
    tree = material.node_tree
    shader = next(n for n in tree.nodes if n.bl_idname == bsdf)
    node = c.shader_node(tree, node_type, location=(-300.0, 0.0), **node_values)
    color_input = "Base Color" if bsdf == "ShaderNodeBsdfPrincipled" else "Color"
    tree.links.new(node.outputs["Color"], shader.inputs[color_input])
    if bsdf == "ShaderNodeBsdfPrincipled":
        tree.links.new(node.outputs["Alpha"], shader.inputs["Roughness"])
    return material


def _tint(x, y):
    """The floor's linear RGBA at (x, y): a smooth gradient with ripples."""
    s = 0.5 + 0.5 * math.sin(0.9 * x + 0.3 * y)
    t = 0.5 + 0.5 * math.cos(0.7 * y - 0.2 * x)
    return (0.1 + 0.7 * s, 0.1 + 0.35 * (s + t), 0.1 + 0.7 * t, 1.0)


def _add_floor(scene):
    n, h = FLOOR_CELLS, c.STAGE_FLOOR_HALF_SIZE
    coords = [-h + 2.0 * h * k / n for k in range(n + 1)]
    vertices = [(x, y, 0.0) for y in coords for x in coords]
    faces = [(j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i)
             for j in range(n) for i in range(n)]
    material = _attribute_material("Floor", "ShaderNodeBsdfDiffuse", "ShaderNodeAttribute",
                                   attribute_type="GEOMETRY", attribute_name="Tint")
    obj = c.add_mesh(scene, "Floor", vertices, faces, material)
    attr = obj.data.color_attributes.new("Tint", "FLOAT_COLOR", "POINT")
    for k, v in enumerate(obj.data.vertices):
        attr.data[k].color = _tint(v.co.x, v.co.y)
    return obj


def _patch_color(face_index, corner, u, v):
    """Linear RGBA of a painted corner: patch (u, v) picks the hue, the corner a shade."""
    hue = (u + 0.37 * v) % 1.0
    rgb = [max(0.0, min(1.0, abs(6.0 * ((hue + k / 3.0) % 1.0) - 3.0) - 1.0)) for k in range(3)]
    shade = 0.55 + 0.15 * ((face_index * 7 + corner * 3) % 4)
    alpha = 0.2 + 0.8 * ((face_index + corner) % 5) / 4.0
    return (*[0.05 + 0.9 * shade * ch for ch in rgb], alpha)


def _paint_corners(obj, name, color_of_face):
    """A byte corner-domain colour attribute ``name``: corner k of face f gets
    ``color_of_face(f, k, centre)`` (colours are given linear; Blender stores them sRGB)."""
    mesh = obj.data
    attr = mesh.color_attributes.new(name, "BYTE_COLOR", "CORNER")
    for face in mesh.polygons:
        for k, loop in enumerate(face.loop_indices):
            attr.data[loop].color = color_of_face(face.index, k, face.center)
    return attr


def build(scene):
    c.set_world(scene, (0.15, 0.17, 0.2))
    _add_floor(scene)

    painted = c.add_uv_sphere(scene, "Painted", 0.6, _attribute_material(
        "Painted", "ShaderNodeBsdfPrincipled", "ShaderNodeVertexColor"), location=(0.85, 0.1, 0.6))

    def sphere_patch(f, k, centre):
        u = (math.atan2(centre.y, centre.x) / (2.0 * math.pi)) % 1.0
        v = math.acos(max(-1.0, min(1.0, centre.z / 0.6))) / math.pi
        return _patch_color(f, k, math.floor(8.0 * u) / 8.0, math.floor(4.0 * v) / 4.0)

    _paint_corners(painted, "Color", sphere_patch)
    painted.data.color_attributes.active_color_name = "Color"
    painted.data.color_attributes.default_color_name = "Color"

    block = c.add_box(scene, "Block", (1.0, 1.0, 1.0), _attribute_material(
        "Block", "ShaderNodeBsdfDiffuse", "ShaderNodeAttribute", attribute_type="GEOMETRY",
        attribute_name="Paint"), location=(-1.0, 0.4, 0.0), rotation=(0.0, 0.0, math.radians(30.0)))
    _paint_corners(block, "Paint", lambda f, k, centre: _patch_color(f, k, f / 6.0, 0.0))

    c.add_light(scene, "Key", "AREA", 250.0, (-2.0, -2.2, 3.0), target=(0.0, 0.2, 0.3),
                shape="SQUARE", size=2.5)
    c.add_camera(scene, c.STAGE_CAMERA_LOCATION, c.STAGE_CAMERA_TARGET)


if __name__ == "__main__":
    raise SystemExit(c.run(build, __file__))
