"""Blender materials -> :class:`mcengine.scene.Material` (a graph of shader nodes).

The graph read is what the Surface socket of the material's active Cycles
output (``node_tree.get_output_node('CYCLES')``) receives, following
reroutes, skipping muted links and passing through muted nodes as Blender
does.  Every shader node the renderer evaluates is copied with all its inputs
(their unlinked values) and its properties; the core shades them as Cycles
does (``mcengine.kernels.svm``):

* Principled, Diffuse, Glossy, Glass, Refraction, Translucent, Transparent,
  Sheen, Emission and Holdout nodes, Mix Shader and Add Shader;
* Metallic BSDF in F82 mode becomes the Principled BSDF at Metallic 1 (the
  same closure); in Physical Conductor mode its IOR and extinction are fitted
  to F82 (warned);
* Subsurface Scattering becomes a Diffuse BSDF of its colour, and the
  Principled's subsurface layer is rendered as diffuse (Cycles' own
  zero-radius limit), warned;
* any other shader node: 0.8 grey diffuse (Cycles' default surface), warned;
* a linked input that is not a shader (a texture, a math node, a normal map,
  ...) is replaced by the socket's unlinked value, warned;
* nothing linked to Surface, or no output: black, as in Cycles;
* a material without a node tree uses ``diffuse_color``, as Cycles does.

Each material gets at most one warning line listing everything ignored in it.
Colours are linear, in the scene's working colour space.
"""
from __future__ import annotations

import math

from mcengine.kernels.svm.nodes import INPUTS
from mcengine.scene import Link, Material, ShaderNode

__all__ = ["DEFAULT_SURFACE", "MaterialTable", "convert_material", "linked_node", "clamp_color", "fmt"]

# Cycles' default surface for objects without material and for empty slots.
DEFAULT_GREY = (0.8, 0.8, 0.8)
DEFAULT_SURFACE = Material(name="default surface", base_color=DEFAULT_GREY)
BLACK = (0.0, 0.0, 0.0)

# Blender node types -> the graph's node types (the Glossy BSDF is
# ShaderNodeBsdfAnisotropic since Blender 4.0).
_NODE_TYPES = {
    "ShaderNodeBsdfPrincipled": "BsdfPrincipled", "ShaderNodeBsdfDiffuse": "BsdfDiffuse",
    "ShaderNodeBsdfAnisotropic": "BsdfGlossy", "ShaderNodeBsdfGlossy": "BsdfGlossy",
    "ShaderNodeBsdfGlass": "BsdfGlass", "ShaderNodeBsdfRefraction": "BsdfRefraction",
    "ShaderNodeBsdfTranslucent": "BsdfTranslucent", "ShaderNodeBsdfTransparent": "BsdfTransparent",
    "ShaderNodeBsdfSheen": "BsdfSheen", "ShaderNodeEmission": "Emission",
    "ShaderNodeHoldout": "Holdout", "ShaderNodeMixShader": "MixShader",
    "ShaderNodeAddShader": "AddShader",
}
_ROUTING_INPUTS = {"MixShader": ("Fac", "Shader", "Shader_001"), "AddShader": ("Shader", "Shader_001")}
_THIN_FILM_CUTOFF = 0.1


class MaterialTable:
    """De-duplicated list of exported materials; index 0 is the default surface.

    Parameters
    ----------
    ctx : ExportContext
        Receives the material warnings.
    """

    def __init__(self, ctx):
        self._ctx = ctx
        self.materials = [DEFAULT_SURFACE]
        self._index = {None: 0}

    def index(self, material) -> int:
        """Index of a Blender material (None: the default surface), converting it once."""
        key = None if material is None else material.name_full
        if key not in self._index:
            self._index[key] = len(self.materials)
            self.materials.append(convert_material(self._ctx, material))
        return self._index[key]


