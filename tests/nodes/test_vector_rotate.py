"""Vector Rotate against Cycles (harness.py): every rotation type, plain and inverted, about a
centre off the origin, of a vector that varies across the plane (its world position, scaled
and offset), with an angle that varies too (along the plane's x) where the type takes one; a
non-unit axis (normalised by the node) and a zero axis (the vector unrotated)."""
import numpy as np
import pytest

from .harness import assert_agree, render_cases

TYPES = ("AXIS_ANGLE", "X_AXIS", "Y_AXIS", "Z_AXIS", "EULER_XYZ")


def _rotate(rotation_type, invert=False, axis=(0.3, -0.5, 1.2)):
    def build(nt):
        geometry = nt.nodes.new("ShaderNodeNewGeometry")
        vector = nt.nodes.new("ShaderNodeVectorMath")
        vector.operation = "MULTIPLY_ADD"
        vector.inputs[1].default_value = (0.5, 0.5, 0.5)
        vector.inputs[2].default_value = (0.2, -0.3, 0.4)
        nt.links.new(geometry.outputs["Position"], vector.inputs[0])
        x = nt.nodes.new("ShaderNodeSeparateXYZ")
        nt.links.new(geometry.outputs["Position"], x.inputs[0])
        angle = nt.nodes.new("ShaderNodeMath")
        angle.operation = "MULTIPLY_ADD"
        angle.inputs[1].default_value, angle.inputs[2].default_value = 2.0, 0.7
        nt.links.new(x.outputs["X"], angle.inputs[0])
        node = nt.nodes.new("ShaderNodeVectorRotate")
        node.rotation_type, node.invert = rotation_type, invert
        # By identifier: looking up by name skips the inputs the type hides, which keep values.
        inputs = {s.identifier: s for s in node.inputs}
        inputs["Center"].default_value = (0.1, 0.2, -0.3)
        inputs["Axis"].default_value = axis
        inputs["Rotation"].default_value = (0.4, -0.9, 1.3)
        nt.links.new(vector.outputs["Vector"], inputs["Vector"])
        nt.links.new(angle.outputs["Value"], inputs["Angle"])
        return node.outputs["Vector"]
    return build


CASES = {
    **{f"{t.lower()}{' inverted' if inv else ''}": _rotate(t, inv) for t in TYPES for inv in (False, True)},
    "zero axis": _rotate("AXIS_ANGLE", axis=(0.0, 0.0, 0.0)),
}


@pytest.fixture(scope="module")
def images():
    return render_cases(CASES)


@pytest.mark.parametrize("name", list(CASES))
def test_vector_rotate_agrees_with_cycles(images, name):
    ref, ours = images[name]
    assert np.abs(ref).max() > 0.1
    assert_agree(name, ref, ours, rel=1e-4, abs_tol=1e-5)


def test_rotations_differ(images):
    """The cases are not all the same: inverting a rotation changes it."""
    for t in TYPES:
        plain, inverted = images[t.lower()][0], images[f"{t.lower()} inverted"][0]
        assert np.abs(plain - inverted).max() > 0.05, t
