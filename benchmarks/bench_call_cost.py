"""What a call between compiled functions costs with the shader evaluator's argument types.

numba passes a tuple argument field by field: a ``ShadingData`` is 31 machine words, a
``TextureData`` of eight arrays 68.  The node functions of the shader evaluator therefore
take the two by reference (``jit.by_ref``, ``jit.deref``).  This calls one function,
shaped like a node function (a dispatch on ``code`` over a dozen cases, too large for LLVM
to inline), in a loop, three ways:

* ``by value``: ``node(code, regs, b, c, sd, tex)``;
* ``by reference``: the references made once, before the loop, as ``eval_shader`` does;
* ``reference per call``: ``by_ref`` inside the loop (the copy is then made for each call,
  which is why the evaluator makes its references once per run).

``inlined`` is the same work with no call at all, for scale.

The functions are compiled here, without numba's cache and without reference counting, as
the kernels are.  Prints nanoseconds per call (median of the rounds); compare figures of
one run.

Run: python benchmarks/bench_call_cost.py [--calls N] [--rounds R]
"""
from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np
from numba import njit

from mcengine.jit import by_ref, deref
from mcengine.kernels.svm import ShadingData
from mcengine.shaders import NO_TEXTURES

_compiled = njit(error_model="numpy", _nrt=False)


@njit(inline="always")
def _mix(x, a, b):
    return math.sin(x * a) + math.cos(x * b) + math.sqrt(abs(x) + a * a + b * b) + math.exp(-abs(a * b))


@njit(inline="always")
def _body(code, regs, b, c, sd, tex):
    """What the stand-in node function does: reads a few fields of the point and of the
    textures (numba inlines it into both ways of taking them)."""
    x = regs[b]
    if code == 0:
        regs[c] = _mix(x, sd.u, sd.v) + tex.images.shape[0]
    elif code == 1:
        regs[c] = _mix(x, sd.nx, sd.ny) * sd.nz
    elif code == 2:
        regs[c] = _mix(x, sd.px, sd.py) - sd.pz
    elif code == 3:
        regs[c] = _mix(x, sd.wox, sd.woy) + sd.woz
    elif code == 4:
        regs[c] = _mix(x, sd.ngx, sd.ngy) + tex.pixf.shape[0]
    elif code == 5:
        regs[c] = _mix(x, sd.dp, sd.ray_length) + sd.prim
    elif code == 6:
        regs[c] = _mix(x, sd.min_pdf, sd.u) + sd.obj
    elif code == 7:
        regs[c] = _mix(x, sd.v, sd.px) + tex.objects.shape[0]
    elif code == 8:
        regs[c] = _mix(x, sd.py, sd.nz) + sd.depth
    elif code == 9:
        regs[c] = _mix(x, sd.ngz, sd.wox) + tex.attr.shape[0]
    elif code == 10:
        regs[c] = _mix(x, sd.ny, sd.dp) + sd.path_flags
    else:
        regs[c] = _mix(x, sd.pz, sd.ngx) + tex.camera.shape[0]


@_compiled
def _node(code, regs, b, c, sd, tex):
    _body(code, regs, b, c, sd, tex)


@_compiled
def _node_by_ref(code, regs, b, c, sd_ref, tex_ref):
    _body(code, regs, b, c, deref(sd_ref), deref(tex_ref))


@_compiled
def _calls_by_value(calls, regs, sd, tex):
    for i in range(calls):
        _node(i % 12, regs, i & 7, (i & 7) + 8, sd, tex)


@_compiled
def _calls_by_reference(calls, regs, sd, tex):
    sd_ref, tex_ref = by_ref(sd), by_ref(tex)
    for i in range(calls):
        _node_by_ref(i % 12, regs, i & 7, (i & 7) + 8, sd_ref, tex_ref)


@_compiled
def _calls_inlined(calls, regs, sd, tex):
    for i in range(calls):
        _body(i % 12, regs, i & 7, (i & 7) + 8, sd, tex)


@_compiled
def _calls_reference_per_call(calls, regs, sd, tex):
    for i in range(calls):
        _node_by_ref(i % 12, regs, i & 7, (i & 7) + 8, by_ref(sd), by_ref(tex))


def _point() -> ShadingData:
    """A shading point with the field types ``kernels.shading.shading_data`` gives."""
    i64 = np.int64
    return ShadingData(0.1, 0.2, 0.3, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.6, 0.8, False, True,
                       True, True, False, i64(3), 0.25, 0.5, i64(0), i64(1), 2.0,
                       i64(1), i64(1), i64(0), i64(0), i64(0), 0.01, np.uint64(7), 0.0)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--calls", type=int, default=5_000_000, help="calls per round")
    parser.add_argument("--rounds", type=int, default=5, help="rounds per way")
    args = parser.parse_args(argv)
    regs, sd, tex = np.linspace(-1.0, 1.0, 32), _point(), NO_TEXTURES
    ways = {"by value": _calls_by_value, "by reference": _calls_by_reference,
            "reference per call": _calls_reference_per_call, "inlined": _calls_inlined}
    for loop in ways.values():
        loop(100, regs, sd, tex)            # compile
    times = {name: [] for name in ways}
    for _ in range(args.rounds):            # alternate the ways round by round
        for name, loop in ways.items():
            start = time.perf_counter()
            loop(args.calls, regs, sd, tex)
            times[name].append((time.perf_counter() - start) / args.calls * 1e9)
    print(f"one call of a node-like function, {args.calls:,} calls x {args.rounds} rounds "
          "(median ns per call):")
    for name, samples in times.items():
        print(f"  {name:20s} {statistics.median(samples):6.1f} ns")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
