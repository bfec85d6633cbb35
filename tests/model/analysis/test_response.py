"""The exact LTI core of model.analysis.response against hand-derived closed forms.

Single DOF (under- and critically damped, resonance of the excitation with the mode), a free–free
two-mass system (rigid-body ramp/parabola, defective zero eigenvalue), and the excitation of
eq. 23.  Tolerances are rounding-level (1e-9 of the peak): both evaluations are exact.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from model.analysis.response import LinearSystem, ResponseError, ShortCircuit, solve_linear

DT, N = 1e-3, 3001
T = np.arange(N) * DT


def sdof(m: float, c: float, k: float) -> LinearSystem:
    return LinearSystem(np.array([[m]]), np.array([[c]]), np.array([[k]]), np.array([1.0]),
                        np.zeros((1, 0)))


def sdof_formula(m, c, k, u0, a, mu, t):
    """x(t), ẋ(t) of m ẍ + c ẋ + k x = u0 + Re(a e^(μt)), at rest at t = 0 (by hand):
    x = x_p + x_h, x_p = u0/k + Re(a e^(μt) / (m μ² + c μ + k))."""
    H = a / (m * mu**2 + c * mu + k)
    xp0, vp0 = u0 / k + H.real, (mu * H).real
    wn, zeta = math.sqrt(k / m), c / (2 * math.sqrt(k * m))
    xp = u0 / k + (H * np.exp(mu * t)).real
    vp = (mu * H * np.exp(mu * t)).real
    A = -xp0
    if zeta < 1:
        wd = wn * math.sqrt(1 - zeta**2)
        Bc = (zeta * wn * A - vp0) / wd
        e = np.exp(-zeta * wn * t)
        xh = e * (A * np.cos(wd * t) + Bc * np.sin(wd * t))
        vh = -zeta * wn * xh + e * wd * (-A * np.sin(wd * t) + Bc * np.cos(wd * t))
    else:  # critical damping: (A + B t) e^(−ωn t)
        Bc = -vp0 + wn * A
        e = np.exp(-wn * t)
        xh = (A + Bc * t) * e
        vh = Bc * e - wn * xh
    return xp + xh, vp + vh


C_XV = np.array([[1.0, 0.0], [0.0, 1.0]])  # outputs x and ẋ


@pytest.mark.parametrize("method", ["modal", "expm", "auto"])
def test_underdamped_sdof_matches_hand_formula(method):
    m, c, k = 2.0, 3.0, 5000.0
    u0, a, mu = -10.0, 7.0 * np.exp(0.4j), complex(-4.0, 2 * np.pi * 9.0)
    y, used, _ = solve_linear(sdof(m, c, k), C_XV, u0, a, mu, N, DT, method)
    x, v = sdof_formula(m, c, k, u0, a, mu, T)
    assert np.abs(y[:, 0] - x).max() < 1e-9 * np.abs(x).max()
    assert np.abs(y[:, 1] - v).max() < 1e-9 * np.abs(v).max()
    if method != "auto":
        assert used == method


def test_critically_damped_sdof_is_exact_and_auto_avoids_the_defective_eigenbasis():
    m, k = 1.5, 600.0
    c = 2 * math.sqrt(k * m)  # double eigenvalue −ωn with a single eigenvector
    u0, a, mu = 3.0, 0.0j, complex(-1.0, 1.0)
    y, used, _ = solve_linear(sdof(m, c, k), C_XV, u0, a, mu, N, DT, "auto")
    x, v = sdof_formula_critical(m, k, u0, T)
    assert np.abs(y[:, 0] - x).max() < 1e-9 * np.abs(x).max()
    assert np.abs(y[:, 1] - v).max() < 1e-9 * np.abs(v).max()
    assert used == "expm"  # the eigenvector matrix is singular: auto must have switched


def sdof_formula_critical(m, k, u0, t):
    wn = math.sqrt(k / m)
    x = u0 / k * (1 - (1 + wn * t) * np.exp(-wn * t))
    v = u0 / k * wn**2 * t * np.exp(-wn * t)
    return x, v


def test_resonant_excitation_gives_the_secular_term():
    """Undamped SDOF forced exactly at its eigenvalue (μ = iωn): x = F/(2 m ωn) t sin(ωn t)."""
    m, k = 1.0, (2 * np.pi * 5.0) ** 2
    wn = math.sqrt(k / m)
    F = 2.0
    # F sin(ωn t) = Re(−i F e^(iωn t))
    y, used, _ = solve_linear(sdof(m, 0.0, k), C_XV, 0.0, -1j * F, complex(0.0, wn), N, DT,
                              "auto")
    x = F / (2 * m * wn**2) * (np.sin(wn * T) - wn * T * np.cos(wn * T))
    assert np.abs(y[:, 0] - x).max() < 1e-9 * np.abs(x).max()
    assert used == "expm"


def two_mass(c_ground: float) -> LinearSystem:
    m1, m2, k = 3.0, 1.0, 4.0e4
    M = np.diag([m1, m2])
    K = k * np.array([[1.0, -1.0], [-1.0, 1.0]])
    B = np.diag([0.0, c_ground])
    R = np.array([[1.0], [1.0]]) / math.sqrt(2)
    return LinearSystem(M, B, K, np.array([1.0, 0.0]), R)


def test_free_free_two_mass_step_gives_parabola_plus_oscillation():
    """No damping: the rigid mode is a double (defective) zero; by hand
    x_cm = u0 t²/(2(m1+m2)), z = x1 − x2 = u0/(m1 ω²) (1 − cos ωt), ω² = k (m1+m2)/(m1 m2)."""
    m1, m2, k, u0 = 3.0, 1.0, 4.0e4, 50.0
    C = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [k, -k, 0.0, 0.0]])
    y, used, _ = solve_linear(two_mass(0.0), C, u0, 0j, complex(-1, 1), N, DT, "auto")
    w2 = k * (m1 + m2) / (m1 * m2)
    z = u0 / (m1 * w2) * (1 - np.cos(math.sqrt(w2) * T))
    xcm = u0 * T**2 / (2 * (m1 + m2))
    x1, x2 = xcm + m2 / (m1 + m2) * z, xcm - m1 / (m1 + m2) * z
    for column, exact in enumerate((x1, x2, k * z)):
        assert np.abs(y[:, column] - exact).max() < 1e-9 * np.abs(exact).max()
    assert used == "expm"


def test_rigid_mode_with_ground_damping_drifts_as_a_ramp():
    """With a damper c0 to ground (on mass 2) the rigid velocity settles to u0/c0, the positions
    ramp and the spring force settles to c0 v = u0 (by hand); the modal form (now well
    conditioned) must agree with the expm evaluation."""
    k, c0, u0 = 4.0e4, 40.0, 50.0
    system = two_mass(c0)
    C = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [k, -k, 0.0, 0.0]])
    n, dt = 40001, 1e-3  # 40 s, well past the velocity time constant (m1+m2)/c0 = 0.1 s
    y_modal, used, estimate = solve_linear(system, C, u0, 0j, complex(-1, 1), n, dt, "modal")
    y_expm, _, _ = solve_linear(system, C, u0, 0j, complex(-1, 1), n, dt, "expm")
    assert used == "modal"
    assert estimate < 1e-8
    scale = np.abs(y_expm).max(axis=0)
    assert np.all(np.abs(y_modal - y_expm).max(axis=0) < 1e-9 * scale)
    assert y_modal[-1, 1] == pytest.approx(u0 / c0, rel=1e-9)  # steady velocity
    # steady: m2 ẍ2 = 0 = k z − c0 v  ->  spring force k z = c0 v = u0
    assert y_modal[-1, 2] == pytest.approx(u0, rel=1e-6)
    # the position keeps growing linearly: slope u0/c0
    slope = (y_modal[-1, 0] - y_modal[-1001, 0]) / (1000 * dt)
    assert slope == pytest.approx(u0 / c0, rel=1e-9)


def test_short_circuit_torque_is_eq_23():
    e = ShortCircuit(M0=40_000.0, f=90.0, D=0.05, dt=0.001)
    t = np.linspace(0, 0.3, 1001)
    w = 2 * np.pi * 90.0
    expected = -12_000.0 - 40_000.0 * np.exp(-0.05 * w * t) * np.sin(w * (t - 0.001))
    assert np.allclose(e.torque(t, 12_000.0), expected, rtol=0, atol=1e-9)
    assert e.torque(np.array([-0.1]), 12_000.0)[0] == 0.0


def test_default_phase_makes_the_motor_torque_continuous_and_decay_is_gone_at_0_2_s():
    e = ShortCircuit()
    step = 12_800.0
    assert step + e.torque(np.array([0.0]), step)[0] == pytest.approx(step, abs=1e-9)
    envelope = math.exp(-e.D * e.omega * 0.2)
    assert envelope < 0.02  # "after about 0.2 s the oscillating part has died out"
    assert math.exp(-e.D * e.omega * 0.1) > 0.05  # ... and not much earlier


@pytest.mark.parametrize(("kwargs", "word"), [
    ({"M0": -1.0}, "M0"), ({"f": 0.0}, "f"), ({"D": -0.1}, "D"), ({"dt": math.nan}, "dt"),
    ({"M0": "big"}, "M0"), ({"f": math.inf}, "f")])
def test_bad_excitation_is_refused_in_one_line(kwargs, word):
    with pytest.raises(ResponseError, match=word) as info:
        ShortCircuit(**kwargs)
    assert "\n" not in str(info.value)


def test_a_systems_kept_modal_terms_follow_the_excitation():
    """The modal terms kept with a system (a response, its quasi-static part and its peaks ask
    for the same ones) are those of the excitation asked for, not of the one before."""
    from model.analysis.response import _modal_terms, _modal_terms_of

    system = two_mass(c_ground=0.5)
    C = np.eye(system.N)[:2]
    first = _modal_terms(system, C, -1.0, 0.3 + 0.1j, complex(-2.0, 40.0))
    assert _modal_terms(system, C, -1.0, 0.3 + 0.1j, complex(-2.0, 40.0)) is first
    other = _modal_terms(system, C, -1.0, 0.3 + 0.1j, complex(-2.0, 55.0))
    fresh = _modal_terms_of(system, C, -1.0, 0.3 + 0.1j, complex(-2.0, 55.0))
    np.testing.assert_array_equal(other.x_mu, fresh.x_mu)
    np.testing.assert_array_equal(other.coef, fresh.coef)
    assert not np.allclose(other.x_mu, first.x_mu)
