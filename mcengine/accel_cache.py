"""The last render's BVH, kept for the next render of the same triangles.

Frames of an animation in which only the camera, the lights, the materials or
the world change, and the viewport's restarts after a view or material edit,
render the same triangles again: they reuse the Embree BVH of the previous
render instead of building it anew.  The triangles are recognised by a hash
of the vertex and index arrays and their ray visibility, with the BVH settings
(Use Spatial Splits, Use Compact BVH) beside it (``digest``: SHA-256, about
0.7 ms per MB on one core, far below the cost of a build).  One BVH is kept, the last one built; it is dropped before
a different one is built, so at most one extra BVH stays in memory.  A scene
with objects moving during the shutter is never reused nor kept: its moving
triangles have BVHs of their own (``kernels.motion``) that the hash does not see.
"""
from __future__ import annotations

import threading

import numpy as np

from .digest import digest
from .kernels.intersect import Accel

__all__ = ["accel_for", "clear"]

_lock = threading.Lock()
_last: tuple[tuple, Accel] | None = None


def _digest(vertices: np.ndarray, triangles: np.ndarray, visibility) -> bytes:
    visibility = np.zeros(0) if visibility is None else visibility
    return digest(np.asarray(array, dtype) for array, dtype in (
        (vertices, np.float32), (triangles, np.int32), (visibility, np.uint32)))


def accel_for(vertices, triangles, motion=None, visibility=None, spatial_splits=False,
              compact=False) -> tuple[Accel, bool]:
    """A BVH of these triangles (with the moving ones of ``motion``, a
    ``kernels.motion.MotionData``; each triangle's ray ``visibility``, ``Accel``'s; built
    with Cycles' Use Spatial Splits and Use Compact BVH settings) and whether it was reused
    (True) or built (False)."""
    global _last
    options = {"visibility": visibility, "spatial_splits": spatial_splits, "compact": compact}
    if motion is not None and len(motion.tri_slot):
        with _lock:
            _last = None           # free the old BVH; this one is not kept
        return Accel(vertices, triangles, motion, **options), False
    key = (_digest(vertices, triangles, visibility), bool(spatial_splits), bool(compact))
    with _lock:
        if _last is not None and _last[0] == key:
            return _last[1], True
        _last = None               # free the old BVH before building the new one
        accel = Accel(vertices, triangles, **options)
        _last = (key, accel)
        return accel, False


def clear() -> None:
    """Forget the kept BVH (its memory is freed once no session uses it)."""
    global _last
    with _lock:
        _last = None
