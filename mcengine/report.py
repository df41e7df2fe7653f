"""Side by side with Cycles: the comparison report, its images and the suite table.

Concept
-------
A comparison holds, for one scene, a stack of ``K`` renders per engine (made
with different seeds under matched, unbiased settings) and the statistical
verdict of :func:`mcengine.compare.compare_stacks` on them.  This module turns
that into what a person or a script reads:

* ``report.json``: every number, with the verdict as the top-level key
  ``"verdict"`` (``"agree"`` or ``"differ"``);
* ``report.md``: the same for people (render times, samples, per-channel means
  with confidence intervals, relMSE, SMAPE, mean HDR-FLIP, share of
  significant blocks, the regions that differ);
* ``side_by_side.png``: MC Engine | Cycles | signed difference | significant
  blocks, each panel labelled;
* ``mcengine.exr`` and ``cycles.exr``: each engine's K-seed average (linear);
* for a suite of scenes, one summary table as Markdown, HTML (with thumbnails)
  and JSON.

Conventions
-----------
Images are ``(h, w, 4)`` or ``(h, w, 3)`` float arrays of scene-linear
radiance, top row first; only RGB is compared.  "ours" is MC Engine (stack
``a`` of the statistics), "Cycles" the reference (stack ``b``): differences
are ours - Cycles and relative ones ours / Cycles - 1.  Both renders are shown
through the same tone mapping, Blender's "Standard" view transform (the sRGB
curve, clipped to [0, 1], exposure 0).  The error metrics (relMSE, SMAPE,
FLIP) compare the two K-seed averages, so they include both engines' noise;
they describe how close the images look, while only the verdict tests
whether the expected values differ.

No bpy: matplotlib (the side-by-side figure) and flip-evaluator (FLIP) are
imported when first needed.
"""
from __future__ import annotations

import html
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .compare import CHANNELS, Agreement, compare_stacks, relmse, smape, student_t_isf
from .imageio import linear_to_srgb, write_exr, write_png

__all__ = [
    "EngineRuns", "Comparison", "build_comparison", "write_comparison", "side_by_side",
    "thumbnail", "differing_regions", "detectable_bias", "SuiteRow", "suite_row",
    "suite_markdown", "suite_html", "write_suite",
]

OURS_LABEL = "MC Engine"
CYCLES_LABEL = "Cycles"

# Rec. 709 luminance weights (the working space of Blender's scenes): the
# difference panel shows one signed number per pixel.
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])

# The detectable bias is the frame bias that the frame test finds with this
# probability (one-sided normal quantile 1.645).
DETECTION_POWER = 0.95

# The difference panel's colour scale spans +-this percentile of |difference|,
# so a few fireflies do not wash the rest of the map out.
DIFFERENCE_SCALE_PERCENTILE = 99.0

# Panels are drawn at least this many pixels wide (small renders are scaled up
# with nearest-neighbour sampling, so every pixel stays visible).
PANEL_MIN_PIXELS = 320
FIGURE_DPI = 100

# Thumbnails in the suite table: both renders side by side, this tall.
THUMBNAIL_HEIGHT = 96
THUMBNAIL_GAP = 2

