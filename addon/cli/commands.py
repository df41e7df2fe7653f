"""The commands of the command line, once their arguments are valid: render, compare, study.

Each ``run_*`` takes a request from :mod:`.args`, imports ``bpy`` (and
registers MC Engine when it renders with it), does its work with Blender's
log captured (:mod:`.console`) and returns the exit status; failures are
raised as :class:`~.errors.CliError`.  Rendering, comparing and studying
themselves are the add-on's batch tools (:mod:`..batch`); the files come from
:mod:`mcengine.evaluation.output`.
"""
from __future__ import annotations

import time
from pathlib import Path

from ..batch import interrupt
from ..batch.outputs import (
    OutputError,
    Staging,
    remove_placeholder,
    touch_placeholder,
    verify,
    write_folder,
)
from ..batch.render import (
    ENGINES,
    NoSuchScene,
    OpenError,
    ensure_registered,
    error_message,
    open_scene,
    render_scene,
)
from ..batch.settings import apply_overrides, set_image_format
from . import signals
from .args import CompareRequest, RenderRequest, StudyRequest, check_output_paths, partial_path
from .console import BlenderLog, Progress, engine_traceback, warning_lines
from .errors import EXIT_DIFFER, EXIT_OK, EXIT_RENDER_FAILED, PROG, CliError
from .frames import frame_path, plan_frames

__all__ = ["run_render", "run_compare", "run_study", "study_line"]


# ---------------------------------------------------------------------------
# Blender
# ---------------------------------------------------------------------------

def _import_bpy():
    try:
        import bpy
    except ImportError as exc:
        raise CliError(f"cannot import bpy (Blender 5.0 as a Python module): {exc}",
                       EXIT_RENDER_FAILED) from None
    return bpy


def _register_addon() -> None:
    """Register MC Engine (only done when it is the engine asked for); its renders stop
    when the command is interrupted."""
    try:
        ensure_registered()
        interrupt.install_engine_hook()
    except Exception as exc:  # the add-on's failure must not hide behind a traceback
        raise CliError(f"the MC Engine add-on failed to register: {type(exc).__name__}: {exc}",
                       EXIT_RENDER_FAILED) from None


def _start_blender(register: bool):
    """Import bpy (and register MC Engine); a stop requested meanwhile is honoured here."""
    interrupt.check()
    bpy = _import_bpy()
    signals.note_temporary_folder(bpy.app.tempdir)   # removed if the process must end early
    interrupt.check()
    if register:
        _register_addon()  # before loading, as an enabled add-on would be
    return bpy


class _LoggedRenderer:
    """``render`` for the comparison and the study: a progress bar per render, the log checked.

    Called while Blender's log is captured (the whole command runs inside
    ``BlenderLog.capture``); the progress bar goes to the real stderr.  An
    engine's crash (a traceback in the log) is raised as RuntimeError, which
    the comparison and the study report as a failed render.
    """

    def __init__(self, bpy, log: BlenderLog, threads: int | None, bars: bool = True):
        self.bpy = bpy
        self.log = log
        self.threads = threads
        self.bars = bars           # False: no progress display per render
        self.label = ""
        self.warnings: list[str] = []

    def on_render(self, engine: str, index: int, total: int) -> None:
        self.label = f"[{index + 1}/{total}] {engine}"

    def __call__(self, scene, engine, **settings):
        apply_overrides(scene, threads=self.threads)
        progress = Progress(self.log.console, self.label or engine)
        start = self.log.mark()
        if self.bars:
            self.bpy.app.handlers.render_stats.append(progress.on_stats)
        try:
            result = render_scene(scene, engine, **settings)
        finally:
            if self.bars:
                self.bpy.app.handlers.render_stats.remove(progress.on_stats)
                progress.finish()
        text = self.log.text(since=start)
        crash = engine_traceback(text)
        if crash is not None:
            raise RuntimeError(f"{engine} raised {crash}")
        for warning in warning_lines(text):
            if warning not in self.warnings:
                self.warnings.append(warning)
        return result


