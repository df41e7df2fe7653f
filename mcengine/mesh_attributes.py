"""Attributes Cycles derives from a mesh's topology for the Geometry node's Pointiness and
Random Per Island outputs (Cycles' blender/mesh.cc computes them at sync, only for meshes
whose shaders read them; the kernel reads them as attributes).

* :func:`pointiness` (per vertex): vertices at the same place are welded; at each, the
  angle between the welded vertex normal and the mean direction of its edges, over pi
  (0.5 where the surface is flat, more on convex points, less in cavities), averaged with
  its neighbours' once (a two-ring blur).
* :func:`random_per_island` (per triangle): a hash of the representative of the connected
  component (by edges) of the triangle's first vertex, as Cycles' disjoint set finds it.
* :func:`sphere_uv` (per vertex): the UV map a Normal Map's tangents come from on a mesh
  without UV maps (Cycles' mikk_compute_tangents with generated coordinates).

Both follow Cycles step by step, in float32 where Cycles' arithmetic shows, so that the
values agree with Cycles' to float rounding (tests/nodes/test_input_nodes.py).
"""
from __future__ import annotations

import numpy as np

from .kernels.svm.hash import hash_uint, unit

__all__ = ["pointiness", "random_per_island", "sphere_uv"]

_EPS = np.float32(np.finfo(np.float32).eps)     # FLT_EPSILON


def _welded(positions: np.ndarray) -> np.ndarray:
    """Index of the vertex each vertex is welded to (itself if none): vertices sorted by the
    sum of their coordinates, each joined to the first later one within the sum window of
    3 FLT_EPSILON that lies closer than sqrt(FLT_EPSILON), and chains followed to their end.
    Equal positions sort by decreasing index, so a group of equal vertices ends at its
    smallest index, as in Cycles (whose sort leaves distinct vertices of equal sum in an
    unspecified order; here they are in the order of their coordinates, which lets the scan
    skip the rest of a run of equal sums, or of equal sums and x, once x, or y, is too far:
    the anti-diagonals of a flat grid would otherwise be scanned vertex by vertex)."""
    n = len(positions)
    p = positions.astype(np.float32)
    sums = (p[:, 0] + p[:, 1]) + p[:, 2]
    order = np.lexsort((-np.arange(n), p[:, 2], p[:, 1], p[:, 0], sums))
    s, q = sums[order], p[order]
    run_end = np.searchsorted(s, s, side="right")          # end of each equal-sum run
    starts = np.flatnonzero(np.r_[True, (s[1:] != s[:-1]) | (q[1:, 0] != q[:-1, 0])])
    xrun_end = np.r_[starts[1:], n][np.searchsorted(starts, np.arange(n), side="right") - 1]
    reach = np.float32(1.001 * np.sqrt(_EPS))             # farther apart: never welded
    orig = np.arange(n)
    a = np.arange(n - 1)             # sorted positions still looking for a later duplicate
    j = a + 1                        # the next candidate of each
    while a.size:
        keep = j < n
        a, j = a[keep], j[keep]
        keep = (s[j] - s[a]) <= 3 * _EPS
        a, j = a[keep], j[keep]
        d = q[j] - q[a]
        found = np.einsum("ij,ij->i", d, d) < _EPS
        orig[order[a[found]]] = order[j[found]]
        a, j, d = a[~found], j[~found], d[~found]
        same = s[j] == s[a]
        j = np.where(same & (d[:, 0] >= reach), run_end[j],
                     np.where(same & (d[:, 0] == 0) & (d[:, 1] >= reach), xrun_end[j], j + 1))
    while True:
        nxt = orig[orig]
        if np.array_equal(nxt, orig):
            return orig
        orig = nxt


