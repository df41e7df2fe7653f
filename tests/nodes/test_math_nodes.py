"""Converter and vector nodes against Cycles (harness.py): Math, Vector Math, Map Range, Clamp,
Separate/Combine XYZ and Color, RGB to BW, Blackbody, Wavelength, Mapping.

Every operation and option, on inputs that vary over the plane (affine in the
generated coordinates, so each case sweeps a range of values: signs, zero
crossings, poles) and on constant edge values (division by zero, logarithms and
powers of negatives, equal ranges...), which both engines fold ahead of time.
Emission cannot be negative, so a float result r is shown as the colour
(r, -r, 0) and a vector result as two cases, v and -v.
"""

import numpy as np
import pytest

from .harness import assert_agree, render_cases

# Agreement: Cycles computes in single precision, MC Engine in double, on the same exact
# inputs (see _sweep).  Measured (tools: this file's cases, |MC Engine - Cycles| per pixel):
# worst 2.9e-6 (Refract near total reflection), every other case within 6e-7 (relative, or
# absolute where that is smaller); no pixel of a discontinuous operation falls on the other side
# of a step.  Bounds: a pixel agrees within REL relative or ABS absolute.
REL = 1e-5
ABS = 1e-6
LEVELS = 16              # values per sweep axis


def _node(nt, idname, inputs=(), **props):
    node = nt.nodes.new("ShaderNode" + idname)
    for key, value in props.items():
        setattr(node, key, value)
    for index, value in inputs:
        socket = node.inputs[index]
        if hasattr(value, "is_output"):
            nt.links.new(value, socket)
        elif value is not None:
            socket.default_value = value
    return node


def _coords(nt):
    return _node(nt, "TexCoord").outputs["Generated"]


def _sweep(nt, axis, lo, hi):
    """A float running from lo to hi in 16 steps across the plane along axis 0 (x) or 1 (y):
    lo + (hi - lo) floor(16 g) / 16, so that (with dyadic bounds) every value is exact in
    both engines and the comparison sees the node alone, not the rounding of its inputs."""
    sep = _node(nt, "SeparateXYZ", [(0, _coords(nt))])
    cell = _node(nt, "Math", [(0, sep.outputs[axis]), (1, float(LEVELS))], operation="MULTIPLY")
    cell = _node(nt, "Math", [(0, cell.outputs[0])], operation="FLOOR")
    return _node(nt, "Math", [(0, cell.outputs[0]), (1, (hi - lo) / LEVELS), (2, lo)],
                 operation="MULTIPLY_ADD").outputs[0]


def _vsweep(nt, scale, offset):
    """A vector stepping over the plane: floor(16 g + 1/2) scale / 16 + offset (g: generated;
    its z, 0.5 on a plane, is then 8.5 before rounding, far from a step)."""
    cell = _node(nt, "VectorMath", [(0, _coords(nt)), (1, (float(LEVELS),) * 3), (2, (0.5,) * 3)],
                 operation="MULTIPLY_ADD")
    cell = _node(nt, "VectorMath", [(0, cell.outputs[0])], operation="FLOOR")
    return _node(nt, "VectorMath", [(0, cell.outputs[0]), (1, tuple(v / LEVELS for v in scale)),
                                    (2, offset)], operation="MULTIPLY_ADD").outputs[0]


def _show_float(nt, value):
    neg = _node(nt, "Math", [(0, value), (1, -1.0)], operation="MULTIPLY").outputs[0]
    return _node(nt, "CombineXYZ", [(0, value), (1, neg)]).outputs[0]


def _show_vector(nt, value, negate):
    if not negate:
        return value
    return _node(nt, "VectorMath", [(0, value), (3, -1.0)], operation="SCALE").outputs[0]


def _value(v):
    """An input: a constant, or ('x'|'y', lo, hi) for a sweep."""
    if isinstance(v, tuple) and v and isinstance(v[0], str):
        axis = 0 if v[0] == "x" else 1
        return lambda nt: _sweep(nt, axis, v[1], v[2])
    return lambda nt: v


