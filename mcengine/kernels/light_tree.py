"""A light tree over the emissive triangles: which one next-event estimation samples at a point.

Next-event estimation first picks among the lights as a whole (``light_sampling``: the
lamps, the world and the emissive triangles as one group); this tree then picks one
triangle of the group in proportion to its importance at the receiver, as Cycles' light
tree does for mesh lights (kernel/light/tree.h): a triangle's power over its squared
distance (floored at its bounding sphere's radius squared), times the facing term that
leaves out triangles wholly behind the receiver's surface.  Emission is two-sided, so, as
for Cycles' double-sided emitters, the emitter's own orientation bounds nothing.

The tree is a complete binary tree in heap order (the children of node k are 2k + 1 and
2k + 2), its leaves last, each holding up to ``LEAF_SIZE`` triangles consecutive along a
Morton curve through their centroids.  Each node keeps the bounding sphere of its
triangles' box and their summed power; a pick descends from the root choosing a child in
proportion to the two importances, and ``tree_pmf`` retraces that path upwards for the MIS
weight of a triangle that a BSDF ray hit.  Empty (padding) nodes have no power and are
never chosen.  Where emissive triangles move during the shutter there is no tree (its
spheres would not bound them): the group's triangles are picked by power.
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from ..jit import device
from .lights import facing_sphere

LEAF_SIZE = 4                # triangles per leaf
MORTON_BITS = 10             # bits per axis of the centroids' Morton code
MIN_RADIUS2 = 1e-12          # floor of a sphere's radius squared (the distance floor)

# Columns of EmitterTree.nodes and .bounds.
S_CENTRE = 0                 # centre x, y, z of the bounding sphere
S_RADIUS2 = 3                # its radius squared
S_POWER = 4                  # the power of the triangles inside (0: an empty node)
S_STRIDE = 5

EmitterTree = namedtuple("EmitterTree", [
    "nodes",     # (2L - 1, S_STRIDE) f64  the tree in heap order, its L leaves last
    "bounds",    # (NE, S_STRIDE) f64      each emissive triangle's own sphere and power
    "order",     # (L * LEAF_SIZE,) int32  the triangles of leaf k at [k LEAF_SIZE, ...): -1 empty
    "rank",      # (NE,) int32             where each triangle is in ``order``
])


def no_tree() -> EmitterTree:
    """The tree of a scene whose emissive triangles are picked by power (or that has none)."""
    return EmitterTree(np.zeros((0, S_STRIDE)), np.zeros((0, S_STRIDE)), np.zeros(0, np.int32),
                       np.zeros(0, np.int32))


def sphere_rows(lo, hi, power) -> np.ndarray:
    """(N, S_STRIDE) rows of ``sphere_importance``: the spheres around the boxes [lo, hi]
    (N, 3) with their power (N,); a row without power is all zero."""
    rows = np.zeros((len(lo), S_STRIDE))
    full = power > 0.0
    rows[full, S_CENTRE:S_CENTRE + 3] = 0.5 * (lo[full] + hi[full])
    rows[full, S_RADIUS2] = np.maximum(0.25 * np.sum((hi[full] - lo[full]) ** 2, axis=1), MIN_RADIUS2)
    rows[:, S_POWER] = np.where(full, power, 0.0)
    return rows


def _morton(points) -> np.ndarray:
    """Morton codes of points (N, 3), MORTON_BITS bits per axis over their bounding box."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    scale = (1 << MORTON_BITS) - 1
    q = np.floor((points - lo) / np.maximum(hi - lo, 1e-30) * scale).astype(np.int64)
    q = np.clip(q, 0, scale)
    code = np.zeros(len(points), np.int64)
    for bit in range(MORTON_BITS):
        for axis in range(3):
            code |= ((q[:, axis] >> bit) & 1) << (3 * bit + axis)
    return code