FILES = ("mcengine.exr", "cycles.exr", "side_by_side.png", "report.json", "report.md")


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
    """

    images: np.ndarray
    seconds: list
    samples: int
    seeds: list
    notes: list = field(default_factory=list)

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
        return (f"{self.scene}: {self.verdict} (frame MC/Cycles-1 {bias}; "
                f"{blocks['differ']}/{blocks['tested']} blocks differ; relMSE {m['relmse']:.4g}, "
                f"FLIP {m['flip']:.3f})")


def detectable_bias(agreement: Agreement, power: float = DETECTION_POWER) -> np.ndarray:
    """Smallest relative frame bias the verdict finds with probability ``power``.

    A frame channel whose Holm-unadjusted p-value is below ``alpha / n_tests``
    is rejected whatever the other tests give, so a bias of
    ``(z_crit + z_power) * se / mean`` is caught at least with probability
    ``power`` (normal approximation; ``z_crit`` is the two-sided quantile at
    ``alpha / n_tests``).

    Returns
    -------
    (3,) float
        Per RGB channel, relative to Cycles' frame mean (inf where it is 0).
    """
    z_crit = student_t_isf(agreement.alpha / (2 * max(agreement.n_tests, 1)), math.inf)
    z_power = student_t_isf(1.0 - power, math.inf)
    se = np.hypot(agreement.frame_se_a, agreement.frame_se_b)
    mean = np.abs(agreement.frame_mean_b)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(mean > 0, (z_crit + z_power) * se / np.where(mean > 0, mean, 1.0), np.inf)


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


def _flip(ours_rgb: np.ndarray, cycles_rgb: np.ndarray) -> float:
    """Mean HDR-FLIP of ours against Cycles (flip-evaluator, linear RGB input)."""
    import flip_evaluator
    ref = np.ascontiguousarray(np.maximum(cycles_rgb, 0.0), np.float32)
    test = np.ascontiguousarray(np.maximum(ours_rgb, 0.0), np.float32)
    _, mean, _ = flip_evaluator.evaluate(ref, test, "HDR", applyMagma=False)
    return float(mean)


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
        (:func:`mcengine.compare.compare_stacks`).
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
    return Comparison(scene=scene, ours=ours, cycles=cycles, agreement=agreement,
                      report=report, notes=notes)


# ----------------------------------------------------------------------------
# Markdown
# ----------------------------------------------------------------------------

def _pct(v, digits=2) -> str:
    return "n/a" if v is None else f"{100 * v:+.{digits}f} %"


def _scaled(v, factor=100.0):
    return None if v is None else factor * v


def _num(v, fmt=".4g") -> str:
    return "n/a" if v is None else format(v, fmt)


def report_markdown(c: Comparison) -> str:
    """``report.md``: the report for people."""
    r = c.report
    s = r["settings"]
    w, h = s["resolution"]
    verdict = r["verdict"].upper()
    lines = [f"# {c.scene}: MC Engine vs Cycles", "",
             f"**Verdict: {verdict}** (family-wise error rate alpha = {r['test']['alpha']:g} "
             f"over {r['test']['n_tests']} tests)", ""]
    lines += [f"> {note}" for note in c.notes]
    lines += ["", "![MC Engine | Cycles | difference | significant blocks](side_by_side.png)", "",
              "## Settings", "",
              "| | MC Engine | Cycles |", "| --- | --- | --- |",
              f"| resolution | {w} x {h} | {w} x {h} |",
              f"| samples per render | {s['samples']['mcengine']} | {s['samples']['cycles']} |",
              f"| seeds | {', '.join(map(str, s['seeds']['mcengine']))} | "
              f"{', '.join(map(str, s['seeds']['cycles']))} |",
              "| render time per render (s) | " + " | ".join(
                  ", ".join(f"{t:.2f}" for t in r["times"][e]["renders"])
                  for e in ("mcengine", "cycles")) + " |",
              "| mean render time (s) | " + " | ".join(
                  f"{r['times'][e]['mean']:.2f}" for e in ("mcengine", "cycles")) + " |"]
    for key, value in s.items():
        if key not in ("resolution", "samples", "seeds"):
            lines.append(f"| {key.replace('_', ' ')} | {value} | {value} |")
    conf = int(round(100 * r["test"]["confidence"]))
    lines += ["", "## Frame means", "",
              f"Per channel: mean over the image of the average of the seeds, with its "
              f"{conf} % confidence interval; bias = MC / Cycles - 1; t = bias over its noise; "
              f"p = Holm-adjusted p-value; detectable = the bias this comparison finds with "
              f"{int(100 * DETECTION_POWER)} % probability.", "",
              "| channel | MC Engine | Cycles | bias | t | p (Holm) | detectable |",
              "| --- | --- | --- | --- | --- | --- | --- |"]
    for ch in CHANNELS:
        mo, mc = r["means"]["mcengine"][ch], r["means"]["cycles"][ch]
        lo, hi = r["frame"]["rel_bias_ci"][ch]
        lines.append(
            f"| {ch} | {_num(mo['mean'], '.5f')} [{_num(mo['ci'][0], '.5f')}, {_num(mo['ci'][1], '.5f')}] "
            f"| {_num(mc['mean'], '.5f')} [{_num(mc['ci'][0], '.5f')}, {_num(mc['ci'][1], '.5f')}] "
            f"| {_pct(r['frame']['rel_bias'][ch])} [{_pct(lo)}, {_pct(hi)}] "
            f"| {_num(r['frame']['t'][ch], '+.2f')} | {_num(r['frame']['p_holm'][ch], '.3g')} "
            f"| {_num(_scaled(r['frame']['detectable_bias'][ch]), '.2g')} % |")
    m, b = r["metrics"], r["blocks"]
    gy, gx = r["test"]["grid"]
    lines += ["", "## Image metrics", "",
              "Between the two seed averages, so they include both engines' noise.", "",
              "| metric | value |", "| --- | --- |",
              f"| relMSE (top 0.1 % of pixels trimmed) | {m['relmse']:.5g} |",
              f"| SMAPE | {m['smape']:.5g} |",
              f"| mean HDR-FLIP | {m['flip']:.5g} |",
              f"| significant blocks ({gx} x {gy} grid) | {b['differ']} / {b['tested']} "
              f"({100 * b['share_differ']:.1f} %) |",
              "| pixel correlation (block, frame scale) | MC Engine "
              + ", ".join(f"{v:.2f}" for v in r["pixel_correlation"]["mcengine"]) + "; Cycles "
              + ", ".join(f"{v:.2f}" for v in r["pixel_correlation"]["cycles"]) + " |",
              "", "## Regions that differ", ""]
    frame_differs = [ch for ch, d in r["frame"]["differs"].items() if d]
    if frame_differs:
        lines.append("The whole frame differs in " + ", ".join(
            f"{ch} ({_pct(r['frame']['rel_bias'][ch])})" for ch in frame_differs) + ".")
        lines.append("")
    if not r["regions"]:
        lines.append("No block differs significantly." if not frame_differs
                     else "No single block differs significantly.")
    else:
        lines += ["| where | pixels (x0, y0)-(x1, y1) | blocks | MC Engine is "
                  "| channels (mean MC / Cycles - 1) | max abs t |",
                  "| --- | --- | --- | --- | --- | --- |"]
        for reg in r["regions"]:
            x0, y0, x1, y1 = reg["pixels"]
            chans = ", ".join(f"{ch} {_pct(v, 1)}" for ch, v in reg["channels"].items())
            lines.append(f"| {reg['where']} | ({x0}, {y0})-({x1}, {y1}) | {reg['blocks']} | "
                         f"{reg['ours']} | {chans} | {reg['max_abs_t']:.1f} |")
    lines += ["", "## How the verdict is reached", "",
              "Each engine rendered the scene once per seed. The seed-to-seed spread gives "
              "each pixel's noise; the frame mean and the mean of every block are compared per "
              "RGB channel with Welch t-tests (degrees of freedom from the pixel variances, "
              "variances widened if neighbouring pixels are correlated), and Holm-Bonferroni "
              "keeps the chance of a false \"differ\" over all tests at alpha. The verdict is "
              "\"differ\" if any test is rejected.", ""]
    return "\n".join(lines)


# ----------------------------------------------------------------------------
# Images
# ----------------------------------------------------------------------------

def _display(rgb: np.ndarray) -> np.ndarray:
    """(h, w, 3) float in [0, 1]: Blender's Standard view (sRGB curve, clipped)."""
    return linear_to_srgb(np.asarray(rgb, np.float64)[..., :3])


