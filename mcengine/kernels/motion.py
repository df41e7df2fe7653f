"""Motion blur: the shutter's distribution of ray times, and motion interpolated as Cycles does.

Every camera sample gets a time in [0, 1] over the open shutter; the camera,
the objects and deforming meshes are evaluated at that time, and the path
keeps it for all its rays.  The conventions are Cycles':

* **Time.**  ``shutter_table`` is Cycles' inverted CDF of the shutter curve
  (scene/camera.cpp: ``util_cdf_inverted`` over 256 entries, evaluating the
  curve's 257 samples as ``shutter_curve_eval`` does), read by linear
  interpolation (:func:`lookup_table`).  Its quirks are kept: with a flat curve the
  times run from 0.0020 to 0.9941, not 0 to 1.
* **Transforms** are stored at an odd number of motion steps spread evenly
  over the shutter, decomposed as ``transform_motion_decompose`` does
  (translation, rotation quaternion, scale with shear, from Gram-Schmidt on
  the columns; quaternions flipped onto the shortest arc; the rotation of a
  zero-scale step copied from a neighbour) and interpolated as
  ``transform_motion_array_interpolate``: between the two steps around the
  time, slerp for the rotation (a normalised lerp when the quaternions are
  within 0.9995), lerp for translation, scale and shear, then recomposed.
* **Deformation** (vertex positions at the same steps) is linear between
  steps (``motion_triangle_vertices``).

A decomposed transform is 16 floats in Cycles' layout: the quaternion
(x, y, z, w); translation x, y, z and scale x; shear z, shear y, 0, scale y;
shear x, 0, 0, scale z.
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from ..jit import builder, device, function, kernel
from .scalar import safe_acos

SHUTTER_TABLE_SIZE = 256        # Cycles' SHUTTER_TABLE_SIZE
CURVE_SAMPLES = 257             # Cycles' RAMP_TABLE_SIZE + 1 samples of the shutter curve
DECOMPOSED = 16                 # floats per decomposed transform
SLERP_THRESHOLD = 0.9995        # above this cosine Cycles interpolates quaternions linearly


# -- time ------------------------------------------------------------------------------------
def shutter_table(curve=None) -> np.ndarray:
    """Cycles' table of ray times: the inverted CDF of the shutter curve.

    ``curve`` holds the curve's values at i / 256, i = 0..256 (Blender's
    CurveMapping as Cycles samples it); None is the flat default curve.  The
    arithmetic is float32, as in Cycles.
    """
    curve = (np.ones(CURVE_SAMPLES, np.float32) if curve is None
             else np.asarray(curve, np.float32).reshape(CURVE_SAMPLES))
    resolution = SHUTTER_TABLE_SIZE
    # util_cdf_evaluate(resolution - 1, 0, 1, shutter_curve_eval): the CDF of |curve|
    # at x = i / (resolution - 2), i = 0 .. resolution - 2.
    count = resolution - 1
    cdf = np.zeros(count + 1, np.float32)
    for i in range(count):
        x = np.float32(i) / np.float32(count - 1)
        cdf[i + 1] = cdf[i] + np.float32(abs(_curve_eval(x, curve)))
    fac = np.float32(0.0) if cdf[count] == 0.0 else np.float32(1.0) / cdf[count]
    cdf *= fac
    cdf[count] = 1.0
    if fac == 0.0:
        raise ValueError("the shutter curve is zero everywhere: the shutter never opens")
    # util_cdf_invert, the non-symmetric branch.
    table = np.zeros(resolution, np.float32)
    inv_resolution = np.float32(1.0) / np.float32(resolution)
    for i in range(resolution):
        x = (np.float32(i) + np.float32(0.5)) * inv_resolution
        index = int(np.searchsorted(cdf, x, side="right")) - 1
        if index < count:
            t = (x - cdf[index]) / (cdf[index + 1] - cdf[index])
        else:
            t, index = np.float32(0.0), resolution
        table[i] = (np.float32(index) + t) * inv_resolution
    return table.astype(np.float64)


def _curve_eval(x, curve):
    """Cycles' shutter_curve_eval: the curve array read at x * its length (sic)."""
    x = np.float32(x) * np.float32(curve.size)
    index = int(x)
    frac = x - np.float32(index)
    if index < curve.size - 1:
        return curve[index] + (curve[index + 1] - curve[index]) * frac
    return curve[curve.size - 1]


@device
def lookup_table(data, first, size, u):
    """Linear interpolation at u in [0, 1] in the ``size`` entries of ``data`` from
    ``first`` on (Cycles' lookup_table_read)."""
    x = min(max(u, 0.0), 1.0) * (size - 1)
    i = min(int(x), size - 1)
    j = min(i + 1, size - 1)
    f = x - i
    if f == 0.0:
        return data[first + i]
    return (1.0 - f) * data[first + i] + f * data[first + j]


