"""Input nodes against Cycles: Texture Coordinate, UV Map, Attribute, Geometry, Tangent, Color
Attribute, Fresnel, Layer Weight, Object Info, Camera Data, Light Path (as camera rays see it;
tests/nodes/test_light_path.py follows it through light transport), Light Falloff and
Wireframe (harness.py)."""

import math

import numpy as np
import pytest

from .harness import assert_agree, render_cases


def _coord(output, obj=None):
    def build(nt):
        node = nt.nodes.new("ShaderNodeTexCoord")
        if obj is not None:
            import bpy
            node.object = bpy.data.objects[obj]
        return node.outputs[output]
    return build


def _rotated(ob):
    """A plane turned and scaled, so object, generated and normal coordinates differ from world."""
    ob.rotation_euler = (0.3, -0.2, 0.5)
    ob.scale = (0.9, 1.3, 1.0)


def _second_uv(ob):
    layer = ob.data.uv_layers.new(name="Swapped")
    uv = np.array([d.uv[:] for d in ob.data.uv_layers[0].data])
    for d, (u, v) in zip(layer.data, uv):
        d.uv = (v, 1.0 - u * 0.5)


def _colors(ob):
    attr = ob.data.color_attributes.new("Paint", "BYTE_COLOR", "CORNER")
    for k, d in enumerate(attr.data):
        d.color = ((k % 4) / 3.0, 0.5, 1.0 - (k % 3) / 2.0, 1.0)
    attr = ob.data.color_attributes.new("Heat", "FLOAT_COLOR", "POINT")
    for k, d in enumerate(attr.data):
        d.color = (0.25 * k, 2.0 - 0.5 * k, 0.1, 0.5)


def _uv_map(name):
    def build(nt):
        node = nt.nodes.new("ShaderNodeUVMap")
        node.uv_map = name
        return node.outputs["UV"]
    return build


def _attribute(name, output):
    def build(nt):
        node = nt.nodes.new("ShaderNodeAttribute")
        node.attribute_name = name
        return node.outputs[output]
    return build


def _geometry(output):
    return lambda nt: nt.nodes.new("ShaderNodeNewGeometry").outputs[output]


def _tilted(ob):
    """The plane turned and scaled with its corners raised unevenly: its two triangles lean
    different ways, so that no object axis is normal to them (a radial tangent about X or Y
    on a flat plane along Z would be normal to it, and undefined)."""
    _rotated(ob)
    for v, z in zip(ob.data.vertices, (0.0, 0.3, 0.1, 0.45)):
        v.co.z = z


def _flat_beside_smooth(ob, sharp_edge=False):
    """Two non-planar quads side by side, the left one flat, the right one smooth (with
    ``sharp_edge``, one edge of the left one marked sharp)."""
    import bpy
    me = bpy.data.meshes.new(ob.name)
    me.from_pydata([(-0.5, -0.5, 0.0), (0.0, -0.5, 0.3), (0.0, 0.5, 0.1), (-0.5, 0.5, 0.45),
                    (0.5, -0.5, 0.0), (0.5, 0.5, 0.2)], [], [(0, 1, 2, 3), (1, 4, 5, 2)])
    me.polygons[0].use_smooth, me.polygons[1].use_smooth = False, True
    me.edges[0].use_edge_sharp = sharp_edge
    me.uv_layers.new(name="UVMap")
    ob.data = me
    _rotated(ob)


def _tilted_second_uv(ob):
    _tilted(ob)
    _second_uv(ob)


def _bumpy(ob, split_lines=(("x", 0.0),)):
    """The plane cut into a 4 x 4 grid with its inner vertices raised unevenly, and its edges
    along ``split_lines`` (axis, value) split: the vertices there are doubled, which
    Pointiness welds again and Random Per Island sees as the borders of separate islands."""
    import bmesh
    bm = bmesh.new()
    bm.from_mesh(ob.data)
    bmesh.ops.subdivide_edges(bm, edges=bm.edges[:], cuts=3, use_grid_fill=True)
    heights = np.random.default_rng(7).uniform(-0.15, 0.15, len(bm.verts))
    for v, z in zip(bm.verts, heights):
        if max(abs(v.co.x), abs(v.co.y)) < 0.49:
            v.co.z += z
    on_line = [e for e in bm.edges for axis, value in split_lines
               if all(abs(getattr(v.co, axis) - value) < 1e-6 for v in e.verts)]
    bmesh.ops.split_edges(bm, edges=on_line)
    bm.to_mesh(ob.data)
    bm.free()


def _tangent(direction, axis="Z", uv_map=""):
    def build(nt):
        node = nt.nodes.new("ShaderNodeTangent")
        node.direction_type, node.axis, node.uv_map = direction, axis, uv_map
        return node.outputs["Tangent"]
    return build


def _vertex_color(name, output="Color"):
    def build(nt):
        node = nt.nodes.new("ShaderNodeVertexColor")
        node.layer_name = name
        return node.outputs[output]
    return build


