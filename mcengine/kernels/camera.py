"""Camera: from raster positions to world-space rays, with Blender's conventions.

The camera looks along its local -Z with +Y up.  The view plane at distance 1
(perspective) or the film rectangle (orthographic) is fitted as Cycles fits it
(intern/cycles/blender/camera.cpp):

* ``sensor_fit`` AUTO applies the sensor width to the larger image dimension
  (pixel aspect included), HORIZONTAL always to the width, VERTICAL applies the
  sensor height to the height;
* the half-extent of the fitted dimension is ``sensor / (2 lens)`` at distance 1
  (perspective) or ``ortho_scale / 2`` (orthographic);
* ``shift_x`` and ``shift_y`` are fractions of the fitted dimension;
* ``clip_start`` and ``clip_end`` are planes perpendicular to the view axis.

Raster coordinates: x to the right, y downwards, (0, 0) the top-left corner of
the full frame; pixel (i, j) covers [i, i+1) x [j, j+1).

Depth of field follows kernel/camera/camera.h: a point on the aperture (a
disk, or a polygon of blades, squeezed by the anamorphic ratio, times the
aperture radius) becomes the ray's origin in the lens plane, and the ray aims
at the point where the pinhole ray meets the plane of focus (perspective), or
converges on the pinhole ray's point at the focal distance (orthographic).
Clipping keeps Cycles' arithmetic: the near-clip offset and the far limit are
those of the pinhole ray, applied along the lens ray.

Motion blur (kernel/camera/camera.h, ``camera_sample``): with the shutter open,
each sample's time is read from the shutter table (``motion``), moved by the
rolling shutter when there is one; a moving camera's transform is
interpolated at that time from its decomposed motion steps, and a change of
focal length during the shutter scales the view-plane point linearly between
its values at shutter open, frame and close, as Cycles does.  Without motion
blur every time is 0.5.

``generate_camera_rays`` starts the paths of a chunk: a raster position per
sample from the pixel filter, its time, its camera ray, and a fresh path state.
"""
from __future__ import annotations

import math

import numpy as np

from ..jit import device, kernel
from .intersect import T_INFINITE
from .motion import SHUTTER_TABLE_SIZE, decompose_steps, lookup_table, motion_transform, shutter_table
from .sampling import (
    SET_FILTER,
    SET_LENS_TIME,
    disk_concentric,
    filter_offset,
    regular_polygon,
    sample_2d,
    sample_4d,
    sample_key,
)
from .state import (
    CFG_FULL_W,
    CFG_REGION_W,
    CFG_REGION_X,
    CFG_REGION_Y,
    CFG_SAMPLER,
    CFG_SEED,
    CFG_SOBOL_MASK,
    PF_CAMERA,
    PF_FIRST_SAMPLE,
    PF_MIS_SKIP,
    PF_TRANSPARENT_BG,
)

CAM_PERSP = 0
CAM_ORTHO = 1

# Layout of the packed camera parameter vector used by the kernels.
C_TYPE = 0
C_POS = 1            # 3: camera position
C_RIGHT = 4          # 3: unit +X axis (world)
C_UP = 7             # 3: unit +Y axis (world)
C_FWD = 10           # 3: unit -Z axis (world), the view direction
C_HALF_W = 13        # half width of the view plane at distance 1 (or film, ortho)
C_HALF_H = 14
C_SHIFT_X = 15       # view-plane centre offset, same units
C_SHIFT_Y = 16
C_CLIP_START = 17
C_CLIP_END = 18
C_WIDTH = 19         # full frame in pixels
C_HEIGHT = 20
C_APERTURE = 21      # aperture radius (0: pinhole camera, no lens sample is drawn)
C_FOCUS = 22         # focal distance along the view axis
C_BLADES = 23        # polygon corners (0: a disk)
C_BLADES_ROTATION = 24
C_INV_RATIO = 25     # 1 / anamorphic aperture ratio, applied to the lens x
C_SHUTTER = 26       # 1: motion blur, times from the shutter table; 0: every time is 0.5
C_ROLLING = 27       # 1: rolling shutter, top row first
C_ROLLING_DURATION = 28
C_MOTION_STEPS = 29  # decomposed camera transforms stored at C_MOTION_FIRST (0: a still camera)
C_VIEW_PRE = 30      # view-plane scale at shutter open and close (1: the lens does not change)
C_VIEW_POST = 31
C_MOTION_FIRST = 32  # where the camera's motion steps start in the vector
CAMERA_PARAMS = 33
C_SHUTTER_TABLE = CAMERA_PARAMS   # SHUTTER_TABLE_SIZE ray times follow the parameters with motion blur


