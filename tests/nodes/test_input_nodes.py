"""Input nodes against Cycles: Texture Coordinate, UV Map, Attribute, Geometry (harness.py)."""

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
}


@pytest.fixture(scope="module")
def images():
    return render_cases(CASES)


@pytest.mark.parametrize("name", list(CASES))
def test_input_node_agrees_with_cycles(images, name):
    ref, ours = images[name]
    assert np.abs(ref).max() > 0 or name.endswith("missing") or name == "geometry Backfacing"
    assert_agree(name, ref, ours, edge_fraction=0.02)
