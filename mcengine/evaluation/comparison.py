"""One scene compared with Cycles: the renders, the verdict, the report's numbers.

Concept
-------
A comparison holds, for one scene, a stack of ``K`` renders per engine (made
with different seeds under matched, unbiased settings) and the statistical
verdict of :func:`mcengine.evaluation.stats.compare_stacks` on them.
:func:`build_comparison` assembles what a person or a script reads about it
into one JSON-ready dictionary, ``Comparison.report`` (written as
``report.json``, with the verdict as the top-level key ``"verdict"``:
``"agree"`` or ``"differ"``): render times, samples, per-channel means with
confidence intervals, relMSE, SMAPE, mean HDR-FLIP, the share of significant
blocks, the bias the comparison could detect and the regions that differ.  A
suite of scenes is summed up one :class:`SuiteRow` per scene.

This module is the model only: the files (``report.md``,
``side_by_side.png``, the suite table, ...) are written by
:mod:`mcengine.evaluation.output` with the figures, pages and data-file
writers.

Conventions
-----------
Images are ``(h, w, 4)`` or ``(h, w, 3)`` float arrays of scene-linear
radiance, top row first; only RGB is compared.  "ours" is MC Engine (stack
``a`` of the statistics), "Cycles" the reference (stack ``b``): differences
are ours - Cycles and relative ones ours / Cycles - 1.  The error metrics
(relMSE, SMAPE, FLIP) compare the two K-seed averages, so they include both
engines' noise; they describe how close the images look, while only the
verdict tests whether the expected values differ.

No bpy; flip-evaluator (FLIP) is imported when first needed.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .stats import CHANNELS, Agreement, compare_stacks, relmse, smape, student_t_isf

__all__ = [
    "OURS_LABEL", "CYCLES_LABEL", "EngineRuns", "Comparison", "build_comparison",
    "differing_regions", "detectable_bias", "frame_finding", "FrameFinding", "POWER_BIAS",
    "SuiteRow", "suite_row", "suite_verdict",
]

# How reports name the two engines.
OURS_LABEL = "MC Engine"
CYCLES_LABEL = "Cycles"

# The detectable bias is the frame bias that the frame test finds with this
# probability (one-sided quantile 1.645 with many degrees of freedom).
DETECTION_POWER = 0.95
# A frame test that finds no difference says the frame means *agree* only if it
# could have found a bias of this size: detectable bias at most POWER_BIAS in
# every channel.  Otherwise the means are "not distinguishable at this noise".
POWER_BIAS = 0.05


# ----------------------------------------------------------------------------
# Inputs and the comparison itself
# ----------------------------------------------------------------------------

@dataclass
class EngineRuns:
    """The K renders of one engine.

    images   (K, h, w, 3 or 4) float, scene-linear, top row first
    seconds  (K,) wall time of each render
    samples  samples per pixel of each render
    seeds    (K,) the seeds used
    notes    lines for the report, e.g. features the engine did not support
    nonfinite  samples the engine dropped as NaN or infinite, over the K renders
    """

    images: np.ndarray
    seconds: list
    samples: int
    seeds: list
    notes: list = field(default_factory=list)
    nonfinite: int = 0

    @property
    def mean_image(self) -> np.ndarray:
        """(h, w, C) float32 average over the seeds."""
        return np.asarray(self.images, np.float64).mean(axis=0).astype(np.float32)

    @property
    def mean_seconds(self) -> float:
        return float(np.mean(self.seconds))


@dataclass
class Comparison:
    """One scene compared: the inputs, the statistics and the metrics.

    ``report`` is the JSON-ready dictionary written as ``report.json``.
    """

    scene: str
    ours: EngineRuns
    cycles: EngineRuns
    agreement: Agreement
    report: dict
    notes: list = field(default_factory=list)

    @property
    def verdict(self) -> str:
        return self.agreement.verdict

    def summary(self) -> str:
        """One line for a terminal or Blender's info bar."""
        m = self.report["metrics"]
        blocks = self.report["blocks"]
        bias = ", ".join(f"{ch} {100 * v:+.2f}%" for ch, v in
                         self.report["frame"]["rel_bias"].items() if v is not None)
        finding = frame_finding(self.report)
        caveat = f"; {finding.caveat}" if finding.caveat else ""
        return (f"{self.scene}: {self.verdict} (frame MC/Cycles-1 {bias}{caveat}; "
                f"{blocks['differ']}/{blocks['tested']} blocks differ; relMSE {fmt_num(m['relmse'])}, "
                f"FLIP {fmt_num(m['flip'], '.3f')})")


