"""Pointiness, Random Per Island and the sphere UVs (``mcengine.mesh_attributes``): closed
forms on a cube and a flat grid, and agreement with a vertex-by-vertex transcription of
Cycles' loops on meshes with doubled and nearly doubled vertices (the Blender side is
checked against Cycles itself in tests/nodes/test_input_nodes.py and test_normal_nodes.py)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from mcengine.kernels.svm.hash import hash_uint, unit
from mcengine.kernels.svm.image_nodes import map_to_sphere
from mcengine.mesh_attributes import pointiness, random_per_island, sphere_uv

FLT_EPSILON = float(np.finfo(np.float32).eps)
CUBE = np.array([(x, y, z) for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])
CUBE_EDGES = np.array([(i, j) for i in range(8) for j in range(i + 1, 8)
                       if np.abs(CUBE[i] - CUBE[j]).sum() == 2.0])
# At a cube's corner the normal is (1, 1, 1)/sqrt(3) and the three edges run along -x, -y, -z.
CUBE_POINTINESS = math.acos(-1.0 / math.sqrt(3.0)) / math.pi      # 0.69591...


def _normalized(v):
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def _split_cube():
    """The cube with each face's four vertices its own (24 vertices, face normals)."""
    positions, normals, edges = [], [], []
    for axis in range(3):
        for side in (-1.0, 1.0):
            quad = [k for k in range(8) if CUBE[k, axis] == side]
            a, b, d, c = quad          # corners in the order a-b-c-d around the face
            start = len(positions)
            for k in (a, b, c, d):
                positions.append(CUBE[k])
                normals.append(np.eye(3)[axis] * side)
            edges += [(start + i, start + (i + 1) % 4) for i in range(4)]
    return np.array(positions), np.array(normals), np.array(edges)


def test_cube_corners_have_the_closed_form_pointiness():
    got = pointiness(CUBE, _normalized(CUBE), CUBE_EDGES)
    np.testing.assert_allclose(got, CUBE_POINTINESS, atol=1e-6)


def test_a_cube_whose_faces_are_split_is_welded_back():
    """Doubled vertices share one welded normal and one set of edges: without the weld each
    would see its face's normal and two edges in the face's plane (pointiness 0.5)."""
    positions, normals, edges = _split_cube()
    np.testing.assert_allclose(pointiness(positions, normals, edges), CUBE_POINTINESS, atol=1e-6)


def test_a_flat_grid_is_one_half_everywhere():
    n = 5
    xs, ys = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float), indexing="ij")
    positions = np.stack([xs.ravel(), ys.ravel(), np.zeros(n * n)], axis=1)
    index = np.arange(n * n).reshape(n, n)
    edges = np.concatenate([np.stack([index[:-1].ravel(), index[1:].ravel()], 1),
                            np.stack([index[:, :-1].ravel(), index[:, 1:].ravel()], 1),
                            np.stack([index[:-1, :-1].ravel(), index[1:, 1:].ravel()], 1)])
    normals = np.tile([0.0, 0.0, 1.0], (n * n, 1))
    np.testing.assert_allclose(pointiness(positions, normals, edges), 0.5, atol=1e-6)


def _cycles_pointiness(positions, normals, edges):
    """Cycles' attr_create_pointiness, loop by loop (float64; sorted by coordinate sum, ties
    by position and then decreasing index, as mesh_attributes documents)."""
    n = len(positions)
    p = positions.astype(np.float32)
    sums = [float(np.float32(np.float32(q[0] + q[1]) + q[2])) for q in p]
    order = sorted(range(n), key=lambda i: (sums[i], *p[i].tolist(), -i))
    orig = list(range(n))
    for s, i in enumerate(order):
        for j in order[s + 1:]:
            if sums[j] - sums[i] > 3 * FLT_EPSILON:
                break
            if float(((p[j] - p[i]) ** 2).sum()) < FLT_EPSILON:
                orig[i] = j
                break
    for i in range(n):
        o = orig[i]
        while o != orig[o]:
            o = orig[o]
        orig[i] = o
    normal = np.zeros((n, 3))
    for i in range(n):
        normal[orig[i]] += normals[i]
    normal = np.array([normal[orig[i]] / np.linalg.norm(normal[orig[i]]) for i in range(n)])
    counter, accum, visited, unique = [0] * n, np.zeros((n, 3)), set(), []
    for a, b in edges:
        v0, v1 = orig[a], orig[b]
        if (min(v0, v1), max(v0, v1)) in visited:
            continue
        visited.add((min(v0, v1), max(v0, v1)))
        unique.append((v0, v1))
        e = positions[v1] - positions[v0]
        e = e / np.linalg.norm(e) if np.linalg.norm(e) > 0 else e
        accum[v0] += e
        accum[v1] -= e
        counter[v0] += 1
        counter[v1] += 1
    raw = np.zeros(n)
    for i in range(n):
        if orig[i] == i and counter[i] > 0:
            raw[i] = math.acos(np.clip(normal[i] @ (accum[i] / counter[i]), -1, 1)) / math.pi
    data = raw.copy()
    for v0, v1 in unique:
        data[v0] += raw[v1]
        data[v1] += raw[v0]
    data /= np.array(counter) + 1
    return data[orig]