# ---------------------------------------------------------------------------
# render
# ---------------------------------------------------------------------------

def _open(path: Path, scene_name: str | None):
    try:
        return open_scene(path, scene_name)
    except NoSuchScene as exc:
        raise CliError(str(exc)) from None
    except OpenError as exc:
        raise CliError(str(exc), EXIT_RENDER_FAILED) from None


def _render(bpy, scene, request: RenderRequest, targets, log: BlenderLog,
            progress: Progress) -> int | None:
    """Render once and save the image to every (output, path) of ``targets``; returns the
    samples per pixel rendered.

    Raises CliError on any failure and Interrupted if the command was stopped;
    in both cases no output is touched (with ``--keep-partial``, an
    interrupted MC Engine render is saved under the partial names).
    """
    ours = request.engine == ENGINES["mcengine"]
    if ours:
        from ..engine import last_render
        last_render.clear()   # what is left in it afterwards is this render's
    log_start = log.mark()
    interrupt.check()
    bpy.app.handlers.render_stats.append(progress.on_stats)
    try:
        with log.capture():
            bpy.ops.render.render(write_still=False, scene=scene.name)
    except RuntimeError as exc:
        interrupt.check()
        raise CliError(f"render failed: {error_message(exc)}", EXIT_RENDER_FAILED) from None
    finally:
        bpy.app.handlers.render_stats.remove(progress.on_stats)
        progress.finish()
    crash = engine_traceback(log.text(since=log_start))
    if crash is not None:
        interrupt.check()
        raise CliError(f"render failed: {request.engine} raised {crash}", EXIT_RENDER_FAILED)
    if interrupt.requested() is not None:
        if request.keep_partial and ours:
            partials = [(output, partial_path(path)) for output, path in targets]
            _save(bpy, scene, partials, log)
            log.console.write(f"{PROG}: kept the partial image ({_samples_done(ours, progress)} "
                              f"samples) in {', '.join(str(p) for _, p in partials)}\n")
        interrupt.check()
    _save(bpy, scene, targets, log)
    return _samples_done(ours, progress)


def _samples_done(ours: bool, progress: Progress) -> int | None:
    """Samples per pixel the last render took (a time limit or a stop ends it early)."""
    if ours:
        from ..engine import last_render
        stats = last_render.get("stats")
        if stats is not None and getattr(stats, "samples_done", None) is not None:
            return int(stats.samples_done)
    return progress.done


def _save(bpy, scene, targets, log: BlenderLog) -> None:
    """Save the Render Result to every (output, path): temporary files next to the
    targets, read back, then renamed over the targets together (batch.outputs)."""
    result = bpy.data.images["Render Result"]
    with Staging() as staging:
        for output, path in targets:
            try:
                temp = staging.temp(path)
            except OutputError as exc:
                raise CliError(f"cannot save {path}: {exc}", EXIT_RENDER_FAILED) from None
            try:
                set_image_format(scene, output.file_format)
                with log.capture():   # OpenEXR prints its complaints about a bad file
                    result.save_render(filepath=str(temp), scene=scene)
                    verify(temp, output.file_format)
            except RuntimeError as exc:
                raise CliError(f"cannot save {path}: {error_message(exc)}{_unchanged(path)}",
                               EXIT_RENDER_FAILED) from None
            except OutputError as exc:
                raise CliError(f"cannot save {path}: Blender wrote {exc} (is the disk full?)"
                               f"{_unchanged(path)}", EXIT_RENDER_FAILED) from None
        try:
            staging.commit()
        except OutputError as exc:
            raise CliError(str(exc), EXIT_RENDER_FAILED) from None


def _unchanged(path: Path) -> str:
    return "; the existing file is unchanged" if path.exists() and path.stat().st_size else ""


def _ray_accounting() -> str | None:
    """The last MC Engine render's ray accounting line (None if the engine kept none)."""
    from ..engine import last_render
    return last_render.get("accounting")