def view_plane(cam, width: int, height: int, pixel_aspect=(1.0, 1.0)):
    """Half-extents and centre offset of the view plane, as Cycles computes them.

    Returns ``(half_w, half_h, shift_x, shift_y)`` in units of the plane at
    distance 1 (perspective) or metres (orthographic).
    """
    xratio = width * pixel_aspect[0]
    yratio = height * pixel_aspect[1]
    if cam.sensor_fit == "AUTO":
        horizontal = xratio >= yratio
        sensor = cam.sensor_width
    elif cam.sensor_fit == "HORIZONTAL":
        horizontal = True
        sensor = cam.sensor_width
    elif cam.sensor_fit == "VERTICAL":
        horizontal = False
        sensor = cam.sensor_height
    else:
        raise ValueError(f"unknown sensor fit {cam.sensor_fit!r}")
    if cam.type == "ORTHO":
        half_fit = 0.5 * cam.ortho_scale
    else:
        half_fit = 0.5 * sensor / cam.lens
    if horizontal:
        half_w, half_h = half_fit, half_fit * yratio / xratio
    else:
        half_w, half_h = half_fit * xratio / yratio, half_fit
    return half_w, half_h, 2.0 * half_fit * cam.shift_x, 2.0 * half_fit * cam.shift_y


def camera_axes(matrix) -> np.ndarray:
    """Cycles' camera-to-world of a camera's world matrix: the columns right, up, view
    direction (-Z) and position, the axes normalised (Cycles removes the object scale)."""
    m = np.asarray(matrix, np.float64)
    out = np.zeros((4, 4))
    out[:3, 0] = m[:3, 0] / np.linalg.norm(m[:3, 0])
    out[:3, 1] = m[:3, 1] / np.linalg.norm(m[:3, 1])
    out[:3, 2] = -m[:3, 2] / np.linalg.norm(m[:3, 2])
    out[:3, 3] = m[:3, 3]
    out[3, 3] = 1.0
    return out


