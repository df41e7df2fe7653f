"""Colour nodes against Cycles (harness.py): Mix in every mode and option, the legacy MixRGB,
ColorRamp in every interpolation and colour mode, RGB/Vector/Float Curves with both
extensions, Hue/Saturation/Value, Invert, Bright/Contrast and Gamma.

Inputs vary over each plane: ``_ramp_color`` runs each channel linearly over the plane
(Generated coordinates through a per-component Mix), so a case sees a range of values,
including values outside [0, 1] and the negative ones that the clamps and special cases
of Cycles' formulas act on.
"""

import numpy as np
import pytest

from .harness import assert_agree, render_cases

BLENDS = ("MIX", "DARKEN", "MULTIPLY", "BURN", "LIGHTEN", "SCREEN", "DODGE", "ADD", "OVERLAY",
          "SOFT_LIGHT", "LINEAR_LIGHT", "DIFFERENCE", "EXCLUSION", "SUBTRACT", "DIVIDE", "HUE",
          "SATURATION", "COLOR", "VALUE")


def _socket(sockets, identifier):
    return next(s for s in sockets if s.identifier == identifier)


def _mix(nt, data_type, **settings):
    node = nt.nodes.new("ShaderNodeMix")
    node.data_type = data_type
    for key, value in settings.items():
        setattr(node, key, value)
    return node


def _ramp_color(nt, lo, hi):
    """A colour running from ``lo`` to ``hi`` per channel across the plane (x, y; the third
    channel sits at its midpoint)."""
    mix = _mix(nt, "VECTOR", factor_mode="NON_UNIFORM", clamp_factor=False)
    nt.links.new(nt.nodes.new("ShaderNodeTexCoord").outputs["Generated"],
                 _socket(mix.inputs, "Factor_Vector"))
    _socket(mix.inputs, "A_Vector").default_value = lo
    _socket(mix.inputs, "B_Vector").default_value = hi
    return _socket(mix.outputs, "Result_Vector")


def _ramp_value(nt, lo, hi):
    """A value running from ``lo`` (bottom left) to ``hi`` (top right) over the plane."""
    mix = _mix(nt, "FLOAT", clamp_factor=False)
    gen = nt.nodes.new("ShaderNodeTexCoord").outputs["Generated"]
    nt.links.new(gen, _socket(mix.inputs, "Factor_Float"))    # mean of (x, y, 0.5): 1/6 .. 5/6
    span = 1.5 * (hi - lo)
    _socket(mix.inputs, "A_Float").default_value = lo - span / 6.0
    _socket(mix.inputs, "B_Float").default_value = lo - span / 6.0 + span
    return _socket(mix.outputs, "Result_Float")


A_LO, A_HI = (-0.2, 0.1, 1.3), (1.2, 0.9, -0.1)
B_LO, B_HI = (1.3, -0.1, 0.2), (-0.2, 1.1, 0.8)


def _mix_color(blend, clamp_factor=True, clamp_result=False, fac=(-0.25, 1.25), b=None):
    def build(nt):
        node = _mix(nt, "RGBA", blend_type=blend, clamp_factor=clamp_factor,
                    clamp_result=clamp_result)
        nt.links.new(_ramp_value(nt, *fac), _socket(node.inputs, "Factor_Float"))
        nt.links.new(_ramp_color(nt, A_LO, A_HI), _socket(node.inputs, "A_Color"))
        if b is None:
            nt.links.new(_ramp_color(nt, B_LO, B_HI), _socket(node.inputs, "B_Color"))
        else:
            _socket(node.inputs, "B_Color").default_value = (*b, 1.0)
        return _socket(node.outputs, "Result_Color")
    return build


def _mix_float(clamp_factor):
    def build(nt):
        node = _mix(nt, "FLOAT", clamp_factor=clamp_factor)
        nt.links.new(_ramp_value(nt, -0.5, 1.5), _socket(node.inputs, "Factor_Float"))
        _socket(node.inputs, "A_Float").default_value = 0.25
        nt.links.new(_ramp_value(nt, 2.0, -1.0), _socket(node.inputs, "B_Float"))
        return _socket(node.outputs, "Result_Float")
    return build


