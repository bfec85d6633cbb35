"""The torsional fatigue check (DIN 743, simplified) against hand calculations of its formulas.

No worked example of DIN 743 (the standard's supplement, a textbook's) could be retrieved and
checked here, so the reference is the chain of DIN 743-1/-2/-3's formulas written out below once
more, independently of the module (the size factors K1 and K2, the roughness factor K_Fτ, the
total influence factor K_τ, the fatigue limit τ_WK, the mean stress sensitivity ψ_τK and the
permissible amplitude of case 1), and the properties the standard states: K2 = 0.8 from 150 mm,
K1 = 0.67 beyond 300 mm, K_F = 1 for a polished surface, the two branches of τ_ADK meeting at the
yield knee.
"""

from __future__ import annotations

import math

import pytest

from model.analysis.fatigue import (
    FatigueError,
    fatigue_safety,
    geometric_size_factor,
    permissible_amplitude,
    roughness_factor_torsion,
    technological_size_factor,
    torsional_fatigue,
)

MPA = 1e6


def _hand(sigma_B_ref, d_ref, D, beta, R_z_um, tau_F, tau_m):
    """DIN 743 by hand, in the standard's own units (mm, N/mm²): K1 for a quenched and tempered
    steel (d_B = 16 mm; the strength scaled from the diameter it is given for), K2 for bending and
    torsion (0.8 from 150 mm), K_Fσ and K_Fτ = 0.575 K_Fσ + 0.425, K_τ = β_τ/K2 + 1/K_Fτ − 1, τ_W = 0.3 σ_B(d),
    τ_WK = τ_W/K_τ, ψ_τK = τ_WK/(2 σ_B(d) − τ_WK), τ_ADK = τ_WK − ψ_τK |τ_m| (below the yield
    knee)."""
    def k1(d_mm):
        return 1.0 if d_mm <= 16 else 1 - 0.26 * math.log10(d_mm / 16)

    sigma = sigma_B_ref * k1(D) / k1(d_ref)
    k2 = 0.8 if D >= 150 else 1 - 0.2 * math.log10(D / 7.5) / math.log10(20)
    k_f_sigma = 1 - 0.22 * math.log10(R_z_um) * (math.log10(sigma / 20) - 1)
    k_f_tau = 0.575 * k_f_sigma + 0.425
    k_tau = beta / k2 + 1 / k_f_tau - 1
    tau_wk = 0.3 * sigma / k_tau
    psi = tau_wk / (2 * sigma - tau_wk)
    knee = (tau_F - tau_wk) / (1 - psi)
    assert abs(tau_m) < knee  # the example stays on the fatigue branch
    return {"sigma_B": sigma, "K2": k2, "K_F": k_f_tau, "K_tau": k_tau, "tau_WK": tau_wk,
            "psi": psi, "tau_ADK": tau_wk - psi * abs(tau_m)}


@pytest.mark.parametrize(("sigma_B_ref", "d_ref", "D", "d_i", "beta", "R_z_um", "tau_m"), [
    pytest.param(1000, 16, 120, 0, 1.8, 6.3, 40, id="driving shaft, 42CrMo4 from d_B"),
    pytest.param(1000, 16, 120, 0, 1.8, 6.3, -40, id="the mean's sign does not matter"),
    pytest.param(550, 190, 190, 0, 1.3, 10, 25, id="axle, strength at its own size"),
    pytest.param(1100, 16, 60, 30, 2.2, 25, 100, id="a bored 60 mm shaft, rough"),
])
def test_fatigue_chain_equals_the_hand_calculation(sigma_B_ref, d_ref, D, d_i, beta, R_z_um,
                                                   tau_m):
    hand = _hand(sigma_B_ref, d_ref, D, beta, R_z_um, 375, tau_m)
    data = torsional_fatigue(sigma_B_ref * MPA, d_ref * 1e-3, D * 1e-3, d_i * 1e-3, beta,
                             R_z_um * 1e-6, 375 * MPA)
    assert data.sigma_B == pytest.approx(hand["sigma_B"] * MPA, rel=1e-12)
    assert data.K2 == pytest.approx(hand["K2"], rel=1e-12)
    assert data.K_F == pytest.approx(hand["K_F"], rel=1e-12)
    assert data.K_tau == pytest.approx(hand["K_tau"], rel=1e-12)
    assert data.tau_WK == pytest.approx(hand["tau_WK"] * MPA, rel=1e-12)
    assert data.psi == pytest.approx(hand["psi"], rel=1e-12)
    assert permissible_amplitude(data, tau_m * MPA) == pytest.approx(hand["tau_ADK"] * MPA,
                                                                   rel=1e-12)
    tau_a = 0.5 * hand["tau_ADK"] * MPA
    assert fatigue_safety(data, tau_m * MPA, tau_a) == pytest.approx(2.0, rel=1e-12)
    assert data.section_modulus == pytest.approx(
        math.pi * ((D * 1e-3) ** 4 - (d_i * 1e-3) ** 4) / (16 * D * 1e-3), rel=1e-12)