def _nice_scale(x: float) -> float:
    """Round up to 1, 2 or 5 times a power of ten (for a readable colour bar)."""
    if not x > 0 or not math.isfinite(x):
        return 1e-6
    exponent = math.floor(math.log10(x))
    for step in (1.0, 2.0, 5.0, 10.0):
        if x <= step * 10.0 ** exponent:
            return step * 10.0 ** exponent
    return 10.0 ** (exponent + 1)


def side_by_side(c: Comparison, path) -> None:
    """Write the four-panel figure: MC Engine | Cycles | difference | significance.

    * Panels 1 and 2: each engine's seed average through the Standard view.
    * Panel 3: per-pixel signed luminance difference MC - Cycles in a diverging
      colour map (red: MC brighter, blue: MC darker) with its scale bar in
      linear units; the scale is symmetric at the 99th percentile of
      ``|difference|``.  Per-pixel differences include noise.
    * Panel 4: the blocks whose difference is significant (Holm), filled red
      or blue by sign over a dimmed grey Cycles image, each labelled with its
      relative difference; the caption gives the frame test.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.colors import to_rgba
    from matplotlib.figure import Figure
    from matplotlib.patches import Rectangle

    a = c.agreement
    h, w = a.shape
    ours_mean, cycles_mean = c.ours.mean_image[..., :3], c.cycles.mean_image[..., :3]
    scale_up = max(1.0, PANEL_MIN_PIXELS / w)
    panel_w = w * scale_up / FIGURE_DPI
    panel_h = h * scale_up / FIGURE_DPI
    # Room above each panel for two title lines, below for the colour bar / captions.
    top_in, bottom_in, gap_in = 0.95, 0.85, 0.25
    fig_w = 4 * panel_w + 5 * gap_in
    fig_h = panel_h + top_in + bottom_in
    fig = Figure(figsize=(fig_w, fig_h), dpi=FIGURE_DPI, facecolor="white")
    FigureCanvasAgg(fig)

    def axes(i):
        left = (gap_in + i * (panel_w + gap_in)) / fig_w
        ax = fig.add_axes((left, bottom_in / fig_h, panel_w / fig_w, panel_h / fig_h))
        ax.set_xticks([])
        ax.set_yticks([])
        return ax

    r = c.report
    samples = r["settings"]["samples"]
    verdict_colour = "#1a7f37" if c.verdict == "agree" else "#cf222e"
    fig.text(0.5, 1 - 0.12 / fig_h, f"{c.scene}   {w} x {h} px   verdict: {c.verdict.upper()}",
             ha="center", va="top", fontsize=13, weight="bold", color=verdict_colour)

    ax = axes(0)
    ax.imshow(_display(ours_mean), interpolation="nearest")
    ax.set_title(f"{OURS_LABEL}\n{samples['mcengine']} spp x {len(c.ours.seeds)} seeds, "
                 f"{c.ours.mean_seconds:.1f} s/render", fontsize=9)
    ax = axes(1)
    ax.imshow(_display(cycles_mean), interpolation="nearest")
    ax.set_title(f"{CYCLES_LABEL}\n{samples['cycles']} spp x {len(c.cycles.seeds)} seeds, "
                 f"{c.cycles.mean_seconds:.1f} s/render", fontsize=9)
    fig.text((gap_in + panel_w) / fig_w, 0.5 * bottom_in / fig_h,
             "same tone mapping: Standard view (sRGB), exposure 0",
             ha="center", va="center", fontsize=8, color="#555555")

    diff = (ours_mean - cycles_mean) @ LUMINANCE
    vmax = _nice_scale(float(np.percentile(np.abs(diff), DIFFERENCE_SCALE_PERCENTILE)))
    ax = axes(2)
    im = ax.imshow(diff, cmap="RdBu_r", vmin=-vmax, vmax=vmax, interpolation="nearest")
    ax.set_title(f"difference {OURS_LABEL} - {CYCLES_LABEL}\nper pixel, linear luminance",
                 fontsize=9)
    left = (gap_in + 2 * (panel_w + gap_in)) / fig_w
    cax = fig.add_axes((left, 0.42 * bottom_in / fig_h, panel_w / fig_w, 0.12 * bottom_in / fig_h))
    bar = fig.colorbar(im, cax=cax, orientation="horizontal")
    bar.ax.tick_params(labelsize=7)
    bar.set_label(f"red: {OURS_LABEL} brighter, blue: darker", fontsize=7)

    ax = axes(3)
    grey = _display(cycles_mean) @ LUMINANCE
    ax.imshow(0.25 + 0.5 * grey, cmap="gray", vmin=0.0, vmax=1.0, interpolation="nearest")
    for y in a.edges_y[1:-1]:
        ax.axhline(y - 0.5, color="white", lw=0.4, alpha=0.6)
    for x in a.edges_x[1:-1]:
        ax.axvline(x - 0.5, color="white", lw=0.4, alpha=0.6)
    rejected = a.block_rejected
    font = max(5.0, min(8.0, 0.35 * panel_w * FIGURE_DPI / a.block_t.shape[1]))
    for row, col in zip(*np.nonzero(rejected.any(axis=-1))):
        t = np.where(rejected[row, col], np.abs(a.block_t[row, col]), -1.0)
        ch = int(np.argmax(t))
        sign = a.block_t[row, col, ch] > 0
        x0, x1 = a.edges_x[col], a.edges_x[col + 1]
        y0, y1 = a.edges_y[row], a.edges_y[row + 1]
        colour = "#d73027" if sign else "#4575b4"
        ax.add_patch(Rectangle((x0 - 0.5, y0 - 0.5), x1 - x0, y1 - y0,
                               facecolor=to_rgba(colour, 0.55), edgecolor=colour, lw=1.0))
        rel = a.block_rel_diff[row, col, ch]
        label = f"{100 * rel:+.0f}%" if math.isfinite(rel) else "n/a"
        channels = "".join(CHANNELS[k] for k in range(3) if rejected[row, col, k])
        ax.text((x0 + x1 - 1) / 2, (y0 + y1 - 1) / 2, f"{label}\n{channels}", ha="center",
                va="center", fontsize=font, color="white", weight="bold")
    n_differ, n_tested = r["blocks"]["differ"], r["blocks"]["tested"]
    ax.set_title(f"significant differences (Holm, alpha {a.alpha:g})\n"
                 f"{n_differ}/{n_tested} blocks differ", fontsize=9)
    frame = [ch for ch, d in r["frame"]["differs"].items() if d]
    if frame:
        caption = "frame mean differs: " + ", ".join(
            f"{ch} {100 * r['frame']['rel_bias'][ch]:+.1f}%" for ch in frame)
    else:
        caption = "frame means agree: " + ", ".join(
            f"{ch} {100 * v:+.2f}%" for ch, v in r["frame"]["rel_bias"].items() if v is not None)
    left = (gap_in + 3 * (panel_w + gap_in) + 0.5 * panel_w) / fig_w
    fig.text(left, 0.62 * bottom_in / fig_h, caption, ha="center", va="center", fontsize=8,
             color="#cf222e" if frame else "#333333")
    fig.text(left, 0.3 * bottom_in / fig_h,
             f"red: {OURS_LABEL} brighter, blue: darker; label: MC/Cycles-1, channels",
             ha="center", va="center", fontsize=7, color="#555555")
    fig.savefig(str(path), dpi=FIGURE_DPI, facecolor="white")


def thumbnail(c: Comparison) -> np.ndarray:
    """(THUMBNAIL_HEIGHT, W, 3) uint8: MC Engine | Cycles, Standard view, nearest scaling."""
    images = [_display(e.mean_image[..., :3]) for e in (c.ours, c.cycles)]
    h, w = images[0].shape[:2]
    rows = np.minimum((np.arange(THUMBNAIL_HEIGHT) * h) // THUMBNAIL_HEIGHT, h - 1)
    width = max(1, round(w * THUMBNAIL_HEIGHT / h))
    cols = np.minimum((np.arange(width) * w) // width, w - 1)
    gap = np.ones((THUMBNAIL_HEIGHT, THUMBNAIL_GAP, 3))
    strip = np.concatenate([images[0][rows][:, cols], gap, images[1][rows][:, cols]], axis=1)
    return np.round(strip * 255.0).astype(np.uint8)


def write_comparison(c: Comparison, out_dir) -> dict:
    """Write the five files of :data:`FILES` (and ``thumbnail.png``) into ``out_dir``.

    Returns
    -------
    dict
        File name -> Path.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = {name: out / name for name in FILES + ("thumbnail.png",)}
    write_exr(paths["mcengine.exr"], c.ours.mean_image)
    write_exr(paths["cycles.exr"], c.cycles.mean_image)
    side_by_side(c, paths["side_by_side.png"])
    write_png(paths["thumbnail.png"], thumbnail(c))
    paths["report.json"].write_text(json.dumps(c.report, indent=1, allow_nan=False) + "\n")
    paths["report.md"].write_text(report_markdown(c))
    return paths


