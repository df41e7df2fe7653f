"""MikkTSpace tangents (mcengine.kernels.tangents) on meshes whose tangents are known in
closed form; tests/addon/test_export_mesh.py compares them with Blender's bit for bit."""
import numpy as np
import pytest

from mcengine.kernels.tangents import mikktspace

# A unit square in z = 0 as two triangles sharing the diagonal 0-2, normals +z.
SQUARE = np.array([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], np.float32)
TRIS = np.array([(0, 1, 2), (0, 2, 3)])
UP = np.tile(np.float32((0, 0, 1)), (6, 1))


def _uvs(f):
    """Per-corner UVs of TRIS from a map of the square's corners."""
    return np.array([f(*SQUARE[v, :2]) for v in TRIS.ravel()], np.float32)


@pytest.mark.parametrize("uv_map, tangent, sign", [
    (lambda x, y: (x, y), (1, 0, 0), 1.0),              # u along +x
    (lambda x, y: (2 * x + 0.5, 3 * y), (1, 0, 0), 1.0),   # scaled and moved: the same
    (lambda x, y: (1 - x, y), (-1, 0, 0), -1.0),        # mirrored: u along -x, orientation flips
    (lambda x, y: (y, 1 - x), (0, 1, 0), 1.0),           # turned: u along +y
    (lambda x, y: (-y, x), (0, -1, 0), 1.0),             # turned the other way
    (lambda x, y: (y, x), (0, 1, 0), -1.0),              # u and v swapped: mirrored
])
def test_tangent_follows_the_u_direction_and_the_sign_the_orientation(uv_map, tangent, sign):
    out = mikktspace(SQUARE, TRIS, UP, _uvs(uv_map))
    np.testing.assert_allclose(out[:, :3], [tangent] * 6, atol=1e-6)
    assert np.all(out[:, 3] == sign)
    assert out.dtype == np.float32 and out.shape == (6, 4)


def test_tangents_lie_in_each_corners_tangent_plane():
    """Tilted shading normals: each corner's tangent is u's direction projected into its
    plane (a group per corner here: the normals differ), unit length."""
    rng = np.random.default_rng(5)
    normals = UP + 0.3 * rng.normal(size=(6, 3)).astype(np.float32)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    out = mikktspace(SQUARE, TRIS, normals, _uvs(lambda x, y: (x, y)))
    np.testing.assert_allclose(np.einsum("ij,ij->i", out[:, :3], normals), 0.0, atol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(out[:, :3], axis=1), 1.0, atol=1e-6)
    expected = np.float32((1, 0, 0)) - normals[:, 0:1] * normals
    expected /= np.linalg.norm(expected, axis=1, keepdims=True)
    np.testing.assert_allclose(out[:, :3], expected, atol=1e-6)


def test_shared_vertices_average_their_triangles_by_corner_angle():
    """Two triangles whose UVs agree on their shared edge (vertices 0 and 2 weld) but whose u
    directions differ: at the shared vertices both corners get the corner-angle-weighted
    mean of the two triangles' tangents (both corners are 45 degrees: the plain mean),
    elsewhere each triangle's own."""
    uv = np.array([(0, 0), (1, 0), (1, 1),           # triangle 0: u along +x
                   (0, 0), (1, 1), (0, 0.5)], np.float32)   # triangle 1: u along (1, -1)
    out = mikktspace(SQUARE, TRIS, UP, uv)
    t0, t1 = np.array((1, 0, 0)), np.array((1, -1, 0)) / np.sqrt(2)
    mean = (t0 + t1) / np.linalg.norm(t0 + t1)
    np.testing.assert_allclose(out[[0, 2, 3, 4], :3], [mean] * 4, atol=1e-6)
    np.testing.assert_allclose(out[1, :3], t0, atol=1e-6)
    np.testing.assert_allclose(out[5, :3], t1, atol=1e-6)
    assert np.all(out[:, 3] == 1.0)
    # Mirror triangle 1's UVs (v -> -v keeps the shared corners apart): no sharing.
    uv[3:, 1] *= -1
    out = mikktspace(SQUARE, TRIS, UP, uv)
    np.testing.assert_allclose(out[:3, :3], [t0] * 3, atol=1e-6)
    assert np.all(out[3:, 3] == -1.0)


def test_a_degenerate_triangle_copies_the_tangent_of_its_welded_vertex():
    verts = np.vstack([SQUARE, SQUARE[2:3]])            # vertex 4 = vertex 2's position
    tris = np.array([(0, 1, 2), (0, 2, 3), (2, 4, 1)])  # the third has two equal corners
    uv = np.vstack([_uvs(lambda x, y: (x, y)), [(1, 1), (1, 1), (1, 0)]]).astype(np.float32)
    normals = np.tile(np.float32((0, 0, 1)), (9, 1))
    out = mikktspace(verts, tris, normals, uv)
    np.testing.assert_array_equal(out[6], out[2])        # its corner at vertex 2
    np.testing.assert_array_equal(out[8], out[1])        # at vertex 1
    np.testing.assert_array_equal(out[7], out[2])        # vertex 4 welds with vertex 2


def test_a_triangle_without_uv_area_and_no_welded_neighbour_gets_the_default_tangent():
    uv = _uvs(lambda x, y: (x, y))
    uv[3:] = 0.5                                 # triangle 1: every corner the same UV
    out = mikktspace(SQUARE, TRIS, UP, uv)
    np.testing.assert_allclose(out[:3, :3], [(1, 0, 0)] * 3, atol=1e-6)
    # Its corners 0 and 2 weld with triangle 0's only if the UVs match: they do not, so
    # they get the default tangent (1, 0, 0) with sign -1, as Blender's.
    np.testing.assert_array_equal(out[3:], [(1, 0, 0, -1)] * 3)


def test_random_meshes_give_finite_tangents_and_bad_inputs_are_refused():
    """Degenerate and repeated indices give finite tangents; an empty mesh gives none; rows
    that do not match the corners are refused.  (Two calls giving the same bits cannot fail
    for this serial code; the export's determinism, where Blender's threads once made it
    fail, is asserted in tests/addon/test_export_mesh.py.)"""
    rng = np.random.default_rng(1)
    verts = rng.random((3000, 3)).astype(np.float32)
    tris = rng.integers(0, 3000, size=(12000, 3))
    normals = rng.normal(size=(36000, 3)).astype(np.float32)
    uv = rng.random((36000, 2)).astype(np.float32)
    a, b = mikktspace(verts, tris, normals, uv), mikktspace(verts, tris, normals, uv)
    assert a.tobytes() == b.tobytes() and np.isfinite(a).all()
    assert mikktspace(verts, np.zeros((0, 3), int), normals[:0], uv[:0]).shape == (0, 4)
    with pytest.raises(ValueError, match="one row per triangle corner"):
        mikktspace(verts, tris, normals[:10], uv)
