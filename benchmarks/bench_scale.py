"""How MC Engine and Cycles scale with triangles, pixels and images: start-up, speed and memory.

Scenes (benchmarks/scale_scene.py, written to a temporary folder) hold a smooth
height field of 1k to 4M triangles in an open three-walled room with an area
light.  Three sweeps (``--sweeps`` chooses):

* triangles (1k, 10k, 100k, 1M; 4M with ``--full``) at ``--resolution`` (512 x 512);
* resolutions (256 x 256, 1024 x 1024, 1920 x 1080, 3840 x 2160) at 100k triangles;
* images: the 100k scene with 1 and 4 of its surfaces textured by packed 8-bit images of
  4096 x 4096 texels, at ``--resolution`` (each render loads and converts them).

Every (engine, scene, resolution) is measured in a fresh process, so that its peak
memory is its own: the process first renders a tiny scene (kernels loaded, as
after any earlier render), then opens the scene, notes its resident memory
("Blender with the scene loaded"), renders 1 sample per pixel and then S samples
(S so that a render holds about ``--paths`` paths, at least 2), and notes the
peak resident memory.  Figures:

* first image: wall time of the 1-sample render call (export or sync, BVH, the
  first sample of every pixel);
* sync: each engine's ``synchronization_time`` from the image's metadata, its total time
  less its render time (Cycles' blender/session.cpp; MC Engine's the same by definition,
  ``RenderStats.metadata``; 10 ms resolution): everything before sampling, so for Cycles
  its scene sync, BVH build and device updates, for MC Engine its export, scene
  preparation, BVH and kernel loading;
* MC Engine: its export (Blender -> scene description), scene preparation (packing,
  light tables, wall time), BVH (Embree; built beside the packing when nothing moves, so
  the two overlap) and kernel loading, from its own timers;
* the rest of the start-up, estimated: first image minus sync minus one sample at the
  measured rate (outside both engines' total time: Blender's side of the render call);
* Mpaths/s: the extra paths of the S-sample render over the 1-sample render per
  extra second (marginal, as in bench_cornell.py);
* memory: peak resident memory of the process, the part above Blender with the
  scene loaded ("render's own"), and for MC Engine its film and wavefront buffers
  and what mcengine/memory.py estimated before rendering.

Writes ``scale.csv`` and ``scale.png`` (matplotlib) into ``--out`` (default
out/bench_scale/) and prints a Markdown table.  A default run takes about 10
minutes on 2 cores; ``--full`` adds the 4M-triangle scene, 4K at 1M and 4M
triangles, and 4K at 100k triangles with 8 samples, to show that memory does not
grow with samples (about 30 minutes more).

Run: python benchmarks/bench_scale.py [--full] [--engines mcengine,cycles]
                                      [--sweeps triangles,resolutions,images]
                                      [--resolution N] [--paths N] [--out DIR]
"""
from __future__ import annotations

import argparse
import csv
import gc
import json
import math
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
WARM_SCENE = REPO / "blend_scenes" / "cornell_box.blend"
TRIANGLES = (1_000, 10_000, 100_000, 1_000_000)
FULL_TRIANGLES = (4_000_000,)
RESOLUTIONS = ((256, 256), (1024, 1024), (1920, 1080), (3840, 2160))
RESOLUTION_SWEEP_TRIANGLES = 100_000
IMAGE_SWEEP = (1, 4)            # textured surfaces, each an image of IMAGE_SIZE^2 texels
IMAGE_SIZE = 4096
SWEEPS = ("triangles", "resolutions", "images")
FULL_4K_SAMPLES = 8
FIELDS = ("engine", "triangles", "images", "width", "height", "samples", "first_image_s", "export_s",
          "prepare_s", "bvh_s", "kernels_s", "sync_s", "startup_rest_s", "render_1spp_s",
          "render_s", "mpaths_per_s", "rss_scene_mib", "rss_peak_mib", "render_own_mib",
          "buffers_mib", "estimate_mib")
