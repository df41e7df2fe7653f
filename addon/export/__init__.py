"""Export: an evaluated Blender depsgraph -> :class:`mcengine.scene.SceneDescription`.

One module per kind of data (``mesh``, ``materials``, ``lights``, ``camera``,
``world``, ``settings``); this module walks ``depsgraph.object_instances`` once
and hands every instance to the right one.

Conventions
-----------
* The depsgraph is the *render* depsgraph that ``RenderEngine.render`` gets:
  objects hidden from render are already absent from it.
* Lengths are converted to metres with the scene unit scale
  (``unit_settings.scale_length``, only when the unit system is not 'NONE',
  as Blender itself does): mesh positions, light positions, light sizes and
  radii, camera position, clip distances and orthographic scale.  Lamp power
  (watts, W/m^2 for suns) and emission are *not* rescaled.
* Render settings that mean the same in Cycles are read from ``scene.cycles``
  so a scene renders alike in both engines.
* Problems with one object become a warning and the object is skipped; only a
  scene that cannot be rendered at all raises :class:`ExportError`.  Every
  unsupported feature is named in one warning together with the fallback used.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mcengine import blas
from mcengine.kernels.camera import view_plane
from mcengine.scene import MotionVectors, SceneDescription, SceneError

__all__ = ["ExportError", "ExportContext", "ExportResult", "PARTS", "export"]

#: What :func:`export` can re-export on its own (the viewport, after an edit):
#: "objects" (meshes and their materials), "materials" (the materials alone,
#: when every object keeps its material slots), "lights", "world", "settings"
#: (film and integrator).
PARTS = frozenset({"objects", "materials", "lights", "world", "settings"})


class ExportError(SceneError):
    """The Blender scene cannot be rendered; the message is one line for the user."""


class ExportContext:
    """State shared by the exporters during one export.

    Attributes
    ----------
    scene : bpy.types.Scene
        The evaluated scene.
    unit_scale : float
        Metres per Blender unit.
    warnings : list of str
        One line per problem, in the order found, without duplicates.
    ignored : list of str
        Short names of the scene features the renderer ignored ("specular",
        "textures", ...), without duplicates.
    images : dict
        The images the shader graphs read, by name (``export.images``).
    """

    def __init__(self, scene):
        from .settings import unit_scale

        self.scene = scene
        self.unit_scale = unit_scale(scene)
        self.warnings: list[str] = []
        self.ignored: list[str] = []
        self.images: dict = {}

    def warn(self, message: str, *ignored: str) -> None:
        """Record a warning once, plus the names of the features it ignores."""
        if message not in self.warnings:
            self.warnings.append(message)
        for name in ignored:
            if name not in self.ignored:
                self.ignored.append(name)


@dataclass
class ExportResult:
    """What :func:`export` produces: the scene and the features it ignored."""

    scene: SceneDescription
    ignored: list = field(default_factory=list)


def export(depsgraph, camera=None, parts=PARTS, previous: ExportResult | None = None,
           frame_set=None) -> ExportResult:
    """Export everything the renderer needs from an evaluated depsgraph.

    ``camera`` replaces the scene camera (the viewport's view).  With a
    ``previous`` export, only ``parts`` (names of :data:`PARTS`) are exported
    again and the rest is reused; materials alone are re-exported only if the
    objects still use the same materials in the same order, else the objects
    are exported too.  ``frame_set(frame, subframe)`` evaluates the depsgraph
    at another time (``RenderEngine.frame_set``; by default ``scene.frame_set``):
    a final render with motion blur samples the scene at its motion steps with
    it (the viewport, like Cycles', renders without motion blur).

    Raises
    ------
    ExportError
        If the scene cannot be rendered at all (no camera, panoramic camera).
    """
    from . import camera as cameras
    from . import motion, passes, settings, world

    blas.use_one_thread()      # the export's 4 x 4 inverses: microseconds, not ms (mcengine.blas)
    scene = depsgraph.scene
    if frame_set is None:
        def frame_set(frame, subframe):
            scene.frame_set(frame, subframe=subframe)
    ctx = ExportContext(scene)
    shutter = motion.shutter(scene, depsgraph.view_layer) if camera is None else None
    vectors = motion.vector_shutter(scene, depsgraph.view_layer) if camera is None else None
    if shutter is not None and shutter.position != "CENTER":
        # Cycles takes the scene (lamps, materials, what does not move) at the shutter's middle.
        frame_set(int(shutter.middle // 1), shutter.middle % 1)
    cam = camera if camera is not None else cameras.export_camera(ctx, depsgraph)  # may fail
    old = previous.scene if previous is not None else None
    parts = PARTS if old is None else set(parts)
    if "materials" in parts and "objects" not in parts:
        material_list = _materials_in_order(ctx, depsgraph)
        if [m.name for m in material_list] != [m.name for m in old.materials]:
            parts.add("objects")
    layout = None
    if "objects" in parts:
        geometry, material_list, walked_lights, layout = _walk(ctx, depsgraph,
                                                               shutter=shutter or vectors,
                                                               vectors=vectors is not None)
    else:
        geometry, walked_lights = old.geometry, None
        if "materials" not in parts:
            material_list = old.materials
    if "lights" in parts:
        light_list = walked_lights if walked_lights is not None else _walk(ctx, depsgraph,
                                                                           meshes=False)[2]
    else:
        light_list = old.lights
    desc = SceneDescription(
        geometry=geometry,
        materials=material_list,
        lights=light_list,
        camera=cam,
        world=world.export_world(ctx, scene.world) if "world" in parts else old.world,
        film=cameras.export_film(ctx, scene) if "settings" in parts else old.film,
        integrator=(settings.export_integrator(ctx, scene, depsgraph.view_layer)
                    if "settings" in parts else old.integrator),
    )
    if "settings" in parts:
        desc.passes = passes.export_passes(ctx, scene, depsgraph.view_layer, desc.integrator.name)
        desc.denoising = passes.export_denoising(ctx, scene, depsgraph.view_layer,
                                                 desc.integrator.name)
    else:
        desc.passes, desc.denoising = old.passes, old.denoising
    desc.images = _images_used(desc, {**(old.images if old is not None else {}), **ctx.images})
    if shutter is not None and layout is not None:
        desc.motion_blur = _export_motion(ctx, depsgraph, frame_set, shutter, layout, cam)
        motion.warn_moving_frame_geometry(ctx, desc)
    desc.passes.motion_blur = shutter is not None
    if vectors is not None and layout is not None and "Vector" in desc.passes.enabled:
        desc.motion_vectors = _export_motion_vectors(ctx, depsgraph, frame_set, vectors, layout,
                                                     cam)
    desc.warnings = list(ctx.warnings)
    return ExportResult(scene=desc, ignored=list(ctx.ignored))


def _walk(ctx, depsgraph, meshes: bool = True, shutter=None, vectors: bool = False):
    """One pass over the instances: (geometry, materials, lights, layout); geometry,
    materials and layout (``MeshCollector.layout``, tagged with each instance's motion
    settings when the ``shutter`` is open, with the Vector pass's steps for ``vectors``)
    are None without ``meshes``."""
    from . import lights, materials, mesh, motion

    links = _light_links(ctx, depsgraph)
    table = materials.MaterialTable(ctx)
    collector = mesh.MeshCollector(ctx, table, depsgraph.view_layer, links) if meshes else None
    light_list = []
    for inst in depsgraph.object_instances:
        if not inst.show_self:
            continue
        ob = inst.object
        try:
            if ob.type == "LIGHT":
                light = lights.export_light(ctx, ob, inst.matrix_world.copy(), _instance_name(inst),
                                            links.light_sets(ob))
                if light is not None:
                    light_list.append(light)
            elif collector is not None:
                tag = None
                if shutter is not None:
                    parent = inst.parent if inst.is_instance else None
                    steps = motion.VECTOR_STEPS if vectors else motion.motion_steps(
                        ob.original, parent.original if parent else None)
                    tag = (motion.instance_key(inst), steps,
                           steps > 0 and motion.deforms(ob, parent, depsgraph.scene, vectors))
                collector.add(inst, _instance_name(inst), tag)
        except Exception as exc:  # one bad object must not abort the render
            ctx.warn(f"object '{_instance_name(inst)}' skipped: {type(exc).__name__}: {exc}")
    if collector is None:
        return None, None, light_list, None
    return collector.geometry(), table.materials, light_list, collector.layout


def _light_links(ctx, depsgraph):
    """The light sets of the depsgraph's objects (``linking.LightLinks``), with a warning for
    what is not linked: shadow linking, and links beyond Blender's limits."""
    import bpy

    from . import linking, mesh
    objects = [ob for ob in depsgraph.ids if isinstance(ob, bpy.types.Object)]
    links = linking.LightLinks(objects)
    for line in links.warnings:
        ctx.warn(line, "light linking")
    blocked = sorted(ob.name for ob in objects
                     if getattr(getattr(ob, "light_linking", None), "blocker_collection", None))
    if blocked:
        ctx.warn(f"shadow linking not supported yet ({mesh.listed(blocked)}); every object casts "
                 f"their shadows", "shadow linking")
    return links


def _materials_in_order(ctx, depsgraph) -> list:
    """The material table as the walk would build it, without reading any mesh."""
    import bpy

    from . import materials, mesh
    table = materials.MaterialTable(ctx)
    for inst in depsgraph.object_instances:
        ob = inst.object
        if inst.show_self and ob.type != "LIGHT" and isinstance(ob.data, bpy.types.Mesh):
            for material in mesh.slot_materials(ob, depsgraph.view_layer.material_override):
                table.index(material)
    return table.materials


def _images_used(desc: SceneDescription, images: dict) -> dict:
    """The images some node of the scene's shader graphs reads (a re-export keeps the
    previous export's images of the parts it reuses)."""
    graphs = [m.nodes for m in desc.materials] + [getattr(desc.world, "nodes", [])]
    names = {str(n.props.get("image", "")) for nodes in graphs for n in nodes}
    return {name: im for name, im in images.items() if name in names}


def _sample_layout(ctx, depsgraph, frame_set, shutter, layout):
    """The layout's objects and the camera sampled over the ``shutter`` (``motion.sample_motion``):
    (moving objects with matrices in metres, camera steps, camera matrices, view sizes,
    the frame's view size)."""
    from . import camera, mesh, motion

    s = ctx.unit_scale
    objects = {}
    for index, (tag, vertices, local, slots, matrix) in enumerate(layout):
        key, steps, deform = tag        # the layout follows the geometry's object order
        objects[key] = (index, steps, deform, vertices, local, slots, matrix)

    def read_mesh(ob, slots):
        return mesh.read_local_mesh(ob, slots)

    def place(local, matrix):
        placed = mesh.transform_instances(local, matrix[None], s, [""])
        return placed.vertices, placed.corner_normals()

    ob = depsgraph.scene.camera.evaluated_get(depsgraph)
    camera_steps = motion.motion_steps(ob.original)
    frame_size = camera.frame_size(depsgraph.scene.render)
    aspect = (depsgraph.scene.render.pixel_aspect_x, depsgraph.scene.render.pixel_aspect_y)
    size = view_plane(ob.data, *frame_size, aspect)[0]
    moving, camera_matrices, view_sizes = motion.sample_motion(
        ctx, depsgraph, frame_set, shutter, objects, camera_steps, read_mesh, place)
    for om in moving:
        om.matrices = om.matrices.copy()
        om.matrices[:, :3, :] *= s
    return moving, camera_steps, camera_matrices, view_sizes, size


def _export_motion(ctx, depsgraph, frame_set, shutter, layout, cam):
    """The scene's MotionBlur; sets the camera's motion (the frame is set back afterwards)."""
    from . import camera, motion

    s = ctx.unit_scale
    moving, camera_steps, camera_matrices, view_sizes, size = _sample_layout(
        ctx, depsgraph, frame_set, shutter, layout)
    if camera_steps:
        times = motion.step_times(camera_steps)
        cam.motion = np.stack([cam.matrix_world if t == 0.0 else
                               camera.without_scale(camera_matrices[t], s) for t in times])
    if cam.type == "PERSP":
        cam.view_scale_motion = (view_sizes.get(-1.0, size) / size, view_sizes.get(1.0, size) / size)
    settings = shutter.settings()
    settings.objects = moving
    return settings


def _export_motion_vectors(ctx, depsgraph, frame_set, vectors, layout, cam) -> MotionVectors:
    """The objects and the camera at the previous and the next frame, for the Vector pass."""
    from . import camera, motion

    moving, camera_steps, camera_matrices, view_sizes, size = _sample_layout(
        ctx, depsgraph, frame_set, vectors, layout)
    out = MotionVectors(objects=[om for om in moving if motion.moves(om)])
    if camera_steps:
        out.camera = np.stack([camera.without_scale(camera_matrices[t], ctx.unit_scale)
                               for t in (-1.0, 1.0)])
        if cam.type == "ORTHO" and not all(np.allclose(m, cam.matrix_world) for m in out.camera):
            ctx.warn("Vector pass: Cycles projects the motion of a moving orthographic camera as "
                     "if it were perspective; MC Engine writes the orthographic motion",
                     "Vector pass with a moving orthographic camera")
    if cam.type == "PERSP":
        out.view_scale = (view_sizes.get(-1.0, size) / size, view_sizes.get(1.0, size) / size)
    return out


def _instance_name(inst) -> str:
    """A readable name for messages: "Tree" or "Forest/Tree" for an instance."""
    name = inst.object.name
    if inst.is_instance and inst.parent is not None and inst.parent.name != name:
        return f"{inst.parent.name}/{name}"
    return name

