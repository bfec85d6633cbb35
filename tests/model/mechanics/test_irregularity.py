"""Rail–wheel surface deviations Δ_j: their generalized forces and the wheel-force coupling in the
spec's terms (eq. 11's track mass–spring–damper, eq. 8's T = μ N), and Δ = 0 leaving the study's
system as it is."""

from __future__ import annotations

import numpy as np
import pytest

from model import build_model, default_operating_point, load_parameters
from model.analysis.eigen import bogie_system, running_system
from model.mechanics.irregularity import irregularity_forces, irregularity_inputs
from model.mechanics.operating_point import creep_coefficients, damping_matrix


@pytest.fixture(scope="module")
def setup():
    parameters = load_parameters()
    model = build_model(parameters)
    op = default_operating_point(parameters)
    return model, op, irregularity_forces(model, op)


def test_names_follow_the_rims(setup):
    model, _, forces = setup
    assert irregularity_inputs(model) == forces.names == (
        "ID1.rim12.irregularity", "ID1.rim14.irregularity", "ID2.rim12.irregularity",
        "ID2.rim14.irregularity")


def test_a_rise_of_the_rail_pushes_the_rim_up_and_the_contact_forward(setup):
    """A unit Δ_j: k_R upwards on the rim's z, μ(s0) k_R as a longitudinal force at the contact
    point (+x, the sense of the steady traction: e_x − r0 e_ry on the rim); b_R and m_R alike for
    Δ̇ and Δ̈; nothing on any other coordinate."""
    model, op, forces = setup
    p = model.parameters
    mu = creep_coefficients(p, op).mu
    r0 = p["wheel_radius"]
    for j, rim in enumerate(model.rims):
        for G, value in ((forces.G_q, p["track_stiffness"]), (forces.G_v, p["track_damping"]),
                         (forces.G_a, p["track_mass"])):
            column = G[:, j]
            expected = {f"{rim}.z": value, f"{rim}.x": mu * value, f"{rim}.ry": -r0 * mu * value}
            for name, entry in expected.items():
                assert column[model.dofs.index(name)] == pytest.approx(entry, rel=1e-15)
            assert np.count_nonzero(column) == 3


def test_a_wheel_that_follows_the_rail_feels_no_change_of_wheel_force(setup):
    """ΔN_j = k_R (Δ_j − z_j) + b_R (Δ̇_j − ż_j) + m_R (Δ̈_j − z̈_j): a rim moving with the rail
    (z_j = Δ_j) leaves the track's force and the creep force as they were — the input and the
    coupling (with the track's own spring on z) cancel exactly."""
    model, _, forces = setup
    p = model.parameters
    E = np.zeros((model.n, 4))
    for j, index in enumerate(model.rims.values()):
        E[index[2], j] = 1.0
    for G, coupling, own in ((forces.G_q, forces.K_c, p["track_stiffness"]),
                             (forces.G_v, forces.B_c, p["track_damping"]),
                             (forces.G_a, forces.M_c, p["track_mass"])):
        assert np.allclose(G - coupling @ E - own * E, 0.0, rtol=0, atol=1e-12 * np.abs(G).max())


def test_delta_zero_keeps_the_study_system(setup):
    """Δ = 0: the study's system (and so every short-circuit result) is the bogie's as before;
    the running system differs from it by the wheel-force coupling alone, which leaves the rigid
    modes and the rolling velocity exact eigenpairs."""
    model, op, forces = setup
    study = bogie_system(model, op)
    assert np.array_equal(study.M, model.M)
    assert np.array_equal(study.K, model.K)
    assert np.array_equal(study.B, damping_matrix(model, op))
    running = running_system(model, op)
    assert np.array_equal(running.M - forces.M_c, model.M)
    assert np.array_equal(running.K - forces.K_c, model.K)
    assert np.allclose(running.B - forces.B_c, damping_matrix(model, op), rtol=0, atol=0)
    R = model.rigid_body_modes
    assert np.abs(running.K @ R).max() <= 1e-12 * np.abs(model.K).max()
    assert np.abs(running.B @ model.rolling_mode).max() <= 1e-9 * np.abs(running.B).max()
    assert np.all(forces.G_q @ np.zeros(4) == 0)