def _default_heat(ob):
    """Colour attributes, the float one ("Heat") Blender's default for rendering."""
    _colors(ob)
    ob.data.color_attributes.render_color_index = ob.data.color_attributes.find("Heat")
    ob.data.color_attributes.active_color_index = ob.data.color_attributes.find("Paint")


def _varying_normal(nt):
    """A (not unit) normal that turns across the plane: its component towards the viewer runs
    from -0.27 (back side) through 0 (edge-on) to 1.07."""
    mix = nt.nodes.new("ShaderNodeMix")
    mix.data_type = "VECTOR"
    mix.clamp_factor = False
    gen = nt.nodes.new("ShaderNodeTexCoord").outputs["Generated"]     # as a factor: its mean
    nt.links.new(gen, next(s for s in mix.inputs if s.identifier == "Factor_Float"))
    next(s for s in mix.inputs if s.identifier == "A_Vector").default_value = (-1.0, 0.4, -0.6)
    next(s for s in mix.inputs if s.identifier == "B_Vector").default_value = (1.0, -0.4, 1.4)
    return next(s for s in mix.outputs if s.identifier == "Result_Vector")


def _fresnel(ior, normal=True):
    def build(nt):
        node = nt.nodes.new("ShaderNodeFresnel")
        node.inputs["IOR"].default_value = ior
        if normal:
            nt.links.new(_varying_normal(nt), node.inputs["Normal"])
        return node.outputs["Fac"]
    return build


def _layer_weight(blend, output, normal=True):
    def build(nt):
        node = nt.nodes.new("ShaderNodeLayerWeight")
        node.inputs["Blend"].default_value = blend
        if normal:
            nt.links.new(_varying_normal(nt), node.inputs["Normal"])
        return node.outputs[output]
    return build


def _flipped(ob):
    """The plane turned over: the camera sees its back."""
    ob.rotation_euler = (math.pi, 0.0, 0.0)


def _object_info(output):
    def build(nt):
        import bpy
        next(m for m in bpy.data.materials if m.node_tree == nt).pass_index = 7
        return nt.nodes.new("ShaderNodeObjectInfo").outputs[output]
    return build


def _dressed(ob):
    """An object with a colour, alpha and pass index of its own."""
    ob.color = (0.3, 0.6, 0.9, 0.45)
    ob.pass_index = 3
    ob.location.z += 0.2


def _camera_data(output):
    return lambda nt: nt.nodes.new("ShaderNodeCameraData").outputs[output]


def _light_path(output):
    return lambda nt: nt.nodes.new("ShaderNodeLightPath").outputs[output]


def _light_falloff(output, strength, smooth=0.0):
    def build(nt):
        node = nt.nodes.new("ShaderNodeLightFalloff")
        node.inputs["Strength"].default_value = strength
        node.inputs["Smooth"].default_value = smooth
        return node.outputs[output]
    return build


def _wireframe(size, pixel_size=False):
    def build(nt):
        node = nt.nodes.new("ShaderNodeWireframe")
        node.use_pixel_size = pixel_size
        node.inputs["Size"].default_value = size
        return node.outputs["Fac"]
    return build


def _grid(ob, cuts=1, tilt=False):
    """The plane cut into a grid of quads (each two triangles), turned; with ``tilt`` its
    vertices raised unevenly, so that the camera sees its triangles at different slants."""
    import bmesh
    bm = bmesh.new()
    bm.from_mesh(ob.data)
    bmesh.ops.subdivide_edges(bm, edges=bm.edges[:], cuts=cuts, use_grid_fill=True)
    if tilt:
        for v, z in zip(bm.verts, np.random.default_rng(3).uniform(-0.2, 0.2, len(bm.verts))):
            v.co.z += z
    bm.to_mesh(ob.data)
    bm.free()
    _rotated(ob)


LIGHT_PATH = ("Is Camera Ray", "Is Shadow Ray", "Is Diffuse Ray", "Is Glossy Ray", "Is Singular Ray",
              "Is Reflection Ray", "Is Transmission Ray", "Is Volume Scatter Ray", "Ray Length",
              "Ray Depth", "Diffuse Depth", "Glossy Depth", "Transparent Depth",
              "Transmission Depth", "Portal Depth")

