"""Blender materials -> :class:`mcengine.scene.Material` (a graph of shader nodes).

The graph is what the Surface socket of the material's active Cycles output
(``node_tree.get_output_node('CYCLES')``) receives, copied by
:class:`shader_graph.GraphReader` (reroutes, muted links and nodes, node
groups; every node the core evaluates, with its inputs and properties).  On
top of that, materials translate a few shader nodes the core renders through
others:

* any other shader node: 0.8 grey diffuse, warned;
* nothing linked to Surface, or no output: black, as in Cycles;
* a material without a node tree uses ``diffuse_color``, as Cycles does.

Each material gets at most one warning line listing everything ignored in it.
Colours are linear, in the scene's working colour space.
"""
from __future__ import annotations

from mcengine.kernels.svm.nodes import Socket
from mcengine.scene import Link, Material, ShaderNode
from mcengine.shaders import GEOMETRY_ATTRIBUTES, VERTEX_NORMAL_ATTRIBUTE, truly_displaced

from .shader_graph import GraphReader, label, source

__all__ = ["DEFAULT_SURFACE", "MaterialTable", "convert_material", "linked_node", "clamp_color", "fmt"]

# What objects without material and empty slots render with: in Blender 5.0 Cycles renders
# them as a default Principled BSDF (measured: the same pixels bit for bit), not as the
# 0.8 grey diffuse of its own default_surface shader.
DEFAULT_SURFACE = Material(name="default surface", nodes=[ShaderNode("BsdfPrincipled")],
                           surface=Link(0, "BSDF"))
BLACK = (0.0, 0.0, 0.0)


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
        self._attributes = _attributes_read(DEFAULT_SURFACE)    # by the materials so far

    def attribute_names(self) -> set:
        """Names of the attributes the materials converted so far read: those of Attribute
        nodes, and those derived from the mesh that a Geometry node's output reads
        (``GEOMETRY_ATTRIBUTES``); with true displacement, the vertex normals
        (``VERTEX_NORMAL_ATTRIBUTE``).  Gathered as each material is converted (asked
        per mesh, a scan of every material took 1 ms per mesh with 300 materials)."""
        return set(self._attributes)

    def tangent_maps(self, indices) -> set:
        """UV maps whose tangents the materials at ``indices`` read (Normal Map and Vector
        Displacement nodes in tangent space, the latter the default UV map's; Tangent nodes
        along a UV map; "" is the default UV map)."""
        return {str(node.props.get("uv_map", "")) for i in set(indices) for node in self.materials[i].nodes
                if node.type in ("NormalMap", "VectorDisplacement")
                and str(node.props.get("space", "TANGENT")) == "TANGENT"
                or node.type == "Tangent" and str(node.props.get("direction_type")) == "UV_MAP"}

    def index(self, material) -> int:
        """Index of a Blender material (None: the default surface), converting it once."""
        key = None if material is None else material.name_full
        if key not in self._index:
            self._index[key] = len(self.materials)
            converted = convert_material(self._ctx, material)
            self.materials.append(converted)
            self._attributes |= _attributes_read(converted)
        return self._index[key]


def _attributes_read(m: Material) -> set:
    """The attributes material ``m`` reads (see ``MaterialTable.attribute_names``)."""
    names = {VERTEX_NORMAL_ATTRIBUTE} if truly_displaced(m) else set()
    for node in m.nodes:
        if node.type == "Attribute":
            names.add(str(node.props.get("attribute_name", "")))
        for value in node.inputs.values():
            if (isinstance(value, Link) and value.socket in GEOMETRY_ATTRIBUTES
                    and m.nodes[value.node].type == "NewGeometry"):
                names.add(GEOMETRY_ATTRIBUTES[value.socket])
    return names


