"""Motion blur: the shutter, and what moves while it is open, as Cycles' Blender sync reads it.

Cycles (blender/sync.cpp, object.cpp, camera.cpp, mesh.cpp) renders motion
blur when both ``render.use_motion_blur`` and the view layer's
``use_motion_blur`` are on.  The shutter lasts ``motion_blur_shutter`` frames,
centred on the frame (CENTER), starting at it (START) or ending at it (END);
with START or END the whole scene, lamps and materials included, is taken at
the shutter's middle.  Objects with ``cycles.use_motion_blur`` (and, for
instances, their instancer's) move at ``2^motion_steps + 1`` steps spread
evenly over the shutter, the camera at its own steps; each step is the scene
evaluated at its subframe (``frame_set``).  Meshes with
``cycles.use_deform_motion`` whose modifiers, shape keys or armature may
deform them also keep their vertex positions at the steps (dropped when the
vertex count changes, as Cycles does).  Lamps do not move in Cycles, and do
not here.  The shutter curve is sampled at 257 points as Cycles samples it;
``cycles.rolling_shutter_type`` TOP reads the rows out from the top.

The Vector pass (motion vectors), which Cycles fills only with motion blur off,
takes the scene at the previous and the next frame the same way: a shutter of
two frames centred on the frame (Cycles' ``motion_shutter_time`` for the pass),
every object at three steps whatever its motion blur settings, the camera at its
own steps.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mcengine.kernels.camera import view_plane
from mcengine.scene import MotionBlur, ObjectMotion

__all__ = ["Shutter", "shutter", "vector_shutter", "instance_key", "motion_steps",
           "sample_motion", "VECTOR_STEPS"]

CURVE_SAMPLES = 257          # Cycles' RAMP_TABLE_SIZE + 1
MAX_MOTION_STEPS = 129       # Cycles' Object::MAX_MOTION_STEPS
VECTOR_STEPS = 3             # every object's steps for the Vector pass (Cycles' MOTION_PASS)


@dataclass
class Shutter:
    """The open shutter: its length in frames, where the frame lies in it, its curve."""

    length: float
    position: str
    curve: np.ndarray
    rolling: bool = False
    rolling_duration: float = 0.1
    frame: int = 1
    subframe: float = 0.0

    @property
    def middle(self) -> float:
        """The frame (and subframe) at the shutter's middle, where the scene is exported."""
        delta = {"START": 0.5, "END": -0.5}.get(self.position, 0.0) * self.length
        return self.frame + self.subframe + delta

    def time(self, relative: float) -> float:
        """Frame and subframe of a motion time in [-1, 1] over the shutter."""
        return self.middle + relative * self.length * 0.5

    def settings(self) -> MotionBlur:
        return MotionBlur(shutter_curve=self.curve, rolling_shutter=self.rolling,
                          rolling_shutter_duration=self.rolling_duration)


def shutter(scene, view_layer) -> Shutter | None:
    """The shutter of a render of ``scene`` (None when motion blur is off)."""
    render = scene.render
    if not (render.use_motion_blur and view_layer.use_motion_blur):
        return None
    cumap = render.motion_blur_shutter_curve
    cumap.update()
    curve = cumap.curves[0]
    samples = np.array([cumap.evaluate(curve, i / (CURVE_SAMPLES - 1)) for i in range(CURVE_SAMPLES)],
                       np.float64)
    cycles = getattr(scene, "cycles", None)
    rolling = cycles is not None and cycles.rolling_shutter_type == "TOP"
    return Shutter(length=float(render.motion_blur_shutter), position=render.motion_blur_position,
                   curve=samples, rolling=rolling,
                   rolling_duration=float(cycles.rolling_shutter_duration) if cycles else 0.1,
                   frame=scene.frame_current, subframe=float(scene.frame_subframe))


def vector_shutter(scene, view_layer) -> Shutter | None:
    """The previous and the next frame as a shutter, when the view layer's Vector pass is on
    and motion blur off (else None: Cycles then leaves the pass at 0)."""
    if not getattr(view_layer, "use_pass_vector", False) or (
            scene.render.use_motion_blur and view_layer.use_motion_blur):
        return None
    return Shutter(length=2.0, position="CENTER", curve=None, frame=scene.frame_current,
                   subframe=float(scene.frame_subframe))


