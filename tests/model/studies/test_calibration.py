"""Unit tests of the calibration's pieces (model/studies/calibration.py) — not of the calibrated numbers
(those are tests/literature/test_table1.py), and without running the whole calibration (a minute or
two; its reproducibility is checked by scripts/bench_calibration.py, BENCHMARKS.md)."""

from __future__ import annotations

import numpy as np
import pytest

from model import load_parameters
from model.mechanics.parameters import ESTIMATE_FILE
from model.studies.calibration import (
    Weights,
    _bounds,
    _evaluate_j,
    _from_x,
    _jacobian_j,
    _to_x,
    calibrate,
    fit_operating_data,
    real_part_residual,
)
from model.studies.calibration_bounds import CREEP_SHAPE_PARAMETERS, SEARCH_PARAMETERS, with_constraints
from model.studies.calibration_targets import operating_rows


def test_stage_a_meets_the_operating_data_for_another_creep_shape():
    """(μ0, A, B, p) are solved for M(0.005) = M(0.014) = 12 800 N m, M_ad and the creep maximum
    at 0.0082 for a creep shape the search proposes (not every shape allows it within the bounds
    of μ0, A, B, p: stage J keeps the operating data as residuals for that case)."""
    start = load_parameters(ESTIMATE_FILE).replace(polach_kA=0.7, polach_kS=0.3)
    fitted = fit_operating_data(start)
    for row in operating_rows(fitted):
        assert abs(row.error) < 1e-6, row
    assert (fitted["polach_kA"], fitted["polach_kS"]) == (0.7, 0.3)  # the shape is kept


def test_real_part_residual_is_one_at_the_acceptance():
    assert real_part_residual(-3.958 * 1.3, -3.958) == pytest.approx(1.0)
    assert real_part_residual(-3.958 / 1.3, -3.958) == pytest.approx(-1.0)
    assert real_part_residual(-0.032 - 0.05, -0.032) == pytest.approx(-1.0)  # |Re| < 0.2: 0.05
    assert abs(real_part_residual(+0.5, -3.958)) > 3  # wrong sign: linear, large


# the parameters of the finite-difference check: a creep-shape parameter (its stage-A
# dependence), a stiffness, an inertia, a damper, the Maxwell element's series stiffness, the
# motor slope (its operating-point row is linked) and a height (searched on its value)
CHECKED = ("polach_kA", "creep_slope", "primary_stiffness_x", "frame_inertia_y",
           "secondary_damping_z", "yaw_damper_series_stiffness", "motor_slope",
           "traction_link_height")


@pytest.fixture(scope="module")
def stage_j_point():
    start = fit_operating_data(with_constraints(load_parameters(ESTIMATE_FILE)))
    free = tuple(f for f in SEARCH_PARAMETERS if f.name in CHECKED)
    low, high = _bounds(free)
    x = np.clip(_to_x(start, free), low + 0.05 * (high - low), high - 0.05 * (high - low))
    return start, free, x


def test_stage_j_jacobian_matches_finite_differences(stage_j_point):
    """The analytic Jacobian (eigenvalue sensitivities of model/analysis/sensitivity.py, stage A's
    implicit dependence on the creep shape) against central differences of the residuals with
    a step of 5e-4 in x (log or value) — the characters stay assigned to the same modes over
    the step (checked).  Acceptance 1e-3 of each row's scale (below): the differences' own
    error is ~1e-6."""
    start, free, x = stage_j_point
    weights = Weights()
    e = _evaluate_j(x, start, free, x, weights)
    J = _jacobian_j(e, start, free)
    h = 5e-4  # truncation O(h²) ~1e-6 relative (at 1e-3 it reached 1.2e-3 of a row's scale for
    # the primary guide with the hardware-range vertical dampers of the estimate); at 1e-5 the
    # residuals' rounding (~2e-10 from the eigenvalues and stage A) over 2h already shows
    # (measured on the frame bounce: 1e-3)
    # the operating data rows: stage A meets them to its solver's tolerance (~1e-12) here, so
    # they and their derivatives are rounding (differences of noise); checked to be ~0 instead
    operating = np.array([kind == "operating" for kind, *_ in e.terms])
    assert np.abs(e.residual[operating]).max() < 1e-6
    checked_rows = np.array([kind not in ("none", "prior", "constraint", "operating")
                             for kind, *_ in e.terms])
    for j, f in enumerate(free):
        up, down = x.copy(), x.copy()
        up[j] += h
        down[j] -= h
        e_up, e_down = (_evaluate_j(z, start, free, x, weights) for z in (up, down))
        for other in (e_up, e_down):  # the same modes hold the characters (not their indices:
            # LAPACK may order the eigenvalues differently after a perturbation)
            for k, i in e.characters.items():
                moved = other.results[0.005].eigenvalues[other.characters[k]]
                assert abs(moved - e.results[0.005].eigenvalues[i]) < 0.01 * abs(moved), f.name
        column = (e_up.residual - e_down.residual) / (2 * h)
        # residuals are scaled to O(1) at their acceptance: a derivative below 0.01 per unit of
        # x is negligible, and there the differences' rounding (stage A re-solved to 1e-12)
        # dominates, so each row's error is relative to max(its largest entry, 0.01)
        scale = np.maximum(np.abs(J[checked_rows]).max(axis=1), 0.01)
        error = np.abs(J[checked_rows, j] - column[checked_rows]) / scale
        assert error.max() <= 1e-3, (f.name, error.max())
    assert any(f.name in {g.name for g in CREEP_SHAPE_PARAMETERS} for f in free)


def test_stage_j_residual_has_a_fixed_length_and_its_terms(stage_j_point):
    """The residual's length does not depend on how many pairs sit below the cut (fixed slots:
    the least squares needs one length); each Table 2 character has its frequency term."""
    start, free, x = stage_j_point
    e = _evaluate_j(x, start, free, x)
    kinds = [kind for kind, *_ in e.terms]
    assert kinds.count("logf") == 11  # ten characters and the driving-shaft mode
    assert kinds.count("operating") == 4
    assert len(e.residual) == len(_evaluate_j(x + 0.01, start, free, x).residual)
    assert set(e.characters) == set(range(10))


@pytest.mark.slow
def test_calibration_is_deterministic_and_keeps_its_bounds():
    """Two runs of stages A and J on small budgets give the same set, bit for bit, and stage J
    keeps every parameter within its bounds (the full run: scripts/bench_calibration.py)."""
    from threadpoolctl import threadpool_limits

    start = load_parameters(ESTIMATE_FILE)
    phases = ((3, Weights(order=0.0, real=0.0, divergence=0.0)), (3, Weights()))
    with threadpool_limits(1):
        a, _ = calibrate(start, lambda _: None, phases)
        b, _ = calibrate(start, lambda _: None, phases)
    assert a.values == b.values
    for f in SEARCH_PARAMETERS:
        assert f.low - 1e-12 * abs(f.low) <= a[f.name] <= f.high + 1e-12 * abs(f.high), f.name
    assert _from_x(_to_x(a, SEARCH_PARAMETERS), a, SEARCH_PARAMETERS).values == pytest.approx(
        a.values)
