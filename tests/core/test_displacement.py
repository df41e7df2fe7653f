"""True displacement in the core (``mcengine.displacement``): which vertices move and by what,
the first triangle's evaluation of a shared vertex, the direction of its vertex normal, the
normals afterwards, motion steps.  The comparison with Cycles' own renders is
``tests/nodes/test_true_displacement.py``.

The scene is one unit square of two triangles sharing the edge from vertex 0 to vertex 2,
in the z = 0 plane, facing +z.
"""
import dataclasses

import numpy as np
import pytest

from mcengine.displacement import displace
from mcengine.scene import (
    Geometry,
    Link,
    Material,
    MotionBlur,
    ObjectMotion,
    SceneDescription,
    ShaderNode,
)
from mcengine.shaders import (
    SMOOTH_ATTRIBUTE,
    UNDISPLACED_ATTRIBUTE,
    UNDISPLACED_NORMAL_ATTRIBUTE,
    VERTEX_NORMAL_ATTRIBUTE,
)

SQUARE = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], np.float32)
TRIS = np.array([[0, 1, 2], [0, 2, 3]], np.int32)


def _geometry(uvs=None, smooth=True, vertex_normals=None) -> Geometry:
    up = np.zeros((2, 3, 3), np.float32)
    up[..., 2] = 1.0
    corners = np.broadcast_to(SQUARE[TRIS][..., :2], (2, 3, 2))
    attributes = {SMOOTH_ATTRIBUTE: np.full((2, 3, 1), 1.0 if smooth else 0.0, np.float32)}
    if vertex_normals is not None:
        attributes[VERTEX_NORMAL_ATTRIBUTE] = np.asarray(vertex_normals, np.float32)[TRIS]
    return Geometry(vertices=SQUARE.copy(), triangles=TRIS.copy(), normals=up,
                    uvs=np.asarray(corners if uvs is None else uvs, np.float32),
                    material_index=np.zeros(2, np.int32), object_index=np.zeros(2, np.int32),
                    object_names=["square"], attributes=attributes)


def _displaced_by(height_nodes, method="DISPLACEMENT") -> Material:
    """A diffuse material displaced along the normal by the Value of the last of
    ``height_nodes`` (midlevel 0, scale 1)."""
    k = len(height_nodes)
    nodes = list(height_nodes) + [
        ShaderNode("Displacement", {"Height": Link(k - 1, "Value" if height_nodes[-1].type != "SeparateXYZ"
                                                    else "X"), "Midlevel": 0.0, "Scale": 1.0}),
        ShaderNode("BsdfDiffuse")]
    return Material(name="displaced", nodes=nodes, surface=Link(k + 1, "BSDF"),
                    displacement=Link(k, "Displacement"), displacement_method=method)


def _constant(h):
    return [ShaderNode("Value", props={"value": h})]


def _coordinate(output):
    """The x component of a Texture Coordinate output."""
    return [ShaderNode("TexCoord"), ShaderNode("SeparateXYZ", {"Vector": Link(0, output)})]


def _scene(material, geometry=None, **kw) -> SceneDescription:
    return SceneDescription(geometry=geometry or _geometry(), materials=[material], **kw)


def test_a_scene_without_true_displacement_is_left_as_it_is():
    bumped = _scene(_displaced_by(_constant(0.25), "BUMP"))
    assert displace(bumped) is bumped
    plain = _scene(Material())
    assert displace(plain) is plain


def test_a_constant_height_lifts_every_vertex_along_its_normal():
    out = displace(_scene(_displaced_by(_constant(0.25)))).geometry
    np.testing.assert_allclose(out.vertices, SQUARE + [0.0, 0.0, 0.25], atol=1e-7)
    np.testing.assert_allclose(out.corner_normals()[..., 2], 1.0, atol=1e-7)
    # What the Generated output and the bump of 'Displacement and Bump' read there: the
    # points before displacement, flagged as on a displaced mesh, and the normals.
    undisplaced = out.attributes[UNDISPLACED_ATTRIBUTE]
    np.testing.assert_allclose(undisplaced[..., :3], SQUARE[TRIS], atol=1e-7)
    assert np.all(undisplaced[..., 3] == 1.0)
    np.testing.assert_allclose(out.attributes[UNDISPLACED_NORMAL_ATTRIBUTE][..., 2], 1.0, atol=1e-7)
    assert VERTEX_NORMAL_ATTRIBUTE not in out.attributes and SMOOTH_ATTRIBUTE not in out.attributes
    # The automatic texture space is the undisplaced square's (centred at z = 0).
    np.testing.assert_allclose(out.object_texspace[0, 0], [0.5, 0.5, 0.0], atol=1e-7)