def _mix_vector(factor_mode, clamp_factor):
    def build(nt):
        node = _mix(nt, "VECTOR", factor_mode=factor_mode, clamp_factor=clamp_factor)
        nt.links.new(_ramp_value(nt, -0.5, 1.5), _socket(node.inputs, "Factor_Float"))
        nt.links.new(_ramp_color(nt, (-0.5, 1.5, 0.2), (1.5, -0.5, 0.9)),
                     _socket(node.inputs, "Factor_Vector"))
        _socket(node.inputs, "A_Vector").default_value = (0.1, 0.7, 0.3)
        nt.links.new(_ramp_color(nt, A_LO, A_HI), _socket(node.inputs, "B_Vector"))
        return _socket(node.outputs, "Result_Vector")
    return build


def _mix_rgb(blend, use_clamp=False):
    def build(nt):
        node = nt.nodes.new("ShaderNodeMixRGB")
        node.blend_type = blend
        node.use_clamp = use_clamp
        nt.links.new(_ramp_value(nt, -0.5, 1.5), node.inputs["Fac"])
        nt.links.new(_ramp_color(nt, A_LO, A_HI), node.inputs["Color1"])
        nt.links.new(_ramp_color(nt, B_LO, B_HI), node.inputs["Color2"])
        return node.outputs["Color"]
    return build


def _color_ramp(interpolation, color_mode="RGB", hue="NEAR", output="Color"):
    def build(nt):
        node = nt.nodes.new("ShaderNodeValToRGB")
        ramp = node.color_ramp
        ramp.interpolation = interpolation
        ramp.color_mode = color_mode
        ramp.hue_interpolation = hue
        ramp.elements[0].position = 0.1
        ramp.elements[0].color = (0.9, 0.1, 0.05, 0.2)
        ramp.elements[1].position = 0.85
        ramp.elements[1].color = (0.05, 0.3, 1.0, 1.0)
        mid = ramp.elements.new(0.4)
        mid.color = (0.2, 0.95, 0.3, 0.6)
        nt.links.new(_ramp_value(nt, -0.2, 1.2), node.inputs["Fac"])
        return node.outputs[output]
    return build


def _shape(curve, points):
    """Give a curve map these (x, y) points (it starts with two)."""
    while len(curve.points) < len(points):
        curve.points.new(0.5, 0.5)
    for p, (x, y) in zip(curve.points, points):
        p.location = (x, y)


def _curves(kind, extend, fac=0.8):
    def build(nt):
        idname = {"rgb": "ShaderNodeRGBCurve", "vector": "ShaderNodeVectorCurve",
                  "float": "ShaderNodeFloatCurve"}[kind]
        node = nt.nodes.new(idname)
        mapping = node.mapping
        mapping.extend = extend
        shapes = ([(0.0, 0.1), (0.3, 0.6), (1.0, 0.8)], [(0.1, 0.9), (0.7, 0.2), (0.9, 0.4)],
                  [(-0.5, -0.2), (0.2, 0.1), (1.5, 1.2)], [(0.0, 0.2), (0.5, 0.4), (1.0, 1.0)])
        for curve, points in zip(mapping.curves, shapes):
            _shape(curve, points)
        if kind == "vector":
            for curve in mapping.curves:
                for p in curve.points:
                    p.location = (2.0 * p.location[0] - 1.0, 2.0 * p.location[1] - 1.0)
        mapping.update()
        node.inputs[0].default_value = fac
        if kind == "float":
            nt.links.new(_ramp_value(nt, -0.4, 1.6), node.inputs["Value"])
            return node.outputs["Value"]
        nt.links.new(_ramp_color(nt, (-0.3, 1.4, 0.2), (1.3, -0.4, 0.9)), node.inputs[1])
        return node.outputs[0]
    return build


def _hsv(hue, saturation, value, fac):
    def build(nt):
        node = nt.nodes.new("ShaderNodeHueSaturation")
        node.inputs["Hue"].default_value = hue
        node.inputs["Saturation"].default_value = saturation
        node.inputs["Value"].default_value = value
        node.inputs["Fac"].default_value = fac
        nt.links.new(_ramp_color(nt, A_LO, A_HI), node.inputs["Color"])
        return node.outputs["Color"]
    return build


def _simple(idname, color_input="Color", **inputs):
    def build(nt):
        node = nt.nodes.new(idname)
        for name, value in inputs.items():
            node.inputs[name].default_value = value
        nt.links.new(_ramp_color(nt, (-0.3, 0.2, 2.0), (1.5, 0.8, -0.5)), node.inputs[color_input])
        return node.outputs["Color"]
    return build


def _gamma_linked():
    def build(nt):
        node = nt.nodes.new("ShaderNodeGamma")
        nt.links.new(_ramp_value(nt, -1.0, 3.0), node.inputs["Gamma"])
        nt.links.new(_ramp_color(nt, (0.0, 0.3, 2.0), (1.5, 0.8, 0.1)), node.inputs["Color"])
        return node.outputs["Color"]
    return build


