"""Error per second against Cycles: time to a common relMSE on the Cornell box and every fidelity scene.

For each ``blend_scenes/*.blend`` (the fidelity suite, ``cornell_box`` among them), in
one Blender process (bpy as a module), the study (``mcengine_blender.batch.study``)
renders MC Engine's path tracer with the default sampler (scrambled Sobol) and Cycles
at ``--resolution``, a ladder of 1, 2, 4, ... ``--max-samples`` samples per pixel,
``--seeds`` seeds per rung, under the comparison's matched unbiased settings (no
denoising, adaptive sampling, clamping or time limit).  Each engine is measured
against its own converged render (the study's references: 16 times the largest rung,
split over 4 renders), so relMSE is each engine's noise; whether the two converge to
the same image is the fidelity suite's question.  Times are the study's: the wall time
of Blender's render operator (export or sync, BVH, rendering, writing the image), the
median over seeds.

Other jobs.  Under ``nice`` on a shared machine, a job of higher priority can starve
this process for seconds (a 0.2 s render then takes 5 s), and the study renders one
engine's whole ladder before the other's, so such a burst lands on one engine only.
Every ladder render therefore also measures the CPU time of this process; a render
that got less than ``MIN_CPU_SHARE`` of a core over its wall time (an unloaded one
gets one or two cores) is rendered again, with the same seed, up to ``RETRIES`` times,
and the fastest attempt counts.  Each scene's line says how many renders were repeated
and how many stayed starved, and each engine's mean cores used (CPU time over wall
time) shows what the machine's load left it.

The target.  Per scene, the larger of the two engines' mean relMSE at the largest
sample count: the noisier engine reaches it at its last rung, the other one within its
ladder, its time interpolated in log-log between the rungs around the crossing (the
study's ``time_to_target``), so no time is extrapolated.  When the other engine is
already below the target at 1 sample, its time is that render's, an upper bound; the
ratio is then a bound too (marked <= or >=).

Printed per scene: the target, each engine's time to it and the ratio MC Engine /
Cycles (the goal of issue 11 is <= 0.3), each engine's efficiency 1 / (relMSE x s) at
the largest sample count and the ratio Cycles / MC Engine of those (read like the time
ratio: below 1, MC Engine is ahead); then the median of each ratio over the scenes
measured.  Skipped: scenes in ``SKIPPED`` (with the reason), and scenes where an engine
has no noise to measure (relMSE 0 at the largest rung).

Written to ``--out``: ``error_per_second.csv`` (one row per scene),
``error_per_second.md`` (the table, the settings, the medians), both rewritten after
every scene, and per scene ``SCENE/study.csv`` and ``SCENE/study.json`` (the study's own
files: every render's error and time, the fits).

Run: python benchmarks/bench_error_per_second.py [--resolution N] [--max-samples N]
                                                 [--seeds K] [--scenes a,b] [--out DIR]
"""
from __future__ import annotations

import argparse
import csv
import io
import math
import os
import statistics
import sys
import time
from pathlib import Path

from mcengine.samplers import DEFAULT as DEFAULT_SAMPLER

REPO = Path(__file__).resolve().parents[1]
SCENES = REPO / "blend_scenes"
ENGINES = ("path", "cycles")
GOAL = 0.3

# Scenes left out, with the reason.
SKIPPED = {
    "caustics_point": "point-lamp caustics: path tracing (MC Engine's and Cycles') cannot "
                      "reach them; the study measures path tracing there against Path + Light "
                      "Tracing (--reference light), where it plateaus by design, while Cycles "
                      "is measured against its own render without them",
}

# A ladder render that got less than this share of a core was starved by another job.
MIN_CPU_SHARE = 0.5
RETRIES = 4
RETRY_PAUSE = 1.0       # seconds to wait before rendering a starved render again

COLUMNS = ("scene", "target_relmse", "mc_seconds", "mc_how", "cycles_seconds", "cycles_how",
           "time_ratio", "mc_relmse_max", "cycles_relmse_max", "mc_efficiency",
           "cycles_efficiency", "efficiency_ratio", "mc_first_rung_seconds",
           "cycles_first_rung_seconds", "mc_cores", "cycles_cores", "repeated",
           "starved", "load", "note")


