"""Blender lamps -> :class:`mcengine.scene.Light`, in Cycles' units.

strength = color x energy x 2**exposure, times ``temperature_color`` when
``use_temperature`` is on (Blender 5.0 exposes the blackbody colour Cycles
uses as ``Light.temperature_color``), times the emission of the lamp's node tree when
that is constant (the default is white x 1): an Emission shader, also with value nodes
(Blackbody, RGB, Math, ...) and Mix or Add Shaders on constant inputs, compiled and folded
as a material's graph is (``mcengine.shaders``; a Light Falloff's Quadratic without Smooth
is its Strength).  An IES Texture (its Vector unlinked: the direction the light leaves the
lamp, as Cycles reads it) whose Factor the emission is proportional to becomes the lamp's
profile (``mcengine.ies``; the tree folded with the Factor at 1 is the strength); a file
Cycles cannot read gives 100 in every direction, as in Cycles, warned.  A tree that varies
over the lamp otherwise (Light Falloff's other outputs or with Smooth, an IES Texture used
otherwise, textures on its coordinates) is warned and left out.

Shadow casting is ``light.use_shadow``; MIS and max bounces come from
``light.cycles``; the camera/diffuse/glossy/transmission visibility from the
lamp *object*'s ``visible_*`` flags (that is what Cycles reads).

Units: the matrix translation and the point/spot radius and area sizes are
converted to metres with the unit scale; the matrix's rotation and object
scale are kept (the core multiplies area sizes by the object scale, as Cycles
does).  Cycles ignores the unit scale, so to give the same image the power
of point, spot and area lamps is multiplied by scale^2: irradiance
(power / distance^2, or radiance x solid angle) is then unchanged.  Sun
irradiance needs no change.
"""
from __future__ import annotations

import numpy as np

from mcengine.ies import FAILED_VALUE, IESError
from mcengine.kernels.lights import LIGHT_SETS_ALL
from mcengine.scene import Light

from .ies import read_profile
from .materials import linked_node, surface_graph

__all__ = ["export_light"]


def export_light(ctx, ob, matrix_world, name: str,
                 light_sets: int = LIGHT_SETS_ALL) -> Light | None:
    """Convert one evaluated lamp object (None for lamps that emit nothing: portals).

    Parameters
    ----------
    ctx : ExportContext
    ob : bpy.types.Object
        Evaluated object of type 'LIGHT'.
    matrix_world : mathutils.Matrix
        The instance's world matrix (already copied), in Blender units.
    name : str
        Name for messages.
    light_sets : int
        The light sets it lights (light linking, ``linking.LightLinks.light_sets``).
    """
    data = ob.data
    cycles = getattr(data, "cycles", None)
    if cycles is not None and cycles.is_portal:
        ctx.warn(f"light '{name}' is a light portal: portals are not supported yet; skipped "
                 f"(portals add no light, only less noise, in Cycles)", "light portals")
        return None
    strength, profile = _strength(ctx, data, name)
    if not np.all(np.isfinite(strength)):
        ctx.warn(f"light '{name}': strength {strength} is not finite; skipped", "non-finite light")
        return None
    s = ctx.unit_scale
    matrix = np.array(matrix_world, np.float64)
    matrix[:3, 3] *= s
    light = Light(
        type=data.type,
        name=name,
        matrix_world=matrix,
        strength=strength,
        normalize=bool(data.normalize),
        cast_shadow=bool(data.use_shadow),
        use_mis=bool(cycles.use_multiple_importance_sampling) if cycles is not None else True,
        max_bounces=int(cycles.max_bounces) if cycles is not None else 1024,
        visible_camera=bool(ob.visible_camera),
        visible_diffuse=bool(ob.visible_diffuse),
        visible_glossy=bool(ob.visible_glossy),
        visible_transmission=bool(ob.visible_transmission),
        light_sets=int(light_sets),
        ies=profile,
    )
    if data.type in ("POINT", "SPOT"):
        light.radius = float(data.shadow_soft_size) * s
        light.soft_falloff = bool(data.use_soft_falloff)
    if data.type == "SPOT":
        light.spot_size = float(data.spot_size)
        light.spot_blend = float(data.spot_blend)
        # Square (an EEVEE setting): Cycles reads neither it nor anything else of the cone's
        # shape and renders a round cone (blender/light.cpp; measured: the same image), so
        # it is no difference to warn of.
    elif data.type == "SUN":
        light.angle = float(data.angle)
    elif data.type == "AREA":
        light.shape = data.shape
        light.size_x = float(data.size) * s
        light.size_y = float(data.size_y if data.shape in ("RECTANGLE", "ELLIPSE") else data.size) * s
        light.spread = float(data.spread)
    if data.type != "SUN":
        light.strength = tuple(v * s * s for v in light.strength)
    return light


