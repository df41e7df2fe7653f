"""Blender materials -> :class:`mcengine.scene.Material` (a sum of closures).

The shader read is the node linked to the Surface socket of the material's
active output for Cycles (``node_tree.get_output_node('CYCLES')``, target ALL
or CYCLES), following reroutes and skipping muted links.

* Principled BSDF: base colour = 'Base Color' (clamped >= 0), emission =
  'Emission Color' x 'Emission Strength'.  Exact when 'Specular IOR Level',
  Metallic, Transmission, Coat, Sheen, Subsurface and Diffuse Roughness are 0
  and Alpha is 1; anything else is named in the material's warning.
* Diffuse BSDF: 'Color'; Roughness > 0 is Oren-Nayar in Cycles (warned, Lambert used).
* Emission: radiance 'Color' x 'Strength', no diffuse reflection.
* Glossy, Glass and Refraction BSDFs: a mirror, a smooth dielectric and a
  smooth refraction lobe with the node's Color (and IOR); exact at Roughness
  0, rendered sharp (and warned) otherwise.
* Mix Shader and Add Shader: the closures of their inputs, weighted by the
  mix factor or summed, as Cycles sums closures.
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
    closures = _Closures()
    shader = linked_node(out.inputs["Surface"])
    if shader is not None:
        _shader(shader, 1.0, closures, notes, depth=0)
    result = closures.material(name, notes)
    if notes.items:
        ctx.warn(f"material '{name}': {', '.join(notes.items)} not supported yet; "
                 f"{_fallback_text(result, notes)}", *notes.features)
    return result


class _Closures:
    """The sum of closures a shader tree evaluates to, each scaled by its mix weight."""

    LOBES = ("base_color", "mirror_color", "glass_color", "refraction_color", "emission")

    def __init__(self):
        self.colors = {k: [0.0, 0.0, 0.0] for k in self.LOBES}
        self.ior = None

    def add(self, lobe, weight, color):
        acc = self.colors[lobe]
        for c in range(3):
            acc[c] += weight * max(float(color[c]), 0.0)

    def set_ior(self, ior, notes, node):
        if self.ior is None:
            self.ior = float(ior)
        elif abs(self.ior - float(ior)) > 1e-6:
            notes.add(f"{_label(node)} IOR {fmt(ior)} (a second IOR in one material; "
                      f"{fmt(self.ior)} used)", "several IORs")

    def material(self, name, notes) -> Material:
        kw = {k: tuple(v) for k, v in self.colors.items()}
        return Material(name=name, ior=self.ior if self.ior is not None else 1.5, **kw)


_MAX_SHADER_DEPTH = 32
# Glossy BSDF is ShaderNodeBsdfAnisotropic since Blender 4.0 (merged nodes).
_SHARP_LOBES = {"ShaderNodeBsdfAnisotropic": "mirror_color", "ShaderNodeBsdfGlossy": "mirror_color",
                "ShaderNodeBsdfGlass": "glass_color", "ShaderNodeBsdfRefraction": "refraction_color"}


def _shader(node, weight, closures, notes, depth):
    """Add the closures of shader ``node`` times ``weight`` to ``closures``."""
    if weight <= 0.0:
        return
    kind = node.bl_idname
    if depth > _MAX_SHADER_DEPTH:
        notes.add(f"{_label(node)} (shader tree deeper than {_MAX_SHADER_DEPTH})", "shader nodes")
    elif kind == "ShaderNodeBsdfPrincipled":
        _principled(node, weight, closures, notes)
    elif kind == "ShaderNodeBsdfDiffuse":
        _diffuse(node, weight, closures, notes)
    elif kind == "ShaderNodeEmission":
        closures.add("emission", weight, _emission(node, "Color", "Strength", notes))
        _note_other_links(node, ("Color", "Strength"), notes)
    elif kind in _SHARP_LOBES:
        _sharp(node, weight, closures, notes)
    elif kind == "ShaderNodeMixShader":
        fac_socket = node.inputs[0]
        _note_link(node, fac_socket, notes)
        fac = min(max(float(fac_socket.default_value), 0.0), 1.0)
        for sock, w in ((node.inputs[1], 1.0 - fac), (node.inputs[2], fac)):
            src = linked_node(sock)
            if src is not None:
                _shader(src, weight * w, closures, notes, depth + 1)
    elif kind == "ShaderNodeAddShader":
        for sock in node.inputs:
            src = linked_node(sock)
            if src is not None:
                _shader(src, weight, closures, notes, depth + 1)
    else:
        notes.add(f"{_label(node)} surface shader", "shader nodes")
        notes.grey_fallback = True
        closures.add("base_color", weight, DEFAULT_GREY)


def _principled(node, weight, closures, notes):
    for socket_name, feature, neutral in _PRINCIPLED_LOBES:
        sock = node.inputs[socket_name]
        if linked_node(sock) is None and sock.default_value != neutral:
            value = fmt(sock.default_value)
            notes.add(f"Principled BSDF specular layer ({socket_name} {value})"
                      if feature == "specular" else f"{socket_name} {value}", feature)
    closures.add("base_color", weight, _color(node, "Base Color", notes))
    closures.add("emission", weight, _emission(node, "Emission Color", "Emission Strength", notes))
    _note_other_links(node, ("Base Color", "Emission Color", "Emission Strength"), notes)


def _diffuse(node, weight, closures, notes):
    rough = node.inputs["Roughness"]
    if linked_node(rough) is None and rough.default_value > 0:
        notes.add(f"Diffuse BSDF Roughness {fmt(rough.default_value)} (Oren-Nayar)", "rough diffuse")
    closures.add("base_color", weight, _color(node, "Color", notes))
    _note_other_links(node, ("Color",), notes)


def _sharp(node, weight, closures, notes):
    """Glossy, Glass and Refraction BSDFs; exact at Roughness 0 (singular lobes)."""
    lobe = _SHARP_LOBES[node.bl_idname]
    rough = node.inputs["Roughness"]
    if linked_node(rough) is not None or rough.default_value > 0:
        value = "linked" if linked_node(rough) is not None else fmt(rough.default_value)
        notes.add(f"{_label(node)} Roughness {value}", "rough glossy")
        notes.sharpened = True
    closures.add(lobe, weight, _color(node, "Color", notes))
    read = ["Color", "Roughness"]
    if "IOR" in node.inputs:
        ior = node.inputs["IOR"]
        _note_link(node, ior, notes)
        closures.set_ior(ior.default_value, notes, node)
        read.append("IOR")
    film = node.inputs.get("Thin Film Thickness")
    if film is not None and linked_node(film) is None and film.default_value > 0:
        notes.add(f"{_label(node)} Thin Film Thickness {fmt(film.default_value)}", "thin film")
    _note_other_links(node, tuple(read), notes)


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
        self.grey_fallback = False      # an unsupported shader became grey diffuse
        self.sharpened = False          # a rough glossy/glass was rendered sharp

    def add(self, item: str, feature: str) -> None:
        if item not in self.items:
            self.items.append(item)
        if feature not in self.features:
            self.features.append(feature)


def _fallback_text(m: Material, notes: _Notes) -> str:
    parts = []
    if max(m.base_color) > 0:
        parts.append(f"Lambert diffuse with base colour {fmt(m.base_color)}")
    for attr, what in (("mirror_color", "a sharp mirror"), ("glass_color", "sharp glass"),
                       ("refraction_color", "sharp refraction")):
        if max(getattr(m, attr)) > 0:
            parts.append(f"{what} of colour {fmt(getattr(m, attr))}")
    if max(m.emission) > 0:
        parts.append(f"emission {fmt(m.emission)}")
    text = "rendered as " + (" and ".join(parts) if parts else "black")
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
