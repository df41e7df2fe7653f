"""The shader evaluator: runs a material's program at a shading point.

``mcengine.shaders`` compiles each material's node graph into rows of four
int32 ``[op, a, b, c]`` plus a pool of float64 constants, in the manner of
Cycles' SVM (kernel/svm/).  ``eval_shader`` runs a material's rows with a
register file ``regs`` (float64, owned by the worker) and writes the
material's closures at this point into the closure list ``cl`` (see
``closures.layout``).  Operations:

``OP_CONST``       a = first register, b = first constant, c = count: copy constants
``OP_MIX_WEIGHT``  a = factor register, b = incoming weight register (-1: 1),
                   c = first of two registers: in x (1 - fac), in x fac
``OP_CLOSURE``     a = node kind (``nodes.K_*``), b = its first input register,
                   c = weight register (-1: 1): build the node's closures

The result is the number of closures, the emitted radiance, the transparency
(the summed weight of transparent closures, which shadow rays pass through)
and the holdout weight.  ``ShadingData`` is what the nodes see of the point.
"""
from __future__ import annotations

from collections import namedtuple

from ...jit import function
from .closure_nodes import eval_closure_node

OP_END = 0
OP_CONST = 1
OP_MIX_WEIGHT = 2
OP_CLOSURE = 3
MAX_REGS = 1024

ShadingData = namedtuple("ShadingData", [
    "px", "py", "pz",          # the point
    "nx", "ny", "nz",          # unit shading normal (interpolated), on the viewer's side
    "ngx", "ngy", "ngz",       # unit geometric normal, on the viewer's side
    "wox", "woy", "woz",       # unit direction to the viewer
    "backfacing",              # the ray arrived from the inside of the surface
    "allocate",                # closures are built (False on terminated and shadow paths:
                               # only emission, transparency and holdout are wanted)
    "reflective_caustics",     # glossy reflection closures are allowed at this vertex
    "refractive_caustics",     # refraction closures are allowed at this vertex
    "bump_correction",         # tilt glossy normals whose mirror direction points inside
])

ShaderResult = namedtuple("ShaderResult", [
    "n",                       # closures written to cl
    "er", "eg", "eb",          # emitted radiance (two-sided)
    "tr", "tg", "tb",          # transparency: the summed weight of transparent closures
    "holdout",                 # holdout weight (the film's alpha is reduced by it)
])


@function
def eval_shader(ops, consts, start, end, regs, cl, sd):
    """Run rows [start, end) of ``ops`` at the shading point ``sd``; a :class:`ShaderResult`."""
    n = 0
    er = eg = eb = 0.0
    tr = tg = tb = 0.0
    holdout = 0.0
    for pc in range(start, end):
        op = ops[pc, 0]
        a, b, c = ops[pc, 1], ops[pc, 2], ops[pc, 3]
        if op == OP_CONST:
            for k in range(c):
                regs[a + k] = consts[b + k]
        elif op == OP_MIX_WEIGHT:
            fac = min(max(regs[a], 0.0), 1.0)
            w = regs[b] if b >= 0 else 1.0
            regs[c] = w * (1.0 - fac)
            regs[c + 1] = w * fac
        elif op == OP_CLOSURE:
            w = regs[c] if c >= 0 else 1.0
            if w == 0.0:
                continue
            n, der, deg, deb, dtr, dtg, dtb, dh = eval_closure_node(a, regs, b, w, cl, n, sd)
            er += der
            eg += deg
            eb += deb
            tr += dtr
            tg += dtg
            tb += dtb
            holdout += dh
    return ShaderResult(n, er, eg, eb, tr, tg, tb, holdout)