def detectable_bias(agreement: Agreement, power: float = DETECTION_POWER) -> np.ndarray:
    """Smallest relative frame bias the verdict finds with probability ``power``.

    A frame channel whose Holm-unadjusted p-value is below ``alpha / n_tests``
    is rejected whatever the other tests give, so a bias of
    ``(t_crit + t_power) * se / mean`` is caught at least with probability
    ``power``, where ``t_crit`` is the two-sided quantile at ``alpha / n_tests``
    and ``t_power`` the one-sided quantile at ``power``, both of Student's t
    with the frame test's Welch degrees of freedom.  With many degrees of
    freedom these are the normal quantiles (about 4.6 + 1.6 standard errors
    for 195 tests).  With few, as when a handful of bright pixels carry most of
    the noise, the quantiles grow, and so does the bias the test can see: the
    normal quantiles would claim a test some 8 times more sensitive than it is
    (``tests/core/test_report.py``); these err on the safe side.

    Returns
    -------
    (3,) float
        Per RGB channel, relative to Cycles' frame mean (inf where it is 0).
    """
    dof = agreement.frame_dof
    t_crit = student_t_isf(agreement.alpha / (2 * max(agreement.n_tests, 1)), dof)
    t_power = student_t_isf(1.0 - power, dof)
    se = np.hypot(agreement.frame_se_a, agreement.frame_se_b)
    mean = np.abs(agreement.frame_mean_b)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(mean > 0, (t_crit + t_power) * se / np.where(mean > 0, mean, 1.0),
                        np.inf)


@dataclass(frozen=True)
class FrameFinding:
    """What the frame test found, in words: ``kind`` is "differ", "agree" or
    "not distinguishable"; ``headline`` says it, ``values`` gives the frame biases."""

    kind: str
    headline: str
    values: str
    detectable: float       # the largest detectable bias over the channels tested

    @property
    def text(self) -> str:
        return f"{self.headline}: {self.values}"

    @property
    def caveat(self) -> str:
        """For an "agree" verdict whose frame test lacked power: what it could not see."""
        if self.kind != "not distinguishable":
            return ""
        return f"nothing found, but a frame bias up to {_percent(self.detectable)} could hide " \
               "in the noise"


def _frame_difference(report: dict, ch: str) -> str:
    """How channel ``ch``'s frame mean differs: relative to Cycles', or both means where
    Cycles' is zero (a channel it renders black, where a relative difference is undefined)."""
    rel = report["frame"]["rel_bias"][ch]
    if rel is not None:
        return f"{ch} {100 * rel:+.1f}%"
    ours, ref = report["means"]["mcengine"][ch]["mean"], report["means"]["cycles"][ch]["mean"]
    return f"{ch} {ours:.4g} against Cycles' {ref:.4g}"


def frame_finding(report: dict) -> FrameFinding:
    """The frame test's result as a person should read it.

    * "differ": a channel's frame mean differs significantly;
    * "agree": none does, and the test could have seen a difference: a bias of
      :data:`POWER_BIAS` would have been found with :data:`DETECTION_POWER`
      probability in every channel (detectable bias <= POWER_BIAS);
    * "not distinguishable": none does, but the noise would have hidden a bias
      larger than POWER_BIAS; "agree" would claim what the test cannot know.
    """
    frame = report["frame"]
    differs = [ch for ch, d in frame["differs"].items() if d]
    if differs:
        return FrameFinding("differ", "frame mean differs", ", ".join(
            _frame_difference(report, ch) for ch in differs), math.nan)
    values = ", ".join(f"{ch} {100 * v:+.2f}%" for ch, v in frame["rel_bias"].items()
                       if v is not None)
    detectable = [math.inf if v is None else v for ch, v in frame["detectable_bias"].items()
                  if frame["rel_bias"][ch] is not None]
    worst = max(detectable, default=math.inf)
    if worst <= POWER_BIAS:
        return FrameFinding("agree", f"frame means agree (detectable bias {_percent(worst)} "
                                     f"<= {_percent(POWER_BIAS)})", values, worst)
    return FrameFinding("not distinguishable", "frame means not distinguishable at this noise "
                                               f"(detectable bias {_percent(worst)})", values,
                        worst)


