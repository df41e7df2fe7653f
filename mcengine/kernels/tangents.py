"""MikkTSpace tangents of a triangle mesh, computed as Blender's ``intern/mikktspace`` does.

The Normal Map node's tangent space and the anisotropic closures' tangents are the UV map's
MikkTSpace tangents (Cycles: ``ATTR_STD_UV_TANGENT``), which Blender computes on the mesh's
triangles with the shading normals.  Blender's own ``Mesh.calc_tangents`` runs the algorithm
on threads for meshes of more than 10,000 faces and then adds each group's tangents with
atomic float additions in whatever order the threads reach them: the same mesh gives
tangents that differ in the last bit from call to call, and renders that are not
reproducible.  This module computes the same tangents in the serial order, so the same mesh
always gives the same bits (and, for meshes Blender computes serially, Blender's bits, in
single precision as Blender's are).

The algorithm, per corner of the triangles (faces of three corners; quads are not needed):

1. *Welding*: corners with equal position, normal and UV are one vertex (the first such
   corner represents them).
2. Triangles with two equal corner positions are *degenerate*; the others are ordered first.
3. Each good triangle's tangent is the direction in which u grows across it (dP/du, Blender's
   ``vOs``), negated where its UVs are mirrored; a triangle without UV area, or without a u
   or v direction, joins any neighbour's group.
4. *Neighbours*: two triangles share an edge when they have the same two welded vertices in
   opposite order (the first unmatched such pair, in triangle order).
5. *Groups*: around each welded vertex, the triangles reachable across shared edges with the
   same orientation form a group (a depth-first walk, left neighbour first).
6. Each group sums its triangles' tangents projected into the vertex's tangent plane,
   weighted by the corner angle (``fast_acosf``), and normalises the sum; a corner's tangent
   is its group's (the normalised sum of two, in the rare corner in two groups); a
   degenerate triangle's corner copies that of the first good corner of its welded vertex.

The bitangent sign is +1 where the UV orientation is preserved, else -1.
"""
from __future__ import annotations

import numpy as np

from ..jit import builder

__all__ = ["mikktspace"]

_FLT_MIN = np.float32(1.1754943508222875e-38)      # C's FLT_MIN (``not_zero``)
_ZERO = np.float32(0.0)
_ONE = np.float32(1.0)
_PI = np.float32(3.1415926535897932)
# fast_acosf's polynomial (Cycles' util/math_fast.h, as mikktspace uses it).
_A0 = np.float32(1.5707963267)
_A1 = np.float32(-0.213300989)
_A2 = np.float32(0.077980478)
_A3 = np.float32(-0.02164095)


def mikktspace(positions, triangles, normals, uvs) -> np.ndarray:
    """(3T, 4) float32: for corner k of triangle t (row 3t + k), the unit tangent and the
    bitangent sign (+1 or -1).

    ``positions`` (V, 3), ``triangles`` (T, 3) vertex indices, ``normals`` and ``uvs`` per
    corner: (T, 3, 3) or (3T, 3), and (T, 3, 2) or (3T, 2).  Arithmetic is single precision,
    as Blender's.
    """
    tri = np.ascontiguousarray(triangles, np.int32).reshape(-1, 3)
    if len(tri) == 0:
        return np.zeros((0, 4), np.float32)
    p = np.ascontiguousarray(np.asarray(positions, np.float32)[tri].reshape(-1, 3))
    n = np.ascontiguousarray(normals, np.float32).reshape(-1, 3)
    uv = np.ascontiguousarray(uvs, np.float32).reshape(-1, 2)
    if len(n) != len(p) or len(uv) != len(p):
        raise ValueError("mikktspace: normals and uvs need one row per triangle corner")
    return _tangent_spaces(p, n, uv, _welded(p, n, uv))


def _welded(p, n, uv) -> np.ndarray:
    """Each corner's representative corner (int32); the keys and hashes, 40 bytes a corner,
    are freed on return."""
    # Welding compares floats: -0 equals +0 (adding +0 makes every zero +0).
    bits = (np.concatenate([p, n, uv], axis=1) + np.float32(0.0)).view(np.uint32)
    h = _row_hashes(bits)
    return _weld(bits, h, np.argsort(h, kind="stable"))


@builder
def _row_hashes(bits):
    out = np.empty(bits.shape[0], np.uint64)
    for r in range(bits.shape[0]):
        x = np.uint64(1469598103934665603)
        for c in range(bits.shape[1]):
            x = (x ^ np.uint64(bits[r, c])) * np.uint64(1099511628211)
        out[r] = x
    return out


@builder
def _weld(bits, h, order):
    """Each corner's representative: the first corner with the same bits."""
    m = order.shape[0]
    rep = np.empty(m, np.int32)
    s = 0
    while s < m:
        e = s + 1
        while e < m and h[order[e]] == h[order[s]]:
            e += 1
        for a in range(s, e):           # a run of equal hashes, in corner order
            c = order[a]
            rep[c] = c
            for b in range(s, a):
                d = order[b]
                if rep[d] == d:
                    same = True
                    for k in range(bits.shape[1]):
                        if bits[c, k] != bits[d, k]:
                            same = False
                            break
                    if same:
                        rep[c] = d
                        break
        s = e
    return rep


