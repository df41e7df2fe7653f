"""Shader compiler: a material's node graph -> a program for the shader evaluator.

A material is a graph of shader nodes (``scene.Material.graph()``).  The
compiler walks it from the output's Surface socket, as Cycles' SVM compiler
does (scene/shader_graph.cpp, svm.cpp), and emits a straight-line program for
``kernels.svm.eval_shader``:

* every node reached gets a block of registers holding its inputs in the
  order of ``kernels.svm.nodes``; constant inputs are written there once per
  render (``ShaderTable.registers``), a linked input is copied (``OP_COPY``)
  or converted (``OP_CONVERT``: colour -> float is the luminance, vector ->
  float the mean, float -> vector or colour (f, f, f)) from its source's
  output registers before the node runs;
* a value node (textures, maths, coordinates) runs once per point however
  many inputs it feeds (``OP_NODE``) and writes its outputs to registers;
  a node whose inputs are all constant and that reads nothing of the point
  is evaluated here, ahead of time, and becomes constants (constant folding);
  a texture's unlinked Vector input gets the coordinate Cycles uses (a
  Texture Coordinate node's Generated or UV output);
* a Bump node's Height sub-graph is emitted three times, as Cycles does
  (shader_graph.cpp refine_bump_nodes): at the point, and between ``OP_BUMP``
  rows that move the point along dPdx, then dPdy, by the node's Filter Width
  (a fresh copy of every node on the way, texture coordinates included); the
  material output's Displacement (method 'BUMP', or 'BOTH' without its true
  displacement) becomes Cycles' automatic bump (bump_from_displacement): its
  vector dotted with the normal is the height of a Bump node of Distance 1
  whose normal replaces the shading normal (``BUMP_SET_NORMAL``) before the
  surface's nodes run;
* a closure node builds its closures (``OP_CLOSURE``); a Mix Shader computes
  the weights of its two inputs from its factor (``OP_MIX_WEIGHT``: in x
  (1 - fac) and in x fac), an Add Shader passes its weight to both; a closure
  node's weight register holds the product of the factors on its way to the
  output (none: weight 1).

Programs are plain int32/float64 arrays, so a saved scene renders without
Blender and the kernels see one format for every material.  Attributes are
found by name in an :class:`AttributeLayout` (the scene's per-corner
attributes: UV maps, colour attributes); a missing one reads as zeros, as in
Cycles.  Images are found by name in the render's image slots
(``images.ImageTable.slots``); a missing one reads magenta, as in Cycles.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import sky
from .kernels.camera import CAMERA_PARAMS
from .kernels.closures.layout import CL_STRIDE, CLOSURE_WEIGHT_CUTOFF, MAX_CLOSURES
from .kernels.state import (
    MF_BSSRDF_BUMP,
    MF_BUMP_CORRECTION,
    MF_CLOSURES_ONLY,
    MF_EMISSION_VARIES,
    MF_EMISSIVE,
    MF_TRANSPARENT,
)
from .kernels.subsurface import no_local_bvh
from .kernels.svm import (
    BUMP_CENTER,
    BUMP_DX,
    BUMP_DY,
    BUMP_LEAVE,
    BUMP_SET_NORMAL,
    BUMP_UNDISPLACED,
    CONV_COLOR_TO_FLOAT,
    CONV_FLOAT_TO_VECTOR,
    CONV_VECTOR_TO_FLOAT,
    IMG_STRIDE,
    MAX_REGS,
    OBJ_STRIDE,
    OP_BUMP,
    OP_CLOSURE,
    OP_CONVERT,
    OP_COPY,
    OP_MIX_WEIGHT,
    OP_NODE,
    RGB_TO_Y,
    ShaderScene,
    ShadingData,
    TextureData,
    closures_only,
    eval_shader_by_value,
    fold_node,
)
from .kernels.svm.bump import BS_SIZE
from .kernels.svm.nodes import (
    BUMP_HEIGHTS,
    CLOSURES,
    COLOR,
    ENUMS,
    FLOAT,
    IMAGE_NODES,
    IMPLICIT,
    MATRIX,
    SHADER,
    SHADER_ROUTING,
    SIZE,
    TABLE,
    TANGENT,
    TANGENT_PREFIX,
    UNLINKED,
    VALUE_NODES,
    VECTOR,
)
from .scene import Link, Material, SceneError, ShaderNode

__all__ = ["AttributeLayout", "DEFAULT_COLOR_ATTRIBUTE", "GEOMETRY_ATTRIBUTES", "Program", "compile_material",
           "compile_displacement", "truly_displaced", "ShaderTable"]

# The name under which a mesh's default colour attribute (Blender's render colour) is also
# stored: what a Color Attribute node with no name reads, as Cycles' ATTR_STD_VERTEX_COLOR.
DEFAULT_COLOR_ATTRIBUTE = ".default color"
# Geometry node outputs Cycles reads as attributes it derives from the mesh at sync
# (ATTR_STD_POINTINESS, ATTR_STD_RANDOM_PER_ISLAND): output -> the attribute's name, under
# which the export stores what mcengine.mesh_attributes computes for the meshes that need it.
GEOMETRY_ATTRIBUTES = {"Pointiness": ".pointiness", "Random Per Island": ".random per island"}
# Displacement methods whose displacement Cycles turns into a bump, and those that move the
# mesh's vertices (true displacement, ``mcengine.displacement``): 'BOTH' does both.
BUMP_METHODS = ("BUMP", "BOTH")
TRUE_DISPLACEMENT_METHODS = ("DISPLACEMENT", "BOTH")
# Per-corner attributes of truly displaced scenes: the object-space point and vertex normal
# before displacement (what the Texture Coordinate's Generated output reads there, as
# Cycles' generated attribute, and where Bump nodes evaluate their heights, as Cycles'
# undisplaced position and normal) and, from the export, each corner's object-space vertex
# normal and whether its face is smooth (the direction of displacement and how normals are
# recomputed after it).
UNDISPLACED_ATTRIBUTE = ".undisplaced"           # x, y, z and 1 on displaced meshes (else 0)
UNDISPLACED_NORMAL_ATTRIBUTE = ".undisplaced normal"   # object space: what bumps start from
VERTEX_NORMAL_ATTRIBUTE = ".vertex normal"
SMOOTH_ATTRIBUTE = ".smooth"
NO_WEIGHT = -1      # weight register of a closure that reaches the output unmixed (weight 1)
# A closure's anisotropy input and the largest constant value at which the closure ignores
# its tangent (kernels/svm/closure_nodes.py, as Cycles' svm_node_closure_bsdf): the implicit
# tangent is only computed where it is used.
_ANISOTROPY = {"BsdfPrincipled": ("Anisotropic", 0.0), "BsdfMetallic": ("Anisotropy", 0.0),
               "BsdfGlossy": ("Anisotropy", 1e-4)}
# Inputs whose constant values decide whether a closure node can emit or let light through.
_EMISSION_INPUTS = {"Emission": ("Color", "Strength"),
                    "BsdfPrincipled": ("Emission Color", "Emission Strength")}
_TRANSPARENCY_INPUTS = {"BsdfTransparent": ("Color",), "BsdfPrincipled": ("Alpha",)}


@dataclass
class AttributeLayout:
    """Where each per-corner attribute lives in the packed attribute array.

    ``offsets`` maps an attribute name to (first component, component count);
    the default UV map is at offset 0 under the name "" (two components).
    """

    offsets: dict = field(default_factory=lambda: {"": (0, 2)})

    def find(self, name: str) -> tuple[int, int]:
        """(offset, size) of an attribute; (-1, 0) when the scene has none of that name."""
        return self.offsets.get(name, (-1, 0))


def _known_outputs(node, values) -> dict:
    """Outputs of a node that does not fold whose value is known anyway: a Light Falloff
    without Smooth gives its Strength as Quadratic at every ray length (so that a lamp's node
    tree "Light Falloff > Quadratic" of a constant Strength folds and scales the lamp)."""
    if node.type == "LightFalloff" and values[1].constant and values[1].const[0] <= 0.0:
        return {"Quadratic": values[0]}
    return {}


@dataclass
class Value:
    """A socket's value at compile time: constants, or registers filled at run time."""

    type: str
    const: tuple | None = None     # the components when constant
    reg: int = -1                  # first register otherwise

    @property
    def constant(self) -> bool:
        return self.const is not None