def pointiness(positions: np.ndarray, vertex_normals: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """(V,) float32 pointiness of each vertex of a mesh: ``positions`` and ``vertex_normals``
    (V, 3), ``edges`` (E, 2) vertex indices (Blender's order)."""
    n = len(positions)
    if n == 0:
        return np.zeros(0, np.float32)
    orig = _welded(positions)
    normals = np.zeros((n, 3), np.float32)
    np.add.at(normals, orig, np.asarray(vertex_normals, np.float32))
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, length, out=np.zeros_like(normals), where=length > 0)
    # Each welded edge once, in either direction (Cycles' EdgeMap).
    welded = orig[np.asarray(edges, np.int64).reshape(-1, 2)]
    keys = np.sort(welded, axis=1)
    _, first = np.unique(keys[:, 0] * n + keys[:, 1], return_index=True)
    v0, v1 = welded[np.sort(first)].T
    p = np.asarray(positions, np.float32)
    edge = p[v1] - p[v0]
    length = np.linalg.norm(edge, axis=1, keepdims=True)
    edge = np.divide(edge, length, out=np.zeros_like(edge), where=length > 0)
    accum = np.zeros((n, 3), np.float32)
    np.add.at(accum, v0, edge)
    np.add.at(accum, v1, -edge)
    counter = np.bincount(v0, minlength=n) + np.bincount(v1, minlength=n)
    mean = accum / np.maximum(counter, 1)[:, None].astype(np.float32)
    cos = np.clip(np.einsum("ij,ij->i", normals, mean), -1.0, 1.0)
    raw = np.where((counter > 0) & (orig == np.arange(n)),
                   np.arccos(cos) * np.float32(1.0 / np.pi), 0.0).astype(np.float32)
    data = raw.copy()
    np.add.at(data, v0, raw[v1])
    np.add.at(data, v1, raw[v0])
    data /= (counter + 1).astype(np.float32)
    return data[orig]


def random_per_island(vertex_count: int, edges: np.ndarray, first_vertices: np.ndarray) -> np.ndarray:
    """(T,) float32 Random Per Island of each triangle, given its first corner's vertex
    (``first_vertices``, (T,)): vertices are joined along ``edges`` (E, 2) in Blender's order
    by union by rank with path compression, as Cycles' DisjointSet, and the representative
    of each triangle's first vertex is hashed (hash_uint_to_float)."""
    parent = list(range(vertex_count))
    rank = [0] * vertex_count

    def find(x):
        root = x
        while parent[root] != root:
            root = parent[root]
        while parent[x] != root:
            parent[x], x = root, parent[x]
        return root

    for a, b in np.asarray(edges, np.int64).reshape(-1, 2).tolist():
        ra, rb = find(a), find(b)
        if ra == rb:
            continue
        if rank[ra] < rank[rb]:
            ra, rb = rb, ra
        parent[rb] = ra
        if rank[ra] == rank[rb]:
            rank[ra] += 1
    roots = np.array([find(v) for v in range(vertex_count)], np.int64)
    islands, index = np.unique(roots[np.asarray(first_vertices, np.int64)], return_inverse=True)
    values = np.array([unit(hash_uint(int(r))) for r in islands], np.float32)
    return values[index].reshape(-1)


def sphere_uv(positions: np.ndarray) -> np.ndarray:
    """(N, 2) float32: Cycles' map_to_sphere (util/math_float3.h) of (N, 3) object-space
    positions, the UVs MikkTSpace gets on a mesh without UV maps (Cycles' blender/mesh.cc:
    the generated coordinates turned back into positions, ``(orco + loc) / size``).  u from
    the angle about z, 0.5 - atan2(x, y) / 2 pi (0 on the z axis); v from the angle to +z,
    1 - acos(z / |p|) / pi; (0, 0) at the origin.  The kernels' Image Texture projection
    applies the same map to the [0, 1] cube (``svm.image_nodes.map_to_sphere``; both agree:
    tests/core/test_mesh_attributes.py)."""
    p = np.asarray(positions, np.float64)
    length = np.sqrt(np.einsum("ij,ij->i", p, p))
    on_axis = (p[:, 0] == 0.0) & (p[:, 1] == 0.0)
    u = np.where(on_axis, 0.0, 0.5 - np.arctan2(p[:, 0], p[:, 1]) / (2.0 * np.pi))
    cos_z = np.clip(p[:, 2] / np.where(length > 0.0, length, 1.0), -1.0, 1.0)
    uv = np.stack([u, 1.0 - np.arccos(cos_z) / np.pi], axis=1)
    uv[length == 0.0] = 0.0
    return uv.astype(np.float32)