_CHILD = "--measure"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--full", action="store_true",
                    help="add 4M triangles, and 4K renders of the 1M and 4M scenes")
    ap.add_argument("--engines", default="mcengine,cycles")
    ap.add_argument("--resolution", type=int, default=512,
                    help="square resolution of the triangle sweep")
    ap.add_argument("--paths", type=float, default=4e6,
                    help="paths per measured render (sets its samples per pixel)")
    ap.add_argument("--sweeps", default=",".join(SWEEPS),
                    help=f"which sweeps to run, of {', '.join(SWEEPS)}")
    ap.add_argument("--out", type=Path, default=REPO / "out" / "bench_scale")
    args = ap.parse_args(argv)
    sweeps = {w.strip() for w in args.sweeps.split(",") if w.strip()}
    if not sweeps or sweeps - set(SWEEPS):
        print(f"bench_scale: --sweeps takes {', '.join(SWEEPS)}", file=sys.stderr)
        return 2
    engines = [e.strip() for e in args.engines.split(",") if e.strip()]
    if not engines or set(engines) - {"mcengine", "cycles"}:
        print("bench_scale: --engines takes mcengine, cycles or both", file=sys.stderr)
        return 2

    tri_sweep = TRIANGLES + (FULL_TRIANGLES if args.full else ())
    square = (args.resolution, args.resolution)
    # (triangles, textured surfaces, resolution, samples or None: from --paths)
    runs = [(t, 0, square, None) for t in tri_sweep] if "triangles" in sweeps else []
    if "resolutions" in sweeps:
        runs += [(RESOLUTION_SWEEP_TRIANGLES, 0, r, None) for r in RESOLUTIONS
                 if (RESOLUTION_SWEEP_TRIANGLES, 0, r, None) not in runs]
    if "images" in sweeps:
        runs += [(RESOLUTION_SWEEP_TRIANGLES, k, square, None) for k in IMAGE_SWEEP]
    if args.full and "triangles" in sweeps and "resolutions" in sweeps:
        # 4K with the big scenes, and with 4x the samples (memory must not grow with them).
        runs += [(t, 0, RESOLUTIONS[-1], None) for t in (1_000_000, 4_000_000)]
        runs += [(RESOLUTION_SWEEP_TRIANGLES, 0, RESOLUTIONS[-1], FULL_4K_SAMPLES)]
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench_scale_") as tmp:
        blends = {}
        for triangles, images in sorted({(t, k) for t, k, _r, _s in runs}):
            path = Path(tmp) / f"scale_{triangles}_{images}.blend"
            t0 = time.perf_counter()
            done = subprocess.run([sys.executable, str(Path(__file__).with_name("scale_scene.py")),
                                   str(triangles), str(path), str(images), str(IMAGE_SIZE)],
                                  capture_output=True, text=True)
            if done.returncode != 0:
                print(f"bench_scale: building the {triangles}-triangle scene failed:\n"
                      f"{done.stderr[-2000:]}", file=sys.stderr)
                return 1
            blends[triangles, images] = (path, int(done.stdout.split()[-1]))
            textured = f" with {images} image(s) of {IMAGE_SIZE}^2" if images else ""
            print(f"scene of {blends[triangles, images][1]:,} triangles{textured} built in "
                  f"{time.perf_counter() - t0:.1f} s", flush=True)
        for triangles, images, (w, h), samples in runs:
            path, count = blends[triangles, images]
            samples = samples or max(2, math.ceil(args.paths / (w * h)))
            for engine in engines:
                row = measure(engine, path, w, h, samples)
                row["triangles"], row["images"] = count, images
                rows.append(row)
                print(f"{engine:9s} {count:>10,} tris {images} img {w}x{h} {samples:3d} spp: "
                      f"first image {row['first_image_s']:.2f} s, {row['mpaths_per_s']:.2f} "
                      f"Mpaths/s, peak {row['rss_peak_mib']:.0f} MiB (render's own "
                      f"{row['render_own_mib']:.0f})", flush=True)
    args.out.mkdir(parents=True, exist_ok=True)
    write_csv(rows, args.out / "scale.csv")
    plot(rows, args.out / "scale.png", args.resolution)
    print()
    print(markdown_table(rows))
    print(f"\nwrote {args.out / 'scale.csv'} and {args.out / 'scale.png'}")
    return 0


def measure(engine: str, blend: Path, width: int, height: int, samples: int) -> dict:
    """Run one measurement in a fresh process (see the module docstring)."""
    done = subprocess.run([sys.executable, __file__, _CHILD, engine, str(blend), str(width),
                           str(height), str(samples)], capture_output=True, text=True)
    lines = [line for line in done.stdout.splitlines() if line.startswith("{")]
    if done.returncode != 0 or not lines:
        raise SystemExit(f"bench_scale: measuring {engine} on {blend.name} at {width}x{height} "
                         f"failed:\n{done.stderr[-3000:]}")
    return json.loads(lines[-1])


