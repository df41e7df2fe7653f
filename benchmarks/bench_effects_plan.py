"""What the effects plan saves: every fidelity scene with its plan and with every effect forced on.

Each ``blend_scenes/*.blend`` is exported once (Blender in this process, the
comparison's unbiased settings) and rendered by ``RenderSession`` twice per
round: with the plan the scene calls for, and with every effect of
``mcengine.features.EFFECTS`` forced on (``force_effects="all"``).  Both use the
same seed, so the two images must be identical bit for bit (checked every time:
a forced effect that changed the image would be a plan that skips something the
scene needs).  Rounds alternate the order; the table gives the median render
times (tracing and shading, wall clock; export, BVH and kernel loading are not
counted) and the time the plan saves, with the effects it skipped.

Run: python benchmarks/bench_effects_plan.py [--samples N] [--rounds R] [--scenes a,b]
"""
from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
SCENES = REPO / "blend_scenes"


def export_scene(path):
    """The scene of ``path`` as a SceneDescription, under the comparison's unbiased settings."""
    import bpy

    from mcengine_blender import export
    from mcengine_blender.batch.render import open_scene
    from mcengine_blender.batch.settings import make_unbiased
    scene = open_scene(path)
    make_unbiased(scene)
    return export.export(bpy.context.evaluated_depsgraph_get()).scene


def render(desc, force):
    from mcengine.session import RenderSession
    session = RenderSession(desc, force_effects=force).run()
    return session.stats.time_render, session.image(), session.plan


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=64)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--scenes", default="", help="comma-separated scene names (default: all)")
    args = ap.parse_args(argv)

    import bpy  # noqa: F401  (Blender as a module)

    from mcengine.features import EFFECTS
    from mcengine_blender.batch.render import ensure_registered
    ensure_registered()

    wanted = {s for s in args.scenes.split(",") if s}
    paths = [p for p in sorted(SCENES.glob("*.blend")) if not wanted or p.stem in wanted]
    rows = []
    for path in paths:
        desc = export_scene(path)
        desc.integrator.samples = args.samples
        desc.integrator.seed = 1
        render(desc, ())                      # load the kernels, touch the buffers
        times = {"plan": [], "all": []}
        plan = None
        for r in range(args.rounds):
            results = {}
            for which in (("plan", "all") if r % 2 == 0 else ("all", "plan")):
                seconds, image, used = render(desc, () if which == "plan" else "all")
                times[which].append(seconds)
                results[which] = image
                if which == "plan":
                    plan = used
            if not np.array_equal(results["plan"], results["all"]):
                print(f"{path.stem}: forcing every effect on changed the image", file=sys.stderr)
                return 1
        t_plan, t_all = statistics.median(times["plan"]), statistics.median(times["all"])
        skipped = [n for n in EFFECTS if not getattr(plan, n)]
        rows.append((path.stem, t_plan, t_all, skipped))
        print(f"{path.stem}: plan {t_plan:.2f} s, all forced {t_all:.2f} s, saved "
              f"{100 * (1 - t_plan / t_all):.1f} %", flush=True)

    print()
    print(f"{args.samples} spp at each file's resolution, medians of {args.rounds} rounds; "
          f"images identical bit for bit in every round")
    print("| scene | plan (s) | all effects forced (s) | saved | skipped by the plan |")
    print("| --- | --- | --- | --- | --- |")
    for name, t_plan, t_all, skipped in rows:
        labels = ", ".join(EFFECTS[n][0] for n in skipped) or "nothing"
        print(f"| {name} | {t_plan:.2f} | {t_all:.2f} | {100 * (1 - t_plan / t_all):.1f} % | {labels} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