def test_a_shared_vertex_takes_the_first_triangles_value():
    """Heights from the UV map's u, which differs between the triangles at the shared vertices
    0 and 2: they take the first triangle's (u = 0 and 1), not the second's (0.5)."""
    uvs = np.zeros((2, 3, 2), np.float32)
    uvs[0, :, 0] = (0.0, 1.0, 1.0)
    uvs[1, :, 0] = 0.5
    out = displace(_scene(_displaced_by(_coordinate("UV")), _geometry(uvs))).geometry
    np.testing.assert_allclose(out.vertices[:, 2], [0.0, 1.0, 1.0, 0.5], atol=1e-7)


def test_the_vertex_normal_gives_the_direction_on_flat_faces_too():
    """Cycles displaces along the smooth vertex normal whatever the face's shading: vertex 1's
    normal points along +x, so it moves sideways; the flat faces then take their new plane."""
    normals = np.tile([0.0, 0.0, 1.0], (4, 1))
    normals[1] = (1.0, 0.0, 0.0)
    out = displace(_scene(_displaced_by(_constant(0.25)), _geometry(smooth=False,
                                                                   vertex_normals=normals))).geometry
    expected = SQUARE + [0.0, 0.0, 0.25]
    expected[1] = (1.25, 0.0, 0.0)
    np.testing.assert_allclose(out.vertices, expected, atol=1e-7)
    p = expected[TRIS[0]]
    face = np.cross(p[1] - p[0], p[2] - p[0])
    np.testing.assert_allclose(out.corner_normals()[0], np.tile(face / np.linalg.norm(face), (3, 1)), atol=1e-6)
    np.testing.assert_allclose(out.corner_normals()[1], np.tile([0.0, 0.0, 1.0], (3, 1)), atol=1e-6)


@pytest.mark.parametrize("method", ["DISPLACEMENT", "BOTH"])
def test_normals_follow_a_tilt_unless_the_bump_does(method):
    """Height = the Generated x (0 to 1 over the square): the square tilts to z = x, whose
    normal is (-1, 0, 1)/sqrt(2) at every corner; 'Displacement and Bump' keeps the
    undisplaced normals for its bump to start from."""
    out = displace(_scene(_displaced_by(_coordinate("Generated"), method))).geometry
    np.testing.assert_allclose(out.vertices[:, 2], SQUARE[:, 0], atol=1e-6)
    expected = [-np.sqrt(0.5), 0.0, np.sqrt(0.5)] if method == "DISPLACEMENT" else [0.0, 0.0, 1.0]
    np.testing.assert_allclose(out.corner_normals().reshape(-1, 3), np.tile(expected, (6, 1)), atol=1e-6)


def test_motion_steps_move_with_the_frame():
    """Deformation steps move by the displacement of their vertex (as Cycles moves its motion
    positions by the same vector)."""
    steps = np.stack([SQUARE + [dx, 0.0, 0.0] for dx in (-0.1, 0.0, 0.1)])
    motion = MotionBlur(objects=[ObjectMotion(object=0, vertices=(0, 4), positions=steps)])
    out = displace(_scene(_displaced_by(_constant(0.25)), motion_blur=motion))
    moved = out.motion_blur.objects[0].positions
    np.testing.assert_allclose(moved, steps + [0.0, 0.0, 0.25], atol=1e-6)


def test_a_scaled_object_moves_in_its_own_space():
    """A Displacement node in object space scales with the object: an object stretched 3x
    along z lifts by 3 x 0.25 in world space."""
    g = _geometry()
    matrix = np.diag([1.0, 1.0, 3.0, 1.0])
    g = dataclasses.replace(g, object_matrix=matrix[None])
    out = displace(_scene(_displaced_by(_constant(0.25)), g)).geometry
    np.testing.assert_allclose(out.vertices[:, 2], 0.75, atol=1e-6)


def test_the_effects_plan_names_the_displaced_meshes():
    """The plan's line (panel, command line, reports) says how many meshes moved; a scene
    displaced only as bump moves none and says nothing."""
    from mcengine.features import detect
    from mcengine.packing import pack_scene

    moved = pack_scene(displace(_scene(_displaced_by(_constant(0.25))))).plan
    assert moved.displaced == 1 and "1 displaced mesh" in moved.summary()
    bumped = _scene(_displaced_by(_constant(0.25), "BUMP"))
    plan = detect(displace(bumped), 0, [], np.zeros(1, np.int32))
    assert plan.displaced == 0 and "displaced" not in plan.summary()
