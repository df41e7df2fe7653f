"""Blender node trees -> the core's shader graphs (lists of :class:`mcengine.scene.ShaderNode`).

One :class:`GraphReader` copies what one output socket (a material's Surface,
a world's Surface) receives, as Cycles reads it (blender/shader.cpp):

* links are followed through reroutes; muted links, invalid ones and those from or to
  a hidden socket are dropped; muted nodes
  pass their input through along their internal links, as in Blender;
* node groups are flattened: a group node's output leads into the group's
  active Group Output, a Group Input back out to the group node's input (or
  its unlinked value); each use of a group is a copy of its nodes;
* every node the core evaluates (``mcengine.kernels.svm.nodes.NODES`` and the
  Mix and Add Shader) is copied with its inputs, by socket identifier (a
  constant, or a :class:`Link` to another copied node's output socket), and
  its properties: every enum, flag, number and string property of the node
  (enums by identifier), plus what ``SPECIAL_PROPS`` reads from data blocks
  (a Texture Coordinate's object, ...);
* anything else is noted, with the fallback used: a value node's consumer
  keeps its own unlinked value, a shader node becomes 0.8 grey diffuse.

The reader collects what it could not translate (``items``, ``features``,
``fallbacks``) so that its caller can write one warning per material.
"""
from __future__ import annotations

import bpy
import numpy as np

from mcengine.ies import FAILED_PROFILE, FAILED_VALUE, IESError
from mcengine.kernels.svm.nodes import NODES, RAMP_TABLE_SIZE, SHADER_ROUTING
from mcengine.scene import Link, ShaderNode
from mcengine.sky import SKY_TYPES

from .ies import read_profile

__all__ = ["GraphReader", "label", "node_type", "source", "SPECIAL_PROPS"]

# Blender's node idnames are "ShaderNode" + the core's type, except these.
_ALIASES = {"BsdfAnisotropic": "BsdfGlossy"}
_PREFIX = "ShaderNode"
# Properties every node has, not the node's own settings.
_BASE_PROPS = {prop.identifier for prop in bpy.types.ShaderNode.bl_rna.properties}
DEFAULT_GREY = (0.8, 0.8, 0.8)


def node_type(node) -> str:
    """The core's type name of a Blender node ("BsdfPrincipled", "TexChecker", ...)."""
    name = node.bl_idname
    if name.startswith(_PREFIX):
        name = name[len(_PREFIX):]
    return _ALIASES.get(name, name)


def label(node) -> str:
    return node.label or node.name


def _tex_coord_props(node, ctx) -> dict:
    """Texture Coordinate: the object whose space the Object output is in."""
    ob = node.object
    if ob is None:
        return {}
    m = np.array(ob.matrix_world, np.float64)
    m[:3, :] *= ctx.unit_scale
    return {"use_object": 1.0, "object_inverse": np.linalg.inv(m)[:3, :].ravel().tolist()}


def _image_props(node, ctx) -> dict:
    """Image and Environment Texture: the image, by its name in the export's images."""
    from .images import export_image
    return {"image": export_image(ctx, node.image)}


def _ramp_props(node, ctx) -> dict:
    """ColorRamp: baked as Cycles bakes it (colorramp_to_array): RGBA at i / 256, i = 0..256,
    evaluated by Blender in the ramp's own interpolation and colour mode."""
    ramp = node.color_ramp
    table = [v for i in range(RAMP_TABLE_SIZE + 1) for v in ramp.evaluate(i / RAMP_TABLE_SIZE)]
    return {"interpolate": 0.0 if ramp.interpolation == "CONSTANT" else 1.0, "table": table}


def _curve_props(curves: int, combined: bool):
    """A curve node's table as Cycles bakes it (curvemapping_*_to_array): over the x range
    from the first to the last point of all its curves, 257 samples of each curve (RGB
    Curves: each channel's curve applied to the combined curve's value)."""
    def props(node, ctx) -> dict:
        mapping = node.mapping
        mapping.initialize()
        maps = list(mapping.curves)
        lo = min(m.points[0].location[0] for m in maps[:curves + (1 if combined else 0)])
        hi = max(m.points[-1].location[0] for m in maps[:curves + (1 if combined else 0)])
        table = []
        for i in range(RAMP_TABLE_SIZE + 1):
            x = lo + i / RAMP_TABLE_SIZE * (hi - lo)
            if combined:
                x = mapping.evaluate(maps[3], x)
            table.extend(mapping.evaluate(maps[k], x) for k in range(curves))
        return {"min_x": lo, "max_x": hi, "table": table,
                "extrapolate": 1.0 if mapping.extend == "EXTRAPOLATED" else 0.0}
    return props