def pack_camera(cam, film, motion_blur=None) -> np.ndarray:
    """Packed float64 parameter vector (layout ``C_*``) for the kernels.

    ``motion_blur`` is the scene's :class:`~mcengine.scene.MotionBlur` (None:
    the shutter is closed, every ray at time 0.5).
    """
    axes = camera_axes(cam.matrix_world)
    half_w, half_h, sx, sy = view_plane(cam, film.width, film.height,
                                        (film.pixel_aspect_x, film.pixel_aspect_y))
    p = np.zeros(CAMERA_PARAMS)
    p[C_TYPE] = CAM_ORTHO if cam.type == "ORTHO" else CAM_PERSP
    p[C_POS:C_POS + 3] = axes[:3, 3]
    p[C_RIGHT:C_RIGHT + 3] = axes[:3, 0]
    p[C_UP:C_UP + 3] = axes[:3, 1]
    p[C_FWD:C_FWD + 3] = axes[:3, 2]
    p[C_HALF_W], p[C_HALF_H] = half_w, half_h
    p[C_SHIFT_X], p[C_SHIFT_Y] = sx, sy
    p[C_CLIP_START], p[C_CLIP_END] = cam.clip_start, cam.clip_end
    p[C_WIDTH], p[C_HEIGHT] = film.width, film.height
    p[C_APERTURE] = cam.aperture_size
    p[C_FOCUS] = cam.focal_distance
    # Cycles samples a disk below three blades.
    p[C_BLADES] = cam.aperture_blades if cam.aperture_blades >= 3 else 0
    p[C_BLADES_ROTATION] = cam.aperture_rotation
    p[C_INV_RATIO] = 1.0 / cam.aperture_ratio
    p[C_VIEW_PRE] = p[C_VIEW_POST] = 1.0
    if motion_blur is None:
        return p
    p[C_SHUTTER] = 1.0
    p[C_ROLLING] = 1.0 if motion_blur.rolling_shutter else 0.0
    p[C_ROLLING_DURATION] = motion_blur.rolling_shutter_duration
    parts = [p, shutter_table(motion_blur.shutter_curve)]
    steps = np.asarray(cam.motion, np.float64).reshape(-1, 4, 4)
    if len(steps) > 1 and any(not np.array_equal(camera_axes(m), axes) for m in steps):
        p[C_MOTION_STEPS] = len(steps)
        p[C_MOTION_FIRST] = CAMERA_PARAMS + SHUTTER_TABLE_SIZE
        parts.append(decompose_steps([camera_axes(m) for m in steps]).ravel())
    if cam.type == "PERSP":
        p[C_VIEW_PRE], p[C_VIEW_POST] = cam.view_scale_motion
    return np.concatenate(parts)


@device
def camera_frame(cam, time):
    """Camera position, right, up and view axes at ``time`` (12 floats)."""
    if cam[C_MOTION_STEPS] == 0.0:
        return (cam[C_POS], cam[C_POS + 1], cam[C_POS + 2],
                cam[C_RIGHT], cam[C_RIGHT + 1], cam[C_RIGHT + 2],
                cam[C_UP], cam[C_UP + 1], cam[C_UP + 2],
                cam[C_FWD], cam[C_FWD + 1], cam[C_FWD + 2])
    m = motion_transform(cam, int(cam[C_MOTION_FIRST]), int(cam[C_MOTION_STEPS]), time)
    return m[3], m[7], m[11], m[0], m[4], m[8], m[1], m[5], m[9], m[2], m[6], m[10]


@device
def sample_time(cam, u, y):
    """Time in [0, 1] of a sample with random number ``u`` in pixel row ``y`` (from the top)."""
    if cam[C_SHUTTER] == 0.0:
        return 0.5
    time = lookup_table(cam, C_SHUTTER_TABLE, SHUTTER_TABLE_SIZE, u)
    if cam[C_ROLLING] != 0.0:
        # Cycles counts rows from the bottom: the top row is read out first (time 0).
        rolling = 1.0 - (cam[C_HEIGHT] - 1.0 - y) / cam[C_HEIGHT]
        duration = cam[C_ROLLING_DURATION]
        if duration != 0.0:
            time = (time - 0.5) * duration + (rolling - 0.5) * (1.0 - duration) + 0.5
        else:
            time = rolling
    return time


