"""MC Engine's own scene settings, stored as ``scene.mcengine``.

Settings that mean the same as a Cycles setting are *not* duplicated here:
the engine reads ``scene.cycles`` for those (see ``export.settings``).
"""
# No "from __future__ import annotations": bpy reads the property annotations as objects.
import bpy

from mcengine import integrators, samplers

__all__ = ["MCEngineSceneSettings", "SAMPLER_AS_CYCLES", "register", "unregister"]

# The integrator enum's items, from the registry.  A .blend stores the index, so new
# integrators go at the end of the registry.
INTEGRATOR_ITEMS = [(info.enum_id, info.label, info.description, index)
                    for index, info in enumerate(integrators.INTEGRATORS.values())]

# The sampler enum: "As Cycles" (the sampler matching Cycles' Sampling Pattern), then the
# registry's samplers; new samplers go at the end.
SAMPLER_AS_CYCLES = "AUTOMATIC"
SAMPLER_ITEMS = [(SAMPLER_AS_CYCLES, "As Cycles",
                  "The sampler matching Cycles' Sampling Pattern: scrambled Sobol for every "
                  "pattern Cycles offers", 0)] + [
    (info.enum_id, info.label, info.description, index + 1)
    for index, info in enumerate(samplers.SAMPLERS.values())]


class MCEngineSceneSettings(bpy.types.PropertyGroup):
    """Per-scene MC Engine settings that Cycles has no equivalent for."""

    integrator: bpy.props.EnumProperty(
        name="Integrator", items=INTEGRATOR_ITEMS,
        default=integrators.get(integrators.DEFAULT).enum_id,
        description="Light transport algorithm")
    depth: bpy.props.IntProperty(
        name="Depth", default=integrators.DEFAULT_DEPTH, min=integrators.DEPTH_RANGE[0],
        max=integrators.DEPTH_RANGE[1],
        description="Ray levels of Whitted and distribution ray tracing (the camera ray is level 1)")
    branching: bpy.props.IntProperty(
        name="Branching", default=integrators.DEFAULT_BRANCHING,
        min=integrators.BRANCHING_RANGE[0], max=integrators.BRANCHING_RANGE[1],
        description="Secondary rays per hit in distribution ray tracing")
    sampler: bpy.props.EnumProperty(
        name="Sampler", items=SAMPLER_ITEMS, default=SAMPLER_AS_CYCLES,
        description="Random numbers of the path tracer (the other integrators draw "
                    "independent numbers)")

    last_effects: bpy.props.StringProperty(
        name="Effects plan",
        description="What the last MC Engine render simulated and skipped (its effects plan)",
        default="",
    )
    last_ignored: bpy.props.StringProperty(
        name="Ignored",
        description="Scene features the last MC Engine render did not support (see the warnings)",
        default="",
    )


def register() -> None:
    if not MCEngineSceneSettings.is_registered:
        bpy.utils.register_class(MCEngineSceneSettings)
    bpy.types.Scene.mcengine = bpy.props.PointerProperty(type=MCEngineSceneSettings)


def unregister() -> None:
    if hasattr(bpy.types.Scene, "mcengine"):
        del bpy.types.Scene.mcengine
    if MCEngineSceneSettings.is_registered:
        bpy.utils.unregister_class(MCEngineSceneSettings)
