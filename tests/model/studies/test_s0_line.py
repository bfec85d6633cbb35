"""One s0-line (model/studies/s0_line.py) against the dense reference point by point, s0* against
the stability limit's own search, the reduced basis's check and fallback, the point at the
crossing."""

from __future__ import annotations

import numpy as np
import pytest

from model import KMH, build_model, load_parameters, stability_limit
from model.studies.s0_line import dense_line, s0_line

# largest real part: the error-controlled Ritz values are within rtol·max(|λ|, 1 1/s) = 1e-6 x
# |λ| ≤ 2π·60 Hz of the dense solution (measured: 3e-9 1/s); 1e-5 1/s leaves room for it
GROWTH_ATOL = 1e-5
# s0*: both searches stop within xtol = 1e-6 of the crossing, so they differ by at most 2e-6
LIMIT_ATOL = 2e-6


@pytest.fixture(scope="module")
def setup():
    parameters = load_parameters()
    return parameters, build_model(parameters)


@pytest.mark.parametrize(("v_kmh", "n0_factor", "b_M", "method"), [
    pytest.param(50.0, 1.0, None, "reduced", marks=pytest.mark.slow),
    (160.0, 1.0, None, "reduced"), (160.0, 1.0, None, "continuation"),
    pytest.param(240.0, 0.6, 0.0, "reduced", marks=pytest.mark.slow),
    pytest.param(50.0, 1.0, None, "continuation", marks=pytest.mark.slow),
    pytest.param(240.0, 0.6, 0.0, "continuation", marks=pytest.mark.slow)])
def test_line_equals_dense_reference(setup, v_kmh, n0_factor, b_M, method):
    """Every point of an s0-line (largest real part, flutter pairs, divergent reals, verdict) as a
    full eigen-analysis gives it, across the stability limit; s0* as on the dense grid; both
    methods of s0_line (the continuation, the reduced model)."""
    parameters, model = setup
    N0 = parameters["wheel_force"] * n0_factor
    b_M = parameters["motor_slope"] if b_M is None else b_M
    s0 = np.linspace(0.001, 0.02, 17)
    line = s0_line(model, s0, v_kmh * KMH, N0, b_M, method=method)
    reference = dense_line(model, s0, v_kmh * KMH, N0, b_M)
    assert line.method == method
    assert np.count_nonzero(line.dense_points) < len(s0)  # the reduced model did the work
    np.testing.assert_allclose(line.largest_real_part, reference.largest_real_part, rtol=0,
                               atol=GROWTH_ATOL)
    np.testing.assert_array_equal(line.flutter_pairs, reference.flutter_pairs)
    np.testing.assert_array_equal(line.divergent_real, reference.divergent_real)
    np.testing.assert_array_equal(line.stable, reference.stable)
    assert line.stable[0]
    assert not line.stable[-1]
    assert abs(line.s0_limit - reference.s0_limit) <= LIMIT_ATOL
    if method == "reduced":
        assert line.basis_size > 0
        assert line.outside_max_real_part < -5.0  # outside the basis: damped at the ends
    else:
        # grid points solved densely: the first anchor and the fallbacks there (s0* may add more)
        assert line.fallbacks >= np.count_nonzero(line.dense_points) - 1


def test_reduced_basis_falls_back_to_both_ends_when_a_check_fails(setup, monkeypatch):
    """The reduced line's basis is the last creepage's eigenvectors and creep responses; when the
    dense eigenvalues at the first or the steepest creepage have no Ritz value next to them, it
    falls back to the exact eigenvectors at both ends.  With the check made impossible (MATCH = 0)
    the fallback runs: a larger basis, and every point still as the dense reference gives it."""
    import model.studies.s0_line as study

    parameters, model = setup
    N0, b_M = parameters["wheel_force"], parameters["motor_slope"]
    s0 = np.linspace(0.001, 0.02, 17)
    v = 160 * KMH
    reference = dense_line(model, s0, v, N0, b_M)
    normal = s0_line(model, s0, v, N0, b_M)
    monkeypatch.setattr(study, "MATCH", 0.0)
    fallback = s0_line(model, s0, v, N0, b_M)
    assert fallback.basis_size > normal.basis_size
    for line in (normal, fallback):
        np.testing.assert_allclose(line.largest_real_part, reference.largest_real_part, rtol=0,
                                   atol=GROWTH_ATOL)
        np.testing.assert_array_equal(line.flutter_pairs, reference.flutter_pairs)
        np.testing.assert_array_equal(line.divergent_real, reference.divergent_real)


def test_line_limit_equals_stability_limit(setup):
    """s0* of a line (Brent on the reduced evaluation) against model.analysis.stability.stability_limit
    (bracket doubling and Brent on dense eigen-analyses)."""
    parameters, model = setup
    v = 120 * KMH
    line = s0_line(model, np.linspace(0.002, 0.016, 8), v, parameters["wheel_force"],
                   parameters["motor_slope"])
    limit = stability_limit(model, v, parameters["wheel_force"], parameters["motor_slope"],
                            xtol=1e-7)
    assert abs(line.s0_limit - limit.s0_limit) <= LIMIT_ATOL


