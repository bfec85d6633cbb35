"""Peaks and limit crossings: one function for the linear and the nonlinear history ("peaks that
match the curves"); the peaks a reviewer reads (max, min, swing from the pre-fault value with their
times, the swing's quasi-static and dynamic parts, the growth of an unbounded history)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from model import build_model, default_operating_point, load_parameters
from model.analysis.eigen import bogie_system
from model.analysis.load_peaks import (
    LIMIT_TOLERANCE,
    history_peaks_and_crossings,
    load_peaks,
    output_extremes,
)
from model.analysis.nonlinear import nonlinear_response
from model.analysis.response import linear_load_peaks, short_circuit_response


def test_peaks_and_crossings_of_given_histories():
    t = np.arange(5) * 0.1
    totals = {"ID1.disc_clutch.torque": np.array([10.0, 30.0, -50.0, 49.0, 0.0]),
              "ID2.rim12.creep_force": np.array([5.0, 5.0, 5.0, 5.0, 5.0]),
              "ID1.rotor.ry": np.array([0.0, 1.0, -1.0, 0.5, 0.0])}
    steady = {"ID1.disc_clutch.torque": 10.0, "ID2.rim12.creep_force": 5.0, "ID1.rotor.ry": 0.0}
    limits = {"M_ad": 40.0, "mu_max N0": 5.0}
    found = history_peaks_and_crossings(t, totals, steady, limits)
    assert found.peaks["ID1.disc_clutch.torque"] == -50.0
    assert found.peak_times["ID1.disc_clutch.torque"] == pytest.approx(0.2)
    assert found.perturbation_peaks["ID1.disc_clutch.torque"] == -60.0
    assert found.perturbation_peak_times["ID1.disc_clutch.torque"] == pytest.approx(0.2)
    assert found.peaks["ID1.rotor.ry"] == 1.0  # the first of equal magnitudes
    # a load that sits on its limit (to rounding) is not a crossing; one beyond it is
    assert [(c.output, c.limit_name, c.time, c.value) for c in found.limit_crossings] == [
        ("ID1.disc_clutch.torque", "M_ad", pytest.approx(0.2), -50.0)]
    totals["ID2.rim12.creep_force"] = np.full(5, 5.0 * (1 + 10 * LIMIT_TOLERANCE))
    found = history_peaks_and_crossings(t, totals, steady, limits)
    assert [c.output for c in found.limit_crossings] == ["ID2.rim12.creep_force",
                                                        "ID1.disc_clutch.torque"]


@pytest.mark.parametrize("s0", [0.005, 0.014])
def test_tangent_history_gives_the_linear_peak_table(s0):
    """With the law's tangent the nonlinear loop reproduces the closed form (docs/nonlinear.md),
    so the one function gives the same peaks (1e-6 of each perturbation peak: the tangent run
    agrees with the closed form to ≈ 1e-7) and the same crossings (to one sample)."""
    parameters = load_parameters()
    model = build_model(parameters)
    op = default_operating_point(parameters, s0)
    linear = short_circuit_response(model, op, None, 0.5, 2000.0)
    tangent = nonlinear_response(model, op, None, 0.5, 2000.0, creep="tangent")
    for name in tangent.outputs:
        scale = abs(linear.perturbation_peaks[name])
        assert tangent.peaks[name] == pytest.approx(linear.peaks[name], abs=1e-6 * scale), name
        assert tangent.perturbation_peaks[name] == pytest.approx(
            linear.perturbation_peaks[name], abs=1e-6 * scale), name
        assert tangent.perturbation_peak_times[name] == pytest.approx(
            linear.perturbation_peak_times[name], abs=0.5e-3 + 1e-12), name
    crossings = [(c.output, c.limit_name) for c in linear.limit_crossings]
    assert [(c.output, c.limit_name) for c in tangent.limit_crossings] == crossings
    for a, b in zip(linear.limit_crossings, tangent.limit_crossings, strict=True):
        assert abs(a.time - b.time) <= 0.5e-3 + 1e-12
    assert crossings  # the case has crossings to compare (s0 = 0.005: ID2 passes M_ad)


# --- peaks a reviewer can read ----------------------------------------------------------------

def test_extremes_of_a_synthetic_history():
    """Max, min and the swing from the pre-fault value, each with its time: the largest
    magnitude of the total (the pre-fault value here) is neither; ties give the first sample."""
    t = np.arange(7) * 0.1
    total = np.array([50.0, 50.0, 20.0, -40.0, 10.0, -40.0, 35.0])
    e = output_extremes(t, total, pre_fault=50.0)
    assert (e.pre_fault, e.maximum, e.time_of_maximum) == (50.0, 50.0, 0.0)
    assert (e.minimum, e.time_of_minimum) == (-40.0, pytest.approx(0.3))
    assert (e.swing, e.time_of_swing) == (-90.0, pytest.approx(0.3))
    assert math.isnan(e.quasi_static)
    assert math.isnan(e.dynamic)
    assert math.isnan(e.quasi_static_at_end)
    assert math.isnan(e.quasi_static_final)
    # a swing upwards, from a negative pre-fault value
    e = output_extremes(t, np.array([-5.0, -5.0, 3.0, -9.0, -1.0, 2.0, -5.0]), pre_fault=-5.0)
    assert (e.swing, e.time_of_swing) == (8.0, pytest.approx(0.2))
    assert (e.maximum, e.minimum) == (3.0, -9.0)


def test_swing_split_into_quasi_static_and_dynamic_parts():
    """A take-over rising to 30 with an oscillation of amplitude 4 on it: the split at the
    swing's time, the quasi-static part at the end and its final value as given."""
    t = np.linspace(0.0, 2.0, 2001)
    rise = 30.0 * (1 - np.exp(-t / 0.8))
    wiggle = 4.0 * np.exp(-3.0 * t) * np.sin(2 * np.pi * 2.7 * t)
    pre = 50.0
    e = output_extremes(t, pre + rise + wiggle, pre, quasi_static=rise, quasi_static_final=30.0)
    k = int(np.argmax(np.abs(rise + wiggle)))
    assert e.time_of_swing == t[k]
    assert e.quasi_static == pytest.approx(rise[k])
    assert e.dynamic == pytest.approx(wiggle[k])
    assert e.quasi_static + e.dynamic == pytest.approx(e.swing)
    assert e.quasi_static_at_end == pytest.approx(rise[-1])
    assert e.quasi_static_final == 30.0


