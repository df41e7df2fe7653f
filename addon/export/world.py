"""The scene world -> :class:`mcengine.scene.World` (a constant background).

Radiance = Background (or Emission) node 'Color' x 'Strength', read from the
node linked to the Surface socket of the world's active Cycles output.  A
linked Color or Strength (sky or environment textures, ...) is replaced by
the socket's unlinked value; any other shader falls back to ``world.color``;
both are warned.  Nothing linked: black, as in Cycles.  A world without a
node tree uses ``world.color``; no world at all is black.
"""
from __future__ import annotations

import math

from mcengine.scene import World

from .materials import clamp_color, fmt, linked_node

__all__ = ["export_world"]

BLACK = (0.0, 0.0, 0.0)
_CONSTANT_SHADERS = ("ShaderNodeBackground", "ShaderNodeEmission")


def export_world(ctx, world) -> World:
    """Convert the scene's world (may be None)."""
    if world is None:
        return World(color=BLACK)
    visibility = world.cycles_visibility
    hidden = [ray for ray in ("diffuse", "glossy", "transmission", "scatter")
              if not getattr(visibility, ray)]
    if hidden:
        ctx.warn(f"world '{world.name}': ray visibility ({', '.join(hidden)} off) not supported "
                 f"yet; the world lights everything", "world ray visibility")
    color = _world_color(ctx, world)
    if not all(math.isfinite(c) for c in color):
        ctx.warn(f"world '{world.name}': background {fmt(color)} is not finite; rendered black",
                 "non-finite world")
        color = BLACK
    return World(color=color, visible_camera=bool(visibility.camera))


def _world_color(ctx, world) -> tuple:
    tree = world.node_tree
    if tree is None:
        return clamp_color(world.color[:3])
    out = tree.get_output_node("CYCLES")
    if out is None:
        return BLACK
    if linked_node(out.inputs["Volume"]) is not None:
        ctx.warn(f"world '{world.name}': volume shader not supported yet; ignored", "world volume")
    shader = linked_node(out.inputs["Surface"])
    if shader is None:
        return BLACK
    if shader.bl_idname not in _CONSTANT_SHADERS:
        color = clamp_color(world.color[:3])
        ctx.warn(f"world '{world.name}': {shader.label or shader.name} shader not supported yet; "
                 f"using the world's viewport colour {fmt(color)}", "world shader")
        return color
    color, strength = shader.inputs["Color"], shader.inputs["Strength"]
    linked = [f"{(linked_node(s).label or linked_node(s).name)} into '{s.name}'"
              for s in (color, strength) if linked_node(s) is not None]
    value = clamp_color([c * strength.default_value for c in color.default_value[:3]])
    if linked:
        ctx.warn(f"world '{world.name}': {', '.join(linked)} not supported yet; using the "
                 f"unlinked values, background {fmt(value)}", "world textures")
    return value

