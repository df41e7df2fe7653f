"""mcengine.jit's tuples by reference, and mcengine.numba_patches (installed by mcengine.jit):
faster compiles, the same programs."""
from __future__ import annotations

import copy
import re

import numpy as np
import pytest
from numba import njit
from numba.core import analysis, compiler, ir, ir_utils, ssa
from numba.core import inline_closurecall as inlining
from numba.core.registry import cpu_target

import mcengine.jit  # noqa: F401  (installs the changes)
from mcengine.jit import by_ref, deref, field_ref
from mcengine.kernels import light_tracing, path
from mcengine.kernels.svm import ShaderScene, ShadingData
from mcengine.shaders import NO_MESH, NO_TEXTURES


@njit(_nrt=False)
def _fields(ref):
    """Called, not inlined: what it reads through a ``by_ref`` address."""
    return deref(ref)


@njit(_nrt=False)
def _mark(ref, k):
    deref(ref).pixf[k] = k


@njit(_nrt=False)
def _through_refs(sd, tex):
    tex_ref = by_ref(tex)
    for k in range(tex.pixf.shape[0]):      # one address for every call
        _mark(tex_ref, k)
    return _fields(by_ref(sd))


def test_a_tuple_passed_by_reference_reads_as_the_value():
    """Every field of a ``ShadingData`` (floats, booleans, integers, an unsigned key) comes
    back as it was; an array of a ``TextureData`` is the caller's own (writes reach it)."""
    values = [float(k) + 0.25 for k in range(len(ShadingData._fields))]
    sd = ShadingData(*values)._replace(backfacing=True, allocate=False, reflective_caustics=True,
                                       refractive_caustics=False, bump_correction=True,
                                       prim=np.int64(-7), obj=np.int64(123456789012), path_flags=np.int64(5),
                                       depth=np.int64(2), diffuse_depth=np.int64(1), glossy_depth=np.int64(0),
                                       transmission_depth=np.int64(3), transparent_depth=np.int64(4),
                                       rng=np.uint64(2**64 - 3))
    tex = NO_TEXTURES._replace(pixf=np.zeros(5, np.float32))
    assert _through_refs(sd, tex) == sd
    np.testing.assert_array_equal(tex.pixf, np.arange(5))


@njit(_nrt=False)
def _texel_sum(tex_ref):
    """Called: sums the float texels of the ``TextureData`` it has the address of."""
    pixf = deref(tex_ref).pixf
    total = 0.0
    for k in range(pixf.shape[0]):
        total += pixf[k]
    return total


_TEX = ShaderScene._fields.index("tex")


@njit(_nrt=False)
def _through_field(scene):
    scene_ref = by_ref(scene)
    return _texel_sum(field_ref(scene_ref, _TEX)), deref(scene_ref).verts.shape[0]


def test_a_field_reference_reads_that_field_of_the_tuple():
    """``field_ref`` of a ``ShaderScene``'s ``tex`` is the address of that field: what is
    read through it is that ``TextureData`` (a wrong index would give another field, and
    numba would not compile the call)."""
    tex = NO_TEXTURES._replace(pixf=np.arange(1.0, 5.0, dtype=np.float32))
    verts, tris, local = NO_MESH
    scene = ShaderScene(np.zeros((0, 4), np.int32), tex, np.zeros((3, 3)), tris, local)
    assert _through_field(scene) == (10.0, 3)


@njit(inline="always")
def _scaled(x, k):
    y = x * k
    if y > 1.0:
        y = 1.0 + 0.5 * (y - 1.0)
    return y


@njit(inline="always")
def _twice(x, k):
    a = _scaled(x, k)
    b = _scaled(a, k)
    return a + b


def test_inlined_calls_compute_what_python_does():
    xs = np.linspace(-2.0, 3.0, 41)
    expected = np.array([_twice.py_func(x, 0.7) - _scaled.py_func(x, 1.4) for x in xs])
    np.testing.assert_array_equal(_fresh_caller()(xs, 0.7), expected)


def test_block_copies_share_one_copy_of_their_scope():
    func_ir = compiler.run_frontend(_scaled.py_func)      # an if: several blocks
    blocks = list(func_ir.blocks.values())
    assert len(blocks) > 1 and all(b.scope is blocks[0].scope for b in blocks)
    copies = [inlining.copy.deepcopy(b) for b in blocks]
    scope = copies[0].scope
    assert scope is not blocks[0].scope
    assert all(c.scope is scope for c in copies)
    assert scope.localvars._con.keys() == blocks[0].scope.localvars._con.keys()
    # the copy is the callee's own: renaming its variables leaves the original alone
    before = len(blocks[0].scope.localvars._con)
    scope.redefine("$inlined_name", ir.Loc("test", 0))
    assert len(blocks[0].scope.localvars._con) == before
    again = inlining.copy.deepcopy(blocks[0])       # after a change, a new copy
    assert again.scope is not scope and "$inlined_name" not in again.scope.localvars._con