@dataclass
class Program:
    """The compiled form of one material: rows, and the constants of its registers."""

    base: int = 0                                  # first register of this material
    ops: list = field(default_factory=list)        # [op, a, b, c] rows
    init: dict = field(default_factory=dict)       # register -> constant
    registers: int = 0                             # registers used
    emission_varies: bool = False                  # some emission input is not constant
    transparency_varies: bool = False              # some transparency input is not constant
    bssrdf_bump: bool = False                      # a BSSRDF's Normal input is linked

    def reg(self, n: int) -> int:
        """Allocate n consecutive registers; returns the first."""
        first = self.base + self.registers
        self.registers += n
        if self.base + self.registers > MAX_REGS:
            raise SceneError(f"the scene's shaders need more than {MAX_REGS} registers")
        return first

    def store(self, values) -> int:
        """Registers holding constants; returns the first."""
        values = [float(v) for v in values]
        first = self.reg(len(values))
        for k, v in enumerate(values):
            self.init[first + k] = v
        return first


def compile_material(material: Material, attributes: AttributeLayout | None = None,
                     base: int = 0, images: dict | None = None) -> Program:
    """Compile ``material`` from register ``base`` on (SceneError names an unsupported node,
    a bad link or a cycle); ``images`` maps image names to their slots."""
    return _Compiler(material, attributes or AttributeLayout(), base, images or {}).compile()