def convert_material(ctx, material) -> Material:
    """Convert one Blender material; unsupported parts become one warning in ``ctx``."""
    name = material.name
    settings = dict(use_transparent_shadow=bool(getattr(material, "use_transparent_shadow", True)),
                    use_bump_map_correction=bool(getattr(getattr(material, "cycles", None),
                                                         "use_bump_map_correction", True)))
    tree = material.node_tree
    if tree is None:
        return Material(name=name, base_color=clamp_color(material.diffuse_color[:3]), **settings)
    out = tree.get_output_node("CYCLES")
    if out is None:
        return Material(name=name, base_color=BLACK, **settings)
    graph = _Graph()
    for socket_name, what in (("Volume", "volume"), ("Displacement", "displacement")):
        src = linked_node(out.inputs[socket_name])
        if src is not None:
            graph.note(f"{what} ({_label(src)})", what)
    surface = graph.shader(out.inputs["Surface"])
    if surface is None:
        result = Material(name=name, base_color=BLACK, **settings)
    else:
        result = Material(name=name, nodes=graph.nodes, surface=surface, **settings)
    if graph.items:
        ctx.warn(f"material '{name}': {', '.join(graph.items)} not supported yet; "
                 f"{'; '.join(graph.fallbacks) or 'ignored'}", *graph.features)
    return result


class _Graph:
    """The shader graph being copied from one Blender material, and what it ignores."""

    def __init__(self):
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

    def shader(self, socket) -> Link | None:
        """The link a shader socket receives (None: nothing, black)."""
        source = linked_socket(socket)
        if source is None:
            return None
        node = source.node
        key = node.as_pointer()
        if key not in self._index:
            self._index[key] = None     # a cycle through this node finds nothing
            index = len(self.nodes)
            self.nodes.append(ShaderNode(type="", name=node.name))
            self.nodes[index] = self._convert(node)
            self._index[key] = index
        index = self._index[key]
        if index is None:
            self.note(f"{_label(node)} (a shader cycle)", "shader nodes")
            return None
        return Link(index, "Shader" if self.nodes[index].type in _ROUTING_INPUTS else "BSDF")

    # -- one node -------------------------------------------------------------------------------
    def _convert(self, node) -> ShaderNode:
        kind = node.bl_idname
        if kind == "ShaderNodeBsdfMetallic":
            return self._metallic(node)
        if kind == "ShaderNodeSubsurfaceScattering":
            self.note(f"{_label(node)} (subsurface scattering)", "subsurface",
                      f"{_label(node)} rendered as diffuse of its colour")
            return ShaderNode("BsdfDiffuse", {"Color": self._value(node, "Color", 3)}, name=node.name)
        mapped = _NODE_TYPES.get(kind)
        if mapped is None:
            self.note(f"{_label(node)} surface shader", "shader nodes",
                      f"{_label(node)} rendered as 0.8 grey diffuse")
            return ShaderNode("BsdfDiffuse", {"Color": DEFAULT_GREY}, name=node.name)
        if mapped in _ROUTING_INPUTS:
            inputs = {}
            for ident in _ROUTING_INPUTS[mapped]:
                sock = node.inputs[ident]
                if sock.type == "SHADER":
                    link = self.shader(sock)
                    if link is not None:
                        inputs[ident] = link
                else:
                    inputs[ident] = self._value(node, ident, 1)
            return ShaderNode(mapped, inputs, name=node.name)
        inputs = {}
        for ident, size, _default in INPUTS[mapped]:
            if not ident.startswith("prop:"):
                inputs[ident] = self._value(node, ident, size)
        props = {}
        if any(ident == "prop:distribution" for ident, _size, _default in INPUTS[mapped]):
            props["distribution"] = self._distribution(node)
        if mapped == "BsdfSheen" and node.distribution == "ASHIKHMIN":
            self.note(f"{_label(node)} Ashikhmin velvet sheen", "velvet sheen",
                      "microfibre sheen used")
        self._check(node, mapped, inputs)
        return ShaderNode(mapped, inputs, props, name=node.name)

    def _value(self, node, ident, size):
        """The unlinked value of an input (a linked non-shader input is noted)."""
        sock = node.inputs[ident]
        src = linked_node(sock)
        if src is not None:
            self.note(f"{_label(src)} into {_label(node)} '{sock.name}'", "textures",
                      f"unlinked value of {_label(node)} '{sock.name}' used")
        value = sock.default_value
        if size == 1:
            return float(value)
        values = [float(v) for v in value[:3]]
        return tuple(values)

    def _distribution(self, node) -> str:
        dist = node.distribution
        if dist == "ASHIKHMIN_SHIRLEY":
            self.note(f"{_label(node)} Ashikhmin-Shirley distribution", "ashikhmin-shirley",
                      "GGX used")
            return "GGX"
        return dist

    def _check(self, node, kind, inputs) -> None:
        """Note what the closure model renders differently from Cycles."""
        label = _label(node)
        tangent = inputs.get("Tangent")
        aniso = inputs.get("Anisotropic", inputs.get("Anisotropy", 0.0))
        if aniso and (tangent is None or not any(tangent)):
            self.note(f"{label} anisotropy along the default (radial) tangent", "anisotropy",
                      f"{label} rendered isotropic")
        if inputs.get("Thin Film Thickness", 0.0) > _THIN_FILM_CUTOFF:
            self.note(f"{label} thin film", "thin film", "thin-film interference ignored")
        if kind == "BsdfPrincipled" and inputs["Subsurface Weight"] > 0.0:
            self.note(f"{label} subsurface weight {fmt(inputs['Subsurface Weight'])}", "subsurface",
                      "subsurface rendered as diffuse of the base colour (Cycles' zero-radius limit)")

    def _metallic(self, node) -> ShaderNode:
        """Metallic BSDF as the Principled at Metallic 1: the same F82-tint conductor."""
        inputs = {"Metallic": 1.0, "Roughness": self._value(node, "Roughness", 1),
                  "Anisotropic": min(max(self._value(node, "Anisotropy", 1), 0.0), 1.0),
                  "Anisotropic Rotation": self._value(node, "Rotation", 1),
                  "Normal": self._value(node, "Normal", 3), "Tangent": self._value(node, "Tangent", 3),
                  "Thin Film Thickness": self._value(node, "Thin Film Thickness", 1)}
        if node.fresnel_type == "F82":
            inputs["Base Color"] = self._value(node, "Base Color", 3)
            inputs["Specular Tint"] = self._value(node, "Edge Tint", 3)
        else:
            n = self._value(node, "IOR", 3)
            k = self._value(node, "Extinction", 3)
            f0 = [_conductor_fresnel(1.0, a, b) for a, b in zip(n, k)]
            f82 = [_conductor_fresnel(1.0 / 7.0, a, b) for a, b in zip(n, k)]
            schlick = [f + (1.0 - f) * (6.0 / 7.0) ** 5 for f in f0]
            inputs["Base Color"] = tuple(f0)
            inputs["Specular Tint"] = tuple(min(a / b, 1.0) if b > 0 else 1.0 for a, b in zip(f82, schlick))
            self.note(f"{_label(node)} physical conductor Fresnel", "conductor fresnel",
                      "fitted to the F82-tint model")
        node_out = ShaderNode("BsdfPrincipled", inputs, {"distribution": self._distribution(node)},
                              name=node.name)
        self._check(node, "BsdfPrincipled", {**inputs, "Subsurface Weight": 0.0})
        return node_out


