"""Accuracy against time: how fast each integrator's error falls, and where it stops falling.

Concept
-------
A *study* renders one scene with each integrator at a ladder of sample counts
``N = 1, 2, 4, ..., N_max``, ``K`` times with independent seeds, times every
render, and measures its error against a converged *reference*: MC Engine's
path tracer at many samples for MC Engine's integrators, Cycles' own
high-sample render for Cycles.  The reference is the mean of
``REFERENCE_RENDERS`` independent renders, so its own error can be estimated
from their per-pixel spread.

Error model.  A render's expected relMSE against the reference is

    E[relMSE(N)] = a / N + c / N**2 + b,

``a / N + c / N**2`` the Monte Carlo noise, ``b`` what more samples cannot
remove: the squared relative bias of the algorithm plus ``r``, the
reference's own relMSE (image and reference are independent, so their errors
add).  Independent samples give ``a / N``.  The ``c`` term is there because
the first sample of every pixel is taken at the pixel centre (as in Cycles):
with ``s0`` its mean squared error and ``s`` the others', the mean of N
samples has ``(s0 + (N - 1) s) / N**2 = s / N + (s0 - s) / N**2``, and
``s0 < s`` (the centre does not vary with the seed), so ``c < 0`` and renders
of very few samples are less noisy than 1/N predicts.  Path tracing is
unbiased, so ``b = r``; ray casting and Whitted ray tracing leave out light
paths, so their ``b`` is their bias, and their error *plateaus* there.
``a, b >= 0`` and ``c`` are fitted to the per-rung mean of the *untrimmed*
relMSE (the model describes the mean squared error; see the slope below for
what trimming does) by least squares on relative residuals (each rung counts
alike, whatever its size); ``c`` only with at least
``MIN_RUNGS_FIRST_SAMPLE`` rungs.  The standard error of ``b`` follows from
the seed-to-seed scatter of the rung means.

Plateau.  An integrator's bias beyond the reference's error, ``b - r``,
counts only when it is ``BIAS_SIGMAS`` standard errors above zero (a few
bright pixels can lift the largest rung of an unbiased method by chance).
It plateaus when that bias exceeds its noise at the largest sample count:
from there on, doubling the samples no longer halves the error.

Convergence slope.  The slope of ``log(relMSE - r)`` against ``log N`` by
ordinary least squares over every render (all seeds) of the rungs with
``N >= SLOPE_MIN_SAMPLES`` where the noise dominates the bias by
``NOISE_DOMINANCE``; the reference's estimated error ``r`` is subtracted
because it adds to every measurement.  The smallest rungs are left out
because of the centred first sample (the ``c`` term above): the error
approaches the 1/N law from below.  The slope uses the *untrimmed* relMSE:
trimming the worst 0.1 % of pixels removes a larger share of the error at few
samples, where one bright sample dominates a pixel, than at many (10 % at 4
samples, 4 % at 64 on the Cornell box), so the trimmed error falls more
slowly than 1/N over a ladder (slope -0.96 there) although the estimator's
mean squared error falls exactly as 1/N.  Renders are independent (each has its own seed), so the
residual scatter, which is the seed-to-seed spread, gives the slope's
standard error with ``n - 2`` degrees of freedom; the tolerance is the 95 %
Student-t interval.  An unbiased integrator's slope is -1.

Time to target.  The first time an integrator's mean relMSE falls to the
target, interpolated linearly in log(time)-log(error) between the rungs
around the crossing; beyond the ladder it is extrapolated from the fitted
model when the target lies above the bias floor (marked "extrapolated"), and
"not reached" when the floor is above the target.

Efficiency.  ``1 / (relMSE * seconds)`` at each rung (per second, higher is
better); constant along the ladder for an unbiased integrator whose time
grows with N, falling for a biased one once it plateaus.

Conventions
-----------
* relMSE is :func:`mcengine.evaluation.stats.relmse` (top 0.1 % of pixels
  trimmed, ``eps = 1e-2``; ``relmse_untrimmed`` without trimming) and SMAPE
  :func:`mcengine.evaluation.stats.smape`, on RGB.
* ``seconds`` is whatever the render callable reports; the Blender driver
  (``mcengine_blender.batch.study``) times the render call alone.
* Engines are MC Engine's integrators, by their names in
  :mod:`mcengine.integrators`, and ``cycles``.  Images are ``(h, w, 3|4)``
  float, top row first.
* A render callable is ``render(integrator, samples, seed)`` returning an
  object with ``.image`` and ``.seconds``.

This module is the model: it runs the study and fits it, and never draws or
writes; :func:`mcengine.evaluation.output.write_study` writes the CSV, plots,
pages and JSON.  No bpy, no matplotlib.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Callable

import numpy as np

from ..imageio import to_display
from ..integrators import INTEGRATORS, NAMES
from ..integrators import get as get_integrator
from .comparison import CYCLES_LABEL
from .stats import jsonable, relmse, smape, student_t_isf

__all__ = [
    "CYCLES", "StudyOptions", "StudyError", "Reference", "StudyRow", "Preview", "Study", "Rung",
    "Summary", "engine_label", "ladder", "run_study", "reference_self_relmse", "fit_error_model",
    "significant_bias", "fit_slope", "time_to_target", "summarise_integrator", "summarise",
]

CYCLES = "cycles"
REFERENCE_INTEGRATOR = "path"

DEFAULT_MAX_SAMPLES = 64
DEFAULT_SEEDS = 3
DEFAULT_TARGET_RELMSE = 0.02
# The reference has this many times the largest rung's samples, so its own
# error is ~1/16 of the smallest one measured (and subtracted in the fit).
REFERENCE_FACTOR = 16
# ... split into this many independent renders: their spread estimates its error.
REFERENCE_RENDERS = 4
# Rungs where the noise is at least this many times the bias enter the
# slope fit: the bias bends the local slope there by less than 1/11.
NOISE_DOMINANCE = 10.0
# A slope needs at least this many distinct sample counts.
MIN_FIT_RUNGS = 3
# The slope is fitted from this many samples on: the first, centred sample of
# each pixel is then at most 1/8 of the samples and bends the fitted slope by
# about +0.015 (measured: variance x N at 1, 4, 32 samples = 0.35, 0.43, 0.47 on
# a soft shadow), against +0.08 over 1..64.
SLOPE_MIN_SAMPLES = 8
# A bias counts when it is this many standard errors above zero: about one
# false plateau in 1000 unbiased integrators (one-sided normal tail).
BIAS_SIGMAS = 3.0
# The first-sample term c / N^2 is fitted only with this many rungs (three
# parameters need a spare rung or two to be told apart from the noise).
MIN_RUNGS_FIRST_SAMPLE = 5
CONFIDENCE = 0.95
# Seeds: ladder render (replicate k, rung i) gets 1 + k * SEED_STRIDE + i, the
# reference renders REFERENCE_SEED + j and warm-ups WARMUP_SEED, so no two
# renders share a seed (ladders of ints have at most 63 rungs < SEED_STRIDE,
# and MAX_SEEDS replicates stay below WARMUP_SEED).
SEED_STRIDE = 1000
MAX_SEEDS = 999
REFERENCE_SEED = 1_000_000
WARMUP_SEED = 999_999
# Previews for the equal-time strip are kept tone-mapped, at most this many
# pixels on their longest side (enough for a panel of the strip).
PREVIEW_MAX_SIDE = 256
# A render counts for the equal-time strip if it took at most this much more
# than the common time (ladders double, so the nearest rung is within 2x).
EQUAL_TIME_SLACK = 1.25


class StudyError(ValueError):
    """Invalid study options; the message says which and why."""


def engine_label(engine: str) -> str:
    """How reports name an engine: its integrator's label in sentence case
    ("Path tracing", "Ray casting"), "Cycles", or the name itself if unknown."""
    if engine == CYCLES:
        return CYCLES_LABEL
    info = INTEGRATORS.get(engine)
    if info is None:
        return engine
    return info.label[:1] + info.label[1:].lower()


# ----------------------------------------------------------------------------
# Options and records
# ----------------------------------------------------------------------------

def ladder(max_samples: int) -> list[int]:
    """Sample counts 1, 2, 4, ... up to ``max_samples`` (which ends the ladder even if
    it is not a power of two)."""
    if max_samples < 1:
        raise StudyError(f"the largest sample count must be at least 1, got {max_samples}")
    rungs = [1 << k for k in range(max_samples.bit_length()) if 1 << k <= max_samples]
    if rungs[-1] != max_samples:
        rungs.append(max_samples)
    return rungs


@dataclass
class StudyOptions:
    """What to render and the error to reach.

    ``reference_samples`` is each reference's total samples per pixel
    (default ``REFERENCE_FACTOR * max_samples``), split over
    ``reference_renders`` renders.  Integrator settings (depth, branching)
    belong to the driver that renders.
    """

    integrators: tuple = NAMES
    with_cycles: bool = False
    max_samples: int = DEFAULT_MAX_SAMPLES
    seeds: int = DEFAULT_SEEDS
    reference_samples: int | None = None
    reference_renders: int = REFERENCE_RENDERS
    target_relmse: float = DEFAULT_TARGET_RELMSE
    # The integrator whose converged render every MC Engine integrator is measured
    # against: path tracing, or Path + Light Tracing where path tracing misses light
    # (caustics of point lamps), so that its error shows as a plateau.
    reference: str = REFERENCE_INTEGRATOR

    def validate(self) -> "StudyOptions":
        for name in (*self.integrators, self.reference):
            try:
                get_integrator(name)
            except ValueError as exc:
                raise StudyError(str(exc)) from None
        if not self.integrators and not self.with_cycles:
            raise StudyError("nothing to study: no integrator and no Cycles")
        if self.seeds < 2:
            raise StudyError(f"at least 2 seeds are needed for error bars, got {self.seeds}")
        if self.seeds > MAX_SEEDS:
            raise StudyError(f"at most {MAX_SEEDS} seeds, got {self.seeds}")
        if self.reference_renders < 2:
            raise StudyError("the reference needs at least 2 renders to estimate its own error")
        if self.reference_total() < self.reference_renders:
            raise StudyError(f"the reference needs at least {self.reference_renders} samples")
        if not 0 < self.target_relmse:
            raise StudyError(f"the target relMSE must be positive, got {self.target_relmse}")
        return self

    def ladder(self) -> list[int]:
        return ladder(self.max_samples)

    def reference_total(self) -> int:
        return int(self.reference_samples or REFERENCE_FACTOR * self.max_samples)

    def reference_each(self) -> int:
        """Samples of each reference render (the total rounded down to a multiple)."""
        return self.reference_total() // self.reference_renders

    def engines(self) -> list[str]:
        return list(self.integrators) + ([CYCLES] if self.with_cycles else [])


@dataclass
class Reference:
    """A converged image: the mean of ``renders`` independent renders.

    ``self_relmse`` estimates the reference's own relMSE against the truth
    (:func:`reference_self_relmse`), ``self_relmse_untrimmed`` without trimming.
    """

    engine: str
    image: np.ndarray = field(repr=False)
    samples: int
    renders: int
    seconds: float
    self_relmse: float
    self_relmse_untrimmed: float


@dataclass
class StudyRow:
    """One timed render of the ladder and its error against the reference."""

    integrator: str
    samples: int
    seed: int
    replicate: int
    seconds: float
    relmse: float
    relmse_untrimmed: float
    smape: float
    reference: str


@dataclass
class Preview:
    """A ladder render kept for the equal-time strip: (h, w, 4) uint8 display image."""

    samples: int
    seconds: float
    image: np.ndarray = field(repr=False)


@dataclass
class Study:
    """Everything a study measured.

    ``settings`` maps an integrator to a description of its settings (depth,
    branching) for the report; ``notes`` are sentences for the report (what
    the times include, warnings).
    """

    scene: str
    width: int
    height: int
    options: StudyOptions
    rows: list = field(default_factory=list)
    references: dict = field(default_factory=dict)
    previews: dict = field(default_factory=dict)
    reference_previews: dict = field(default_factory=dict)
    settings: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)

    def integrators(self) -> list[str]:
        """Integrators with rows, in the order they were rendered."""
        return list(dict.fromkeys(row.integrator for row in self.rows))


# ----------------------------------------------------------------------------
# Running
# ----------------------------------------------------------------------------

def reference_self_relmse(images, trim: float = 0.001, eps: float = 1e-2) -> float:
    """Estimated relMSE of the mean of ``images`` against the true image.

    Per pixel, the variance of the K-render mean is the renders' sample
    variance (ddof 1) over K; it is divided by ``mean**2 + eps`` like
    :func:`mcengine.evaluation.stats.relmse`, averaged over RGB, and the largest
    ``trim`` share of pixels is dropped before averaging.

    Parameters
    ----------
    images : (K, h, w, C) float, K >= 2, C = 3 or 4 (RGB used)

    Returns
    -------
    float
    """
    stack = np.asarray(images, np.float64)[..., :3]
    if stack.ndim != 4 or stack.shape[0] < 2:
        raise StudyError(f"need a (K >= 2, h, w, C) stack of renders, got shape {stack.shape}")
    k = stack.shape[0]
    mean = stack.mean(axis=0)
    var_of_mean = stack.var(axis=0, ddof=1) / k
    per_pixel = (var_of_mean / (mean**2 + eps)).mean(axis=-1).ravel()
    keep = per_pixel.size - int(math.floor(trim * per_pixel.size))
    return float(np.partition(per_pixel, keep - 1)[:keep].mean())


def _preview(image) -> np.ndarray:
    """Tone-mapped (h, w, 4) uint8 copy, box-downsampled to at most PREVIEW_MAX_SIDE."""
    img = np.asarray(image, np.float64)
    if img.shape[-1] == 3:
        img = np.concatenate([img, np.ones(img.shape[:2] + (1,))], axis=-1)
    step = max(1, math.ceil(max(img.shape[:2]) / PREVIEW_MAX_SIDE))
    if step > 1:
        h, w = (img.shape[0] // step) * step, (img.shape[1] // step) * step
        img = img[:h, :w].reshape(h // step, step, w // step, step, 4).mean(axis=(1, 3))
    return to_display(img)


def _render_reference(render, engine, options, progress) -> Reference:
    each = options.reference_each()
    images, seconds = [], 0.0
    for j in range(options.reference_renders):
        progress(f"{engine} reference {j + 1}/{options.reference_renders}, {each} samples")
        out = render(engine, each, REFERENCE_SEED + j)
        images.append(np.asarray(out.image, np.float32))
        seconds += float(out.seconds)
    stack = np.stack(images)
    return Reference(engine=engine, image=stack.mean(axis=0), samples=each * len(images),
                     renders=len(images), seconds=seconds,
                     self_relmse=reference_self_relmse(stack),
                     self_relmse_untrimmed=reference_self_relmse(stack, trim=0.0))


def run_study(render: Callable, options: StudyOptions, *, scene: str = "", settings=None,
              notes=(), on_render: Callable | None = None) -> Study:
    """Render the references and every ladder, measure each render's error.

    Parameters
    ----------
    render : callable ``(integrator, samples, seed) -> object with .image, .seconds``
        ``integrator`` is one of ``options.engines()``; ``image`` is
        ``(h, w, 3|4)`` float, top row first.
    options : StudyOptions
    scene : str
        Name for the report.
    settings : dict, optional
        Integrator -> description of its settings, for the report.
    notes : sequence of str
        Sentences for the report.
    on_render : callable ``(label, index, total)``, optional
        Called before each render.

    Returns
    -------
    Study

    Before each integrator's ladder one 1-sample render (seed
    ``WARMUP_SEED``, not timed) loads its kernels, so compilation is not
    charged to the first rung.
    """
    options.validate()
    engines = options.engines()
    rungs = options.ladder()
    ref_engines = ([options.reference] if options.integrators else []) + (
        [CYCLES] if options.with_cycles else [])
    warmups = [e for e in engines if e not in ref_engines]
    total = (len(ref_engines) * options.reference_renders + len(warmups)
             + len(engines) * len(rungs) * options.seeds)
    count = [0]

    def progress(label):
        if on_render is not None:
            on_render(label, count[0], total)
        count[0] += 1

    study = Study(scene=scene, width=0, height=0, options=options,
                  settings=dict(settings or {}), notes=list(notes))
    for engine in ref_engines:
        ref = _render_reference(render, engine, options, progress)
        study.references[engine] = ref
        study.reference_previews[engine] = _preview(ref.image)
        study.height, study.width = ref.image.shape[:2]
    for engine in engines:
        ref_name = CYCLES if engine == CYCLES else options.reference
        ref = study.references[ref_name]
        if engine in warmups:
            progress(f"{engine} warm-up")
            render(engine, 1, WARMUP_SEED)
        previews = study.previews.setdefault(engine, [])
        for i, n in enumerate(rungs):
            for k in range(options.seeds):
                seed = 1 + k * SEED_STRIDE + i
                progress(f"{engine} {n} sample{'s' if n > 1 else ''}, seed {seed}")
                out = render(engine, n, seed)
                image = np.asarray(out.image, np.float32)
                if image.shape[:2] != ref.image.shape[:2]:
                    raise StudyError(f"{engine} rendered {image.shape[1]}x{image.shape[0]} pixels, "
                                     f"the reference {ref.image.shape[1]}x{ref.image.shape[0]}")
                study.rows.append(StudyRow(
                    integrator=engine, samples=n, seed=seed, replicate=k,
                    seconds=float(out.seconds), relmse=relmse(image, ref.image),
                    relmse_untrimmed=relmse(image, ref.image, trim=0.0),
                    smape=smape(image, ref.image), reference=ref_name))
                if k == 0:
                    previews.append(Preview(n, float(out.seconds), _preview(image)))
    return study


# ----------------------------------------------------------------------------
# Analysis
# ----------------------------------------------------------------------------

@dataclass
class Rung:
    """One sample count of one integrator, over its seeds.

    ``relmse`` is the mean over seeds, ``relmse_lo``/``relmse_hi`` the
    smallest and largest seed; ``relmse_untrimmed`` the mean without trimming
    (what the error model describes).
    ``seconds`` is the median over seeds: a render slowed by other work on
    the machine does not move it.
    """

    samples: int
    seconds: float
    relmse: float
    relmse_lo: float
    relmse_hi: float
    relmse_untrimmed: float
    smape: float
    smape_lo: float
    smape_hi: float
    renders: int

    @property
    def efficiency(self) -> float:
        """1 / (relMSE * seconds), per second."""
        product = self.relmse * self.seconds
        return 1.0 / product if product > 0 else math.inf


@dataclass
class Summary:
    """One integrator's convergence: error model, slope, plateau, time to target."""

    integrator: str
    reference: str
    rungs: list
    noise: float                   # a of a/N + c/N^2 + b (untrimmed relMSE)
    first_sample: float            # c
    floor: float                   # b
    floor_se: float                # standard error of b
    reference_error: float         # r, the reference's own estimated relMSE
    reference_error_untrimmed: float  # the same without trimming (for the model)
    plateau: bool
    slope: float | None
    slope_se: float | None
    slope_dof: int
    slope_ci: float | None         # half-width of the CONFIDENCE interval
    fit_samples: tuple
    target: float
    time_to_target: float | None
    target_how: str                # "interpolated", "first rung", "extrapolated", "not reached"

    def noise_at(self, samples) -> float:
        """The model's noise term ``a / N + c / N**2``."""
        return self.noise / samples + self.first_sample / samples**2

    @property
    def bias(self) -> float:
        """The floor beyond the reference's own error, the algorithm's squared relative
        bias; 0 unless ``BIAS_SIGMAS`` standard errors above zero."""
        return significant_bias(self.floor, self.floor_se, self.reference_error_untrimmed)

    @property
    def efficiency(self) -> float:
        """At the largest sample count."""
        return self.rungs[-1].efficiency

    def slope_consistent(self, expected: float = -1.0) -> bool | None:
        """Whether ``expected`` lies in the slope's confidence interval (None without a fit)."""
        if self.slope is None or self.slope_ci is None:
            return None
        return abs(self.slope - expected) <= self.slope_ci

    def to_dict(self) -> dict:
        out = {k: v for k, v in asdict(self).items() if k != "rungs"}
        out["rungs"] = [dict(asdict(r), efficiency=r.efficiency) for r in self.rungs]
        out.update(bias=self.bias, efficiency=self.efficiency,
                   slope_consistent_with_minus_one=self.slope_consistent())
        return jsonable(out)