def _output_value_props(name, size):
    """Props of a node whose value is its output socket's own (RGB, Value, Normal): Blender keeps
    it there, not in a node property."""
    def props(node, ctx) -> dict:
        value = node.outputs[0].default_value
        return {name: tuple(float(v) for v in value[:size]) if size > 1 else float(value)}
    return props


def _ao_props(node, ctx) -> dict:
    """Ambient Occlusion: a Distance of 0 that nothing is linked to is the world's AO distance
    (World > Light Settings > Distance; Cycles' NODE_AO_GLOBAL_RADIUS), else -1 (its own)."""
    distance = node.inputs["Distance"]
    world = ctx.scene.world
    if distance.is_linked or distance.default_value != 0.0:
        return {"global_distance": -1.0}
    return {"global_distance": float(world.light_settings.distance) if world is not None else 0.0}


def _ies_props(node, ctx) -> dict:
    """IES Texture: its profile as the kernel reads it (``mcengine.ies``), and whether its
    Vector is the implicit one (Cycles' Incoming in object space, taken as a normal).  A file
    Cycles cannot read gives 100 in every direction, as in Cycles, warned."""
    try:
        profile = read_profile(node, getattr(node.id_data, "library", None))
    except (IESError, OSError) as exc:
        ctx.warn(f"IES Texture '{label(node)}' could not be read ({exc}); rendered as Cycles "
                 f"renders it, {FAILED_VALUE:g} x Strength in every direction", "IES files")
        profile = FAILED_PROFILE
    return {"table": profile.packed().tolist(),
            "implicit_vector": 1.0 if source(node.inputs["Vector"])[0] is None else 0.0}


def _sky_props(node, ctx) -> dict:
    """Sky Texture: the Preetham type's Sun Direction (a vector, which the generic copy skips)."""
    return {"sun_direction": tuple(float(v) for v in node.sun_direction)}


def _hair_props(node, ctx) -> dict:
    """Hair BSDF: whether its Tangent is the implicit one (on a mesh Cycles then takes the
    triangle's dPdv and ignores the Offset)."""
    return {"implicit_tangent": 1.0 if source(node.inputs["Tangent"])[0] is None else 0.0}


# Node type -> function(node, ctx) returning props read from data blocks (objects, images,
# ramps, curves) or sockets (RGB, Value, Normal), which the generic property copy cannot.
SPECIAL_PROPS = {
    "RGB": _output_value_props("color", 3),
    "Value": _output_value_props("value", 1),
    "Normal": _output_value_props("direction", 3),
    "TexCoord": _tex_coord_props,
    "TexImage": _image_props,
    "TexEnvironment": _image_props,
    "ValToRGB": _ramp_props,
    "RGBCurve": _curve_props(3, True),
    "VectorCurve": _curve_props(3, False),
    "FloatCurve": _curve_props(1, False),
    "AmbientOcclusion": _ao_props,
    "TexIES": _ies_props,
    "BsdfHair": _hair_props,
    "TexSky": _sky_props,
}


