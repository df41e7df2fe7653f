"""Compare MC Engine with Cycles on a Blender scene: the bpy half of the comparison.

``compare_scene`` renders the scene in memory (saved or not) ``K`` times with
each engine under matched settings, restores the scene's settings afterwards
and hands the pixels to :func:`mcengine.evaluation.comparison.build_comparison`,
which computes the verdict; :mod:`mcengine.evaluation.output` writes the
files.  ``compare_file`` does the same for a .blend on disk and ``run_suite``
for every .blend in a folder.  The command line (``mcengine compare``), the
"Compare with Cycles" operator and the fidelity tests all go through here.

Matched settings (both engines read Cycles' settings): the same resolution,
samples and bounces; denoising, adaptive sampling, clamping, Filter Glossy
and the time limit off; the view layer's sample override ignored; CPU; view
transform Standard; MC Engine's path tracing integrator (the others are
biased by design); renders read back as 32-bit linear EXR.  Seeds are
``first_seed, first_seed + 1, ...`` for both engines.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mcengine.evaluation.comparison import EngineRuns, SuiteRow, build_comparison, suite_row
from mcengine.evaluation.output import write_comparison, write_suite
from mcengine.integrators import INTEGRATORS

from .outputs import OutputError, write_folder
from .render import ENGINES, OpenError, ensure_registered, error_message, open_scene, render_scene
from .settings import apply_overrides, make_unbiased, restoring

__all__ = ["CompareOptions", "CompareError", "compare_scene", "compare_file", "render_runs",
           "suite_files", "run_suite", "render_size", "matched_settings"]

# The two engines of a comparison, in the order of the statistics' stacks a and b.
COMPARED = tuple(ENGINES)        # ("mcengine", "cycles")
# MC Engine's integrator in a comparison: the one that matches Cycles (path tracing).
INTEGRATOR = next(name for name, info in INTEGRATORS.items() if info.matches_cycles)


class CompareError(Exception):
    """The comparison could not be made; the message is one line for the user."""


@dataclass(frozen=True)
class CompareOptions:
    """What to render.

    samples      samples per render; None = the scene's Cycles samples
    resolution   (width, height) at 100 %; None = the scene's size
    percentage   scale of the scene's size in percent (instead of resolution)
    seeds        renders per engine, at least 2 (the noise is estimated from them)
    first_seed   seed of the first render of each engine
    alpha        family-wise false-alarm rate of the verdict
    grid         (rows, columns) of tested blocks
    """

    samples: int | None = None
    resolution: tuple | None = None
    percentage: int | None = None
    seeds: int = 2
    first_seed: int = 1
    alpha: float = 1e-3
    grid: tuple = (8, 8)


def render_size(scene, options: CompareOptions) -> tuple:
    """(width, height) in pixels that the comparison renders.

    Raises
    ------
    CompareError
        If the image would be smaller than the block grid.
    """
    render = scene.render
    if options.resolution is not None:
        width, height = options.resolution
    else:
        pct = options.percentage if options.percentage is not None else render.resolution_percentage
        width, height = render.resolution_x * pct // 100, render.resolution_y * pct // 100
    rows, cols = options.grid
    if width < cols or height < rows:
        raise CompareError(f"a {width}x{height} image is too small for the {cols}x{rows} block "
                           f"grid of the comparison")
    return int(width), int(height)


def matched_settings(scene) -> dict:
    """Apply the matched settings; returns the ones recorded in the report."""
    make_unbiased(scene)
    cycles = scene.cycles
    cycles.time_limit = 0.0
    cycles.use_layer_samples = "IGNORE"
    apply_overrides(scene, integrator=INTEGRATOR)
    return {"max_bounces": cycles.max_bounces, "diffuse_bounces": cycles.diffuse_bounces,
            "pixel_filter": f"{cycles.pixel_filter_type} {cycles.filter_width:g} px",
            "view_transform": scene.view_settings.view_transform,
            "denoising, adaptive sampling, clamping": "off"}


def _render_runs(scene, engine: str, options: CompareOptions, size, render, on_render,
                 first_index: int = 0, total: int | None = None) -> EngineRuns:
    """K renders of the (already matched) scene with one engine."""
    seeds = list(range(options.first_seed, options.first_seed + options.seeds))
    samples = options.samples if options.samples is not None else scene.cycles.samples
    renders = []
    for i, seed in enumerate(seeds):
        if on_render is not None:
            on_render(engine, first_index + i, total or len(seeds))
        try:
            renders.append(render(scene, engine, samples=samples, seed=seed, resolution=size))
        except RuntimeError as exc:
            raise CompareError(f"{engine} render failed: {error_message(exc)}") from None
    notes = []
    if engine == "mcengine":
        settings = getattr(scene, "mcengine", None)
        plan = getattr(settings, "last_effects", "")
        if plan:
            notes.append(f"MC Engine's effects plan: {plan}.")
        ignored = getattr(settings, "last_ignored", "")
        if ignored:
            notes.append(f"MC Engine does not support, and rendered without: {ignored}. "
                         f"Where these matter, \"differ\" is expected.")
    return EngineRuns(images=np.stack([r.image for r in renders]),
                      seconds=[r.seconds for r in renders], samples=renders[0].samples,
                      seeds=seeds, notes=notes,
                      nonfinite=sum(int(getattr(r, "nonfinite", 0) or 0) for r in renders))


def _check_seeds(options: CompareOptions) -> None:
    if options.seeds < 2:
        raise CompareError(f"at least 2 seeds per engine are needed to estimate the noise, "
                           f"got {options.seeds}")


def render_runs(scene, engine: str, options: CompareOptions = CompareOptions(), *,
                render=render_scene, on_render=None) -> EngineRuns:
    """One engine's K renders of ``scene`` under the matched settings (scene restored).

    For comparisons the caller assembles itself, e.g. a deliberately altered
    scene against the original, or Cycles against Cycles with other seeds.
    """
    _check_seeds(options)
    ensure_registered()
    with restoring(scene):
        matched_settings(scene)
        return _render_runs(scene, engine, options, render_size(scene, options), render,
                            on_render)


def compare_scene(scene, options: CompareOptions = CompareOptions(), *, name: str | None = None,
                  render=render_scene, on_render=None):
    """Render ``scene`` with both engines and compare (the scene is left as it was).

    Parameters
    ----------
    scene : bpy.types.Scene
        Rendered as it is in memory; its settings are restored afterwards.
    options : CompareOptions
    name : str, optional
        Name in the report; default the scene's name.
    render : callable
        ``render(scene, engine, samples=, seed=, resolution=) -> render.Render``;
        the command line passes one that shows progress.
    on_render : callable, optional
        ``on_render(engine, index, total)`` before each render (index from 0).

    Returns
    -------
    mcengine.evaluation.comparison.Comparison

    Raises
    ------
    CompareError
        If a render fails (with the engine's message) or the image is too small.
    """
    _check_seeds(options)
    ensure_registered()
    total = len(COMPARED) * options.seeds
    with restoring(scene):
        settings = matched_settings(scene)
        size = render_size(scene, options)
        runs = [_render_runs(scene, engine, options, size, render, on_render,
                             first_index=e * options.seeds, total=total)
                for e, engine in enumerate(COMPARED)]
    return build_comparison(name or scene.name, *runs, grid=options.grid, alpha=options.alpha,
                            settings=settings)


def compare_file(path, options: CompareOptions = CompareOptions(), *,
                 scene_name: str | None = None, render=render_scene, on_render=None):
    """Open ``path`` and :func:`compare_scene` it; the report is named after the file."""
    try:
        scene = open_scene(path, scene_name)
    except OpenError as exc:
        raise CompareError(str(exc)) from None
    return compare_scene(scene, options, name=Path(path).stem, render=render, on_render=on_render)


def suite_files(folder) -> list:
    """The .blend files directly in ``folder``, sorted by name."""
    return sorted(p for p in Path(folder).glob("*.blend") if p.is_file())


def run_suite(folder, options: CompareOptions, out_dir, *, render=render_scene,
              on_scene=None, on_render=None, on_done=None):
    """Compare every .blend in ``folder``; write per-scene folders and the summary.

    Scene ``NAME.blend`` gets the folder ``out_dir/NAME``.  A scene whose
    comparison fails (or whose files cannot be written) becomes an "error"
    row; the others still run.  Every file is written to a temporary file
    first and renamed into place once complete (:mod:`.outputs`), so files of
    an earlier run are replaced whole or not at all.

    Parameters
    ----------
    on_scene : callable, optional
        ``on_scene(path, index, total)`` before each scene.
    on_done : callable, optional
        ``on_done(row)`` after each scene, with its :class:`SuiteRow`.
    render, on_render
        As for :func:`compare_scene`.

    Returns
    -------
    rows : list of SuiteRow
    paths : dict
        The summary files written (see :func:`mcengine.evaluation.output.write_suite`).
    """
    out = Path(out_dir)
    rows = []
    files = suite_files(folder)
    for index, path in enumerate(files):
        if on_scene is not None:
            on_scene(path, index, len(files))
        started = time.perf_counter()
        try:
            comparison = compare_file(path, options, render=render, on_render=on_render)
            write_folder(write_comparison, comparison, out / path.stem)
            rows.append(suite_row(comparison, path.stem))
        except (CompareError, OutputError) as exc:
            rows.append(SuiteRow(scene=path.stem, verdict="error", folder=path.stem,
                                 error=str(exc)))
        rows[-1].wall_seconds = time.perf_counter() - started
        if on_done is not None:
            on_done(rows[-1])
    return rows, write_folder(write_suite, rows, out)