# ----------------------------------------------------------------------------
# Suite summary
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
        samples=f"{spp['mcengine']} x {len(c.ours.seeds)}")


def _ratio(row: SuiteRow) -> str:
    if row.seconds_ours is None or not row.seconds_cycles:
        return ""
    return f"{row.seconds_ours / row.seconds_cycles:.1f}"


_COLUMNS = ("scene", "verdict", "frame bias (max abs)", "detectable bias", "blocks differ",
            "relMSE", "FLIP", "time ours (s)", "time Cycles (s)", "ours / Cycles")


def _cells(row: SuiteRow) -> list:
    if row.verdict == "error":
        return [row.scene, "**error**", row.error] + [""] * (len(_COLUMNS) - 3)
    return [row.scene, row.verdict if row.verdict == "agree" else f"**{row.verdict}**",
            f"{100 * row.max_abs_bias:.2f} %" if row.max_abs_bias is not None else "",
            f"{100 * row.detectable_bias:.2g} %" if row.detectable_bias is not None else "",
            row.blocks_differ, _num(row.relmse, ".3g"), _num(row.flip, ".3f"),
            _num(row.seconds_ours, ".2f"), _num(row.seconds_cycles, ".2f"), _ratio(row)]


def _settings_line(rows) -> str:
    done = [r for r in rows if r.verdict != "error"]
    res = sorted({r.resolution for r in done})
    spp = sorted({r.samples for r in done})
    return (f"{len(rows)} scenes; resolution {', '.join(res) or 'n/a'}; samples x seeds per engine "
            f"{', '.join(spp) or 'n/a'}; {sum(r.verdict == 'agree' for r in rows)} agree, "
            f"{sum(r.verdict == 'differ' for r in rows)} differ, "
            f"{sum(r.verdict == 'error' for r in rows)} failed.")