def _math(op, a, b=0.5, c=0.5, clamp=False):
    fa, fb, fc = _value(a), _value(b), _value(c)

    def build(nt):
        node = _node(nt, "Math", [(0, fa(nt)), (1, fb(nt)), (2, fc(nt))], operation=op,
                     use_clamp=clamp)
        return _show_float(nt, node.outputs[0])
    return build


X, Y = ("x", -3.0, 3.0), ("y", -2.0, 2.0)
MATH = {
    "ADD": (X, Y), "SUBTRACT": (X, Y), "MULTIPLY": (X, Y), "DIVIDE": (X, ("y", -1.0, 1.5)),
    "MULTIPLY_ADD": (X, Y, 0.75), "POWER": (("x", -2.0, 2.0), ("y", -3.0, 3.0)),
    "LOGARITHM": (("x", -1.0, 5.0), ("y", 0.25, 3.25)), "SQRT": (("x", -1.0, 4.0),),
    "INVERSE_SQRT": (("x", -1.0, 4.0),), "ABSOLUTE": (X,), "EXPONENT": (X,),
    "MINIMUM": (X, Y), "MAXIMUM": (X, Y), "LESS_THAN": (X, Y), "GREATER_THAN": (X, Y),
    "SIGN": (X,), "COMPARE": (X, Y, 0.3), "SMOOTH_MIN": (X, Y, 0.8), "SMOOTH_MAX": (X, Y, 0.8),
    "ROUND": (("x", -3.25, 3.25),), "FLOOR": (("x", -3.25, 3.25),), "CEIL": (("x", -3.25, 3.25),),
    "TRUNC": (("x", -3.25, 3.25),), "FRACT": (("x", -3.25, 3.25),),
    "MODULO": (("x", -5.0, 5.0), ("y", -2.0, 2.5)), "FLOORED_MODULO": (("x", -5.0, 5.0), ("y", -2.0, 2.5)),
    "WRAP": (("x", -5.0, 5.0), 1.5, -0.5), "SNAP": (("x", -5.0, 5.0), ("y", 0.25, 2.25)),
    "PINGPONG": (("x", -5.0, 5.0), ("y", 0.5, 2.0)), "SINE": (("x", -4.0, 4.0),),
    "COSINE": (("x", -4.0, 4.0),), "TANGENT": (("x", -1.25, 1.25),), "ARCSINE": (("x", -1.5, 1.5),),
    "ARCCOSINE": (("x", -1.5, 1.5),), "ARCTANGENT": (("x", -5.0, 5.0),),
    "ARCTAN2": (("x", -1.0, 1.0), ("y", -1.0, 1.0)), "SINH": (X,), "COSH": (X,), "TANH": (X,),
    "RADIANS": (("x", -400.0, 400.0),), "DEGREES": (X,),
}
# Constant edge values (folded ahead of time by both engines): (op, a, b, c).
MATH_EDGES = [
    ("DIVIDE", 3.0, 0.0, 0.0), ("POWER", -2.0, 3.0, 0.0), ("POWER", -2.0, 0.5, 0.0),
    ("POWER", 0.0, -1.0, 0.0), ("POWER", 0.0, 0.0, 0.0), ("POWER", -2.0, 1e10, 0.0),
    ("POWER", -2.0, -2.0, 0.0), ("POWER", 10.0, 30.0, 0.0), ("LOGARITHM", -1.0, 2.0, 0.0),
    ("LOGARITHM", 8.0, 1.0, 0.0), ("LOGARITHM", 8.0, -2.0, 0.0), ("LOGARITHM", 0.0, 2.0, 0.0),
    ("SQRT", -4.0, 0.0, 0.0), ("INVERSE_SQRT", 0.0, 0.0, 0.0), ("MODULO", 5.0, 0.0, 0.0),
    ("FLOORED_MODULO", -5.0, 0.0, 0.0), ("FLOORED_MODULO", -5.5, 2.0, 0.0), ("MODULO", -5.5, 2.0, 0.0),
    ("WRAP", 3.0, 2.0, 2.0), ("SNAP", 3.3, 0.0, 0.0), ("PINGPONG", 3.0, 0.0, 0.0),
    ("ARCTAN2", 0.0, 0.0, 0.0), ("SIGN", 0.0, 0.0, 0.0), ("SMOOTH_MIN", 1.0, 2.0, 0.0),
    ("COMPARE", 1.0, 1.0 + 1e-8, 0.0), ("ARCSINE", 2.0, 0.0, 0.0), ("ARCCOSINE", -2.0, 0.0, 0.0),
    ("MULTIPLY", 1e20, 1e15, 0.0), ("EXPONENT", 80.0, 0.0, 0.0), ("ROUND", -2.5, 0.0, 0.0),
    ("FRACT", -1e8 - 0.5, 0.0, 0.0), ("TRUNC", -2.7, 0.0, 0.0),
]


