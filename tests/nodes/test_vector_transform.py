"""Vector Transform against Cycles (harness.py): each type (Point, Vector, Normal) between
each pair of World, Object and Camera space, on planes turned and scaled unevenly (so
that points, directions and normals transform differently), the input varying across the
plane: half the world position plus an offset (not of unit length, so a Normal's
normalisation shows)."""
import numpy as np
import pytest

from .harness import assert_agree, render_cases

SPACES = ("WORLD", "OBJECT", "CAMERA")
TYPES = ("POINT", "VECTOR", "NORMAL")


def _transform(vector_type, src, dst):
    def build(nt):
        geometry = nt.nodes.new("ShaderNodeNewGeometry")
        scale = nt.nodes.new("ShaderNodeVectorMath")
        scale.operation = "MULTIPLY_ADD"
        scale.inputs[1].default_value = (0.5, 0.5, 0.5)
        scale.inputs[2].default_value = (0.2, -0.3, 0.4)
        nt.links.new(geometry.outputs["Position"], scale.inputs[0])
        node = nt.nodes.new("ShaderNodeVectorTransform")
        node.vector_type, node.convert_from, node.convert_to = vector_type, src, dst
        nt.links.new(scale.outputs["Vector"], node.inputs["Vector"])
        return node.outputs["Vector"]
    return build


def _turned(ob):
    ob.rotation_euler = (0.3, -0.2, 0.5)
    ob.scale = (0.9, 1.3, 0.6)


def _mirrored(ob):
    ob.rotation_euler = (0.0, 0.2, -0.4)
    ob.scale = (-1.1, 0.8, 2.0)


CASES = {
    **{f"{t.lower()} {a.lower()} to {b.lower()}": (_transform(t, a, b), _turned)
       for t in TYPES for a in SPACES for b in SPACES},
    **{f"{t.lower()} object to camera, mirrored": (_transform(t, "OBJECT", "CAMERA"), _mirrored)
       for t in TYPES},
}


@pytest.fixture(scope="module")
def images():
    return render_cases(CASES)


@pytest.mark.parametrize("name", list(CASES))
def test_vector_transform_agrees_with_cycles(images, name):
    ref, ours = images[name]
    assert np.abs(ref).max() > 0.1
    assert_agree(name, ref, ours, rel=1e-4, abs_tol=1e-5)


def test_spaces_differ(images):
    """The cases are not all the identity: world -> object changes the point."""
    same, moved = images["point world to world"][0], images["point world to object"][0]
    assert np.abs(same - moved).max() > 0.1
