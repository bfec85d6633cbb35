"""The prior ranges of the strength data and ripple amplitudes: well formed around the default
set, a file of ranges that changes, adds and removes them, and bad ranges refused with one line
naming the datum."""

from __future__ import annotations

import numpy as np
import pytest

from model.mechanics.parameters import ASSESSMENT_SCHEMA, SCHEMA, load_parameters
from model.studies.assessment import AssessmentOptions
from model.studies.uncertainty import UNCERTAIN_PARAMETERS
from model.studies.verdict_priors import (
    GROUPS,
    NOT_SAMPLED,
    RIPPLE_ONLY,
    STRENGTH_PARAMETERS,
    PriorRangeError,
    VerdictUncertaintyError,
    check_ranges,
    default_ranges,
    group_of,
    load_ranges,
    merge_ranges,
    parse_ranges,
    relevant_ranges,
)


@pytest.fixture(scope="module")
def parameters():
    return load_parameters()


def test_every_strength_prior_is_a_datum_with_a_reason_around_the_sets_value(parameters):
    names = [r.name for r in STRENGTH_PARAMETERS]
    assert len(names) == len(set(names))
    for r in STRENGTH_PARAMETERS:
        assert r.name in ASSESSMENT_SCHEMA, r.name
        assert r.name not in NOT_SAMPLED, r.name
        assert r.low <= parameters[r.name] <= r.high, r.name
        assert 0 < r.low < r.high, r.name
        assert r.reason.split(":")[0] in {"estimate", "standard's spread", "tolerance class",
                                          "catalogue"}, r.name
        assert group_of(r.name) == GROUPS[1]
    assert all(group_of(r.name) == GROUPS[0] for r in UNCERTAIN_PARAMETERS)
    # the sampled kinds of data: every check's capacity has at least one unknown
    for word in ("interference_min", "friction_min", "shear_stress_allowable", "tensile_strength",
                 "notch_factor", "rated_torque", "vibratory_torque", "ripple_el"):
        assert any(word in name for name in names), word
    assert not any(name.startswith("required_factor_") for name in names)
    check_ranges(parameters, default_ranges())  # together, on the default set


def test_a_file_changes_adds_and_removes_ranges(tmp_path, parameters):
    path = tmp_path / "ranges.toml"
    path.write_text('wheel_seat_friction_min = { low = 0.06, high = 0.14 }\n'
                    'wheel_seat_length = { low = 0.18, high = 0.2, reason = "the drawing\'s '
                    'tolerance" }\n'
                    'motor_slope = { fixed = true }\n'
                    'disc_clutch_rated_torque = { low = 9e4, high = 1.5e5, log = true }\n',
                    encoding="utf-8")
    overrides = load_ranges(path)
    merged = merge_ranges(overrides)
    by_name = {r.name: r for r in merged}
    assert (by_name["wheel_seat_friction_min"].low, by_name["wheel_seat_friction_min"].log) == (
        0.06, False)
    assert by_name["disc_clutch_rated_torque"].log
    assert "motor_slope" not in by_name
    assert merged[-1].name == "wheel_seat_length"  # added after the defaults
    assert by_name["wheel_seat_length"].reason == "the drawing's tolerance"
    assert len(merged) == len(default_ranges())  # one removed, one added
    check_ranges(parameters, merged)


def _table_error(table: dict, parameters) -> str:
    with pytest.raises(PriorRangeError) as caught:
        check_ranges(parameters, merge_ranges(parse_ranges(table, "ranges.toml")))
    return str(caught.value)


