"""The figures of the evaluation: what a comparison and a study draw.

* :func:`side_by_side`: a comparison's four panels, MC Engine | Cycles |
  signed difference | significant blocks (``side_by_side.png``);
* :func:`thumbnail`: both renders side by side, small, for the suite table;
* :func:`plot_error`: a study's relMSE and SMAPE against time or samples,
  log-log (``error_vs_time.png``, ``error_vs_samples.png``);
* :func:`equal_time_strip`: one render per integrator at about equal time
  (``equal_time.png``).

Both renders of a comparison are shown through the same tone mapping,
Blender's "Standard" view transform (the sRGB curve, clipped to [0, 1],
exposure 0).  Colours and markers of the study's curves are keyed by engine
name.  This is the only module of the package that uses matplotlib, and it
imports it when first drawing.
"""
from __future__ import annotations

import math

import numpy as np

from ..imageio import linear_to_srgb
from ..integrators import NAMES
from .comparison import CYCLES_LABEL, OURS_LABEL, Comparison, frame_finding
from .stats import CHANNELS
from .study import CYCLES, EQUAL_TIME_SLACK, Study, StudyError, engine_label

__all__ = ["side_by_side", "thumbnail", "plot_error", "equal_time_strip"]

# Rec. 709 luminance weights (the working space of Blender's scenes): the
# difference panel shows one signed number per pixel.
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])

# The difference panel's colour scale spans +-this percentile of |difference|,
# so a few fireflies do not wash the rest of the map out.
DIFFERENCE_SCALE_PERCENTILE = 99.0

# Colours of the verdict and of the frame test's finding (comparison.frame_finding):
# green agree, red differ, amber when the noise could hide a difference.
FINDING_COLOURS = {"agree": "#1a7f37", "differ": "#cf222e", "not distinguishable": "#9a6700"}

# Panels are drawn at least this many pixels wide (small renders are scaled up
# with nearest-neighbour sampling, so every pixel stays visible).
PANEL_MIN_PIXELS = 320
COMPARISON_DPI = 100

# Thumbnails in the suite table: both renders side by side, this tall.
THUMBNAIL_HEIGHT = 96
THUMBNAIL_GAP = 2

# The study's plots: one colour and marker per engine, the integrators in the
# registry's order, Cycles in grey.
COLORS = {**{name: f"C{i}" for i, name in enumerate(NAMES)}, CYCLES: "C7"}
MARKERS = {**dict(zip(NAMES, "os^Dp")), CYCLES: "v"}
STUDY_DPI = 110


# ----------------------------------------------------------------------------
# Comparison
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
    panel_w = w * scale_up / COMPARISON_DPI
    panel_h = h * scale_up / COMPARISON_DPI
    # Room above each panel for two title lines, below for the colour bar / captions.
    top_in, bottom_in, gap_in = 0.95, 1.05, 0.25
    fig_w = 4 * panel_w + 5 * gap_in
    fig_h = panel_h + top_in + bottom_in
    fig = Figure(figsize=(fig_w, fig_h), dpi=COMPARISON_DPI, facecolor="white")
    FigureCanvasAgg(fig)

    def axes(i):
        left = (gap_in + i * (panel_w + gap_in)) / fig_w
        ax = fig.add_axes((left, bottom_in / fig_h, panel_w / fig_w, panel_h / fig_h))
        ax.set_xticks([])
        ax.set_yticks([])
        return ax

    r = c.report
    samples = r["settings"]["samples"]
    finding = frame_finding(r)
    verdict = c.verdict.upper()
    if c.verdict == "agree" and finding.caveat:
        verdict += f" ({finding.caveat})"
    fig.text(0.5, 1 - 0.12 / fig_h, f"{c.scene}   {w} x {h} px   verdict: {verdict}",
             ha="center", va="top", fontsize=13, weight="bold",
             color=FINDING_COLOURS["differ" if c.verdict == "differ" else finding.kind])

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
    font = max(5.0, min(8.0, 0.35 * panel_w * COMPARISON_DPI / a.block_t.shape[1]))
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
    finding = frame_finding(r)
    left = (gap_in + 3 * (panel_w + gap_in) + 0.5 * panel_w) / fig_w
    fig.text(left, 0.64 * bottom_in / fig_h,
             finding.headline.replace(" (", "\n(") + "\n" + finding.values,
             ha="center", va="center", fontsize=8, linespacing=1.3,
             color=FINDING_COLOURS[finding.kind])
    fig.text(left, 0.3 * bottom_in / fig_h,
             f"red: {OURS_LABEL} brighter, blue: darker; label: MC/Cycles-1, channels",
             ha="center", va="center", fontsize=7, color="#555555")
    fig.savefig(str(path), dpi=COMPARISON_DPI, facecolor="white")


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


# ----------------------------------------------------------------------------
# Study
# ----------------------------------------------------------------------------

def _pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _guide(ax, xs, y0, slope, label):
    """A dashed power-law guide ``y0 * (x / x0)**slope`` over ``xs``' range."""
    x = np.array([min(xs), max(xs)], float)
    ax.plot(x, y0 * (x / x[0]) ** slope, color="0.45", linestyle="--", linewidth=1.0,
            label=label, zorder=1)


