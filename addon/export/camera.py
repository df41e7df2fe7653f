"""The scene camera -> :class:`mcengine.scene.Camera`, render settings -> :class:`~mcengine.scene.Film`.

Camera: perspective and orthographic cameras (panoramic ones raise
:class:`ExportError`).  The world matrix is the evaluated camera's with the
object scale removed (Cycles ignores camera scale), translation in metres;
clip distances and the orthographic scale are converted to metres too.

Depth of field as Cycles' Blender sync computes it (blender/camera.cpp): the
aperture radius is ``lens x 1e-3 / (2 f-stop)`` (``1 / (2 f-stop)`` for an
orthographic camera) in scene units, the f-stop at least 1e-5; the focal
distance is ``dof.focus_distance``, or with a focus object (and bone) the
depth of that object's origin along the camera's view axis.  Both become
metres with the unit scale.  With ``dof.use_dof`` off the camera is a pinhole.

Film: the frame is ``resolution x percentage / 100`` pixels (integer division,
as Blender does).  With ``render.use_border`` the rendered region is Blender's
border rectangle, computed exactly as Blender rounds it (float32 fraction x
size, truncated), then flipped from Blender's bottom-left origin to the
core's top-left one.  Blender always expects a RenderResult of the border's
size, whether ``use_crop_to_border`` is on or off (it pastes the region into a
full frame itself when cropping is off).
"""
from __future__ import annotations

import numpy as np

from mcengine.scene import Camera, Film

from . import ExportError
from .settings import cycles_settings

__all__ = ["export_camera", "camera_from_view", "export_film", "frame_size", "border_region",
           "focal_distance", "without_scale"]

MIN_FSTOP = 1e-5     # Cycles clamps the f-stop to this before dividing by it


def export_camera(ctx, depsgraph) -> Camera:
    """The active scene camera, evaluated."""
    scene = depsgraph.scene
    if scene.camera is None:
        raise ExportError("the scene has no active camera")
    ob = scene.camera.evaluated_get(depsgraph)
    cam = ob.data
    if cam.type not in ("PERSP", "ORTHO"):
        kind = "panoramic" if cam.type == "PANO" else f"of type {cam.type}"
        raise ExportError(f"camera '{ob.name}' is {kind}; MC Engine renders perspective and "
                          f"orthographic cameras only")
    s = ctx.unit_scale
    camera = Camera(
        matrix_world=without_scale(np.array(ob.matrix_world, np.float64), s),
        type=cam.type,
        lens=float(cam.lens),
        sensor_width=float(cam.sensor_width),
        sensor_height=float(cam.sensor_height),
        sensor_fit=cam.sensor_fit,
        shift_x=float(cam.shift_x),
        shift_y=float(cam.shift_y),
        ortho_scale=float(cam.ortho_scale) * s,
        clip_start=float(cam.clip_start) * s,
        clip_end=float(cam.clip_end) * s,
    )
    dof = cam.dof
    if dof.use_dof:
        fstop = max(float(dof.aperture_fstop), MIN_FSTOP)
        unit_aperture = 1.0 if cam.type == "ORTHO" else float(cam.lens) * 1e-3
        camera.aperture_size = unit_aperture / (2.0 * fstop) * s
        camera.focal_distance = focal_distance(ob, dof, depsgraph) * s
        camera.aperture_blades = int(dof.aperture_blades)
        camera.aperture_rotation = float(dof.aperture_rotation)
        camera.aperture_ratio = float(dof.aperture_ratio)
    return camera


def focal_distance(ob, dof, depsgraph) -> float:
    """Distance of the plane in focus, in scene units, as Cycles computes it.

    Without a focus object it is ``dof.focus_distance``; with one, the absolute
    depth of the object's origin (or of its ``focus_subtarget`` bone's head)
    along the camera's view axis.
    """
    target = dof.focus_object
    if target is None:
        return float(dof.focus_distance)
    target = target.evaluated_get(depsgraph)
    m = np.array(target.matrix_world, np.float64)
    if dof.focus_subtarget and target.pose is not None:
        bone = target.pose.bones.get(dof.focus_subtarget)
        if bone is not None:
            m = m @ np.array(bone.matrix, np.float64)
    cam = np.array(ob.matrix_world, np.float64)
    view_axis = cam[:3, 2] / np.linalg.norm(cam[:3, 2])
    return abs(float(np.dot(view_axis, cam[:3, 3] - m[:3, 3])))