@builder
def _normalized(x, y, z):
    length = np.sqrt(x * x + y * y + z * z)
    if length != _ZERO:
        inv = _ONE / length
        return x * inv, y * inv, z * inv
    return x, y, z


@builder
def _project(nx, ny, nz, vx, vy, vz):
    """v projected into the plane of unit normal n, normalised."""
    d = nx * vx + ny * vy + nz * vz
    return _normalized(vx - nx * d, vy - ny * d, vz - nz * d)


@builder
def _fast_acos(x):
    f = abs(x)
    m = (_ONE - (_ONE - f)) if f < _ONE else _ONE
    a = np.sqrt(_ONE - m) * (_A0 + m * (_A1 + m * (_A2 + m * _A3)))
    return _PI - a if x < _ZERO else a


@builder
def _tangent_spaces(p, n, uv, weld):
    corners = p.shape[0]
    t_all = corners // 3
    # -- degenerate triangles last, the good ones in their order -----------------------------
    degenerate = np.empty(t_all, np.bool_)
    for t in range(t_all):
        a, b, c = weld[3 * t], weld[3 * t + 1], weld[3 * t + 2]
        degenerate[t] = _same(p, a, b) or _same(p, a, c) or _same(p, b, c)
    ng = t_all - int(degenerate.sum())
    order = np.empty(t_all, np.int32)
    good, bad = 0, ng
    for t in range(t_all):
        if degenerate[t]:
            order[bad] = t
            bad += 1
        else:
            order[good] = t
            good += 1
    vid = np.empty((ng, 3), np.int32)
    for k in range(ng):
        for i in range(3):
            vid[k, i] = weld[3 * order[k] + i]

    # -- each good triangle's tangent and orientation ------------------------------------------
    tan = np.zeros((ng, 3), np.float32)
    orient = np.zeros(ng, np.bool_)
    any_group = np.ones(ng, np.bool_)
    for k in range(ng):
        c1, c2, c3 = vid[k, 0], vid[k, 1], vid[k, 2]
        t21x = uv[c2, 0] - uv[c1, 0]
        t21y = uv[c2, 1] - uv[c1, 1]
        t31x = uv[c3, 0] - uv[c1, 0]
        t31y = uv[c3, 1] - uv[c1, 1]
        d1x, d1y, d1z = p[c2, 0] - p[c1, 0], p[c2, 1] - p[c1, 1], p[c2, 2] - p[c1, 2]
        d2x, d2y, d2z = p[c3, 0] - p[c1, 0], p[c3, 1] - p[c1, 1], p[c3, 2] - p[c1, 2]
        signed = t21x * t31y - t21y * t31x
        osx, osy, osz = d1x * t31y - d2x * t21y, d1y * t31y - d2y * t21y, d1z * t31y - d2z * t21y
        nt31x = -t31x
        otx, oty, otz = d1x * nt31x + d2x * t21x, d1y * nt31x + d2y * t21x, d1z * nt31x + d2z * t21x
        orient[k] = signed > _ZERO
        if abs(signed) > _FLT_MIN:
            len_s2 = osx * osx + osy * osy + osz * osz
            len_t2 = otx * otx + oty * oty + otz * otz
            sign = _ONE if orient[k] else -_ONE
            if abs(len_s2) > _FLT_MIN:
                f = sign / np.sqrt(len_s2)
                tan[k, 0], tan[k, 1], tan[k, 2] = osx * f, osy * f, osz * f
                if abs(len_t2) > _FLT_MIN:
                    any_group[k] = False

    # -- neighbours across shared edges ----------------------------------------------------------
    nbr = np.full((ng, 3), -1, np.int32)
    keys = np.empty(3 * ng, np.int64)
    for k in range(ng):
        for i in range(3):
            a, b = vid[k, i], vid[k, (i + 1) % 3]
            keys[3 * k + i] = min(a, b) * corners + max(a, b)
    edges = np.argsort(keys, kind="mergesort")
    s = 0
    while s < 3 * ng:
        e = s + 1
        while e < 3 * ng and keys[edges[e]] == keys[edges[s]]:
            e += 1
        for x in range(s, e):
            ka, ia = edges[x] // 3, edges[x] % 3
            if nbr[ka, ia] != -1:
                continue
            i0a, i1a = vid[ka, ia], vid[ka, (ia + 1) % 3]
            for y in range(x + 1, e):
                kb, ib = edges[y] // 3, edges[y] % 3
                if nbr[kb, ib] != -1:
                    continue
                if vid[kb, (ib + 1) % 3] == i0a and vid[kb, ib] == i1a:
                    nbr[ka, ia] = kb
                    nbr[kb, ib] = ka
                    break
        s = e

    # -- groups around each welded vertex ----------------------------------------------------------
    group = np.full((ng, 3), -1, np.int32)
    g_vertex = np.empty(3 * ng, np.int32)
    g_orient = np.zeros(3 * ng, np.bool_)
    n_groups = 0
    stack = np.empty(3 * ng + 2, np.int32)
    for k in range(ng):
        for i in range(3):
            if any_group[k] or group[k, i] != -1:
                continue
            g = n_groups
            n_groups += 1
            group[k, i] = g
            g_vertex[g] = vid[k, i]
            g_orient[g] = orient[k]
            top = 0
            stack[top] = nbr[k, (i + 2) % 3]       # right, walked after the left
            stack[top + 1] = nbr[k, i]             # left
            top = 2
            while top > 0:
                top -= 1
                t = stack[top]
                if t == -1:
                    continue
                j = 0 if vid[t, 0] == g_vertex[g] else (1 if vid[t, 1] == g_vertex[g] else 2)
                if group[t, j] != -1:
                    continue
                if any_group[t] and group[t, 0] == -1 and group[t, 1] == -1 and group[t, 2] == -1:
                    orient[t] = g_orient[g]     # the first group it joins orients it
                if orient[t] != g_orient[g]:
                    continue
                group[t, j] = g
                stack[top] = nbr[t, (j + 2) % 3]
                stack[top + 1] = nbr[t, j]
                top += 2

    # -- each group's tangent: its corners' angle-weighted projected tangents -------------------
    g_tan = np.zeros((n_groups, 3), np.float32)
    for k in range(ng):
        if any_group[k]:
            continue
        fcos = np.empty(3, np.float32)
        for i in range(3):
            c, c1, c2 = vid[k, i], vid[k, (i + 1) % 3], vid[k, (i + 2) % 3]
            ax, ay, az = _project(n[c, 0], n[c, 1], n[c, 2], p[c1, 0] - p[c, 0],
                                  p[c1, 1] - p[c, 1], p[c1, 2] - p[c, 2])
            bx, by, bz = _project(n[c, 0], n[c, 1], n[c, 2], p[c2, 0] - p[c, 0],
                                  p[c2, 1] - p[c, 1], p[c2, 2] - p[c, 2])
            fcos[i] = ax * bx + ay * by + az * bz
        for i in range(3):
            g = group[k, i]
            if g == -1:
                continue
            c = vid[k, i]
            tx, ty, tz = _project(n[c, 0], n[c, 1], n[c, 2], tan[k, 0], tan[k, 1], tan[k, 2])
            w = _fast_acos(min(max(fcos[i], -_ONE), _ONE))
            g_tan[g, 0] += tx * w
            g_tan[g, 1] += ty * w
            g_tan[g, 2] += tz * w
    for g in range(n_groups):
        g_tan[g, 0], g_tan[g, 1], g_tan[g, 2] = _normalized(g_tan[g, 0], g_tan[g, 1], g_tan[g, 2])

    # -- the corners' tangent spaces -------------------------------------------------------------
    ts = np.zeros((corners, 3), np.float32)
    ts[:, 0] = _ONE
    count = np.zeros(corners, np.int32)
    ts_orient = np.zeros(corners, np.bool_)
    for k in range(ng):
        for i in range(3):
            g = group[k, i]
            if g == -1:
                continue
            r = 3 * order[k] + i
            if count[r] == 0:
                ts[r, 0], ts[r, 1], ts[r, 2] = g_tan[g, 0], g_tan[g, 1], g_tan[g, 2]
            elif not (ts[r, 0] == g_tan[g, 0] and ts[r, 1] == g_tan[g, 1] and ts[r, 2] == g_tan[g, 2]):
                ts[r, 0], ts[r, 1], ts[r, 2] = _normalized(ts[r, 0] + g_tan[g, 0], ts[r, 1] + g_tan[g, 1],
                                                           ts[r, 2] + g_tan[g, 2])
            count[r] += 1
            ts_orient[r] = g_orient[g]
    # Degenerate triangles: each corner copies the first good corner of its welded vertex.
    if ng < t_all:
        first = np.full(corners, -1, np.int32)
        for k in range(ng):
            for i in range(3):
                if first[vid[k, i]] == -1:
                    first[vid[k, i]] = 3 * order[k] + i
        for d in range(ng, t_all):
            t = order[d]
            for i in range(3):
                src = first[weld[3 * t + i]]
                if src != -1:
                    for c in range(3):
                        ts[3 * t + i, c] = ts[src, c]
                    ts_orient[3 * t + i] = ts_orient[src]

    out = np.empty((corners, 4), np.float32)
    for r in range(corners):
        out[r, 0], out[r, 1], out[r, 2] = ts[r, 0], ts[r, 1], ts[r, 2]
        out[r, 3] = _ONE if ts_orient[r] else -_ONE
    return out


@builder
def _same(p, a, b):
    return p[a, 0] == p[b, 0] and p[a, 1] == p[b, 1] and p[a, 2] == p[b, 2]