CASES = {
    **{f"texcoord {o}": _coord(o) for o in ("Generated", "Normal", "UV", "Object", "Camera",
                                             "Window", "Reflection")},
    **{f"texcoord {o} rotated": (_coord(o), _rotated) for o in ("Generated", "Normal", "Object")},
    "texcoord Object of the camera": _coord("Object", obj="cam"),
    "uv map default": _uv_map(""),
    "uv map named": (_uv_map("Swapped"), _second_uv),
    "uv map missing": _uv_map("Nothing"),
    "attribute byte colour": (_attribute("Paint", "Color"), _colors),
    "attribute float colour": (_attribute("Heat", "Color"), _colors),
    "attribute fac": (_attribute("Heat", "Fac"), _colors),
    "attribute alpha": (_attribute("Heat", "Alpha"), _colors),
    "attribute uv as vector": (_attribute("Swapped", "Vector"), _second_uv),
    "attribute missing": _attribute("Nothing", "Color"),
    **{f"geometry {o}": (_geometry(o), _rotated) for o in ("Position", "Normal", "True Normal",
                                                         "Incoming", "Parametric", "Backfacing")},
    # flat faces are shaded with their triangle's own normal, not their polygon's, and
    # smooth ones beside them with the vertex normals, unless an edge is sharp
    "geometry Normal of a non-planar quad": (_geometry("Normal"), _tilted),
    "geometry Normal flat beside smooth": (_geometry("Normal"), _flat_beside_smooth),
    "geometry Normal flat beside smooth, a sharp edge": (
        _geometry("Normal"), lambda ob: _flat_beside_smooth(ob, sharp_edge=True)),
    "geometry Tangent": (_geometry("Tangent"), _tilted),
    "geometry Pointiness": (_geometry("Pointiness"), _bumpy),
    "geometry Random Per Island": (_geometry("Random Per Island"),
                                   lambda ob: _bumpy(ob, (("x", 0.0), ("y", 0.25)))),
    **{f"tangent radial {a}": (_tangent("RADIAL", a), _tilted) for a in "XYZ"},
    "tangent uv map default": (_tangent("UV_MAP"), _tilted),
    "tangent uv map named": (_tangent("UV_MAP", uv_map="Swapped"), _tilted_second_uv),
    "tangent uv map missing": (_tangent("UV_MAP", uv_map="Nothing"), _tilted),
    "color attribute byte": (_vertex_color("Paint"), _colors),
    "color attribute float": (_vertex_color("Heat"), _colors),
    "color attribute alpha": (_vertex_color("Heat", "Alpha"), _colors),
    "color attribute byte alpha": (_vertex_color("Paint", "Alpha"), _colors),
    "color attribute default": (_vertex_color(""), _default_heat),
    "color attribute missing": _vertex_color("Nothing"),
    "color attribute missing alpha": _vertex_color("Nothing", "Alpha"),
    **{f"fresnel ior {ior}": _fresnel(ior) for ior in (1.5, 1.0, 0.6, 40.0, -1.0)},
    "fresnel shading normal": _fresnel(1.5, normal=False),
    "fresnel back face": (_fresnel(1.45), _flipped),
    **{f"layer weight {o.lower()} blend {b}": _layer_weight(b, o)
       for o in ("Fresnel", "Facing") for b in (0.0, 0.3, 0.5, 0.8, 1.0, 1.7, -0.4)},
    "layer weight fresnel back face": (_layer_weight(0.3, "Fresnel"), _flipped),
    "layer weight facing back face": (_layer_weight(0.3, "Facing"), _flipped),
    **{f"object info {o}": (_object_info(o), _dressed)
       for o in ("Location", "Color", "Alpha", "Object Index", "Material Index", "Random")},
    **{f"camera data {o}": (_camera_data(o), _rotated)
       for o in ("View Vector", "View Z Depth", "View Distance")},
    **{f"light path {o}": _light_path(o) for o in LIGHT_PATH},
    # the ray length runs from about 9.5 to 10.5 over the tilted plane
    **{f"light falloff {o} smooth {smooth}": (_light_falloff(o, strength, smooth), _tilted)
       for o, strength in (("Quadratic", 0.6), ("Linear", 0.06), ("Constant", 0.006))
       for smooth in (0.0, 60.0)},
    "wireframe size 0.06": (_wireframe(0.06), _grid),
    "wireframe size 0.08 tilted": (_wireframe(0.08), lambda ob: _grid(ob, 2, tilt=True)),
    "wireframe pixel size 1": (_wireframe(1.0, pixel_size=True), _grid),
    "wireframe pixel size 1.5 tilted": (_wireframe(1.5, pixel_size=True), lambda ob: _grid(ob, 2, tilt=True)),
}

# Outputs that are 0 everywhere on a plane seen by a camera ray, or by definition (IOR 1 and
# Blend 0 reflect nothing; Blend <= 0 makes Facing 0).
ZERO = {"geometry Backfacing", "color attribute missing", "color attribute missing alpha",
        "fresnel ior 1.0", "layer weight fresnel blend 0.0", "layer weight facing blend 0.0",
        "layer weight facing blend -0.4",
        *(f"light path {o}" for o in LIGHT_PATH if o not in ("Is Camera Ray", "Ray Length"))}


@pytest.fixture(scope="module")
def images():
    return render_cases(CASES)


@pytest.mark.parametrize("name", list(CASES))
def test_input_node_agrees_with_cycles(images, name):
    ref, ours = images[name]
    assert np.abs(ref).max() > 0 or name.endswith("missing") or name in ZERO
    # Measured: 4.6e-6 at most, but where a tangent lies nearly along the normal: Cycles
    # projects it (N x normalize(T x N)) in float32, and the cross product cancels.
    loose = name.startswith("tangent radial")      # measured there: 5e-5 at most
    if name.startswith("wireframe"):
        # 0 or 1 at each pixel centre: no pixel differs (measured), though one whose centre
        # lay within float32 rounding of a line's border could
        assert 0.1 < ref.mean() < 0.7, "the lines cover part of the plane"
    assert_agree(name, ref, ours, rel=1e-4, abs_tol=1e-4 if loose else 1e-5)
