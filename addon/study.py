"""Accuracy against time on a Blender scene: the bpy half of :mod:`mcengine.study`.

``study_scene`` renders the scene as it is in memory (saved or not) with each
of MC Engine's integrators, and with Cycles if asked, at a ladder of sample
counts and several seeds, and hands the timed images to
:func:`mcengine.study.run_study`, which measures the errors; the scene's
settings are restored afterwards.  ``study_file`` does the same for a .blend
on disk.  The command line (``mcengine study``) and the "Study Accuracy vs
Time" operator go through here.

Settings: the comparison's matched, unbiased settings
(``comparison.matched_settings``: denoising, adaptive sampling, clamping,
Filter Glossy and the time limit off, CPU), so every error is the algorithm's
own.  The integrator is chosen through ``scene.mcengine``; ``depth`` applies
to Whitted and distribution ray tracing (Whitted keeps the scene's depth when
it is not given), ``branching`` to distribution ray tracing.

Timing: each render's ``seconds`` is the wall time of the render operator
alone (``batch.render_scene``): for MC Engine the scene export, BVH build,
kernel set-up, tracing and shading; for Cycles its scene sync, BVH build and
rendering; for both, writing the image to a temporary 32-bit EXR.  Loading
the file, reading the image back and measuring the error are not counted.
One untimed 1-sample render per integrator first loads (or compiles) its
kernels, so JIT compilation is not charged to the first rung.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from mcengine.study import CYCLES, Study, StudyError, StudyOptions, run_study

from . import batch

__all__ = ["DISTRIBUTION_DEPTH", "DISTRIBUTION_BRANCHING", "StudySettings", "study_scene",
           "study_file", "TIMING_NOTE"]

# Distribution ray tracing's defaults for a study: 4 rays at each of the first
# two hits, 1 + 4 + 16 = 21 closest-hit rays per camera sample (about five
# times a path's on the Cornell box) and two bounces of indirect light.  One
# level more costs four times as much (85 rays), the lecture's b^r growth;
# with fewer levels the missing bounces dominate the error.
DISTRIBUTION_DEPTH = 3
DISTRIBUTION_BRANCHING = 4

# scene.mcengine values for each of the study's integrator names.
_ENUM = {"path": "PATH", "raycast": "RAYCAST", "whitted": "WHITTED",
         "distribution": "DISTRIBUTION"}
_OWN_SETTINGS = ("integrator", "depth", "branching")

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
    """

    resolution: tuple | None = None
    depth: int | None = None
    branching: int | None = None
    threads: int | None = None


def _integrator_settings(scene, settings: StudySettings) -> dict:
    """Integrator -> (depth, branching) it renders with."""
    own = scene.mcengine
    whitted_depth = settings.depth or own.depth
    return {"path": (own.depth, own.branching), "raycast": (1, own.branching),
            "whitted": (whitted_depth, own.branching),
            "distribution": (settings.depth or DISTRIBUTION_DEPTH,
                             settings.branching or DISTRIBUTION_BRANCHING)}


def _descriptions(chosen: dict, integrators) -> dict:
    """Integrator -> one-line description of its settings, for the report."""
    out = {}
    if "whitted" in integrators:
        out["whitted"] = f"depth {chosen['whitted'][0]}"
    if "distribution" in integrators:
        depth, b = chosen["distribution"]
        rays = sum(b ** k for k in range(depth))
        out["distribution"] = f"depth {depth}, branching {b}: up to {rays} rays per sample"
    return out


def study_scene(scene, options: StudyOptions = StudyOptions(), settings: StudySettings = StudySettings(),
                *, name: str | None = None, render=batch.render_scene, on_render=None) -> Study:
    """Study ``scene`` (left as it was afterwards).

    Parameters
    ----------
    scene : bpy.types.Scene
    options : mcengine.study.StudyOptions
    settings : StudySettings
    name : str, optional
        Name in the report; default the scene's name.
    render : callable
        ``render(scene, engine, samples=, seed=) -> batch.Render``; the command
        line passes one that shows progress.
    on_render : callable, optional
        ``on_render(label, index, total)`` before each render (index from 0).

    Returns
    -------
    mcengine.study.Study

    Raises
    ------
    StudyError
        On invalid options or a failed render (with the engine's message).
    """
    from .cli import error_message
    from .comparison import matched_settings

    options.validate()
    batch.ensure_registered()
    own = scene.mcengine
    saved = {key: getattr(own, key) for key in _OWN_SETTINGS}
    threads = scene.render.threads_mode, scene.render.threads
    chosen = _integrator_settings(scene, settings)
    try:
        with batch.restoring(scene):
            matched_settings(scene)
            if settings.resolution is not None:
                scene.render.resolution_x, scene.render.resolution_y = settings.resolution
                scene.render.resolution_percentage = 100
            if settings.threads is not None:
                scene.render.threads_mode = "AUTO" if settings.threads == 0 else "FIXED"
                if settings.threads:
                    scene.render.threads = settings.threads

            def render_one(integrator, samples, seed):
                engine = "cycles" if integrator == CYCLES else "mcengine"
                if engine == "mcengine":
                    own.integrator = _ENUM[integrator]
                    own.depth, own.branching = chosen[integrator]
                try:
                    return render(scene, engine, samples=samples, seed=seed)
                except RuntimeError as exc:
                    raise StudyError(f"{integrator} render failed: {error_message(exc)}") from None

            study = run_study(render_one, options, scene=name or scene.name,
                              settings=_descriptions(chosen, options.integrators),
                              notes=[TIMING_NOTE], on_render=on_render)
    finally:
        for key, value in saved.items():
            if getattr(own, key) != value:
                setattr(own, key, value)
        if (scene.render.threads_mode, scene.render.threads) != threads:
            scene.render.threads_mode, scene.render.threads = threads
    if options.integrators and own.last_ignored:
        study.notes.append(f"MC Engine does not support, and rendered without: "
                           f"{own.last_ignored}. Its reference leaves them out too, so its "
                           f"errors measure its own convergence, not its agreement with Cycles.")
    return study


def study_file(path, options: StudyOptions = StudyOptions(),
               settings: StudySettings = StudySettings(), *, scene_name: str | None = None,
               render=batch.render_scene, on_render=None) -> Study:
    """Open ``path`` and :func:`study_scene` it; the report is named after the file."""
    from .comparison import CompareError, open_scene
    try:
        scene = open_scene(path, scene_name)
    except CompareError as exc:
        raise StudyError(str(exc)) from None
    return study_scene(scene, options, settings, name=Path(path).stem, render=render,
                       on_render=on_render)

