"""The reduced models of model/studies/reachability.py and wheelset_reachability.py against
closed forms and limits, and the proofs' conclusions on small scans (the full numbers: scripts/reachability.py,
docs/validation.md)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from model import load_parameters
from model.mechanics.operating_point import creep_coefficients
from model.studies.calibration_targets import reference_point
from model.studies.reachability import (
    Chain,
    bounce_two_mass,
    suspension_proof,
    torsional_chain_proof,
)
from model.studies.wheelset_reachability import (
    clamped_modes,
    creep_slope_relation,
    full_ranks,
    key_inequality_ratio,
    realize_case,
    wheelset_model,
    yaw_proof,
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


# --- (c) the wheelsets' longitudinal and yaw modes ---------------------------------------------

@pytest.fixture(scope="module")
def wheelset():
    return wheelset_model(load_parameters())


def test_wheelset_model_reproduces_the_full_model_of_the_bundled_set(wheelset):
    """The single-wheelset model against the full model's drive 1 under a clamped frame, with the
    set's creep at both creepages: frequencies within 1 % (measured 0.3 %), real parts within 8 %
    (measured 4.6 %: the reduced model leaves out the rubber parts' own damping and the x–yaw
    coupling of the drive's lateral asymmetry), the spin within 1 % (0.15 %).  Against the whole
    model: its ranks 7 and 10 (the pairs whose frame reactions nearly cancel) within 1 %
    (0.2 %, 0.08 %), the divergence within 5 % (2.8 %: the frame and the car body move)."""
    p = load_parameters()
    for s0 in (0.005, 0.014):
        b11 = creep_coefficients(p, reference_point(p, s0)).b11
        clamped = clamped_modes(p, b11)
        for key, lam in (("longitudinal", wheelset.longitudinal(b11)), ("yaw", wheelset.yaw(b11))):
            assert lam.imag == pytest.approx(clamped[key].imag, rel=0.01)
            assert lam.real == pytest.approx(clamped[key].real, rel=0.08)
        if s0 == 0.014:
            assert wheelset.spin(b11) == pytest.approx(clamped["spin"].real, rel=0.01)
    b5 = creep_coefficients(p, reference_point(p, 0.005)).b11
    b14 = creep_coefficients(p, reference_point(p, 0.014)).b11
    full = full_ranks(p)
    assert wheelset.longitudinal(b5).imag / (2 * math.pi) == pytest.approx(
        full.frequencies_hz[0], rel=0.01)
    assert wheelset.yaw(b5).imag / (2 * math.pi) == pytest.approx(full.frequencies_hz[3], rel=0.01)
    assert wheelset.spin(b14) == pytest.approx(full.divergence, rel=0.05)


def test_wheelset_model_limits(wheelset):
    """No creep: the longitudinal and yaw modes are √(K_x/m) and √(K_ψ/I) exactly (how the
    drive's shares were identified); the yaw's real part is −(2 e² b11 + 2 b33)/(2 I) exactly;
    a stiff disc clutch makes the spin the rigid −2 r0² b11/(J_w + J1) (1 %: the wheelset's
    longitudinal motion on its guides takes part, 0.5 % on the bundled set)."""
    assert wheelset.longitudinal(0.0) == pytest.approx(
        1j * math.sqrt(wheelset.stiffness_x / wheelset.mass), abs=1e-9)
    assert wheelset.yaw(0.0).imag == pytest.approx(
        math.sqrt(wheelset.stiffness_yaw / wheelset.yaw_inertia - wheelset.yaw(0.0).real**2))
    e, I_yaw = wheelset.contact_half_distance, wheelset.yaw_inertia
    for b11 in (-4000.0, 12000.0):
        assert wheelset.yaw(b11).real == pytest.approx(
            -(2 * e**2 * b11 + 2 * wheelset.spin_creep) / (2 * I_yaw), rel=1e-12)
    stiff = replace(wheelset, disc_clutch_stiffness=1e10)
    r0, b11 = wheelset.wheel_radius, -3000.0
    rigid = -2 * r0**2 * b11 / (wheelset.spin_inertia + wheelset.drive_inertia)
    assert stiff.spin(b11) == pytest.approx(rigid, rel=0.01)
    assert wheelset.spin(wheelset.b11_for_spin(7.031)) == pytest.approx(7.031, rel=1e-9)


def test_key_inequality_gives_the_published_yaw_real_parts():
    """A single-DOF yaw with I = key_inequality_ratio(R) · J_eff, its creep dampers from the
    divergence (b11(0.014) = −λ J_eff/(2 r0²), b11(0.005) = R |b11(0.014)|) and the other yaw
    damping d that Re(0.014) leaves has both published real parts of rank 9 exactly; d >= 0 needs
    R <= −Re5/Re14 = 4.345."""
    e, r0, lam, J_eff = 0.75, 0.625, 7.031, 300.0
    re5, re14 = -3.958, 0.911
    for R in (2.8, 3.29, 3.5):
        I_yaw = key_inequality_ratio(R, re5, re14) * J_eff
        b14 = -lam * J_eff / (2 * r0**2)
        X = e**2 * -b14 / I_yaw  # e² N0 |μ'14| / (v I)
        d = 2 * I_yaw * (X - re14)
        assert d >= 0
        for b11, published in ((-R * b14, re5), (b14, re14)):
            assert -(2 * e**2 * b11 + d) / (2 * I_yaw) == pytest.approx(published, rel=1e-12)
    assert -re5 / re14 == pytest.approx(4.345, abs=1e-3)


def test_creep_laws_that_meet_the_operating_data_have_a_narrow_slope_ratio():
    """Stage A on a 3x3x3 grid of the creep-shape box: every law that meets the four operating
    data has R = ∂μ/∂s(0.005)/|∂μ/∂s(0.014)| between 2.5 and 4 — below the 4.345 the study's
    yaw real parts allow (the key inequality's d >= 0), while |∂μ/∂s(0.014)| spreads over
    more than a factor 5 (the divergence picks it)."""
    met = [c for c in creep_slope_relation(load_parameters(), points=3) if c.met]
    assert len(met) >= 5
    assert all(2.5 <= c.ratio <= 4.0 for c in met)
    slopes = [-c.dmu_unstable for c in met]
    assert max(slopes) / min(slopes) > 5


def test_small_scan_separates_the_modes_most_with_the_heaviest_drive():
    """The single wheelset's yaw frequency with its longitudinal mode at rank 7's cap is highest
    for the heaviest drive (J_rotor and J_w at their upper ends): more creep damping at 0.005 for
    the same divergence adds more of the spin inertia to the longitudinal mode only."""
    proof = yaw_proof(load_parameters(), points=2, creep_points=2)
    cap = min(c.longitudinal_cap_hz for c in proof.cases)
    best = proof.best(cap)
    assert best.J_rotor == pytest.approx(24.0)
    assert best.spin_inertia == pytest.approx(400.0)
    light = min((c for c in proof.cases if c.longitudinal_cap_hz == cap),
                key=lambda c: c.effective_spin_inertia)
    assert light.yaw_hz < best.yaw_hz


@pytest.mark.slow
def test_best_scanned_wheelset_in_the_full_model():
    """The scan's best case (longitudinal at rank 7's cap, the published divergence) carried into
    the full model: the divergence stays within 10 %, rank 9 (the in-phase yaw, lowered by the
    frame) misses its 5 % acceptance (docs/validation.md: −6.3 %)."""
    p = load_parameters()
    proof = yaw_proof(p, points=2, creep_points=3)
    cap = min(c.longitudinal_cap_hz for c in proof.cases)
    full = full_ranks(realize_case(p, proof.best(cap, exact_divergence=True)))
    assert abs(full.divergence / 7.031 - 1) <= 0.1
    assert full.errors[2] < -0.05