class GraphReader:
    """The nodes of one material's (or world's) graph being copied.

    Parameters
    ----------
    ctx : ExportContext
        Gives the unit scale to data-block properties.
    constants : dict, optional
        Nodes read as constants: {node.as_pointer(): value}, the value every output of the
        node gives (a lamp's IES Texture, whose Factor the lamp's profile carries).
    """

    def __init__(self, ctx, constants=None):
        self.ctx = ctx
        self.constants = constants or {}
        self.nodes: list[ShaderNode] = []
        self._index: dict = {}
        self.items: list[str] = []
        self.features: list[str] = []
        self.fallbacks: list[str] = []

    def note(self, item: str, feature: str, fallback: str = "") -> None:
        if item not in self.items:
            self.items.append(item)
        if feature not in self.features:
            self.features.append(feature)
        if fallback and fallback not in self.fallbacks:
            self.fallbacks.append(fallback)

    def shader(self, socket, groups=()) -> Link | None:
        """The link a shader socket receives (None: nothing, black)."""
        out, groups = source(socket, groups)
        if out is None:
            return None
        index = self.node(out.node, groups)
        if index is None:
            return None
        copied = self.nodes[index]
        if copied.type in SHADER_ROUTING:
            return Link(index, "Shader")
        spec = NODES.get(copied.type)
        return Link(index, spec.outputs[0].name if spec is not None and spec.outputs else "BSDF")

    def node(self, node, groups) -> int | None:
        """Index of the copy of ``node`` (copied once per group path); None in a cycle."""
        key = (node.as_pointer(), tuple(g.as_pointer() for g in groups))
        if key not in self._index:
            self._index[key] = None     # a cycle through this node finds nothing
            index = len(self.nodes)
            self.nodes.append(ShaderNode(type="", name=node.name))
            self.nodes[index] = self.convert(node, groups)
            self._index[key] = index
        index = self._index[key]
        if index is None:
            self.note(f"{label(node)} (a cycle in the node graph)", "shader nodes")
        return index

    # -- one node ---------------------------------------------------------------------------------
    def convert(self, node, groups) -> ShaderNode:
        kind = node_type(node)
        if not _identity_mapping(getattr(node, "texture_mapping", None)):
            self.note(f"{label(node)} Texture Mapping (the node's sidebar)", "texture mapping",
                      f"{label(node)} read at its unmapped coordinates")
        if kind in SHADER_ROUTING or kind in NODES:
            spec = SHADER_ROUTING.get(kind) or NODES[kind]
            inputs = {}
            sockets = {s.identifier: s for s in node.inputs}
            for socket in spec.inputs:
                if socket.name.startswith("prop:"):
                    continue
                sock = sockets.get(socket.name)
                if sock is None:
                    continue
                value = self.input(node, sock, socket, groups)
                if value is not None:
                    inputs[socket.name] = value
            props = self.props(node, kind)
            return ShaderNode(kind, inputs, props, name=node.name)
        return self.unsupported(node, kind)

    def input(self, node, sock, socket, groups):
        """An input's copy: a Link, a constant, or None (the node's default)."""
        if socket.type == "shader":
            return self.shader(sock, groups)
        out, got = source(sock, groups)
        if out is None:
            if isinstance(socket.default, str):
                return None       # an implicit texture coordinate, as Cycles fills it
            return _constant(got, socket.type)
        target = out.node
        if target.as_pointer() in self.constants:
            return _constant(self.constants[target.as_pointer()], socket.type)
        kind = node_type(target)
        spec = NODES.get(kind)
        feature = f"{kind} node"
        if kind == "LightPath" and out.identifier == "Portal Depth":
            self.note(f"{label(target)} 'Portal Depth' into {label(node)}", "Light Path Portal Depth",
                      "Portal Depth read as 0 (ray portals passed are not counted)")
        if kind == "TexSky" and target.sky_type not in SKY_TYPES:
            spec, feature = None, f"Sky Texture type {target.sky_type}"
        if spec is None or spec.outputs and spec.outputs[0].type == "shader":
            what = "shader output" if spec is not None else "node"
            self.note(f"{label(target)} into {label(node)} '{sock.name}'",
                      "shader nodes" if spec is not None else feature,
                      f"unlinked value of {label(node)} '{sock.name}' used"
                      + ("" if spec is None else f" ({what} into a value)"))
            return _constant(getattr(sock, "default_value", None), socket.type)
        index = self.node(target, got)
        if index is None:
            return _constant(getattr(sock, "default_value", None), socket.type)
        return Link(index, out.identifier)

    def props(self, node, kind) -> dict:
        """Every setting of the node (enums by identifier, flags, numbers, strings) and the
        data-block ones of ``SPECIAL_PROPS``."""
        props = {}
        for prop in node.bl_rna.properties:
            ident = prop.identifier
            if ident in _BASE_PROPS or prop.type not in ("ENUM", "BOOLEAN", "INT", "FLOAT", "STRING"):
                continue
            if getattr(prop, "is_array", False) or getattr(prop, "array_length", 0):
                continue
            if prop.type == "ENUM" and getattr(prop, "is_enum_flag", False):
                continue
            value = getattr(node, ident)
            props[ident] = value if prop.type in ("ENUM", "STRING") else float(value)
        special = SPECIAL_PROPS.get(kind)
        if special is not None:
            props.update(special(node, self.ctx))
        return props

    def unsupported(self, node, kind) -> ShaderNode:
        """A node the core does not evaluate: grey diffuse for shaders (values: see input)."""
        is_shader = any(s.type == "SHADER" for s in node.outputs)
        if is_shader:
            self.note(f"{label(node)} surface shader", "shader nodes",
                      f"{label(node)} rendered as 0.8 grey diffuse")
            return ShaderNode("BsdfDiffuse", {"Color": DEFAULT_GREY}, name=node.name)
        return ShaderNode(kind, {}, name=node.name)


