"""True displacement: the material output's Displacement evaluated at mesh vertices.

Cycles displaces a mesh before building its BVH (scene/mesh_displace.cpp): each vertex
once, at the first triangle (in order) that uses it and has a material displacing it, by
the vector its displacement shader gives there (kernel/bake/bake.h
``kernel_displace_evaluate``).  The point is set up as ``shader_setup_from_displace``
(kernel/geom/shader_data.h) does: the vertex as the corner of that triangle (barycentrics
(0, 0), (1, 0), (0, 1)), the smooth vertex normal as N whatever the face's shading, the
viewer along N, no ray differential, no path.  ``mcengine.displacement`` chooses the
vertices and moves them; this kernel evaluates the vectors.
"""
from __future__ import annotations

import math

import numpy as np

from ..jit import by_ref, kernel
from .svm import ShaderScene, ShadingData, eval_values


@kernel
def displacement_offsets(ops, ranges, results, regs, tex, verts, tris, local, ng, mat_index,
                         corner_tri, corner, normals, out):
    """The displacement (world space) at corner ``corner[j]`` of triangle ``corner_tri[j]``,
    whose unit vertex normal is ``normals[j]``, into ``out[j]``: the rows
    [ranges[m, 0], ranges[m, 1]) of ``ops`` of the triangle's material m run at the vertex
    and leave the vector in registers ``results[m]`` to ``results[m] + 2`` of ``regs``.
    ``ng`` are the triangles' unit geometric normals; ``local`` is a ``subsurface.LocalBVH``
    the shader evaluator takes (Bevel nodes trace nothing here, as in Cycles).  A component that is not finite
    becomes 0 (Cycles' ``ensure_finite``)."""
    i64, f64 = np.int64, np.float64
    scene_ref = by_ref(ShaderScene(ops, tex, verts, tris, local))
    for j in range(corner_tri.shape[0]):
        t = corner_tri[j]
        k = corner[j]
        m = mat_index[t]
        vert = tris[t, k]
        nx, ny, nz = f64(normals[j, 0]), f64(normals[j, 1]), f64(normals[j, 2])
        u = f64(1.0 if k == 1 else 0.0)     # (not inside the call: numba takes no branches
        v = f64(1.0 if k == 2 else 0.0)     # among that many arguments)
        sd = ShadingData(f64(verts[vert, 0]), f64(verts[vert, 1]), f64(verts[vert, 2]), nx, ny, nz,
                         f64(ng[t, 0]), f64(ng[t, 1]), f64(ng[t, 2]), nx, ny, nz,
                         False, False, True, True, False, i64(t), u, v,
                         i64(tex.tri_object[t]), i64(0), 0.0,
                         i64(0), i64(0), i64(0), i64(0), i64(0), 0.0, np.uint64(0), 0.0)
        # (int64 bounds, as eval_shader passes them: one compiled eval_values for both)
        eval_values(i64(ranges[m, 0]), i64(ranges[m, 1]), regs, by_ref(sd), scene_ref)
        r = results[m]
        for c in range(3):
            x = regs[r + c]
            out[j, c] = x if math.isfinite(x) else 0.0