def truly_displaced(material: Material) -> bool:
    """Whether the material moves the vertices of its triangles (a linked Displacement, method
    'DISPLACEMENT' or 'BOTH')."""
    return (getattr(material, "displacement", None) is not None
            and material.displacement_method in TRUE_DISPLACEMENT_METHODS)


def compile_displacement(material: Material, attributes: AttributeLayout | None = None,
                         base: int = 0, images: dict | None = None) -> tuple[Program, int]:
    """The output's Displacement of a truly displaced material as value rows (no closures):
    the program and the first of the three registers its vector ends in."""
    return _Compiler(material, attributes or AttributeLayout(), base, images or {}).displacement()


class _Compiler:
    def __init__(self, material: Material, attributes: AttributeLayout, base: int, images: dict):
        self.material = material
        self.nodes, self.surface = material.graph()
        self.attributes = attributes
        self.images = images
        # Output sockets something is linked to, by node (Cycles computes an image's
        # unassociated colour only when its Alpha output is used).
        self.linked = {(v.node, v.socket) for n in self.nodes for v in n.inputs.values()
                       if isinstance(v, Link)}
        self.program = Program(base=base)
        self.outputs: dict[int, dict] = {}       # value node -> its outputs (name -> Value)
        self.implicit: dict[str, Value] = {}     # texture coordinates inserted for unlinked inputs
        self.path: tuple = ()
        self.undisplaced = False                 # compiling the bump of 'Displacement and Bump'

    def compile(self) -> Program:
        if self.surface is not None:
            displacement = getattr(self.material, "displacement", None)
            if displacement is not None and self.material.displacement_method in BUMP_METHODS:
                self.displacement_bump(displacement)
            self.shader(self.surface, NO_WEIGHT, False)
        return self.program

    def displacement(self) -> tuple[Program, int]:
        value = self.converted(self.output(self.material.displacement), VECTOR)
        reg = value.reg if not value.constant else self.program.store(value.const)
        return self.program, reg

    def displacement_bump(self, link: Link) -> None:
        """Cycles' automatic bump from the output's Displacement: a Bump node (Distance 1,
        Strength 1, the node's default filter width; in object space for method 'BOTH')
        whose Height is the displacement dotted with the Geometry node's Normal; its normal
        becomes the shading normal for the rest of the program."""
        header = len(self.program.ops)
        self.program.ops.append([OP_BUMP, BUMP_SET_NORMAL, 0, 0])     # completed below
        k = len(self.nodes)
        self.nodes = self.nodes + [
            ShaderNode("NewGeometry"),
            ShaderNode("VectorMath", {"Vector": link, "Vector_001": Link(k, "Normal")},
                       {"operation": "DOT_PRODUCT"}),
            ShaderNode("Bump", {"Height": Link(k + 1, "Value"), "Distance": 1.0, "Strength": 1.0},
                       {"use_object_space": float(self.material.displacement_method == "BOTH")})]
        # On a truly displaced mesh Cycles evaluates this bump, and only this one, at the
        # undisplaced point (svm_node_enter_bump_eval around it; user Bump nodes see P).
        self.undisplaced = True
        normal = self.output(Link(k + 2, "Normal"))
        self.undisplaced = False
        reg = normal.reg if not normal.constant else self.program.store(normal.const)
        self.program.ops[header] = [OP_BUMP, BUMP_SET_NORMAL, reg, len(self.program.ops) - header]
        # Nodes after this see the bumped normal: the surface compiles its own copies.
        self.outputs, self.implicit = {}, {}

    def bump_heights(self, node, spec, values) -> list:
        """A Bump node's inputs with its Height at the two offset points: the Height sub-graph
        again, fresh, between OP_BUMP rows (Filter Width: its unlinked value, as Cycles)."""
        names = [s.name for s in spec.inputs]
        k = names.index("Filter Width")
        width = values[k].const[0] if values[k].constant else spec.inputs[k].default
        values[k] = Value(FLOAT, (float(width),))
        centre, dx, dy = (names.index(h) for h in BUMP_HEIGHTS)
        height = node.inputs.get("Height")
        if not isinstance(height, Link) or values[centre].constant:
            values[dx] = values[dy] = values[centre]
            return values
        axes = ((BUMP_DX, dx), (BUMP_DY, dy))
        point, _size = self.attributes.find(UNDISPLACED_ATTRIBUTE)
        if point < 0 or not self.undisplaced:
            width_reg = self.program.store((width,))
        else:
            # The bump of 'Displacement and Bump' in a scene with true displacement: every
            # height at the undisplaced point (Cycles' svm_node_enter_bump_eval), the centre
            # too; the node's state block.
            normal, _size = self.attributes.find(UNDISPLACED_NORMAL_ATTRIBUTE)
            width_reg = self.program.store((width, point, normal) + (0.0,) * (BS_SIZE - 3))
            values[names.index("prop:state")] = Value(FLOAT, (float(width_reg),))
            axes = tuple((BUMP_UNDISPLACED + axis, i) for axis, i in ((BUMP_CENTER, centre),) + axes)
        for axis, i in axes:
            enter = len(self.program.ops)
            self.program.ops.append([OP_BUMP, axis, width_reg, 0])     # completed below
            saved = self.outputs, self.implicit
            self.outputs, self.implicit = {}, {}
            values[i] = self.converted(self.output(height), FLOAT)
            self.outputs, self.implicit = saved
            self.program.ops[enter][3] = len(self.program.ops) - enter
            self.program.ops.append([OP_BUMP, BUMP_LEAVE, 0, 0])
        return values

    def error(self, message: str) -> SceneError:
        return SceneError(f"material '{self.material.name}': {message}")

    # -- closures ---------------------------------------------------------------------------------
    def shader(self, link: Link, weight_reg: int, varies: bool) -> None:
        """Compile the closures ``link`` leads to, weighted by ``weight_reg``; ``varies``: that
        weight depends on the point (a Mix Shader factor on the way is linked)."""
        node = self.node(link)
        if node.type in SHADER_ROUTING:
            self.path += (link.node,)
            if node.type == "MixShader":
                fac = self.input(node, SHADER_ROUTING["MixShader"].inputs[0])
                varies = varies or not fac.constant
                fac_reg = fac.reg if not fac.constant else self.program.store(fac.const)
                out = self.program.reg(2)
                self.program.ops.append([OP_MIX_WEIGHT, fac_reg, weight_reg, out])
                weights = (out, out + 1)
            else:
                weights = (weight_reg, weight_reg)
            for name, w in zip(("Shader", "Shader_001"), weights):
                shader_in = node.inputs.get(name)
                if isinstance(shader_in, Link):
                    self.shader(shader_in, w, varies)
            self.path = self.path[:-1]
            return
        spec = CLOSURES.get(node.type)
        if spec is None:
            if node.type in VALUE_NODES:
                raise self.error(f"the output of {node.type} is not a shader")
            raise self.error(f"shader node {node.type} is not supported")
        isotropic = _isotropic(node)
        values = [Value(VECTOR, UNLINKED) if isotropic and node.inputs.get(socket.name, socket.default) == TANGENT
                  else self.input(node, socket) for socket in spec.inputs]
        base = self.block(spec.inputs, values)
        self.program.ops.append([OP_CLOSURE, spec.code, base, weight_reg])
        # What emits or lets light through differently from point to point (or from ray to
        # ray: a Light Path factor) is evaluated where a light sample or a shadow ray meets it.
        named = dict(zip((s.name for s in spec.inputs), values))
        emission = [named[name] for name in _EMISSION_INPUTS.get(node.type, ())]
        if any(not v.constant for v in emission) or (
                varies and emission and all(any(v.const) for v in emission)):
            self.program.emission_varies = True
        transparency = [named[name] for name in _TRANSPARENCY_INPUTS.get(node.type, ())]
        opaque = (1.0,) if node.type == "BsdfPrincipled" else (0.0, 0.0, 0.0)   # alpha 1, black
        if any(not v.constant for v in transparency) or (
                varies and transparency and transparency[0].const != opaque):
            self.program.transparency_varies = True
        if self.bssrdf_bump(node):
            self.program.bssrdf_bump = True

    def bssrdf_bump(self, node: ShaderNode) -> bool:
        """Cycles' has_bssrdf_bump: the node can make a BSSRDF (a Subsurface Scattering node, a
        Principled BSDF whose Subsurface Weight is linked or above the cutoff) and its Normal
        input is linked to anything but the Geometry node (shader_nodes.cpp: has_bump)."""
        if node.type == "BsdfPrincipled":
            weight = node.inputs.get("Subsurface Weight", 0.0)
            if not isinstance(weight, Link) and not float(weight) > CLOSURE_WEIGHT_CUTOFF:
                return False
        elif node.type != "SubsurfaceScattering":
            return False
        normal = node.inputs.get("Normal")
        return isinstance(normal, Link) and self.nodes[normal.node].type != "NewGeometry"

    # -- values -----------------------------------------------------------------------------------
    def node(self, link: Link):
        if link.node in self.path:
            raise self.error("its shader graph has a cycle")
        return self.nodes[link.node]

    def input(self, node, socket) -> Value:
        """The value an input receives: its link's (converted), or its constant."""
        value = node.inputs.get(socket.name, socket.default)
        if isinstance(value, Link):
            return self.converted(self.output(value), socket.type)
        if socket.name.startswith("prop:"):
            return Value(socket.type, self.prop(node, socket))
        if isinstance(value, str):      # an implicit texture coordinate
            return self.coordinate(IMPLICIT[value])
        return Value(socket.type, self.constant(node, socket, value))

    def constant(self, node, socket, value) -> tuple:
        size = SIZE[socket.type]
        flat = np.asarray(value, float).ravel()
        if flat.size == 0:
            raise self.error(f"input '{socket.name}' of {node.type} has no value")
        return tuple(np.broadcast_to(flat[:size], (size,)).tolist())

    def prop(self, node, socket) -> tuple:
        """A property as register values (``nodes`` module docstring)."""
        name = socket.name[5:]
        if name == "image":
            return (-1.0,)          # an image's name: its slot is found by image_inputs
        value = node.props.get(name, socket.default)
        if socket.type == TABLE:
            flat = [float(v) for v in np.asarray(value, float).ravel()]
            return (float(len(flat)), *flat)
        if socket.type == MATRIX:
            flat = np.asarray(value, float).ravel()
            if flat.size != 12:
                raise self.error(f"property '{name}' of {node.type} is not a 3 x 4 matrix")
            return tuple(flat.tolist())
        if isinstance(value, str):
            codes = ENUMS.get(name, {})
            if value not in codes:
                raise self.error(f"{node.type} {name} '{value}' is not supported")
            return (float(codes[value]),)
        return self.constant(node, socket, value)

    def output(self, link: Link) -> Value:
        """The value of a node's output socket (the node is compiled once)."""
        node = self.node(link)
        spec = VALUE_NODES.get(node.type)
        if spec is None:
            if node.type in CLOSURES or node.type in SHADER_ROUTING:
                raise self.error(f"a shader output ({node.type}) is linked to a value input")
            raise self.error(f"node {node.type} is not supported")
        if link.node not in self.outputs:
            self.path += (link.node,)
            self.outputs[link.node] = self.evaluate(node, spec)
            self.path = self.path[:-1]
        outputs = self.outputs[link.node]
        if link.socket not in outputs:
            raise self.error(f"{node.type} has no output '{link.socket}'")
        return outputs[link.socket]

    def coordinate(self, implicit: tuple) -> Value:
        """Output ``implicit`` = (node type, output) of the coordinate node of that type that
        the compiler inserts for unlinked inputs (one per material)."""
        kind, name = implicit
        if kind not in self.implicit:
            self.implicit[kind] = self.evaluate(ShaderNode(kind), VALUE_NODES[kind])
        return self.implicit[kind][name]

    def evaluate(self, node, spec) -> dict:
        """Compile value node ``node`` (or fold it); its outputs by name."""
        values = [self.input(node, socket) for socket in spec.inputs]
        if node.type == "Bump":
            values = self.bump_heights(node, spec, values)
        elif node.type in _ATTRIBUTE_READERS:
            values = self.attribute_inputs(node, spec, values)
        elif node.type in IMAGE_NODES:
            values = self.image_inputs(node, spec, values)
        elif node.type == "TexCoord":
            names = [s.name for s in spec.inputs]
            offset = self.attributes.find(UNDISPLACED_ATTRIBUTE)[0]
            values[names.index("prop:undisplaced")] = Value(FLOAT, (float(offset),))
        if spec.pure and all(v.constant for v in values):
            return self.fold(spec, values)
        known = _known_outputs(node, values)
        if known and all(o.name in known or not self.is_linked(node, o.name) for o in spec.outputs):
            return known
        base = self.block(spec.inputs, values)
        out = self.program.reg(sum(SIZE[s.type] for s in spec.outputs))
        self.program.ops.append([OP_NODE, spec.code, base, out])
        outputs, k = {}, out
        for socket in spec.outputs:
            outputs[socket.name] = Value(socket.type, reg=k)
            k += SIZE[socket.type]
        outputs.update(known)
        if node.type == "NewGeometry":
            for name, attribute in GEOMETRY_ATTRIBUTES.items():
                if self.is_linked(node, name):
                    read = ShaderNode("Attribute", props={"attribute_name": attribute})
                    outputs[name] = self.evaluate(read, VALUE_NODES["Attribute"])["Fac"]
        return outputs

    def attribute_inputs(self, node, spec, values) -> list:
        """The attribute a UV Map, Attribute, Color Attribute or Normal Map node reads, found by
        name (a Color Attribute without one reads the mesh's default colour attribute)."""
        prefix, prop = _ATTRIBUTE_READERS[node.type]
        name = str(node.props.get(prop, ""))
        if node.type == "VertexColor" and not name:
            name = DEFAULT_COLOR_ATTRIBUTE
        offset, size = self.attributes.find(prefix + name)
        names = [s.name for s in spec.inputs]
        values[names.index("prop:attribute")] = Value(FLOAT, (float(offset),))
        if "prop:attribute_size" in names:
            values[names.index("prop:attribute_size")] = Value(FLOAT, (float(size),))
        return values

    def image_inputs(self, node, spec, values) -> list:
        """The image an image node reads, found by name (-1: none, magenta), and whether its
        Alpha output is used; a Sky Texture's sun and horizon (``sky.node_parameters``)."""
        names = [s.name for s in spec.inputs]
        slot = self.images.get(sky.node_image(node), -1)
        values[names.index("prop:image")] = Value(FLOAT, (float(slot),))
        if "prop:alpha_linked" in names:
            linked = 1.0 if self.is_linked(node, "Alpha") else 0.0
            values[names.index("prop:alpha_linked")] = Value(FLOAT, (linked,))
        if node.type == "TexSky":
            for name, value in sky.node_parameters(node.props).items():
                values[names.index("prop:" + name)] = Value(FLOAT, (float(value),))
        return values

    def is_linked(self, node, output: str) -> bool:
        """Whether something is linked to ``output`` of ``node`` (False for the nodes the
        compiler inserts itself, which are not in the graph)."""
        index = next((k for k, n in enumerate(self.nodes) if n is node), -1)
        return (index, output) in self.linked

    def fold(self, spec, values) -> dict:
        """Evaluate a pure node with constant inputs now, with the kernels' own code."""
        regs = np.concatenate([np.asarray(v.const, float) for v in values] + [np.zeros(64)])
        out = sum(len(v.const) for v in values)
        fold_node(spec.code, regs, 0, out, _HOST_POINT, NO_TEXTURES)
        outputs, k = {}, out
        for socket in spec.outputs:
            n = SIZE[socket.type]
            outputs[socket.name] = Value(socket.type, tuple(regs[k:k + n].tolist()))
            k += n
        return outputs

    def block(self, sockets, values) -> int:
        """Registers for a node's inputs: constants stored, linked values copied in."""
        sizes = [len(v.const) if v.constant else SIZE[s.type] for s, v in zip(sockets, values)]
        base = self.program.reg(sum(sizes))
        k = base
        for value, n in zip(values, sizes):
            if value.constant:
                for j, c in enumerate(value.const):
                    self.program.init[k + j] = float(c)
            else:
                self.program.ops.append([OP_COPY, k, value.reg, n])
            k += n
        return base

    def converted(self, value: Value, to: str) -> Value:
        """``value`` as socket type ``to`` (Cycles' implicit conversions)."""
        frm = value.type
        if frm == to or {frm, to} <= {COLOR, VECTOR} or to in (TABLE, MATRIX):
            return Value(to, value.const, value.reg)
        if frm == SHADER or to == SHADER:
            raise self.error("a shader output is linked to a value input")
        if to == FLOAT:
            kind = CONV_COLOR_TO_FLOAT if frm == COLOR else CONV_VECTOR_TO_FLOAT
            if value.constant:
                c = value.const
                f = (sum(w * x for w, x in zip(RGB_TO_Y, c)) if kind == CONV_COLOR_TO_FLOAT
                     else sum(c) / 3.0)
                return Value(FLOAT, (f,))
        else:
            kind = CONV_FLOAT_TO_VECTOR
            if value.constant:
                return Value(to, (value.const[0],) * 3)
        out = self.program.reg(SIZE[to])
        self.program.ops.append([OP_CONVERT, out, value.reg, kind])
        return Value(to, reg=out)