# -- the measuring process --------------------------------------------------------------------
def _child(engine: str, blend: str, width: int, height: int, samples: int) -> int:
    import bpy  # noqa: F401  (Blender as a module)

    from mcengine import memory
    from mcengine_blender import engine as mc_engine
    from mcengine_blender.batch.render import ENGINES, ensure_registered, open_scene
    from mcengine_blender.batch.settings import make_unbiased

    ensure_registered()
    timing = {}
    real_factory = mc_engine.session_factory

    def timed_factory(desc, threads=None):
        t0 = time.perf_counter()
        session = real_factory(desc, threads=threads)
        timing["session"] = time.perf_counter() - t0
        timing["desc"], timing["obj"] = desc, session
        return session

    mc_engine.session_factory = timed_factory
    bl_engine = ENGINES[engine]
    warm = open_scene(WARM_SCENE)
    make_unbiased(warm)
    _render(warm, bl_engine, 1, (32, 32))

    def run(spp):
        scene = open_scene(blend)
        make_unbiased(scene)
        rss = _rss_now()
        return _render(scene, bl_engine, spp, (width, height)), rss

    (first, sync), rss_scene = run(1)
    row = {"engine": engine, "width": width, "height": height, "samples": samples}
    if engine == "mcengine":
        stats = timing["obj"].stats
        row.update(export_s=mc_engine.last_render["export_seconds"], bvh_s=stats.time_bvh,
                   kernels_s=stats.time_kernels,
                   prepare_s=timing["session"] - stats.extra["bvh_wait"] - stats.time_kernels)
    # Let the 1-sample render's session go before the next one is built, as Blender does
    # between two renders (held here, it added its film and geometry to the peak).
    timing.clear()
    gc.collect()
    (full, _sync), _rss = run(samples)
    pixels = width * height
    rate = pixels * (samples - 1) / max(full - first, 1e-9)
    row.update(first_image_s=first, render_1spp_s=first, render_s=full, mpaths_per_s=rate / 1e6,
               rss_scene_mib=rss_scene / 2**20)
    row.update(sync_s=sync, startup_rest_s=max(first - sync - pixels / rate, 0.0))
    if engine == "mcengine":
        session, desc = timing["obj"], timing["desc"]
        row["buffers_mib"] = session.buffer_bytes / 2**20
        from mcengine.session import _Buffers
        need = memory.estimate(pixels, desc.geometry.num_triangles,
                               session.threads * _Buffers.bytes_for(session.batch_size, False),
                               mc_engine.BLENDER_BYTES_PER_PIXEL)
        row["estimate_mib"] = need.total / 2**20
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    row.update(rss_peak_mib=peak / 2**20, render_own_mib=(peak - rss_scene) / 2**20)
    print(json.dumps(row), flush=True)
    return 0


def _rss_now() -> int:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) * 1024
    return 0


def _render(scene, bl_engine, samples, resolution):
    """(wall seconds of the render call, the engine's own synchronisation seconds, or 0
    without them) of one render written to a temporary EXR (not read back)."""
    import bpy
    import OpenEXR

    from mcengine_blender.batch.settings import apply_overrides, set_image_format
    apply_overrides(scene, engine=bl_engine, samples=samples, seed=0, resolution=resolution)
    set_image_format(scene, "OPEN_EXR")
    fd, tmp = tempfile.mkstemp(suffix=".exr", prefix="bench_scale_")
    os.close(fd)
    try:
        scene.render.filepath = tmp
        scene.render.use_file_extension = False
        t0 = time.perf_counter()
        bpy.ops.render.render(write_still=True, scene=scene.name)
        seconds = time.perf_counter() - t0
        header = OpenEXR.File(tmp, header_only=True).header()
    finally:
        Path(tmp).unlink(missing_ok=True)
    sync = next((v for k, v in header.items() if k.endswith(".synchronization_time")), "0:0")
    return seconds, _clock_seconds(sync)


def _clock_seconds(text) -> float:
    """Blender's "MM:SS.ss" (or "HH:MM:SS.ss") time stamp in seconds."""
    value = 0.0
    for part in str(text).split(":"):
        value = value * 60.0 + float(part)
    return value


