"""Rail–wheel surface deviations in the nonlinear response: against the linear running system (its
closed form for the short circuit, its frequency response for a harmonic deviation), the creep
force that follows the varying wheel force, and the checks of the input.

Tolerances, and why:

* Δ = 0 with the tangent law and the short circuit scaled by ε = 1e-6, against the running
  system's closed form: 1e-6 of each load's perturbation peak.  The linear part is that system,
  stepped exactly; what is left is the product ΔN μ0' Δs, O(ε) relative (1e-6 here), and
  rounding (the bogie's tangent check holds 1e-6 as well);
* the two kinds of zero history (harmonic, sampled): 1e-12 of the peaks (the same loop; the
  sampled one adds its exact zeros through other sums);
* harmonic deviation of 1 µm at 20 Hz against the FRF of the running system: 1e-4 of the
  amplitude (and 1e-4 rad of the phase).  The harmonic force is stepped exactly; the product
  term is O(1e-6); what separates the fit from the FRF is the start transient left at 2.5–3 s:
  the slowest modes (|Re λ| < 3 1/s) are fitted beside the sinusoid, the next ones have decayed
  by e^(−3·2.5) ≈ 5e-4 of their start (measured 1.5e-5 at most).  A sampled history of the same
  sinusoid (1 ms samples) takes the first-order hold of the force, error ≈ (ωh)²/12 = 1.3e-5 at
  h = 0.1 ms, and the spline's Δ̈, ≈ (ω Δt)²/12 of its m_R Δ̈ share (≈ 3 % of the force): same
  bound (measured 4.2e-5 at most);
* the creep force within μ_max N_j: 1e-9 relative (|μ| ≤ μ_max is the law's; rounding only);
* the wheel force from the kept states: see its test (a finite difference sets the bound).
"""

from __future__ import annotations

import numpy as np
import pytest

from model import build_model, default_operating_point, load_parameters
from model.analysis.eigen import running_system
from model.analysis.frequency_response import direct_response, solve_irregularity
from model.analysis.nonlinear import NonlinearError, nonlinear_response
from model.analysis.nonlinear_inputs import IrregularityHistory
from model.analysis.response import ShortCircuit, solve_linear
from model.mechanics.operating_point import creep_coefficients, motor_torque
from model.mechanics.outputs import output_matrices

WHEEL = "ID1.rim12.irregularity"
LOADS = ["ID1.driving_shaft.torque", "ID1.disc_clutch.torque", "ID1.axle.wheel_seat_12.torque",
         "ID2.disc_clutch.torque"]


@pytest.fixture(scope="module")
def bogie():
    parameters = load_parameters()
    return parameters, build_model(parameters)


def zero_history() -> IrregularityHistory:
    return IrregularityHistory.harmonic(0.0, 0.0)


# --- Δ = 0 --------------------------------------------------------------------------------------------

def test_no_deviation_and_no_fault_is_the_operating_point(bogie):
    """Without a short circuit and with Δ = 0 nothing moves: every perturbation is zero and every
    wheel force stays N0, exactly."""
    parameters, model = bogie
    op = default_operating_point(parameters, 0.005, 120.0)
    r = nonlinear_response(model, op, t_end=0.05, fs=10_000.0, excitation_scale=0.0,
                           irregularity=zero_history())
    assert all(np.all(r.perturbation(name) == 0.0) for name in r.outputs)
    assert all(np.all(force == op.N0) for force in r.wheel_force.values())


def test_zero_deviation_is_the_running_system(bogie):
    """Δ = 0 given: the short circuit drives the running system (the wheel-force coupling included)
    with T = N μ; with the tangent law and a tiny short circuit that is the running system's
    closed form.  Without irregularities the bogie's (N = N0) is kept: the two differ by the
    coupling."""
    parameters, model = bogie
    op = default_operating_point(parameters, 0.005, 120.0)
    scale = 1e-6
    r = nonlinear_response(model, op, t_end=0.5, fs=10_000.0, creep="tangent", outputs=LOADS,
                           excitation_scale=scale, irregularity=zero_history())
    system = running_system(model, op)
    matrices = output_matrices(model, op)
    rows = [matrices.index(name) for name in LOADS]
    C = system.state_output(matrices.C_q[rows], matrices.C_v[rows])
    u0, a, mu = ShortCircuit().terms(motor_torque(parameters, op))
    y, _, _ = solve_linear(system, C, u0, a, mu, len(r.t), 1e-4, method="expm")
    errors = {name: float(np.abs(r.perturbation(name) / scale - y[:, j]).max()
                          / np.abs(y[:, j]).max()) for j, name in enumerate(LOADS)}
    assert max(errors.values()) <= 1e-6, errors
    plain = nonlinear_response(model, op, t_end=0.5, fs=10_000.0, creep="tangent", outputs=LOADS,
                               excitation_scale=scale)
    assert plain.wheel_force is None
    coupling = max(float(np.abs(plain.perturbation(n) / scale - y[:, j]).max()
                         / np.abs(y[:, j]).max()) for j, n in enumerate(LOADS))
    assert coupling > 1e-2  # the coupling: 3.6e-2 … 0.99 of the peaks (measured)


