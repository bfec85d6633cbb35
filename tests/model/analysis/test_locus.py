"""Root locus: the reduced, error-controlled sweep against dense solutions, branch continuity,
the speed sweep, bad input."""

from __future__ import annotations

from dataclasses import replace
from itertools import pairwise
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from model import OperatingPointError, build_model, default_operating_point, eigen_analysis, load_parameters
from model.analysis.locus import (
    clear_sweep_starts,
    dense_generalized_eigenvalues,
    pattern_coefficients,
    root_locus,
)

CONTROLLED = 1.5 * 2 * np.pi * 20.0  # |λ| inside which the tolerance is enforced [1/s]
PREVIOUS_SET = Path(__file__).resolve().parents[3] / "assets" / "parameters" / "previous_calibrated.toml"


@pytest.fixture(scope="module")
def setup():
    parameters = load_parameters()
    model = build_model(parameters)
    op = default_operating_point(parameters)
    s0 = np.linspace(0.002, 0.016, 30)
    return model, op, s0, root_locus(model, op, "s0", s0)


def test_tracked_eigenvalues_equal_dense_solution(setup):
    """Every tracked eigenvalue inside the controlled disc lies within 1e-6 (relative) of an
    eigenvalue of the dense QZ solution of eqs. (21)–(22) at the same point."""
    model, op, s0, locus = setup
    for i in range(0, len(s0), 3):
        reference = dense_generalized_eigenvalues(model, op.__class__(s0[i], op.v, op.N0, op.b_M))
        reference = reference[np.isfinite(reference)]
        for value in locus.eigenvalues[i]:
            if abs(value) < CONTROLLED:
                assert np.min(np.abs(reference - value)) <= 1e-6 * abs(value)


def test_denser_sweep_reuses_the_start_and_gives_the_same_values(setup, monkeypatch):
    """A denser sweep over the same range (the dashboard's dense locus after its coarse one)
    reuses the kept end points, basis and short sweep's solutions: it solves each of its new
    points once and none of the old ones (the reduced points between two of its points, where
    an assignment is ambiguous, are solved in addition) and gives bitwise the same eigenvalues
    as the same sweep computed from scratch."""
    import model.analysis.locus as locus_module

    model, op, _, _ = setup
    solves = []
    solve = locus_module.Reduced.solve
    monkeypatch.setattr(locus_module.Reduced, "solve",
                        lambda self, c: solves.append(c.tobytes()) or solve(self, c))
    coarse_s0 = np.linspace(0.002, 0.016, 8)
    dense_s0 = np.concatenate([np.linspace(a, b, 4)[:-1] for a, b in pairwise(coarse_s0)]
                              + [coarse_s0[-1:]])
    clear_sweep_starts()
    coarse = root_locus(model, op, "s0", coarse_s0)
    solves.clear()
    reused = root_locus(model, op, "s0", dense_s0)
    key = lambda s0: pattern_coefficients(model, op.__class__(s0, op.v, op.N0, op.b_M)).tobytes()  # noqa: E731
    old, new = ({key(s0) for s0 in grid[1:-1]}
                for grid in (coarse_s0, [s for s in dense_s0 if s not in coarse_s0]))
    assert not old & set(solves)
    assert all(solves.count(k) == 1 for k in new)
    clear_sweep_starts()
    fresh = root_locus(model, op, "s0", dense_s0)
    assert np.array_equal(reused.eigenvalues, fresh.eigenvalues)
    assert np.array_equal(reused.error_estimate, fresh.error_estimate)
    # another operating point does not reuse this start
    other = root_locus(model, op.__class__(op.s0, op.v, op.N0, 2 * op.b_M + 1.0), "s0", coarse_s0)
    assert not np.array_equal(other.eigenvalues, coarse.eigenvalues)


