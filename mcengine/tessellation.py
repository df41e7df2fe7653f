"""Blender's triangulation of a mesh's triangles and quads, from its raw arrays.

Blender's ``Mesh.loop_triangles`` (its corner triangles) can only be read item by item from
Python: 0.5 s for the 4 million triangles of a 2-million-quad mesh, where the arrays they
derive from (face offsets, corner vertices, positions) are read in a fifth of that.  For
meshes whose faces all have 3 or 4 corners, :func:`corner_triangles` computes the same
triangles as Blender (``blenkernel/intern/mesh_tessellate.cc``): a triangle is itself; a
quad (corners 0..3) is cut along 0-2 into (0, 1, 2) and (0, 2, 3), unless
``is_quad_flip_v3_first_third_fast`` finds those two facing away from each other (a concave
or folded quad), when it is cut along 1-3 into (0, 1, 3) and (1, 2, 3).  That test is done
in float32 with Blender's order of operations, so it gives Blender's answer to the bit.
Faces of 5 or more corners need Blender's polygon fill: the caller reads Blender's own
triangles then.  Triangle i of face f starts at ``3 * (start_f - 2 f)`` in both.
"""
from __future__ import annotations

import numpy as np

from .parallel import map_threads

__all__ = ["corner_triangles"]

_BLOCK = 1 << 15                                        # quads per block of work
# A quad's corners in its two triangles when cut along 0-2 (Blender's first choice); a cut
# along 1-3 adds 1 to the marked corners: (0, 1, 3) and (1, 2, 3).
_CUT_02 = np.array([[0, 1, 2], [0, 2, 3]], np.int32)


def corner_triangles(face_starts: np.ndarray | None, corner_count: int, corner_verts: np.ndarray,
                     positions: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """The corner of every triangle corner and the face of every triangle, as Blender's
    ``loop_triangles.loops`` ((T * 3,) int32) and ``loop_triangle_polygons`` ((T,) int32),
    or None if a face has more than 4 corners.

    Parameters
    ----------
    face_starts : (F,) int array, or None
        First corner of each face (ascending, as Blender stores them); None when every
        face is a triangle (``corner_count == 3 F``), which needs no offsets.
    corner_count : int
        Corners of the mesh (L).
    corner_verts : (L,) int array
        Vertex of each corner.
    positions : (V, 3) float array
        Vertex positions (the test of a quad's diagonal is made on them in float32, as
        Blender's).

    The quads go in blocks (small temporaries, no page faults on large fresh ones) on
    threads (``map_threads``), each writing its own rows.
    """
    if face_starts is None:
        corners = np.arange(corner_count, dtype=np.int32)
        return corners, np.arange(corner_count // 3, dtype=np.int32)
    faces = len(face_starts)
    starts = np.asarray(face_starts, np.int32)
    sizes = np.diff(starts, append=np.int32(corner_count))
    if faces and (sizes.min() < 3 or sizes.max() > 4):
        return None
    out = np.empty((corner_count - 2 * faces, 3), np.int32)
    all_quads = faces == 0 or sizes.min() == 4
    quads = None
    if not all_quads:
        tri = np.flatnonzero(sizes == 3)
        out[starts[tri] - 2 * tri] = starts[tri, None] + np.arange(3, dtype=np.int32)
        quads = np.flatnonzero(sizes == 4).astype(np.int32)
    count = faces if all_quads else len(quads)
    xyz = np.ascontiguousarray(np.asarray(positions, np.float32).T)    # (3, V)

    def block(lo):
        hi = min(count, lo + _BLOCK)
        if all_quads:                                   # face i starts at corner 4 i
            first = np.arange(4 * lo, 4 * hi, 4, dtype=np.int32)
            verts = corner_verts[4 * lo:4 * hi].reshape(-1, 4).T
        else:
            first = starts[quads[lo:hi]]
            verts = [np.take(corner_verts, first + k) for k in range(4)]
        flip = _quad_flips(xyz, [np.ascontiguousarray(v) for v in verts])
        tris = out.reshape(-1, 6)[lo:hi] if all_quads else np.empty((hi - lo, 6), np.int32)
        np.add(first[:, None], _CUT_02.reshape(6), out=tris)
        tris[:, 2] += flip
        tris[:, 3] += flip
        if not all_quads:
            row = first - 2 * quads[lo:hi]              # each quad's first triangle
            out[row] = tris[:, :3]
            out[row + 1] = tris[:, 3:]

    map_threads(block, range(0, count, _BLOCK))
    face = np.arange(faces, dtype=np.int32)
    return out.reshape(-1), np.repeat(face, 2) if all_quads else np.repeat(face, sizes - 2)


def _quad_flips(xyz: np.ndarray, verts) -> np.ndarray:
    """(Q,) int32, 1 where Blender cuts a quad along 1-3: ``is_quad_flip_v3_first_third_fast``
    (blenlib/intern/math_geom.cc) in float32, (v2 - v1) x (v3 - v1) . (v4 - v1) x (v3 - v1) > 0,
    with its order of operations; ``xyz`` (3, V) float32, ``verts`` the 4 corners' vertices."""
    (x1, y1, z1), (x2, y2, z2), (x3, y3, z3), (x4, y4, z4) = (np.take(xyz, v, axis=1) for v in verts)
    ux, uy, uz = x2 - x1, y2 - y1, z2 - z1              # d_12
    dx, dy, dz = x3 - x1, y3 - y1, z3 - z1              # d_13
    wx, wy, wz = x4 - x1, y4 - y1, z4 - z1              # d_14
    # cross_v3_v3v3(a, d_12, d_13), cross_v3_v3v3(b, d_14, d_13), then dot_v3v3(a, b).
    dot = (uy * dz - uz * dy) * (wy * dz - wz * dy)
    dot += (uz * dx - ux * dz) * (wz * dx - wx * dz)
    dot += (ux * dy - uy * dx) * (wx * dy - wy * dx)
    return (dot > 0.0).astype(np.int32)