def _frames(scene, request: RenderRequest, console) -> tuple[int, ...]:
    """The frames the request renders (the file's current frame if none was given)."""
    if not request.frame_actions:
        return (scene.frame_current,)
    plan = plan_frames(request.frame_actions, scene.frame_start, scene.frame_end,
                       scene.frame_step)
    for warning in plan.warnings:
        console.write(f"{PROG}: warning: {warning}\n")
    return plan.frames


class _Warnings:
    """Blender's ``Warning:`` lines, each passed on once (an animation repeats them)."""

    def __init__(self, log: BlenderLog):
        self.log = log
        self.start = log.mark()
        self.seen: set[str] = set()

    def flush(self) -> None:
        for warning in warning_lines(self.log.text(since=self.start)):
            if warning not in self.seen:
                self.seen.add(warning)
                self.log.console.write(f"{PROG}: warning: {warning}\n")
        self.start = self.log.mark()


def run_render(request: RenderRequest) -> int:
    """Load, then render and save each frame; returns the exit status.

    Frames given with -f or -a follow Blender's Output > Overwrite (off: a frame
    whose images all exist is skipped, and only the missing images of the
    others are written) and Placeholders (an empty file at each image while its
    frame renders, removed if the frame is not saved).  Each frame's images are
    committed as soon as it is rendered, and their paths printed, so a stop
    leaves the finished frames in place.
    """
    log = BlenderLog(passthrough=request.verbose)
    started = time.monotonic()
    ours = request.engine == ENGINES["mcengine"]
    with log.capture():
        bpy = _start_blender(register=ours)
        scene = _open(request.blendfile, request.scene)
        interrupt.check()
        apply_overrides(scene, engine=request.engine, samples=request.samples, seed=request.seed,
                        resolution=request.resolution, threads=request.threads,
                        integrator=request.integrator, depth=request.depth,
                        branching=request.branching, overwrite=request.overwrite,
                        placeholders=request.placeholders, sampler=request.sampler)
    frames = _frames(scene, request, log.console)
    paths = {frame: [frame_path(output.pattern, frame) for output in request.outputs]
             for frame in frames}
    # Again now that the frames are known ('#' in a name), before anything is rendered.
    check_output_paths([path for frame in frames for path in paths[frame]], request.blendfile)
    if request.keep_partial:
        check_output_paths([partial_path(path) for frame in frames for path in paths[frame]],
                           request.blendfile)
    by_frame = len(frames) > 1          # one line per frame instead of per 10 %
    rules = bool(request.frame_actions)  # Blender's Overwrite and Placeholders apply
    warnings = _Warnings(log)
    rendered = skipped = 0
    samples = None
    for index, frame in enumerate(frames):
        interrupt.check()
        where = f"frame {frame} [{index + 1}/{len(frames)}]"
        targets = list(zip(request.outputs, paths[frame]))
        if rules and not scene.render.use_overwrite:
            targets = [(output, path) for output, path in targets if not path.exists()]
            if not targets:
                skipped += 1
                log.console.write(f"{PROG}: {where}: skipped, "
                                  f"{' and '.join(map(str, paths[frame]))} exist"
                                  f"{'s' if len(paths[frame]) == 1 else ''} (Overwrite is off)\n")
                continue
        frame_started = time.monotonic()
        with log.capture():
            scene.frame_set(frame)     # animation, drivers and the animated seed follow
        label = f"{request.engine} {where}" if by_frame else request.engine
        samples = _render_frame(bpy, scene, request, targets, log,
                                Progress(log.console, label, lines=not by_frame),
                                placeholders=rules and scene.render.use_placeholder,
                                where=where if by_frame else None)
        rendered += 1
        warnings.flush()
        if by_frame:
            log.console.write(f"{PROG}: {where}: {_samples_text(samples, scene)}, "
                              f"{time.monotonic() - frame_started:.1f} s\n")
        for _, path in targets:
            print(path, flush=True)
    _summary(log.console, scene, request, frames, rendered, skipped, samples,
             time.monotonic() - started)
    if ours and rendered and not by_frame:
        plan = getattr(getattr(scene, "mcengine", None), "last_effects", "")
        if plan:
            log.console.write(f"{PROG}: plan: {plan}\n")
        accounting = _ray_accounting()
        if accounting:
            log.console.write(f"{PROG}: {accounting}\n")
    return EXIT_OK


