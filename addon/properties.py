"""MC Engine's own scene settings, stored as ``scene.mcengine``.

Settings that mean the same as a Cycles setting are *not* duplicated here:
the engine reads ``scene.cycles`` for those (see ``export.settings``).
"""
# No "from __future__ import annotations": bpy reads the property annotations as objects.
import bpy

__all__ = ["MCEngineSceneSettings", "register", "unregister"]


INTEGRATORS = [
    ("PATH", "Path Tracing", "One secondary ray per bounce, light sampling with multiple "
     "importance sampling, Russian roulette; matches Cycles", 0),
    ("RAYCAST", "Ray Casting", "Camera rays and direct light from every light; no reflected "
     "light: fast and biased", 1),
    ("WHITTED", "Whitted", "Direct light plus perfect mirror and refraction rays down to Depth "
     "ray levels: 2^depth - 1 rays per sample at most", 2),
    ("DISTRIBUTION", "Distribution", "Direct light plus Branching rays at every hit down to Depth "
     "ray levels: 1 + b + ... + b^(depth-1) rays per sample", 3),
]


class MCEngineSceneSettings(bpy.types.PropertyGroup):
    """Per-scene MC Engine settings that Cycles has no equivalent for."""

    integrator: bpy.props.EnumProperty(
        name="Integrator", items=INTEGRATORS, default="PATH",
        description="Light transport algorithm")
    depth: bpy.props.IntProperty(
        name="Depth", default=5, min=1, max=16,
        description="Ray levels of Whitted and distribution ray tracing (the camera ray is level 1)")
    branching: bpy.props.IntProperty(
        name="Branching", default=4, min=1, max=64,
        description="Secondary rays per hit in distribution ray tracing")

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
