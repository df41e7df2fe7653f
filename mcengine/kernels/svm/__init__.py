"""The shader evaluator: runs a material's program at a shading point.

``mcengine.shaders`` compiles each material's node graph into rows of four
int32 ``[op, a, b, c]``, in the manner of Cycles' SVM (kernel/svm/).  Every
material owns a range of the register file ``regs`` (float64, one copy per
worker): its constants are written there once per render
(``ShaderTable.registers``), so a material whose inputs are all constant
runs nothing but its closure rows.  ``eval_shader`` runs a material's rows
and writes its closures at this point into the closure list ``cl`` (see
``closures.layout``).  Operations:

``OP_NODE``        a = node code (``nodes.VALUE_NODES``), b = its first input register,
                   c = its first output register: evaluate a value node
``OP_COPY``        a = destination register, b = source register, c = count
``OP_CONVERT``     a = destination, b = source, c = ``CONV_*``: a link between sockets of
                   different types (Cycles' implicit conversions)
``OP_MIX_WEIGHT``  a = factor register, b = incoming weight register (-1: 1),
                   c = first of two registers: in x (1 - fac), in x fac
``OP_CLOSURE``     a = node kind (``nodes.K_*``), b = its first input register,
                   c = weight register (-1: 1): build the node's closures
``OP_BUMP``        a = ``BUMP_DX`` or ``BUMP_DY``: the rows after it, up to its BUMP_LEAVE row c
                   rows further on, run at the point moved along dPdx or dPdy by the filter
                   width in register b (a Bump node's Height sub-graph, ``bump.bump_point``);
                   plus ``BUMP_UNDISPLACED`` (with a = ``BUMP_CENTER`` too, the Height at the
                   point itself): in a scene with true displacement, register b starts the
                   Bump node's state block and the point is the undisplaced one
                   (``bump.undisplaced_point``, Cycles' svm_node_enter_bump_eval);
                   a = ``BUMP_SET_NORMAL``, only as a program's first row: the rows after it,
                   up to c rows further on, run first (the output's Displacement), then the
                   shading normal is the vector in register b for the rest of the program
                   (displacement as bump)

Those rows hold nothing but value nodes; ``eval_values`` runs them at the moved point,
so the point ``eval_shader``'s loop shades never changes inside it.

The result is the number of closures, the emitted radiance, the transparency
(the summed weight of transparent closures, which shadow rays pass through)
and the holdout weight.  ``ShadingData`` is what the nodes see of the point,
``TextureData`` what they read of the scene (attributes, objects, images).
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np

from ...jit import by_ref, deref, device, field_ref, function
from ..colorspace import RGB_TO_Y, luminance  # noqa: F401  (RGB_TO_Y: for the compiler)
from ..scalar import saturate
from .ao import ao_node
from .bevel import bevel_node
from .bump import bump_point, dpdv_node, undisplaced_point, with_normal
from .closure_nodes import eval_closure_node
from .color_nodes import eval_color_node
from .data import (  # noqa: F401  (what the evaluator reads, for its callers)
    ATTR_DEFAULT_UV,
    IMG_STRIDE,
    OBJ_COLOR,
    OBJ_HOLDOUT,
    OBJ_INVERSE,
    OBJ_LIGHT_SETS,
    OBJ_MATRIX,
    OBJ_PASS_INDEX,
    OBJ_RANDOM,
    OBJ_RECEIVER_SET,
    OBJ_STRIDE,
    OBJ_TERMINATOR_GEOMETRY,
    OBJ_TERMINATOR_SHADING,
    OBJ_TEXSPACE_LOC,
    OBJ_TEXSPACE_SIZE,
    OBJ_VISIBILITY,
    ShaderScene,
    ShadingData,
    TextureData,
)
from .image_nodes import eval_image_node
from .input_nodes import eval_input_node
from .math_nodes import eval_math_node
from .nodes import (
    FAMILY_COLOR,
    FAMILY_INPUT,
    FAMILY_MATH,
    FAMILY_NORMAL,
    FAMILY_TEXTURE,
    FAMILY_VECTOR,
    IMAGE_CODES,
    NODES,
)
from .normal_nodes import eval_normal_node
from .texture_nodes import eval_texture_node
from .vector_nodes import eval_vector_node
from .wireframe import wireframe_node

_WIREFRAME = NODES["Wireframe"].code
_DPDV = NODES["dPdv"].code
_BEVEL = NODES["Bevel"].code
_AO = NODES["AmbientOcclusion"].code
_TEX = ShaderScene._fields.index("tex")      # for jit.field_ref

OP_END = 0
OP_NODE = 1
OP_MIX_WEIGHT = 2
OP_CLOSURE = 3
OP_COPY = 4
OP_CONVERT = 5
OP_BUMP = 6
BUMP_LEAVE = 0                # OP_BUMP a
BUMP_DX = 1
BUMP_DY = 2
BUMP_SET_NORMAL = 3
BUMP_CENTER = 0               # with BUMP_UNDISPLACED: the Height at the (undisplaced) point
BUMP_UNDISPLACED = 8          # added to BUMP_CENTER, BUMP_DX, BUMP_DY
MAX_REGS = 1 << 22            # registers of all materials together (32 MiB per worker)

# Implicit conversions of a link (OP_CONVERT c).
CONV_COLOR_TO_FLOAT = 0       # luminance: dot(c, RGB_TO_Y)
CONV_VECTOR_TO_FLOAT = 1      # mean of the components
CONV_FLOAT_TO_VECTOR = 2      # (f, f, f), also to a colour

ShaderResult = namedtuple("ShaderResult", [
    "n",                       # closures written to cl
    "er", "eg", "eb",          # emitted radiance (two-sided)
    "tr", "tg", "tb",          # transparency: the summed weight of transparent closures
    "holdout",                 # holdout weight (the film's alpha is reduced by it)
])
NO_RESULT = ShaderResult(np.int64(0), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)   # before any row


@device
def eval_node(code, regs, b, c, sd_ref, tex_ref):
    """Evaluate value node ``code``: inputs at regs[b:], outputs to regs[c:]; the point and
    the texture data by reference (``jit.by_ref``)."""
    family = code // 100
    if family == FAMILY_INPUT:
        eval_input_node(code, regs, b, c, sd_ref, tex_ref)
    elif family == FAMILY_MATH:          # these two read neither the point nor the scene
        eval_math_node(code, regs, b, c)
    elif family == FAMILY_COLOR:
        eval_color_node(code, regs, b, c)
    elif family == FAMILY_TEXTURE:
        if code >= IMAGE_CODES:
            eval_image_node(code, regs, b, c, sd_ref, tex_ref)
        else:
            eval_texture_node(code, regs, b, c, sd_ref, tex_ref)
    elif family == FAMILY_VECTOR:
        eval_vector_node(code, regs, b, c, sd_ref, tex_ref)
    elif family == FAMILY_NORMAL:
        eval_normal_node(code, regs, b, c, sd_ref, tex_ref)


@function
def fold_node(code, regs, b, c, sd, tex):
    """``eval_node`` with the point and the texture data by value: the shader compiler's
    constant folding calls it on the host."""
    eval_node(code, regs, b, c, by_ref(sd), by_ref(tex))


@device
def convert(regs, a, b, kind):
    """OP_CONVERT: regs[a:] = regs[b:] converted (``CONV_*``)."""
    if kind == CONV_COLOR_TO_FLOAT:
        regs[a] = luminance(regs[b], regs[b + 1], regs[b + 2])
    elif kind == CONV_VECTOR_TO_FLOAT:
        regs[a] = (regs[b] + regs[b + 1] + regs[b + 2]) * (1.0 / 3.0)
    else:
        f = regs[b]
        regs[a] = f
        regs[a + 1] = f
        regs[a + 2] = f


@device
def eval_row(ops, pc, regs, sd_ref, scene_ref):
    """One value row: OP_NODE, OP_COPY or OP_CONVERT."""
    op = ops[pc, 0]
    a, b, c = ops[pc, 1], ops[pc, 2], ops[pc, 3]
    if op == OP_NODE:
        tex_ref = field_ref(scene_ref, _TEX)
        if a == _WIREFRAME:         # the nodes that read the triangles themselves
            scene = deref(scene_ref)
            wireframe_node(regs, b, c, deref(sd_ref), scene.verts, scene.tris)
        elif a == _DPDV:
            scene = deref(scene_ref)
            dpdv_node(regs, c, deref(sd_ref), scene.verts, scene.tris)
        elif a == _BEVEL:
            scene = deref(scene_ref)
            bevel_node(regs, b, c, deref(sd_ref), scene.tex, scene.verts, scene.tris, scene.local)
        elif a == _AO:
            scene = deref(scene_ref)
            ao_node(regs, b, c, deref(sd_ref), scene.tex, scene.verts, scene.tris, scene.local)
        else:
            eval_node(np.int64(a), regs, np.int64(b), np.int64(c), sd_ref, tex_ref)   # as the compiler folds
    elif op == OP_COPY:
        for k in range(c):
            regs[a + k] = regs[b + k]
    elif op == OP_CONVERT:
        convert(regs, a, b, c)


@function
def eval_values(start, end, regs, sd_ref, scene_ref):
    """Run value rows [start, end) of the scene's programs at the point ``sd_ref`` (the
    point and the ``ShaderScene`` by reference): the Height sub-graph of a Bump node, or the
    output's Displacement; a Bump node in there moves the point again from that point."""
    ops = deref(scene_ref).ops
    point = sd_ref
    for pc in range(start, end):
        if ops[pc, 0] == OP_BUMP:
            if ops[pc, 1] == BUMP_LEAVE:
                point = sd_ref
            else:
                point = by_ref(region_point(ops, pc, regs, deref(sd_ref), deref(scene_ref)))
        else:
            eval_row(ops, pc, regs, point, scene_ref)


