"""Accuracy-against-time studies: the fits on synthetic data, the files, and a real slope.

Synthetic errors follow the study's model ``relMSE = a / N + b`` with
log-normal scatter from a fixed seed, so the true slope, floor and crossing
times are known.  The real check renders a small scene with the path tracer
and independent samples (the 1/N law is theirs) at 1..32 samples, four seeds
each, and asserts that the measured relMSE slope is -1 within the 95 %
interval the study derives from the seed-to-seed spread, and that this
interval is narrow enough to tell -1 from -0.8.
"""
import math
from types import SimpleNamespace

import numpy as np
import pytest

from mcengine.evaluation import study as S
from mcengine.evaluation.datafiles import COLUMNS, read_csv
from mcengine.evaluation.output import write_study
from mcengine.evaluation.stats import relmse
from mcengine.scene import Camera, Film, Geometry, Integrator, Light, Material, SceneDescription, World
from mcengine.session import RenderSession

from .scenes import grid_plane, translation
from .test_adaptive import _box


def _rows(integrator, a, b, ladder=(1, 2, 4, 8, 16, 32, 64), seeds=4, scatter=0.08,
          seconds_per_sample=0.01, rng_seed=0):
    """Synthetic study rows with E[relMSE] = a / N + b and log-normal seed scatter."""
    rng = np.random.default_rng(rng_seed)
    rows = []
    for i, n in enumerate(ladder):
        for k in range(seeds):
            err = (a / n + b) * math.exp(rng.normal(0, scatter))
            rows.append(S.StudyRow(integrator, n, 1 + k * 1000 + i, k, 0.02 + seconds_per_sample * n,
                                   err, err, 0.1, "path"))
    return rows


def test_ladder_doubles_and_ends_at_the_maximum():
    assert S.ladder(1) == [1]
    assert S.ladder(64) == [1, 2, 4, 8, 16, 32, 64]
    assert S.ladder(48) == [1, 2, 4, 8, 16, 32, 48]
    with pytest.raises(S.StudyError):
        S.ladder(0)


def test_slope_fit_recovers_a_known_slope_and_its_interval_excludes_others():
    rng = np.random.default_rng(1)
    n = np.repeat([1, 2, 4, 8, 16, 32, 64], 4)
    err = 0.7 * n ** -0.7 * np.exp(rng.normal(0, 0.05, n.size))
    slope, se, dof, half = S.fit_slope(n, err)
    assert dof == n.size - 2
    assert abs(slope + 0.7) <= half
    assert half < 0.05                  # narrow enough that -1 and -0.5 fall outside
    assert abs(slope + 1.0) > half and abs(slope + 0.5) > half
    # the standard error is the textbook one: residual scatter over the spread of log N
    x = np.log(n)
    assert se == pytest.approx(0.05 / math.sqrt(((x - x.mean()) ** 2).sum()), rel=0.3)


def test_slope_needs_three_sample_counts():
    slope, se, _, half = S.fit_slope([1, 1, 2, 2], [1.0, 1.1, 0.5, 0.6])
    assert slope is None and se is None and half is None


def test_error_model_recovers_noise_first_sample_term_and_bias():
    n = np.array([1, 2, 4, 8, 16, 32, 64])
    a, c, b, _ = S.fit_error_model(n, 0.8 / n - 0.2 / n**2 + 0.05)
    assert (a, c, b) == pytest.approx((0.8, -0.2, 0.05), rel=1e-9)
    a, c, b, b_se = S.fit_error_model(n, 0.8 / n)            # unbiased: b on its boundary
    assert (a, c, b, b_se) == pytest.approx((0.8, 0.0, 0.0, 0.0), abs=1e-12)
    a, c, b, _ = S.fit_error_model(n, np.full(n.size, 0.3))  # all bias
    assert (a, c, b) == pytest.approx((0.0, 0.0, 0.3), abs=1e-12)
    # with few rungs the 1/N^2 term is not fitted
    a, c, b, _ = S.fit_error_model(n[:4], 0.8 / n[:4] + 0.05)
    assert c == 0.0 and (a, b) == pytest.approx((0.8, 0.05), rel=1e-9)