def test_basis_check_at_the_most_destabilizing_point(setup):
    """The reduced line's basis comes from the two ends; at the creepage of the most negative
    b11 the dense eigenvalues check it: with both ends every eigenvalue the selection takes there
    has a Ritz value next to it, with the first end alone (the rim modes that the falling creep
    slope destabilizes are damped by more than 5 1/s at the first end and not in its basis) some
    have none and the check fails.

    The line runs from s0 = 0.001 to twice the creepage of the steepest fall of the creep slope
    (b11's minimum, solved for), so that the most negative b11 lies inside it and not at an end:
    where that fall is steepest is a matter of the creep law (at 120 km/h a calibrated set had
    it inside 0.001…0.02, the next one beyond 0.02, where the range's most negative b11 is its
    last point, itself an end of the basis)."""
    from scipy.optimize import minimize_scalar

    from model.analysis.reduced_model import pattern_coefficients
    from model.mechanics.operating_point import OperatingPoint
    from model.studies.s0_line import _dense_point, _LineModel, _missing_modes

    parameters, model = setup
    v, N0, b_M = 120 * KMH, parameters["wheel_force"], parameters["motor_slope"]
    steepest = minimize_scalar(
        lambda s: pattern_coefficients(model, OperatingPoint(float(s), v, N0, b_M))[0],
        bounds=(0.001, 0.2), method="bounded", options={"xatol": 1e-7}).x
    s0 = np.linspace(0.001, 2 * steepest, 100)
    points = [OperatingPoint(float(s), v, N0, b_M) for s in s0]
    b11 = [pattern_coefficients(model, op)[0] for op in points]
    middle = int(np.argmin(b11))
    assert 0 < middle < len(s0) - 1
    c = pattern_coefficients(model, points[middle])
    eigenvalues = _dense_point(model, points[middle]).eigenvalues
    radius = 2 * np.pi * 10.0
    ends = [_dense_point(model, points[i], vectors=True) for i in (0, len(s0) - 1)]
    both = _LineModel(model, v, N0, b_M, ends, 10.0, 1e-6)
    first = _LineModel(model, v, N0, b_M, ends[:1], 10.0, 1e-6)
    assert not _missing_modes(eigenvalues, both.ritz_values(c), radius)
    assert _missing_modes(eigenvalues, first.ritz_values(c), radius)


def test_line_limit_few_evaluations(setup, monkeypatch):
    """s0* of a reduced line takes at most 8 reduced evaluations (secant steps on the crossing
    branch, bracket closed within xtol; Brent's method from the grid bracket took 9-12) and
    agrees with the dense line's Brent search within both tolerances."""
    import model.studies.s0_line as study

    parameters, model = setup
    calls = []
    point = study._LineModel.point

    def counted(self, s0, c=None):
        calls.append(s0)
        return point(self, s0, c)

    s0 = np.linspace(0.001, 0.02, 40)
    v, N0, b_M = 250 * KMH, parameters["wheel_force"], parameters["motor_slope"]
    monkeypatch.setattr(study._LineModel, "point", counted)
    line = s0_line(model, s0, v, N0, b_M)
    monkeypatch.undo()
    grid_calls = len(s0) - np.count_nonzero(line.dense_points)
    assert len(calls) - grid_calls <= 8
    reference = dense_line(model, s0, v, N0, b_M)
    assert abs(line.s0_limit - reference.s0_limit) <= LIMIT_ATOL


def test_point_at_the_crossing_needs_no_full_analysis(setup):
    """At s0* the crossing eigenvalue is real and ≈ 0, next to the rigid-body zeros: its Newton
    refinement divides the rigid rows by λ and converges; the point is not sent to a full
    eigen-analysis, and its largest real part is the dense one within rtol = 1e-6 1/s."""
    from model.analysis.eigen import eigen_analysis
    from model.analysis.reduced_model import pattern_coefficients
    from model.mechanics.operating_point import OperatingPoint
    from model.studies.s0_line import _dense_point, _LineModel

    parameters, model = setup
    v, N0, b_M = 250 * KMH, parameters["wheel_force"], parameters["motor_slope"]
    reference = dense_line(model, np.linspace(0.001, 0.02, 17), v, N0, b_M)
    s0_limit = reference.s0_limit
    ends = [_dense_point(model, OperatingPoint(s, v, N0, b_M), vectors=True)
            for s in (0.001, 0.02)]
    line_model = _LineModel(model, v, N0, b_M, ends, 10.0, 1e-6)
    for s in (s0_limit - 2e-7, s0_limit + 2e-7):
        op = OperatingPoint(s, v, N0, b_M)
        (growth, _, _), dense = line_model.point(s, pattern_coefficients(model, op))
        assert not dense
        dense_growth = eigen_analysis(model, op, vectors=False).max_real_part
        assert abs(growth) < 1e-2  # the crossing eigenvalue: ≈ 0
        assert abs(growth - dense_growth) <= 1e-6
