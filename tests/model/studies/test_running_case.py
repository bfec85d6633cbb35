"""The running load case where the running system has a growing mode: the point has no stationary
response, so it is left out of the checks and named (creepage, speed, growth rate); a grid without
one stable point is refused.

The previous bundled set (``assets/parameters/previous_calibrated.toml``, near-zero vertical
dampers) is the test's bogie: with the wheel-force coupling its running system is stable at
s0 = 0.002 over the whole speed range and at s0 = 0.005 up to about 60 km/h, growing from about
70 km/h (``running_system``'s largest non-neutral real part: −0.001 1/s at 60 km/h, +0.008 1/s
at 120 km/h).  The test asserts those signs first, so a change of the set shows as such."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from model import build_model, default_operating_point, load_parameters
from model.analysis.eigen import non_neutral, running_system
from model.mechanics.operating_point import KMH
from model.studies.assessment import (
    LOAD_CASES,
    AssessmentError,
    AssessmentOptions,
    assessed_outputs,
    running_case,
)

PREVIOUS = Path(__file__).resolve().parents[3] / "assets" / "parameters" / \
    "previous_calibrated.toml"


@pytest.fixture(scope="module")
def previous():
    return load_parameters(PREVIOUS)


def growth(parameters, s0: float, v_kmh: float) -> float:
    """The running system's largest non-neutral real part [1/s]."""
    lam = running_system(build_model(parameters),
                         default_operating_point(parameters, s0=s0, v_kmh=v_kmh)).eigen[0]
    return float(np.max(lam[non_neutral(lam)].real))


def options(s0, v_kmh) -> AssessmentOptions:
    return AssessmentOptions(cases=(*LOAD_CASES, "running"), running_s0=tuple(s0),
                             running_v=tuple(x * KMH for x in v_kmh))


@pytest.mark.slow
def test_an_unstable_point_is_left_out_and_named(previous):
    assert growth(previous, 0.005, 40) < 0 < growth(previous, 0.005, 120)
    assert growth(previous, 0.002, 120) < 0
    case = running_case(previous, assessed_outputs(previous), options((0.002, 0.005), (40, 120)))
    (point,) = case.scenario["unstable"]
    assert point["s0"] == 0.005
    assert point["v_kmh"] == pytest.approx(120.0)
    assert point["growth"] == pytest.approx(growth(previous, 0.005, 120), rel=1e-9)
    assert "NOT STABLE" in case.description
    assert "s0 = 0.005 at 120 km/h" in case.description
    for load in case.loads.values():  # 120 km/h stays: stable at s0 = 0.002
        assert list(np.round(load.v / KMH, 9)) == [40.0, 120.0]
        assert load.scenarios[1]["s0"] == 0.002
        assert np.all(np.isfinite(load.mean))
        assert np.all(np.isfinite(load.alternating))
    for check in case.checks:
        assert check.scenario["s0"] == 0.002 or check.v_kmh == pytest.approx(40.0)
        assert np.isfinite(check.safety_factor)


@pytest.mark.slow
def test_a_speed_unstable_at_every_creepage_drops_out(previous):
    case = running_case(previous, assessed_outputs(previous), options((0.005,), (40, 120)))
    assert [round(u["v_kmh"]) for u in case.scenario["unstable"]] == [120]
    for load in case.loads.values():
        assert list(np.round(load.v / KMH, 9)) == [40.0]


def test_a_grid_without_a_stable_point_is_refused(previous):
    with pytest.raises(AssessmentError, match="no point of the grid is stable"):
        running_case(previous, assessed_outputs(previous), options((0.005,), (120, 200)))