@device
def camera_ray(cam, rx, ry, lens_u, lens_v, time):
    """World-space ray through raster position (rx, ry) at ``time``.

    ``lens_u``, ``lens_v`` in [0, 1) pick the point on the aperture (unused by
    a pinhole camera).  Returns ``(ox, oy, oz, dx, dy, dz, tmax)`` with a unit
    direction; the origin lies on the near clip plane and ``tmax`` reaches the
    far plane.
    """
    x = cam[C_SHIFT_X] + (2.0 * rx / cam[C_WIDTH] - 1.0) * cam[C_HALF_W]
    y = cam[C_SHIFT_Y] + (1.0 - 2.0 * ry / cam[C_HEIGHT]) * cam[C_HALF_H]
    if cam[C_VIEW_PRE] != 1.0 or cam[C_VIEW_POST] != 1.0:
        # Cycles interpolates the projected point between shutter open, frame and close.
        if time < 0.5:
            k = cam[C_VIEW_PRE] + (1.0 - cam[C_VIEW_PRE]) * (time * 2.0)
        else:
            k = 1.0 + (cam[C_VIEW_POST] - 1.0) * ((time - 0.5) * 2.0)
        x *= k
        y *= k
    px, py, pz, rx_, ry_, rz_, ux, uy, uz, fx, fy, fz = camera_frame(cam, time)
    if cam[C_APERTURE] > 0.0:
        return lens_ray(cam, x, y, lens_u, lens_v, px, py, pz, rx_, ry_, rz_, ux, uy, uz, fx, fy, fz)
    if cam[C_TYPE] == CAM_ORTHO:
        ox = px + x * rx_ + y * ux + cam[C_CLIP_START] * fx
        oy = py + x * ry_ + y * uy + cam[C_CLIP_START] * fy
        oz = pz + x * rz_ + y * uz + cam[C_CLIP_START] * fz
        if cam[C_MOTION_STEPS] != 0.0:
            fx, fy, fz = normalized(fx, fy, fz)
        return ox, oy, oz, fx, fy, fz, cam[C_CLIP_END] - cam[C_CLIP_START]
    dx = x * rx_ + y * ux + fx
    dy = x * ry_ + y * uy + fy
    dz = x * rz_ + y * uz + fz
    if cam[C_MOTION_STEPS] != 0.0:
        # Cycles' clipping distances come from the camera-space direction.
        z_inv = math.sqrt(x * x + y * y + 1.0)
        dx, dy, dz = normalized(dx, dy, dz)
        t0 = cam[C_CLIP_START] * z_inv
        return (px + t0 * dx, py + t0 * dy, pz + t0 * dz,
                dx, dy, dz, (cam[C_CLIP_END] - cam[C_CLIP_START]) * z_inv)
    inv_len = 1.0 / math.sqrt(dx * dx + dy * dy + dz * dz)
    dx *= inv_len
    dy *= inv_len
    dz *= inv_len
    # The direction's component along the view axis is inv_len: the clip planes
    # are at depth clip_start and clip_end, i.e. at ray distances depth/inv_len.
    t0 = cam[C_CLIP_START] / inv_len
    return (px + t0 * dx, py + t0 * dy, pz + t0 * dz,
            dx, dy, dz, (cam[C_CLIP_END] - cam[C_CLIP_START]) / inv_len)


@device
def camera_differential(cam, rx, ry):
    """Cycles' compact ray differential of the camera ray through raster position (rx, ry):
    (footprint at the ray's origin, its growth per unit of ray length).

    Perspective (with or without depth of field, as Cycles): the mean change of the unit
    direction over one pixel step in x and in y, the footprint at the near plane that growth
    times the distance to it.  Orthographic: the width of a pixel, not growing (Cycles takes
    the x step for both axes).
    """
    sx = 2.0 * cam[C_HALF_W] / cam[C_WIDTH]
    if cam[C_TYPE] == CAM_ORTHO:
        return sx, 0.0
    sy = 2.0 * cam[C_HALF_H] / cam[C_HEIGHT]
    x = cam[C_SHIFT_X] + (2.0 * rx / cam[C_WIDTH] - 1.0) * cam[C_HALF_W]
    y = cam[C_SHIFT_Y] + (1.0 - 2.0 * ry / cam[C_HEIGHT]) * cam[C_HALF_H]
    r = math.sqrt(x * x + y * y + 1.0)
    # Raster y grows downwards: one pixel step lowers y (the sign does not change a length).
    rxx = math.sqrt((x + sx) * (x + sx) + y * y + 1.0)
    ryy = math.sqrt(x * x + (y - sy) * (y - sy) + 1.0)
    ddx = math.sqrt(((x + sx) / rxx - x / r) ** 2 + (y / rxx - y / r) ** 2 + (1.0 / rxx - 1.0 / r) ** 2)
    ddy = math.sqrt((x / ryy - x / r) ** 2 + ((y - sy) / ryy - y / r) ** 2 + (1.0 / ryy - 1.0 / r) ** 2)
    dd = 0.5 * (ddx + ddy)
    return cam[C_CLIP_START] * r * dd, dd


