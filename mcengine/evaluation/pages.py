"""The pages of the evaluation: Markdown and HTML for people.

* a comparison's ``report.md`` (:func:`report_markdown`);
* a suite's table as Markdown (``summary.md``, also pasted into README) and as
  an HTML page with thumbnails (``summary.html``);
* a study's page (``study.html``) and its time-to-target table as Markdown
  (``study.md``).

Pages read the models (:mod:`.comparison`, :mod:`.study`) and only format
them: every number is computed there.  The CSS of both HTML pages is here.
"""
from __future__ import annotations

import html
import math

from ..integrators import INTEGRATORS
from .comparison import DETECTION_POWER, POWER_BIAS, Comparison, SuiteRow, fmt_num, frame_finding
from .stats import CHANNELS
from .study import (
    CONFIDENCE,
    CYCLES,
    DEFAULT_TARGET_RELMSE,
    MIN_FIT_RUNGS,
    NOISE_DOMINANCE,
    SLOPE_MIN_SAMPLES,
    Study,
    Summary,
    engine_label,
)

__all__ = ["report_markdown", "suite_markdown", "suite_summary_markdown", "suite_html",
           "target_table_markdown", "study_markdown", "study_html"]

SUITE_CSS = ("body{font-family:sans-serif;margin:1.5em}table{border-collapse:collapse}"
             "td,th{border:1px solid #ccc;padding:4px 8px;text-align:right}"
             "td:nth-child(2),th:nth-child(2){text-align:left}img{display:block}"
             ".agree{color:#1a7f37;font-weight:bold}.differ{color:#cf222e;font-weight:bold}"
             ".error{color:#9a6700;font-weight:bold}")

STUDY_CSS = """
body { font-family: system-ui, sans-serif; max-width: 1180px; margin: 2em auto; padding: 0 1em;
       color: #222; line-height: 1.45; }
table { border-collapse: collapse; margin: 1em 0; font-size: 0.95em; }
th, td { border: 1px solid #ccc; padding: 0.3em 0.6em; text-align: left; }
th { background: #f3f3f3; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
img { max-width: 100%; border: 1px solid #ddd; }
.note { color: #555; font-size: 0.92em; }
"""

# What a plateau of Cycles would mean (MC Engine's integrators say it in the registry).
CYCLES_LEAVES_OUT = ("Cycles is unbiased with these settings: a plateau means its reference is "
                     "not converged enough")


# ----------------------------------------------------------------------------
# Comparison
# ----------------------------------------------------------------------------

def _pct(v, digits=2) -> str:
    return "n/a" if v is None else f"{100 * v:+.{digits}f} %"


def _scaled(v, factor=100.0):
    return None if v is None else factor * v


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
    if r.get("nonfinite_samples"):
        lines.append(f"| non-finite samples dropped (all renders) | {r['nonfinite_samples']:,} | |")
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
            f"| {ch} | {fmt_num(mo['mean'], '.5f')} [{fmt_num(mo['ci'][0], '.5f')}, {fmt_num(mo['ci'][1], '.5f')}] "
            f"| {fmt_num(mc['mean'], '.5f')} [{fmt_num(mc['ci'][0], '.5f')}, {fmt_num(mc['ci'][1], '.5f')}] "
            f"| {_pct(r['frame']['rel_bias'][ch])} [{_pct(lo)}, {_pct(hi)}] "
            f"| {fmt_num(r['frame']['t'][ch], '+.2f')} | {fmt_num(r['frame']['p_holm'][ch], '.3g')} "
            f"| {fmt_num(_scaled(r['frame']['detectable_bias'][ch]), '.2g')} % |")
    m, b = r["metrics"], r["blocks"]
    gy, gx = r["test"]["grid"]
    lines += ["", "## Image metrics", "",
              "Between the two seed averages, so they include both engines' noise.", "",
              "| metric | value |", "| --- | --- |",
              f"| relMSE (top 0.1 % of pixels trimmed) | {m['relmse']:.5g} |",
              f"| SMAPE | {m['smape']:.5g} |",
              f"| mean HDR-FLIP | {fmt_num(m['flip'], '.5g')} |",
              f"| significant blocks ({gx} x {gy} grid) | {b['differ']} / {b['tested']} "
              f"({100 * b['share_differ']:.1f} %) |",
              "| pixel correlation (block, frame scale) | MC Engine "
              + ", ".join(f"{v:.2f}" for v in r["pixel_correlation"]["mcengine"]) + "; Cycles "
              + ", ".join(f"{v:.2f}" for v in r["pixel_correlation"]["cycles"]) + " |",
              "", "## Regions that differ", ""]
    finding = frame_finding(r)
    lines += ["", f"**{finding.text[0].upper() + finding.text[1:]}.** The frame means are said "
              f"to agree only when no channel differs and the test would have found a "
              f"{100 * POWER_BIAS:g} % bias with {int(100 * DETECTION_POWER)} % probability in "
              "every channel (detectable bias at most "
              f"{100 * POWER_BIAS:g} %); otherwise they are not distinguishable at this noise, "
              "which says nothing about a bias smaller than the detectable one."]
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
# Suite
# ----------------------------------------------------------------------------