def _conductor_fresnel(cos_i, n, k) -> float:
    """Unpolarised reflectance of a conductor of complex IOR n + ik (from air)."""
    c2 = cos_i * cos_i
    s2 = 1.0 - c2
    t0 = n * n - k * k - s2
    a2b2 = math.sqrt(t0 * t0 + 4.0 * n * n * k * k)
    a = math.sqrt(max(0.5 * (a2b2 + t0), 0.0))
    t1 = a2b2 + c2
    t2 = 2.0 * a * cos_i
    rs = (t1 - t2) / (t1 + t2)
    t3 = c2 * a2b2 + s2 * s2
    t4 = t2 * s2
    rp = rs * (t3 - t4) / (t3 + t4)
    return 0.5 * (rs + rp)


def linked_socket(socket):
    """The output socket feeding ``socket`` through reroutes, unmuted links and muted
    nodes (which pass their first matching input through, as in Blender), or None."""
    for _ in range(256):
        if not socket.is_linked:
            return None
        links = [link for link in socket.links if not link.is_muted]
        if not links:
            return None
        source = links[0].from_socket
        node = source.node
        if node.bl_idname == "NodeReroute":
            socket = node.inputs[0]
        elif node.mute:
            through = [lk.from_socket for lk in node.internal_links if lk.to_socket == source]
            if not through:
                return None
            socket = through[0]
        else:
            return source
    return None


def linked_node(socket):
    """The node feeding ``socket`` (see :func:`linked_socket`), or None."""
    source = linked_socket(socket)
    return source.node if source is not None else None


def _label(node) -> str:
    return node.label or node.name


def clamp_color(values) -> tuple:
    """Negative components -> 0 (the core wants non-negative colours)."""
    return tuple(max(float(v), 0.0) for v in values)


def fmt(value) -> str:
    """A number or a colour with 3 significant digits, for messages."""
    if isinstance(value, (tuple, list)):
        return "(" + ", ".join(f"{v:.3g}" for v in value) + ")"
    return f"{value:.3g}"
