"""What a process's new memory costs on this machine: the time to fill a fresh 256 MiB numpy
array, and to fill one again after freeing the first (memory the process has touched before).

Start-up work on large scenes (export, packing, the BVH) writes hundreds of MiB into fresh
memory, and on some machines (virtual machines, sandboxes) the first touch of a page costs
far more than the writing: there, the megabytes a render allocates set much of its start-up
time, for MC Engine and Cycles alike.  Each figure is the median of ``--runs`` fresh
processes.

Run: python benchmarks/fresh_memory.py [--mib 256] [--runs 3]
"""
from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time

_CHILD = "--child"


def _child(mib: int) -> None:
    import numpy as np

    times = []
    for _ in range(2):
        start = time.perf_counter()
        a = np.empty(mib * 2**20 // 8)
        a[:] = 1.0
        times.append(time.perf_counter() - start)
        del a
    print(json.dumps(times))


def main() -> int:
    if len(sys.argv) > 2 and sys.argv[1] == _CHILD:
        _child(int(sys.argv[2]))
        return 0
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--mib", type=int, default=256)
    ap.add_argument("--runs", type=int, default=3)
    args = ap.parse_args()
    first, again = [], []
    for _ in range(args.runs):
        out = subprocess.run([sys.executable, __file__, _CHILD, str(args.mib)], check=True,
                             capture_output=True, text=True).stdout
        f, a = json.loads(out.strip().splitlines()[-1])
        first.append(f)
        again.append(a)
    f, a = statistics.median(first), statistics.median(again)
    print(f"fill {args.mib} MiB of fresh memory: {f * 1e3:.0f} ms ({f * 1e3 / args.mib:.2f} ms/MiB); "
          f"again after freeing it: {a * 1e3:.0f} ms ({a * 1e3 / args.mib:.2f} ms/MiB); "
          f"medians of {args.runs} processes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