def fit_error_model(samples, relmse_mean, relative_se: float | None = None):
    """Fit ``relMSE(N) = a / N + c / N**2 + b`` with ``a, b >= 0``.

    Least squares on relative residuals ``model / m - 1``, so a rung at
    relMSE 0.01 weighs as much as one at 1.  Every subset of the three terms
    is fitted and the best one with ``a, b >= 0`` and a positive noise term
    at every sample count is kept; ``c`` is left out (0) with fewer than
    ``MIN_RUNGS_FIRST_SAMPLE`` rungs.

    Parameters
    ----------
    samples : (n,) int
    relmse_mean : (n,) float, positive
    relative_se : float, optional
        Relative standard error of one rung mean (from the seed scatter);
        default: from the fit's residuals.

    Returns
    -------
    (a, c, b, b_se) : floats
        ``b_se`` is 0 when ``b`` is not fitted (held at 0) and inf when it
        cannot be estimated.
    """
    n = np.asarray(samples, np.float64)
    m = np.asarray(relmse_mean, np.float64)
    if n.size != m.size or n.size == 0 or np.any(m <= 0):
        raise StudyError("the error model needs positive errors, one per sample count")
    columns = np.stack([1.0 / n, 1.0 / n**2, np.ones_like(n)], axis=1) / m[:, None]
    terms = [(0,), (2,), (0, 2)] + ([(0, 1), (0, 1, 2)] if n.size >= MIN_RUNGS_FIRST_SAMPLE else [])
    best = None
    for subset in terms:
        if len(subset) > n.size:
            continue
        x = columns[:, subset]
        coef, *_ = np.linalg.lstsq(x, np.ones_like(m), rcond=None)
        full = np.zeros(3)
        full[list(subset)] = coef
        a, c, b = full
        if a < 0 or b < 0 or np.any(a / n + c / n**2 < 0):
            continue
        residual = float(np.sum((columns @ full - 1.0) ** 2))
        if best is None or residual < best[0] - 1e-15:
            best = (residual, full, subset, x)
    if best is None:     # only for pathological data: all error as bias
        return 0.0, 0.0, float(m.mean()), math.inf
    residual, (a, c, b), subset, x = best
    b_se = 0.0
    if 2 in subset:
        dof = n.size - len(subset)
        if relative_se is not None:
            var = relative_se**2
        else:
            var = residual / dof if dof > 0 else math.inf
        cov = np.linalg.pinv(x.T @ x) * var
        b_se = float(math.sqrt(max(cov[-1, -1], 0.0)))
    return float(a), float(c), float(b), b_se