def _identity_mapping(mapping) -> bool:
    """Whether a texture node's legacy Texture Mapping (sidebar > Properties; Cycles applies
    it, blender/shader.cpp get_tex_mapping) leaves coordinates as they are (or is absent)."""
    if mapping is None:
        return True
    return (tuple(mapping.translation) == (0.0, 0.0, 0.0)
            and tuple(mapping.rotation) == (0.0, 0.0, 0.0)
            and tuple(mapping.scale) == (1.0, 1.0, 1.0)
            and not mapping.use_min and not mapping.use_max
            and (mapping.mapping_x, mapping.mapping_y, mapping.mapping_z) == ("X", "Y", "Z")
            and mapping.mapping == "FLAT")


def source(socket, groups=()):
    """What an input socket receives: (output socket, group path) of a real node, or
    (None, value) with the constant it gets (None: nothing at all)."""
    for _ in range(1024):
        links = [link for link in socket.links if _carries(link)] if socket.is_linked else []
        if not links:
            value = getattr(socket, "default_value", None)
            return None, value
        out = links[0].from_socket
        node = out.node
        if node.bl_idname == "NodeReroute":
            socket = node.inputs[0]
        elif node.mute:
            through = [lk.from_socket for lk in node.internal_links if lk.to_socket == out]
            if not through:
                return None, None
            socket = through[0]
        elif node.bl_idname == "ShaderNodeGroup" and node.node_tree is not None:
            inner = _group_output(node.node_tree)
            if inner is None:
                return None, None
            target = _by_identifier(inner.inputs, out.identifier)
            if target is None:
                return None, None
            socket, groups = target, groups + (node,)
        elif node.bl_idname == "NodeGroupInput":
            if not groups:
                return None, None
            outer = groups[-1]
            target = _by_identifier(outer.inputs, out.identifier)
            if target is None:
                return None, None
            socket, groups = target, groups[:-1]
        else:
            return out, groups
    return None, None


def _carries(link) -> bool:
    """Whether a link carries a value: Cycles drops muted and invalid links and those from or
    to a socket the node hides (Vector Math's Value output for a vector operation, ...)."""
    return (not link.is_muted and link.is_valid and link.from_socket.enabled
            and link.to_socket.enabled)


def _constant(value, kind):
    """A socket's unlinked value as a constant (None when it has none)."""
    if value is None:
        return None
    if kind == "float":
        try:
            return float(value)
        except TypeError:
            return float(value[0])
    try:
        values = [float(v) for v in value][:3]
    except TypeError:
        values = [float(value)] * 3
    return tuple(values + [0.0] * (3 - len(values)))


def _group_output(tree):
    """The active Group Output node of a node group (None: none)."""
    outputs = [n for n in tree.nodes if n.bl_idname == "NodeGroupOutput"]
    for n in outputs:
        if n.is_active_output:
            return n
    return outputs[0] if outputs else None


def _by_identifier(sockets, identifier):
    for s in sockets:
        if s.identifier == identifier:
            return s
    return None