@device
def region_point(ops, pc, regs, sd, scene):
    """The point the rows after ``OP_BUMP`` row pc run at (not ``BUMP_LEAVE``)."""
    axis = ops[pc, 1]
    if axis >= BUMP_UNDISPLACED:
        return undisplaced_point(sd, scene.verts, scene.tris, regs, ops[pc, 2],
                                 axis - BUMP_UNDISPLACED, scene.tex)
    return bump_point(sd, scene.verts, scene.tris, regs[ops[pc, 2]], axis)


@function
def eval_shader(start, end, regs, cl, sd, scene_ref):
    """Run rows [start, end) of the scene's programs at the shading point ``sd``; a
    :class:`ShaderResult`.  ``scene_ref`` is the address of a :class:`ShaderScene`
    (``jit.by_ref``), which callers make once per kernel call, not once per point; the node
    functions take the point and the texture data by reference too."""
    res = NO_RESULT
    ops = deref(scene_ref).ops
    if start < end and ops[start, 0] == OP_BUMP and ops[start, 1] == BUMP_SET_NORMAL:
        surface, b = start + ops[start, 3], ops[start, 2]
        eval_values(start + 1, surface, regs, by_ref(sd), scene_ref)
        sd = with_normal(sd, regs[b], regs[b + 1], regs[b + 2])
        start = surface
    sd_ref = by_ref(sd)
    skip = start             # rows before it were run by eval_values
    for pc in range(start, end):
        if pc < skip:
            continue
        op = ops[pc, 0]
        if op == OP_CLOSURE or op == OP_MIX_WEIGHT:
            res = closure_row(ops, pc, regs, cl, sd, res)
        elif op == OP_BUMP:
            eval_values(pc + 1, pc + ops[pc, 3], regs,
                        by_ref(region_point(ops, pc, regs, sd, deref(scene_ref))), scene_ref)
            skip = pc + ops[pc, 3] + 1
        else:
            eval_row(ops, pc, regs, sd_ref, scene_ref)
    return res