class StarvationGuard:
    """A study render callable that renders again what another job starved (see above).

    Counts per scene (``reset``): ``repeated`` renders, ``starved`` ones still starved
    after ``RETRIES``, and per engine the CPU seconds and wall seconds of the renders kept.
    References and warm-ups (seeds from the study's ``WARMUP_SEED`` on) are not timed by
    the study and are rendered once.
    """

    def __init__(self):
        self.reset()

    def reset(self):
        self.repeated = self.starved = 0
        self.cpu, self.wall = {}, {}

    def __call__(self, scene, engine, *, samples, seed):
        from mcengine.evaluation.study import WARMUP_SEED
        from mcengine_blender.batch.render import render_scene
        best, best_cpu = None, 0.0
        for attempt in range(1 + (RETRIES if seed < WARMUP_SEED else 0)):
            if attempt:
                self.repeated += 1
                time.sleep(RETRY_PAUSE)
            c0 = time.process_time()
            out = render_scene(scene, engine, samples=samples, seed=seed)
            cpu = time.process_time() - c0
            if best is None or out.seconds < best.seconds:
                best, best_cpu = out, cpu
            if seed >= WARMUP_SEED or cpu >= MIN_CPU_SHARE * out.seconds:
                break
        else:
            self.starved += 1
        if seed < WARMUP_SEED:
            self.cpu[engine] = self.cpu.get(engine, 0.0) + best_cpu
            self.wall[engine] = self.wall.get(engine, 0.0) + best.seconds
        return best

    def cores(self, engine) -> float:
        """CPU time over wall time of the kept ladder renders of ``engine``."""
        wall = self.wall.get(engine, 0.0)
        return self.cpu.get(engine, 0.0) / wall if wall > 0 else math.nan


def measure(summaries) -> dict:
    """The row of one scene from its study summaries (``path`` and ``cycles``)."""
    from mcengine.evaluation.study import time_to_target
    mc, cy = summaries["path"].rungs, summaries["cycles"].rungs
    last = {"path": mc[-1], "cycles": cy[-1]}
    row = {"mc_first_rung_seconds": mc[0].seconds, "cycles_first_rung_seconds": cy[0].seconds,
           "mc_relmse_max": mc[-1].relmse, "cycles_relmse_max": cy[-1].relmse,
           "mc_efficiency": mc[-1].efficiency, "cycles_efficiency": cy[-1].efficiency}
    if min(r.relmse for r in last.values()) <= 0:
        return dict(row, note="no noise to measure (relMSE 0 at the largest sample count)")
    target = max(r.relmse for r in last.values())
    row["target_relmse"] = target
    for key, rungs in (("mc", mc), ("cycles", cy)):
        t, how = time_to_target([r.seconds for r in rungs], [r.relmse for r in rungs], target)
        row[f"{key}_seconds"], row[f"{key}_how"] = t, how
    row["time_ratio"] = row["mc_seconds"] / row["cycles_seconds"]
    row["efficiency_ratio"] = row["cycles_efficiency"] / row["mc_efficiency"]
    return row


def ratio_text(row) -> str:
    """The time ratio, with <= or >= when one time is only a bound."""
    bound = ("<= " if row["mc_how"] == "first rung" else
             ">= " if row["cycles_how"] == "first rung" else "")
    return f"{bound}{row['time_ratio']:.2f}"


def table_markdown(rows, args, options, elapsed) -> str:
    out = io.StringIO()
    out.write(f"MC Engine (path tracing, {DEFAULT_SAMPLER} sampler) against Cycles, "
              f"{args.resolution}x{args.resolution}, 1 to {args.max_samples} spp, "
              f"{args.seeds} seeds, references {options.reference_total()} spp; "
              f"{elapsed / 60:.1f} min in all.\n\n")
    out.write("| scene | target relMSE | MC Engine time | Cycles time | time MC / Cycles "
              "| efficiency MC | efficiency Cycles | efficiency Cycles / MC |\n")
    out.write("| --- | --- | --- | --- | --- | --- | --- | --- |\n")
    for row in rows:
        if "time_ratio" not in row:
            out.write(f"| {row['scene']} | {row['note'].split(':')[0]} (below) | | | | | | |\n")
            continue
        out.write(f"| {row['scene']} | {row['target_relmse']:.3g} | {row['mc_seconds']:.2f} s "
                  f"| {row['cycles_seconds']:.2f} s | {ratio_text(row)} "
                  f"| {row['mc_efficiency']:.3g} | {row['cycles_efficiency']:.3g} "
                  f"| {row['efficiency_ratio']:.2f} |\n")
    out.write("\n" + medians_text(rows) + "\n")
    for row in rows:
        if "time_ratio" not in row:
            out.write(f"\n{row['scene']}: {row['note']}.\n")
    measured = [r for r in rows if "load" in r]
    if measured:
        loads = [r["load"] for r in measured]
        out.write(f"\nLoad average (1 min) after each scene {min(loads):.1f} to {max(loads):.1f}; "
                  f"median cores used MC Engine "
                  f"{statistics.median(r['mc_cores'] for r in measured):.2f}, Cycles "
                  f"{statistics.median(r['cycles_cores'] for r in measured):.2f}; "
                  f"renders repeated because starved {sum(r['repeated'] for r in measured)}, "
                  f"still starved {sum(r['starved'] for r in measured)}.\n")
    return out.getvalue()