@pytest.mark.parametrize("seed", range(4))
def test_pointiness_follows_cycles_on_meshes_with_doubled_vertices(seed):
    """A bumpy (or flat) grid of triangles, some vertices doubled exactly or within the weld distance
    (and some of their edges moved to the copies), edges repeated, in a shuffled order, one
    of them degenerate once welded."""
    rng = np.random.default_rng(seed)
    n = 6
    xs, ys = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float), indexing="ij")
    positions = np.stack([xs.ravel(), ys.ravel(), rng.uniform(-0.4, 0.4, n * n)], axis=1)
    if seed == 1:           # flat: runs of equal coordinate sums along the anti-diagonals
        positions[:, 2] = 0.0
    elif seed == 2:         # flat in the y-z plane: equal sums and equal x
        positions = np.stack([np.zeros(n * n), xs.ravel(), ys.ravel()], axis=1)
    index = np.arange(n * n).reshape(n, n)
    edges = np.concatenate([np.stack([index[:-1].ravel(), index[1:].ravel()], 1),
                            np.stack([index[:, :-1].ravel(), index[:, 1:].ravel()], 1),
                            np.stack([index[:-1, :-1].ravel(), index[1:, 1:].ravel()], 1)])
    doubled = rng.choice(n * n, 8, replace=False)
    copies = positions[doubled] + rng.choice([0.0, 1e-4], (8, 1)) * rng.normal(size=(8, 3))
    for k, v in enumerate(doubled):
        moved = rng.random(len(edges)) < 0.5
        edges[moved & (edges[:, 0] == v), 0] = n * n + k
        edges[moved & (edges[:, 1] == v), 1] = n * n + k
    # Blender stores positions in float32 (a near-double's edge is 1e-4 long: its direction
    # depends on that rounding).
    positions = np.concatenate([positions, copies]).astype(np.float32).astype(float)
    # Edges Cycles' EdgeMap visits once: some twice (reversed), some through a vertex's copy.
    again = edges[rng.choice(len(edges), 6, replace=False)][:, ::-1]
    through_copy = np.array([[n * n + k, w] for k, v in enumerate(doubled[:4])
                             for w in edges[edges[:, 0] == v, 1][:1]]).reshape(-1, 2)
    edges = np.concatenate([edges, again, through_copy, [[doubled[0], n * n]]])
    edges = edges[rng.permutation(len(edges))]
    normals = _normalized(rng.normal(size=(len(positions), 3)) * 0.3 + [0.0, 0.0, 1.0])
    got = pointiness(positions, normals, edges)
    np.testing.assert_allclose(got, _cycles_pointiness(positions, normals, edges), atol=2e-6)
    assert np.ptp(got) > (0.0 if seed in (1, 2) else 0.05)


def test_islands_are_hashed_by_the_representative_union_by_rank_keeps():
    """Joining (1, 2) makes 1 the root of rank 1; joining (0, 1) then keeps 1 (the deeper
    tree), not the smaller index 0.  Vertices 3..5 are another island, rooted at 3."""
    edges = np.array([(1, 2), (0, 1), (3, 4), (4, 5), (5, 3)])
    got = random_per_island(6, edges, np.array([0, 2, 5, 4]))
    want = [unit(hash_uint(1))] * 2 + [unit(hash_uint(3))] * 2
    np.testing.assert_array_equal(got, np.float32(want))
    assert got[0] != got[2]


def test_a_double_is_found_past_other_vertices_of_the_same_coordinate_sum():
    """v and its near double v2 (x + d, y - d) have the same coordinate sum as w, which sorts
    between them (its x is between theirs) but lies far away: the scan must go on past w."""
    d = 2.0 ** -13
    positions = np.array([(1.0, 2.0, 3.0), (1.0 + d / 2, 2.5, 2.5 - d / 2), (1.0 + d, 2.0 - d, 3.0),
                          (0.0, 2.0, 3.5), (1.0, 0.0, 3.0), (1.0, 2.5, 0.0)])
    edges = np.array([(0, 3), (2, 4), (1, 5), (0, 5)])
    normals = _normalized(np.array([(0.2, 0.3, 1.0), (0.1, 1.0, 0.3), (1.0, 0.2, 0.4),
                                    (0.5, 0.5, 1.0), (1.0, 1.0, 0.2), (0.3, 1.0, 1.0)]))
    got = pointiness(positions, normals, edges)
    np.testing.assert_allclose(got, _cycles_pointiness(positions, normals, edges), atol=2e-6)
    assert got[0] == got[2]


def test_sphere_uvs_have_the_closed_form_and_match_the_kernels_projection():
    """u = 0.5 - atan2(x, y) / 2 pi, v = 1 - acos(z / |p|) / pi (Cycles' map_to_sphere): the
    poles, the equator's quarters, the origin; and on random points what the Image Texture
    node's sphere projection gives for the same point of its [0, 1] cube."""
    points = np.array([(0, 0, 2), (0, 0, -1), (0, 1, 0), (1, 0, 0), (0, -1, 0), (-1, 0, 0), (0, 0, 0)])
    np.testing.assert_allclose(sphere_uv(points), [(0, 1), (0, 0), (0.5, 0.5), (0.25, 0.5),
                                                   (0, 0.5), (0.75, 0.5), (0, 0)], atol=1e-7)
    rng = np.random.default_rng(4)
    p = rng.normal(size=(200, 3))
    kernel = np.array([map_to_sphere(*(0.5 * q + 0.5)) for q in p])
    np.testing.assert_allclose(sphere_uv(p), kernel, rtol=1e-6, atol=1e-6)