def test_size_and_roughness_factors_at_the_standards_limits():
    assert geometric_size_factor(0.005) == 1.0
    assert geometric_size_factor(0.0075) == pytest.approx(1.0)
    assert geometric_size_factor(0.1499999) == pytest.approx(0.8, abs=1e-6)  # continuous at 150 mm
    assert geometric_size_factor(0.25) == 0.8
    assert technological_size_factor(0.010) == 1.0
    assert technological_size_factor(0.016) == 1.0
    assert technological_size_factor(0.2999) == pytest.approx(0.67, abs=2e-3)  # the standard's 0.67
    assert technological_size_factor(0.5) == 0.67
    assert roughness_factor_torsion(0.8e-6, 1e9) == 1.0  # polished
    # rougher and stronger: a smaller factor; torsion feels roughness less than bending
    assert roughness_factor_torsion(25e-6, 1e9) < roughness_factor_torsion(6.3e-6, 1e9) < 1.0
    assert roughness_factor_torsion(25e-6, 1.2e9) < roughness_factor_torsion(25e-6, 0.6e9)


def test_a_strength_given_at_the_parts_own_size_is_not_scaled():
    own = torsional_fatigue(550e6, 0.19, 0.19, 0.0, 1.3, 10e-6, 185e6)
    assert own.K1 == 1.0
    assert own.sigma_B == 550e6
    table = torsional_fatigue(550e6, 0.016, 0.19, 0.0, 1.3, 10e-6, 185e6)
    assert table.sigma_B == pytest.approx(550e6 * (1 - 0.26 * math.log10(190 / 16)))


def test_mean_stress_lowers_the_amplitude_down_to_the_yield_limit():
    """Below the knee the permissible amplitude falls with slope ψ; beyond it the largest stress
    reaches the yield limit (τ_ADK = τ_FK − τ_mv); the branches meet at the knee; none is
    negative."""
    data = torsional_fatigue(1000e6, 0.016, 0.12, 0.0, 1.8, 6.3e-6, 375e6)
    assert permissible_amplitude(data, 0.0) == data.tau_WK
    knee = (data.tau_FK - data.tau_WK) / (1 - data.psi)
    assert permissible_amplitude(data, knee) == pytest.approx(data.tau_FK - knee, rel=1e-12)
    assert permissible_amplitude(data, knee * 1.1) == pytest.approx(data.tau_FK - 1.1 * knee)
    assert permissible_amplitude(data, 2 * data.tau_FK) == 0.0
    assert fatigue_safety(data, 0.0, 0.0) == math.inf


@pytest.mark.parametrize(("arguments", "message"), [
    ((0.0, 0.016, 0.12, 0.0, 1.8, 6.3e-6, 375e6), "the tensile strength must be > 0"),
    ((-1e9, 0.016, 0.12, 0.0, 1.8, 6.3e-6, 375e6), "the tensile strength must be > 0"),
    ((1e9, 0.016, 0.12, 0.12, 1.8, 6.3e-6, 375e6), "need 0 <= bore < outer diameter"),
    ((1e9, 0.016, 0.12, 0.0, 0.9, 6.3e-6, 375e6), "the notch factor beta_tau must be >= 1"),
    ((1e9, 0.016, 0.12, 0.0, 1.8, 6.3e-6, 0.0), "the shear yield limit must be > 0"),
])
def test_bad_fatigue_data_are_refused_in_one_line(arguments, message):
    with pytest.raises(FatigueError, match=message) as error:
        torsional_fatigue(*arguments)
    assert "\n" not in str(error.value)
