"""MC Engine's own scene settings, stored as ``scene.mcengine``.

Settings that mean the same as a Cycles setting are *not* duplicated here:
the engine reads ``scene.cycles`` for those (see ``export.settings``).
"""
# No "from __future__ import annotations": bpy reads the property annotations as objects.
import bpy

__all__ = ["MCEngineSceneSettings", "register", "unregister"]


class MCEngineSceneSettings(bpy.types.PropertyGroup):
    """Per-scene MC Engine data (integrator options will go here)."""

    last_effects: bpy.props.StringProperty(
        name="Effects",
        description="What the scene used at the last MC Engine render",
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
