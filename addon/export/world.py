"""The scene world -> :class:`mcengine.scene.World`.

The world's shader graph is what the Surface socket of its active Cycles output
receives, copied by :class:`shader_graph.GraphReader` as a material's is
(reroutes, muted nodes, groups, every node the core evaluates: Background and
Emission, Mix and Add Shader, Environment Texture, Sky Texture (Multiple and Single
Scattering, Preetham), Light Path, ...).  A graph whose radiance does not vary is rendered as a
constant colour at no cost per ray.  Unsupported nodes (and the Sky Texture's Hosek / Wilkie type)
are warned, their consumer keeping its unlinked value.  Nothing linked: black, as in
Cycles.  A world without a node tree uses ``world.color``; no world at all is black.  Cycles' world settings
Sampling Method and Map Resolution are copied, and its Ray Visibility (camera, diffuse,
glossy, transmission; volume scatter has no volume to light).
"""
from __future__ import annotations

import math

from mcengine.scene import World

from .materials import clamp_color, fmt, linked_node
from .shader_graph import GraphReader

__all__ = ["export_world"]

BLACK = (0.0, 0.0, 0.0)
_CONSTANT_SHADERS = ("Background", "Emission")


def export_world(ctx, world) -> World:
    """Convert the scene's world (may be None)."""
    if world is None:
        return World(color=BLACK)
    visibility = world.cycles_visibility
    settings = getattr(world, "cycles", None)
    common = dict(visible_camera=bool(visibility.camera), visible_diffuse=bool(visibility.diffuse),
                  visible_glossy=bool(visibility.glossy),
                  visible_transmission=bool(visibility.transmission),
                  sampling=str(getattr(settings, "sampling_method", "AUTOMATIC")),
                  map_resolution=int(getattr(settings, "sample_map_resolution", 1024)))
    tree = world.node_tree
    if tree is None:
        return World(color=_finite(ctx, world, clamp_color(world.color[:3])), **common)
    out = tree.get_output_node("CYCLES")
    if out is None:
        return World(color=BLACK, **common)
    if linked_node(out.inputs["Volume"]) is not None:
        ctx.warn(f"world '{world.name}': volume shader not supported yet; ignored", "world volume")
    graph = GraphReader(ctx)
    surface = graph.shader(out.inputs["Surface"])
    if graph.items:
        ctx.warn(f"world '{world.name}': {', '.join(graph.items)} not supported yet; "
                 f"{'; '.join(graph.fallbacks) or 'ignored'}", *graph.features)
    if surface is None:
        return World(color=BLACK, **common)
    for node in graph.nodes:
        for name, value in node.inputs.items():
            if isinstance(value, tuple) and not all(math.isfinite(v) for v in value) or \
                    isinstance(value, float) and not math.isfinite(value):
                ctx.warn(f"world '{world.name}': {node.name} '{name}' {fmt(value)} is not finite; "
                         f"the world is rendered black", "non-finite world")
                return World(color=BLACK, **common)
    if len(graph.nodes) == 1 and graph.nodes[0].type in _CONSTANT_SHADERS:
        # One Background (or Emission) of constant colour: the constant world.
        inputs = graph.nodes[0].inputs
        color, strength = inputs.get("Color", (0.8, 0.8, 0.8)), inputs.get("Strength", 1.0)
        return World(color=clamp_color([c * strength for c in color]), **common)
    return World(color=BLACK, nodes=graph.nodes, surface=surface, **common)


def _finite(ctx, world, color) -> tuple:
    if not all(math.isfinite(c) for c in color):
        ctx.warn(f"world '{world.name}': background {fmt(color)} is not finite; rendered black",
                 "non-finite world")
        return BLACK
    return color
