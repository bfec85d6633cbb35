"""The verdict under uncertainty.  On a stand-in whose two checks' safety factors are explicit
functions of sampled data (a press fit ``c δ μ / L`` of interference δ and friction μ over a load
scale L, and a shaft ``c₂ / L``): its quantiles and probabilities against a brute-force Monte Carlo,
its indices against the closed form, the grouping of rows by their dynamics, progress and
stopping, samples without a verdict, the JSON.  On the bogie: a listed sample's parameter set,
written and read back, re-assessed by ``assess`` gives its recorded governing safety factor;
rows that change only strength data reuse the loads; the ripple responses scale exactly."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from model.mechanics.operating_point import KMH
from model.mechanics.parameters import load_parameters
from model.studies import verdict_uncertainty
from model.studies.assessment import AssessmentOptions, assess, ripple_case
from model.studies.parameter_ranges import ParameterRange
from model.studies.ripple_case import ripple_amplitudes
from model.studies.verdict_priors import PriorRangeError, VerdictUncertaintyError
from model.studies.verdict_result import GOVERNING, VerdictUncertainty
from model.studies.verdict_statistics import quantiles, saltelli_design
from model.studies.verdict_uncertainty import (
    RowVerdicts,
    assess_rows,
    dynamics_cases,
    planned_size,
    run_verdict_uncertainty,
    sample_parameters,
    sample_verdicts,
    save_sample_parameters,
    scaled_sweep,
    verdict_on_loads,
)

# --- the stand-in --------------------------------------------------------------------------------

UNKNOWNS = (ParameterRange("rotor_inertia", 8.0, 18.0, "stand-in: the load scale L"),
            ParameterRange("wheel_seat_interference_min", 1.28e-4, 2.36e-4, "stand-in: δ",
                           log=False),
            ParameterRange("wheel_seat_friction_min", 0.08, 0.16, "stand-in: μ", log=False))
SLIP_SCALE = 1.5 * 12.0 / (1.9e-4 * 0.12)  # the press fit's factor 1.5 at L = 12, 0.19 mm, 0.12
SHEAR_SCALE = SLIP_SCALE * 1.6e-5 / 1.5  # the shaft governs where δ μ > 1.6e-5 m
CHECKS = (("stand-in seat", "press_fit_slip", "stand-in"),
          ("stand-in shaft", "torsional_shear", "stand-in"))
REQUIRED = np.array([1.5, 1.0])


def stand_in_factors(X: np.ndarray) -> np.ndarray:
    """rows x checks: the press fit c δ μ / L, the shaft c₂ / L."""
    return np.column_stack([SLIP_SCALE * X[:, 1] * X[:, 2] / X[:, 0], SHEAR_SCALE / X[:, 0]])


def stand_in_rows(rows: np.ndarray, checks: int = 2, undefined_above: float = math.inf
                  ) -> RowVerdicts:
    """The stand-in's work item (rows share their L); no verdict where L > ``undefined_above``."""
    rows = np.atleast_2d(rows)
    if rows[0, 0] > undefined_above:
        return RowVerdicts(np.full((len(rows), 0), np.nan), np.full(len(rows), -1), (), (),
                           ("AssessmentError: unstable",) * len(rows))
    factors = stand_in_factors(rows)[:, :checks]
    governing = np.argmax(REQUIRED[:checks] / factors, axis=1)
    return RowVerdicts(factors, governing, CHECKS[:checks], tuple(REQUIRED[:checks]),
                       ("",) * len(rows))


@pytest.fixture(scope="module")
def brute_force():
    """Factors of 2^21 independent draws of the prior (the reference)."""
    rng = np.random.default_rng(2024)
    X = np.column_stack([u.distribution().ppf(rng.random(2**21)) for u in UNKNOWNS])
    factors = stand_in_factors(X)
    governing = np.argmax(REQUIRED / factors, axis=1)
    return factors, factors[np.arange(len(X)), governing], REQUIRED[governing]


def _sigma(interval) -> float:
    """The standard deviation a 95 % interval implies."""
    return (interval[1] - interval[0]) / (2 * 1.96)