def build_emitter_tree(corners, power) -> EmitterTree:
    """The tree over triangles with ``corners`` (NE, 3, 3) and ``power`` (NE,) (> 0 to be
    picked at all)."""
    corners = np.asarray(corners, np.float64)
    power = np.asarray(power, np.float64)
    n = len(power)
    if n == 0:
        return no_tree()
    sorted_ = np.argsort(_morton(corners.mean(axis=1)), kind="stable")
    leaves = 1 << max(0, math.ceil(math.log2(math.ceil(n / LEAF_SIZE))))
    order = np.full(leaves * LEAF_SIZE, -1, np.int32)
    order[:n] = sorted_
    rank = np.empty(n, np.int32)
    rank[sorted_] = np.arange(n, dtype=np.int32)

    lo_t, hi_t = corners.min(axis=1), corners.max(axis=1)
    filled = order >= 0
    lo = np.full((len(order), 3), np.inf)
    hi = np.full((len(order), 3), -np.inf)
    slot_power = np.zeros(len(order))
    lo[filled], hi[filled] = lo_t[order[filled]], hi_t[order[filled]]
    slot_power[filled] = power[order[filled]]
    # Boxes and power of every node, the leaves from the slots, then level by level upwards.
    count = 2 * leaves - 1
    node_lo, node_hi, node_power = np.empty((count, 3)), np.empty((count, 3)), np.empty(count)
    node_lo[leaves - 1:] = lo.reshape(leaves, LEAF_SIZE, 3).min(axis=1)
    node_hi[leaves - 1:] = hi.reshape(leaves, LEAF_SIZE, 3).max(axis=1)
    node_power[leaves - 1:] = slot_power.reshape(leaves, LEAF_SIZE).sum(axis=1)
    width = leaves // 2
    while width >= 1:
        k = np.arange(width - 1, 2 * width - 1)
        node_lo[k] = np.minimum(node_lo[2 * k + 1], node_lo[2 * k + 2])
        node_hi[k] = np.maximum(node_hi[2 * k + 1], node_hi[2 * k + 2])
        node_power[k] = node_power[2 * k + 1] + node_power[2 * k + 2]
        width //= 2
    return EmitterTree(sphere_rows(node_lo, node_hi, node_power), sphere_rows(lo_t, hi_t, power),
                       order, rank)


@device
def sphere_importance(rows, k, recv):
    """Importance of row k (a sphere and its power) at the receiver ``recv`` (point and
    normal, or no normal: see ``light_sampling.receiver``): power over the squared distance,
    floored at the radius squared, times the facing term; 0 for no power or a sphere wholly
    behind the receiver's surface."""
    power = rows[k, S_POWER]
    if power <= 0.0:
        return 0.0
    px, py, pz, rx, ry, rz = recv
    dx, dy, dz = px - rows[k, S_CENTRE], py - rows[k, S_CENTRE + 1], pz - rows[k, S_CENTRE + 2]
    d2 = dx * dx + dy * dy + dz * dz
    r2 = rows[k, S_RADIUS2]
    return power / max(d2, r2) * facing_sphere(rx, ry, rz, dx, dy, dz, d2, math.sqrt(r2))


@device
def _leaf_total(tree, leaf, recv):
    """Summed importance of the triangles of leaf ``leaf`` (0-based among the leaves)."""
    total = 0.0
    for s in range(leaf * LEAF_SIZE, (leaf + 1) * LEAF_SIZE):
        j = tree.order[s]
        if j >= 0:
            total += sphere_importance(tree.bounds, j, recv)
    return total


@device
def tree_pick(tree, recv, u):
    """Pick an emissive triangle at the receiver with the number u in [0, 1): ``(j, pmf)``,
    j indexing ``SceneData.emit_tri``; (-1, 0) when no triangle can light the receiver."""
    nodes = tree.nodes
    first_leaf = nodes.shape[0] // 2
    k = 0
    pmf = 1.0
    while k < first_leaf:
        a = sphere_importance(nodes, 2 * k + 1, recv)
        b = sphere_importance(nodes, 2 * k + 2, recv)
        if not a + b > 0.0:
            return -1, 0.0
        pa = a / (a + b)
        if u < pa:
            k = 2 * k + 1
            u = u / pa
            pmf *= pa
        else:
            k = 2 * k + 2
            u = min((u - pa) / (1.0 - pa), 1.0) if pa < 1.0 else 0.0
            pmf *= b / (a + b)
    leaf = k - first_leaf
    total = _leaf_total(tree, leaf, recv)
    if not total > 0.0:
        return -1, 0.0
    target = u * total
    acc = 0.0
    last, last_w = -1, 0.0
    for s in range(leaf * LEAF_SIZE, (leaf + 1) * LEAF_SIZE):
        j = tree.order[s]
        if j < 0:
            continue
        w = sphere_importance(tree.bounds, j, recv)
        if w > 0.0:
            acc += w
            last, last_w = j, w
            if target < acc:
                return j, pmf * w / total
    return last, pmf * last_w / total      # rounding at the end of the leaf


@device
def tree_pmf(tree, j, recv):
    """The probability that ``tree_pick`` at the receiver returns triangle j."""
    nodes = tree.nodes
    first_leaf = nodes.shape[0] // 2
    leaf = tree.rank[j] // LEAF_SIZE
    w = sphere_importance(tree.bounds, j, recv)
    if not w > 0.0:
        return 0.0
    pmf = w / _leaf_total(tree, leaf, recv)
    k = first_leaf + leaf
    while k > 0:
        parent = (k - 1) // 2
        a = sphere_importance(nodes, 2 * parent + 1, recv)
        b = sphere_importance(nodes, 2 * parent + 2, recv)
        if not a + b > 0.0:
            return 0.0      # the node's sphere is behind the receiver, so is the triangle
        pmf *= (a if k == 2 * parent + 1 else b) / (a + b)
        k = parent
    return pmf