def _isotropic(node) -> bool:
    """Whether a closure node's constant anisotropy leaves its tangent unused."""
    name, cutoff = _ANISOTROPY.get(node.type, (None, 0.0))
    value = node.inputs.get(name, 0.0)
    if isinstance(value, Link):
        return False
    a = float(np.asarray(value, float).ravel()[0])
    return abs(a) <= cutoff if node.type == "BsdfGlossy" else a <= cutoff


# Nodes that read a per-corner attribute: type -> (prefix of the attribute's name, the
# property naming it); the attribute's offset goes to their "prop:attribute" input.
_ATTRIBUTE_READERS = {"Attribute": ("", "attribute_name"), "UVMap": ("", "uv_map"),
                      "VertexColor": ("", "layer_name"), "NormalMap": (TANGENT_PREFIX, "uv_map"),
                      "VectorDisplacement": (TANGENT_PREFIX, "uv_map"),
                      "Tangent": (TANGENT_PREFIX, "uv_map")}


# What the compiler shows a node it evaluates ahead of time: no point, no scene (and, public,
# what a program run on the host without a scene reads: tests/core/test_closure_rows.py).
_HOST_POINT = ShadingData(0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, False,
                          False, True, True, True, -1, 0.0, 0.0, -1, 0, 0.0, 0, 0, 0, 0, 0, 0.0,
                          np.uint64(0), 0.0)
