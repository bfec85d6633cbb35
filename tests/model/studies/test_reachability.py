"""The reduced models of model/studies/reachability.py against closed forms and limits, and the
proofs' conclusions on small scans (the full numbers: scripts/reachability.py,
docs/validation.md)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from model import load_parameters
from model.studies.reachability import (
    Chain,
    bounce_two_mass,
    suspension_proof,
    torsional_chain_proof,
)


def test_rigid_chain_spin_is_the_closed_form():
    """k → ∞: the chain turns as one body, its spin −(b + c)/(J1 + J2) exactly."""
    chain = Chain(J1=150.0, J2=250.0, k=1e9, c_dc=0.0, b=500.0)
    for c in (-4000.0, -900.0, 300.0):
        assert chain.spin(c) == pytest.approx(-(500.0 + c) / 400.0, rel=1e-5)


@pytest.mark.parametrize(("c", "b", "zeta"), [(-50.0, 0.0, 0.0), (40.0, 20.0, 0.01),
                                               (-30.0, 10.0, 0.02)])
def test_lightly_damped_twisting_mode_is_the_first_order_closed_form(c, b, zeta):
    """Light damping: Re of the twisting mode −[c r² + b + c_dc (1 + r)²] / (2 m), r = J1/J2,
    m = J1 (J1 + J2)/J2 (1 % — the next order is ζ² ~ 1e-4 here)."""
    chain = Chain.tuned(180.0, 260.0, 2.694, zeta_dc=zeta, b=b)
    assert chain.twisting(c).real == pytest.approx(chain.first_order_twisting_real(c), rel=0.01)
    assert chain.twisting(c).imag / (2 * math.pi) == pytest.approx(2.694, rel=0.01)


def test_twisting_mode_carries_the_spins_real_part_times_J1_over_2J2():
    """b = c_dc = 0: Re_twist = Re_spin · J1 / (2 J2) to first order (the estimate the docs quote)."""
    chain = Chain.tuned(120.0, 300.0)
    c = -20.0
    spin = chain.spin(c)
    assert spin == pytest.approx(-c / 420.0, rel=1e-3)
    assert chain.twisting(c).real == pytest.approx(spin * 120.0 / 600.0, rel=0.01)


def test_creep_damper_for_a_spin_gives_that_spin():
    chain = Chain.tuned(200.0, 250.0, zeta_dc=0.1, b=60 * 16.0)
    c = chain.creep_damper_for_spin(7.031)
    assert c < 0
    assert chain.spin(c) == pytest.approx(7.031, rel=1e-9)


def test_twisting_mode_less_damped_as_the_creep_damper_falls():
    """Re_twist rises monotonically as c falls (the proof's argument: c14 < 0 <= c5)."""
    chain = Chain.tuned(250.0, 220.0, zeta_dc=0.05, b=960.0)
    re = [chain.twisting(c).real for c in np.linspace(2000.0, -3000.0, 26)]
    assert np.all(np.diff(re) > 0)


def test_small_scan_finds_mode2_always_less_damped_at_the_divergence():
    """On a 2^5 scan of the plausible box with the +7.031 spin, every chain with the study's
    mode 2 frequencies has Re(0.014) − Re(0.005) > 0, and none reaches the study's −0.019 1/s."""
    p = load_parameters()
    proof = torsional_chain_proof(p["gear_inertia"], p["pinion_inertia"], 7.031, points=2)
    assert proof.scanned == 32
    with_mode2 = proof.with_mode2_frequency(proof.cases)  # b_M = 0 included
    assert with_mode2
    assert all(case.difference > 0 for case in with_mode2)
    assert not proof.reachable
    assert proof.published_difference == pytest.approx(-0.019)


def test_two_mass_bounce_matches_a_hand_solution_without_damping():
    """Undamped, the two-mass bounce's frequencies are the roots of the 2x2 eigenproblem."""
    p = load_parameters().replace(primary_damping_z=0.0, secondary_damping_z=0.0)
    m2 = 11_000.0
    lam = bounce_two_mass(p, m2)
    M, ks, kp = p["car_body_mass"], 4 * p["secondary_stiffness_z"], 4 * p["primary_stiffness_z"]
    # det(K − ω² M) = 0: M m2 ω⁴ − (M (ks + kp) + m2 ks) ω² + ks kp = 0
    a, b, c = M * m2, -(M * (ks + kp) + m2 * ks), ks * kp
    omega2 = sorted(np.roots([a, b, c]).real)
    assert np.allclose(lam.real, 0.0, atol=1e-9)
    assert lam.imag == pytest.approx(np.sqrt(omega2), rel=1e-9)


@pytest.mark.slow
def test_suspension_proof_on_the_bundled_set():
    """The full model's suspension modes with the vertical dampers at their hardware lower
    bounds: the real part is linear in the dampers' rates below their bounds (first order:
    within 1 % of the full solve at half the bounds), the car body bounce's sensitivity to the
    secondary dampers agrees with the two-mass reduced model (30 %: measured 6 % on the bundled
    set — the frame's pitch, the motors on their silent blocks and the car body's longitudinal
    coupling are not in it; the proof's factors are 10-100x), and no published real part is
    reachable within the bounds."""
    p = load_parameters()
    proof = suspension_proof(p)
    by_row = {m.row: m for m in proof.modes}
    for mode in proof.modes:
        assert mode.re_first_order == pytest.approx(mode.re_at_half_bounds, rel=0.01)
        assert not mode.reachable
        assert mode.re_at_lower_bounds < mode.published_re
        assert mode.scale_needed < 1  # below the bounds (< 0: not even without the dampers)
    m2 = p["frame_mass"] + 2 * (p["stator_mass"] + p["rotor_mass"] + p["pinion_mass"])
    h = 1e-3 * p["secondary_damping_z"]
    up = bounce_two_mass(p.replace(secondary_damping_z=p["secondary_damping_z"] + h), m2)[0]
    down = bounce_two_mass(p.replace(secondary_damping_z=p["secondary_damping_z"] - h), m2)[0]
    reduced = (up.real - down.real) / (2 * h)
    assert by_row[1].slopes["secondary_damping_z"] == pytest.approx(reduced, rel=0.3)