def _ratio(row: SuiteRow) -> str:
    if row.seconds_ours is None or not row.seconds_cycles:
        return ""
    return f"{row.seconds_ours / row.seconds_cycles:.1f}"


_COLUMNS = ("scene", "verdict", "frame bias (max abs)", "detectable bias", "blocks differ",
            "relMSE", "FLIP", "time ours (s)", "time Cycles (s)", "ours / Cycles")


def _cells(row: SuiteRow) -> list:
    if row.verdict == "error":
        return [row.scene, "**error**", row.error] + [""] * (len(_COLUMNS) - 3)
    return [row.scene, _verdict_cell(row),
            f"{100 * row.max_abs_bias:.2f} %" if row.max_abs_bias is not None else "",
            f"{100 * row.detectable_bias:.2g} %" if row.detectable_bias is not None else "",
            row.blocks_differ, fmt_num(row.relmse, ".3g"), fmt_num(row.flip, ".3f"),
            fmt_num(row.seconds_ours, ".2f"), fmt_num(row.seconds_cycles, ".2f"), _ratio(row)]


def _low_power(row: SuiteRow) -> bool:
    """An "agree" whose frame test could not have seen a POWER_BIAS bias."""
    return row.verdict == "agree" and (row.detectable_bias is None
                                       or row.detectable_bias > POWER_BIAS)


def _verdict_cell(row: SuiteRow) -> str:
    if row.verdict != "agree":
        return f"**{row.verdict}**"
    return "agree (low power)" if _low_power(row) else "agree"


def _settings_line(rows) -> str:
    done = [r for r in rows if r.verdict != "error"]
    res = sorted({r.resolution for r in done})
    spp = sorted({r.samples for r in done})
    dropped = [f"{r.scene} ({r.nonfinite:,})" for r in done if getattr(r, "nonfinite", 0)]
    return (f"{len(rows)} scenes; resolution {', '.join(res) or 'n/a'}; samples x seeds per engine "
            f"{', '.join(spp) or 'n/a'}; {sum(r.verdict == 'agree' for r in rows)} agree, "
            f"{sum(r.verdict == 'differ' for r in rows)} differ, "
            f"{sum(r.verdict == 'error' for r in rows)} failed."
            + (f" MC Engine dropped non-finite samples in: {', '.join(dropped)}." if dropped else "")
            + (f" Low power: the frame test of {sum(map(_low_power, rows))} scene(s) could not "
               f"have seen a {100 * POWER_BIAS:g} % bias (detectable bias above "
               f"{100 * POWER_BIAS:g} %); nothing was found there, but nothing is shown to agree."
               if any(map(_low_power, rows)) else ""))


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
    return (f"<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{e(title)}</title>"
            f"<style>{SUITE_CSS}</style></head><body>\n<h1>{e(title)}</h1>\n"
            f"<p>{e(_settings_line(rows))}</p>\n<table>\n<tr>{head}</tr>\n"
            + "\n".join(body) + "\n</table>\n</body></html>\n")