# -- transforms: decomposition (host) ---------------------------------------------------------
def _to_quat(m) -> np.ndarray:
    """Cycles' transform_to_quat of a rotation matrix: (x, y, z, w)."""
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0.0:
        s = math.sqrt(trace + 1.0)
        w = s / 2.0
        s = 0.5 / s
        return np.array([(m[2, 1] - m[1, 2]) * s, (m[0, 2] - m[2, 0]) * s, (m[1, 0] - m[0, 1]) * s, w])
    i = 0
    if m[1, 1] > m[i, i]:
        i = 1
    if m[2, 2] > m[i, i]:
        i = 2
    j, k = (i + 1) % 3, (i + 2) % 3
    s = math.sqrt(m[i, i] - (m[j, j] + m[k, k]) + 1.0)
    q = np.zeros(4)
    q[i] = s * 0.5
    if s != 0.0:
        s = 0.5 / s
    q[3] = (m[k, j] - m[j, k]) * s
    q[j] = (m[j, i] + m[i, j]) * s
    q[k] = (m[k, i] + m[i, k]) * s
    return q


def _safe_divide(v, s):
    return v / s if s != 0.0 else np.zeros(3)


def decompose(matrix) -> np.ndarray:
    """Cycles' transform_decompose of a 4x4 (or 3x4) affine matrix: 16 floats."""
    m = np.asarray(matrix, np.float64)
    out = np.zeros(DECOMPOSED)
    out[4:7] = m[:3, 3]
    colx, coly, colz = m[:3, 0].copy(), m[:3, 1].copy(), m[:3, 2].copy()
    sx = float(np.linalg.norm(colx))
    colx = _safe_divide(colx, sx)
    shear_z = float(colx @ coly)
    coly -= shear_z * colx
    sy = float(np.linalg.norm(coly))
    coly = _safe_divide(coly, sy)
    shear_y = float(colx @ colz)
    colz -= shear_y * colx
    shear_x = float(coly @ colz)
    colz -= shear_x * coly
    sz = float(np.linalg.norm(colz))
    colz = _safe_divide(colz, sz)
    rot = np.stack([colx, coly, colz], axis=1)
    if np.cross(rot[:, 0], rot[:, 1]) @ rot[:, 2] < 0.0:
        sx, sy, sz = -sx, -sy, -sz
        rot = -rot
    out[0:4] = _to_quat(rot)
    out[7] = sx
    out[8], out[9], out[11] = shear_z, shear_y, sy
    out[12], out[15] = shear_x, sz
    return out


def decompose_steps(matrices) -> np.ndarray:
    """Cycles' transform_motion_decompose of (S, 4, 4) matrices: (S, 16)."""
    steps = [decompose(m) for m in np.asarray(matrices, np.float64)]
    for i in range(1, len(steps)):
        if steps[i - 1][:4] @ steps[i][:4] < 0.0:        # the shortest arc
            steps[i][:4] = -steps[i][:4]
    for i, d in enumerate(steps):
        if d[7] == 0.0 and d[11] == 0.0 and d[15] == 0.0:   # zero scale: keep a neighbour's rotation
            if i > 0:
                d[:4] = steps[i - 1][:4]
            elif i < len(steps) - 1:
                d[:4] = steps[i + 1][:4]
    return np.array(steps).reshape(-1, DECOMPOSED)


# -- transforms: interpolation (kernels) ------------------------------------------------------
@device
def compose(qx, qy, qz, qw, tx, ty, tz, s0x, s1x, s2x, s1y, s2y, s2z):
    """The 3x4 matrix (row-major, 12 floats) of a decomposed transform (Cycles' transform_compose).

    (qx, qy, qz, qw) is the rotation, (tx, ty, tz) the translation and the s's
    the upper-triangular scale-shear matrix: column 0 is (s0x, 0, 0), column 1
    (s1x, s1y, 0), column 2 (s2x, s2y, s2z).
    """
    r2 = math.sqrt(2.0)
    q0, q1, q2, q3 = r2 * qw, r2 * qx, r2 * qy, r2 * qz
    qda, qdb, qdc = q0 * q1, q0 * q2, q0 * q3
    qaa, qab, qac = q1 * q1, q1 * q2, q1 * q3
    qbb, qbc, qcc = q2 * q2, q2 * q3, q3 * q3
    rxx, rxy, rxz = 1.0 - qbb - qcc, -qdc + qab, qdb + qac
    ryx, ryy, ryz = qdc + qab, 1.0 - qaa - qcc, -qda + qbc
    rzx, rzy, rzz = -qdb + qac, qda + qbc, 1.0 - qaa - qbb
    return (rxx * s0x, rxx * s1x + rxy * s1y, rxx * s2x + rxy * s2y + rxz * s2z, tx,
            ryx * s0x, ryx * s1x + ryy * s1y, ryx * s2x + ryy * s2y + ryz * s2z, ty,
            rzx * s0x, rzx * s1x + rzy * s1y, rzx * s2x + rzy * s2y + rzz * s2z, tz)


@device
def motion_step(steps, time):
    """The step below ``time`` in [0, 1] and the fraction towards the next, over ``steps`` steps."""
    last = steps - 1
    step = min(int(time * last), last - 1)
    return step, time * last - step