def motion_steps(ob, parent=None) -> int:
    """Cycles' object_motion_steps: 0 without motion blur, else 2^steps + 1 (the
    instancer's setting too for an instance)."""
    settings = getattr(ob, "cycles", None)
    if settings is None or not settings.use_motion_blur:
        return 0
    steps = max(1, int(settings.motion_steps))
    if parent is not None and parent != ob:
        parent_settings = getattr(parent, "cycles", None)
        if parent_settings is None or not parent_settings.use_motion_blur:
            return 0
        steps = max(steps, int(parent_settings.motion_steps))
    return min((2 << (steps - 1)) + 1, MAX_MOTION_STEPS)


def deforms(ob, parent, scene, vectors: bool = False) -> bool:
    """Cycles' use of deformation motion: ``use_deform_motion`` (and the instancer's; not
    for the Vector pass, ``vectors``, which takes every deformation), and a mesh that
    something may deform: ``is_deform_modified``, or any instance's data (Cycles cannot tell
    whether geometry made by an instancer is animated)."""
    if parent is not None and parent != ob:
        return vectors or bool(ob.cycles.use_deform_motion and parent.cycles.use_deform_motion)
    if not (vectors or getattr(ob.cycles, "use_deform_motion", False)):
        return False
    return bool(ob.original.is_deform_modified(scene, "RENDER"))


def instance_key(inst) -> tuple:
    """What names one depsgraph instance across frames (Cycles' ObjectKey)."""
    if inst.is_instance:
        parent = inst.parent.original.name if inst.parent is not None else ""
        return inst.object.original.name, parent, tuple(inst.persistent_id)
    return inst.object.original.name, "", ()


def step_times(steps: int) -> list:
    """Motion times in [-1, 1] of ``steps`` steps (Cycles' Object::motion_time)."""
    return [2.0 * k / (steps - 1) - 1.0 for k in range(steps)]


@dataclass
class _Track:
    """One exported object instance that may move: what is sampled at each step."""

    index: int                   # object index in the geometry
    steps: int
    deform: bool
    vertices: tuple              # (first, count) in the geometry
    mesh: object                 # the LocalMesh of the frame (for the topology check)
    slots: tuple                 # material slots of the mesh key
    matrices: dict = field(default_factory=dict)      # time -> 4x4 (Blender units)
    positions: dict = field(default_factory=dict)     # time -> (count, 3) world, frame's matrix
    normals: dict = field(default_factory=dict)


def sample_motion(ctx, depsgraph, frame_set, shutter_: Shutter, objects, camera_steps,
                  read_mesh, place):
    """Evaluate the scene at every motion time and return (object motions, camera
    matrices by time, view sizes by time).

    ``objects`` maps instance keys to ``(geometry object index, motion steps, deforms,
    (first vertex, count), frame's LocalMesh, material slots, frame's matrix)``;
    ``camera_steps`` is the camera's step count; ``read_mesh(ob, slots)`` reads an
    evaluated mesh and ``place(mesh, matrix)`` places it in the world as the frame
    placed it, returning (vertices, normals).
    """
    tracks = {}
    times = set()
    for key, (index, steps, deform, vertices, mesh, slots, matrix) in objects.items():
        if steps:
            track = _Track(index, steps, deform, vertices, mesh, slots)
            track.matrices[0.0] = matrix
            tracks[key] = track
            times.update(step_times(steps))
    if camera_steps:
        times.update(step_times(camera_steps))
    camera_matrices, view_sizes = {}, {}
    scene = depsgraph.scene
    for relative in sorted(times):
        if relative == 0.0:
            continue
        time = shutter_.time(relative)
        frame = int(np.floor(time))
        frame_set(frame, time - frame)
        ob = scene.camera.evaluated_get(depsgraph)
        if camera_steps and relative in step_times(camera_steps):
            camera_matrices[relative] = np.array(ob.matrix_world, np.float64)
        if relative in (-1.0, 1.0):
            # Cycles looks at the focal length at shutter open and close whenever anything
            # has motion steps there, the camera or not.
            view_sizes[relative] = view_plane(ob.data, *_frame_size(scene))[0]
        for inst in depsgraph.object_instances:
            if not inst.show_self:
                continue
            track = tracks.get(instance_key(inst))
            if track is None or relative not in step_times(track.steps):
                continue
            track.matrices[relative] = np.array(inst.matrix_world, np.float64)
            if track.deform and relative not in track.positions:
                mesh = read_mesh(inst.object, track.slots)
                if (mesh is not None and mesh.vertices.shape == track.mesh.vertices.shape
                        and np.array_equal(mesh.triangles, track.mesh.triangles)):
                    track.positions[relative], track.normals[relative] = \
                        place(mesh, track.matrices[0.0])
                else:
                    track.deform = False
                    ctx.warn(f"object '{key_name(instance_key(inst))}': its topology changes "
                             f"during the shutter; rendered without deformation blur (as Cycles)",
                             "deformation motion blur")
    frame_set(shutter_.frame, shutter_.subframe)
    return [om for om in (_object_motion(t, place) for t in tracks.values()) if om is not None], \
        camera_matrices, view_sizes