def test_zero_histories_of_both_kinds_agree(bogie):
    parameters, model = bogie
    op = default_operating_point(parameters, 0.014, 120.0)
    runs = [nonlinear_response(model, op, t_end=0.2, fs=10_000.0, irregularity=history)
            for history in (zero_history(),
                            IrregularityHistory.sampled(np.linspace(0, 0.2, 5), np.zeros((5, 4))))]
    for name in runs[0].outputs:
        scale = np.abs(runs[0].perturbation(name)).max()
        assert np.abs(runs[0].outputs[name] - runs[1].outputs[name]).max() <= 1e-12 * scale
    for rim, force in runs[0].wheel_force.items():
        assert np.abs(force - runs[1].wheel_force[rim]).max() <= 1e-12 * op.N0


def test_the_short_circuit_moves_the_wheel_forces(bogie):
    """With the wheel forces free to vary, the short circuit's torque reaction loads ID1's wheels
    and unloads ID2's by more than a fifth of N0 within 0.3 s (s0 = 0.005, 120 km/h)."""
    parameters, model = bogie
    op = default_operating_point(parameters, 0.005, 120.0)
    r = nonlinear_response(model, op, t_end=0.3, fs=10_000.0, irregularity=zero_history())
    for rim, force in r.wheel_force.items():
        if rim.startswith("ID1."):
            assert force.max() > 1.2 * op.N0, rim
            assert force.min() > 0.95 * op.N0, rim
        else:
            assert force.min() < 0.8 * op.N0, rim
            assert force.max() < 1.05 * op.N0, rim


def test_wheel_force_is_the_states(bogie):
    """The reported N_j is N0 − (m_R (z̈ − Δ̈) + b_R (ż − Δ̇) + k_R (z − Δ)) of the kept states (the
    rim's z and ż; z̈ by central differences of ż at 20 kHz, whose error, ≈ (ω/fs)²/6 of the
    inertia term, sets the bound: 1e-3 of each wheel force's swing, measured 5.6e-5)."""
    parameters, model = bogie
    op = default_operating_point(parameters, 0.005, 120.0)
    history = IrregularityHistory.harmonic(40.0, {"ID2.rim12.irregularity": 2e-4})
    r = nonlinear_response(model, op, t_end=0.3, fs=20_000.0, irregularity=history,
                           keep_states=True)
    system = running_system(model, op)
    p = parameters
    delta, rate, acceleration = history.values(r.t)
    for j, (rim, index) in enumerate(model.rims.items()):
        z = r.states[:, index[2]]
        zd = r.states[:, model.n + int(np.searchsorted(system.inertial, index[2]))]
        zdd = np.gradient(zd, r.t)
        N = op.N0 - (p["track_mass"] * (zdd - acceleration[:, j])
                     + p["track_damping"] * (zd - rate[:, j])
                     + p["track_stiffness"] * (z - delta[:, j]))
        swing = np.ptp(r.wheel_force[rim])
        assert np.abs(N - r.wheel_force[rim])[1:-1].max() <= 1e-3 * swing, rim


# --- a harmonic deviation against the frequency response ------------------------------------------

def steady_harmonic(t: np.ndarray, y: np.ndarray, f: float, slow: np.ndarray) -> complex:
    """Y with y ≈ Re(Y e^(iωt)) + transient, least squares over t; the transient's regressors: a
    constant and the free decay e^(λt) of the eigenvalues ``slow`` [1/s]."""
    w = 2 * np.pi * f
    columns = [np.cos(w * t), np.sin(w * t), np.ones_like(t)]
    for lam in slow:
        e = np.exp(lam * (t - t[0]))
        columns += [e.real, e.imag] if lam.imag > 0 else [e.real]
    c = np.linalg.lstsq(np.column_stack(columns), y, rcond=None)[0]
    return complex(c[0], -c[1])


