"""The data files of the evaluation, for scripts: CSV and JSON.

* ``report.json``: a comparison's report dictionary
  (:attr:`mcengine.evaluation.comparison.Comparison.report`), strict JSON;
* ``summary.json``: a suite's verdict and one row per scene;
* ``study.csv``: one line per render of a study, columns :data:`COLUMNS`
  (read back with :func:`read_csv`);
* ``study.json``: a study's numbers (options, references, each integrator's
  summary), without images.
"""
from __future__ import annotations

import csv
import json
from dataclasses import asdict, fields

from .comparison import Comparison, suite_verdict
from .stats import jsonable
from .study import Study, StudyRow

__all__ = ["COLUMNS", "write_comparison_json", "write_suite_json", "write_csv", "read_csv",
           "study_json", "write_study_json"]

# study.csv: the fields of a StudyRow, in order.
COLUMNS = tuple(f.name for f in fields(StudyRow))


def write_comparison_json(c: Comparison, path) -> None:
    """``report.json``: the report dictionary (NaN and inf are already None)."""
    path.write_text(json.dumps(c.report, indent=1, allow_nan=False) + "\n")


def write_suite_json(rows, path) -> None:
    """``summary.json``: ``{"verdict": ..., "scenes": [row, ...]}``."""
    path.write_text(json.dumps(
        {"verdict": suite_verdict(rows), "scenes": [r.to_dict() for r in rows]}, indent=1) + "\n")


def write_csv(rows, path) -> None:
    """One line per render, columns :data:`COLUMNS`."""
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=COLUMNS)
        writer.writeheader()
        for row in rows:
            d = asdict(row)
            d["seconds"] = f"{row.seconds:.6g}"
            d["relmse"] = f"{row.relmse:.8g}"
            d["relmse_untrimmed"] = f"{row.relmse_untrimmed:.8g}"
            d["smape"] = f"{row.smape:.8g}"
            writer.writerow(d)


def read_csv(path) -> list[StudyRow]:
    """Rows written by :func:`write_csv`."""
    with open(path, newline="") as f:
        return [StudyRow(integrator=d["integrator"], samples=int(d["samples"]), seed=int(d["seed"]),
                         replicate=int(d["replicate"]), seconds=float(d["seconds"]),
                         relmse=float(d["relmse"]),
                         relmse_untrimmed=float(d["relmse_untrimmed"]), smape=float(d["smape"]),
                         reference=d["reference"])
                for d in csv.DictReader(f)]


def study_json(study: Study, summaries: dict) -> dict:
    """The numbers of the report (no images)."""
    return jsonable({
        "scene": study.scene, "width": study.width, "height": study.height,
        "options": asdict(study.options), "ladder": study.options.ladder(),
        "settings": study.settings, "notes": study.notes,
        "references": {k: {"samples": r.samples, "renders": r.renders, "seconds": r.seconds,
                           "self_relmse": r.self_relmse,
                           "self_relmse_untrimmed": r.self_relmse_untrimmed}
                       for k, r in study.references.items()},
        "integrators": {k: s.to_dict() for k, s in summaries.items()},
    })


def write_study_json(study: Study, summaries: dict, path) -> None:
    """``study.json``: :func:`study_json`."""
    path.write_text(json.dumps(study_json(study, summaries), indent=2), encoding="utf-8")
