"""User interface: Blender's and Cycles' panels for MC Engine, plus MC Engine's own panel.

A Properties panel is drawn only when ``context.engine`` is in its
``COMPAT_ENGINES``.  Like Cycles' ``ui.get_panels``, we add our engine id to
every built-in panel that lists 'BLENDER_RENDER' (camera lens, light and
material context, output, colour management, ...), except the ones Cycles
replaces with its own version (listed below).  Cycles' panels (Sampling,
Light Paths, Film, Light, World, Material, object visibility, ...) share one
set, ``cycles.ui.CyclesButtonsPanel.COMPAT_ENGINES``; adding our id to it
shows them all, and they edit ``scene.cycles`` etc., which the engine reads.
Everything is undone on unregister.
"""
from __future__ import annotations

import bpy

from mcengine.integrators import from_enum

from .engine import ENGINE_ID

__all__ = ["MCENGINE_RENDER_PT_engine", "compatible_panels", "register", "unregister"]

# Built-in panels Cycles replaces by its own (in the shared set); showing both would
# duplicate them.  Cycles also excludes RENDER_PT_simplify because it has its own
# (non-shared) simplify panel; we keep Blender's, whose settings act on the depsgraph.
_REPLACED_BY_CYCLES = {
    "DATA_PT_camera_dof", "DATA_PT_falloff_curve", "DATA_PT_light", "DATA_PT_preview",
    "DATA_PT_spot", "MATERIAL_PT_context_material", "MATERIAL_PT_preview", "NODE_DATA_PT_light",
    "NODE_DATA_PT_spot", "OBJECT_PT_visibility", "VIEWLAYER_PT_filter",
    "VIEWLAYER_PT_layer_passes", "RENDER_PT_post_processing",
}


class MCENGINE_RENDER_PT_engine(bpy.types.Panel):
    """Render Properties > MC Engine: the integrator, the tools, and what the last render
    used, ignored and cost in rays and time."""

    bl_label = "MC Engine"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    COMPAT_ENGINES = {ENGINE_ID}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES

    def draw(self, context):
        settings = context.scene.mcengine
        layout = self.layout
        _draw_integrator(layout, settings)
        row = layout.row(align=True)
        row.operator("mcengine.compare_with_cycles", icon="SEQ_SPLITVIEW")
        row.operator("mcengine.study_accuracy", icon="GRAPH")
        col = layout.column(align=True)
        if not settings.last_effects:
            col.label(text="Not rendered yet", icon="INFO")
            return
        # The effects plan: lights and surfaces | simulated | skipped, one label each.
        for k, part in enumerate(settings.last_effects.split(" | ")):
            col.label(text=part[:1].upper() + part[1:], icon="SHADING_RENDERED" if k == 0 else "BLANK1")
        if settings.last_ignored:
            col.label(text=f"Ignored: {settings.last_ignored}", icon="ERROR")
        accounting = settings.get("last_accounting")
        if accounting:
            # One label per part: the whole line is wider than the panel.
            for part in accounting.split(" | "):
                col.label(text=part)


def _draw_integrator(layout, settings) -> None:
    """The integrator and, where they apply, its depth and branching; the sampler."""
    col = layout.column()
    col.use_property_split = True
    col.use_property_decorate = False
    col.prop(settings, "integrator")
    info = from_enum(settings.integrator)
    row = col.row()
    row.active = info.uses_sampler
    row.prop(settings, "sampler")
    if info.uses_depth:
        col.prop(settings, "depth")
    if info.uses_branching:
        col.prop(settings, "branching")
        rays = info.rays_per_sample(settings.depth, settings.branching)
        col.label(text=f"Up to {rays:,} rays per sample ({info.rays_formula()})")


def compatible_panels() -> list:
    """Built-in and Cycles panel classes that should also show for MC Engine."""
    panels = [p for p in bpy.types.Panel.__subclasses__()
              if "BLENDER_RENDER" in getattr(p, "COMPAT_ENGINES", ())
              and p.__name__ not in _REPLACED_BY_CYCLES]
    cycles_base = _cycles_panel_base()
    if cycles_base is not None:
        panels.append(cycles_base)
    return panels


def _cycles_panel_base():
    """``cycles.ui.CyclesButtonsPanel``, or None when the Cycles add-on is not available."""
    try:
        from cycles import ui as cycles_ui
    except ImportError:
        return None
    return cycles_ui.CyclesButtonsPanel


def register() -> None:
    if not MCENGINE_RENDER_PT_engine.is_registered:
        bpy.utils.register_class(MCENGINE_RENDER_PT_engine)
    for panel in compatible_panels():
        panel.COMPAT_ENGINES.add(ENGINE_ID)


def unregister() -> None:
    for panel in compatible_panels():
        panel.COMPAT_ENGINES.discard(ENGINE_ID)
    if MCENGINE_RENDER_PT_engine.is_registered:
        bpy.utils.unregister_class(MCENGINE_RENDER_PT_engine)