def test_quantiles_and_probabilities_match_a_brute_force_monte_carlo(brute_force):
    """n = 1024 Sobol' samples through the study against 2^21 independent draws: every quantile
    within three standard deviations its interval implies, every P(fail) within three binomial
    standard errors; each listed sample's governing check and factor are the stand-in's."""
    factors, governing_factor, governing_required = brute_force
    result = sample_verdicts(stand_in_rows, UNKNOWNS, 1024, seed=7)
    assert (result.runs, result.evaluations, len(result.samples)) == (1024, 1024, 1024)
    for band, truth in ((result.checks[0], factors[:, 0]), (result.checks[1], factors[:, 1]),
                        (result.governing, governing_factor)):
        exact = quantiles(truth, [5.0, 50.0, 95.0])
        for estimate, interval, reference in zip(band.quantiles, band.quantile_intervals, exact,
                                                 strict=True):
            assert abs(estimate - reference) <= 3 * _sigma(interval), band.label
    for band, failing in ((result.checks[0], factors[:, 0] < 1.5),
                          (result.checks[1], factors[:, 1] < 1.0),
                          (result.governing, governing_factor < governing_required)):
        p = failing.mean()
        assert 0.05 < p < 0.95  # the test compares a probability that is not trivial
        assert abs(band.failure.value - p) <= 3 * math.sqrt(p * (1 - p) / 1024), band.label
    X = np.array([s.values for s in result.samples])
    expected = stand_in_factors(X)
    governs = np.argmax(REQUIRED / expected, axis=1)
    assert [s.check for s in result.samples] == list(governs)
    assert 0 < np.mean(governs) < 1  # both checks govern somewhere
    np.testing.assert_array_equal([s.safety_factor for s in result.samples],
                                  expected[np.arange(1024), governs])
    assert sum(result.governing_counts) == 1024


def test_the_binomial_error_is_a_conservative_stand_in_here(brute_force):
    """The spread of P(fail) over 16 independent scrambles of 256 points stays below the binomial
    standard error the result quotes (scrambled Sobol' points do better than independent ones on
    this smooth, low-dimensional stand-in; the docstrings say that is not a bound)."""
    _, governing_factor, governing_required = brute_force
    p = np.mean(governing_factor < governing_required)
    estimates = [sample_verdicts(stand_in_rows, UNKNOWNS, 256, seed=seed).governing.failure.value
                 for seed in range(16)]
    assert np.std(estimates) < math.sqrt(p * (1 - p) / 256)


def test_indices_through_the_study_match_the_closed_form():
    """With one check the governing factor is the press fit's, whose indices are known
    (tests/model/studies/test_verdict_statistics.py gives the closed form and the tolerance's
    reason); the rows are grouped by their dynamics value: one work item per distinct L."""
    from test_verdict_statistics import TOLERANCE, analytic_indices

    n = 1024
    items = []

    def work(rows):
        items.append(len(rows))
        return stand_in_rows(rows, checks=1)

    result = sample_verdicts(work, UNKNOWNS, n, seed=3, indices=True, resamples=100)
    first, total, group_first, group_total = analytic_indices()
    band = result.governing
    assert np.abs(np.array(band.first_order) - first).max() <= TOLERANCE
    assert np.abs(np.array(band.total_order) - total).max() <= TOLERANCE
    assert np.abs(np.array(band.group_first_order) - group_first).max() <= TOLERANCE
    assert np.abs(np.array(band.group_total_order) - group_total).max() <= TOLERANCE
    for (low, high), value in zip(band.total_order_interval, band.total_order, strict=True):
        assert low <= value <= high
    assert result.checks[0].total_order == band.total_order  # the one check governs everywhere
    design = saltelli_design([u.distribution() for u in UNKNOWNS], n, 3,
                             [("dynamics", [0]), ("strength data", [1, 2])])
    distinct = len(np.unique(design.rows[:, 0]))
    assert result.runs == len(items) == distinct == 2 * n  # L of A or of B: 2n dynamics runs
    assert result.evaluations == sum(items) == n * (3 + 4)
    assert planned_size(n, True, result.groups, nominal=False) == (result.runs,
                                                                   result.evaluations)
    assert len(result.samples) == 2 * n


def test_without_a_dynamics_unknown_one_run_serves_every_row():
    def work(rows):  # the strength data alone, at L = 12
        rows = np.atleast_2d(rows)
        return stand_in_rows(np.column_stack([np.full(len(rows), 12.0), rows]))

    result = sample_verdicts(work, UNKNOWNS[1:], 64, indices=True,
                             nominal_row=np.array([1.9e-4, 0.12]))
    assert (result.runs, result.evaluations) == planned_size(64, True, result.groups) == (
        1, 64 * (2 + 2 + 1) + 1)
    assert math.isnan(result.governing.group_first_order[0])  # nothing of the dynamics sampled
    assert math.isfinite(result.governing.group_total_order[1])


def test_progress_and_a_checkpoint_that_stops_the_study():
    calls, seen = [], []

    def progress(done, total, elapsed):
        seen.append((done, total))
        assert elapsed >= 0

    sample_verdicts(stand_in_rows, UNKNOWNS, 8, progress=progress)
    assert seen[0] == (0, 8)
    assert seen[-1] == (8, 8)
    assert [d for d, _ in seen] == list(range(9))

    class Stop(Exception):
        pass

    def checkpoint():
        calls.append(1)
        if len(calls) == 4:
            raise Stop

    worked = []

    def work(rows):
        worked.append(1)
        return stand_in_rows(rows)

    with pytest.raises(Stop):
        sample_verdicts(work, UNKNOWNS, 8, checkpoint=checkpoint)
    assert len(worked) == 3  # stopped before the rest was taken


