"""Blender materials -> :class:`mcengine.scene.Material` (Lambert diffuse + emission).

The shader read is the node linked to the Surface socket of the material's
active output for Cycles (``node_tree.get_output_node('CYCLES')``, target ALL
or CYCLES), following reroutes and skipping muted links.

* Principled BSDF: base colour = 'Base Color' (clamped >= 0), emission =
  'Emission Color' x 'Emission Strength'.  Exact when 'Specular IOR Level',
  Metallic, Transmission, Coat, Sheen, Subsurface and Diffuse Roughness are 0
  and Alpha is 1; anything else is named in the material's warning.
* Diffuse BSDF: 'Color'; Roughness > 0 is Oren-Nayar in Cycles (warned, Lambert used).
* Emission: radiance 'Color' x 'Strength', no diffuse reflection.
* Nothing linked to Surface, or no output: black, as in Cycles.
* Any other surface node: 0.8 grey diffuse (Cycles' default surface), warned.
* A linked input (a texture, a node group, ...) is replaced by the socket's
  unlinked value, warned.
* A material without a node tree (files from before Blender 5.0, where
  ``use_nodes`` could be off) uses ``diffuse_color``, as Cycles does.

Each material gets at most one warning line listing everything ignored in it.
Colours are linear, in the scene's working colour space.
"""
from __future__ import annotations

from mcengine.scene import Material

__all__ = ["DEFAULT_SURFACE", "MaterialTable", "convert_material", "linked_node", "clamp_color", "fmt"]

# Cycles' default surface for objects without material and for empty slots.
DEFAULT_GREY = (0.8, 0.8, 0.8)
DEFAULT_SURFACE = Material(name="default surface", base_color=DEFAULT_GREY)
BLACK = (0.0, 0.0, 0.0)

# Principled BSDF inputs that add lobes the Lambert core does not have yet:
# (socket name, short feature name, value at which the lobe vanishes).
_PRINCIPLED_LOBES = (
    ("Specular IOR Level", "specular", 0.0),
    ("Metallic", "metallic", 0.0),
    ("Transmission Weight", "transmission", 0.0),
    ("Coat Weight", "coat", 0.0),
    ("Sheen Weight", "sheen", 0.0),
    ("Subsurface Weight", "subsurface", 0.0),
    ("Diffuse Roughness", "rough diffuse", 0.0),
    ("Thin Film Thickness", "thin film", 0.0),
    ("Alpha", "alpha", 1.0),
)


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
    tree = material.node_tree
    if tree is None:
        return Material(name=name, base_color=clamp_color(material.diffuse_color[:3]))
    out = tree.get_output_node("CYCLES")
    if out is None:
        return Material(name=name, base_color=BLACK)
    notes = _Notes()
    for socket_name, what in (("Volume", "volume"), ("Displacement", "displacement")):
        src = linked_node(out.inputs[socket_name])
        if src is not None:
            notes.add(f"{what} ({_label(src)})", what)
    shader = linked_node(out.inputs["Surface"])
    if shader is None:
        result = Material(name=name, base_color=BLACK)
    elif shader.bl_idname == "ShaderNodeBsdfPrincipled":
        result = _principled(name, shader, notes)
    elif shader.bl_idname == "ShaderNodeBsdfDiffuse":
        result = _diffuse(name, shader, notes)
    elif shader.bl_idname == "ShaderNodeEmission":
        result = Material(name=name, base_color=BLACK,
                          emission=_emission(shader, "Color", "Strength", notes))
    else:
        notes.add(f"{_label(shader)} surface shader", "shader nodes")
        result = Material(name=name, base_color=DEFAULT_GREY)
    if notes.items:
        ctx.warn(f"material '{name}': {', '.join(notes.items)} not supported yet; "
                 f"{_fallback_text(result, notes)}", *notes.features)
    return result


def _principled(name, node, notes) -> Material:
    for socket_name, feature, neutral in _PRINCIPLED_LOBES:
        sock = node.inputs[socket_name]
        if linked_node(sock) is None and sock.default_value != neutral:
            value = fmt(sock.default_value)
            notes.add(f"Principled BSDF specular layer ({socket_name} {value})"
                      if feature == "specular" else f"{socket_name} {value}", feature)
    base = _color(node, "Base Color", notes)
    emission = _emission(node, "Emission Color", "Emission Strength", notes)
    _note_other_links(node, ("Base Color", "Emission Color", "Emission Strength"), notes)
    return Material(name=name, base_color=base, emission=emission)


def _diffuse(name, node, notes) -> Material:
    rough = node.inputs["Roughness"]
    if linked_node(rough) is None and rough.default_value > 0:
        notes.add(f"Diffuse BSDF Roughness {fmt(rough.default_value)} (Oren-Nayar)", "rough diffuse")
    base = _color(node, "Color", notes)
    _note_other_links(node, ("Color",), notes)
    return Material(name=name, base_color=base)


def _color(node, socket_name, notes) -> tuple:
    sock = node.inputs[socket_name]
    _note_link(node, sock, notes)
    return clamp_color(sock.default_value[:3])


def _emission(node, color_name, strength_name, notes) -> tuple:
    color = node.inputs[color_name]
    strength = node.inputs[strength_name]
    _note_link(node, color, notes)
    _note_link(node, strength, notes)
    return clamp_color([c * strength.default_value for c in color.default_value[:3]])


def _note_link(node, sock, notes) -> None:
    src = linked_node(sock)
    if src is not None:
        notes.add(f"{_label(src)} into {_label(node)} '{sock.name}'", "textures")
        notes.unlinked.append(sock.name)


def _note_other_links(node, read, notes) -> None:
    """Linked inputs the conversion does not read (Normal, Roughness, ...) are ignored."""
    for sock in node.inputs:
        if sock.enabled and sock.name not in read and linked_node(sock) is not None:
            notes.add(f"{_label(linked_node(sock))} into {_label(node)} '{sock.name}'", "textures")


class _Notes:
    """Unsupported things found in one material, for its single warning line."""

    def __init__(self):
        self.items: list[str] = []
        self.features: list[str] = []
        self.unlinked: list[str] = []   # read sockets replaced by their unlinked values

    def add(self, item: str, feature: str) -> None:
        if item not in self.items:
            self.items.append(item)
        if feature not in self.features:
            self.features.append(feature)


def _fallback_text(m: Material, notes: _Notes) -> str:
    if max(m.base_color) > 0 or max(m.emission) == 0:
        text = f"rendered as Lambert diffuse with base colour {fmt(m.base_color)}"
        if max(m.emission) > 0:
            text += f" and emission {fmt(m.emission)}"
    else:
        text = f"rendered as emission {fmt(m.emission)}"
    if notes.unlinked:
        names = ", ".join(f"'{n}'" for n in notes.unlinked)
        text += f" (unlinked value of {names})"
    return text


def linked_node(socket):
    """The node feeding ``socket`` through reroutes and unmuted links, or None."""
    while socket.is_linked:
        links = [link for link in socket.links if not link.is_muted]
        if not links:
            return None
        node = links[0].from_node
        if node.bl_idname != "NodeReroute":
            return node
        socket = node.inputs[0]
    return None


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