CASES = {
    **{f"mix {b.lower()}": _mix_color(b) for b in BLENDS},
    **{f"mix {b.lower()} unclamped factor": _mix_color(b, clamp_factor=False)
       for b in ("MIX", "BURN", "DODGE", "OVERLAY", "SOFT_LIGHT", "LINEAR_LIGHT", "SCREEN", "HUE",
                 "SATURATION")},
    **{f"mix {b.lower()} clamped result": _mix_color(b, clamp_result=True)
       for b in ("ADD", "DIVIDE", "LINEAR_LIGHT", "SUBTRACT")},
    "mix divide by zero": _mix_color("DIVIDE", b=(0.0, 0.5, -2.0)),
    "mix hue with grey": _mix_color("HUE", b=(0.4, 0.4, 0.4)),
    "mix color with grey": _mix_color("COLOR", b=(0.4, 0.4, 0.4)),
    "mix float": _mix_float(True),
    "mix float unclamped": _mix_float(False),
    "mix vector": _mix_vector("UNIFORM", True),
    "mix vector unclamped": _mix_vector("UNIFORM", False),
    "mix vector non-uniform": _mix_vector("NON_UNIFORM", True),
    "mix vector non-uniform unclamped": _mix_vector("NON_UNIFORM", False),
    "mixrgb mix": _mix_rgb("MIX"),
    "mixrgb multiply clamped": _mix_rgb("MULTIPLY", True),
    "mixrgb linear light": _mix_rgb("LINEAR_LIGHT"),
    "mixrgb value": _mix_rgb("VALUE"),
    **{f"ramp {i.lower()}": _color_ramp(i) for i in ("CONSTANT", "LINEAR", "EASE", "CARDINAL",
                                                      "B_SPLINE")},
    "ramp alpha": _color_ramp("LINEAR", output="Alpha"),
    "ramp constant alpha": _color_ramp("CONSTANT", output="Alpha"),
    **{f"ramp hsv {h.lower()}": _color_ramp("LINEAR", "HSV", h) for h in ("NEAR", "FAR", "CW", "CCW")},
    "ramp hsl": _color_ramp("EASE", "HSL", "NEAR"),
    **{f"curves {k} {e.lower()}": _curves(k, e) for k in ("rgb", "vector", "float")
       for e in ("HORIZONTAL", "EXTRAPOLATED")},
    "curves rgb factor 1.5": _curves("rgb", "EXTRAPOLATED", fac=1.5),
    "hsv default": _hsv(0.5, 1.0, 1.0, 1.0),
    "hsv shifted": _hsv(0.8, 1.6, 0.7, 1.0),
    "hsv desaturate half": _hsv(0.2, 0.3, 1.4, 0.5),
    "hsv factor out of range": _hsv(0.35, 2.0, 1.0, 1.5),
    "invert": _simple("ShaderNodeInvert", Fac=1.0),
    "invert part": _simple("ShaderNodeInvert", Fac=0.3),
    "invert over": _simple("ShaderNodeInvert", Fac=1.7),
    "bright contrast": _simple("ShaderNodeBrightContrast", Bright=0.2, Contrast=0.5),
    "bright contrast negative": _simple("ShaderNodeBrightContrast", Bright=-0.3, Contrast=-0.6),
    "gamma 2.2": _simple("ShaderNodeGamma", Gamma=2.2),
    "gamma 0": _simple("ShaderNodeGamma", Gamma=0.0),
    "gamma linked": _gamma_linked(),
}

# Cases whose output jumps somewhere on the plane (a Constant ramp's steps): a pixel centre
# on the jump may differ.  Measured: none does (every case agrees to 5.4e-6 relative).
EDGES = {"ramp constant": 0.02, "ramp constant alpha": 0.02}
# Cases that are constant on purpose (Gamma 0 is white whatever the colour).
CONSTANT = {"gamma 0": 1.0}


@pytest.fixture(scope="module")
def images():
    return render_cases(CASES)


@pytest.mark.parametrize("name", list(CASES))
def test_color_node_agrees_with_cycles(images, name):
    ref, ours = images[name]
    if name in CONSTANT:
        assert np.allclose(ref, CONSTANT[name])
    else:
        assert np.ptp(ref) > 0.05, "the case shows no variation: it would test nothing"
    assert_agree(name, ref, ours, rel=1e-4, abs_tol=1e-5, edge_fraction=EDGES.get(name, 0.0))