def suite_summary_markdown(rows, title: str = "MC Engine vs Cycles") -> str:
    """``summary.md``: a title, the settings line and the table with thumbnails."""
    return f"# {title}\n\n{_settings_line(rows)}\n\n" + suite_markdown(rows)


# ----------------------------------------------------------------------------
# Study
# ----------------------------------------------------------------------------

def _fmt_time(s: Summary) -> str:
    if s.time_to_target is None:
        return f"not reached (error levels off at {s.floor:.3g})" if s.plateau or s.floor >= s.target \
            else "not reached"
    text = f"{s.time_to_target:.2f} s"
    if s.target_how == "first rung":
        return f"≤ {text} (at 1 spp)"
    if s.target_how == "extrapolated":
        return f"~{text} (extrapolated)"
    return text


def _fmt_slope(s: Summary) -> str:
    if s.slope is None:
        return "n/a (bias dominates)" if s.plateau else f"n/a (needs {MIN_FIT_RUNGS} rungs ≥ {SLOPE_MIN_SAMPLES} spp)"
    return f"{s.slope:.3f} ± {s.slope_ci:.3f}"


def target_table_markdown(summaries: dict, study: Study | None = None) -> str:
    """Markdown table: time to target relMSE, slope, plateau, efficiency per integrator."""
    target = next(iter(summaries.values())).target if summaries else DEFAULT_TARGET_RELMSE
    lines = [f"| integrator | time to relMSE {target:g} | relMSE slope (95 %) | bias floor | "
             f"relMSE at max spp | efficiency 1/(relMSE·s) |",
             "|---|---|---|---|---|---|"]
    for name, s in summaries.items():
        last = s.rungs[-1]
        label = engine_label(name)
        if study is not None and study.settings.get(name):
            label += f" ({study.settings[name]})"
        floor = f"{s.floor:.3g} (plateau)" if s.plateau else "none"
        lines.append(f"| {label} | {_fmt_time(s)} | {_fmt_slope(s)} | {floor} | "
                     f"{last.relmse:.3g} at {last.samples} | {last.efficiency:.3g} |")
    return "\n".join(lines) + "\n"


def _same_errors(study: Study | None, a: str, b: str) -> bool:
    """True when integrators ``a`` and ``b`` measured exactly the same errors (same images)."""
    if study is None:
        return False
    errors = {m: [r.relmse for r in study.rows if r.integrator == m] for m in (a, b)}
    return bool(errors[a]) and errors[a] == errors[b]


def _biased_by_design(name: str) -> bool:
    """True for the lecture's classic integrators (all but path tracing and path + light
    tracing)."""
    info = INTEGRATORS.get(name)
    return info is not None and not info.matches_cycles and not info.light_tracing


def _leaves_out(name: str) -> str:
    """Why an engine's error stops falling, in words."""
    if name == CYCLES:
        return CYCLES_LEAVES_OUT
    info = INTEGRATORS.get(name)
    return info.leaves_out if info is not None and info.leaves_out else "it is biased"


def _reduced(study: Study | None) -> dict:
    """Integrator -> the one whose images it rendered exactly (Whitted -> ray casting on a
    scene without mirrors or glass)."""
    out = {}
    for name, info in INTEGRATORS.items():
        if info.reduces_to and _same_errors(study, info.reduces_to, name):
            out[name] = info.reduces_to
    return out


