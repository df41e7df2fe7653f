"""What Embree's queries alone cost per path, beside MC Engine's and Mitsuba 3's whole paths.

Issue 11 asks for MC Engine's paths per second to reach Mitsuba 3's (``llvm_ad_rgb``) on the
Cornell box.  This benchmark measures how much of Mitsuba's time per path the ray queries
alone would take: it records every closest-hit and occlusion batch of an MC Engine render of
the box (one thread, the rays a real render traces, camera rays, bounces and shadow rays),
then traces those same batches again through ``kernels.embree`` (packets of eight, one
thread), with the BVH built two ways:

* robust, medium build quality: MC Engine's (and Cycles', ``bvh/embree.cpp``) settings;
  the robust mode is the watertight triangle test that issue 11's tests require;
* fast (not robust), high build quality: Mitsuba 3's (``src/render/scene_embree.inl``:
  ``RTC_SCENE_FLAG_NONE``, ``RTC_BUILD_QUALITY_HIGH``).

In the same run, alternating round by round, it renders the box with MC Engine
(``RenderSession``, two threads), Cycles (through Blender, two threads: a full render's
time less a 1-sample render's) and Mitsuba (its child process, two threads, JIT compile
excluded as in bench_cornell.py) and prints each engine's time per path on one core (the
render's wall time x 2 cores / paths), beside Embree's time per path of MC Engine's rays.
Cycles traces MC Engine's paths (the same rules); Mitsuba counts its own rays per path (its
Russian roulette differs), so times per ray are printed too.  With ``--materials principled``
the rounds also render the file's Lambert box with MC Engine: what the Principled box would
cost if its material cost no more than Lambert's, beside Cycles' Principled paths (issue 9
asks for half their time).

Run: python benchmarks/bench_embree_floor.py [--samples N] [--record-samples N]
                                             [--rounds R] [--materials file|principled]
"""
from __future__ import annotations

import argparse
import contextlib
import statistics
import sys
import tempfile
import time
from pathlib import Path

import bench_cornell
import mitsuba_peer

RESOLUTION = 256
CORES = 2


class _Recorder:
    """An accelerator that keeps a copy of every batch of rays it is asked to trace."""

    def __init__(self, accel):
        self._accel, self.masked = accel, accel.masked
        self.batches = []

    def closest(self, o, d, t, times=None, mask=None):
        self.batches.append((False, o.copy(), d.copy(), t.copy()))
        return self._accel.closest(o, d, t, times, mask)

    def occluded(self, o, d, t, times=None, mask=None):
        self.batches.append((True, o.copy(), d.copy(), t.copy()))
        return self._accel.occluded(o, d, t, times, mask)


def _blender_render(materials: str, engine_name: str, samples: int):
    """Render the Cornell box through Blender (bpy as a module); the render's result."""
    import bpy

    from mcengine_blender.batch.render import ensure_registered, open_scene, render_scene
    from mcengine_blender.batch.settings import make_unbiased

    ensure_registered()
    scene = open_scene(bench_cornell.SCENE)
    make_unbiased(scene)
    if materials == "principled":
        bench_cornell.to_default_principled(bpy)
    return render_scene(scene, engine_name, samples=samples, seed=0,
                        resolution=(RESOLUTION, RESOLUTION))


def _export(materials: str):
    """The Cornell box as MC Engine exports it (a SceneDescription)."""
    from mcengine_blender import engine

    scenes, real_factory = [], engine.session_factory

    def recording_factory(desc, threads=None):
        scenes.append(desc)
        return real_factory(desc, threads=threads)

    engine.session_factory = recording_factory
    try:
        _blender_render(materials, "mcengine", 1)
    finally:
        engine.session_factory = real_factory
    return scenes[-1]


def _cycles_seconds(materials: str, samples: int) -> float:
    """Cycles' marginal render time of ``samples`` - 1 samples per pixel (a full render's
    time less a 1-sample render's: its scene sync left out)."""
    one = _blender_render(materials, "cycles", 1).seconds
    return _blender_render(materials, "cycles", samples).seconds - one


def _record(desc, samples: int):
    """The batches of rays a one-thread render of ``desc`` traces at ``samples`` spp."""
    from mcengine.session import RenderSession

    desc.integrator.samples = samples
    session = RenderSession(desc, threads=1)
    recorder = _Recorder(session.accel)
    session.accel = recorder
    session.run()
    return recorder.batches


