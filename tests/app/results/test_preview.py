"""The preview of a dragged slider (app.results.preview): its verdict against the eigen-analysis
at every creepage step across the limit, its sources, and that it never runs a dense
eigendecomposition."""

from __future__ import annotations

import numpy as np
import pytest

from app.results import compute, preview
from app.results.case import Case
from model import eigen_analysis
from model.analysis.linear_system import dense_decompositions

SET, RAIL, V_KMH = "", "calibrated", 120.0
S0_STEP = 0.0001  # the dashboard's s0 slider step [-]


@pytest.fixture(scope="module")
def known():
    """The dense root locus over s0 and s0*(v) at 120 km/h, as the dashboard has them once its
    follow-ups are done: (N0 [kN], b_M [N m s/rad], locus key, s0*)."""
    p = compute.parameters(SET, RAIL)
    N0, b_M = round(p["wheel_force"] / 1e3, 3), round(p["motor_slope"], 3)
    key = _point(0.005, V_KMH, N0, b_M).sweep("s0")
    # computed here, not taken from the cache an earlier test module of this process filled: the
    # sweep's reduced model is kept for the last few sweeps only (model.analysis.locus), and a
    # locus cached long ago may have lost it (the preview then says "not computed yet")
    compute.RESULTS.drop("locus")
    compute.RESULTS.drop("dense locus")
    compute.dense_locus_result(key)
    limit = compute.limit_result(key.at(0.005))
    return N0, b_M, key, limit.s0_limit


def _point(s0: float, v: float, N0: float, b_M: float, rail: str = RAIL) -> Case:
    """The operating point (s0 [-], v [km/h], N0 [kN], b_M [N m s/rad]) of the set in use."""
    return Case(set_key=SET, rail=rail, s0=s0, v=v, N0=N0, b_M=b_M)


def _exact_stable(point: Case) -> bool:
    op = point.operating_point()
    return eigen_analysis(compute.model(SET, RAIL), op, vectors=False).stable


@pytest.mark.slow
def test_the_verdict_across_the_limit_is_the_eigen_analysis_one(known):
    """Every s0 step from 0.005 to 0.012 at 120 km/h: the preview's verdict equals the dense
    eigen-analysis's (no step excepted; the limit is known exactly), from s0*(v) below it and
    from the root locus above; no dense eigendecomposition is run for the 71 previews."""
    N0, b_M, key, s0_limit = known
    assert 0.005 < s0_limit < 0.012
    grid = np.round(np.arange(0.005, 0.012 + S0_STEP / 2, S0_STEP), 7)
    before = dense_decompositions()
    previews = [preview.preview(_point(float(s0), V_KMH, N0, b_M), key, "s0") for s0 in grid]
    assert dense_decompositions() == before
    for s0, result in zip(grid, previews, strict=True):
        assert result.stable == _exact_stable(_point(float(s0), V_KMH, N0, b_M)), s0
        # (a point another test computed in this process is known exactly)
        assert result.source in ((preview.BELOW_LIMIT, preview.EXACT) if s0 < s0_limit
                                 else (preview.ABOVE_LIMIT, preview.LOCUS, preview.EXACT)), s0
        assert result.s0_limit == s0_limit
        assert result.leading is not None
        assert result.leading_source in (preview.INTERPOLATED, preview.EXACT)
        assert (result.leading.real > 0) == (not result.stable) or abs(s0 - s0_limit) < S0_STEP
    text = preview.describe(previews[29], "s0")  # s0 = 0.0079
    assert text[0] == (f"s0 = 0.0079, limit s0* = {s0_limit:.4f} at 120 km/h "
                       f"(margin s0* − s0 = {s0_limit - 0.0079:+.4f})")


@pytest.mark.slow
def test_other_sliders_use_the_reduced_model_and_say_when_nothing_is_known(known):
    """A speed, wheel force or motor slope no computation has visited: the reduced model of the
    locus on screen gives the verdict (the eigen-analysis's) and the leading eigenvalue with its
    error estimate, without a dense solve.  A point with no cached result and no kept sweep (another
    rail condition, never computed) is not guessed: verdict None.  A computed point is exact."""
    N0, b_M, key, _ = known
    points = [_point(0.005, 155.0, N0, b_M), _point(0.005, V_KMH, 131.0, b_M),
              _point(0.005, V_KMH, N0, 7300.0), _point(0.012, 95.0, N0, b_M)]
    before = dense_decompositions()
    results = [preview.preview(point, key, "v") for point in points]
    # a point of its own (speed and wheel force no other test uses): a test module that ran
    # earlier in this process may have computed the wet rail at the dashboard's defaults
    wet = _point(0.005, 117.3, N0 + 0.7, b_M, rail="wet")
    unknown = preview.preview(wet, wet.sweep("s0"), "s0")
    assert dense_decompositions() == before
    for point, result in zip(points, results, strict=True):
        assert result.source == preview.REDUCED, point
        assert result.stable == _exact_stable(point), point
        assert result.leading_source == preview.REDUCED
        assert result.leading_error is not None
        assert result.leading_error < 1e-3
    assert unknown.stable is None
    assert unknown.source == preview.NOT_COVERED
    assert "no computed result covers this point" in preview.describe(unknown, "s0")[-1]
    exact_point = compute.point_result(points[0])
    again = preview.preview(points[0], key, "v")
    assert again.source == preview.EXACT
    assert again.stable == exact_point.stable
    assert again.leading.real == pytest.approx(exact_point.max_real_part, abs=1e-12)


def test_interpolation_along_the_branches():
    """Between two sweep points each branch is interpolated linearly in the swept parameter; a
    branch that jumps there keeps the nearer point's value."""
    lam = np.array([[-1 + 10j, -2 + 20j], [-3 + 12j, 5 + 40j]])
    locus = compute.LocusResult("s0", np.array([0.001, 0.003]), lam, np.array([True, False]),
                                jumps=np.array([[False, True]]))
    values, between, stable = preview.along(locus, 0.0015)
    np.testing.assert_allclose(values, [-1.5 + 10.5j, -2 + 20j])
    assert between == (0.001, 0.003)
    assert stable == (True, False)


def test_the_limit_alone_decides_where_no_locus_covers_the_point(monkeypatch):
    """With s0*(v) known and no root locus through the point (none kept): stable below s0*,
    unstable at or above it; the leading eigenvalue then comes from the reduced model, or none
    is given."""
    monkeypatch.setattr(compute, "known_point", lambda *args: None)
    monkeypatch.setattr(compute, "known_locus", lambda *args: None)
    monkeypatch.setattr(compute, "known_limit", lambda *args: compute.LimitResult(0.008, ""))
    monkeypatch.setattr(compute, "reduced_estimate", lambda *args: None)
    below = preview.preview(_point(0.0079, V_KMH, 100.0, 1000.0), None, "s0")
    above = preview.preview(_point(0.008, V_KMH, 100.0, 1000.0), None, "s0")
    assert (below.stable, below.source) == (True, preview.BELOW_LIMIT)
    assert (above.stable, above.source) == (False, preview.ABOVE_LIMIT)
    assert below.leading is None
    assert below.s0_limit == 0.008