def significant_bias(floor: float, floor_se: float, reference_error: float) -> float:
    """``floor - reference_error`` if at least ``BIAS_SIGMAS`` standard errors above 0, else 0."""
    bias = floor - reference_error
    return bias if bias > 0 and bias >= BIAS_SIGMAS * floor_se else 0.0


def fit_slope(samples, errors, confidence: float = CONFIDENCE):
    """Least-squares slope of ``log(errors)`` against ``log(samples)``.

    Parameters
    ----------
    samples : (n,) int
        One entry per render (sample counts repeat across seeds).
    errors : (n,) float, positive
    confidence : float
        Level of the returned interval.

    Returns
    -------
    (slope, standard_error, dof, half_width)
        ``dof = n - 2``; ``half_width`` is the Student-t interval's.  All but
        dof are None with fewer than ``MIN_FIT_RUNGS`` distinct sample counts.
    """
    x = np.log(np.asarray(samples, np.float64))
    y = np.log(np.asarray(errors, np.float64))
    dof = x.size - 2
    if np.unique(x).size < MIN_FIT_RUNGS or dof < 1:
        return None, None, max(dof, 0), None
    xc = x - x.mean()
    slope = float(xc @ (y - y.mean()) / (xc @ xc))
    residual = y - y.mean() - slope * xc
    se = float(math.sqrt(residual @ residual / dof / (xc @ xc)))
    half = float(student_t_isf(0.5 * (1.0 - confidence), dof)) * se
    return slope, se, dof, half