def _trace_seconds(scene, batches) -> float:
    """Seconds to trace all ``batches`` through ``scene`` on this thread."""
    t0 = time.perf_counter()
    for occlusion, o, d, t in batches:
        (scene.occluded if occlusion else scene.closest)(o, d, t)
    return time.perf_counter() - t0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=64, help="spp of the timed renders")
    ap.add_argument("--record-samples", type=int, default=8, help="spp of the recorded render")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--materials", choices=("file", "principled"), default="file")
    args = ap.parse_args(argv)

    from mcengine.kernels import embree
    from mcengine.session import RenderSession

    if embree.library_path() is None:
        print("bench_embree_floor: Embree's library was not found in the embreex wheel",
              file=sys.stderr)
        return 2
    desc = _export(args.materials)
    batches = _record(desc, args.record_samples)
    recorded_paths = RESOLUTION * RESOLUTION * args.record_samples
    rays = sum(len(b[1]) for b in batches)
    g = desc.geometry
    bvhs = {"robust, medium (MC Engine, Cycles)": embree.build(g.vertices, g.triangles),
            "fast, high (Mitsuba 3)": embree.build(g.vertices, g.triangles, robust=False,
                                                   spatial_splits=True)}
    desc.integrator.samples = args.samples
    paths = RESOLUTION * RESOLUTION * args.samples
    per_path = {name: [] for name in (*bvhs, "MC Engine", "Cycles", "Mitsuba")}
    lambert = _export("file") if args.materials == "principled" else None
    if lambert is not None:
        lambert.integrator.samples = args.samples
        per_path["MC Engine, Lambert"] = []

    with contextlib.ExitStack() as stack:
        folder = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="bench_floor_")))
        try:
            spec, _notes = mitsuba_peer.scene_spec(desc, folder)
            peer = stack.enter_context(mitsuba_peer.MitsubaPeer(spec, folder))
        except mitsuba_peer.PeerError as exc:
            print(f"bench_embree_floor: {exc}", file=sys.stderr)
            return 2
        peer.render(args.samples, 0)                       # compiles Mitsuba's kernels
        RenderSession(desc, threads=CORES).run()           # loads MC Engine's
        _cycles_seconds(args.materials, 2)                 # and Cycles' kernels
        for r in range(args.rounds):
            steps = ["bvh", "mc", "cycles", "mitsuba"] + (["mc_lambert"] if lambert else [])
            for step in steps[r % len(steps):] + steps[:r % len(steps)]:
                if step == "bvh":
                    for name, scene in bvhs.items():
                        per_path[name].append(_trace_seconds(scene, batches) / recorded_paths)
                elif step in ("mc", "mc_lambert"):
                    session = RenderSession(desc if step == "mc" else lambert, threads=CORES)
                    t0 = time.perf_counter()
                    session.run()
                    name = "MC Engine" if step == "mc" else "MC Engine, Lambert"
                    per_path[name].append((time.perf_counter() - t0) * CORES / paths)
                    if step == "mc_lambert":
                        lambert_rays = session.stats.rays / session.stats.paths
                elif step == "cycles":
                    seconds = _cycles_seconds(args.materials, args.samples)
                    per_path["Cycles"].append(seconds * CORES / (paths - RESOLUTION ** 2))
                else:
                    reply = peer.render(args.samples, r + 1)
                    seconds = reply["seconds"] - reply["compile"]
                    per_path["Mitsuba"].append(seconds * CORES / paths)
        mitsuba_rays = peer.rays_per_path()

    med = {name: statistics.median(v) for name, v in per_path.items()}
    ours = rays / recorded_paths
    print(f"Cornell box ({args.materials} materials) {RESOLUTION}x{RESOLUTION}; renders at "
          f"{args.samples} spp, medians of {args.rounds} rounds; Embree traced the "
          f"{rays} rays of a {args.record_samples}-spp render ({ours:.2f} rays/path)")
    print(f"{'time per path on one core':50s}{'us/path':>9s}{'ns/ray':>9s}"
          f"{'of Mitsuba path':>17s}{'of Cycles path':>16s}")
    rows = [("MC Engine render", med["MC Engine"], ours),
            ("Cycles render (marginal; MC Engine's rays)", med["Cycles"], ours),
            ("Mitsuba 3 render", med["Mitsuba"], mitsuba_rays)]
    if lambert is not None:
        rows.insert(1, ("MC Engine render, the file's Lambert materials",
                        med["MC Engine, Lambert"], lambert_rays))
    rows += [(f"Embree alone, {name}", med[name], ours) for name in bvhs]
    for name, seconds, rays_per_path in rows:
        print(f"{name:50s}{seconds * 1e6:9.3f}{seconds / rays_per_path * 1e9:9.1f}"
              f"{seconds / med['Mitsuba']:16.2f}x{seconds / med['Cycles']:15.2f}x")
    print(f"Mitsuba traces {mitsuba_rays:.2f} rays/path (its stopping rules replayed); "
          f"MC Engine {ours:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