def test_floor_standard_error_scales_with_the_rung_scatter():
    n = np.array([1, 2, 4, 8, 16, 32, 64])
    m = 0.8 / n + 0.01
    _, _, _, se1 = S.fit_error_model(n, m, relative_se=0.01)
    _, _, _, se2 = S.fit_error_model(n, m, relative_se=0.02)
    assert se2 == pytest.approx(2 * se1) and 0 < se1 < 0.01
    # a floor within BIAS_SIGMAS standard errors of the reference's error is no bias
    assert S.significant_bias(0.011, 0.001, 0.01) == 0.0
    assert S.significant_bias(0.02, 0.001, 0.01) == pytest.approx(0.01)


def test_plateau_is_detected_on_biased_data_and_not_on_unbiased():
    unbiased = S.summarise_integrator(_rows("path", 1.0, 0.001), reference_error=0.001, target=0.02)
    biased = S.summarise_integrator(_rows("raycast", 1.0, 0.3, rng_seed=2), reference_error=0.001,
                                    target=0.02)
    assert not unbiased.plateau
    assert unbiased.fit_samples == (8, 16, 32, 64)
    assert unbiased.slope_consistent(-1.0)
    assert biased.plateau
    assert biased.floor == pytest.approx(0.3, rel=0.1)
    # noise dominates the bias 10x only below N = 1/(10 * 0.3): no slope to fit
    assert biased.slope is None
    assert biased.time_to_target is None and biased.target_how == "not reached"
    # a small bias: the fit keeps only the rungs where it is negligible, and no plateau yet
    slight = S.summarise_integrator(_rows("distribution", 1.0, 0.002, scatter=0.02, rng_seed=3),
                                    reference_error=0.0, target=0.02)
    assert not slight.plateau and slight.fit_samples == (8, 16, 32)


def test_time_to_target_interpolates_in_log_log():
    seconds = np.array([1.0, 2.0, 4.0, 8.0])
    errors = 0.4 / seconds            # an exact power law: log-log interpolation is exact
    t, how = S.time_to_target(seconds, errors, 0.4 / 3.0)
    assert how == "interpolated" and t == pytest.approx(3.0, rel=1e-12)
    assert S.time_to_target(seconds, errors, 0.5) == (1.0, "first rung")
    assert S.time_to_target(seconds, errors, 0.01) == (None, "not reached")


def test_time_to_target_is_extrapolated_only_above_the_floor():
    s = S.summarise_integrator(_rows("path", 1.0, 0.0, ladder=(1, 2, 4, 8)), 0.0, target=0.01)
    assert s.target_how == "extrapolated"
    # the model needs N = a / target = ~100 samples at 0.01 s per sample, plus the fixed 0.02 s
    assert s.time_to_target == pytest.approx((0.02 + 0.08) / 8 * 100, rel=0.2)


def test_reference_self_error_matches_its_actual_error():
    rng = np.random.default_rng(4)
    truth = rng.random((64, 64, 3)) + 0.1
    stack = truth + rng.normal(0, 0.2, (4,) + truth.shape) * truth
    estimated = S.reference_self_relmse(stack)
    actual = relmse(stack.mean(axis=0), truth)
    # E[(mean - t)^2 / (t^2 + eps)] = 0.04 t^2 / 4 / (t^2 + eps): both agree with it
    expected = float(np.mean(0.01 * truth**2 / (truth**2 + 1e-2)))
    assert estimated == pytest.approx(expected, rel=0.05)
    assert actual == pytest.approx(expected, rel=0.05)


class _FakeRenderer:
    """Images truth * (1 + bias) + noise / sqrt(N); records every call."""

    BIAS = {"path": 0.0, "raycast": -0.5, "cycles": 0.0}

    def __init__(self):
        self.truth = np.random.default_rng(5).random((12, 16, 4)) + 0.2
        self.calls = []

    def __call__(self, integrator, samples, seed):
        self.calls.append((integrator, samples, seed))
        rng = np.random.default_rng(seed)
        img = self.truth * (1 + self.BIAS[integrator]) + rng.normal(0, 0.5, self.truth.shape) \
            * self.truth / math.sqrt(samples)
        return SimpleNamespace(image=img, seconds=0.01 * samples)