@pytest.mark.parametrize(("table", "names"), [
    ({"wheel_seat_friction_min": {"low": 0.16, "high": 0.08}}, ["wheel_seat_friction_min",
                                                                "not below"]),
    ({"wheel_seat_friction_min": {"low": -0.05, "high": 0.16}}, ["wheel_seat_friction_min",
                                                                 "-0.05"]),
    ({"wheel_seat_friction": {"low": 0.1, "high": 0.2}}, ["wheel_seat_friction", "unknown"]),
    ({"required_factor_slip": {"low": 1.2, "high": 1.8}}, ["required_factor_slip", "rule"]),
    ({"driven_wheelsets": {"low": 2, "high": 6}}, ["driven_wheelsets"]),
    ({"axle_torsional_notch_factor": {"low": 0.8, "high": 1.5}}, ["axle_torsional_notch_factor",
                                                                  "0.8"]),
    ({"gear_seat_friction_min": {"low": 0.13, "high": 0.16}}, ["gear_seat_friction_min",
                                                               "set's value 0.12"]),
    ({"ripple_el6_amplitude": {"low": 0.0, "high": 500.0, "log": True}}, ["ripple_el6_amplitude",
                                                                           "above 0"]),
    ({"wheel_seat_interference_min": {"low": 1.5e-4, "high": 3.0e-4},
      "wheel_seat_interference_max": {"low": 2.5e-4, "high": 4.0e-4}},
     ["wheel_seat_interference_min", "wheel_seat_interference_max", "together"]),
    ({"wheel_seat_friction_min": {"low": "0.1", "high": 0.2}}, ["wheel_seat_friction_min",
                                                                "must be a number"]),
    ({"wheel_seat_friction_min": {"lo": 0.1, "high": 0.2}}, ["wheel_seat_friction_min", "'lo'"]),
    ({"motor_slope": {"fixed": True, "low": 1.0}}, ["motor_slope", "fixed"]),
])
def test_bad_ranges_are_refused_in_one_line_naming_the_datum(table, names, parameters):
    try:
        message = _table_error(table, parameters)
    except PriorRangeError as error:  # refused while parsing
        message = str(error)
    assert "\n" not in message
    for name in names:
        assert name in message, message
    assert issubclass(PriorRangeError, VerdictUncertaintyError)
    assert issubclass(PriorRangeError, ValueError)


def test_a_bad_file_is_refused_in_one_line(tmp_path):
    with pytest.raises(PriorRangeError, match="does not exist"):
        load_ranges(tmp_path / "missing.toml")
    broken = tmp_path / "broken.toml"
    broken.write_text("wheel_seat_friction_min = { low = \n", encoding="utf-8")
    with pytest.raises(PriorRangeError, match="not valid TOML") as caught:
        load_ranges(broken)
    assert "\n" not in str(caught.value)


def test_the_default_ranges_of_another_set_must_hold_its_values(parameters):
    """A set whose datum lies outside the default prior (another bogie's) is refused, naming the
    datum: its ranges belong in a file."""
    other = parameters.replace(wheel_seat_interference_min=2.6e-4)
    with pytest.raises(PriorRangeError, match=r"wheel_seat_interference_min.*set's value"):
        check_ranges(other, default_ranges())


def test_the_options_leave_out_what_cannot_change_the_verdict():
    everything = default_ranges()
    kept, fixed = relevant_ranges(everything, AssessmentOptions())
    assert kept == everything
    assert fixed == {}
    kept, fixed = relevant_ranges(everything, AssessmentOptions(b_M=3000.0, cases=("starting",)))
    names = {r.name for r in kept}
    assert "motor_slope" not in names
    assert "motor slope" in fixed["motor_slope"]
    assert not names & RIPPLE_ONLY
    assert {"wheel_seat_friction_min", "creep_slope", "disc_clutch_rated_torque"} <= names
    from model.mechanics.excitation import Order

    _, fixed = relevant_ranges(everything, AssessmentOptions(ripple={Order("el", 6.0): 100.0}))
    assert set(fixed) == {"ripple_el6_amplitude", "ripple_el12_amplitude"}


def test_groups_follow_the_schemas():
    assert all(group_of(name) == "dynamics" for name in SCHEMA)
    assert all(group_of(name) == "strength data" for name in ASSESSMENT_SCHEMA)
    assert np.array_equal([group_of(r.name) for r in default_ranges()],
                          ["dynamics"] * len(UNCERTAIN_PARAMETERS)
                          + ["strength data"] * len(STRENGTH_PARAMETERS))