def time_to_target(seconds, errors, target: float):
    """First time the error falls to ``target``, interpolated in log-log.

    Parameters
    ----------
    seconds, errors : (n,) float
        Per rung, in ladder order.

    Returns
    -------
    (seconds or None, how) : how is "first rung" (already at or below the
        target at the first rung: the time is that rung's), "interpolated",
        or "not reached".
    """
    seconds, errors = np.asarray(seconds, float), np.asarray(errors, float)
    below = np.flatnonzero(errors <= target)
    if below.size == 0:
        return None, "not reached"
    i = int(below[0])
    if i == 0:
        return float(seconds[0]), "first rung"
    le0, le1 = math.log(errors[i - 1]), math.log(errors[i])
    lt0, lt1 = math.log(seconds[i - 1]), math.log(seconds[i])
    f = (math.log(target) - le0) / (le1 - le0)
    return float(math.exp(lt0 + f * (lt1 - lt0))), "interpolated"


def _rungs(rows) -> list[Rung]:
    by_n = {}
    for row in rows:
        by_n.setdefault(row.samples, []).append(row)
    out = []
    for n in sorted(by_n):
        group = by_n[n]
        rel = np.array([r.relmse for r in group])
        sm = np.array([r.smape for r in group])
        out.append(Rung(samples=n, seconds=float(np.median([r.seconds for r in group])),
                        relmse=float(rel.mean()), relmse_lo=float(rel.min()),
                        relmse_hi=float(rel.max()),
                        relmse_untrimmed=float(np.mean([r.relmse_untrimmed for r in group])),
                        smape=float(sm.mean()),
                        smape_lo=float(sm.min()), smape_hi=float(sm.max()), renders=len(group)))
    return out