def medians_text(rows) -> str:
    measured = [r for r in rows if "time_ratio" in r]
    if not measured:
        return "No scene measured."
    times = [r["time_ratio"] for r in measured]
    effs = [r["efficiency_ratio"] for r in measured]
    within = sum(t <= GOAL for t in times)
    return (f"Median over {len(measured)} scenes: time MC / Cycles {statistics.median(times):.2f} "
            f"(<= {GOAL} on {within}), efficiency Cycles / MC {statistics.median(effs):.2f}.")


def write_atomic(path: Path, text: str) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)


def write_csv(rows, path: Path) -> None:
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=COLUMNS, extrasaction="ignore")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in row.items()})
    write_atomic(path, buf.getvalue())


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--resolution", type=int, default=64, help="width and height in pixels")
    ap.add_argument("--max-samples", type=int, default=64, help="the ladder's largest rung")
    ap.add_argument("--seeds", type=int, default=3, help="renders per rung (at least 2)")
    ap.add_argument("--scenes", default="", help="comma-separated scene names (default: all)")
    ap.add_argument("--out", default="error-per-second", help="output folder (created)")
    args = ap.parse_args(argv)

    all_scenes = sorted(SCENES.glob("*.blend"))
    wanted = [s for s in args.scenes.split(",") if s]
    unknown = sorted(set(wanted) - {p.stem for p in all_scenes})
    if unknown:
        print(f"error: no such scene in blend_scenes/: {', '.join(unknown)}", file=sys.stderr)
        return 2
    paths = [p for p in all_scenes if not wanted or p.stem in wanted]

    import bpy  # noqa: F401  (Blender as a module)

    from mcengine.evaluation.datafiles import write_csv as write_study_csv
    from mcengine.evaluation.datafiles import write_study_json
    from mcengine.evaluation.study import StudyError, StudyOptions, summarise
    from mcengine_blender.batch.study import StudySettings, study_file

    options = StudyOptions(integrators=("path",), with_cycles=True, max_samples=args.max_samples,
                           seeds=args.seeds)
    settings = StudySettings(resolution=(args.resolution, args.resolution),
                             sampler=DEFAULT_SAMPLER)
    try:
        options.validate()
    except StudyError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    guard = StarvationGuard()
    rows, start = [], time.perf_counter()
    for path in paths:
        name = path.stem
        if name in SKIPPED:
            rows.append({"scene": name, "note": f"skipped: {SKIPPED[name]}"})
            print(f"{name}: skipped ({SKIPPED[name]})", flush=True)
            continue
        t0 = time.perf_counter()
        guard.reset()
        try:
            study = study_file(path, options, settings, render=guard)
        except StudyError as exc:
            rows.append({"scene": name, "note": f"failed: {exc}"})
            print(f"{name}: failed: {exc}", flush=True)
            continue
        summaries = summarise(study)
        (out / name).mkdir(exist_ok=True)
        write_study_csv(study.rows, out / name / "study.csv")
        write_study_json(study, summaries, out / name / "study.json")
        row = dict(scene=name, **measure(summaries), mc_cores=guard.cores("mcengine"),
                   cycles_cores=guard.cores("cycles"), repeated=guard.repeated,
                   starved=guard.starved, load=os.getloadavg()[0])
        rows.append(row)
        if "time_ratio" in row:
            print(f"{name}: target relMSE {row['target_relmse']:.3g}: MC Engine "
                  f"{row['mc_seconds']:.2f} s ({row['mc_how']}), Cycles {row['cycles_seconds']:.2f} s "
                  f"({row['cycles_how']}), ratio {ratio_text(row)}; efficiency MC "
                  f"{row['mc_efficiency']:.3g}, Cycles {row['cycles_efficiency']:.3g}, Cycles / MC "
                  f"{row['efficiency_ratio']:.2f}; cores used MC {row['mc_cores']:.2f}, Cycles "
                  f"{row['cycles_cores']:.2f}; renders repeated {guard.repeated}, starved "
                  f"{guard.starved}; load {row['load']:.1f}  [{time.perf_counter() - t0:.0f} s]",
                  flush=True)
        else:
            print(f"{name}: {row['note']}", flush=True)
        write_csv(rows, out / "error_per_second.csv")
        write_atomic(out / "error_per_second.md",
                     table_markdown(rows, args, options, time.perf_counter() - start))
    elapsed = time.perf_counter() - start
    write_csv(rows, out / "error_per_second.csv")
    table = table_markdown(rows, args, options, elapsed)
    write_atomic(out / "error_per_second.md", table)
    print()
    print(table)
    print(f"written to {out}/")
    return 0

if __name__ == "__main__":
    sys.exit(main())
