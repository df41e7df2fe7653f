"""Where MC Engine's render time goes, per compiled function: a ``perf`` profile of the kernels.

Renders blend_scenes/cornell_box.blend (the materials of ``bench_cornell.py``: the file's,
the default Principled BSDF or textured), or the .blend given with ``--scene``, once to load the kernels, writes
``/tmp/perf-<pid>.map`` naming every function numba compiled (the address of each
overload's symbols in its code library; perf reads that file for code it finds no ELF file
for), then records ``perf record`` samples of this process over a few renders and prints
each function's share of the samples, the shared libraries' (Embree, libm) included.

Functions inlined into another (``jit.device``) count as the one they are inlined into; a
``jit.function`` is its own line. Needs Linux ``perf`` (perf_event_paranoid <= 2 for one's
own processes).

``--annotate NAME`` also shows where inside one compiled function (e.g. ``path.shade``)
the samples fall: it copies the function's machine code out of this process, disassembles
it with ``objdump`` and prints the instructions with the most samples, each after the
instructions before it, with the functions its calls go to named (numba compiles without
debug information, so the listing is machine code, not source lines).

Run: python benchmarks/profile_kernels.py [--scene FILE.blend] [--materials file|principled|textured]
                                          [--samples N] [--resolution N] [--renders K] [--top T]
                                          [--annotate NAME [--context C] [--listing FILE]]
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


def write_perf_map() -> dict:
    """Write /tmp/perf-<pid>.map for every function numba compiled in this process; returns
    {address: (symbol, size)} of what it names."""
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
    table = {}
    with open(f"/tmp/perf-{os.getpid()}.map", "w") as fh:
        for k, address in enumerate(addresses):
            gap = addresses[k + 1] - address if k + 1 < len(addresses) else 1 << 16
            table[address] = (symbols[address], min(gap, 1 << 24))
            fh.write(f"{address:x} {table[address][1]:x} {symbols[address]}\n")
    return table


def annotate(data: Path, table: dict, name: str, top: int, context: int,
             listing_path: str | None = None) -> None:
    """Print the instructions of the compiled function ``name`` (a short name such as
    'path.shade', matched at the end) with the most samples in ``data``."""
    matches = [(a, s, n) for a, (s, n) in table.items() if short_name(s).endswith(name)]
    if not matches:
        print(f"annotate: no compiled function named {name!r}")
        return
    script = subprocess.run(["perf", "script", "-i", str(data), "-F", "ip"],
                            capture_output=True, text=True).stdout
    ips = [int(word, 16) for word in script.split()]
    # A name has several symbols (the function, its CPython wrapper, one per overload): take
    # the one the samples fall in.
    address, symbol, size = max(matches, key=lambda m: sum(m[0] <= ip < m[0] + m[2] for ip in ips))
    counts = collections.Counter()
    for ip in ips:
        if address <= ip < address + size:
            counts[ip] += 1
    inside = sum(counts.values())
    with tempfile.NamedTemporaryFile(suffix=".bin") as code:
        code.write(read_own_memory(address, size))
        code.flush()
        listing = subprocess.run(["objdump", "-D", "-b", "binary", "-m", "i386:x86-64",
                                  "--no-show-raw-insn", f"--adjust-vma={address:#x}", code.name],
                                 capture_output=True, text=True).stdout
    names = {a: short_name(s) for a, (s, _) in table.items()}
    rows = []
    for line in listing.splitlines():
        m = re.match(r"\s*([0-9a-f]+):\s*(.*)", line)
        if not m:
            continue
        insn = m.group(2).strip()
        # numba calls through a register loaded with the target's address: name both.
        target = re.search(r"(?:call|movabs)\s+\$?0x([0-9a-f]+)", insn)
        if target and int(target.group(1), 16) in names:
            insn += f"    <{names[int(target.group(1), 16)]}>"
        rows.append((int(m.group(1), 16), insn))
    index = {a: i for i, (a, _) in enumerate(rows)}
    print(f"\n{short_name(symbol)}: {size} bytes of code, {inside} of {len(ips)} samples "
          f"({100.0 * inside / max(len(ips), 1):.1f} %); its {top} instructions with most samples:")
    for ip, n in counts.most_common(top):
        print(f"-- {100.0 * n / max(inside, 1):5.2f} % of the function's samples at +{ip - address:#x}")
        i = index.get(ip)
        for a, insn in rows[max(i - context, 0):i + 1] if i is not None else []:
            mark = f"{counts[a]:5d}" if counts.get(a) else "     "
            print(f"   {mark} +{a - address:#07x}  {insn}")
    if listing_path:
        with open(listing_path, "w") as out:
            for a, insn in rows:
                mark = f"{counts[a]:5d}" if counts.get(a) else "     "
                out.write(f"   {mark} +{a - address:#07x}  {insn}\n")


def read_own_memory(address: int, size: int) -> bytes:
    """Up to ``size`` bytes of this process's memory from ``address``, stopping at the first
    page that is not mapped (a perf-map size is the gap to the next symbol, which may run past
    the end of the compiled code; reading it through a pointer crashed the process)."""
    out = bytearray()
    with open("/proc/self/mem", "rb", buffering=0) as mem:
        while len(out) < size:
            step = min(4096 - (address + len(out)) % 4096, size - len(out))
            try:
                chunk = os.pread(mem.fileno(), step, address + len(out))
            except OSError:
                break
            if not chunk:
                break
            out += chunk
    return bytes(out)


def short_name(symbol: str) -> str:
    """'mcengine.kernels.path.shade' from numba's mangled name (or the symbol as it is)."""
    m = re.match(r"(?:cfunc\.)?_ZN(?:7cpython)?((?:\d+[A-Za-z_]\w*?)+)B\d", symbol)
    if not m:
        return symbol
    parts, rest = [], m.group(1)
    while rest:
        n = re.match(r"\d*", rest).group(0)
        if not n:
            return symbol
        parts.append(rest[len(n):len(n) + int(n)])
        rest = rest[len(n) + int(n):]
    return ".".join(parts)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", type=Path, default=bench_cornell.SCENE,
                    help="the .blend to render (default: the Cornell box)")
    ap.add_argument("--materials", choices=("file", "principled", "textured"),
                    help="the Cornell box's materials as bench_cornell.py sets them (default: "
                         "principled for the Cornell box, the file's for any other scene)")
    ap.add_argument("--samples", type=int, default=128)
    ap.add_argument("--resolution", type=int, default=256)
    ap.add_argument("--renders", type=int, default=2)
    ap.add_argument("--top", type=int, default=20)
    ap.add_argument("--annotate", metavar="NAME",
                    help="also show the hottest instructions of this compiled function")
    ap.add_argument("--context", type=int, default=6,
                    help="instructions shown before each hot one (with --annotate)")
    ap.add_argument("--listing", metavar="FILE",
                    help="write the annotated function's whole listing, samples per "
                         "instruction, to FILE (with --annotate)")
    args = ap.parse_args(argv)
    if args.materials is None:
        args.materials = "principled" if args.scene == bench_cornell.SCENE else "file"
    if shutil.which("perf") is None:
        print("profile_kernels: Linux 'perf' is not installed", file=sys.stderr)
        return 2

    import bpy

    from mcengine_blender.batch.render import ensure_registered, open_scene, render_scene
    from mcengine_blender.batch.settings import make_unbiased

    ensure_registered()

    def render(samples):
        scene = open_scene(args.scene)
        make_unbiased(scene)
        scene.mcengine.sampler = samplers.get(samplers.DEFAULT).enum_id
        if args.materials in ("principled", "textured"):
            bench_cornell.to_default_principled(bpy)
        if args.materials == "textured":
            bench_cornell.to_textured(bpy)
        return render_scene(scene, "mcengine", samples=samples, seed=0,
                            resolution=(args.resolution, args.resolution))

    render(1)
    table = write_perf_map()
    count = len(table)
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
        if args.annotate:
            annotate(data, table, args.annotate, args.top, args.context, args.listing)
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
    print(f"{args.scene.stem}, {args.materials} materials, {args.resolution}x{args.resolution}, "
          f"{args.samples} spp x {args.renders} renders ({seconds:.1f} s); {count} compiled "
          f"symbols named")
    print(f"{'share':>7s}  function (or shared library)")
    for name, share in shares.most_common(args.top):
        print(f"{share:6.2f}%  {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