@pytest.mark.parametrize("kind", ["harmonic", "sampled"])
def test_small_deviation_follows_the_frequency_response(bogie, kind):
    """Δ = a sin(ωt) at ID1's rim 12 (a = 1 µm, 20 Hz), tangent law, no short circuit: the steady
    amplitude and phase of the loads and of the wheel force N_j are the running system's FRF
    (``ID1.rim12.irregularity``) — the inputs' signs and the wheel-force coupling."""
    parameters, model = bogie
    op = default_operating_point(parameters, 0.005, 120.0)
    f, a, t_end = 20.0, 1e-6, 3.0
    if kind == "harmonic":
        history = IrregularityHistory.harmonic(f, {WHEEL: a}, {WHEEL: -90.0})
    else:
        times = np.arange(0.0, t_end + 0.01, 1e-3)
        history = IrregularityHistory.sampled(times, {WHEEL: a * np.sin(2 * np.pi * f * times)})
    r = nonlinear_response(model, op, t_end=t_end, fs=10_000.0, creep="tangent", outputs=LOADS,
                           excitation_scale=0.0, irregularity=history)
    lam = running_system(model, op).eigen[0]
    slow = lam[(np.abs(lam.real) < 3.0) & (lam.imag >= 0)]
    last = r.t >= t_end - 0.5 - 1e-9  # the last ten periods
    w = 2 * np.pi * f
    expected = direct_response(model, op, [f], WHEEL, LOADS)[:, 0] * (-1j * a)  # Δ̂ = −i a
    found = [steady_harmonic(r.t[last], r.perturbation(name)[last], f, slow) for name in LOADS]
    # the wheel force from the rim's vertical motion: N̂ = −(k_R + iω b_R − ω² m_R) (ẑ − Δ̂)
    p = parameters
    C = np.zeros((1, model.n))
    C[0, model.rims["ID1.rim12"][2]] = 1.0
    z = solve_irregularity(model, op, WHEEL, C, np.zeros_like(C), np.array([f]))[0, 0]
    track = p["track_stiffness"] + 1j * w * p["track_damping"] - w * w * p["track_mass"]
    expected = np.append(expected, -track * (z - 1.0) * (-1j * a))
    found.append(steady_harmonic(r.t[last], r.wheel_force["ID1.rim12"][last] - op.N0, f, slow))
    for name, want, got in zip([*LOADS, "N"], expected, found, strict=True):
        assert abs(got - want) <= 1e-4 * abs(want), (name, abs(got - want) / abs(want))
        assert abs(np.angle(got / want)) <= 1e-4, name


# --- a large unloading: the creep force follows N ------------------------------------------------

def test_creep_force_saturates_at_the_varying_wheel_force(bogie):
    """Short circuit at s0 = 0.014 (the creep law driven through its maximum) and a deviation of
    0.3 mm at 80 Hz on ID2's rim 12, which unloads that wheel by more than half: every creep force
    stays within μ_max N_j, it saturates while the wheel is unloaded by a third and more (where
    μ_max N0 would allow half as much again), and the loop's remainder is the varying-N law's."""
    parameters, model = bogie
    op = default_operating_point(parameters, 0.014, 120.0)
    history = IrregularityHistory.harmonic(80.0, {"ID2.rim12.irregularity": 3e-4})
    r = nonlinear_response(model, op, t_end=0.5, fs=10_000.0, irregularity=history)
    rim = "ID2.rim12"
    N = r.wheel_force[rim]
    assert N.min() < 0.5 * op.N0
    for i, name in enumerate(r.wheel_force):
        force, wheel = r.outputs[f"{name}.creep_force"], r.wheel_force[name]
        assert np.all(np.abs(force) <= r.mu_max * wheel * (1 + 1e-9)), name
        # the remainder the loop applied: N μ − N0 μ0 − N0 μ0' Δs − μ0 ΔN
        c = creep_coefficients(parameters, op)
        z = r.contact_velocity[:, i]
        remainder = (force - op.N0 * c.mu - op.N0 * c.dmu_ds * z / op.v
                     - c.mu * (wheel - op.N0))
        assert np.abs(r.remainder_force[:, i] - remainder).max() <= 1e-9 * op.N0 * c.mu, name
    saturated = np.abs(r.utilisation[rim]) > 0.99
    assert saturated.any()
    assert N[saturated].min() < 0.67 * op.N0


# --- input checks ---------------------------------------------------------------------------------------

def test_bad_irregularity_input(bogie):
    parameters, model = bogie
    op = default_operating_point(parameters, 0.005, 120.0)
    cases = [
        ("a", "IrregularityHistory or None"),
        (IrregularityHistory.sampled([0.0, 0.1, 0.2, 0.3], np.zeros((4, 4))), "covers 0 … 0.3 s"),
        (IrregularityHistory.harmonic(600.0, 1e-6), "too high"),
        (IrregularityHistory(names=("a", "b", "c", "d"), frequency=np.zeros(4),
                             amplitude=np.zeros(4, dtype=complex)), "are not the model's"),
    ]
    for irregularity, message in cases:
        with pytest.raises(NonlinearError, match=message) as error:
            nonlinear_response(model, op, t_end=0.5, fs=10_000.0, irregularity=irregularity)
        assert "\n" not in str(error.value)


def test_a_wheel_that_lifts_ends_the_run(bogie):
    parameters, model = bogie
    op = default_operating_point(parameters, 0.005, 120.0)
    history = IrregularityHistory.harmonic(80.0, {"ID2.rim14.irregularity": 2e-3})
    with pytest.raises(NonlinearError, match=r"wheel force of ID2\.rim14 falls to .* lifting off"):
        nonlinear_response(model, op, t_end=0.2, fs=10_000.0, irregularity=history)