def _render_frame(bpy, scene, request, targets, log, progress, placeholders: bool,
                  where: str | None) -> int | None:
    """:func:`_render`, with Blender's placeholders around it and the frame named in errors."""
    made = []
    try:
        if placeholders:
            for _, path in targets:
                try:
                    made.append(touch_placeholder(path))
                except OutputError as exc:
                    raise CliError(str(exc), EXIT_RENDER_FAILED) from None
        return _render(bpy, scene, request, targets, log, progress)
    except CliError as exc:
        if where is None:
            raise
        raise CliError(f"{where}: {exc}", exc.exit_code) from None
    finally:
        for path in made:
            if path is not None:
                remove_placeholder(path)    # unless the image replaced it


def _samples_text(samples: int | None, scene) -> str:
    asked = scene.cycles.samples
    if samples is None or samples == asked:
        return f"{asked} samples"
    return f"{samples} of {asked} samples"


def _summary(console, scene, request, frames, rendered, skipped, samples, seconds) -> None:
    render = scene.render
    scale = render.resolution_percentage / 100
    size = f"{round(render.resolution_x * scale)}x{round(render.resolution_y * scale)}"
    if len(frames) == 1 and rendered:
        console.write(f"{PROG}: rendered {scene.name!r} frame {frames[0]} with {request.engine}, "
                      f"{size}, {_samples_text(samples, scene)}, in {seconds:.1f} s\n")
        return
    what = f"frame {frames[0]}" if len(frames) == 1 else (
        f"frames {frames[0]}..{frames[-1]}" if list(frames) == list(
            range(frames[0], frames[-1] + 1)) else f"{len(frames)} frames")
    line = (f"{PROG}: rendered {rendered} of {len(frames)} frame{'s' if len(frames) > 1 else ''} "
            f"of {scene.name!r} ({what}) with {request.engine}, {size}, "
            f"{scene.cycles.samples} samples, in {seconds:.1f} s")
    if skipped:
        line += f"; {skipped} skipped (their images exist and Overwrite is off)"
    console.write(line + "\n")


# ---------------------------------------------------------------------------
# compare
# ---------------------------------------------------------------------------

