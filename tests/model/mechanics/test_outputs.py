"""Section torques of the shafts (``IDk.axle.wheel_seat_12.torque`` …): free-body balance under
steady traction, the axle's twist between the wheels, and both drives alike."""

from __future__ import annotations

import math

import numpy as np
import pytest

from model.mechanics.assembly import build_model
from model.mechanics.operating_point import (
    OperatingPoint,
    creep_coefficients,
    motor_torque,
)
from model.mechanics.outputs import SECTION_TORQUES, output_matrices, static_deflection
from model.mechanics.parameters import load_parameters


@pytest.fixture(scope="module")
def setup():
    parameters = load_parameters()
    model = build_model(parameters)
    op = OperatingPoint.from_kmh(0.005, 120.0, parameters["wheel_force"],
                                 parameters["motor_slope"])
    return model, op, output_matrices(model, op)


def test_section_torques_are_named_outputs_of_both_drives(setup):
    _, _, out = setup
    for drive in ("ID1", "ID2"):
        for section in ("axle.wheel_seat_12", "axle.wheel_seat_14", "axle.centre",
                        "hollow_shaft.gear_seat", "hollow_shaft"):
            name = f"{drive}.{section}.torque"
            assert name in SECTION_TORQUES
            assert out.units[out.index(name)] == "N m"
    assert len(set(out.names)) == len(out.names)


def test_free_body_balance_under_steady_traction(setup):
    """The motor's torque M(s0, v) on the rotor, the creep forces μ N0 at the contacts: the
    static deflection gives p M through the gear train and the hollow shaft, and at each wheel
    seat what that wheel's contact takes, μ N0 r0; the axle's centre carries wheel 14's share."""
    model, op, out = setup
    p = model.parameters
    M = motor_torque(p, op)
    wheel = creep_coefficients(p, op).mu * op.N0 * p["wheel_radius"]
    q0 = static_deflection(model, op)
    value = dict(zip(out.names, out.C_q @ q0, strict=True))
    for drive in ("ID1", "ID2"):
        assert value[f"{drive}.driving_shaft.torque"] == pytest.approx(M, rel=1e-9)
        for name in ("disc_clutch", "hollow_shaft.gear_seat", "hollow_shaft", "claw_clutch"):
            assert value[f"{drive}.{name}.torque"] == pytest.approx(p["gear_ratio"] * M,
                                                                    rel=1e-9), name
        for name in ("axle.wheel_seat_12", "axle.wheel_seat_14", "axle.centre"):
            assert value[f"{drive}.{name}.torque"] == pytest.approx(wheel, rel=1e-9), name
        # the two seats hold the whole wheelset torque: p M = 2 μ N0 r0 (eq. 7)
        assert value[f"{drive}.axle.wheel_seat_12.torque"] \
            + value[f"{drive}.axle.wheel_seat_14.torque"] == pytest.approx(
                value[f"{drive}.claw_clutch.torque"], rel=1e-9)
    # the steady values the histories start from are the same numbers
    for name in SECTION_TORQUES:
        assert out.steady[out.index(name)] == pytest.approx(value[name], rel=1e-12)


@pytest.mark.parametrize("drive", ["ID1", "ID2"])
def test_axle_centre_torque_of_an_antisymmetric_wheel_twist(setup, drive):
    """Equal and opposite torques T on the two wheel rims (nothing else): the axle between the
    wheels twists by φ14 − φ12, and its centre carries k_axle (φ14 − φ12) with the hand value
    k_axle = G J / (2 c) of the solid axle (G = E / (2 (1 + ν)), J = π r⁴ / 2)."""
    model, _, out = setup
    p = model.parameters
    T = 10_000.0  # [N m]
    f = np.zeros(model.n)
    f[model.dofs.index(f"{drive}.rim14.ry")] = T
    f[model.dofs.index(f"{drive}.rim12.ry")] = -T
    R = model.rigid_body_modes
    r = R.shape[1]
    bordered = np.block([[model.K, R], [R.T, np.zeros((r, r))]])
    q = np.linalg.solve(bordered, np.concatenate([f, np.zeros(r)]))[: model.n]
    twist = q[model.dofs.index(f"{drive}.ax14.ry")] - q[model.dofs.index(f"{drive}.ax12.ry")]
    G = p["young_modulus"] / (2 * (1 + p["poisson_ratio"]))
    k_axle = G * math.pi * p["axle_radius"] ** 4 / 2 / (2 * p["contact_half_distance"])
    centre = out.C_q[out.index(f"{drive}.axle.centre.torque")] @ q
    # the torque flows from wheel 14 to wheel 12: the claw side (12) lags, so the section
    # torque (up = claw side) is −T
    assert abs(twist) > 0
    assert centre == pytest.approx(-k_axle * twist, rel=1e-9)
    assert centre == pytest.approx(-T, rel=1e-7)
    # the seats hold ±T, the hollow shaft nothing (the gear train is free to spin)
    assert out.C_q[out.index(f"{drive}.axle.wheel_seat_14.torque")] @ q == pytest.approx(-T, rel=1e-7)
    assert out.C_q[out.index(f"{drive}.axle.wheel_seat_12.torque")] @ q == pytest.approx(T, rel=1e-7)
    assert abs(out.C_q[out.index(f"{drive}.hollow_shaft.torque")] @ q) < 1e-6 * T


def test_damping_part_is_the_shafts_loss_time(setup):
    model, _, out = setup
    loss = model.parameters["shaft_loss_time"]
    for name in SECTION_TORQUES:
        i = out.index(name)
        np.testing.assert_allclose(out.C_v[i], loss * out.C_q[i], rtol=0, atol=0)