def _percent(v: float) -> str:
    """0.0033 -> '0.33 %', 1.35 -> '135 %', 87.2 -> '8.7e+03 %'; inf -> 'unbounded'."""
    if not math.isfinite(v):
        return "unbounded"
    value = 100 * v
    return f"{value:.2g} %" if value < 100 else (f"{value:.0f} %" if value < 1e4
                                                 else f"{value:.1e} %")


def _where(cx: float, cy: float) -> str:
    """'left top', 'centre middle', ... for a point in [0, 1]^2 (y down)."""
    horizontal = ("left", "centre", "right")[min(int(cx * 3), 2)]
    vertical = ("top", "middle", "bottom")[min(int(cy * 3), 2)]
    return f"{vertical} {horizontal}"


def differing_regions(agreement: Agreement) -> list:
    """Connected groups of differing blocks, as pixel rectangles.

    Blocks with at least one rejected channel are grouped by 4-neighbourhood.

    Returns
    -------
    list of dict, largest ``max_abs_t`` first
        ``pixels``: [x0, y0, x1, y1] bounding box (top-left origin, exclusive
        ends); ``where``: its position in words; ``blocks``: number of blocks;
        ``channels``: {channel: mean relative difference over the region's
        rejected blocks of that channel, None where Cycles is black};
        ``max_abs_t``; ``ours``: "brighter"
        or "darker" (sign of the largest-|t| test).
    """
    rejected = agreement.block_rejected
    differ = rejected.any(axis=-1)
    h, w = agreement.shape
    ey, ex = agreement.edges_y, agreement.edges_x
    seen = np.zeros_like(differ)
    regions = []
    for start in zip(*np.nonzero(differ)):
        if seen[start]:
            continue
        members, todo = [], [start]
        seen[start] = True
        while todo:
            r, c = todo.pop()
            members.append((r, c))
            for rr, cc in ((r - 1, c), (r + 1, c), (r, c - 1), (r, c + 1)):
                if 0 <= rr < differ.shape[0] and 0 <= cc < differ.shape[1] \
                        and differ[rr, cc] and not seen[rr, cc]:
                    seen[rr, cc] = True
                    todo.append((rr, cc))
        rows, cols = np.array(members).T
        x0, x1 = int(ex[cols.min()]), int(ex[cols.max() + 1])
        y0, y1 = int(ey[rows.min()]), int(ey[rows.max() + 1])
        t = agreement.block_t[rows, cols]                   # (n, 3)
        hit = rejected[rows, cols]
        channels = {CHANNELS[ch]: _finite(np.mean(agreement.block_rel_diff[rows, cols, ch][hit[:, ch]]))
                    for ch in range(3) if hit[:, ch].any()}
        masked = np.where(hit, np.abs(t), -1.0)
        worst = np.unravel_index(np.argmax(masked), masked.shape)
        regions.append(dict(
            pixels=[x0, y0, x1, y1], where=_where((x0 + x1) / 2 / w, (y0 + y1) / 2 / h),
            blocks=len(members), channels=channels, max_abs_t=float(masked[worst]),
            ours="brighter" if t[worst] > 0 else "darker"))
    return sorted(regions, key=lambda r: -r["max_abs_t"])


def _channel_dict(values) -> dict:
    return {ch: _finite(v) for ch, v in zip(CHANNELS, np.asarray(values, np.float64))}