def test_an_ambiguous_long_step_is_carried_through_reduced_points(setup, monkeypatch):
    """The dashboard's coarse sweep (25 points over s0 = 0.001…0.02 at 120 km/h, branches up to
    20 Hz, errors relative to max(|λ|, 1 1/s)) has steps near s0 = 0.002 where branches move too
    far to be assigned unambiguously: they are carried through reduced points in between, not
    solved densely (only the two ends are), and every tracked eigenvalue inside the controlled
    disc is an eigenvalue of the dense solution within 1e-6 of max(|λ|, 1 1/s)."""
    import model.analysis.locus as locus_module

    model, op, _, _ = setup
    bridged = []
    steps = locus_module._reduced_steps
    monkeypatch.setattr(locus_module, "_reduced_steps",
                        lambda *args: bridged.append(args[3].s0) or steps(*args))
    clear_sweep_starts()
    s0 = np.linspace(0.001, 0.02, 25)
    locus = root_locus(model, op, "s0", s0, lambda_floor=1.0)
    assert bridged
    assert min(bridged) < 0.004
    assert np.flatnonzero(locus.dense_points).tolist() == [0, len(s0) - 1]
    for i in range(len(s0)):
        reference = eigen_analysis(model, replace(op, s0=float(s0[i]))).eigenvalues
        for value in locus.eigenvalues[i]:
            if abs(value) < CONTROLLED:
                assert np.min(np.abs(reference - value)) <= 1e-6 * max(abs(value), 1.0)


def test_branches_do_not_swap(setup):
    """Tracking on the coarse grid and on a grid four times finer (same start) must follow the
    same branches: a swap on either grid shows as a different eigenvalue in the same column.
    Compared: the lightly damped pairs that stay complex over the sweep (a pair that turns into
    two reals — the 0.3 Hz vehicle-yaw pair of the free car body at s0 < 0.005 — continues as
    either half; which one is not a swap)."""
    model, op, s0, coarse = setup
    fine_s0 = np.linspace(s0[0], s0[-1], 4 * (len(s0) - 1) + 1)
    fine = root_locus(model, op, "s0", fine_s0)
    first = coarse.eigenvalues[0]
    stays_complex = np.all(coarse.eigenvalues.imag != 0, axis=0) & np.all(
        fine.eigenvalues.imag != 0, axis=0)
    lightly_damped = ((np.abs(first) < CONTROLLED) & (np.abs(first.imag) > 3 * np.abs(first.real))
                      & stays_complex)
    difference = np.abs(fine.eigenvalues[::4] - coarse.eigenvalues)[:, lightly_damped]
    assert np.all(difference <= 1e-5 * np.abs(coarse.eigenvalues[:, lightly_damped]))


def test_conjugate_closed(setup):
    """The branches that start as complex pairs stay conjugate pairs.  (A branch that starts
    real may meet another real eigenvalue, tracked or not, and continue as one half of a new
    pair; that branch is checked against the dense solution like every other.)"""
    _, _, _, locus = setup
    first = locus.eigenvalues[0]
    paired = np.abs(first.imag) > 1e-9 * np.abs(first)
    for row in locus.eigenvalues[:, paired]:
        row = row[np.abs(row) < CONTROLLED]
        assert np.allclose(np.sort_complex(row), np.sort_complex(row.conj()), rtol=1e-8, atol=1e-8)


def test_locus_crosses_into_instability_at_the_limit(setup):
    _, _, s0, locus = setup
    unstable = s0[~locus.stable]
    assert locus.stable[0]
    assert not locus.stable[-1]
    assert 0.0075 < unstable.min() < 0.0095  # the crossing near s0* = 0.0082 (test_literature)


def test_speed_sweep(setup):
    model, op, _, _ = setup
    v = np.linspace(60, 200, 8) / 3.6
    locus = root_locus(model, op, "v", v)
    assert locus.eigenvalues.shape[0] == 8
    reference = dense_generalized_eigenvalues(model, op.__class__(op.s0, v[-1], op.N0, op.b_M))
    value = locus.eigenvalues[-1][np.argmax(locus.eigenvalues[-1].real)]
    assert np.min(np.abs(reference[np.isfinite(reference)] - value)) <= 1e-6 * abs(value)