def camera_from_view(view_matrix, window_matrix, unit_scale: float = 1.0) -> Camera:
    """The camera whose rays are those of a view and a projection matrix (the 3D viewport).

    ``view_matrix`` maps world to view space (looking down -Z), ``window_matrix``
    is the OpenGL projection of ``RegionView3D`` for the whole region (in the
    camera view it includes the camera's zoom and offset).  The frustum at
    unit distance, ``[l, r] x [b, t]``, gives a horizontally fitted camera:
    half width ``1 / P[0][0]`` (perspective: sensor / (2 lens); orthographic:
    half the orthographic scale) and shift ``(r + l) / (2 (r - l))`` of the
    width, likewise for y; the clip distances come from the depth rows.
    """
    view = np.asarray(view_matrix, np.float64)
    p = np.asarray(window_matrix, np.float64)
    half_w, half_h = 1.0 / p[0, 0], 1.0 / p[1, 1]
    ortho = p[3, 3] == 1.0
    if ortho:
        centre_x, centre_y = -p[0, 3] * half_w, -p[1, 3] * half_h
        near, far = (p[2, 3] + 1.0) / p[2, 2], (p[2, 3] - 1.0) / p[2, 2]
    else:
        centre_x, centre_y = p[0, 2] * half_w, p[1, 2] * half_h
        near, far = p[2, 3] / (p[2, 2] - 1.0), p[2, 3] / (p[2, 2] + 1.0)
    sensor = 36.0
    return Camera(
        matrix_world=without_scale(np.linalg.inv(view), unit_scale),
        type="ORTHO" if ortho else "PERSP",
        lens=sensor / (2.0 * half_w), sensor_width=sensor, sensor_height=sensor * half_h / half_w,
        sensor_fit="HORIZONTAL",
        shift_x=centre_x / (2.0 * half_w), shift_y=centre_y / (2.0 * half_w),
        ortho_scale=2.0 * half_w * unit_scale,
        clip_start=float(near) * unit_scale, clip_end=float(far) * unit_scale,
    )


def export_film(ctx, scene) -> Film:
    """Resolution, border region, pixel filter, transparency and exposure."""
    render = scene.render
    width, height = frame_size(render)
    film = Film(width=width, height=height,
                pixel_aspect_x=float(render.pixel_aspect_x),
                pixel_aspect_y=float(render.pixel_aspect_y),
                region=border_region(render) if render.use_border else None,
                transparent=bool(render.film_transparent))
    cycles = cycles_settings(ctx, scene)
    if cycles is not None:
        film.filter_type = cycles.pixel_filter_type
        film.filter_width = float(cycles.filter_width)
        film.exposure = float(cycles.film_exposure)
    return film


def frame_size(render) -> tuple:
    """Full frame size in pixels: resolution x percentage / 100, rounded down like Blender."""
    pct = render.resolution_percentage
    return render.resolution_x * pct // 100, render.resolution_y * pct // 100


def border_region(render) -> tuple:
    """Blender's border as the core's region ``(x0, y0, x1, y1)``, top-left origin, exclusive.

    Blender computes the border in pixels as ``(int)(float_fraction * size)``
    (``re_init_resolution`` / ``RE_ReadRenderResult``), with y measured from
    the bottom of the frame.
    """
    width, height = frame_size(render)

    def px(fraction, size):
        return int(np.float32(fraction) * np.float32(size))

    x0, x1 = px(render.border_min_x, width), px(render.border_max_x, width)
    y0_up, y1_up = px(render.border_min_y, height), px(render.border_max_y, height)
    return x0, height - y1_up, x1, height - y0_up


def without_scale(m: np.ndarray, unit_scale: float) -> np.ndarray:
    """Normalise the rotation columns (drop object scale) and convert the translation to metres."""
    out = m.copy()
    lengths = np.linalg.norm(m[:3, :3], axis=0)
    out[:3, :3] = m[:3, :3] / np.where(lengths > 0, lengths, 1.0)
    out[:3, 3] = m[:3, 3] * unit_scale
    return out