@device
def normalized(x, y, z):
    inv = 1.0 / math.sqrt(x * x + y * y + z * z)
    return x * inv, y * inv, z * inv


@device
def aperture_point(cam, u1, u2):
    """Point on the lens in camera coordinates (x right, y up), Cycles' camera_sample_aperture.

    A uniform point on the unit disk (concentric map) or on the regular
    polygon of the blades, x divided by the anamorphic ratio, times the
    aperture radius.
    """
    if cam[C_BLADES] == 0.0:
        bx, by = disk_concentric(u1, u2)
    else:
        bx, by = regular_polygon(cam[C_BLADES], cam[C_BLADES_ROTATION], u1, u2)
    r = cam[C_APERTURE]
    return bx * cam[C_INV_RATIO] * r, by * r


@device
def lens_ray(cam, x, y, u1, u2, px0, py0, pz0, rx, ry, rz, ux, uy, uz, fx, fy, fz):
    """The ray of a thin lens through view-plane point (x, y), as :func:`camera_ray` returns it,
    for the camera at (px0, py0, pz0) with axes right r, up u and view direction f."""
    lx, ly = aperture_point(cam, u1, u2)
    focus = cam[C_FOCUS]
    near = cam[C_CLIP_START]
    # Camera space: x right, y up, z along the view axis.
    if cam[C_TYPE] == CAM_ORTHO:
        # Aim from the lens point at (0, 0, focus); start where that ray
        # crosses the near plane, offset by the pinhole ray's position.
        cx, cy, cz = normalized(-lx, -ly, focus)
        s = near / cz
        px, py, pz = x + lx + cx * s, y + ly + cy * s, cz * s
        tmax = cam[C_CLIP_END] - near
    else:
        # Aim from the lens point at the pinhole ray's point on the plane of focus.
        cx, cy, cz = normalized(x * focus - lx, y * focus - ly, focus)
        # Cycles clips along the lens ray with the pinhole ray's 1/cos.
        z_inv = math.sqrt(x * x + y * y + 1.0)
        t0 = near * z_inv
        px, py, pz = lx + t0 * cx, ly + t0 * cy, t0 * cz
        tmax = (cam[C_CLIP_END] - near) * z_inv
    ox = px0 + px * rx + py * ux + pz * fx
    oy = py0 + px * ry + py * uy + pz * fy
    oz = pz0 + px * rz + py * uz + pz * fz
    dx, dy, dz = normalized(cx * rx + cy * ux + cz * fx, cx * ry + cy * uy + cz * fy,
                            cx * rz + cy * uz + cz * fz)
    return ox, oy, oz, dx, dy, dz, tmax


