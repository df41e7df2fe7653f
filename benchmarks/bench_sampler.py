"""Error per second of MC Engine's two samplers, scrambled Sobol and independent, in one run.

Renders each scene (default ``blend_scenes/cornell_box.blend``) at ``--resolution``
with the path tracer and the file's settings made unbiased (8 bounces on the Cornell
box, no clamping, no denoising, no adaptive sampling), at a ladder of sample counts,
``--seeds`` seeds each, alternating the two samplers render by render, so that both
meet the same machine load.  The reference is the mean of 4 renders of
``--reference-samples`` samples (two with each sampler, seeds of their own): both
samplers are unbiased, and the reference's own error adds equally to both.

For each sampler and rung it prints the mean relMSE (``mcengine.evaluation.stats.relmse``,
the study's metric), the mean seconds of the render call (export and start-up included,
as the study times it) and the error per second as the product relMSE x seconds
(lower is better; the inverse of the study's efficiency), then the ratio
Sobol / independent of that product: below 1 means the Sobol sampler reaches a given
error sooner.  Finally the time to reach ``--target`` relMSE, interpolated in
log-log between rungs as the study does, and its ratio.

Run: python benchmarks/bench_sampler.py [--scenes a.blend,b.blend] [--resolution N]
                                        [--ladder 4,16,64] [--seeds K]
                                        [--reference-samples N] [--target X]
"""
from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
SAMPLERS = ("sobol", "independent")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", default=str(REPO / "blend_scenes" / "cornell_box.blend"),
                    help="comma-separated .blend files")
    ap.add_argument("--resolution", type=int, default=128)
    ap.add_argument("--ladder", default="4,16,64", help="comma-separated samples per pixel")
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--reference-samples", type=int, default=1024)
    ap.add_argument("--target", type=float, default=0.02, help="relMSE to reach")
    args = ap.parse_args(argv)
    ladder = [int(x) for x in args.ladder.split(",")]

    import bpy  # noqa: F401  (Blender as a module)

    from mcengine.evaluation.stats import relmse
    from mcengine_blender.batch.render import ensure_registered, open_scene, render_scene
    from mcengine_blender.batch.settings import make_unbiased

    ensure_registered()
    res = (args.resolution, args.resolution)
    for blend in args.scenes.split(","):
        def run(sampler, samples, seed, blend=blend):
            scene = open_scene(blend)
            make_unbiased(scene)
            from mcengine.samplers import get
            scene.mcengine.sampler = get(sampler).enum_id
            return render_scene(scene, "mcengine", samples=samples, seed=seed, resolution=res)

        run("sobol", 1, 0)      # load the kernels
        refs = [run(SAMPLERS[k % 2], args.reference_samples, 10_000 + k).image[..., :3]
                for k in range(4)]
        ref = np.mean(refs, axis=0)
        rows = {s: {n: ([], []) for n in ladder} for s in SAMPLERS}
        for n in ladder:
            for seed in range(args.seeds):
                order = SAMPLERS if seed % 2 == 0 else SAMPLERS[::-1]
                for s in order:
                    r = run(s, n, seed + 1)
                    rows[s][n][0].append(relmse(r.image[..., :3], ref))
                    rows[s][n][1].append(r.seconds)
        print(f"\n{Path(blend).name} {res[0]}x{res[1]}, reference {4 * args.reference_samples} spp, "
              f"{args.seeds} seeds per rung")
        print(f"{'spp':>5s} {'sampler':12s}{'relMSE':>10s}{'seconds':>9s}{'relMSE x s':>12s}"
              f"{'Sobol / independent':>21s}")
        for n in ladder:
            prod = {}
            for s in SAMPLERS:
                e, t = statistics.mean(rows[s][n][0]), statistics.mean(rows[s][n][1])
                prod[s] = e * t
                ratio = f"{prod['sobol'] / prod['independent']:21.2f}" if s == SAMPLERS[-1] else ""
                print(f"{n:5d} {s:12s}{e:10.4f}{t:9.2f}{e * t:12.4f}{ratio}")
        times = {s: time_to(args.target, ladder, rows[s]) for s in SAMPLERS}
        text = {s: ("not reached" if t is None else f"{t:.2f} s") for s, t in times.items()}
        ratio = (f", Sobol / independent {times['sobol'] / times['independent']:.2f}"
                 if None not in times.values() else "")
        print(f"time to relMSE {args.target}: Sobol {text['sobol']}, independent "
              f"{text['independent']}{ratio}")
    return 0


def time_to(target, ladder, rows):
    """Seconds at which the mean relMSE reaches ``target`` (the study's interpolation), or None."""
    from mcengine.evaluation.study import time_to_target
    return time_to_target([statistics.mean(rows[n][1]) for n in ladder],
                          [statistics.mean(rows[n][0]) for n in ladder], target)[0]


if __name__ == "__main__":
    sys.exit(main())