def moves(om: ObjectMotion) -> bool:
    """Whether an object with motion settings moves or deforms over its steps."""
    return om.positions is not None or not all(np.array_equal(m, om.matrices[0]) for m in om.matrices)


# Nodes that read an object's triangles themselves: what they see of them.
_FRAME_GEOMETRY_NODES = {"Wireframe": "the edges of their triangles",
                         "Bevel": "their surfaces' normals around the point"}


def warn_moving_frame_geometry(ctx, desc) -> None:
    """Warn when moving objects use a material with a Wireframe or Bevel node, or move in a
    scene where a material uses Ambient Occlusion: these read triangles as they are at the
    frame's time (the evaluator reads the frame's vertices, Bevel and AO hierarchies built
    from them), where Cycles takes them at each ray's time."""
    if desc.motion_blur is None:
        return
    g = desc.geometry
    for kind, what in _FRAME_GEOMETRY_NODES.items():
        used = {k for k, m in enumerate(desc.materials) if any(n.type == kind for n in m.nodes)}
        names = [g.object_names[om.object] for om in desc.motion_blur.objects if moves(om)
                 and used & set(np.unique(g.material_index[g.object_index == om.object]).tolist())]
        if names:
            from .mesh import listed
            ctx.warn(f"{kind} on moving objects ({listed(names)}): {what} as they are at the "
                     f"frame, not as they move during the shutter", f"{kind} under motion blur")
    in_use = {k for k in np.unique(g.material_index).tolist() if k >= 0}
    if any(n.type == "AmbientOcclusion" for k in in_use for n in desc.materials[k].nodes):
        names = [g.object_names[om.object] for om in desc.motion_blur.objects if moves(om)]
        if names:
            from .mesh import listed
            ctx.warn(f"Ambient Occlusion with moving objects ({listed(names)}): they occlude "
                     f"as they are at the frame, not as they move during the shutter",
                     "Ambient Occlusion under motion blur")


def key_name(key) -> str:
    return f"{key[1]}/{key[0]}" if key[1] else key[0]


def _object_motion(track: _Track, place) -> ObjectMotion | None:
    times = step_times(track.steps)
    # A step where the object is missing keeps the frame's transform (Cycles).
    mats = np.stack([track.matrices.get(t, track.matrices[0.0]) for t in times])
    om = ObjectMotion(object=track.index, vertices=track.vertices, matrices=mats)
    rest, rest_normals = place(track.mesh, track.matrices[0.0]) if track.positions else (None, None)
    first = min(track.positions) if track.positions else None
    # Cycles keeps deformation only where the first motion step read differs from the frame.
    if track.deform and first is not None and not np.array_equal(
            np.asarray(track.positions[first], np.float32), np.asarray(rest, np.float32)):
        om.positions = np.stack([track.positions.get(t, rest) for t in times]).astype(np.float32)
        om.normals = np.stack([track.normals.get(t, rest_normals) for t in times]).astype(np.float32)
    return om


def _frame_size(scene):
    render = scene.render
    pct = render.resolution_percentage
    return (render.resolution_x * pct // 100, render.resolution_y * pct // 100,
            (render.pixel_aspect_x, render.pixel_aspect_y))