def test_study_writes_one_csv_row_per_render_and_every_file(tmp_path):
    fake = _FakeRenderer()
    options = S.StudyOptions(integrators=("path", "raycast"), with_cycles=True, max_samples=8,
                             seeds=2, reference_renders=2)
    labels = []
    study = S.run_study(fake, options, scene="fake", on_render=lambda label, i, n: labels.append((i, n)))
    paths = write_study(study, tmp_path)
    rows = read_csv(paths["csv"])
    assert open(paths["csv"]).readline().strip().split(",") == list(COLUMNS)
    assert len(rows) == 3 * 4 * 2       # (path, raycast, cycles) x (1, 2, 4, 8) x 2 seeds
    assert {(r.integrator, r.samples) for r in rows} == {
        (m, n) for m in ("path", "raycast", "cycles") for n in (1, 2, 4, 8)}
    assert {r.reference for r in rows if r.integrator == "cycles"} == {"cycles"}
    assert {r.reference for r in rows if r.integrator != "cycles"} == {"path"}
    # every render of an engine has its own seed; references: 2 x 64 samples for path and Cycles
    for engine in ("path", "raycast", "cycles"):
        seeds = [c[2] for c in fake.calls if c[0] == engine]
        assert len(set(seeds)) == len(seeds)
    assert [c for c in fake.calls if c[2] >= S.REFERENCE_SEED] == [
        ("path", 64, S.REFERENCE_SEED), ("path", 64, S.REFERENCE_SEED + 1),
        ("cycles", 64, S.REFERENCE_SEED), ("cycles", 64, S.REFERENCE_SEED + 1)]
    assert ("raycast", 1, S.WARMUP_SEED) in fake.calls           # warm-up, not in the rows
    assert labels == [(i, len(fake.calls)) for i in range(len(fake.calls))]
    assert rows[0].seconds == pytest.approx(0.01)
    for name in ("time", "samples", "strip"):
        assert paths[name].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    page = paths["html"].read_text()
    assert "Ray casting</b>: the error stops falling" in page
    assert "error_vs_time.png" in page and "study.csv" in page
    assert "| Ray casting | not reached" in paths["markdown"].read_text()


def test_options_are_validated():
    with pytest.raises(S.StudyError, match="unknown integrator 'bidir'"):
        S.StudyOptions(integrators=("bidir",)).validate()
    with pytest.raises(S.StudyError, match="2 seeds"):
        S.StudyOptions(seeds=1).validate()


# -- the path tracer on a real render -----------------------------------------------------

RES = 32


def _scene(samples, seed):
    """A plane lit by an area light and a box casting a soft shadow (direct light), with
    independent samples: the 1/N law is theirs (Sobol points converge faster)."""
    tris = np.concatenate([grid_plane(20.0), _box()])
    light = Light(type="AREA", matrix_world=translation(0.3, 0, 3), strength=(300.0,) * 3,
                  size_x=1.5)
    return SceneDescription(
        geometry=Geometry.from_triangles(tris), materials=[Material(base_color=(0.8, 0.8, 0.8))],
        lights=[light],
        camera=Camera(matrix_world=translation(0, 0, 6), type="ORTHO", ortho_scale=4.0),
        world=World(color=(0.0, 0.0, 0.0)), film=Film(width=RES, height=RES),
        integrator=Integrator(samples=samples, seed=seed, max_bounces=0,
                              sampler="independent"))


def _render_path(integrator, samples, seed):
    session = RenderSession(_scene(samples, seed), threads=2).run()
    return SimpleNamespace(image=session.image(), seconds=session.stats.time_render)


def test_path_tracer_relmse_falls_as_one_over_n():
    options = S.StudyOptions(integrators=("path",), max_samples=64, seeds=4,
                             reference_samples=1024, reference_renders=4)
    study = S.run_study(_render_path, options)
    s = S.summarise(study)["path"]
    assert not s.plateau
    assert s.fit_samples == (8, 16, 32, 64)
    # the 95 % interval from the seed-to-seed spread contains -1 ...
    assert abs(s.slope + 1.0) <= s.slope_ci, (s.slope, s.slope_ci)
    # ... and is narrow enough to reject a wrong rate such as -0.8
    assert s.slope_ci < 0.2
