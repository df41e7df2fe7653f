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

from mcengine.scene import SceneDescription, SceneError

__all__ = ["ExportError", "ExportContext", "ExportResult", "export"]


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
    """

    def __init__(self, scene):
        from .settings import unit_scale

        self.scene = scene
        self.unit_scale = unit_scale(scene)
        self.warnings: list[str] = []
        self.ignored: list[str] = []

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


def export(depsgraph) -> ExportResult:
    """Export everything the renderer needs from an evaluated render depsgraph.

    Raises
    ------
    ExportError
        If the scene cannot be rendered at all (no camera, panoramic camera).
    """
    from . import camera, lights, materials, mesh, settings, world

    scene = depsgraph.scene
    ctx = ExportContext(scene)
    cam = camera.export_camera(ctx, depsgraph)  # first: it is the only fatal part
    table = materials.MaterialTable(ctx)
    meshes = mesh.MeshCollector(ctx, table)
    light_list = []
    for inst in depsgraph.object_instances:
        if not inst.show_self:
            continue
        ob = inst.object
        try:
            if ob.type == "LIGHT":
                light = lights.export_light(ctx, ob, inst.matrix_world.copy(), _instance_name(inst))
                if light is not None:
                    light_list.append(light)
            else:
                meshes.add(inst, _instance_name(inst))
        except Exception as exc:  # one bad object must not abort the render
            ctx.warn(f"object '{_instance_name(inst)}' skipped: {type(exc).__name__}: {exc}")
    desc = SceneDescription(
        geometry=meshes.geometry(),
        materials=table.materials,
        lights=light_list,
        camera=cam,
        world=world.export_world(ctx, scene.world),
        film=camera.export_film(ctx, scene),
        integrator=settings.export_integrator(ctx, scene, depsgraph.view_layer),
    )
    desc.warnings = list(ctx.warnings)
    return ExportResult(scene=desc, ignored=list(ctx.ignored))


def _instance_name(inst) -> str:
    """A readable name for messages: "Tree" or "Forest/Tree" for an instance."""
    name = inst.object.name
    if inst.is_instance and inst.parent is not None and inst.parent.name != name:
        return f"{inst.parent.name}/{name}"
    return name

