"""Ray-scene intersection: Embree's BVH (``kernels.embree``, the only module that calls
Embree) merged with the moving objects, and the float64 geometry around the hits.

Two Python worker threads trace their batches at once: the tracing kernels release the GIL.
How the renderer lives with Embree's float32 rays:

* rays are float32, start at ``tnear`` 0 and have no filter callbacks, so a ray
  leaving a surface must start slightly off it.
  :func:`offset_origin` moves the origin along the geometric normal by a
  distance proportional to the point's magnitude (float32 rounding of the
  origin and Embree's own arithmetic are relative errors, so a fixed epsilon
  fails for scenes far from the origin or at millimetre scale);
* the closest-hit query returns only the primitive id; the integrator
  recomputes the hit distance and barycentrics in float64 from the triangle
  (:func:`intersect_triangle`), which is more accurate than Embree's float32
  values;
* a ray that re-hits the triangle it starts on (possible only through
  rounding, as triangles are flat) is detected by primitive id and traced
  again from just past that hit (``Accel.closest`` callers do this).

Objects hidden from some rays (Object > Visibility > Ray Visibility) are passed through by
those rays: each triangle has a visibility mask (``state.VIS_*`` bits) and each query the
mask of its rays (:func:`ray_visibility` of the path's flags, ``VIS_SHADOW`` for shadow
rays), as Cycles' BVH skips the objects whose visibility shares no bit with the ray's.

The Embree scene has no motion blur (no time on rays, no motion BVH).  Objects that
move while the shutter is open (``kernels.motion``) are left out of the
Embree scene and intersected exactly at each ray's time by the motion
module's own BVHs; ``Accel`` merges the two, so the callers see one scene.
"""
from __future__ import annotations

import math

import numpy as np

from ..jit import device, kernel
from . import embree
from .motion import corner_normals, moving_closest, moving_normals, moving_occluded, moving_triangle
from .scalar import saturate
from .state import (
    PF_CAMERA,
    PF_DIFFUSE,
    PF_GLOSSY,
    PF_SUBSURFACE,
    PF_TRANSMIT,
    VIS_ALL,
    VIS_CAMERA,
    VIS_DIFFUSE,
    VIS_GLOSSY,
    VIS_TRANSMISSION,
)

# Relative origin offset: 2^-18 of the largest coordinate magnitude is about
# 32 float32 ulps, above the rounding of the origin to float32 (half an ulp
# per coordinate) and of Embree's watertight test (a few ulps), and far below
# any feature a float32 scene can represent at that magnitude.
OFFSET_RELATIVE = 2.0 ** -18
# Absolute floor, for points at the origin itself: float32 normals are
# accurate to about 1e-7, so 1e-9 m is well resolved and never visible.
OFFSET_ABSOLUTE = 1e-9
# Shadow rays stop short of their target by this fraction of their length
# (plus the target's own offset), so they never hit the emitter they aim at.
SHADOW_SHORTEN = 2.0 ** -16
T_INFINITE = 1e30   # "no hit" distance; Embree's float32 tfar for unbounded rays