@function
def eval_shader_by_value(start, end, regs, cl, sd, scene):
    """``eval_shader`` with the ``ShaderScene`` by value, for callers on the host."""
    return eval_shader(start, end, regs, cl, sd, by_ref(scene))


@device
def shader_scene(sc):
    """What the shader evaluator reads of the scene (``state.SceneData``)."""
    return ShaderScene(sc.svm_ops, sc.tex, sc.verts, sc.tris, sc.local)


@device
def closure_row(ops, pc, regs, cl, sd, res):
    """Run row pc, an ``OP_CLOSURE`` or ``OP_MIX_WEIGHT``, after the rows that gave ``res``;
    returns the :class:`ShaderResult` with this row's closures and light added."""
    a, b, c = ops[pc, 1], ops[pc, 2], ops[pc, 3]
    if ops[pc, 0] == OP_MIX_WEIGHT:
        fac = saturate(regs[a])
        w = regs[b] if b >= 0 else 1.0
        regs[c] = w * (1.0 - fac)
        regs[c + 1] = w * fac
        return res
    w = regs[c] if c >= 0 else 1.0
    if w == 0.0:
        return res
    n, er, eg, eb, tr, tg, tb, h = eval_closure_node(np.int64(a), regs, np.int64(b), w, cl,
                                                     np.int64(res.n), sd)
    return ShaderResult(n, res.er + er, res.eg + eg, res.eb + eb, res.tr + tr, res.tg + tg,
                        res.tb + tb, res.holdout + h)


@device
def eval_closure_rows(ops, start, end, regs, cl, sd):
    """``eval_shader`` for a program of closure and mix-weight rows only (``closures_only``):
    the same result, without taking the texture data and the triangles, which a call copies
    (about 90 machine words, a tenth of the render time of a constant material)."""
    res = NO_RESULT
    for pc in range(start, end):
        res = closure_row(ops, pc, regs, cl, sd, res)
    return res


def closures_only(rows) -> bool:
    """Whether a program's rows (an (R, 4) array) are all ``OP_CLOSURE`` or ``OP_MIX_WEIGHT``:
    its inputs are constant registers, and ``eval_closure_rows`` can run it."""
    return bool(np.isin(np.asarray(rows)[:, 0], (OP_CLOSURE, OP_MIX_WEIGHT)).all())
