"""Excitation orders: the lines' frequencies from the kinematics, the order grammar, the
excitation file (values with their sources), bad input."""

from __future__ import annotations

import math

import pytest

from model import load_parameters
from model.mechanics.excitation import (
    DEFAULT_ORDERS,
    DriveExcitation,
    ExcitationError,
    Order,
    load_excitation,
    parse_amplitudes,
    parse_orders,
)


def test_line_frequencies_follow_the_drive_kinematics():
    """At 200 km/h a 1250 mm wheel turns 14.15 times a second; the rotor p times as fast; the
    gear mesh z times the rotor; the electrical frequency P times the rotor."""
    p = load_parameters()
    e = DriveExcitation(pole_pairs=2, pinion_teeth=21)
    v = 200 / 3.6
    wheel = v / (2 * math.pi * p["wheel_radius"])
    assert wheel == pytest.approx(14.147, abs=1e-3)
    assert Order("wheel", 2).frequency_hz(v, p, e) == pytest.approx(2 * wheel)
    assert Order("rotor", 1).frequency_hz(v, p, e) == pytest.approx(p["gear_ratio"] * wheel)
    assert Order("mesh", 1).frequency_hz(v, p, e) == pytest.approx(21 * p["gear_ratio"] * wheel)
    assert Order("el", 6).frequency_hz(v, p, e) == pytest.approx(12 * p["gear_ratio"] * wheel)
    assert Order("fixed", 450).frequency_hz([10.0, 50.0], p, e).tolist() == [450.0, 450.0]
    assert Order("el", 6).per_speed_hz(p, e) * v == pytest.approx(
        Order("el", 6).frequency_hz(v, p, e))


def test_order_grammar():
    orders = parse_orders("wheel:1, rotor:2,mesh:1, 6, el:6, fixed:450.5")
    assert [o.name for o in orders] == ["wheel:1", "rotor:2", "mesh:1", "el:6", "fixed:450.5"]
    assert [o.label for o in orders][:2] == ["1× wheel", "2× rotor"]
    assert len(parse_orders(DEFAULT_ORDERS)) == 7
    assert parse_amplitudes("el:6=250, 12=120") == {Order("el", 6): 250.0, Order("el", 12): 120.0}


@pytest.mark.parametrize(("text", "message"), [
    ("", "no excitation orders"),
    ("el:-6", "must be > 0"),
    ("wheel:0", "must be > 0"),
    ("gear:1", "unknown order family"),
    ("el:six", "must be a number"),
    ("el:5000", "at most 1000"),
    ("el:1:2", "not an order"),
    (",".join(f"el:{k}" for k in range(1, 26)), "at most 24"),
])
def test_bad_orders(text, message):
    with pytest.raises(ExcitationError, match=message):
        parse_orders(text)


@pytest.mark.parametrize(("text", "message"), [
    ("el:6", "order=amplitude"),
    ("el:6=-1", r"\[0, 1e7\]"),
    ("el:6=x", "must be a number"),
    ("el:6=1,6=2", "given twice"),
])
def test_bad_amplitudes(text, message):
    with pytest.raises(ExcitationError, match=message):
        parse_amplitudes(text)


def test_the_bundled_excitation_file_says_where_each_value_comes_from():
    e = load_excitation()
    assert (e.pole_pairs, e.pinion_teeth) == (2, 21)
    assert set(e.notes) == {"motor_pole_pairs", "pinion_teeth"}
    assert all(note.startswith("estimate:") and len(note) > 60 for note in e.notes.values())


@pytest.mark.parametrize(("content", "message"), [
    ('motor_pole_pairs = { value = 2, unit = "1" }\n', "missing pinion_teeth"),
    ('motor_pole_pairs = { value = 2.5, unit = "1" }\npinion_teeth = { value = 21, unit = "1" }\n',
     "whole number"),
    ('motor_pole_pairs = { value = 2, unit = "1" }\npinion_teeth = { value = 21, unit = "m" }\n',
     "must be"),
    ('poles = { value = 2, unit = "1" }\n', "unknown entry"),
    ("not toml [", "not valid TOML"),
])
def test_bad_excitation_files(tmp_path, content, message):
    path = tmp_path / "excitation.toml"
    path.write_text(content)
    with pytest.raises(ExcitationError, match=message):
        load_excitation(path)
    with pytest.raises(ExcitationError, match="does not exist"):
        load_excitation(tmp_path / "missing.toml")