class Accel:
    """Embree BVH over the scene triangles, plus the moving ones.

    Parameters
    ----------
    vertices : (V, 3) float32
    triangles : (T, 3) int32
    motion : kernels.motion.MotionData, optional
        The moving objects; their triangles are intersected at each ray's time.
    packets : bool
        Trace in Embree's packets (``kernels.embree``); False: embreex's single rays.
    visibility : (T,) integer, optional
        Each triangle's ray visibility (``VIS_*`` bits; absent: visible to every ray).
    spatial_splits, compact : bool
        Cycles' Use Spatial Splits and Use Compact BVH (``embree.build``).

    ``masked`` is True when some triangle is hidden from some rays: the callers then pass
    their rays' masks to the queries (``mask``: one for every ray, or one per ray).
    """

    def __init__(self, vertices, triangles, motion=None, packets=True, visibility=None,
                 spatial_splits=False, compact=False):
        self.num_triangles = int(len(triangles))
        self._scene = None
        self._motion = motion if motion is not None and len(motion.tri_slot) else None
        self._static_ids = None
        if visibility is not None and np.all(np.asarray(visibility) & VIS_ALL == VIS_ALL):
            visibility = None
        self._slot_masks = embree.NO_MASKS
        if visibility is not None:
            visibility = np.asarray(visibility, np.uint32) & VIS_ALL
        if self._motion is not None:
            self._static_ids = np.flatnonzero(self._motion.tri_slot < 0).astype(np.int32)
            self._verts = np.asarray(vertices, np.float64)
            self._tris = np.ascontiguousarray(triangles, np.int32)
            triangles = np.asarray(triangles)[self._static_ids]
            if visibility is not None:     # a moving object's triangles share its visibility
                slots = self._motion.tri_slot
                self._slot_masks = np.full(self._motion.slot_info.shape[0], VIS_ALL, np.uint32)
                self._slot_masks[slots[slots >= 0]] = visibility[slots >= 0]
                visibility = visibility[self._static_ids]
        if len(triangles):
            self._scene = embree.build(vertices, triangles, packets, visibility, spatial_splits,
                                       compact)
        self.masked = visibility is not None and (self._scene is None or self._scene.masked)

    def closest(self, origins, directions, tfar, time=None, mask=None):
        """Primitive id of the closest hit within (0, tfar), or -1.

        origins, directions : (n, 3) float32; tfar : (n,) float32; time : (n,)
        float64 in [0, 1] over the shutter (only moving objects look at it); mask: the rays'
        visibility (``VIS_*`` bits: one int for all, or (n,) per ray; absent: every bit).
        """
        n = origins.shape[0]
        mask = mask if self.masked else None
        if self._scene is None or n == 0:
            prim = np.full(n, -1, np.int32)
        else:
            prim = self._scene.closest(origins, directions, tfar, mask)
        if self._motion is None or n == 0:
            return prim
        if self._scene is not None:
            prim = np.where(prim >= 0, self._static_ids[np.maximum(prim, 0)], -1).astype(np.int32)
        best = np.empty(n)
        hit_distances(self._verts, self._tris, origins, directions, tfar, prim, best)
        moving_closest(self._motion, self._verts, self._tris, origins, directions,
                       _times(time, n), best, prim, self._slot_masks, embree.mask_array(mask))
        return prim

    def occluded(self, origins, directions, tfar, time=None, mask=None):
        """True where something the rays see (``mask``, as for ``closest``) blocks the
        segment (0, tfar) (at the ray's time)."""
        n = origins.shape[0]
        mask = mask if self.masked else None
        if self._scene is None or n == 0:
            blocked = np.zeros(n, np.bool_)
        else:
            blocked = self._scene.occluded(origins, directions, tfar, mask)
        if self._motion is not None and n:
            moving_occluded(self._motion, self._verts, self._tris, origins, directions, tfar,
                            _times(time, n), blocked, self._slot_masks, embree.mask_array(mask))
        return blocked


@device
def ray_visibility(flags):
    """The visibility mask of a ray of a path with these PF_* flags (Cycles'
    path_state_ray_visibility): camera rays, until the path scatters (transparent surfaces
    passed keep it one); transmission rays see the objects visible to transmission only;
    reflected rays those visible to their lobe (diffuse or glossy, singular included).  The
    ray that brings a subsurface walk to its exit triangle (Cycles finds the exit with a
    local query, which has no visibility) sees everything."""
    if flags & PF_SUBSURFACE:
        return VIS_ALL
    if flags & PF_CAMERA:
        return VIS_CAMERA
    if flags & PF_TRANSMIT:
        return VIS_TRANSMISSION
    vis = 0
    if flags & PF_DIFFUSE:
        vis |= VIS_DIFFUSE
    if flags & PF_GLOSSY:
        vis |= VIS_GLOSSY
    return vis


@kernel
def ray_masks(flags, out):
    """out[i] = ray_visibility(flags[i]) (uint32)."""
    for i in range(out.shape[0]):
        out[i] = ray_visibility(flags[i])


def _times(time, n):
    return np.full(n, 0.5) if time is None else np.ascontiguousarray(time, np.float64)


@kernel
def hit_distances(verts, tris, o32, d32, t32, prim, best):
    """Distance of each ray's hit on triangle ``prim`` (``t32`` where there is none)."""
    for i in range(prim.shape[0]):
        best[i] = t32[i]
        if prim[i] >= 0:
            t, _, _ = intersect_prim(float(o32[i, 0]), float(o32[i, 1]), float(o32[i, 2]),
                                     float(d32[i, 0]), float(d32[i, 1]), float(d32[i, 2]),
                                     verts, tris, prim[i])
            best[i] = t if math.isfinite(t) and t > 0.0 else 0.0


@device
def offset_scale(px, py, pz):
    """Offset distance for a ray leaving point p (see OFFSET_RELATIVE)."""
    m = max(abs(px), abs(py), abs(pz))
    return OFFSET_RELATIVE * m + OFFSET_ABSOLUTE


@device
def offset_origin(px, py, pz, ngx, ngy, ngz, dx, dy, dz):
    """Move p off its surface to the side of the geometric normal ng that d leaves to."""
    s = offset_scale(px, py, pz)
    if ngx * dx + ngy * dy + ngz * dz < 0.0:
        s = -s
    return px + s * ngx, py + s * ngy, pz + s * ngz


