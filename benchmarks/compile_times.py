"""How long a cold compile of the kernels takes, and which compiled functions it goes to.

Compiles into an empty numba cache (a temporary ``NUMBA_CACHE_DIR``, removed afterwards),
as the first render after installing does: the warm-up scene of ``mcengine.warmup``
rendered with each integrator asked for (default: the path tracer, which also compiles the
shader evaluator), in this process.  Prints the seconds per integrator and the functions
that took longest to compile by themselves (a called ``jit.function`` or kernel is a
compile of its own; what is inlined into it counts as its own time), from numba's compile
events.  Numba compiles on one core, so run it with nothing else on the machine, or
compare figures of one run.

Run: python benchmarks/compile_times.py [INTEGRATOR ...] [--all] [--top N]
"""
from __future__ import annotations

import argparse
import collections
import os
import shutil
import sys
import tempfile
import time


class _CompileTimer:
    """Listens to numba's ``numba:compile`` events: seconds per compiled function, minus its
    nested compiles (a callee numba compiles while typing its caller)."""

    def __init__(self):
        self.own = collections.Counter()
        self._open = []      # [name, started, seconds of nested compiles]

    def on_start(self, event):
        dispatcher = (event.data or {}).get("dispatcher")
        fn = getattr(dispatcher, "py_func", None)
        name = f"{fn.__module__}.{fn.__qualname__}" if fn is not None else str(dispatcher)
        self._open.append([name, time.perf_counter(), 0.0])

    def on_end(self, event):
        name, started, nested = self._open.pop()
        took = time.perf_counter() - started
        self.own[name] += took - nested
        if self._open:
            self._open[-1][2] += took


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("integrators", nargs="*", help="integrators to compile (default: path)")
    parser.add_argument("--all", action="store_true", help="every integrator, as the warm-up does")
    parser.add_argument("--top", type=int, default=15, help="functions to list")
    args = parser.parse_args(argv)

    cache = tempfile.mkdtemp(prefix="mcengine-cold-cache-")
    os.environ["NUMBA_CACHE_DIR"] = cache    # before numba is imported: an empty cache
    try:
        from numba.core import event

        from mcengine import integrators
        from mcengine.session import RenderSession
        from mcengine.warmup import warm_up_scene

        names = list(integrators.NAMES) if args.all else (args.integrators or [integrators.DEFAULT])
        names.sort(key=lambda n: n != integrators.DEFAULT)
        for name in names:
            integrators.get(name)
        timer = type("CompileTimer", (_CompileTimer, event.Listener), {})()
        event.register("numba:compile", timer)
        total = 0.0
        for name in names:
            start = time.perf_counter()
            RenderSession(warm_up_scene(name), threads=1).run()
            took = time.perf_counter() - start
            total += took
            print(f"{name:>24}: {took:7.1f} s")
        print(f"{'all':>24}: {total:7.1f} s")
        print(f"\nlongest compiles (own seconds, nested compiles excluded), {len(timer.own)} functions:")
        for fn, seconds in timer.own.most_common(args.top):
            print(f"  {seconds:7.1f} s  {fn}")
    finally:
        shutil.rmtree(cache, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
