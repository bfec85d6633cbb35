"""Peaks and limit crossings: one function for the linear and the nonlinear history ("peaks that
match the curves")."""

from __future__ import annotations

import numpy as np
import pytest

from model import build_model, default_operating_point, load_parameters
from model.analysis.load_peaks import LIMIT_TOLERANCE, history_peaks_and_crossings
from model.analysis.nonlinear import nonlinear_response
from model.analysis.response import short_circuit_response


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