def _finite(v):
    v = float(v)
    return v if math.isfinite(v) else None


_FLIP_MIN_VALUE = 1e-20     # a reference with no larger value is black to HDR-FLIP


def _flip(ours_rgb: np.ndarray, cycles_rgb: np.ndarray) -> float | None:
    """Mean HDR-FLIP of ours against Cycles (flip-evaluator, linear RGB input); None where
    Cycles' image is black: HDR-FLIP's exposures come from the reference's largest luminance,
    and without one flip-evaluator ends the whole process (Blender with it)."""
    import flip_evaluator
    ref = np.ascontiguousarray(np.maximum(cycles_rgb, 0.0), np.float32)
    test = np.ascontiguousarray(np.maximum(ours_rgb, 0.0), np.float32)
    if not np.max(ref, initial=0.0) > _FLIP_MIN_VALUE:
        return None
    _, mean, _ = flip_evaluator.evaluate(ref, test, "HDR", applyMagma=False)
    return float(mean)


def fmt_num(v, fmt=".4g") -> str:
    """A metric for people: "n/a" where there is none (None)."""
    return "n/a" if v is None else format(v, fmt)


def build_comparison(scene: str, ours: EngineRuns, cycles: EngineRuns, *, grid=(8, 8),
                     alpha: float = 1e-3, settings: dict | None = None,
                     notes=()) -> Comparison:
    """Compare the two stacks and assemble the report.

    Parameters
    ----------
    scene : str
        Name shown in the report (usually the .blend file's stem).
    ours, cycles : EngineRuns
        MC Engine's and Cycles' renders, same image size, K >= 2 each.
    grid, alpha
        Block grid and family-wise error rate of the verdict
        (:func:`mcengine.evaluation.stats.compare_stacks`).
    settings : dict, optional
        Render settings to record (resolution, bounces, ...); JSON-ready.
    notes : sequence of str
        Lines shown under the verdict, after the engines' own notes.

    Returns
    -------
    Comparison
    """
    agreement = compare_stacks(ours.images, cycles.images, grid=grid, alpha=alpha)
    notes = [*ours.notes, *cycles.notes, *notes]
    if ours.nonfinite:
        notes.append(f"{OURS_LABEL} dropped {ours.nonfinite:,} non-finite samples (NaN or "
                     f"infinite) over its {len(ours.seeds)} renders; its image leaves them out.")
    if agreement.pixels_correlated:
        notes.append("Neighbouring pixels of one engine are correlated (a denoiser or a "
                     "splatting pixel filter?); the test widened its variances to match.")
    ours_mean, cycles_mean = ours.mean_image[..., :3], cycles.mean_image[..., :3]
    z = student_t_isf(0.5 * (1.0 - agreement.confidence), math.inf)

    def means(mean, se):
        return {ch: {"mean": _finite(m), "ci": [_finite(m - z * s), _finite(m + z * s)],
                     "se": _finite(s)} for ch, m, s in zip(CHANNELS, mean, se)}

    h, w = agreement.shape
    tested = int((~np.isnan(agreement.block_p).all(axis=-1)).sum())
    differ = int(agreement.block_rejected.any(axis=-1).sum())
    report = {
        "verdict": agreement.verdict,
        "scene": scene,
        "summary": agreement.summary(),
        "test": {
            "method": "Welch t-tests of the frame mean and of each block mean per RGB channel, "
                      "noise estimated from the seed-to-seed spread, Holm-Bonferroni over all tests",
            "alpha": agreement.alpha, "grid": list(grid), "n_tests": agreement.n_tests,
            "n_skipped": agreement.n_skipped, "confidence": agreement.confidence,
        },
        "settings": {"resolution": [w, h], "samples": {"mcengine": ours.samples,
                                                         "cycles": cycles.samples},
                     "seeds": {"mcengine": list(ours.seeds), "cycles": list(cycles.seeds)},
                     **(settings or {})},
        "times": {
            "mcengine": {"renders": [float(s) for s in ours.seconds], "mean": ours.mean_seconds},
            "cycles": {"renders": [float(s) for s in cycles.seconds], "mean": cycles.mean_seconds},
        },
        "means": {"mcengine": means(agreement.frame_mean_a, agreement.frame_se_a),
                  "cycles": means(agreement.frame_mean_b, agreement.frame_se_b)},
        "frame": {
            "rel_bias": _channel_dict(agreement.frame_rel_bias),
            "rel_bias_ci": {ch: [_finite(lo), _finite(hi)] for ch, (lo, hi)
                            in zip(CHANNELS, agreement.frame_rel_bias_ci)},
            "t": _channel_dict(agreement.frame_t),
            "p_holm": _channel_dict(agreement.frame_p_holm),
            "differs": {ch: bool(r) for ch, r in zip(CHANNELS, agreement.frame_rejected)},
            "detectable_bias": _channel_dict(detectable_bias(agreement)),
            "power_bias": POWER_BIAS,
        },
        "metrics": {
            "relmse": relmse(ours_mean, cycles_mean),
            "smape": smape(ours_mean, cycles_mean),
            "flip": _flip(ours_mean, cycles_mean),
        },
        "blocks": {"tested": tested, "differ": differ,
                   "share_differ": agreement.share_blocks_differ},
        "regions": differing_regions(agreement),
        "pixel_correlation": {"mcengine": [float(v) for v in agreement.correlation[0]],
                              "cycles": [float(v) for v in agreement.correlation[1]]},
        "notes": notes,
        "agreement": agreement.to_dict(),
    }
    report["frame"]["finding"] = frame_finding(report).kind
    if ours.nonfinite:
        # Only when there are any: samples MC Engine dropped, summed over its K renders.
        report["nonfinite_samples"] = int(ours.nonfinite)
    return Comparison(scene=scene, ours=ours, cycles=cycles, agreement=agreement,
                      report=report, notes=notes)