@pytest.mark.parametrize(("parameter", "values", "error"), [
    ("N0", [1e5, 2e5], ValueError),
    ("s0", [0.005], ValueError),
    ("s0", [0.005, np.nan], ValueError),
    ("s0", [0.005, 1.5], OperatingPointError),
    ("v", [10.0, -1.0], OperatingPointError),
])
def test_bad_input(setup, parameter, values, error):
    model, op, _, _ = setup
    with pytest.raises(error):
        root_locus(model, op, parameter, values)


def test_a_floor_keeps_the_sweep_reduced_through_a_zero_eigenvalue():
    """The dashboard's sweep (s0 = 0.001…0.02 at 151 km/h) passes a drivetrain spin through
    λ = 0 at the creep maximum s0_max (b11 = 0: the spin meets no damping there): relative to
    |λ| its error cannot be controlled near there, and each point there was solved densely.  With
    ``lambda_floor`` the errors are measured relative to max(|λ|, floor): fewer dense points, and
    at every point of the sweep each tracked eigenvalue inside the controlled disc is an
    eigenvalue of the deflated dense solution (``eigen_analysis``, without the rigid-body λ = 0
    that the spin's vector shares) within 1e-5·max(|λ|, 1 1/s) (the estimate is conservative;
    rtol 1e-6).

    The points near the crossing are placed by the creep law, within 10⁻⁴·s0_max of the creep
    maximum (b11 = 0, solved for), so that the spin's |λ| is small there whatever the parameter
    set: how fast it moves with s0 follows the creep slope's fall, which a calibration changes
    (a fixed band that held |λ| ≤ 0.06 1/s with one set held |λ| ≥ 0.06 1/s with the next,
    and every point of it stayed reduced without a floor).  None lies on s0_max itself: there
    the spin is a double zero (its position a rigid-body mode, its velocity undamped), whose
    first-order error estimate has nothing to divide by, and that one point is solved densely
    with or without a floor.

    The set is assets/parameters/previous_calibrated.toml, whose points near the crossing are
    solved densely without a floor; on the bundled set they stay reduced with or without one (its
    spin's error estimate near the crossing stays within the tolerance), so the floor's effect
    cannot be seen there."""
    parameters = load_parameters(PREVIOUS_SET)
    model = build_model(parameters)
    op = replace(default_operating_point(parameters), v=151.0 / 3.6)
    s0_max = brentq(lambda s: pattern_coefficients(model, replace(op, s0=s))[0], 0.001, 0.02,
                    xtol=1e-12)
    s0 = np.concatenate([np.linspace(0.001, 0.9 * s0_max, 8),
                         s0_max * (1 + 1e-4 * np.linspace(-1, 1, 8)),
                         np.linspace(1.1 * s0_max, 0.02, 8)])
    clear_sweep_starts()
    plain = root_locus(model, replace(op, s0=s0[0]), "s0", s0)
    clear_sweep_starts()
    floored = root_locus(model, replace(op, s0=s0[0]), "s0", s0, lambda_floor=1.0)
    clear_sweep_starts()
    assert floored.lambda_floor == 1.0
    assert plain.lambda_floor == 0.0
    assert floored.dense_points.sum() < plain.dense_points.sum(), (
        plain.dense_points, floored.dense_points)
    for i, s0_i in enumerate(s0):
        reference = eigen_analysis(model, replace(op, s0=s0_i), vectors=False).eigenvalues
        for value in floored.eigenvalues[i]:
            if abs(value) < CONTROLLED:
                assert np.min(np.abs(reference - value)) <= 1e-5 * max(abs(value), 1.0), (
                    s0_i, value)