def _vector_math(op, a, b, c=None, scale=1.0, output="Vector", negate=False):
    def build(nt):
        node = _node(nt, "VectorMath", [(0, a(nt)), (1, b(nt)), (2, c(nt) if c else None),
                                        (3, scale)],
                     operation=op)
        if output == "Value":
            return _show_float(nt, node.outputs["Value"])
        return _show_vector(nt, node.outputs["Vector"], negate)
    return build


def _va(nt):
    return _vsweep(nt, (6.0, -4.0, 2.0), (-3.0, 2.0, -0.5))


def _vb(nt):
    return _vsweep(nt, (-2.0, 3.0, 1.0), (1.25, -1.0, 0.25))


def _vc(nt):
    return _vsweep(nt, (0.5, -1.0, 0.0), (-0.75, 0.25, -0.875))


def _const(v):
    return lambda nt: v


VECTOR_OPS = ["ADD", "SUBTRACT", "MULTIPLY", "DIVIDE", "MULTIPLY_ADD", "CROSS_PRODUCT", "PROJECT",
              "REFLECT", "REFRACT", "FACEFORWARD", "SCALE", "NORMALIZE", "ABSOLUTE", "POWER", "SIGN",
              "MINIMUM", "MAXIMUM", "FLOOR", "CEIL", "FRACTION", "MODULO", "WRAP", "SNAP", "SINE",
              "COSINE", "TANGENT"]
VALUE_OPS = ["DOT_PRODUCT", "DISTANCE", "LENGTH"]


def _map_range(interp, clamp, vector=False, fmin=0.2, fmax=0.8, tmin=-1.0, tmax=3.0, steps=4.0,
               negate=False):
    def build(nt):
        if vector:
            value = _vsweep(nt, (1.5, -1.5, 0.0), (-0.25, 1.25, 0.5))
            steps3 = steps if isinstance(steps, tuple) else (steps,) * 3
            node = _node(nt, "MapRange", [(6, value), (7, fmin), (8, fmax), (9, tmin), (10, tmax),
                                          (11, steps3)], data_type="FLOAT_VECTOR",
                         interpolation_type=interp, clamp=clamp)
            return _show_vector(nt, node.outputs["Vector"], negate)
        value = _sweep(nt, 0, -0.25, 1.25)
        node = _node(nt, "MapRange", [(0, value), (1, fmin), (2, fmax), (3, tmin), (4, tmax),
                                      (5, steps)], interpolation_type=interp, clamp=clamp)
        return _show_float(nt, node.outputs["Result"])
    return build


def _clamp(kind, lo, hi):
    def build(nt):
        node = _node(nt, "Clamp", [(0, _sweep(nt, 0, -2.0, 3.0)), (1, lo), (2, hi)], clamp_type=kind)
        return _show_float(nt, node.outputs[0])
    return build