def suite_markdown(rows, thumbnails: bool = True) -> str:
    """The summary table as Markdown (thumbnail column optional, e.g. for README)."""
    head = (["", *_COLUMNS] if thumbnails else list(_COLUMNS))
    lines = ["| " + " | ".join(head) + " |", "|" + " --- |" * len(head)]
    for row in rows:
        cells = _cells(row)
        if thumbnails:
            done = row.verdict != "error"
            cells = [f"![{row.scene}]({row.folder}/thumbnail.png)" if done else ""] + cells
            if done:
                cells[1] = f"[{row.scene}]({row.folder}/report.md)"
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def suite_html(rows, title: str = "MC Engine vs Cycles") -> str:
    """The summary table as a self-contained HTML page (thumbnails linked, not embedded)."""
    e = html.escape
    head = "".join(f"<th>{e(c)}</th>" for c in ("MC Engine | Cycles", *_COLUMNS))
    body = []
    for row in rows:
        cells = _cells(row)
        cls = {"agree": "agree", "differ": "differ"}.get(row.verdict, "error")
        thumb = (f'<a href="{e(row.folder)}/side_by_side.png"><img src="{e(row.folder)}/thumbnail.png" '
                 f'alt="{e(row.scene)}"></a>' if row.verdict != "error" else "")
        scene = (f'<a href="{e(row.folder)}/report.md">{e(row.scene)}</a>'
                 if row.verdict != "error" else e(row.scene))
        rest = "".join(f"<td>{e(str(v).strip('*'))}</td>" for v in cells[2:])
        body.append(f'<tr><td>{thumb}</td><td>{scene}</td><td class="{cls}">'
                    f"{e(row.verdict)}</td>{rest}</tr>")
    style = ("body{font-family:sans-serif;margin:1.5em}table{border-collapse:collapse}"
             "td,th{border:1px solid #ccc;padding:4px 8px;text-align:right}"
             "td:nth-child(2),th:nth-child(2){text-align:left}img{display:block}"
             ".agree{color:#1a7f37;font-weight:bold}.differ{color:#cf222e;font-weight:bold}"
             ".error{color:#9a6700;font-weight:bold}")
    return (f"<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{e(title)}</title>"
            f"<style>{style}</style></head><body>\n<h1>{e(title)}</h1>\n"
            f"<p>{e(_settings_line(rows))}</p>\n<table>\n<tr>{head}</tr>\n"
            + "\n".join(body) + "\n</table>\n</body></html>\n")


def write_suite(rows, out_dir, title: str = "MC Engine vs Cycles") -> dict:
    """Write ``summary.md``, ``summary.html`` and ``summary.json`` into ``out_dir``."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = {name: out / name for name in ("summary.md", "summary.html", "summary.json")}
    paths["summary.md"].write_text(f"# {title}\n\n{_settings_line(rows)}\n\n" + suite_markdown(rows))
    paths["summary.html"].write_text(suite_html(rows, title))
    verdict = ("error" if any(r.verdict == "error" for r in rows)
               else "differ" if any(r.verdict == "differ" for r in rows) else "agree")
    paths["summary.json"].write_text(json.dumps(
        {"verdict": verdict, "scenes": [r.to_dict() for r in rows]}, indent=1) + "\n")
    return paths
