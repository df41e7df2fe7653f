"""Texture nodes: procedural patterns and images (kernel/svm/checker.h, noise.h, voronoi.h, ...).

``eval_texture_node`` evaluates one texture node: inputs at regs[b:] in the
order of ``nodes.VALUE_NODES``, outputs to regs[c:].  The Vector input is
always present: when nothing is linked to it, the compiler links the
texture coordinate Cycles uses by default (Generated, or UV for images).
"""
from __future__ import annotations

import math

from ...jit import device, function
from .nodes import NODES, OFFSETS

_CHECKER = NODES["TexChecker"].code
_CK_VECTOR = OFFSETS["TexChecker"]["Vector"]
_CK_COLOR1 = OFFSETS["TexChecker"]["Color1"]
_CK_COLOR2 = OFFSETS["TexChecker"]["Color2"]
_CK_SCALE = OFFSETS["TexChecker"]["Scale"]


@function
def eval_texture_node(code, regs, b, c, sd, tex):
    if code == _CHECKER:
        checker_node(regs, b, c)


@device
def checker(x, y, z):
    """1 on the odd cells of the unit grid, else 0 (Cycles' svm_checker)."""
    # Nudged so that integer coordinates fall consistently into one cell.
    xi = abs(int(math.floor((x + 0.000001) * 0.999999)))
    yi = abs(int(math.floor((y + 0.000001) * 0.999999)))
    zi = abs(int(math.floor((z + 0.000001) * 0.999999)))
    return 1.0 if ((xi % 2 == yi % 2) == (zi % 2 == 1)) else 0.0


@device
def checker_node(regs, b, c):
    scale = regs[b + _CK_SCALE]
    v = b + _CK_VECTOR
    f = checker(regs[v] * scale, regs[v + 1] * scale, regs[v + 2] * scale)
    col = b + (_CK_COLOR1 if f == 1.0 else _CK_COLOR2)
    regs[c], regs[c + 1], regs[c + 2] = regs[col], regs[col + 1], regs[col + 2]
    regs[c + 3] = f