NO_TEXTURES = TextureData(attr=np.zeros((0, 3, 2), np.float32), normals=np.zeros((0, 3), np.float32),
                          normal_index=np.zeros((0, 3), np.int32),
                          tri_object=np.zeros(0, np.int32),
                          objects=np.zeros((0, OBJ_STRIDE)), camera=np.zeros(CAMERA_PARAMS),
                          images=np.zeros((0, IMG_STRIDE), np.int64), pix8=np.zeros(0, np.uint8),
                          pixf=np.zeros(0, np.float32))
# verts, tris and the objects' own hierarchies (SceneData's types)
NO_MESH = (np.zeros((0, 3)), np.zeros((0, 3), np.int32), no_local_bvh())


def compile_node_functions(functions) -> None:
    """Compile functions that the shader evaluator calls (``kernels.svm``'s node functions
    ``eval_*_node`` and closure nodes' ``principled``, ``glossy``, ...) for the argument types
    it gives them (``evaluator_argument_types``), without running them: ``mcengine.warmup``
    compiles some in a second process while the first compiles the others."""
    for function in functions:
        function.compile(evaluator_argument_types(function))


def evaluator_argument_types(function) -> tuple:
    """numba's types of what the shader evaluator (and the folding above) passes to
    ``function``, named by its parameters: a node function's (code, regs, b, c[, sd_ref,
    tex_ref]: the point and the texture data by reference, ``jit.by_ref``), a closure node's
    (regs, b[, mix_weight], cl, n, sd[, cr, cg, cb])."""
    from numba import typeof, types
    i64, f64 = typeof(np.int64(0)), typeof(0.0)
    known = {"code": i64, "b": i64, "c": i64, "n": i64, "regs": typeof(np.zeros(1)),
             "cl": typeof(np.zeros((MAX_CLOSURES, CL_STRIDE))), "mix_weight": f64, "w": f64,
             "cr": f64, "cg": f64, "cb": f64,
             "sd": typeof(_HOST_POINT), "sd_ref": types.CPointer(typeof(_HOST_POINT)),
             "tex_ref": types.CPointer(typeof(NO_TEXTURES))}
    code = function.py_func.__code__
    return tuple(known[name] for name in code.co_varnames[:code.co_argcount])


