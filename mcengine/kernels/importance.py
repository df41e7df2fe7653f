"""The camera seen from the scene: where a point lands on the film, and how much it counts.

Path tracing asks the camera for rays (``camera``); light tracing goes the
other way: a point lit by a light path is joined to the camera, and its light
is added ("splatted") to the pixels whose filter covers the raster position it
projects to.  This module holds that side of the camera:

* ``camera_sees``: the raster position of a world point, the direction and
  distance to the camera (the shadow ray ends where camera rays start, on the
  near clip plane), and the camera's importance W there.  A pixel j measures
  I_j = integral of h_j(raster) L over the film (h_j: the pixel filter about
  its centre, of integral 1 in pixel units), so per unit solid angle of the
  ray W = h / (s_x s_y cos^3 theta) for a perspective camera (s_x, s_y: a
  pixel's extent on the view plane at distance 1, theta: the angle to the view
  axis), and per unit film area W = h / (s_x s_y) for an orthographic one;
* ``filter_density``: h itself, the density of the pixel-filter offsets that
  path tracing draws from Cycles' table (``sampling.filter_table``: a piecewise
  linear inverse CDF, quirks included), so that splatted and camera samples
  estimate the same filtered pixel;
* ``splat``: add a contribution to every pixel of the film region whose filter
  reaches the raster position.

A pinhole only: a thin lens (depth of field) would need a point on the lens
per join, which light tracing does not draw (``light_tracing`` is off then).
"""
from __future__ import annotations

import math
from collections import namedtuple

from ..jit import device
from .camera import (
    C_CLIP_END,
    C_CLIP_START,
    C_FWD,
    C_HALF_H,
    C_HALF_W,
    C_HEIGHT,
    C_POS,
    C_RIGHT,
    C_SHIFT_X,
    C_SHIFT_Y,
    C_TYPE,
    C_UP,
    C_WIDTH,
    CAM_ORTHO,
)

CameraView = namedtuple("CameraView", [
    "ok",                  # the point is in front of the camera, between the clip planes
    "rx", "ry",            # raster position, full frame, pixels (x right, y down)
    "wx", "wy", "wz",      # unit direction from the point to the camera
    "dist",                # distance along w to where camera rays start (the near plane)
    "importance",          # W without the filter: 1 / (s_x s_y cos^3) (per steradian), or
                           # 1 / (s_x s_y) (orthographic, per unit film area)
    "geometry",            # 1 / d^2 from the camera's position (perspective), 1 (orthographic)
    "cos3",                # cos^3 of the angle to the view axis (1: orthographic)
])


@device
def camera_sees(cam, px, py, pz):
    """Where the world point p lands on the film, and the camera's side of joining it."""
    vx, vy, vz = px - cam[C_POS], py - cam[C_POS + 1], pz - cam[C_POS + 2]
    depth = vx * cam[C_FWD] + vy * cam[C_FWD + 1] + vz * cam[C_FWD + 2]
    if not (depth > cam[C_CLIP_START] and depth < cam[C_CLIP_END]):
        return CameraView(False, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0)
    x = vx * cam[C_RIGHT] + vy * cam[C_RIGHT + 1] + vz * cam[C_RIGHT + 2]
    y = vx * cam[C_UP] + vy * cam[C_UP + 1] + vz * cam[C_UP + 2]
    pixel_w = 2.0 * cam[C_HALF_W] / cam[C_WIDTH]
    pixel_h = 2.0 * cam[C_HALF_H] / cam[C_HEIGHT]
    if cam[C_TYPE] == CAM_ORTHO:
        rx = ((x - cam[C_SHIFT_X]) / cam[C_HALF_W] + 1.0) * 0.5 * cam[C_WIDTH]
        ry = (1.0 - (y - cam[C_SHIFT_Y]) / cam[C_HALF_H]) * 0.5 * cam[C_HEIGHT]
        return CameraView(True, rx, ry, -cam[C_FWD], -cam[C_FWD + 1], -cam[C_FWD + 2],
                          depth - cam[C_CLIP_START], 1.0 / (pixel_w * pixel_h), 1.0, 1.0)
    x /= depth
    y /= depth
    rx = ((x - cam[C_SHIFT_X]) / cam[C_HALF_W] + 1.0) * 0.5 * cam[C_WIDTH]
    ry = (1.0 - (y - cam[C_SHIFT_Y]) / cam[C_HALF_H]) * 0.5 * cam[C_HEIGHT]
    d2 = vx * vx + vy * vy + vz * vz
    d = math.sqrt(d2)
    cos = depth / d
    cos3 = cos * cos * cos
    # Camera rays start on the near plane: the segment to the camera ends there.
    return CameraView(True, rx, ry, -vx / d, -vy / d, -vz / d, d * (1.0 - cam[C_CLIP_START] / depth),
                      1.0 / (pixel_w * pixel_h * cos3), 1.0 / d2, cos3)


@device
def filter_density(table, o):
    """Density of the pixel-filter offset o (pixels from the pixel's corner) that
    ``sampling.filter_offset`` draws: its table's n - 1 intervals each carry 1 / (n - 1)
    of the samples; all but the last are increasing, the last runs from the top back to 0
    (a quirk of Cycles' table, kept)."""
    n = table.shape[0]
    mass = 1.0 / (n - 1)
    h = 0.0
    top = table[n - 2]
    if table[0] <= o < top:
        lo, hi = 0, n - 2
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if table[mid] <= o:
                lo = mid
            else:
                hi = mid
        width = table[lo + 1] - table[lo]
        if width > 0.0:
            h += mass / width
    end = table[n - 1]
    a, b = min(top, end), max(top, end)
    if a <= o < b:
        h += mass / (b - a)
    return h


@device
def filter_reach(table):
    """(lowest, highest) offset the filter gives a sample."""
    n = table.shape[0]
    return min(table[0], table[n - 1]), max(table[n - 2], table[n - 1])


@device
def splat(film, table, x0, y0, w, h, rx, ry, cr, cg, cb):
    """Add (cr, cg, cb) times the filter weight to the pixels of the region (origin x0, y0,
    size w x h, rows of ``film``: (w h, 3)) whose filter reaches the raster point."""
    lo, hi = filter_reach(table)
    ix0 = max(int(math.ceil(rx - hi)), x0)
    ix1 = min(int(math.floor(rx - lo)), x0 + w - 1)
    iy0 = max(int(math.ceil(ry - hi)), y0)
    iy1 = min(int(math.floor(ry - lo)), y0 + h - 1)
    for iy in range(iy0, iy1 + 1):
        hy = filter_density(table, ry - iy)
        if hy == 0.0:
            continue
        for ix in range(ix0, ix1 + 1):
            k = hy * filter_density(table, rx - ix)
            if k != 0.0:
                row = (iy - y0) * w + (ix - x0)
                film[row, 0] += cr * k
                film[row, 1] += cg * k
                film[row, 2] += cb * k


@device
def in_film(table, x0, y0, w, h, rx, ry):
    """Whether some pixel of the region can take a sample at this raster point."""
    lo, hi = filter_reach(table)
    return x0 + lo <= rx < x0 + w - 1 + hi and y0 + lo <= ry < y0 + h - 1 + hi