def run_compare(request: CompareRequest) -> int:
    """Compare one file or a suite; returns the exit status (0 agree, 3 differ)."""
    log = BlenderLog(passthrough=request.verbose)
    with log.capture():
        bpy = _start_blender(register=True)
    from mcengine.evaluation.comparison import fmt_num
    from mcengine.evaluation.output import write_comparison

    from ..batch.comparison import CompareError, CompareOptions, compare_file, run_suite
    renderer = _LoggedRenderer(bpy, log, request.threads)
    options = CompareOptions(samples=request.samples, resolution=request.resolution,
                             percentage=request.percentage, seeds=request.seeds,
                             alpha=request.alpha)
    console = log.console
    if request.suite is not None:
        def on_scene(path, index, total):
            console.write(f"{PROG}: comparing {path.name} ({index + 1}/{total})\n")

        def on_done(row):
            detail = row.error if row.verdict == "error" else (
                f"relMSE {fmt_num(row.relmse, '.3g')}, FLIP {fmt_num(row.flip, '.3f')}, "
                f"blocks differ {row.blocks_differ}")
            console.write(f"{PROG}: {row.scene}: {row.verdict} ({detail})\n")

        with log.capture():
            rows, paths = run_suite(request.suite, options, request.out, render=renderer,
                                    on_scene=on_scene, on_render=renderer.on_render,
                                    on_done=on_done)
        verdicts = {row.verdict for row in rows}
        console.write(f"{PROG}: {sum(r.verdict == 'agree' for r in rows)}/{len(rows)} scenes agree; "
                      f"summary in {paths['summary.md']} and {paths['summary.html']}\n")
        print(paths["summary.json"])
        if "error" in verdicts:
            return EXIT_RENDER_FAILED
        return EXIT_DIFFER if "differ" in verdicts else EXIT_OK
    try:
        with log.capture():
            comparison = compare_file(request.blendfile, options, scene_name=request.scene,
                                      render=renderer, on_render=renderer.on_render)
            interrupt.check()
            paths = write_folder(write_comparison, comparison, request.out)
    except (CompareError, OutputError) as exc:
        raise CliError(str(exc), EXIT_RENDER_FAILED) from None
    for warning in renderer.warnings:
        console.write(f"{PROG}: warning: {warning}\n")
    console.write(f"{PROG}: {comparison.summary()}\n{PROG}: wrote " + ", ".join(
        str(paths[name]) for name in ("side_by_side.png", "report.md", "mcengine.exr",
                                      "cycles.exr")) + "\n")
    print(paths["report.json"])
    return EXIT_OK if comparison.verdict == "agree" else EXIT_DIFFER


# ---------------------------------------------------------------------------
# study
# ---------------------------------------------------------------------------

def run_study(request: StudyRequest) -> int:
    """Render the study and write its files; returns the exit status."""
    log = BlenderLog(passthrough=request.verbose)
    with log.capture():
        bpy = _start_blender(register=True)
    from mcengine.evaluation.output import write_study
    from mcengine.evaluation.study import StudyError, StudyOptions, summarise

    from ..batch.study import StudySettings, study_file
    console = log.console
    # One line per render: a study makes a hundred, too many for a bar each.
    renderer = _LoggedRenderer(bpy, log, None, bars=False)

    def on_render(label, index, total):
        renderer.label = label
        console.write(f"{PROG}: [{index + 1}/{total}] {label}\n")

    options = StudyOptions(integrators=request.integrators, with_cycles=request.with_cycles,
                           max_samples=request.max_samples, seeds=request.seeds,
                           reference_samples=request.reference_samples,
                           target_relmse=request.target, reference=request.reference)
    settings = StudySettings(resolution=request.resolution, depth=request.depth,
                             branching=request.branching, threads=request.threads,
                             sampler=request.sampler)
    try:
        with log.capture():
            study = study_file(request.blendfile, options, settings, scene_name=request.scene,
                               render=renderer, on_render=on_render)
            interrupt.check()
            paths = write_folder(write_study, study, request.out)
    except (StudyError, RuntimeError, OutputError) as exc:
        raise CliError(str(exc).splitlines()[0], EXIT_RENDER_FAILED) from None
    for warning in renderer.warnings:
        console.write(f"{PROG}: warning: {warning}\n")
    for name, s in summarise(study).items():
        console.write(f"{PROG}: {study_line(name, s)}\n")
    console.write(f"{PROG}: wrote {paths['csv']}, {paths['time']}, {paths['markdown']}\n")
    print(paths["html"])
    return EXIT_OK


def study_line(name: str, s) -> str:
    """One line per integrator: time to target, slope, plateau."""
    if s.time_to_target is None:
        reach = f"does not reach relMSE {s.target:g}"
    else:
        how = {"extrapolated": " (extrapolated)", "first rung": " (at 1 sample)"}.get(
            s.target_how, "")
        reach = f"relMSE {s.target:g} in {s.time_to_target:.2f} s{how}"
    parts = [f"{name}: {reach}"]
    if s.slope is not None:
        parts.append(f"slope {s.slope:.3f} ± {s.slope_ci:.3f}")
    if s.plateau:
        parts.append(f"plateau at relMSE {s.floor:.3g}")
    return ", ".join(parts)