@kernel
def generate_camera_rays(pixels, spp, sample_base, st, sc, cfg):
    """Start ``spp`` paths for each film pixel in ``pixels``; returns the path count.

    The sample index of a path is the pixel's count of finished samples
    (``sample_base``) plus its rank here, so every sample of a pixel has its
    own random numbers whatever the pass schedule (and a pixel's Sobol points go on
    from where its earlier passes stopped).
    """
    n = 0
    region_x, region_y, region_w = cfg[CFG_REGION_X], cfg[CFG_REGION_Y], cfg[CFG_REGION_W]
    cam = sc.camera
    lens = cam[C_APERTURE] > 0.0
    shutter = cam[C_SHUTTER] != 0.0
    sampler, mask = cfg[CFG_SAMPLER], np.uint64(cfg[CFG_SOBOL_MASK])
    for pi in range(pixels.shape[0]):
        pix = pixels[pi]
        x = region_x + pix % region_w
        y = region_y + pix // region_w
        global_pixel = y * cfg[CFG_FULL_W] + x
        for j in range(spp):
            sample = sample_base[pix] + j
            key = sample_key(sampler, cfg[CFG_SEED], global_pixel, sample)
            # Cycles takes the first sample of every pixel at the pixel centre.
            if sample == 0:
                fx, fy = 0.5, 0.5
            else:
                ux, uy = sample_2d(sampler, key, SET_FILTER, mask)
                fx = filter_offset(sc.filter_table, ux)
                fy = filter_offset(sc.filter_table, uy)
            lu = lv = 0.0
            time = 0.5
            if shutter:
                # Lens and time are one set, stratified together (Cycles' PRNG_LENS_TIME).
                a, b, u_time, _ = sample_4d(sampler, key, SET_LENS_TIME, mask)
                time = sample_time(cam, u_time, y)
                if lens:
                    lu, lv = a, b
            elif lens:
                lu, lv = sample_2d(sampler, key, SET_LENS_TIME, mask)
            ox, oy, oz, dx, dy, dz, tmax = camera_ray(cam, x + fx, y + fy, lu, lv, time)
            st.time[n] = time
            st.key[n] = key
            st.pixel[n] = pix
            st.ray_o[n, 0], st.ray_o[n, 1], st.ray_o[n, 2] = ox, oy, oz
            st.ray_d[n, 0], st.ray_d[n, 1], st.ray_d[n, 2] = dx, dy, dz
            st.ray_tmax[n] = tmax
            st.beta[n, 0], st.beta[n, 1], st.beta[n, 2] = 1.0, 1.0, 1.0
            st.radiance[n, 0], st.radiance[n, 1], st.radiance[n, 2] = 0.0, 0.0, 0.0
            st.transparency[n] = 0.0
            st.bounce[n] = 0
            st.diffuse[n] = 0
            st.glossy[n] = 0
            st.transmission[n] = 0
            st.transparent[n] = 0
            st.flags[n] = PF_CAMERA | PF_MIS_SKIP | PF_TRANSPARENT_BG | (PF_FIRST_SAMPLE if sample == 0 else 0)
            st.mis_pdf[n] = 0.0
            st.mis_p[n, 0], st.mis_p[n, 1], st.mis_p[n, 2] = ox, oy, oz   # ray length from here
            st.mis_p[n, 3] = st.mis_p[n, 4] = st.mis_p[n, 5] = 0.0
            st.min_pdf[n] = math.inf
            st.self_prim[n] = -1
            st.mis_set[n] = 0
            st.dp[n], st.dd[n] = camera_differential(sc.camera, x + fx, y + fy)
            st.o32[n, 0], st.o32[n, 1], st.o32[n, 2] = ox, oy, oz
            st.d32[n, 0], st.d32[n, 1], st.d32[n, 2] = dx, dy, dz
            st.t32[n] = min(tmax, T_INFINITE)
            n += 1
    return n


def camera_rays(scene_camera, film, rx, ry, lens_u=None, lens_v=None, time=None, motion_blur=None):
    """Vectorised helper (tests, tools): rays for arrays of raster positions (lens samples, times)."""
    p = pack_camera(scene_camera, film, motion_blur)
    rx, ry = np.ravel(rx), np.ravel(ry)
    lu = np.zeros(rx.size) if lens_u is None else np.ravel(lens_u)
    lv = np.zeros(rx.size) if lens_v is None else np.ravel(lens_v)
    t = np.full(rx.size, 0.5) if time is None else np.broadcast_to(np.ravel(time), rx.shape)
    out = np.array([camera_ray(p, float(a), float(b), float(u), float(v), float(w))
                    for a, b, u, v, w in zip(rx, ry, lu, lv, t)])
    return out[:, :3], out[:, 3:6], out[:, 6]