def _plateau_sentences(summaries: dict, study: Study | None = None) -> list[str]:
    out = []
    reduced = _reduced(study)
    for name, base in reduced.items():
        out.append(f"{engine_label(name)} ray tracing rendered exactly the images of "
                   f"{engine_label(base).lower()}: the scene has no mirror or glass, so no ray "
                   f"ever branches.")
    for name, s in summaries.items():
        if name in reduced:
            continue          # said with the one it reduces to
        label = " and ".join([engine_label(name)]
                             + [engine_label(n) for n, base in reduced.items() if base == name])
        if s.plateau:
            start = next((r.samples for r in s.rungs if s.noise_at(r.samples) < s.bias), 1)
            out.append(
                f"<b>{label}</b>: the error stops falling at relMSE ≈ {s.floor:.3g} "
                f"(pixels off by about {100 * math.sqrt(s.bias):.0f} % on average). From about "
                f"{start} sample{'s' if start > 1 else ''} per pixel on, more samples only make a "
                f"wrong image less noisy: {_leaves_out(name)}. This is what "
                f"the cheaper algorithm costs in accuracy, and no amount of time buys it back.")
        elif _biased_by_design(name):
            out.append(f"<b>{label}</b>: no plateau within this ladder (its bias, relMSE "
                       f"≈ {s.bias:.2g}, is still below its noise at {s.rungs[-1].samples} "
                       f"samples).")
    return out


def _slope_sentences(summaries: dict) -> list[str]:
    out = []
    for name in ("path", "cycles"):
        s = summaries.get(name)
        if s is None or s.slope is None:
            continue
        verdict = "consistent with" if s.slope_consistent() else "<b>not</b> consistent with"
        why = ""
        if name == "cycles" and not s.slope_consistent() and s.slope < -1:
            why = (" It falls faster than 1/N because its samples are not independent: "
                   "Cycles' sampler stratifies each pixel's samples (quasi-Monte Carlo).")
        out.append(f"{engine_label(name)}: measured slope {s.slope:.3f} ± {s.slope_ci:.3f} (95 % "
                   f"interval, standard error {s.slope_se:.3f}, {s.slope_dof} degrees of freedom "
                   f"over {len(s.fit_samples)} sample counts), {verdict} the −1 of Monte Carlo "
                   f"convergence with independent samples.{why}")
    return out


def study_markdown(study: Study, summaries: dict) -> str:
    """``study.md``: one sentence naming the scene and the target, then the table."""
    return (f"Time to reach relMSE {study.options.target_relmse:g} on {study.scene} "
            f"({study.width}×{study.height}, {study.options.seeds} seeds):\n\n"
            + target_table_markdown(summaries, study))


def study_html(study: Study, summaries: dict, files: dict) -> str:
    """The report page; ``files`` maps "csv", "time", "samples", "strip" to file names."""
    e = html.escape
    o = study.options
    target = o.target_relmse
    rows = []
    for name, s in summaries.items():
        last = s.rungs[-1]
        settings = study.settings.get(name, "")
        rows.append(
            "<tr>" + "".join([
                f"<td>{e(engine_label(name))}" + (f"<br><span class=note>{e(settings)}</span>"
                                                       if settings else "") + "</td>",
                f"<td class=num>{e(_fmt_time(s))}</td>",
                f"<td class=num>{e(_fmt_slope(s))}</td>",
                f"<td class=num>{'%.3g' % s.floor if s.plateau else 'none'}</td>",
                f"<td class=num>{last.relmse:.3g} / {last.smape:.3g} at {last.samples} spp</td>",
                f"<td class=num>{last.seconds:.2f} s</td>",
                f"<td class=num>{last.efficiency:.3g}</td>",
            ]) + "</tr>")
    refs = []
    smallest = {}
    for row in study.rows:
        smallest[row.reference] = min(smallest.get(row.reference, math.inf), row.relmse)
    for engine, ref in study.references.items():
        ratio = smallest.get(engine, math.nan) / ref.self_relmse if ref.self_relmse > 0 else math.inf
        refs.append(f"<li>{e(engine_label(engine))}: {ref.samples} samples per pixel "
                    f"({ref.renders} renders of {ref.samples // ref.renders}, {ref.seconds:.0f} s). "
                    f"Its own relMSE, estimated from the spread of those renders, is "
                    f"{ref.self_relmse:.2g}, {ratio:.0f}× below the smallest error measured "
                    f"against it ({smallest.get(engine, math.nan):.3g}), so it is converged "
                    f"enough to measure against; it is subtracted before fitting slopes.</li>")
    plateaus = _plateau_sentences(summaries, study)
    slopes = _slope_sentences(summaries)
    notes = "".join(f"<li>{e(n)}</li>" for n in study.notes)
    return f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8">
