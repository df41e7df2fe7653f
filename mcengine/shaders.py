"""Shader compiler: a material's node graph -> a program for the shader evaluator.

A material is a graph of shader nodes (``scene.Material.graph()``).  The
compiler walks it from the output's Surface socket, as Cycles' SVM compiler
does (scene/shader_graph.cpp, svm.cpp), and emits a straight-line program for
``kernels.svm.eval_shader``:

* every closure node (Principled, Diffuse, Glossy, ...) gets a block of
  registers holding its inputs in the order of ``kernels.svm.nodes``, filled
  by one ``OP_CONST`` from the constant pool, and an ``OP_CLOSURE`` that
  builds its closures at the shading point;
* a Mix Shader computes the weights of its two inputs from its factor
  (``OP_MIX_WEIGHT``: in x (1 - fac) and in x fac), an Add Shader passes its
  weight to both; a closure node's weight register holds the product of the
  factors on its way to the output (none: weight 1).

Programs are plain int32/float64 arrays, so a saved scene renders without
Blender and the kernels see one format for every material.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .kernels.closures.layout import CL_STRIDE, MAX_CLOSURES
from .kernels.state import MF_BUMP_CORRECTION, MF_EMISSIVE, MF_TRANSPARENT
from .kernels.svm import MAX_REGS, OP_CLOSURE, OP_CONST, OP_MIX_WEIGHT, ShadingData, eval_shader
from .kernels.svm.nodes import DISTRIBUTIONS, INPUTS, KIND, SHADER_ROUTING
from .scene import Link, Material, SceneError

__all__ = ["Program", "compile_material", "ShaderTable"]

NO_WEIGHT = -1      # weight register of a closure that reaches the output unmixed (weight 1)


@dataclass
class Program:
    """The compiled form of one material."""

    ops: list = field(default_factory=list)        # [op, a, b, c] rows
    consts: list = field(default_factory=list)     # float constants
    registers: int = 0                             # registers used

    def reg(self, n: int) -> int:
        """Allocate n consecutive registers; returns the first."""
        first = self.registers
        self.registers += n
        if self.registers > MAX_REGS:
            raise SceneError(f"shader needs more than {MAX_REGS} registers")
        return first


def compile_material(material: Material) -> Program:
    """Compile ``material`` (SceneError names an unsupported node or a cycle)."""
    nodes, surface = material.graph()
    program = Program()
    if surface is not None:
        _compile_shader(material, nodes, surface, NO_WEIGHT, program, ())
    return program


def _compile_shader(material, nodes, link: Link, weight_reg: int, program: Program, path: tuple):
    if link.node in path:
        raise SceneError(f"material '{material.name}': its shader graph has a cycle")
    node = nodes[link.node]
    path = path + (link.node,)
    if node.type in SHADER_ROUTING:
        first = node.inputs.get("Shader")
        second = node.inputs.get("Shader_001")
        if node.type == "MixShader":
            fac = _constant(material, node, "Fac", 0.5)
            fac_reg = program.reg(1)
            _load(program, fac_reg, [fac])
            out = program.reg(2)
            program.ops.append([OP_MIX_WEIGHT, fac_reg, weight_reg, out])
            weights = (out, out + 1)
        else:
            weights = (weight_reg, weight_reg)
        for shader_in, w in ((first, weights[0]), (second, weights[1])):
            if isinstance(shader_in, Link):
                _compile_shader(material, nodes, shader_in, w, program, path)
        return
    if node.type not in KIND:
        raise SceneError(f"material '{material.name}': shader node {node.type} is not supported")
    values = []
    for name, size, default in INPUTS[node.type]:
        if name.startswith("prop:"):
            prop = node.props.get(name[5:])
            values.append(float(DISTRIBUTIONS[prop]) if prop is not None else float(default))
            continue
        value = _constant(material, node, name, default)
        values.extend(np.broadcast_to(np.asarray(value, float).ravel()[:size], (size,)).tolist())
    base = program.reg(len(values)) if values else 0
    if values:
        _load(program, base, values)
    program.ops.append([OP_CLOSURE, KIND[node.type], base, weight_reg])


def _constant(material, node, name, default):
    value = node.inputs.get(name, default)
    if isinstance(value, Link):
        raise SceneError(f"material '{material.name}': input '{name}' of {node.type} is linked; "
                         f"only constant inputs are supported")
    return value


def _load(program: Program, reg: int, values) -> None:
    program.ops.append([OP_CONST, reg, len(program.consts), len(values)])
    program.consts.extend(float(v) for v in values)


class ShaderTable:
    """Every material's program in one pair of arrays, and what the renderer must know
    of each material before shading it.

    ``ops`` (P, 4) int32 and ``consts`` (C,) float64 hold the programs;
    ``ranges`` (M, 2) int32 is the [start, end) row range of material m's.
    ``emission`` (M, 3) is the radiance the material emits as a light source,
    evaluated as Cycles evaluates a light's shader (no closures built, so no
    layer above the emission darkens it; facing the normal), and ``flags``
    (M,) holds MF_* bits: emissive, transparent to shadow rays, bump-map correction.
    """

    def __init__(self, materials):
        ops, consts, ranges = [], [], []
        for m in materials:
            program = compile_material(m)
            start = len(ops)
            for op, a, b, c in program.ops:
                if op == OP_CONST:
                    b += len(consts)
                ops.append([op, a, b, c])
            consts.extend(program.consts)
            ranges.append([start, len(ops)])
        self.ops = np.array(ops, np.int32).reshape(-1, 4)
        self.consts = np.array(consts, np.float64)
        self.ranges = np.array(ranges, np.int32).reshape(-1, 2)
        self.emission = np.zeros((len(materials), 3))
        self.flags = np.zeros(len(materials), np.int32)
        regs, cl = np.zeros(MAX_REGS), np.zeros((MAX_CLOSURES, CL_STRIDE))
        for i, m in enumerate(materials):
            sd = ShadingData(0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, False,
                             False, True, True, m.use_bump_map_correction)
            res = eval_shader(self.ops, self.consts, self.ranges[i, 0], self.ranges[i, 1], regs,
                              cl, sd)
            self.emission[i] = np.maximum((res.er, res.eg, res.eb), 0.0)
            flags = MF_BUMP_CORRECTION if m.use_bump_map_correction else 0
            if self.emission[i].max() > 0.0:
                flags |= MF_EMISSIVE
            if m.use_transparent_shadow and max(res.tr, res.tg, res.tb) > 0.0:
                flags |= MF_TRANSPARENT
            self.flags[i] = flags
