"""The exact continuation of all eigenvalues along s0 (model.analysis.continuation) against a full
eigen-analysis (model.analysis.eigen.eigen_analysis) at every point: all eigenvalues, the largest real
part, flutter pairs and divergent reals, s0*; the rank-4 structure it rests on; its checks
catch a lost or wrong root.  Real components, no mocks.

Tolerances.  Both sides carry rounding errors of the order of eps·‖A‖·cond(λ): ‖A‖ ≈ 3·10⁵ 1/s
(|λ| up to 3·10⁵ 1/s), so the two computations of one eigenvalue differ by more than eps·|λ|.
Measured on 100-point lines at 40, 120 and 250 km/h (the set calibrated by rank): at
most 2.6·10⁻⁸ / 1.9·10⁻⁸ / 1.5·10⁻⁸ relative to max(|λ|, 1 1/s), at the ill-conditioned
near-twin eigenvalues (the ID1/ID2 twins near 3·10⁵ 1/s, closer on this set than on the previous
one, which gave at most 6.5·10⁻⁹), largest real part within 3.4·10⁻⁹ 1/s.  EIG_RTOL = 8·10⁻⁸
and GROWTH_ATOL = 10⁻⁷ 1/s leave a factor 3 and 30 to these.  s0*: both
searches stop within xtol = 10⁻⁶, so they differ by at most 2·10⁻⁶.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment

from model import KMH, build_model, eigen_analysis, load_parameters
from model.analysis.continuation import (
    Continuation,
    continue_line,
    creep_coefficient,
    make_anchor,
    update_vectors,
)
from model.analysis.eigen import rigid_zero_count, state_matrix
from model.mechanics.operating_point import OperatingPoint
from model.studies.s0_line import dense_line, s0_line, spectrum_summary

EIG_RTOL = 8e-8
GROWTH_ATOL = 1e-7
LIMIT_ATOL = 2e-6


@pytest.fixture(scope="module")
def setup():
    parameters = load_parameters()
    return parameters, build_model(parameters)


def _worst_relative(a: np.ndarray, b: np.ndarray) -> float:
    """Largest |a_i − b_π(i)| / max(|b|, 1) over the optimal matching π of two spectra."""
    assert a.shape == b.shape
    cost = np.abs(a[:, None] - b[None, :])
    rows, cols = linear_sum_assignment(cost)
    return float((cost[rows, cols] / np.maximum(np.abs(b[cols]), 1.0)).max())


def test_state_matrix_is_a_rank4_update_along_s0(setup):
    """A(s0_b) = A(s0_a) + (b11(s0_b) − b11(s0_a)) U Vᵀ: s0 enters only through b11."""
    parameters, model = setup
    v, N0, b_M = 120 * KMH, parameters["wheel_force"], parameters["motor_slope"]
    a, b = OperatingPoint(0.002, v, N0, b_M), OperatingPoint(0.015, v, N0, b_M)
    U, V = update_vectors(model)
    A_a, A_b = state_matrix(model, a), state_matrix(model, b)
    update = (creep_coefficient(model, b) - creep_coefficient(model, a)) * (U @ V.T)
    n = model.n
    damping = np.abs(A_b[n:, n:]).max()  # the −M⁻¹B block [1/s]
    assert np.array_equal(A_b[:, :n], A_a[:, :n])
    assert np.array_equal(A_b[:n], A_a[:n])
    assert np.abs(A_b - A_a - update).max() <= 1e-12 * damping
    # and the update is not negligible: 566 1/s here, 6.5e-4 of the largest damping entry (the
    # rubber loss of light parts; the creep's own scale is N0 μ'/v over a rim's mass)
    assert np.abs(update).max() > 1e-4 * damping


@pytest.mark.parametrize(("v_kmh", "points"), [
    (120.0, 25),  # crosses s0*
    pytest.param(40.0, 100, marks=pytest.mark.slow),
    pytest.param(120.0, 100, marks=pytest.mark.slow),
    pytest.param(250.0, 100, marks=pytest.mark.slow)])
def test_line_equals_dense_at_every_point(setup, v_kmh, points):
    """Every eigenvalue at every point of an s0-line, and the summary (largest real part,
    flutter pairs, divergent reals) as a full eigen-analysis gives them."""
    parameters, model = setup
    v, N0, b_M = v_kmh * KMH, parameters["wheel_force"], parameters["motor_slope"]
    s0 = np.linspace(0.001, 0.02, points)
    line = continue_line(model, s0, v, N0, b_M)
    assert line.fallbacks < points // 4  # the continuation did most of the work
    assert np.count_nonzero(~line.dense_points) >= points - points // 4 - 1
    stable = []
    for i, s in enumerate(s0):
        dense = eigen_analysis(model, OperatingPoint(float(s), v, N0, b_M),
                               vectors=False).eigenvalues
        assert _worst_relative(line.spectra[i], dense) <= EIG_RTOL
        ours, reference = spectrum_summary(line.spectra[i]), spectrum_summary(dense)
        assert abs(ours[0] - reference[0]) <= GROWTH_ATOL
        assert ours[1:] == reference[1:]
        stable.append(reference[0] <= 0)
    if v_kmh == 120.0:  # the line crosses the stability limit
        assert stable[0]
        assert not stable[-1]


def test_s0_line_limit_equals_dense(setup):
    """s0* by Brent on the continuation against Brent on full eigen-analyses."""
    parameters, model = setup
    v, N0, b_M = 120 * KMH, parameters["wheel_force"], parameters["motor_slope"]
    s0 = np.linspace(0.004, 0.016, 13)
    line = s0_line(model, s0, v, N0, b_M, method="continuation")
    reference = dense_line(model, s0, v, N0, b_M)
    assert line.method == "continuation"
    np.testing.assert_allclose(line.largest_real_part, reference.largest_real_part, rtol=0,
                               atol=GROWTH_ATOL)
    np.testing.assert_array_equal(line.flutter_pairs, reference.flutter_pairs)
    np.testing.assert_array_equal(line.divergent_real, reference.divergent_real)
    assert np.isfinite(line.s0_limit)
    assert abs(line.s0_limit - reference.s0_limit) <= LIMIT_ATOL


def test_checks_catch_lost_and_wrong_roots(setup):
    """The certified roots pass; one root found twice, a large root moved by 10⁻³ of itself
    (trace identity) and a small one moved by 10⁻³ (inverse-trace identity) fail.  The reference
    is the full state matrix's spectrum without its exact zeros: one per rigid-body mode and one
    for the velocity of the vehicle rolling without slip, which no damping meets
    (``rigid_zero_count``; the continuation deflates the same)."""
    parameters, model = setup
    v, N0, b_M = 120 * KMH, parameters["wheel_force"], parameters["motor_slope"]
    anchor = make_anchor(model, OperatingPoint(0.006, v, N0, b_M))
    continuation = Continuation(anchor)
    tracked = continuation.start()
    c = creep_coefficient(model, OperatingPoint(0.0062, v, N0, b_M))
    mu, step, local, _ = continuation.solve(c, continuation.predictor(c - anchor.c_ref,
                                                                       tracked))
    assert continuation.check(c, mu, step, local, tracked) is None
    # the reference: the roots are the eigenvalues of the full model at that b11
    U, V = update_vectors(model)
    A = state_matrix(model, anchor.operating_point) + (c - anchor.c_ref) * (U @ V.T)
    dense = np.linalg.eigvals(A)
    dense = dense[np.argsort(np.abs(dense))[rigid_zero_count(model):]]
    assert _worst_relative(np.concatenate([mu, mu[tracked.mirrored].conj()]), dense) <= EIG_RTOL

    gap = np.abs(mu[:, None] - mu[None, :]) + np.diag(np.full(len(mu), np.inf))
    isolated = gap.min(axis=1) > 1e-3 * np.abs(mu)
    single = np.flatnonzero(~tracked.mirrored & (np.abs(mu) > 10) & isolated)
    i, j = single[0], single[1]  # two real roots with no other root near
    twice = mu.copy()
    twice[j] = twice[i]
    assert "one value" in continuation.check(c, twice, step, local, tracked)
    # real roots moved without a neighbour: only the traces see it
    candidates = np.flatnonzero(isolated & ~tracked.mirrored)
    big = int(candidates[np.argmax(np.abs(mu[candidates]))])
    moved = mu.copy()
    moved[big] *= 1 + 1e-3
    assert "trace identity" in continuation.check(c, moved, step, local, tracked)
    small = int(candidates[np.argmin(np.abs(mu[candidates]))])
    moved = mu.copy()
    moved[small] *= 1 + 1e-3
    assert "inverse-trace" in continuation.check(c, moved, step, local, tracked)