def test_samples_without_a_verdict_are_listed_and_left_out():
    def work(rows):
        return stand_in_rows(rows, undefined_above=16.0)

    result = sample_verdicts(work, UNKNOWNS, 64, seed=1, indices=True)
    undefined = [s for s in result.samples if s.check < 0]
    assert undefined
    assert result.undefined == len(undefined)
    assert all(s.values[0] > 16.0 and s.error.startswith("AssessmentError") for s in undefined)
    assert all(math.isnan(s.safety_factor) for s in undefined)
    assert result.governing.failure.samples == len(result.samples) - len(undefined)
    assert all(math.isfinite(x) for x in result.governing.total_order)
    json.dumps(result.as_dict(), allow_nan=False)
    with pytest.raises(VerdictUncertaintyError, match="no sample has a verdict"):
        sample_verdicts(lambda rows: stand_in_rows(rows, undefined_above=0.0), UNKNOWNS, 4)


def test_the_result_round_trips_through_json():
    result = sample_verdicts(stand_in_rows, UNKNOWNS, 16, seed=2, indices=True, resamples=50,
                             nominal_row=np.array([12.0, 1.9e-4, 0.12]), set_hash="x",
                             options={"cases": ["stand-in"]})
    data = json.loads(json.dumps(result.as_dict(), allow_nan=False))
    again = VerdictUncertainty.from_dict(data)
    assert again.as_dict() == data
    assert again.band(*CHECKS[1]).quantiles == result.checks[1].quantiles
    nominal = stand_in_factors(np.array([[12.0, 1.9e-4, 0.12]]))[0]
    assert [band.nominal for band in result.checks] == list(nominal)
    assert result.nominal_check == int(np.argmax(REQUIRED / nominal))
    assert result.governing.nominal == nominal[result.nominal_check]
    assert data["governing"]["component"] == GOVERNING
    assert set(data["governing"]["indices"]["groups"]) == {"dynamics", "strength data"}
    assert result.convergence(95.0)[-1] == (32, result.governing.quantiles[2])
    with pytest.raises(VerdictUncertaintyError, match="format"):
        VerdictUncertainty.from_dict({"format": "bogie-uncertainty-2"})
    with pytest.raises(KeyError):
        result.band("ID1 axle", "torsional_shear", "starting")


# --- the bogie -------------------------------------------------------------------------------------

STARTING = AssessmentOptions(cases=("starting",))  # a few milliseconds per dynamics run
SMALL = AssessmentOptions(s0=(0.005,), v=(120.0 * KMH,), t_end=2.0, fs=2000.0,
                          unstable_t_end=0.5, ripple_v=tuple(np.linspace(60.0, 120.0, 4) * KMH))


@pytest.fixture(scope="module")
def parameters():
    return load_parameters()


def _reassessed(parameters, result, options, tmp_path):
    """(recorded, re-assessed) governing factor and check of every listed sample, through the
    TOML files the study writes and load_parameters reads."""
    paths = save_sample_parameters(parameters, result, tmp_path)
    assert len(paths) == len(result.samples)
    pairs = []
    for sample, path in zip(result.samples, paths, strict=True):
        verdict = assess(load_parameters(path), options)
        band = result.checks[sample.check]
        pairs.append(((sample.safety_factor, band.component, band.kind, band.load_case),
                      (verdict.governing.safety_factor, verdict.governing.component,
                       verdict.governing.kind, verdict.governing.load_case)))
    return pairs


def test_a_listed_sample_reassessed_gives_its_recorded_verdict(parameters, tmp_path):
    """The starting case (fast): every listed sample's set written as TOML, read back and assessed
    gives the governing check and factor the study recorded (1e-9); the set itself, the nominal."""
    result = run_verdict_uncertainty(parameters, 4, seed=5, options=STARTING)
    assert planned_size(4, False, result.groups) == (result.runs, result.evaluations) == (5, 5)
    for recorded, again in _reassessed(parameters, result, STARTING, tmp_path):
        assert again[1:] == recorded[1:]
        assert again[0] == pytest.approx(recorded[0], rel=1e-9)
    nominal = assess(parameters, STARTING).governing
    assert result.governing.nominal == pytest.approx(nominal.safety_factor, rel=1e-9)
    assert result.checks[result.nominal_check].component == nominal.component
    text = (tmp_path / "sample_0001.toml").read_text(encoding="utf-8")
    assert "sample 1 of the verdict under uncertainty" in text
    assert "the set's value" in text
    with pytest.raises(VerdictUncertaintyError, match="another parameter set"):
        sample_parameters(parameters.replace(gear_seat_friction_min=0.11), result, 0)
    with pytest.raises(VerdictUncertaintyError, match="not listed"):
        sample_parameters(parameters, result, 4)