def _strength(ctx, data, name) -> tuple:
    """(color x energy x 2**exposure (x temperature colour) (x node emission), IES profile)."""
    rgb = np.array(data.color[:3], np.float64) * data.energy * 2.0 ** data.exposure
    if data.use_temperature:
        rgb *= np.array(data.temperature_color[:3], np.float64)
    factor, profile = _node_factor(ctx, data, name)
    rgb *= factor
    return tuple(float(x) for x in rgb), profile


def _node_factor(ctx, data, name) -> tuple:
    """Colour factor of the lamp's node tree (ones without one, as Cycles evaluates it) and
    the IES profile it carries (None: none)."""
    tree = data.node_tree if data.use_nodes else None
    if tree is None:
        return np.ones(3), None
    out = tree.get_output_node("CYCLES")
    shader = linked_node(out.inputs["Surface"]) if out is not None else None
    if shader is None:
        return np.zeros(3), None  # an empty light shader emits nothing in Cycles
    # An IES Texture first: folding the tree without its Factor would read its file again.
    profiled = _ies_emission(ctx, data, tree, out, name)
    if profiled is not None:
        return profiled
    constant = _constant_emission(ctx, out)
    if constant is not None:
        return constant, None
    what = f"{shader.label or shader.name} shader"
    if shader.bl_idname == "ShaderNodeEmission":
        linked = [(linked_node(s), s.name) for s in (shader.inputs["Color"], shader.inputs["Strength"])
                  if linked_node(s) is not None]
        what = ", ".join(f"{src.label or src.name} into Emission '{sock}'" for src, sock in linked)
    ctx.warn(f"light '{name}': light node tree ({what}) not supported yet; rendered without "
             f"its node tree (Emission strength 1)", "light nodes")
    return np.ones(3), None


def _constant_emission(ctx, out, constants=None) -> np.ndarray | None:
    """The emission of a light's output node when its graph folds to constants (None when it
    varies over the lamp or holds nodes MC Engine does not evaluate); ``constants``: nodes
    read as constants (``GraphReader``)."""
    from mcengine.shaders import ShaderTable

    material = surface_graph(ctx, out.inputs["Surface"], constants)
    return None if material is None else ShaderTable([material]).constant_emission(0)


def _ies_emission(ctx, data, tree, out, name) -> tuple | None:
    """(strength factor, profile) of a lamp tree whose one IES Texture scales its emission
    (None: the tree is not of that form; the caller warns).

    The tree is folded with the node's Factor read as a constant x: it must give x times
    what it gives at 1 (checked at 0, 1 and beyond the profile's peak), so that the profile
    times the Factor-1 emission is the lamp's emission in every direction.
    """
    nodes = [n for n in tree.nodes if n.bl_idname == "ShaderNodeTexIES" and not n.mute
             and any(s.is_linked for s in n.outputs)]
    if len(nodes) != 1:
        return None
    node = nodes[0]
    label = node.label or node.name
    if linked_node(node.inputs["Vector"]) is not None or linked_node(node.inputs["Strength"]) is not None:
        ctx.warn(f"light '{name}': IES Texture '{label}' with a linked Vector or Strength is not "
                 f"supported yet; rendered without its node tree (Emission strength 1)", "light nodes")
        return np.ones(3), None
    strength = float(node.inputs["Strength"].default_value)
    key = node.as_pointer()
    try:
        profile = read_profile(node, data.library)
    except (IESError, OSError) as exc:
        ctx.warn(f"light '{name}': IES Texture '{label}' could not be read ({exc}); rendered as "
                 f"Cycles renders it, {FAILED_VALUE:g} x Strength in every direction", "IES files")
        folded = _constant_emission(ctx, out, {key: FAILED_VALUE * strength})
        return None if folded is None else (folded, None)
    at_one = _constant_emission(ctx, out, {key: 1.0})
    at_zero = _constant_emission(ctx, out, {key: 0.0})
    x = max(2.0, 4.0 * profile.peak * abs(strength))
    at_x = _constant_emission(ctx, out, {key: x})
    if at_one is None or at_zero is None or at_x is None:
        return None
    scale = float(np.abs(at_x).max()) + 1e-300
    if np.abs(at_zero).max() > 1e-9 * scale or np.abs(at_x - x * at_one).max() > 1e-6 * scale:
        ctx.warn(f"light '{name}': the emission is not proportional to IES Texture '{label}' "
                 f"(not supported yet); rendered without its node tree (Emission strength 1)",
                 "light nodes")
        return np.ones(3), None
    return at_one * strength, profile
