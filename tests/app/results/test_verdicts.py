"""The dashboard's assessment (:func:`app.results.verdicts.assessment_result`, its unstable and
ripple cases cached apart) is :func:`model.studies.assessment.assess` with the same options, check
by check; its ripple case is always at the assessment's default creepages."""

from __future__ import annotations

from dataclasses import replace

import pytest

from app.results import compute, verdicts
from app.results.case import Case
from model.analysis.response import ShortCircuit
from model.mechanics.operating_point import KMH
from model.studies.assessment import AssessmentOptions, assess, assessment_of

WITHOUT_RIPPLE = ("short_circuit", "unstable_adhesion", "starting")


def _expected(parameters, options: AssessmentOptions):
    """``assess`` with ``options``, its ripple case at the default creepages."""
    cases = assess(parameters, replace(options, cases=WITHOUT_RIPPLE)).cases
    ripple = assess(parameters, AssessmentOptions(N0=options.N0, b_M=options.b_M,
                                                  cases=("ripple",))).cases
    return assessment_of(parameters, cases + ripple)


def _same(a, b) -> None:
    assert [c.name for c in a.cases] == [c.name for c in b.cases]
    assert len(a.checks) == len(b.checks)
    for x, y in zip(a.checks, b.checks, strict=True):
        assert (x.component, x.kind, x.load_case) == (y.component, y.kind, y.load_case)
        assert x.load == pytest.approx(y.load, rel=1e-12)
        assert x.safety_factor == pytest.approx(y.safety_factor, rel=1e-12)
    assert a.governing.component == b.governing.component
    assert a.governing.load_case == b.governing.load_case


@pytest.mark.slow
def test_dashboard_assessment_is_the_models_at_a_stable_point_and_after_a_step():
    parameters = compute.parameters("", "calibrated")
    # the set's N0 and b_M as a case record keeps them (rounded: its decimals)
    point = Case(**Case.defaults(parameters))
    N0, b_M = point.N0 * 1e3, point.b_M
    excitation = ShortCircuit(M0=50e3, f=90.0, D=0.04)
    for s0 in (0.005, 0.0055):  # the second reuses the cached unstable case of the first
        shown = verdicts.assessment_result(Case(s0=s0, v=120.0, N0=N0 / 1e3, b_M=b_M, M0=50.0,
                                                f=90.0, D=0.04))
        expected = _expected(parameters, AssessmentOptions(s0=(s0,), v=(120.0 * KMH,), N0=N0,
                                                           b_M=b_M, excitation=excitation))
        _same(shown, expected)


@pytest.mark.slow
def test_dashboard_assessment_is_the_models_at_an_unstable_point():
    """Beyond the limit the unstable case is the operating point's own and the short circuit
    takes the default grid."""
    parameters = compute.parameters("", "calibrated")
    point = Case(**Case.defaults(parameters))  # the set's N0 and b_M as a record keeps them
    N0, b_M = point.N0 * 1e3, point.b_M
    shown = verdicts.assessment_result(Case(s0=0.012, v=140.0, N0=N0 / 1e3, b_M=b_M, M0=50.0,
                                            f=90.0, D=0.04))
    expected = _expected(parameters, AssessmentOptions(
        N0=N0, b_M=b_M, excitation=ShortCircuit(M0=50e3, f=90.0, D=0.04), unstable_s0=0.012,
        unstable_v=140.0 * KMH))
    _same(shown, expected)


@pytest.mark.slow
def test_running_rows_say_the_parts_of_their_amplitude():
    """A running check's row (what the Verdicts table and the report list): its worst speed,
    mean ± amplitude, the parts (ripple, the wheel polygon's orders by the Campbell diagram's
    names, the random RMS)."""
    from app.results.verdicts import check_rows
    from model import load_parameters
    from model.mechanics.operating_point import KMH
    from model.studies.assessment import AssessmentOptions, assess

    result = assess(load_parameters(), AssessmentOptions(cases=("running",),
                                                         running_v=(100 * KMH, 200 * KMH)))
    rows = check_rows(result)
    assert len(rows) == 16
    for row, check in zip(rows, sorted(result.checks, key=lambda c: -c.utilisation), strict=True):
        assert row["load case"] == "running"
        assert "wheel:20" in row["where"]
        assert f"RMS {check.rms / 1e3:.3g} kN m" in row["where"]
