"""The healthy motor's converter torque control (``motor_bandwidth`` f_c): the slope b_M acts on
the motor's relative speed Δφ̇ high-passed at f_c (one massless filter coordinate).  Checked
against the element's own transfer ``T/Δφ̇ = −b_M s/(s + ω_c)``: no steady torque for a constant
speed offset, the slope's torque far above f_c, the crossover (|T/Δφ̇| = b_M/√2, 45°) at f_c —
both from the filter's rows and through the whole model's dynamic stiffness."""

from __future__ import annotations

import numpy as np
import pytest

from model import build_model, default_operating_point, eigen_analysis, load_parameters
from model.analysis.frequency_response import solve_direct
from model.mechanics.assembly import CONVERTER_FILTER, motor_speed_row
from model.mechanics.operating_point import damping_matrix

BANDWIDTH = 8.0  # [Hz] a converter's torque control in the range the docs quote


@pytest.fixture(scope="module")
def controlled():
    parameters = load_parameters().replace(motor_bandwidth=BANDWIDTH)
    model = build_model(parameters)
    return parameters, model, default_operating_point(parameters)


def _element_transfer(model, b_M: float, f_hz: np.ndarray) -> np.ndarray:
    """T/Δφ̇ [N m s/rad] from the filter's rows of B and K alone: a unit relative speed Δφ̇
    (the rotor alone turning), the filter's coordinate from its first-order row, the slope torque
    −b_M (B_M row of the rotor) · q̇."""
    z = model.dofs.index(CONVERTER_FILTER)
    rotor = model.dofs.index("ID2.rotor.ry")
    s = 2j * np.pi * f_hz
    q_dot = np.zeros(model.n, dtype=complex)
    q_dot[rotor] = 1.0  # Δφ̇ = 1 rad/s
    out = []
    for value in s:
        Z = -(model.B[z] @ q_dot) / (value * model.B[z, z] + model.K[z, z])
        velocity = q_dot.copy()
        velocity[z] = value * Z
        out.append(-b_M * (model.motor_pattern[rotor] @ velocity))
    return np.array(out)


def test_no_filter_coordinate_without_control():
    parameters = load_parameters()
    assert parameters["motor_bandwidth"] == 0.0  # the study's natural characteristic, default
    model = build_model(parameters)
    assert CONVERTER_FILTER not in model.dofs.names
    assert model.n == 197


def test_constant_offset_no_torque_fast_change_the_slope(controlled):
    _, model, op = controlled
    assert model.n == 198
    assert model.dofs.names[-1] == CONVERTER_FILTER
    b_M = op.b_M
    H = _element_transfer(model, b_M, np.array([0.0, BANDWIDTH, 1e3 * BANDWIDTH]))
    assert abs(H[0]) <= 1e-12 * b_M  # a constant offset: the converter restores the set-point
    assert abs(H[1]) == pytest.approx(b_M / np.sqrt(2), rel=1e-12)  # crossover at f_c
    assert np.angle(-H[1], deg=True) == pytest.approx(45.0, abs=1e-9)
    assert H[2] == pytest.approx(-b_M, rel=2e-3)  # far above f_c: the study's slope (1e-3 off)
    f = np.geomspace(0.01, 1000.0, 25)
    s = 2j * np.pi * f
    expected = -b_M * s / (s + 2 * np.pi * BANDWIDTH)
    np.testing.assert_allclose(_element_transfer(model, b_M, f), expected, rtol=1e-12)


def test_the_whole_model_crosses_over_at_the_bandwidth(controlled):
    """Through the dynamic stiffness of the whole bogie (a torque on ID2's rotor), the slope
    torque over the motor's relative speed (rotor − stator + p/r0 · CB.x) is the element's
    transfer at every frequency: the motor's own dynamics do not enter the ratio."""
    _, model, op = controlled
    rotor = model.dofs.index("ID2.rotor.ry")
    force = np.zeros(model.n)
    force[rotor] = 1.0
    speed = motor_speed_row(model.parameters, model.dofs)
    slope = -op.b_M * model.motor_pattern[rotor]
    f = np.array([0.5, BANDWIDTH / 2, BANDWIDTH, 2 * BANDWIDTH, 100.0, 298.0])
    C_v = np.vstack([slope, speed])
    H = solve_direct(model, damping_matrix(model, op), force, np.zeros_like(C_v), C_v, f)
    ratio = H[0] / H[1]
    s = 2j * np.pi * f
    np.testing.assert_allclose(ratio, -op.b_M * s / (s + 2 * np.pi * BANDWIDTH), rtol=1e-8)


def test_eigen_analysis_with_control(controlled):
    """The filter adds one real eigenvalue and no rigid-body zero; the study's stable case stays
    stable; a rigid motion leaves the filter at rest (K r = 0 with its coordinate 0)."""
    _, model, op = controlled
    result = eigen_analysis(model, op, vectors=False)
    assert result.n_rigid == 5
    assert result.stable
    z = model.dofs.index(CONVERTER_FILTER)
    assert not np.any(model.rigid_body_modes[z])
    assert model.rolling_mode[z] == 0.0
    assert result.eigenvalues.size == 2 * model.n - 3 - 5  # two strokes and the filter massless
