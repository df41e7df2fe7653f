"""Render time against the number of lamps: MC Engine and Cycles on the Cornell box lit by
N more point lamps.

blend_scenes/cornell_box.blend gets N point lamps (1 W, radius 2 cm, at random places in
the box, seed 0) besides its own light, for each N of ``--lamps``; both engines render it
through ``bpy.ops.render.render`` in this process (no clamping, denoising or adaptive
sampling), alternating engine by engine for ``--rounds`` rounds, and the median wall time
of the render call is printed with the ratio MC / Cycles and each image's mean (a check
that both rendered the same scene).

Per path vertex, next-event estimation picks one light in proportion to its importance
there: MC Engine sums the lamps' importances (linear in N) and then scans them; Cycles
descends its light tree (logarithmic). Every ray is also tested against every lamp a ray
can hit, in both engines.

Run: python benchmarks/bench_lamps.py [--lamps 1,10,100,1000] [--samples N]
                                      [--resolution N] [--rounds R]
"""
from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
SCENE = REPO / "blend_scenes" / "cornell_box.blend"


def add_lamps(bpy, scene, count: int, seed: int = 0) -> None:
    """``count`` point lamps at random places inside the box (0.9 m from its centre at most)."""
    rng = np.random.default_rng(seed)
    for k in range(count):
        data = bpy.data.lights.new(f"Lamp{k}", "POINT")
        data.energy, data.shadow_soft_size = 1.0, 0.02
        ob = bpy.data.objects.new(f"Lamp{k}", data)
        ob.location = rng.uniform(-0.9, 0.9, 3) + np.array([0.0, 0.0, 1.0])
        scene.collection.objects.link(ob)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lamps", default="1,10,100,1000")
    ap.add_argument("--samples", type=int, default=16)
    ap.add_argument("--resolution", type=int, default=64)
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args(argv)
    try:
        counts = [int(n) for n in args.lamps.split(",") if n.strip()]
    except ValueError:
        counts = []
    if not counts or min(counts) < 0:
        print("bench_lamps: --lamps takes counts of lamps, e.g. 1,10,100,1000", file=sys.stderr)
        return 2

    import bpy

    from mcengine_blender.batch.render import ensure_registered, open_scene, render_scene
    from mcengine_blender.batch.settings import make_unbiased

    ensure_registered()
    res = (args.resolution, args.resolution)

    def run(bl_engine, count, samples):
        scene = open_scene(SCENE)
        make_unbiased(scene)
        add_lamps(bpy, scene, count)
        return render_scene(scene, bl_engine, samples=samples, seed=0, resolution=res)

    run("mcengine", 1, 1)            # load the kernels and Cycles' once
    run("cycles", 1, 1)
    engines = ("mcengine", "cycles")
    rows = []
    for count in counts:
        seconds = {e: [] for e in engines}
        means = {}
        for r in range(args.rounds):
            for name in engines[r % 2:] + engines[:r % 2]:
                done = run(name, count, args.samples)
                seconds[name].append(done.seconds)
                means[name] = float(done.image[..., :3].mean())
        med = {e: statistics.median(v) for e, v in seconds.items()}
        rows.append((count, med, means))
        print(f"{count:5d} lamps: MC Engine {med['mcengine']:.3f} s, Cycles {med['cycles']:.3f} s",
              flush=True)
    print()
    print(f"Cornell box + N point lamps, {args.resolution}x{args.resolution}, {args.samples} spp, "
          f"median render call of {args.rounds} rounds")
    print("| lamps | MC Engine (s) | Cycles (s) | MC / Cycles | image mean MC / Cycles |")
    print("| --- | --- | --- | --- | --- |")
    for count, med, means in rows:
        print(f"| {count} | {med['mcengine']:.3f} | {med['cycles']:.3f} | "
              f"{med['mcengine'] / med['cycles']:.2f} | {means['mcengine'] / means['cycles']:.3f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