def test_the_reduced_model_deflates_its_zeros_as_the_dense_solve():
    """The reduced model deflates its exact zeros as the dense solve does: the rigid-body modes
    and the free rolling velocity, whose Jordan chain, left in the reduced eigenproblem, splits
    under rounding into a pair of size ≈ 1e-5 1/s.  Just below the creep maximum at 151 km/h
    (b11 = 0, solved for), where the drivetrain spin's eigenvalue is smaller than that, the kept
    sweep's reduced model has a single Ritz value below 1e-3 1/s, real, the spin's: within
    1e-9 1/s of the dense eigenvalue (without the deflation, dropping the five Ritz values
    nearest to zero left in the spin's place a spurious one of the split pair's size, here of
    the opposite sign)."""
    from model.analysis.locus import kept_sweep_estimate

    parameters = load_parameters()
    model = build_model(parameters)
    op = replace(default_operating_point(parameters), v=151.0 / 3.6)
    s0_max = brentq(lambda s: pattern_coefficients(model, replace(op, s0=s))[0], 0.001, 0.02,
                    xtol=1e-14)
    ends = [replace(op, s0=0.001), replace(op, s0=0.02)]
    clear_sweep_starts()
    root_locus(model, ends[0], "s0", np.linspace(0.001, 0.02, 6), lambda_floor=1.0)
    point = replace(op, s0=s0_max * (1 - 1e-6))
    estimate = kept_sweep_estimate(model, point, *ends, lambda_floor=1.0)
    clear_sweep_starts()
    exact = eigen_analysis(model, point, vectors=False).eigenvalues
    spin = exact[np.argmin(np.abs(exact))]
    assert abs(spin) < 1e-3  # the spin is the only eigenvalue this close to zero
    near_zero = estimate.eigenvalues[np.abs(estimate.eigenvalues) < 1e-3]
    assert near_zero.shape == (1,), near_zero
    assert near_zero[0].imag == 0.0
    assert abs(near_zero[0] - spin) <= 1e-9, (near_zero[0], spin)


def test_a_negative_floor_is_refused():
    parameters = load_parameters()
    model = build_model(parameters)
    with pytest.raises(ValueError, match="lambda_floor"):
        root_locus(model, default_operating_point(parameters), "s0", [0.005, 0.006],
                   lambda_floor=-1.0)


def test_a_kept_sweep_estimates_other_points_without_a_dense_solve(setup):
    """The reduced model of a kept sweep (over s0 at 120 km/h) gives the eigenvalues at points
    off the sweep — another creepage, speed, wheel force or motor slope — with no dense
    eigendecomposition; each Ritz value inside the disc lies within its own error estimate (plus
    1e-9 1/s) of an eigenvalue of the deflated dense solution, and the verdict, where the estimates
    decide it, is the dense one's.  A sweep that is not kept gives None."""
    from model.analysis.linear_system import dense_decompositions
    from model.analysis.locus import kept_sweep_estimate

    model, op, _, _ = setup
    ends = [replace(op, s0=0.001), replace(op, s0=0.02)]
    clear_sweep_starts()
    assert kept_sweep_estimate(model, op, *ends, lambda_floor=1.0) is None
    root_locus(model, ends[0], "s0", np.linspace(0.001, 0.02, 6), lambda_floor=1.0)
    decided = 0
    for point in (replace(op, s0=0.0079), replace(op, s0=0.0095), replace(op, v=150 / 3.6),
                  replace(op, N0=1.2 * op.N0), replace(op, b_M=3 * op.b_M + 500.0)):
        before = dense_decompositions()
        estimate = kept_sweep_estimate(model, point, *ends, lambda_floor=1.0)
        assert dense_decompositions() == before, point
        exact = eigen_analysis(model, point, vectors=False)
        assert estimate.basis_size > 0
        assert estimate.eigenvalues.size > 0
        for value, bound in zip(estimate.eigenvalues, estimate.absolute_error, strict=True):
            assert np.min(np.abs(exact.eigenvalues - value)) <= bound + 1e-9, (point, value)
        if estimate.stable is not None:
            decided += 1
            assert estimate.stable == exact.stable, point
    assert decided >= 4  # the estimates are small enough to decide away from the limit
    assert dense_decompositions() > before  # the counter counts (the reference solves above)
    clear_sweep_starts()