<title>Accuracy against time: {e(study.scene)}</title><style>{STUDY_CSS}</style></head>
<body>
<h1>What accuracy costs in time: {e(study.scene)}</h1>
<p>{study.width}×{study.height} pixels; sample counts {', '.join(str(n) for n in o.ladder())};
{o.seeds} seeds per count; {len(study.rows)} timed renders
(<a href="{e(files['csv'])}">{e(files['csv'])}</a>, one row per render).
Error is measured against a converged reference: relMSE (squared error over the squared
reference value, top 0.1 % of pixels trimmed) and SMAPE.</p>

<h2>In short</h2>
<ul>
{''.join(f'<li>{s}</li>' for s in slopes)}
{''.join(f'<li>{s}</li>' for s in plateaus)}
<li>An unbiased algorithm's error halves when the samples (and so the time) double: its curve
follows the dashed 1/N guide.  A biased algorithm's curve bends flat at its bias: past that
point it is cheap but wrong.</li>
</ul>

<h2>Time to reach relMSE {target:g}</h2>
<table>
<tr><th>integrator</th><th>time to relMSE {target:g}</th><th>relMSE slope vs samples (95 %)</th>
<th>plateau (relMSE floor)</th><th>relMSE / SMAPE</th><th>render time</th>
<th>efficiency 1/(relMSE·s)</th></tr>
{''.join(rows)}
</table>
<p class=note>Times to target are interpolated between the two rungs around the crossing
(log time against log error); "extrapolated" uses the fitted error model a/N + c/N² + b beyond
the ladder; "not reached" means the error levels off above the target.  The last three columns are
at the largest sample count (mean over seeds).  Efficiency is constant for an unbiased method
and falls once a biased one plateaus.</p>

<h2>Error against time</h2>
<img src="{e(files['time'])}" alt="relMSE and SMAPE against render time, log-log">
<h2>Error against samples</h2>
<img src="{e(files['samples'])}" alt="relMSE and SMAPE against samples per pixel, log-log">
<p class=note>Markers: mean over seeds; bars: smallest and largest seed.  Thin horizontal lines:
the fitted floor of each integrator whose error plateaus.  Cycles is measured against its own
reference.</p>
<h2>Equal time</h2>
<img src="{e(files['strip'])}" alt="one render per integrator at about equal render time">

<h2>How this was measured</h2>
<ul>
{''.join(refs)}
<li>Error model: each integrator's mean untrimmed relMSE per sample count (the mean squared
error, see the slope below) is fitted by a/N + c/N² + b (a, b ≥ 0, relative least squares).
b is what samples cannot remove: the algorithm's squared
bias plus the reference's own error; c/N² accounts for the first sample of each pixel, taken at
the pixel centre.  An integrator <i>plateaus</i> when its bias exceeds its noise at the largest
sample count.</li>
<li>Slope: least squares of log(relMSE − reference error) on log N over every render (all seeds)
at the sample counts from {SLOPE_MIN_SAMPLES} on where the noise is at least {NOISE_DOMINANCE:g}×
the bias.  Every render has its own seed, so the scatter about the line is the seed-to-seed
spread and gives the standard error; the ± is the {100 * CONFIDENCE:.0f} % Student-t interval.
Fewer samples are left out because both engines take the first sample of each pixel at its
centre: it varies less than the others, so 1- to 4-sample renders are less noisy than 1/N
predicts and the curve joins the 1/N line from below.  The slope is measured on the
<i>untrimmed</i> relMSE (column relmse_untrimmed): trimming the worst 0.1 % of pixels removes a
larger share of the error at few samples, where a single bright sample dominates a pixel, than
at many, which flattens the trimmed curves a little although the mean squared error itself falls
as 1/N.</li>
{notes}
</ul>
</body></html>
"""