def test_load_peaks_bounded_or_growing_and_the_first_crossings():
    t = np.arange(4) * 0.5
    totals = {"ID1.disc_clutch.torque": np.array([10.0, 60.0, -70.0, 1e6]),
              "ID1.disc_clutch.force_x": np.array([1.0, 2.0, 3.0, 4.0])}
    steady = {"ID1.disc_clutch.torque": 10.0, "ID1.disc_clutch.force_x": 1.0}
    units = {"ID1.disc_clutch.torque": "N m", "ID1.disc_clutch.force_x": "N"}
    found = history_peaks_and_crossings(t, totals, steady, {"M_ad": 50.0})
    growing = load_peaks(t, totals, steady, units, found.limit_crossings, "linear",
                         growth_rate=3.0, split_note="unbounded with linear creep")
    assert not growing.bounded
    assert growing.growth_rate == 3.0
    assert growing.t_end == 1.5
    assert growing.crossings["ID1.disc_clutch.torque"].time == 0.5  # the first one
    assert "ID1.disc_clutch.force_x" not in growing.crossings  # no limit
    assert growing.split_note == "unbounded with linear creep"
    assert growing.extremes["ID1.disc_clutch.torque"].swing == 1e6 - 10.0
    stable = load_peaks(t, totals, steady, units, [], "linear", growth_rate=-0.05,
                        quasi_static={n: np.zeros(4) for n in totals},
                        quasi_static_final={n: 0.0 for n in totals})
    assert stable.bounded
    assert stable.split_note == ""
    nonlinear = load_peaks(t, totals, steady, units, [], "nonlinear")
    assert nonlinear.bounded  # nonlinear creep: bounded whatever the linear system does
    assert nonlinear.split_note  # not split: it says so
    with pytest.raises(ValueError, match="creep"):
        load_peaks(t, totals, steady, units, [], "tangent")


def _linear_peaks(s0: float):
    parameters = load_parameters()
    model = build_model(parameters)
    op = default_operating_point(parameters, s0)
    result = short_circuit_response(model, op, None, 2.0, 2000.0)
    growth = float(np.max(bogie_system(model, op).eigenvalues().real))
    return result, linear_load_peaks(model, result), growth


def test_linear_load_peaks_at_the_stable_point(uniform_acceleration_loads):
    """The swing of every output is the history's perturbation peak and its parts add up to it;
    ID1's quasi-static part loses the motor's torque at once; both settle to the static response
    of the vehicle decelerating under the lost torque (ID2 takes none of it over)."""
    result, peaks, growth = _linear_peaks(0.005)
    assert growth < 0  # the published stable case
    assert peaks.growth_rate == growth
    assert peaks.bounded
    assert peaks.split_note == ""
    for name, e in peaks.extremes.items():
        assert e.swing == result.perturbation_peaks[name], name
        assert e.time_of_swing == result.perturbation_peak_times[name], name
        assert e.quasi_static + e.dynamic == pytest.approx(e.swing, abs=1e-9 * abs(e.swing))
        assert e.pre_fault == result.steady[name]
    lost = result.steady["ID1.disc_clutch.torque"]
    id1, id2 = (peaks.extremes[f"{d}.disc_clutch.torque"] for d in ("ID1", "ID2"))
    assert id1.time_of_swing > 0.0
    parameters = load_parameters()
    model = build_model(parameters)
    op = default_operating_point(parameters, 0.005)
    balance = uniform_acceleration_loads(model, op, -result.motor_torque
                                         * model.short_circuit_force)
    assert id1.quasi_static_final == pytest.approx(balance["ID1.disc_clutch.torque"], rel=1e-6)
    assert id2.quasi_static_final == pytest.approx(balance["ID2.disc_clutch.torque"], rel=1e-6)
    assert id1.quasi_static == pytest.approx(-lost, rel=0.05)  # there at once
    assert abs(id2.quasi_static_at_end) < 0.05 * lost  # no take-over


def test_linear_load_peaks_at_the_unstable_point():
    """The history grows at the largest Re λ, is not split, and each output's first crossing of
    its limit is the history's."""
    result, peaks, growth = _linear_peaks(0.014)
    assert growth > 0  # the published unstable case
    assert peaks.growth_rate == growth
    assert not peaks.bounded
    assert peaks.split_note == "unbounded with linear creep"
    assert math.isnan(peaks.extremes["ID1.disc_clutch.torque"].quasi_static)
    first = {}
    for crossing in result.limit_crossings:
        first.setdefault(crossing.output, crossing)
    assert peaks.crossings == first
    assert "ID1.disc_clutch.torque" in peaks.crossings