# ----------------------------------------------------------------------------
# Suite of scenes
# ----------------------------------------------------------------------------

@dataclass
class SuiteRow:
    """One scene of a suite: its numbers, or the error that stopped it.

    ``folder`` is the scene's output folder relative to the summary files.
    """

    scene: str
    verdict: str            # "agree", "differ" or "error"
    folder: str
    relmse: float | None = None
    flip: float | None = None
    seconds_ours: float | None = None
    seconds_cycles: float | None = None
    max_abs_bias: float | None = None
    detectable_bias: float | None = None
    blocks_differ: str = ""
    resolution: str = ""
    samples: str = ""
    wall_seconds: float | None = None   # the whole scene: loading, 2K renders, report
    error: str = ""
    nonfinite: int = 0      # samples MC Engine dropped as NaN or infinite (K renders)

    def to_dict(self) -> dict:
        return dict(self.__dict__)


def suite_row(c: Comparison, folder: str) -> SuiteRow:
    """The summary row of one comparison."""
    r = c.report
    bias = [abs(v) for v in r["frame"]["rel_bias"].values() if v is not None]
    detectable = [v for v in r["frame"]["detectable_bias"].values() if v is not None]
    w, h = r["settings"]["resolution"]
    spp = r["settings"]["samples"]
    return SuiteRow(
        scene=c.scene, verdict=c.verdict, folder=folder, relmse=r["metrics"]["relmse"],
        flip=r["metrics"]["flip"], seconds_ours=c.ours.mean_seconds,
        seconds_cycles=c.cycles.mean_seconds, max_abs_bias=max(bias) if bias else None,
        detectable_bias=max(detectable) if detectable else None,
        blocks_differ=f"{r['blocks']['differ']}/{r['blocks']['tested']}",
        resolution=f"{w}x{h}",
        samples=f"{spp['mcengine']} x {len(c.ours.seeds)}",
        nonfinite=int(r.get("nonfinite_samples", 0)))


def suite_verdict(rows) -> str:
    """The suite's verdict: "error" if any scene failed, else "differ" if any differs, else "agree"."""
    return ("error" if any(r.verdict == "error" for r in rows)
            else "differ" if any(r.verdict == "differ" for r in rows) else "agree")