@device
def intersect_triangle(ox, oy, oz, dx, dy, dz, v0x, v0y, v0z, v1x, v1y, v1z, v2x, v2y, v2z):
    """Plane hit of a ray with a triangle, in float64.

    Returns ``(t, b1, b2)`` with barycentrics clamped into the triangle (the
    caller already knows from Embree that the ray hits it; clamping absorbs
    the difference between Embree's float32 test and this one at edges).
    ``t`` is NaN if the ray is parallel to the plane.
    """
    e1x, e1y, e1z = v1x - v0x, v1y - v0y, v1z - v0z
    e2x, e2y, e2z = v2x - v0x, v2y - v0y, v2z - v0z
    nx = e1y * e2z - e1z * e2y
    ny = e1z * e2x - e1x * e2z
    nz = e1x * e2y - e1y * e2x
    denom = nx * dx + ny * dy + nz * dz
    if denom == 0.0:
        return math.nan, 0.0, 0.0
    t = (nx * (v0x - ox) + ny * (v0y - oy) + nz * (v0z - oz)) / denom
    # Barycentrics of the plane hit by projecting onto the edges (Gram matrix).
    px, py, pz = ox + t * dx - v0x, oy + t * dy - v0y, oz + t * dz - v0z
    d00 = e1x * e1x + e1y * e1y + e1z * e1z
    d01 = e1x * e2x + e1y * e2y + e1z * e2z
    d11 = e2x * e2x + e2y * e2y + e2z * e2z
    d20 = px * e1x + py * e1y + pz * e1z
    d21 = px * e2x + py * e2y + pz * e2z
    g = d00 * d11 - d01 * d01
    if g <= 0.0:
        return t, 1.0 / 3.0, 1.0 / 3.0
    b1 = (d11 * d20 - d01 * d21) / g
    b2 = (d00 * d21 - d01 * d20) / g
    b1 = saturate(b1)
    b2 = saturate(b2)
    s = b1 + b2
    if s > 1.0:
        b1 /= s
        b2 /= s
    return t, b1, b2


@device
def intersect_prim(ox, oy, oz, dx, dy, dz, verts, tris, p):
    """:func:`intersect_triangle` for triangle ``p`` of the scene tables."""
    a, b, c = tris[p, 0], tris[p, 1], tris[p, 2]
    return intersect_triangle(ox, oy, oz, dx, dy, dz,
                              verts[a, 0], verts[a, 1], verts[a, 2],
                              verts[b, 0], verts[b, 1], verts[b, 2],
                              verts[c, 0], verts[c, 1], verts[c, 2])


@device
def is_moving(sc, p):
    """Whether triangle p belongs to an object that moves during the shutter."""
    return sc.motion.tri_slot.shape[0] != 0 and sc.motion.tri_slot[p] >= 0


@device
def prim_corners(sc, p, time):
    """The corners of triangle p at ``time`` (9 floats, world space)."""
    if is_moving(sc, p):
        return moving_triangle(sc.motion, sc.verts, sc.tris, p, time)
    a, b, c = sc.tris[p, 0], sc.tris[p, 1], sc.tris[p, 2]
    v = sc.verts
    return v[a, 0], v[a, 1], v[a, 2], v[b, 0], v[b, 1], v[b, 2], v[c, 0], v[c, 1], v[c, 2]


@device
def prim_normals(sc, p, time):
    """The corner shading normals of triangle p at ``time`` (9 floats, world space)."""
    if is_moving(sc, p):
        return moving_normals(sc.motion, sc.verts, sc.tris, sc.tex.normals, sc.tex.normal_index,
                              p, time)
    return corner_normals(sc.tex.normals, sc.tex.normal_index, p)


@device
def triangle_frame(verts, tris, p):
    """Unit geometric normal (from the winding) and area of triangle p of ``verts`` and
    ``tris``, as ``packing.areas_and_normals`` computes them, to the bit (a zero-length
    normal comes back as it is).  Computed where it is needed rather than stored: a table
    would cost 32 bytes per triangle, and fresh memory costs start-up time."""
    a, b, c = tris[p, 0], tris[p, 1], tris[p, 2]
    ax, ay, az = verts[a, 0], verts[a, 1], verts[a, 2]
    e1x, e1y, e1z = verts[b, 0] - ax, verts[b, 1] - ay, verts[b, 2] - az
    e2x, e2y, e2z = verts[c, 0] - ax, verts[c, 1] - ay, verts[c, 2] - az
    nx, ny, nz = e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x
    length = math.sqrt(nx * nx + ny * ny + nz * nz)
    d = length if length > 0.0 else 1.0
    return nx / d, ny / d, nz / d, 0.5 * length


@device
def prim_frame(sc, p, time):
    """Unit geometric normal (from the winding) and area of triangle p at ``time``."""
    if not is_moving(sc, p):
        return triangle_frame(sc.verts, sc.tris, p)
    ax, ay, az, bx, by, bz, cx, cy, cz = moving_triangle(sc.motion, sc.verts, sc.tris, p, time)
    e1x, e1y, e1z = bx - ax, by - ay, bz - az
    e2x, e2y, e2z = cx - ax, cy - ay, cz - az
    nx, ny, nz = e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x
    length = math.sqrt(nx * nx + ny * ny + nz * nz)
    if length <= 0.0:
        return 0.0, 0.0, 1.0, 0.0
    return nx / length, ny / length, nz / length, 0.5 * length