@device
def motion_transform(d, first, steps, time):
    """The 3x4 matrix (12 floats, row-major) at ``time`` of the ``steps`` decomposed
    transforms stored from ``d[first]`` on (Cycles' transform_motion_array_interpolate)."""
    step, t = motion_step(steps, time)
    a = first + step * DECOMPOSED
    b = a + DECOMPOSED
    # Rotation: slerp on the arc (the decomposition made it the shortest one).
    cos = d[a] * d[b] + d[a + 1] * d[b + 1] + d[a + 2] * d[b + 2] + d[a + 3] * d[b + 3]
    if cos > SLERP_THRESHOLD:
        x = (1.0 - t) * d[a] + t * d[b]
        y = (1.0 - t) * d[a + 1] + t * d[b + 1]
        z = (1.0 - t) * d[a + 2] + t * d[b + 2]
        w = (1.0 - t) * d[a + 3] + t * d[b + 3]
        inv = 1.0 / math.sqrt(x * x + y * y + z * z + w * w)
        x, y, z, w = x * inv, y * inv, z * inv, w * inv
    else:
        theta = safe_acos(cos)
        px = d[b] - d[a] * cos
        py = d[b + 1] - d[a + 1] * cos
        pz = d[b + 2] - d[a + 2] * cos
        pw = d[b + 3] - d[a + 3] * cos
        inv = 1.0 / math.sqrt(px * px + py * py + pz * pz + pw * pw)
        c, s = math.cos(theta * t), math.sin(theta * t) * inv
        x, y, z, w = d[a] * c + px * s, d[a + 1] * c + py * s, d[a + 2] * c + pz * s, d[a + 3] * c + pw * s
    u = 1.0 - t
    return compose(x, y, z, w,
                   u * d[a + 4] + t * d[b + 4], u * d[a + 5] + t * d[b + 5], u * d[a + 6] + t * d[b + 6],
                   u * d[a + 7] + t * d[b + 7], u * d[a + 8] + t * d[b + 8], u * d[a + 9] + t * d[b + 9],
                   u * d[a + 11] + t * d[b + 11], u * d[a + 12] + t * d[b + 12],
                   u * d[a + 15] + t * d[b + 15])


# -- moving geometry ----------------------------------------------------------------------------
# A moving object's triangles are intersected in the object's frame pose ("rest space": the
# world positions at the frame): a ray at time t is mapped there by B(t) = M(frame) M(t)^-1,
# which keeps its parameter t, and meets the triangle as it is at t (deformation steps
# interpolated linearly); the hit is shaded in world space with A(t) = B(t)^-1.
MotionData = namedtuple("MotionData", [
    "tri_slot",      # (T,) int32   moving object of each triangle, -1 static; (0,) without motion
    "tri_local",     # (T,) int32   the triangle's rank among its object's triangles
    "tri_flat",      # (T,) uint8   flat shaded (its corner normals are equal): shaded with the
                     #              geometric normal at the ray's time, as Cycles shades flat faces
    "slot_info",     # (J, SLOT_INFO) int64  per moving object (SI_* columns)
    "xforms",        # (N,) f64     decomposed transforms, 16 per step
    "frame",         # (J, 12) f64  M(frame), 3x4 row-major
    "frame_inv",     # (J, 12) f64  M(frame)^-1
    "world_box",     # (J, 6) f64   world bounds of the object over the shutter (lo, hi)
    "positions",     # (P, 3) f64   deformation steps in rest space
    "normals",       # (Q, 3, 3) f64  corner normals at the deformation steps
    "bvh_box",       # (K, 6) f64   BVH node bounds in rest space, one BVH per slot and segment
    "bvh_node",      # (K, 3) int32 skip index, first and count of a leaf's triangles (count 0: inner)
    "bvh_tris",      # (L,) int32   triangles of the leaves (scene ids)
    "bvh_root",      # (R, 2) int32 [first, end) nodes of each (slot, segment) BVH
])
SI_STEPS = 0          # motion steps
SI_XFORM = 1          # first decomposed transform in xforms (-1: no transform motion)
SI_VFIRST = 2         # the object's vertices in the scene
SI_VCOUNT = 3
SI_POS = 4            # first row in positions (-1: no deformation)
SI_NRM = 5            # first row in normals
SI_NTRIS = 6          # the object's triangle count
SI_ROOT = 7           # first row in bvh_root (one per segment, or one when rigid)
SLOT_INFO = 8
BVH_LEAF = 4          # triangles per BVH leaf
BOUND_SAMPLES = 64    # transform samples per motion segment for the world bounds


def no_motion() -> MotionData:
    """Motion data of a scene where nothing moves."""
    z = np.zeros
    return MotionData(z(0, np.int32), z(0, np.int32), z(0, np.uint8), z((0, SLOT_INFO), np.int64), z(0),
                      z((0, 12)),
                      z((0, 12)), z((0, 6)), z((0, 3)), z((0, 3, 3)), z((0, 6)), z((0, 3), np.int32),
                      z(0, np.int32), z((0, 2), np.int32))