def _separate_xyz(output):
    def build(nt):
        node = _node(nt, "SeparateXYZ", [(0, _va(nt))])
        return _show_float(nt, node.outputs[output])
    return build


def _combine_xyz(nt):
    return _node(nt, "CombineXYZ", [(0, _sweep(nt, 0, 0.125, 2.125)), (1, _sweep(nt, 1, 0.0, 3.0)),
                                    (2, 0.4)]).outputs[0]


def _colour(nt, lo=(0.0, 0.0, 0.25), hi=(1.25, 1.0, 0.25)):
    """A colour sweeping hues and values (x -> red, y -> green)."""
    return _node(nt, "CombineXYZ", [(0, _sweep(nt, 0, lo[0], hi[0])), (1, _sweep(nt, 1, lo[1], hi[1])),
                                    (2, lo[2])]).outputs[0]


def _separate_color(mode, output):
    def build(nt):
        node = _node(nt, "SeparateColor", [(0, _colour(nt))], mode=mode)
        return _show_float(nt, node.outputs[output])
    return build


def _combine_color(mode, lo, hi, third):
    def build(nt):
        node = _node(nt, "CombineColor", [(0, _sweep(nt, 0, lo, hi)), (1, _sweep(nt, 1, 0.0, 1.0)),
                                          (2, third)], mode=mode)
        return node.outputs[0]
    return build


def _rgb_to_bw(nt):
    return _node(nt, "RGBToBW", [(0, _colour(nt, (0.0, 0.5, 0.75), (2.0, 0.0, 0.75)))]).outputs[0]


def _value_node(nt):
    """A Value node (its value is its output socket's) added to a sweep."""
    value = _node(nt, "Value")
    value.outputs[0].default_value = 0.375
    return _show_float(nt, _node(nt, "Math", [(0, value.outputs[0]), (1, _sweep(nt, 0, -1.0, 1.0))],
                                 operation="ADD").outputs[0])


def _rgb_node(nt):
    """An RGB node's colour (its output socket's) times a sweep."""
    rgb = _node(nt, "RGB")
    rgb.outputs[0].default_value = (0.25, 0.625, 1.5, 1.0)
    return _node(nt, "VectorMath", [(0, rgb.outputs[0]), (3, _sweep(nt, 1, 0.5, 2.0))],
                 operation="SCALE").outputs[0]


def _normal_node(output, direction, linked=True, negate=False):
    """A Normal node with its vector (kept in its output socket) set to ``direction`` (not
    of unit length: Cycles normalises it), the Normal input a vector stepping over the plane
    (or its unlinked (0, 0, 1)); its Dot shown with its negative part, or its Normal."""
    def build(nt):
        node = _node(nt, "Normal")
        node.outputs["Normal"].default_value = direction
        if linked:
            nt.links.new(_vsweep(nt, (2.0, -1.5, 0.0), (-1.0, 0.75, 0.25)), node.inputs["Normal"])
        if output == "Dot":
            return _show_float(nt, node.outputs["Dot"])
        return _show_vector(nt, node.outputs["Normal"], negate)
    return build


def _blackbody(lo, hi=None):
    def build(nt):
        t = lo if hi is None else _sweep(nt, 0, lo, hi)
        return _node(nt, "Blackbody", [(0, t)]).outputs[0]
    return build


def _wavelength(lo, hi=None):
    def build(nt):
        w = lo if hi is None else _sweep(nt, 0, lo, hi)
        return _node(nt, "Wavelength", [(0, w)]).outputs[0]
    return build


def _mapping(kind, scale=(1.5, -0.5, 2.0), negate=False):
    def build(nt):
        node = _node(nt, "Mapping", [(0, _va(nt)), (1, (0.3, -0.2, 0.1)), (2, (0.4, -0.7, 1.1)),
                                     (3, scale)], vector_type=kind)
        return _show_vector(nt, node.outputs[0], negate)
    return build