def test_a_listed_sample_of_all_four_cases_reassessed_gives_its_recorded_verdict(parameters,
                                                                                 tmp_path):
    """The whole assessment (short circuit, unstable adhesion, starting, ripple) on a small grid:
    dynamics, strength data and ripple amplitudes sampled together."""
    result = run_verdict_uncertainty(parameters, 2, seed=11, options=SMALL, nominal=False)
    assert {g for g in result.groups} == {"dynamics", "strength data"}
    assert "ripple_el6_amplitude" in result.names
    assert {band.load_case for band in result.checks} == {"short_circuit", "unstable_adhesion",
                                                          "starting", "ripple"}
    for recorded, again in _reassessed(parameters, result, SMALL, tmp_path):
        assert again[1:] == recorded[1:]
        assert again[0] == pytest.approx(recorded[0], rel=1e-9)


def test_rows_of_other_strength_data_reuse_the_loads(parameters, monkeypatch):
    """One work item computes the load cases once for its rows (same dynamics, different strength
    data), and each row's checks equal ``assess`` on its own set; with indices the study runs
    n (2 + d_dynamics) dynamics (plus the set's own) for n (d + 4) assessments."""
    runs = []
    original = verdict_uncertainty.dynamics_cases
    monkeypatch.setattr(verdict_uncertainty, "dynamics_cases",
                        lambda *args: runs.append(1) or original(*args))
    names = ("creep_slope", "rotor_inertia", "gear_seat_friction_min", "disc_clutch_rated_torque")
    rows = np.array([[800.0, 12.0, 0.09, 1.0e5], [800.0, 12.0, 0.15, 1.6e5],
                     [800.0, 12.0, 0.12, 1.2e5]])
    verdicts = assess_rows(rows, dict(parameters.values), names, names[:2], STARTING)
    assert len(runs) == 1
    for row, factors in zip(rows, verdicts.factors, strict=True):
        expected = assess(parameters.replace(**dict(zip(names, row, strict=True))), STARTING)
        np.testing.assert_allclose(factors, [c.safety_factor for c in expected.checks],
                                   rtol=1e-12)
    ranges = [ParameterRange(name, 0.9 * parameters[name], 1.1 * parameters[name], "test")
              for name in names]
    runs.clear()
    result = run_verdict_uncertainty(parameters, 4, options=STARTING, ranges=ranges,
                                     indices=True)
    assert result.runs == len(runs) == 4 * (2 + 2) + 1
    assert result.evaluations == 4 * (4 + 4) + 1
    assert planned_size(4, True, result.groups) == (result.runs, result.evaluations)
    with pytest.raises(ValueError, match="share their dynamics"):
        assess_rows(rows + np.array([0.0, 1.0, 0.0, 0.0]) * np.arange(3)[:, None],
                    dict(parameters.values), names, names[:2], STARTING)


def test_bad_ranges_stop_the_study_before_it_computes(parameters):
    bad = [ParameterRange("wheel_seat_friction_min", 0.16, 0.08, "upside down", log=False)]
    with pytest.raises(PriorRangeError, match="wheel_seat_friction_min"):
        run_verdict_uncertainty(parameters, 2, options=STARTING, ranges=bad,
                                checkpoint=pytest.fail)
    with pytest.raises(VerdictUncertaintyError, match="power of 2"):
        run_verdict_uncertainty(parameters, 3, options=STARTING, checkpoint=pytest.fail)


def test_the_ripple_responses_scale_exactly(parameters):
    """The sweep at 1 N m per order scaled to the set's amplitudes equals the ripple case
    computed at them, and so does the verdict on those loads."""
    options = AssessmentOptions(s0=(0.005,), ripple_v=(80.0 * KMH, 90.0 * KMH),
                                cases=("starting", "ripple"))
    cases, unit = dynamics_cases(parameters, options)
    direct = ripple_case(parameters, [*unit.names], options)
    scaled = scaled_sweep(unit, ripple_amplitudes(parameters))
    np.testing.assert_array_equal(scaled.ripple, [256.0, 128.0])
    ours = verdict_on_loads(parameters, options, cases, unit)
    theirs = assess(parameters, options)
    assert [c.safety_factor for c in ours.checks] == [c.safety_factor for c in theirs.checks]
    for name, load in direct.loads.items():
        mine = ours.cases[1].loads[name]
        np.testing.assert_array_equal(mine.alternating, load.alternating)
        np.testing.assert_array_equal(mine.by_order, load.by_order)
