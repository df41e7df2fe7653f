"""Wireframe (kernel/svm/wireframe.h): 1 where the point lies within half the Size of an edge
of its triangle, else 0.

Size is in world units, or with Pixel Size in pixels: times the mean length of the ray
differential's dPdx and dPdy projected onto the plane facing the viewer (``bump``'s
compact differentials; 0 without one, as on light samples).  The edges are the render's
triangles (a quad shows its diagonal, as in Cycles).  A Bump node's offset copies see their
moved point (``bump_point``), as Cycles moves P by dPdx or dPdy times the filter width.
"""
from __future__ import annotations

import math

from ...jit import device
from .bump import differentials
from .nodes import OFFSETS

_WF_PIXEL_SIZE = OFFSETS["Wireframe"]["prop:use_pixel_size"]


@device
def _projected_length(x, y, z, wx, wy, wz):
    d = x * wx + y * wy + z * wz
    x, y, z = x - d * wx, y - d * wy, z - d * wz
    return math.sqrt(x * x + y * y + z * z)


@device
def wireframe_node(regs, b, c, sd, verts, tris):
    """Inputs at regs[b:] (Size, use_pixel_size), Fac to regs[c]."""
    regs[c] = 0.0
    p = sd.prim
    if p < 0:
        return
    width = 1.0
    if regs[b + _WF_PIXEL_SIZE] != 0.0:
        xx, xy, xz, yx, yy, yz = differentials(sd)
        width = 0.5 * (_projected_length(xx, xy, xz, sd.wox, sd.woy, sd.woz)
                       + _projected_length(yx, yy, yz, sd.wox, sd.woy, sd.woz))
    # half the width: the neighbouring triangle draws the other half; squared to compare
    width *= 0.5 * regs[b]
    width *= width
    t = tris[p]
    for k in range(3):
        a = verts[t[k]]
        o = verts[t[k - 1 if k > 0 else 2]]
        ex, ey, ez = a[0] - o[0], a[1] - o[1], a[2] - o[2]
        dx, dy, dz = sd.px - a[0], sd.py - a[1], sd.pz - a[2]
        cx, cy, cz = ey * dz - ez * dy, ez * dx - ex * dz, ex * dy - ey * dx
        # |e x d|^2 / |e|^2: the squared distance to the edge's line
        if cx * cx + cy * cy + cz * cz < (ex * ex + ey * ey + ez * ez) * width:
            regs[c] = 1.0
            return