def _hidden_output(nt):
    """Vector Math's Value output, hidden for Add, into a Math node: the link carries nothing
    and the Math node uses its own unlinked value (0.5)."""
    vm = _node(nt, "VectorMath", [(0, _va(nt)), (1, _vb(nt))], operation="ADD")
    add = _node(nt, "Math", [(1, 0.25)], operation="ADD")
    hidden = next(s for s in vm.outputs if s.identifier == "Value")
    nt.links.new(hidden, add.inputs[0])
    return _show_float(nt, add.outputs[0])


MATH_CASES = {
    **{f"math {op}": _math(op, *args) for op, args in MATH.items()},
    **{f"math {op} {a} {b} {c}": _math(op, a, b, c) for op, a, b, c in MATH_EDGES},
    "math ADD clamp": _math("ADD", X, Y, clamp=True),
    "math SINE clamp": _math("SINE", ("x", -4.0, 4.0), clamp=True),
}
VECTOR_MATH_CASES = {
    **{f"vector math {op}{' -' if neg else ''}": _vector_math(op, _va, _vb, _vc, 0.7, negate=neg)
       for op in VECTOR_OPS for neg in (False, True)},
    **{f"vector math {op}": _vector_math(op, _va, _vb, output="Value") for op in VALUE_OPS},
    "vector math REFRACT total reflection": _vector_math("REFRACT", _va, _vb, scale=3.0),
    "vector math DIVIDE by zero": _vector_math("DIVIDE", _va, _const((0.0, 2.0, 0.0))),
    "vector math MODULO by zero": _vector_math("MODULO", _va, _const((0.0, 1.5, 0.0))),
    "vector math NORMALIZE zero": _vector_math("NORMALIZE", _const((0.0, 0.0, 0.0)), _vb),
    "vector math PROJECT on zero": _vector_math("PROJECT", _va, _const((0.0, 0.0, 0.0))),
    "vector math POWER of negatives": _vector_math("POWER", _const((-2.0, -2.0, 0.0)),
                                                   _const((3.0, 0.5, -1.0)), negate=True),
    "vector math hidden Value output": _hidden_output,
    "vector math WRAP empty range": _vector_math("WRAP", _va, _const((1.0, 1.0, 1.0)),
                                                 _const((1.0, 1.0, 1.0))),
}
MAP_RANGE_CASES = {
    **{f"map range {i} clamp {c}": _map_range(i, c) for i in ("LINEAR", "STEPPED", "SMOOTHSTEP",
                                                              "SMOOTHERSTEP") for c in (False, True)},
    **{f"map range {i} reversed from": _map_range(i, True, fmin=0.9, fmax=0.1)
       for i in ("LINEAR", "STEPPED", "SMOOTHSTEP", "SMOOTHERSTEP")},
    "map range LINEAR reversed to clamp": _map_range("LINEAR", True, tmin=2.0, tmax=-1.0),
    "map range LINEAR empty from clamp": _map_range("LINEAR", True, fmin=0.5, fmax=0.5, tmin=2.0),
    "map range LINEAR empty from": _map_range("LINEAR", False, fmin=0.5, fmax=0.5, tmin=2.0),
    "map range STEPPED 0 steps": _map_range("STEPPED", False, steps=0.0),
    "map range STEPPED 2.5 steps": _map_range("STEPPED", False, steps=2.5),
    **{f"map range vector {i} clamp {c}{' -' if n else ''}":
       _map_range(i, c, vector=True, fmin=(0.2, 0.9, 0.0), fmax=(0.8, 0.1, 1.0),
                  tmin=(-1.0, 0.5, 2.0), tmax=(3.0, 0.0, -2.0), steps=(4.0, 2.0, 0.0), negate=n)
       for i in ("LINEAR", "STEPPED", "SMOOTHSTEP", "SMOOTHERSTEP") for c in (False, True)
       for n in (False, True)},
    "map range vector empty from": _map_range("LINEAR", True, vector=True, fmin=(0.5, 0.2, 0.0),
                                              fmax=(0.5, 0.8, 1.0), tmin=(1.0, 0.0, 0.0),
                                              tmax=(2.0, 1.0, 1.0)),
}
CLAMP_CASES = {
    "clamp MINMAX": _clamp("MINMAX", -0.5, 1.5), "clamp MINMAX min > max": _clamp("MINMAX", 1.5, -0.5),
    "clamp RANGE": _clamp("RANGE", -0.5, 1.5), "clamp RANGE min > max": _clamp("RANGE", 1.5, -0.5),
}
COLOR_CASES = {
    **{f"separate xyz {o}": _separate_xyz(o) for o in ("X", "Y", "Z")},
    "combine xyz": _combine_xyz,
    **{f"separate color {m} {o}": _separate_color(m, o) for m in ("RGB", "HSV", "HSL")
       for o in ("Red", "Green", "Blue")},
    "combine color RGB": _combine_color("RGB", 0.0, 1.5, 0.3),
    "combine color HSV": _combine_color("HSV", 0.0, 1.0, 0.8),
    "combine color HSV hue outside": _combine_color("HSV", -0.4, 1.6, 0.8),
    "combine color HSL": _combine_color("HSL", 0.0, 1.0, 0.4),
    "combine color HSL light": _combine_color("HSL", -0.25, 1.25, 0.8),
    "rgb to bw": _rgb_to_bw,
    "value node": _value_node, "rgb node": _rgb_node,
    "normal node dot": _normal_node("Dot", (0.5, -1.0, 1.25)),
    "normal node dot unlinked": _normal_node("Dot", (0.5, -1.0, 1.25), linked=False),
    "normal node normal": _normal_node("Normal", (0.5, -1.0, 1.25)),
    "normal node normal -": _normal_node("Normal", (0.5, -1.0, 1.25), negate=True),
    "blackbody cold": _blackbody(300.0, 1600.0), "blackbody warm": _blackbody(1400.0, 4000.0),
    "blackbody hot": _blackbody(3500.0, 14000.0), "blackbody 6500": _blackbody(6500.0),
    "blackbody 0": _blackbody(0.0), "blackbody 1e6": _blackbody(1e6),
    "wavelength blue": _wavelength(360.0, 500.0), "wavelength green": _wavelength(490.0, 650.0),
    "wavelength red": _wavelength(640.0, 800.0), "wavelength 379": _wavelength(379.0),
    "wavelength 779": _wavelength(779.0), "wavelength 780": _wavelength(780.0),
    **{f"mapping {k}{' -' if n else ''}": _mapping(k, negate=n)
       for k in ("POINT", "TEXTURE", "VECTOR", "NORMAL") for n in (False, True)},
    **{f"mapping {k} zero scale{' -' if n else ''}": _mapping(k, (0.0, 2.0, 1.0), negate=n)
       for k in ("TEXTURE", "NORMAL") for n in (False, True)},
}
CASES = {**MATH_CASES, **VECTOR_MATH_CASES, **MAP_RANGE_CASES, **CLAMP_CASES, **COLOR_CASES}
@pytest.fixture(scope="module")
def images():
    return render_cases(CASES)


@pytest.mark.parametrize("name", list(CASES))
def test_converter_node_agrees_with_cycles(images, name):
    ref, ours = images[name]
    assert_agree(name, ref, ours, rel=REL, abs_tol=ABS)


def test_sweeps_vary(images):
    """Each sweep shows a range of values (a mistake in building the cases, or a node both
    engines ignore, would compare two uniform images)."""
    uniform = [name for name, (ref, _ours) in images.items()
               if name in SWEEPS and np.ptp(ref) == 0.0]
    assert not uniform


SWEEPS = [name for name in CASES if name not in {f"math {op} {a} {b} {c}" for op, a, b, c in MATH_EDGES}
          and not any(w in name for w in ("zero", "empty", "hidden", "blackbody 6500", "blackbody 0",
                                          "blackbody 1e6", "wavelength 7", "wavelength 3"))]
