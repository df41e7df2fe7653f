"""Faster ways for numba to do three of its compile steps, with the same results.

The kernels inline most of what they call (``jit.device``), so numba's passes over one
kernel see thousands of blocks and tens of thousands of variables; three of them took
time that grows as blocks times variables, and were most of a cold compile
(``benchmarks/compile_times.py``).  Each
change below computes what numba's own code computes, and is left out if this numba lays
the code out otherwise (``apply``).  ``tests/core/test_jit.py`` compares each with the
original, and the machine code of a compiled function with and without them.

* Inlining (``inline_closurecall``): numba copied the callee's IR before splicing it in
  with one ``copy.deepcopy`` per block, and each block refers to the function's scope,
  which holds every variable, so every block copied the whole variable table again.  The
  blocks of one IR now share one copy of their scope, as they shared the scope they were
  copied from.  For every call site numba also prepared the callee's IR from its bytecode
  again, inlining the callee's own callees again, and so on down the call tree; the IR it
  prepares is only ever copied, so it is kept and handed out again, under a fresh function
  identity, from which numba names the inlined variables as a fresh run would.  (A cold
  compile of the path tracer took 898 s before this change, 529 s after.)
* SSA reconstruction (``ssa._run_ssa``): for each variable assigned more than once numba
  walked every statement of the function twice (renaming its definitions, then its uses).
  Only the blocks that define, respectively use, that variable can change, so only those
  are walked, in the same order (the names of new variables and phi nodes come out the
  same); the others are kept as they are.
* Liveness (``analysis.compute_live_map``, run after most passes): the sets of variables
  that reach and that are live at each block, propagated over the control-flow graph
  until nothing changes, are held as bit sets (Python integers, one bit per variable)
  while they propagate, rather than as sets of names.  (With the SSA change: every
  integrator, cold, in one process, 877 s before, 637 s after; ``path.shade`` alone
  299 s before, 140 s after.)
"""
from __future__ import annotations

import copy
from collections import defaultdict

import numpy as np

__all__ = ["apply"]


def apply() -> None:
    """Install the three changes (each once, and only on a numba laid out as expected)."""
    _speed_up_inlining()
    _speed_up_ssa()
    _speed_up_live_map()


# -- inlining ------------------------------------------------------------------------------
def _speed_up_inlining() -> None:
    try:
        from numba.core import bytecode, ir
        from numba.core import inline_closurecall as inlining
    except ImportError:         # pragma: no cover - another numba layout
        return
    worker = getattr(inlining, "InlineWorker", None)
    original = getattr(worker, "run_untyped_passes", None)
    if original is None or getattr(inlining, "copy", None) is not copy \
            or hasattr(original, "__wrapped__"):
        return

    class BlockCopier:
        """``copy`` as ``inline_closurecall`` sees it: blocks of one scope share its copy."""

        def __init__(self):
            self.last = None      # (scope, its copy, their numbers of variables)

        def deepcopy(self, x, memo=None):
            if memo is not None or not isinstance(x, ir.Block):
                return copy.deepcopy(x, memo)
            scope, last = x.scope, self.last
            if last is None or last[0] is not scope or \
                    (len(scope.localvars._con), len(last[1].localvars._con)) != last[2]:
                shared = copy.deepcopy(scope)
                last = self.last = (scope, shared,
                                    (len(scope.localvars._con), len(shared.localvars._con)))
            return copy.deepcopy(x, {id(scope): last[1]})

    prepared = {}

    def run_untyped_passes(self, func, enable_ssa=False):
        key = (func, enable_ssa)
        if key not in prepared:
            prepared[key] = original(self, func, enable_ssa)
        else:
            self.flags.enable_ssa = enable_ssa     # as the pipeline run sets it
        func_ir = prepared[key].copy()
        func_ir.func_id = bytecode.FunctionIdentity.from_function(func)
        return func_ir

    run_untyped_passes.__wrapped__ = original
    inlining.copy = BlockCopier()
    worker.run_untyped_passes = run_untyped_passes