def _label_floors(ax, summaries: dict) -> None:
    """Name each plateau line at the right edge; equal floors (within 2 %) share a label."""
    groups = []
    for name, s in summaries.items():
        if not s.plateau:
            continue
        for group in groups:
            if abs(group[0] / s.floor - 1.0) < 0.02:
                group[1].append(name)
                break
        else:
            groups.append((s.floor, [name]))
    for floor, names in groups:
        text = " and ".join(engine_label(n) for n in names) + f": bias floor {floor:.2g}"
        ax.annotate(text, xy=(0.98, floor), xycoords=("axes fraction", "data"), ha="right",
                    va="top", fontsize=7.5, color=COLORS.get(names[0]), zorder=4,
                    xytext=(0, -3), textcoords="offset points",
                    bbox=dict(boxstyle="square,pad=0.1", facecolor="white", edgecolor="none",
                              alpha=0.8))


def plot_error(summaries: dict, path, x: str = "seconds", title: str = "") -> None:
    """relMSE and SMAPE against time or samples, log-log, one curve per integrator.

    Markers are the mean over seeds, bars the smallest and largest seed.
    The relMSE panel has a 1/x guide (slope -1), the target as a dotted line
    and each plateauing integrator's fitted floor as a thin line of its
    colour; the SMAPE panel a 1/sqrt(x) guide.
    """
    if x not in ("seconds", "samples"):
        raise StudyError(f"x must be 'seconds' or 'samples', got {x!r}")
    plt = _pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(11.5, 4.6), dpi=STUDY_DPI)
    xlabel = "render time (s)" if x == "seconds" else "samples per pixel"
    xs_all = [getattr(r, x) for s in summaries.values() for r in s.rungs]
    for ax, metric in zip(axes, ("relmse", "smape")):
        for name, s in summaries.items():
            xs = [getattr(r, x) for r in s.rungs]
            ys = np.array([getattr(r, metric) for r in s.rungs])
            lo = np.array([getattr(r, metric + "_lo") for r in s.rungs])
            hi = np.array([getattr(r, metric + "_hi") for r in s.rungs])
            ax.errorbar(xs, ys, yerr=[ys - lo, hi - ys], color=COLORS.get(name),
                        marker=MARKERS.get(name, "o"), markersize=5, capsize=2, linewidth=1.4,
                        label=engine_label(name), zorder=3)
            if metric == "relmse" and s.plateau:
                ax.axhline(s.floor, color=COLORS.get(name), linewidth=0.8, alpha=0.6, zorder=2)
        if metric == "relmse":
            _label_floors(ax, summaries)
        first = next(iter(summaries.values()))
        anchor = first.rungs[0]
        if metric == "relmse":
            _guide(ax, xs_all, anchor.relmse * (min(xs_all) / getattr(anchor, x)) ** -1, -1.0,
                   "∝ 1/N" if x == "samples" else "∝ 1/time")
            target = first.target
            ax.axhline(target, color="k", linestyle=":", linewidth=1.0,
                       label=f"target relMSE {target:g}")
            ax.set_ylabel("relMSE (top 0.1 % trimmed)")
        else:
            _guide(ax, xs_all, anchor.smape * (min(xs_all) / getattr(anchor, x)) ** -0.5, -0.5,
                   "∝ 1/√N" if x == "samples" else "∝ 1/√time")
            ax.set_ylabel("SMAPE")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(xlabel)
        ax.grid(True, which="both", alpha=0.25)
    axes[0].legend(fontsize=8, loc="best")
    fig.suptitle(title or ("Error against " + ("time" if x == "seconds" else "samples")))
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def _equal_time_choice(study: Study, summaries: dict):
    """The common time T and, per integrator, the preview taken closest to it.

    T is the longest time every integrator spent on some render; each
    integrator shows its longest render within ``EQUAL_TIME_SLACK * T``
    (its fastest one if even that took longer).
    """
    names = [n for n in summaries if study.previews.get(n)]
    if not names:
        return None, {}
    common = min(max(p.seconds for p in study.previews[n]) for n in names)
    chosen = {}
    for n in names:
        within = [p for p in study.previews[n] if p.seconds <= EQUAL_TIME_SLACK * common]
        chosen[n] = max(within, key=lambda p: p.seconds) if within else min(
            study.previews[n], key=lambda p: p.seconds)
    return common, chosen


def equal_time_strip(study: Study, summaries: dict, path) -> dict:
    """Save the strip of images at (about) equal time; returns integrator -> Preview shown.

    Each panel is labelled with its integrator, samples, time and relMSE;
    the references come last.
    """
    common, chosen = _equal_time_choice(study, summaries)
    panels = []
    for name, p in chosen.items():
        err = next((r.relmse for r in study.rows if r.integrator == name
                    and r.samples == p.samples and r.replicate == 0), float("nan"))
        panels.append((p.image, f"{engine_label(name)}\n{p.samples} spp, {p.seconds:.2f} s, "
                                f"relMSE {err:.3g}"))
    for engine, img in study.reference_previews.items():
        ref = study.references[engine]
        panels.append((img, f"{engine_label(engine)} reference\n{ref.samples} spp, "
                            f"{ref.seconds:.0f} s"))
    if not panels:
        return {}
    plt = _pyplot()
    h, w = panels[0][0].shape[:2]
    scale = 2.4 / max(h, w)
    fig, axes = plt.subplots(1, len(panels), figsize=(len(panels) * w * scale, h * scale + 0.75),
                             dpi=STUDY_DPI, squeeze=False)
    for ax, (img, label) in zip(axes[0], panels):
        ax.imshow(img, interpolation="nearest")
        ax.set_title(label, fontsize=8)
        ax.axis("off")
    fig.suptitle(f"Equal time: about {common:.2f} s each (render time)" if common else "",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return chosen
