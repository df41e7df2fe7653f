"""Where MC Engine's render time goes, per compiled function: a ``perf`` profile of the kernels.

Renders blend_scenes/cornell_box.blend (the materials of ``bench_cornell.py``: the file's,
the default Principled BSDF or textured) once to load the kernels, writes
``/tmp/perf-<pid>.map`` naming every function numba compiled (the address of each
overload's symbols in its code library; perf reads that file for code it finds no ELF file
for), then records ``perf record`` samples of this process over a few renders and prints
each function's share of the samples, the shared libraries' (Embree, libm) included.

Functions inlined into another (``jit.device``) count as the one they are inlined into; a
``jit.function`` is its own line. Needs Linux ``perf`` (perf_event_paranoid <= 2 for one's
own processes).

Run: python benchmarks/profile_kernels.py [--materials file|principled|textured]
                                          [--samples N] [--renders K] [--top T]
"""
from __future__ import annotations

import argparse
import collections
import gc
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import bench_cornell

from mcengine import samplers


def write_perf_map() -> int:
    """Write /tmp/perf-<pid>.map for every function numba compiled in this process; returns
    how many symbols it names."""
    from numba.core.registry import CPUDispatcher

    symbols = {}
    for obj in gc.get_objects():
        if not isinstance(obj, CPUDispatcher):
            continue
        for cres in obj.overloads.values():
            library = cres.library
            module = getattr(library, "_shared_module", None) or getattr(library, "_final_module", None)
            if module is None:
                continue
            engine = library._codegen._engine
            for fn in module.functions:
                if fn.is_declaration:
                    continue
                address = engine.get_function_address(fn.name)
                if address:
                    symbols.setdefault(address, fn.name)
    addresses = sorted(symbols)
    with open(f"/tmp/perf-{os.getpid()}.map", "w") as fh:
        for k, address in enumerate(addresses):
            gap = addresses[k + 1] - address if k + 1 < len(addresses) else 1 << 16
            fh.write(f"{address:x} {min(gap, 1 << 24):x} {symbols[address]}\n")
    return len(addresses)


def short_name(symbol: str) -> str:
    """'mcengine.kernels.path.shade' from numba's mangled name (or the symbol as it is)."""
    m = re.match(r"(?:cfunc\.)?_ZN(?:7cpython)?((?:\d+[A-Za-z_]\w*?)+)B\d", symbol)
    if not m:
        return symbol
    parts, rest = [], m.group(1)
    while rest:
        n = re.match(r"\d+", rest).group(0)
        parts.append(rest[len(n):len(n) + int(n)])
        rest = rest[len(n) + int(n):]
    return ".".join(parts)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--materials", choices=("file", "principled", "textured"), default="principled")
    ap.add_argument("--samples", type=int, default=128)
    ap.add_argument("--resolution", type=int, default=256)
    ap.add_argument("--renders", type=int, default=2)
    ap.add_argument("--top", type=int, default=20)
    args = ap.parse_args(argv)
    if shutil.which("perf") is None:
        print("profile_kernels: Linux 'perf' is not installed", file=sys.stderr)
        return 2

    import bpy

    from mcengine_blender.batch.render import ensure_registered, open_scene, render_scene
    from mcengine_blender.batch.settings import make_unbiased

    ensure_registered()

    def render(samples):
        scene = open_scene(bench_cornell.SCENE)
        make_unbiased(scene)
        scene.mcengine.sampler = samplers.get(samplers.DEFAULT).enum_id
        if args.materials in ("principled", "textured"):
            bench_cornell.to_default_principled(bpy)
        if args.materials == "textured":
            bench_cornell.to_textured(bpy)
        return render_scene(scene, "mcengine", samples=samples, seed=0,
                            resolution=(args.resolution, args.resolution))

    render(1)
    count = write_perf_map()
    with tempfile.TemporaryDirectory(prefix="mcengine_perf_") as folder:
        data = Path(folder) / "perf.data"
        recorder = subprocess.Popen(["perf", "record", "-q", "-F", "499", "-o", str(data),
                                     "-p", str(os.getpid())],
                                    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(1.0)
        seconds = sum(render(args.samples).seconds for _ in range(args.renders))
        recorder.send_signal(2)
        recorder.wait()
        report = subprocess.run(["perf", "report", "-i", str(data), "--no-children", "--stdio",
                                 "-g", "none", "--sort", "dso,sym", "--field-separator", "|"],
                                capture_output=True, text=True).stdout
    shares = collections.Counter()
    for line in report.splitlines():
        fields = line.split("|")
        if line.startswith("#") or len(fields) < 3 or not fields[0].strip().endswith("%"):
            continue
        share, dso = float(fields[0].strip().rstrip("%")), fields[1].strip()
        symbol = re.sub(r"^\[[.k]\]\s*", "", fields[2].strip())
        if dso.startswith("[JIT]"):
            shares[short_name(symbol)] += share
        else:
            shares[dso] += share
    print(f"cornell_box, {args.materials} materials, {args.resolution}x{args.resolution}, "
          f"{args.samples} spp x {args.renders} renders ({seconds:.1f} s); {count} compiled "
          f"symbols named")
    print(f"{'share':>7s}  function (or shared library)")
    for name, share in shares.most_common(args.top):
        print(f"{share:6.2f}%  {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