def convert_material(ctx, material) -> Material:
    """Convert one Blender material; unsupported parts become one warning in ``ctx``."""
    name = material.name
    settings = dict(use_transparent_shadow=bool(getattr(material, "use_transparent_shadow", True)),
                    use_bump_map_correction=bool(getattr(getattr(material, "cycles", None),
                                                         "use_bump_map_correction", True)),
                    pass_index=int(getattr(material, "pass_index", 0)))
    tree = material.node_tree
    if tree is None:
        return Material(name=name, base_color=clamp_color(material.diffuse_color[:3]), **settings)
    out = tree.get_output_node("CYCLES")
    if out is None:
        return Material(name=name, base_color=BLACK, **settings)
    graph = _MaterialGraph(ctx)
    graph.pass_index = float(getattr(material, "pass_index", 0))
    src = linked_node(out.inputs["Volume"])
    if src is not None:
        graph.note(f"volume ({label(src)})", "volume")
    surface = graph.shader(out.inputs["Surface"])
    displacement = _displacement(graph, material, out)
    if surface is None:
        result = Material(name=name, base_color=BLACK, **settings)
    else:
        result = Material(name=name, nodes=graph.nodes, surface=surface, displacement=displacement,
                          displacement_method=str(material.displacement_method), **settings)
    if graph.items:
        ctx.warn(f"material '{name}': {', '.join(graph.items)} not supported yet; "
                 f"{'; '.join(graph.fallbacks) or 'ignored'}", *graph.features)
    return result


def surface_graph(ctx, socket, constants=None) -> Material | None:
    """The shader graph feeding ``socket`` (a lamp's output Surface) as a material of that
    graph; None when nothing feeds it or it holds nodes MC Engine does not evaluate.
    ``constants``: nodes read as constants (``GraphReader``)."""
    graph = _MaterialGraph(ctx, constants)
    surface = graph.shader(socket)
    if surface is None or graph.items:
        return None
    return Material(nodes=graph.nodes, surface=surface)


def _displacement(graph, material, out):
    """What the output's Displacement receives (a Link, else None): Cycles' bump from
    displacement (method 'BUMP'), true displacement of the mesh ('DISPLACEMENT',
    ``mcengine.displacement``) or both ('BOTH').  A tangent-space Normal Map on a surface
    whose normals displacement recomputed uses the new normal, where Cycles uses the
    undisplaced one: warned."""
    socket = out.inputs["Displacement"]
    src = linked_node(socket)
    if src is None:
        return None
    method = str(getattr(material, "displacement_method", "BUMP"))
    if method == "DISPLACEMENT" and any(n.type == "NormalMap" and n.props.get("space", "TANGENT") == "TANGENT"
                                        for n in graph.nodes):
        graph.note("tangent-space Normal Map on a displaced surface", "displacement",
                   "it perturbs the displaced normal, not the undisplaced one")
    link = graph.input(out, socket, Socket("Displacement", "vector", None), ())
    return link if isinstance(link, Link) else None


class _MaterialGraph(GraphReader):
    """A material's graph: the generic copy, plus the shader nodes rendered through others."""

    pass_index = 0.0      # the material's pass index (Object Info's Material Index)

    def convert(self, node, groups) -> ShaderNode:
        copied = super().convert(node, groups)
        if copied.type == "ObjectInfo":
            copied.props["material_index"] = self.pass_index
        return copied


def linked_node(socket):
    """The node feeding ``socket`` (through reroutes, muted nodes and links and node groups,
    as :func:`shader_graph.source` follows them), or None."""
    out, _groups = source(socket)
    return out.node if out is not None else None


def clamp_color(values) -> tuple:
    """Negative components -> 0 (the core wants non-negative colours)."""
    return tuple(max(float(v), 0.0) for v in values)


def fmt(value) -> str:
    """A number or a colour with 3 significant digits, for messages."""
    if isinstance(value, (tuple, list)):
        return "(" + ", ".join(f"{v:.3g}" for v in value) + ")"
    return f"{value:.3g}"