class ShaderTable:
    """Every material's program in one pair of arrays, and what the renderer must know
    of each material before shading it.

    ``ops`` (P, 4) int32 holds the programs, ``ranges`` (M, 2) int32 the
    [start, end) row range of material m's, ``registers`` (R,) float64 the
    register file with every material's constants in place (each worker
    copies it once per render) and ``register_ranges`` (M, 2) the [start, end)
    of material m's registers in it.  ``emission`` (M, 3) is the radiance the
    material emits as a light source, evaluated as Cycles evaluates a light's
    shader (no closures built, so no layer above the emission darkens it;
    facing the normal; ``emitted`` the same before negative values are clipped),
    and ``flags`` (M,) holds MF_* bits: emissive,
    transparent to shadow rays, bump-map correction, closures only, BSSRDF bump.
    """

    def __init__(self, materials, attributes: AttributeLayout | None = None,
                 images: dict | None = None):
        ops, ranges, register_ranges, init = [], [], [], {}
        programs = []
        base = 0
        for m in materials:
            program = compile_material(m, attributes, base, images)
            register_ranges.append([base, base + program.registers])
            base += program.registers
            ranges.append([len(ops), len(ops) + len(program.ops)])
            ops.extend(program.ops)
            init.update(program.init)
            programs.append(program)
        self.ops = np.array(ops, np.int32).reshape(-1, 4)
        self.ranges = np.array(ranges, np.int32).reshape(-1, 2)
        self.register_ranges = np.array(register_ranges, np.int64).reshape(-1, 2)
        self.registers = np.zeros(max(base, 1))
        if init:
            self.registers[np.fromiter(init.keys(), np.int64)] = np.fromiter(init.values(), float)
        self.emitted = np.zeros((len(materials), 3))
        self.flags = np.zeros(len(materials), np.int32)
        regs, cl = self.registers.copy(), np.zeros((MAX_CLOSURES, CL_STRIDE))
        point = _HOST_POINT._replace(allocate=False, bump_correction=False)
        for i, (m, program) in enumerate(zip(materials, programs)):
            point = point._replace(bump_correction=m.use_bump_map_correction)
            res = eval_shader_by_value(self.ranges[i, 0], self.ranges[i, 1], regs, cl, point,
                                       ShaderScene(self.ops, NO_TEXTURES, *NO_MESH))
            self.emitted[i] = (res.er, res.eg, res.eb)
            flags = MF_BUMP_CORRECTION if m.use_bump_map_correction else 0
            if self.emitted[i].max() > 0.0 or program.emission_varies:
                flags |= MF_EMISSIVE
            if program.emission_varies:
                flags |= MF_EMISSION_VARIES
            if closures_only(self.ops[self.ranges[i, 0]:self.ranges[i, 1]]):
                flags |= MF_CLOSURES_ONLY
            if program.bssrdf_bump:
                flags |= MF_BSSRDF_BUMP
            if m.use_transparent_shadow and (max(res.tr, res.tg, res.tb) > 0.0
                                             or program.transparency_varies):
                flags |= MF_TRANSPARENT
            self.flags[i] = flags
        self.emission = np.maximum(self.emitted, 0.0)

    def constant_emission(self, m: int) -> np.ndarray | None:
        """Material m's emission when its program folded to constants (a lamp's node tree,
        whose emission scales the lamp: Cycles evaluates it per light sample, the same
        everywhere then); None when it varies over the surface."""
        start, end = self.ranges[m]
        if not closures_only(self.ops[start:end]) or self.flags[m] & MF_EMISSION_VARIES:
            return None
        return self.emitted[m].copy()

    def closure_kinds(self, m: int) -> list[int]:
        """Closure node kinds in material m's program."""
        start, end = self.ranges[m]
        rows = self.ops[start:end]
        return [int(k) for k in rows[rows[:, 0] == OP_CLOSURE, 1]]