def _affine_inverse(m):
    out = np.eye(4)
    out[:3, :3] = np.linalg.inv(m[:3, :3])
    out[:3, 3] = -out[:3, :3] @ m[:3, 3]
    return out


def moves(om, vertices) -> bool:
    """Whether an :class:`~mcengine.scene.ObjectMotion` moves at all (Cycles drops motion that
    does not: every step equal to the frame's)."""
    mats = np.asarray(om.matrices)
    if len(mats) and np.any(mats != mats[len(mats) // 2]):
        return True
    if om.positions is None:
        return False
    first, count = (int(v) for v in om.vertices)
    rest = np.asarray(vertices[first:first + count], np.float32)
    return bool(np.any(np.asarray(om.positions, np.float32) != rest))


def pack_motion(geometry, objects) -> MotionData:
    """Kernel tables of the moving objects (a list of :class:`mcengine.scene.ObjectMotion`)."""
    objects = [om for om in objects if moves(om, geometry.vertices)]
    if not objects:
        return no_motion()
    t = geometry.num_triangles
    verts = geometry.vertices.astype(np.float64)
    tris = np.asarray(geometry.triangles, np.int64)
    tri_slot = np.full(t, -1, np.int32)
    tri_local = np.full(t, -1, np.int32)
    tri_flat = np.zeros(t, np.uint8)        # read for moving triangles only: set below
    info = np.zeros((len(objects), SLOT_INFO), np.int64)
    xforms, positions, normals, roots = [], [], [], []
    frame = np.zeros((len(objects), 12))
    frame_inv = np.zeros((len(objects), 12))
    world_box = np.zeros((len(objects), 6))
    boxes, nodes, leaves = [], [], []
    n_xf = n_pos = n_nrm = n_nodes = n_leaves = 0
    for j, om in enumerate(objects):
        mine = np.flatnonzero(geometry.object_index == om.object).astype(np.int32)
        tri_slot[mine] = j
        tri_local[mine] = np.arange(len(mine), dtype=np.int32)
        n = np.take(geometry.normals, geometry.normal_index[mine], axis=0)
        tri_flat[mine] = np.all(n[:, 0] == n[:, 1], axis=1) & np.all(n[:, 0] == n[:, 2], axis=1)
        first, count = (int(v) for v in om.vertices)
        steps = om.steps
        info[j, SI_STEPS], info[j, SI_VFIRST], info[j, SI_VCOUNT] = steps, first, count
        info[j, SI_NTRIS] = len(mine)
        mats = np.asarray(om.matrices, np.float64)
        if len(mats) and not np.any(mats != mats[steps // 2]):
            mats = mats[:0]                  # a still transform: only the mesh deforms
        center = mats[steps // 2] if len(mats) else np.eye(4)
        frame[j] = center[:3].ravel()
        frame_inv[j] = _affine_inverse(center)[:3].ravel()
        if len(mats):
            info[j, SI_XFORM] = n_xf
            d = decompose_steps(mats).ravel()
            xforms.append(d)
            n_xf += d.size
        else:
            info[j, SI_XFORM] = -1
        if om.positions is not None:
            pos = np.asarray(om.positions, np.float64).reshape(steps, count, 3)
            info[j, SI_POS], info[j, SI_NRM] = n_pos, n_nrm
            positions.append(pos.reshape(-1, 3))
            normals.append(np.asarray(om.normals, np.float64).reshape(-1, 3, 3))
            n_pos += steps * count
            n_nrm += steps * len(mine)
            rest = pos                                   # (S, count, 3)
        else:
            info[j, SI_POS] = info[j, SI_NRM] = -1
            rest = verts[first:first + count][None]      # one segment: the rest pose
        # One BVH per segment between deformation steps (one in all for a rigid object).
        info[j, SI_ROOT] = len(roots)
        corner = tris[mine] - first                      # (T_o, 3)
        for seg in range(max(len(rest) - 1, 1)):
            a = rest[seg][corner]
            b = rest[min(seg + 1, len(rest) - 1)][corner]
            lo = np.minimum(a.min(axis=1), b.min(axis=1))
            hi = np.maximum(a.max(axis=1), b.max(axis=1))
            box, node, order = build_bvh(lo, hi, BVH_LEAF)
            node[:, 0] += n_nodes
            node[:, 1] += n_leaves
            roots.append((n_nodes, n_nodes + len(node)))
            boxes.append(box)
            nodes.append(node)
            leaves.append(mine[order])
            n_nodes += len(node)
            n_leaves += len(order)
        world_box[j] = _world_bounds(rest, mats, frame_inv[j])
    return MotionData(
        tri_slot=tri_slot, tri_local=tri_local, tri_flat=tri_flat, slot_info=info,
        xforms=np.concatenate(xforms) if xforms else np.zeros(0), frame=frame, frame_inv=frame_inv,
        world_box=world_box,
        positions=np.concatenate(positions) if positions else np.zeros((0, 3)),
        normals=np.concatenate(normals) if normals else np.zeros((0, 3, 3)),
        bvh_box=np.concatenate(boxes), bvh_node=np.concatenate(nodes).astype(np.int32),
        bvh_tris=np.concatenate(leaves).astype(np.int32), bvh_root=np.array(roots, np.int32))


def _world_bounds(rest, mats, frame_inv) -> np.ndarray:
    """World box holding the object at every time of the shutter (lo, hi).

    The rest-space box of all deformation steps, its corners carried by A(t)
    sampled densely over every segment; the box grows by the longest step a
    corner makes between two samples (the path between them stays within that
    distance of either end).
    """
    lo = rest.reshape(-1, 3).min(axis=0)
    hi = rest.reshape(-1, 3).max(axis=0)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    if not len(mats):
        return np.concatenate([lo, hi])
    d = decompose_steps(mats).ravel()
    inv = np.vstack([frame_inv.reshape(3, 4), [0, 0, 0, 1]])
    samples = (len(mats) - 1) * BOUND_SAMPLES + 1
    pts = []
    for time in np.linspace(0.0, 1.0, samples):
        m = np.vstack([np.reshape(motion_transform(d, 0, len(mats), float(time)), (3, 4)), [0, 0, 0, 1]])
        a = m @ inv
        pts.append(corners @ a[:3, :3].T + a[:3, 3])
    pts = np.array(pts)                                  # (samples, 8, 3)
    pad = np.linalg.norm(np.diff(pts, axis=0), axis=2).max() if samples > 1 else 0.0
    pad += 1e-9 * max(1.0, float(np.abs(pts).max()))
    return np.concatenate([pts.min(axis=(0, 1)) - pad, pts.max(axis=(0, 1)) + pad])


@builder
def build_bvh(lo, hi, leaf):
    """Bounding-volume hierarchy over N boxes, depth-first with skip pointers.

    Returns ``(box (K, 6), node (K, 3) [skip, first, count], order (N,))``:
    a ray that misses node k continues at ``skip``; a leaf's boxes are
    ``order[first:first + count]``.  Nodes split at the median centroid along
    their widest axis.
    """
    n = lo.shape[0]
    order = np.arange(n)
    cent = 0.5 * (lo + hi)
    cap = 2 * n + 1
    box = np.zeros((cap, 6))
    node = np.zeros((cap, 3), np.int64)
    parent = np.full(cap, -1, np.int64)
    stack = np.zeros((64 + 2 * int(np.log2(n + 1)) + 2, 3), np.int64)   # start, end, parent
    stack[0, 0], stack[0, 1], stack[0, 2] = 0, n, -1
    top = 1
    k = 0
    while top > 0:
        top -= 1
        start, end, par = stack[top, 0], stack[top, 1], stack[top, 2]
        for a in range(3):
            box[k, a] = np.inf
            box[k, 3 + a] = -np.inf
        clo = np.full(3, np.inf)
        chi = np.full(3, -np.inf)
        for e in range(start, end):
            q = order[e]
            for a in range(3):
                box[k, a] = min(box[k, a], lo[q, a])
                box[k, 3 + a] = max(box[k, 3 + a], hi[q, a])
                clo[a] = min(clo[a], cent[q, a])
                chi[a] = max(chi[a], cent[q, a])
        parent[k] = par
        if end - start <= leaf:
            node[k, 1], node[k, 2] = start, end - start
        else:
            axis = 0
            if chi[1] - clo[1] > chi[axis] - clo[axis]:
                axis = 1
            if chi[2] - clo[2] > chi[axis] - clo[axis]:
                axis = 2
            idx = order[start:end].copy()
            keys = np.empty(end - start)
            for e in range(end - start):
                keys[e] = cent[idx[e], axis]
            order[start:end] = idx[np.argsort(keys, kind="mergesort")]
            mid = (start + end) // 2
            # Depth first: the left child is node k + 1 (pushed last, popped next).
            stack[top, 0], stack[top, 1], stack[top, 2] = mid, end, k
            stack[top + 1, 0], stack[top + 1, 1], stack[top + 1, 2] = start, mid, k
            top += 2
        k += 1
    size = np.ones(k, np.int64)
    for i in range(k - 1, 0, -1):
        size[parent[i]] += size[i]
    for i in range(k):
        node[i, 0] = i + size[i]
    return box[:k], node[:k], order


@device
def slot_matrix(md, j, time):
    """A(t) = M(t) M(frame)^-1 of moving object j: rest space to world at ``time`` (12 floats)."""
    info = md.slot_info
    f = md.frame_inv
    if info[j, SI_XFORM] < 0:
        return 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0
    m = motion_transform(md.xforms, info[j, SI_XFORM], info[j, SI_STEPS], time)
    return (m[0] * f[j, 0] + m[1] * f[j, 4] + m[2] * f[j, 8],
            m[0] * f[j, 1] + m[1] * f[j, 5] + m[2] * f[j, 9],
            m[0] * f[j, 2] + m[1] * f[j, 6] + m[2] * f[j, 10],
            m[0] * f[j, 3] + m[1] * f[j, 7] + m[2] * f[j, 11] + m[3],
            m[4] * f[j, 0] + m[5] * f[j, 4] + m[6] * f[j, 8],
            m[4] * f[j, 1] + m[5] * f[j, 5] + m[6] * f[j, 9],
            m[4] * f[j, 2] + m[5] * f[j, 6] + m[6] * f[j, 10],
            m[4] * f[j, 3] + m[5] * f[j, 7] + m[6] * f[j, 11] + m[7],
            m[8] * f[j, 0] + m[9] * f[j, 4] + m[10] * f[j, 8],
            m[8] * f[j, 1] + m[9] * f[j, 5] + m[10] * f[j, 9],
            m[8] * f[j, 2] + m[9] * f[j, 6] + m[10] * f[j, 10],
            m[8] * f[j, 3] + m[9] * f[j, 7] + m[10] * f[j, 11] + m[11])


@device
def inverse_affine(a):
    """Inverse of a 3x4 affine matrix (12 floats); a singular one gives non-finite values."""
    c00 = a[5] * a[10] - a[6] * a[9]
    c01 = a[2] * a[9] - a[1] * a[10]
    c02 = a[1] * a[6] - a[2] * a[5]
    c10 = a[6] * a[8] - a[4] * a[10]
    c11 = a[0] * a[10] - a[2] * a[8]
    c12 = a[2] * a[4] - a[0] * a[6]
    c20 = a[4] * a[9] - a[5] * a[8]
    c21 = a[1] * a[8] - a[0] * a[9]
    c22 = a[0] * a[5] - a[1] * a[4]
    inv = 1.0 / (a[0] * c00 + a[1] * c10 + a[2] * c20)
    r00, r01, r02 = c00 * inv, c01 * inv, c02 * inv
    r10, r11, r12 = c10 * inv, c11 * inv, c12 * inv
    r20, r21, r22 = c20 * inv, c21 * inv, c22 * inv
    return (r00, r01, r02, -(r00 * a[3] + r01 * a[7] + r02 * a[11]),
            r10, r11, r12, -(r10 * a[3] + r11 * a[7] + r12 * a[11]),
            r20, r21, r22, -(r20 * a[3] + r21 * a[7] + r22 * a[11]))


@device
def rest_position(md, verts, j, v, time):
    """Vertex ``v`` of moving object j in rest space at ``time``."""
    info = md.slot_info
    if info[j, SI_POS] < 0:
        return verts[v, 0], verts[v, 1], verts[v, 2]
    step, f = motion_step(info[j, SI_STEPS], time)
    count = info[j, SI_VCOUNT]
    a = info[j, SI_POS] + step * count + v - info[j, SI_VFIRST]
    b = a + count
    pos = md.positions
    return ((1.0 - f) * pos[a, 0] + f * pos[b, 0], (1.0 - f) * pos[a, 1] + f * pos[b, 1],
            (1.0 - f) * pos[a, 2] + f * pos[b, 2])


@device
def rest_triangle(md, verts, tris, p, time):
    """The corners of moving triangle p in rest space at ``time`` (9 floats)."""
    j = md.tri_slot[p]
    ax, ay, az = rest_position(md, verts, j, tris[p, 0], time)
    bx, by, bz = rest_position(md, verts, j, tris[p, 1], time)
    cx, cy, cz = rest_position(md, verts, j, tris[p, 2], time)
    return ax, ay, az, bx, by, bz, cx, cy, cz


@device
def apply_point(m, x, y, z):
    return (m[0] * x + m[1] * y + m[2] * z + m[3], m[4] * x + m[5] * y + m[6] * z + m[7],
            m[8] * x + m[9] * y + m[10] * z + m[11])


@device
def apply_vector(m, x, y, z):
    return m[0] * x + m[1] * y + m[2] * z, m[4] * x + m[5] * y + m[6] * z, m[8] * x + m[9] * y + m[10] * z


# The two below are called, not inlined: every shading step reaches them through
# intersect.prim_corners and prim_normals, and inlining them at each of those places made
# the path kernels several times larger, for scenes where nothing moves too.
@function
def moving_triangle(md, verts, tris, p, time):
    """The corners of moving triangle p in world space at ``time`` (9 floats)."""
    a = slot_matrix(md, md.tri_slot[p], time)
    ax, ay, az, bx, by, bz, cx, cy, cz = rest_triangle(md, verts, tris, p, time)
    ax, ay, az = apply_point(a, ax, ay, az)
    bx, by, bz = apply_point(a, bx, by, bz)
    cx, cy, cz = apply_point(a, cx, cy, cz)
    return ax, ay, az, bx, by, bz, cx, cy, cz


@device
def corner_normals(normals, normal_index, p):
    """The shading normals of triangle p's three corners (9 floats): the rows
    ``normal_index[p, k]`` of the normal table (``Geometry.normals``)."""
    i0, i1, i2 = normal_index[p, 0], normal_index[p, 1], normal_index[p, 2]
    return (normals[i0, 0], normals[i0, 1], normals[i0, 2], normals[i1, 0], normals[i1, 1],
            normals[i1, 2], normals[i2, 0], normals[i2, 1], normals[i2, 2])


@function
def moving_normals(md, verts, tris, normals, normal_index, p, time):
    """The corner shading normals of moving triangle p in world space at ``time`` (9 floats,
    each of unit length): deformation steps interpolated linearly and normalised, as Cycles
    does, then carried by the inverse transpose of A(t); a deforming flat face takes the
    normal of its triangle at that time."""
    j = md.tri_slot[p]
    info = md.slot_info
    if md.tri_flat[p] and info[j, SI_POS] >= 0:
        # A flat face that deforms: the normal of the triangle as it is at this time.
        ax, ay, az, bx, by, bz, cx, cy, cz = moving_triangle(md, verts, tris, p, time)
        e1x, e1y, e1z = bx - ax, by - ay, bz - az
        e2x, e2y, e2z = cx - ax, cy - ay, cz - az
        nx, ny, nz = _unit(e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x)
        return nx, ny, nz, nx, ny, nz, nx, ny, nz
    if info[j, SI_NRM] < 0:
        n0x, n0y, n0z, n1x, n1y, n1z, n2x, n2y, n2z = corner_normals(normals, normal_index, p)
    else:
        step, f = motion_step(info[j, SI_STEPS], time)
        a = info[j, SI_NRM] + step * info[j, SI_NTRIS] + md.tri_local[p]
        b = a + info[j, SI_NTRIS]
        nn = md.normals
        n0x, n0y, n0z = _unit((1.0 - f) * nn[a, 0, 0] + f * nn[b, 0, 0], (1.0 - f) * nn[a, 0, 1] + f * nn[b, 0, 1],
                              (1.0 - f) * nn[a, 0, 2] + f * nn[b, 0, 2])
        n1x, n1y, n1z = _unit((1.0 - f) * nn[a, 1, 0] + f * nn[b, 1, 0], (1.0 - f) * nn[a, 1, 1] + f * nn[b, 1, 1],
                              (1.0 - f) * nn[a, 1, 2] + f * nn[b, 1, 2])
        n2x, n2y, n2z = _unit((1.0 - f) * nn[a, 2, 0] + f * nn[b, 2, 0], (1.0 - f) * nn[a, 2, 1] + f * nn[b, 2, 1],
                              (1.0 - f) * nn[a, 2, 2] + f * nn[b, 2, 2])
    m = slot_matrix(md, j, time)
    # Normals go with the cofactor matrix det(A) A^-T, its sign made positive.
    c = (m[5] * m[10] - m[6] * m[9], m[6] * m[8] - m[4] * m[10], m[4] * m[9] - m[5] * m[8], 0.0,
         m[2] * m[9] - m[1] * m[10], m[0] * m[10] - m[2] * m[8], m[1] * m[8] - m[0] * m[9], 0.0,
         m[1] * m[6] - m[2] * m[5], m[2] * m[4] - m[0] * m[6], m[0] * m[5] - m[1] * m[4], 0.0)
    if m[0] * c[0] + m[1] * c[1] + m[2] * c[2] < 0.0:
        c = (-c[0], -c[1], -c[2], 0.0, -c[4], -c[5], -c[6], 0.0, -c[8], -c[9], -c[10], 0.0)
    n0x, n0y, n0z = apply_vector(c, n0x, n0y, n0z)
    n1x, n1y, n1z = apply_vector(c, n1x, n1y, n1z)
    n2x, n2y, n2z = apply_vector(c, n2x, n2y, n2z)
    n0x, n0y, n0z = _unit(n0x, n0y, n0z)
    n1x, n1y, n1z = _unit(n1x, n1y, n1z)
    n2x, n2y, n2z = _unit(n2x, n2y, n2z)
    return n0x, n0y, n0z, n1x, n1y, n1z, n2x, n2y, n2z


@device
def _unit(x, y, z):
    length = math.sqrt(x * x + y * y + z * z)
    if length > 0.0:
        return x / length, y / length, z / length
    return x, y, z


# -- intersecting moving geometry -----------------------------------------------------------------
@device
def hit_triangle(ox, oy, oz, dx, dy, dz, ax, ay, az, bx, by, bz, cx, cy, cz):
    """Distance t > 0 along the ray to the triangle (edges included), or inf (float64)."""
    e1x, e1y, e1z = bx - ax, by - ay, bz - az
    e2x, e2y, e2z = cx - ax, cy - ay, cz - az
    px, py, pz = dy * e2z - dz * e2y, dz * e2x - dx * e2z, dx * e2y - dy * e2x
    det = e1x * px + e1y * py + e1z * pz
    if det == 0.0:
        return math.inf
    inv = 1.0 / det
    tx, ty, tz = ox - ax, oy - ay, oz - az
    u = (tx * px + ty * py + tz * pz) * inv
    if u < 0.0 or u > 1.0:
        return math.inf
    qx, qy, qz = ty * e1z - tz * e1y, tz * e1x - tx * e1z, tx * e1y - ty * e1x
    v = (dx * qx + dy * qy + dz * qz) * inv
    if v < 0.0 or u + v > 1.0:
        return math.inf
    t = (e2x * qx + e2y * qy + e2z * qz) * inv
    return t if t > 0.0 else math.inf


@device
def ray_box(ox, oy, oz, dx, dy, dz, box, k, tmax):
    """Does the segment (0, tmax) of the ray meet box k (lo xyz, hi xyz)?"""
    t0, t1 = 0.0, tmax
    for a in range(3):
        o = ox if a == 0 else (oy if a == 1 else oz)
        d = dx if a == 0 else (dy if a == 1 else dz)
        lo, hi = box[k, a], box[k, 3 + a]
        if d == 0.0:
            if o < lo or o > hi:
                return False
            continue
        inv = 1.0 / d
        near, far = (lo - o) * inv, (hi - o) * inv
        if near > far:
            near, far = far, near
        t0 = max(t0, near)
        t1 = min(t1, far)
        if t0 > t1:
            return False
    return True


@device
def slot_hit(md, verts, tris, j, ox, oy, oz, dx, dy, dz, tmax, time, any_hit):
    """Closest (or, with ``any_hit``, some) hit within (0, tmax) of a world ray at ``time``
    on moving object j: ``(t, triangle)``, triangle -1 for none."""
    if not ray_box(ox, oy, oz, dx, dy, dz, md.world_box, j, tmax):
        return tmax, -1
    info = md.slot_info
    if info[j, SI_XFORM] >= 0:
        b = inverse_affine(slot_matrix(md, j, time))
        ox, oy, oz = apply_point(b, ox, oy, oz)
        dx, dy, dz = apply_vector(b, dx, dy, dz)
    root = info[j, SI_ROOT]
    if info[j, SI_POS] >= 0:
        root += motion_step(info[j, SI_STEPS], time)[0]
    k, end = md.bvh_root[root, 0], md.bvh_root[root, 1]
    best, found = tmax, -1
    while k < end:
        if not ray_box(ox, oy, oz, dx, dy, dz, md.bvh_box, k, best):
            k = md.bvh_node[k, 0]
            continue
        count = md.bvh_node[k, 2]
        first = md.bvh_node[k, 1]
        for e in range(first, first + count):
            p = md.bvh_tris[e]
            ax, ay, az, bx, by, bz, cx, cy, cz = rest_triangle(md, verts, tris, p, time)
            t = hit_triangle(ox, oy, oz, dx, dy, dz, ax, ay, az, bx, by, bz, cx, cy, cz)
            if t < best:
                best, found = t, p
                if any_hit:
                    return best, found
        k += 1
    return best, found


@device
def _sees(slot_masks, mask, i, j):
    """Whether ray i sees slot j (its mask shares a bit with the slot's)."""
    if mask.shape[0] == 0:
        return True
    m = mask[i] if mask.shape[0] > 1 else mask[0]
    return (slot_masks[j] & m) != 0


@kernel
def moving_closest(md, verts, tris, o32, d32, time, best, prim, slot_masks, mask):
    """Lower ``best`` and update ``prim`` where a moving object is hit closer (n rays).
    ``slot_masks``: each slot's visibility and ``mask`` the rays' (``intersect.Accel``;
    empty: every ray sees every slot)."""
    for i in range(prim.shape[0]):
        ox, oy, oz = float(o32[i, 0]), float(o32[i, 1]), float(o32[i, 2])
        dx, dy, dz = float(d32[i, 0]), float(d32[i, 1]), float(d32[i, 2])
        for j in range(md.slot_info.shape[0]):
            if not _sees(slot_masks, mask, i, j):
                continue
            t, p = slot_hit(md, verts, tris, j, ox, oy, oz, dx, dy, dz, best[i], time[i], False)
            if p >= 0:
                best[i], prim[i] = t, p


@kernel
def moving_occluded(md, verts, tris, o32, d32, t32, time, occluded, slot_masks, mask):
    """Set ``occluded`` where a moving object blocks the segment (0, t32) (n rays; masks as
    in ``moving_closest``)."""
    for i in range(occluded.shape[0]):
        if occluded[i]:
            continue
        ox, oy, oz = float(o32[i, 0]), float(o32[i, 1]), float(o32[i, 2])
        dx, dy, dz = float(d32[i, 0]), float(d32[i, 1]), float(d32[i, 2])
        for j in range(md.slot_info.shape[0]):
            if not _sees(slot_masks, mask, i, j):
                continue
            if slot_hit(md, verts, tris, j, ox, oy, oz, dx, dy, dz, float(t32[i]), time[i], True)[1] >= 0:
                occluded[i] = True
                break
