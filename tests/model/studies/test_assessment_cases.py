"""The assessment's load cases together: the ripple case beside the three rare events, checked by
the components under alternating load, the options that choose the cases."""

from __future__ import annotations

import json

import numpy as np
import pytest

from model.analysis.assessment import alternating_components, drive_components
from model.mechanics.operating_point import KMH
from model.mechanics.parameters import load_parameters
from model.studies.assessment import (
    DEFAULT_RIPPLE_V,
    LOAD_CASES,
    AssessmentOptions,
    assess,
    assessed_outputs,
    assessment_of,
    ripple_case,
    starting_case,
)


def test_the_ripple_case_is_a_load_case_of_its_own_by_default():
    assert LOAD_CASES == ("short_circuit", "unstable_adhesion", "starting", "ripple")
    options = AssessmentOptions()
    assert options.cases == LOAD_CASES
    assert options.ripple is None  # the set's amplitudes
    speeds = np.asarray(DEFAULT_RIPPLE_V) / KMH
    assert speeds[0] == pytest.approx(10.0)
    assert speeds[-1] == pytest.approx(200.0)  # the locomotive's top speed
    assert np.diff(speeds) == pytest.approx(10.0)


def test_a_steady_case_and_the_ripple_case_side_by_side():
    """The starting case checks the 16 sections against their largest torque, the ripple case
    the same sections under alternating load; the assessment lists the components of both, the
    governing check is the one of least margin over both cases, and the JSON carries the
    alternating checks' mean, amplitude, speed and orders."""
    parameters = load_parameters()
    options = AssessmentOptions(s0=(0.005,), ripple_v=tuple(np.linspace(60.0, 120.0, 7) * KMH),
                                cases=("starting", "ripple"))
    outputs = assessed_outputs(parameters)
    cases = [starting_case(parameters, outputs, options), ripple_case(parameters, outputs, options)]
    result = assessment_of(parameters, cases)
    assert [c.name for c in result.cases] == ["starting", "ripple"]
    assert len(result.checks) == 32
    ripple = [c for c in result.checks if c.load_case == "ripple"]
    assert [(c.component, c.kind) for c in ripple] == [
        (c.name, c.kind) for c in alternating_components(parameters)]
    assert {c.kind for c in result.components} == {"press_fit_slip", "torsional_shear", "coupling",
                                                   "torsional_fatigue", "coupling_vibratory"}
    assert len(result.components) == len(drive_components(parameters)) + 10  # 6 shafts, 4 couplings
    assert result.governing is max(result.checks, key=lambda c: c.utilisation)
    data = result.as_dict()
    assert [c["name"] for c in data["load_cases"]] == ["starting", "ripple"]
    for check in data["checks"]:
        if check["load_case"] == "ripple":
            assert 60.0 <= check["v_kmh"] <= 120.0
            assert check["alternating"] >= 0
            assert [o["order"] for o in check["orders"]] == ["el:6", "el:12"]
            assert sum(o["amplitude"] for o in check["orders"]) == pytest.approx(
                check["alternating"], rel=1e-12)
        else:
            assert check["orders"] == []
    json.dumps(data)
    # the same through assess() with the options' cases
    again = assess(parameters, options)
    assert [(c.component, c.kind, c.load_case, c.safety_factor) for c in again.checks] == [
        (c.component, c.kind, c.load_case, c.safety_factor) for c in result.checks]


def test_the_converters_bandwidth_enters_through_the_model():
    """The ripple case's model is built from the set: a torque-controlled healthy motor
    (``motor_bandwidth`` above the ripple's frequencies) changes what the motors' ripple drives.
    Compared at one speed near the driving shafts' resonance."""
    parameters = load_parameters()
    options = AssessmentOptions(s0=(0.005,), ripple_v=(80.0 * KMH, 90.0 * KMH), cases=("ripple",))
    outputs = ["ID2.driving_shaft.torque"]
    base = ripple_case(parameters, outputs, options).loads[outputs[0]]
    controlled = ripple_case(parameters.replace(motor_bandwidth=50.0), outputs,
                             options).loads[outputs[0]]
    assert base.alternating.max() != pytest.approx(controlled.alternating.max(), rel=1e-3)


@pytest.mark.slow
def test_assess_runs_all_four_cases():
    result = assess(load_parameters())
    assert [c.name for c in result.cases] == list(LOAD_CASES)
    assert len(result.checks) == 4 * 16
    assert result.governing is max(result.checks, key=lambda c: c.utilisation)
