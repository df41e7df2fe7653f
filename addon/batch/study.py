"""Accuracy against time on a Blender scene: the bpy half of :mod:`mcengine.evaluation.study`.

``study_scene`` renders the scene as it is in memory (saved or not) with each
of MC Engine's integrators, and with Cycles if asked, at a ladder of sample
counts and several seeds, and hands the timed images to
:func:`mcengine.evaluation.study.run_study`, which measures the errors; the
scene's settings are restored afterwards.  ``study_file`` does the same for a
.blend on disk.  The command line (``mcengine study``) and the "Study Accuracy
vs Time" operator go through here; :mod:`mcengine.evaluation.output` writes
the files.

Settings: the comparison's matched, unbiased settings
(``comparison.matched_settings``: denoising, adaptive sampling, clamping,
Filter Glossy and the time limit off, CPU), so every error is the algorithm's
own.  The integrator is chosen through ``scene.mcengine``; ``depth`` applies
to Whitted and distribution ray tracing (Whitted keeps the scene's depth when
it is not given), ``branching`` to distribution ray tracing.

Timing: each render's ``seconds`` is the wall time of the render operator
alone (``render.render_scene``): for MC Engine the scene export, BVH build,
kernel set-up, tracing and shading; for Cycles its scene sync, BVH build and
rendering; for both, writing the image to a temporary 32-bit EXR.  Loading
the file, reading the image back and measuring the error are not counted.
One untimed 1-sample render per integrator first loads (or compiles) its
kernels, so JIT compilation is not charged to the first rung.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from mcengine.evaluation.study import CYCLES, Study, StudyError, StudyOptions, run_study
from mcengine.integrators import INTEGRATORS
from mcengine.integrators import get as get_integrator
from mcengine.samplers import DEFAULT as DEFAULT_SAMPLER
from mcengine.samplers import get as get_sampler

from ..export.settings import sampler_for
from .comparison import matched_settings
from .render import OpenError, ensure_registered, error_message, open_scene, render_scene
from .settings import apply_overrides, restoring

__all__ = ["DISTRIBUTION_DEPTH", "DISTRIBUTION_BRANCHING", "StudySettings", "study_scene",
           "study_file", "TIMING_NOTE"]

# Distribution ray tracing's defaults for a study: 4 rays at each of the first
# two hits, 1 + 4 + 16 = 21 closest-hit rays per camera sample (about five
# times a path's on the Cornell box) and two bounces of indirect light.  One
# level more costs four times as much (85 rays), the lecture's b^r growth;
# with fewer levels the missing bounces dominate the error.
DISTRIBUTION_DEPTH = 3
DISTRIBUTION_BRANCHING = 4

TIMING_NOTE = (
    "Render times are the wall time of Blender's render operator alone: for MC Engine the "
    "scene export, BVH build, kernel set-up, tracing and shading; for Cycles its scene sync, "
    "BVH build and rendering; for both, writing the image to a temporary EXR. One untimed "
    "1-sample render per integrator first loads its compiled kernels.")


@dataclass(frozen=True)
class StudySettings:
    """Scene-side settings of a study.

    resolution  (width, height) at 100 %; None keeps the scene's size and percentage
    depth       ray levels of Whitted and distribution ray tracing; None: the scene's
                depth for Whitted, DISTRIBUTION_DEPTH for distribution
    branching   rays per hit of distribution ray tracing; None: DISTRIBUTION_BRANCHING
    threads     CPU threads (0 = all); None keeps the scene's setting
    sampler     the path tracer's sampler (a name of mcengine.samplers), for its ladder and
                its reference; None keeps the scene's setting
    """

    resolution: tuple | None = None
    depth: int | None = None
    branching: int | None = None
    threads: int | None = None
    sampler: str | None = None


def _integrator_settings(scene, settings: StudySettings) -> dict:
    """Integrator -> (depth, branching) it renders with.

    The one that branches (distribution ray tracing) gets the study's defaults
    above; the others get the depth given (else the scene's) and the scene's
    branching, of which only Whitted reads anything: its depth.
    """
    own = scene.mcengine
    chosen = {}
    for name, info in INTEGRATORS.items():
        if info.uses_branching:
            chosen[name] = (settings.depth or DISTRIBUTION_DEPTH,
                            settings.branching or DISTRIBUTION_BRANCHING)
        else:
            chosen[name] = (settings.depth or own.depth, own.branching)
    return chosen


def _descriptions(chosen: dict, integrators, sampler) -> dict:
    """Integrator -> one-line description of the settings it uses, for the report."""
    out = {}
    for name in integrators:
        info = get_integrator(name)
        parts = [info.settings_text(*chosen[name]),
                 f"{sampler.label} sampler" if info.uses_sampler else ""]
        text = "; ".join(part for part in parts if part)
        if text:
            out[name] = text
    return out


def study_scene(scene, options: StudyOptions = StudyOptions(), settings: StudySettings = StudySettings(),
                *, name: str | None = None, render=render_scene, on_render=None) -> Study:
    """Study ``scene`` (left as it was afterwards).

    Parameters
    ----------
    scene : bpy.types.Scene
    options : mcengine.evaluation.study.StudyOptions
    settings : StudySettings
    name : str, optional
        Name in the report; default the scene's name.
    render : callable
        ``render(scene, engine, samples=, seed=) -> render.Render``; the command
        line passes one that shows progress.
    on_render : callable, optional
        ``on_render(label, index, total)`` before each render (index from 0).

    Returns
    -------
    mcengine.evaluation.study.Study

    Raises
    ------
    StudyError
        On invalid options or a failed render (with the engine's message).
    """
    options.validate()
    ensure_registered()
    chosen = _integrator_settings(scene, settings)
    with restoring(scene):
        matched_settings(scene)
        apply_overrides(scene, resolution=settings.resolution, threads=settings.threads,
                        sampler=settings.sampler)

        def render_one(integrator, samples, seed):
            engine = "cycles" if integrator == CYCLES else "mcengine"
            if engine == "mcengine":
                depth, branching = chosen[integrator]
                apply_overrides(scene, integrator=integrator, depth=depth, branching=branching)
            try:
                return render(scene, engine, samples=samples, seed=seed)
            except RuntimeError as exc:
                raise StudyError(f"{integrator} render failed: {error_message(exc)}") from None

        sampler = sampler_for(scene, scene.cycles) or get_sampler(DEFAULT_SAMPLER)
        study = run_study(render_one, options, scene=name or scene.name,
                          settings=_descriptions(chosen, options.integrators, sampler),
                          notes=[TIMING_NOTE], on_render=on_render)
    plan = scene.mcengine.last_effects
    if options.integrators and plan:
        study.notes.append(f"MC Engine's effects plan (its last render): {plan}.")
    ignored = scene.mcengine.last_ignored
    if options.integrators and ignored:
        study.notes.append(f"MC Engine does not support, and rendered without: "
                           f"{ignored}. Its reference leaves them out too, so its "
                           f"errors measure its own convergence, not its agreement with Cycles.")
    return study


def study_file(path, options: StudyOptions = StudyOptions(),
               settings: StudySettings = StudySettings(), *, scene_name: str | None = None,
               render=render_scene, on_render=None) -> Study:
    """Open ``path`` and :func:`study_scene` it; the report is named after the file."""
    try:
        scene = open_scene(path, scene_name)
    except OpenError as exc:
        raise StudyError(str(exc)) from None
    return study_scene(scene, options, settings, name=Path(path).stem, render=render,
                       on_render=on_render)
