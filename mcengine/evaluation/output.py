"""What a comparison, a suite and a study write into their folders.

Each ``write_*`` function writes every file of one result and returns the
paths by name; the files themselves come from :mod:`.figures` (images),
:mod:`.pages` (Markdown and HTML) and :mod:`.datafiles` (CSV and JSON).

* A comparison (:data:`COMPARISON_FILES`): ``mcengine.exr`` and
  ``cycles.exr``, each engine's K-seed average (linear), ``side_by_side.png``,
  ``report.json``, ``report.md`` and ``thumbnail.png`` for the suite table.
* A suite: ``summary.md``, ``summary.html`` and ``summary.json``, next to one
  comparison folder per scene.
* A study (:data:`STUDY_FILES`): ``study.csv``, the two error plots, the
  equal-time strip, ``study.html``, ``study.md`` and ``study.json``.
"""
from __future__ import annotations

from pathlib import Path

from ..imageio import write_exr, write_png
from . import datafiles, figures, pages
from .comparison import Comparison
from .study import Study, summarise

__all__ = ["COMPARISON_FILES", "SUITE_FILES", "STUDY_FILES", "write_comparison", "write_suite",
           "write_study"]

COMPARISON_FILES = ("mcengine.exr", "cycles.exr", "side_by_side.png", "report.json", "report.md")
SUITE_FILES = ("summary.md", "summary.html", "summary.json")
STUDY_FILES = {"csv": "study.csv", "time": "error_vs_time.png",
               "samples": "error_vs_samples.png", "strip": "equal_time.png",
               "html": "study.html", "markdown": "study.md", "json": "study.json"}


def write_comparison(c: Comparison, out_dir) -> dict:
    """Write the files of :data:`COMPARISON_FILES` (and ``thumbnail.png``) into ``out_dir``.

    Returns
    -------
    dict
        File name -> Path.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = {name: out / name for name in COMPARISON_FILES + ("thumbnail.png",)}
    write_exr(paths["mcengine.exr"], c.ours.mean_image)
    write_exr(paths["cycles.exr"], c.cycles.mean_image)
    figures.side_by_side(c, paths["side_by_side.png"])
    write_png(paths["thumbnail.png"], figures.thumbnail(c))
    datafiles.write_comparison_json(c, paths["report.json"])
    paths["report.md"].write_text(pages.report_markdown(c))
    return paths


def write_suite(rows, out_dir, title: str = "MC Engine vs Cycles") -> dict:
    """Write :data:`SUITE_FILES` for the suite's rows into ``out_dir``; returns name -> Path."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = {name: out / name for name in SUITE_FILES}
    paths["summary.md"].write_text(pages.suite_summary_markdown(rows, title))
    paths["summary.html"].write_text(pages.suite_html(rows, title))
    datafiles.write_suite_json(rows, paths["summary.json"])
    return paths


def write_study(study: Study, out) -> dict:
    """Write the CSV, plots, strip, HTML, Markdown table and JSON; returns name -> path."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    paths = {k: out / v for k, v in STUDY_FILES.items()}
    summaries = summarise(study)
    datafiles.write_csv(study.rows, paths["csv"])
    figures.plot_error(summaries, paths["time"], x="seconds",
                       title=f"{study.scene}: error against render time")
    figures.plot_error(summaries, paths["samples"], x="samples",
                       title=f"{study.scene}: error against samples per pixel")
    figures.equal_time_strip(study, summaries, paths["strip"])
    paths["html"].write_text(pages.study_html(study, summaries, STUDY_FILES), encoding="utf-8")
    paths["markdown"].write_text(pages.study_markdown(study, summaries), encoding="utf-8")
    datafiles.write_study_json(study, summaries, paths["json"])
    return paths