# -- SSA reconstruction --------------------------------------------------------------------
def _speed_up_ssa() -> None:
    try:
        from numba.core import ir, ssa
    except ImportError:         # pragma: no cover
        return
    needed = ("_run_ssa", "compute_cfg_from_blocks", "_iterated_domfronts",
              "_find_defs_violators", "_CacheListVars", "_make_states", "_FreshVarHandler",
              "_FixSSAVars", "_compute_phi_locations", "_run_ssa_block_pass")
    if not all(hasattr(ssa, name) for name in needed) or hasattr(ssa._run_ssa, "__wrapped__"):
        return          # pragma: no cover - another numba layout, or installed already

    def rewrite(blocks, labels, order, states, handler):
        """numba's ``_run_block_rewrite`` over the blocks ``labels`` only (in the order of
        ``blocks``): a new dict in which the other blocks are the same objects."""
        newblocks = dict(blocks)
        for label in sorted(labels, key=order.__getitem__):
            blk = blocks[label]
            states["label"] = label
            states["block"] = blk
            newblk = ir.Block(scope=blk.scope, loc=blk.loc)
            newblk.body = list(ssa._run_ssa_block_pass(states, blk, handler))
            newblocks[label] = newblk
        return newblocks

    def run_ssa(blocks):
        if not blocks:
            return {}
        cfg = ssa.compute_cfg_from_blocks(blocks)
        df_plus = ssa._iterated_domfronts(cfg)
        violators = ssa._find_defs_violators(blocks, cfg)
        cache_list_vars = ssa._CacheListVars()
        # Where each variable is defined (assigned) and used: the statements that numba's
        # two handlers read (an assignment's target and value, another statement's variables).
        order = {label: k for k, label in enumerate(blocks)}
        defined_in, used_in = defaultdict(set), defaultdict(set)
        for label, blk in blocks.items():
            for stmt in blk.body:
                if isinstance(stmt, ir.Assign):
                    defined_in[stmt.target.name].add(label)
                    value = stmt.value
                    if isinstance(value, ir.Inst):
                        used = cache_list_vars.get(value)
                    elif isinstance(value, ir.Var):
                        used = (value,)
                    else:
                        continue
                else:
                    used = cache_list_vars.get(stmt)
                for var in used:
                    used_in[var.name].add(label)
        for varname in violators:
            # The definitions get fresh names (numba's _fresh_vars) ...
            states = ssa._make_states(blocks)
            states["varname"] = varname
            states["defmap"] = defmap = defaultdict(list)
            blocks = rewrite(blocks, defined_in[varname], order, states, ssa._FreshVarHandler())
            # ... and the uses the definition that reaches them, through phi nodes where
            # needed (numba's _fix_ssa_vars).
            states = ssa._make_states(blocks)
            states["varname"] = varname
            states["defmap"] = defmap
            states["phimap"] = phimap = defaultdict(list)
            states["cfg"] = cfg
            states["phi_locations"] = ssa._compute_phi_locations(df_plus, defmap)
            blocks = rewrite(blocks, used_in[varname], order, states,
                             ssa._FixSSAVars(cache_list_vars))
            for label, philist in phimap.items():
                blk = blocks[label]
                newblk = ir.Block(scope=blk.scope, loc=blk.loc)
                newblk.body = philist + blk.body
                blocks[label] = newblk
        if ssa.compute_cfg_from_blocks(blocks) != cfg:
            from numba.core import errors
            raise errors.CompilerError("CFG mutated in SSA pass")
        return blocks

    run_ssa.__wrapped__ = ssa._run_ssa
    ssa._run_ssa = run_ssa


# -- liveness ------------------------------------------------------------------------------
def _speed_up_live_map() -> None:
    try:
        from numba.core import analysis, ir_utils
    except ImportError:         # pragma: no cover
        return
    original = getattr(analysis, "compute_live_map", None)
    if original is None or hasattr(original, "__wrapped__") \
            or getattr(ir_utils, "compute_live_map", None) is not original:
        return          # pragma: no cover

    def compute_live_map(cfg, blocks, var_use_map, var_def_map):
        """The variables live at the entry of each block, as numba's ``compute_live_map``
        finds them: the ones used there or later, along paths on which a definition of
        them reaches the block (numba's ``def_reach``) and none follows before the use."""
        topo_order = cfg.topo_order()
        names = sorted({name for s in (*var_use_map.values(), *var_def_map.values())
                        for name in s})
        index = {name: k for k, name in enumerate(names)}
        nbytes = (len(names) + 7) // 8

        def bits(of):
            buf = bytearray(nbytes)
            for name in of:
                k = index[name]
                buf[k >> 3] |= 1 << (k & 7)
            return int.from_bytes(buf, "little")

        use = {offset: bits(s) for offset, s in var_use_map.items()}
        define = {offset: bits(s) for offset, s in var_def_map.items()}
        succs = {offset: [out for out, _ in cfg.successors(offset)] for offset in topo_order}
        preds = {offset: [inc for inc, _ in cfg.predecessors(offset)] for offset in topo_order}

        reach = defaultdict(int)        # definitions (or uses) reaching the block's entry
        changed = True
        while changed:
            changed = False
            for offset in topo_order:
                here = reach[offset] | define[offset] | use[offset]
                if here != reach[offset]:
                    reach[offset] = here
                    changed = True
                for out in succs[offset]:
                    grown = reach[out] | here
                    if grown != reach[out]:
                        reach[out] = grown
                        changed = True

        live = {offset: use[offset] for offset in blocks}
        changed = True
        while changed:
            changed = False
            for offset in reversed(topo_order):
                here = live[offset]
                for inc in preds[offset]:
                    grown = live[inc] | (here & reach[inc] & ~define[inc])
                    if grown != live[inc]:
                        live[inc] = grown
                        changed = True

        table = np.array(names, dtype=object)

        def as_names(value):
            if not value:
                return set()
            flags = np.unpackbits(np.frombuffer(value.to_bytes(nbytes, "little"), np.uint8),
                                  bitorder="little")
            return set(table[np.flatnonzero(flags)].tolist())

        return {offset: as_names(value) for offset, value in live.items()}

    compute_live_map.__wrapped__ = original
    analysis.compute_live_map = compute_live_map
    ir_utils.compute_live_map = compute_live_map