def test_prepared_inlinee_is_handed_out_fresh():
    worker = inlining.InlineWorker(cpu_target.typing_context, cpu_target.target_context,
                                   {}, object(), compiler.Flags())
    first = worker.run_untyped_passes(_twice.py_func)
    second = worker.run_untyped_passes(_twice.py_func)
    assert first.func_id.unique_name != second.func_id.unique_name
    assert first.blocks is not second.blocks
    assert all(first.blocks[k] is not second.blocks[k] for k in first.blocks)
    assert first.blocks.keys() == second.blocks.keys()


def _fresh_caller():
    """``_twice(x, k) - _scaled(x, 2k)`` over an array, in new dispatchers (numba compiles
    each once): one callee inlined at two call sites in one caller and again a level up."""
    scaled = njit(inline="always")(_scaled.py_func)

    @njit(inline="always")
    def twice(x, k):
        a = scaled(x, k)
        b = scaled(a, k)
        return a + b

    @njit
    def caller(xs, k):
        out = np.empty_like(xs)
        for i in range(xs.shape[0]):
            out[i] = twice(xs[i], k) - scaled(xs[i], 2.0 * k)
        return out
    return caller


def _machine_code(caller) -> str:
    caller(np.linspace(-2.0, 3.0, 5), 0.7)
    (asm,) = caller.inspect_asm().values()
    # mangled names carry a per-process counter of compiled functions ("B3v11"), and the
    # sizes of the strings that spell them out change when it gains a digit
    asm = re.sub(r"\n\t\.size\t[^\n]*", "", asm)
    return re.sub(r"B\d+v\d+B", "B_v_B", asm)


def test_the_changes_leave_the_machine_code_as_it_was(monkeypatch):
    changed = _machine_code(_fresh_caller())
    monkeypatch.setattr(inlining, "copy", copy)
    monkeypatch.setattr(inlining.InlineWorker, "run_untyped_passes",
                        inlining.InlineWorker.run_untyped_passes.__wrapped__)
    monkeypatch.setattr(ssa, "_run_ssa", ssa._run_ssa.__wrapped__)
    live_map = analysis.compute_live_map.__wrapped__
    monkeypatch.setattr(analysis, "compute_live_map", live_map)
    monkeypatch.setattr(ir_utils, "compute_live_map", live_map)
    assert _machine_code(_fresh_caller()) == changed


def _loops(xs, k):
    """Variables assigned in several blocks and loops (phi nodes), one used before it is
    assigned on some paths, and one defined only in a branch."""
    total = 0.0
    best = -1.0
    for i in range(xs.shape[0]):
        y = xs[i] * k
        if y > best:
            best = y
            where = i
        elif y < 0.0:
            y = -y
            total -= y
            continue
        total += y
        while y > 1.0:
            y *= 0.5
            total += y
    return total, best, where


# Python functions whose IR (before inlining) the SSA and liveness changes are checked on:
# the synthetic one and two kernels of a hundred blocks and more.
_IR_SOURCES = [_loops, path.shade.py_func, light_tracing.extend_light_paths.py_func]


def _statements(blocks):
    return {label: [str(stmt) for stmt in block.body] for label, block in blocks.items()}


@pytest.mark.parametrize("fn", _IR_SOURCES, ids=lambda fn: fn.__name__)
def test_ssa_reconstruction_is_numbas(fn):
    blocks = compiler.run_frontend(fn).blocks
    mine, numbas = copy.deepcopy(blocks), copy.deepcopy(blocks)    # each with its own scope
    expected = _statements(ssa._run_ssa.__wrapped__(numbas))
    got = _statements(ssa._run_ssa(mine))
    assert list(got) == list(expected)
    assert got == expected
    assert any("phi" in stmt for body in got.values() for stmt in body)


@pytest.mark.parametrize("fn", _IR_SOURCES, ids=lambda fn: fn.__name__)
def test_live_map_is_numbas(fn):
    blocks = ssa._run_ssa(compiler.run_frontend(fn).blocks)
    cfg = analysis.compute_cfg_from_blocks(blocks)
    usedefs = analysis.compute_use_defs(blocks)
    expected = analysis.compute_live_map.__wrapped__(cfg, blocks, usedefs.usemap, usedefs.defmap)
    got = analysis.compute_live_map(cfg, blocks, usedefs.usemap, usedefs.defmap)
    assert got == expected
    assert sum(map(len, got.values())) > 0