def _relative_se(errors, samples) -> float | None:
    """Pooled relative standard error of a rung's mean error, from the seed scatter."""
    by_n = {}
    for err, n in zip(errors, samples):
        by_n.setdefault(n, []).append(err)
    ratios = [np.var(v, ddof=1) / np.mean(v) ** 2 / len(v) for v in by_n.values()
              if len(v) >= 2 and np.mean(v) > 0]
    return float(math.sqrt(np.mean(ratios))) if ratios else None


def summarise_integrator(rows, reference_error: float, target: float,
                         reference_error_untrimmed: float | None = None) -> Summary:
    """Error model, plateau, slope and time to target of one integrator's rows.

    ``reference_error`` (and ``reference_error_untrimmed``, default the same)
    is the reference's own estimated relMSE.
    """
    r_full = reference_error if reference_error_untrimmed is None else reference_error_untrimmed
    rows = list(rows)
    rungs = _rungs(rows)
    n = np.array([r.samples for r in rungs], float)
    # The model describes the mean squared error: fitted on the untrimmed relMSE.
    a, c, b, b_se = fit_error_model(n, [max(r.relmse_untrimmed, 1e-300) for r in rungs],
                                    _relative_se([r.relmse_untrimmed for r in rows],
                                                 [r.samples for r in rows]))
    bias = significant_bias(b, b_se, r_full)
    noise = a / n + c / n**2
    plateau = bias > noise[-1]
    fit_n = tuple(int(k) for k, e in zip(n, noise)
                  if k >= SLOPE_MIN_SAMPLES and e >= NOISE_DOMINANCE * bias)
    fit_rows = [r for r in rows if r.samples in fit_n]
    # The reference's error adds to every measurement; a floor keeps the log finite.
    corrected = [max(r.relmse_untrimmed - r_full, 1e-3 * r.relmse_untrimmed) for r in fit_rows]
    slope, se, dof, half = fit_slope([r.samples for r in fit_rows], corrected)
    t, how = time_to_target([r.seconds for r in rungs], [r.relmse for r in rungs], target)
    if t is None and target > b and a > 0:
        # The model's sample count for the target (the 1/N^2 term is negligible
        # there), at the last rung's time per sample.
        needed = a / (target - b)
        t, how = rungs[-1].seconds * needed / rungs[-1].samples, "extrapolated"
    return Summary(integrator=rows[0].integrator, reference=rows[0].reference, rungs=rungs,
                   noise=a, first_sample=c, floor=b, floor_se=b_se,
                   reference_error=reference_error, reference_error_untrimmed=r_full,
                   plateau=bool(plateau),
                   slope=slope, slope_se=se, slope_dof=dof, slope_ci=half, fit_samples=fit_n,
                   target=target, time_to_target=t, target_how=how)


def summarise(study: Study) -> dict:
    """Integrator -> :class:`Summary`, in the study's order."""
    out = {}
    for name in study.integrators():
        rows = [r for r in study.rows if r.integrator == name]
        ref = study.references.get(rows[0].reference)
        r, r_full = (ref.self_relmse, ref.self_relmse_untrimmed) if ref is not None else (0.0, 0.0)
        out[name] = summarise_integrator(rows, r, study.options.target_relmse, r_full)
    return out