# -- output -----------------------------------------------------------------------------------
def write_csv(rows, path: Path) -> None:
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=FIELDS)
        writer.writeheader()
        for row in rows:
            writer.writerow({k: (f"{v:.4g}" if isinstance(v, float) else v)
                             for k, v in row.items() if k in FIELDS})
    os.replace(tmp, path)


def markdown_table(rows) -> str:
    """The rows as a Markdown table; a dash where a figure does not apply to the engine."""
    head = ("| engine | triangles | images | resolution | spp | first image (s) | export (s) | BVH (s) "
            "| sync, total - render (s) | other start-up, est. (s) | Mpaths/s | peak RSS (MiB) "
            "| above Blender and the scene (MiB) |")
    lines = [head, "|" + " --- |" * (head.count("|") - 1)]

    def cell(row, key):
        value = row.get(key)
        return "-" if value is None or value == "" else f"{float(value):.2f}"

    for r in rows:
        images = int(r.get("images") or 0)
        lines.append(f"| {r['engine']} | {int(r['triangles']):,} | "
                     f"{f'{images} x {IMAGE_SIZE}^2' if images else '-'} | {r['width']}x{r['height']} | "
                     f"{r['samples']} | {cell(r, 'first_image_s')} | {cell(r, 'export_s')} | "
                     f"{cell(r, 'bvh_s')} | {cell(r, 'sync_s')} | {cell(r, 'startup_rest_s')} | "
                     f"{cell(r, 'mpaths_per_s')} | {float(r['rss_peak_mib']):.0f} | "
                     f"{float(r['render_own_mib']):.0f} |")
    return "\n".join(lines)


def plot(rows, path: Path, square: int) -> None:
    """Four panels: first image and Mpaths/s against triangles, peak memory against
    triangles and against pixels."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(9, 6.5), dpi=80)
    styles = {"mcengine": ("MC Engine", "C0"), "cycles": ("Cycles", "C1")}
    rows = [r for r in rows if not int(r.get("images") or 0)]      # the untextured scenes
    for engine, (label, color) in styles.items():
        tri = sorted((r for r in rows if r["engine"] == engine and r["width"] == r["height"] == square),
                     key=lambda r: r["triangles"])
        res = sorted((r for r in rows if r["engine"] == engine
                      and r["triangles"] == max((x["triangles"] for x in rows
                                                 if abs(x["triangles"] - RESOLUTION_SWEEP_TRIANGLES)
                                                 < 0.05 * RESOLUTION_SWEEP_TRIANGLES), default=0)),
                     key=lambda r: r["width"] * r["height"])
        if not tri:
            continue
        t = [r["triangles"] for r in tri]
        axes[0, 0].plot(t, [r["first_image_s"] for r in tri], "o-", color=color, label=label)
        axes[0, 1].plot(t, [r["mpaths_per_s"] for r in tri], "o-", color=color, label=label)
        axes[1, 0].plot(t, [r["rss_peak_mib"] for r in tri], "o-", color=color, label=f"{label}: peak")
        axes[1, 0].plot(t, [r["render_own_mib"] for r in tri], "o--", color=color,
                        label=f"{label}: above Blender")
        p = [r["width"] * r["height"] / 1e6 for r in res]
        axes[1, 1].plot(p, [r["rss_peak_mib"] for r in res], "o-", color=color, label=f"{label}: peak")
        axes[1, 1].plot(p, [r["render_own_mib"] for r in res], "o--", color=color,
                        label=f"{label}: above Blender")
    titles = [(f"first image, {square}x{square} (s)", "triangles"),
              (f"Mpaths/s, {square}x{square}", "triangles"),
              (f"memory, {square}x{square} (MiB)", "triangles"),
              (f"memory at {RESOLUTION_SWEEP_TRIANGLES // 1000}k triangles (MiB)", "megapixels")]
    for ax, (title, xlabel) in zip(axes.flat, titles):
        ax.set_title(title, fontsize=10)
        ax.set_xlabel(xlabel)
        ax.set_xscale("log")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    axes[0, 0].set_yscale("log")
    fig.tight_layout()
    tmp = path.with_name(path.name + ".tmp.png")
    fig.savefig(tmp)
    plt.close(fig)
    os.replace(tmp, path)


if __name__ == "__main__":
    if len(sys.argv) == 7 and sys.argv[1] == _CHILD:
        sys.exit(_child(sys.argv[2], sys.argv[3], *map(int, sys.argv[4:7])))
    sys.exit(main())
