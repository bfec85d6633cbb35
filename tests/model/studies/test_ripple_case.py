"""The ripple load case: its amplitudes against the steady state of a long time response (exact
propagation of the state space, each motor alone, then added as the case adds them), its refined
speed grid against a brute-force sweep around a resonance, what the case states, bad input."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla

from model.analysis.assessment import AlternatingLoad
from model.analysis.campbell import MOTOR_INPUTS
from model.analysis.eigen import bogie_system
from model.analysis.frequency_response import input_force
from model.mechanics.excitation import ExcitationError, Order, load_excitation, parse_amplitudes
from model.mechanics.operating_point import KMH, damping_matrix
from model.mechanics.outputs import output_matrices, static_deflection
from model.mechanics.parameters import load_parameters
from model.studies.assessment import (
    AssessmentError,
    AssessmentOptions,
    assessed_outputs,
    assessment_of,
    operating_point,
    ripple_load_case,
)
from model.studies.maps import cached_model
from model.studies.ripple_case import (
    RippleCaseError,
    RippleSweep,
    envelope_loads,
    ripple_amplitudes,
    ripple_sweep,
)


def _sweep(parameters, outputs, options):
    """The sweep the ripple case computes with these options."""
    points = [operating_point(parameters, s0, options.ripple_v[0], options) for s0 in options.s0]
    ripple = options.ripple if options.ripple is not None else ripple_amplitudes(parameters)
    return ripple_sweep(cached_model(parameters), points, options.ripple_v, ripple,
                        load_excitation(), outputs)


@pytest.fixture(scope="module")
def setup():
    """The case at one creepage (the default speed grid, the set's ripple), its sweep and checks."""
    parameters = load_parameters()
    options = AssessmentOptions(s0=(0.005,))
    outputs = assessed_outputs(parameters)
    sweep = _sweep(parameters, outputs, options)
    case = ripple_load_case(sweep, parameters, options)
    assessment = assessment_of(parameters, [case])
    return parameters, options, sweep, case, {c.component + " / " + c.kind: c
                                              for c in assessment.checks}


def _steady_amplitudes(system, C: np.ndarray, inputs: list[tuple[np.ndarray, float]],
                       t_long: float, steps: int = 32, periods: int = 40) -> np.ndarray:
    """Steady complex amplitudes (p x inputs) of y = C x under each input b_j cos(2π f_j t) alone,
    from rest: the state and one (cos, sin) generator per input propagated exactly together (the
    matrix exponential of one step, the first ``t_long`` seconds by repeated squaring), each
    input's response started from its own generator, then a + b cos + c sin + a slow quadratic
    drift fitted over ``periods`` periods of the lowest frequency.  The frequencies must be whole
    multiples of the lowest (the electrical harmonics of one speed are).  The method of
    tests/model/analysis/test_frequency_response.py, for several inputs at once."""
    A = system.A
    N, k = A.shape[0], len(inputs)
    f_low, f_high = min(f for _, f in inputs), max(f for _, f in inputs)
    h = 1.0 / (f_high * steps)
    F = np.zeros((N + 2 * k, N + 2 * k))
    F[:N, :N] = A
    start = np.zeros((N + 2 * k, k))
    for j, (b, f_hz) in enumerate(inputs):
        g = N + 2 * j
        F[:N, g] = b
        w = 2 * np.pi * f_hz
        F[g:g + 2, g:g + 2] = [[0.0, -w], [w, 0.0]]
        start[g, j] = 1.0
    step = sla.expm(F * h)
    count = round(t_long / h)
    z = np.linalg.matrix_power(step, count) @ start
    samples = round(periods * f_high / f_low) * steps
    t = (count + np.arange(samples)) * h
    y = np.empty((samples, C.shape[0], k))
    for i in range(samples):
        y[i] = C @ z[:N]
        z = step @ z
    tau = (t - t[0]) / (t[-1] - t[0])
    out = np.empty((C.shape[0], k), dtype=complex)
    for j, (_, f_hz) in enumerate(inputs):
        w = 2 * np.pi * f_hz
        basis = np.column_stack([np.cos(w * t), np.sin(w * t), np.ones_like(t), tau, tau**2])
        coefficients, *_ = np.linalg.lstsq(basis, y[:, :, j], rcond=None)
        out[:, j] = coefficients[0] - 1j * coefficients[1]
    return out


@pytest.mark.parametrize("check_name", ["ID1 driving shaft / torsional_fatigue",
                                        "ID2 driving shaft / torsional_fatigue",
                                        "ID2 claw clutch / coupling_vibratory"])
def test_amplitude_at_the_worst_speed_is_the_steady_state_of_a_time_response(setup, check_name):
    """At the check's worst speed each motor's torque ripple A_k cos(2π f_k t) alone is propagated
    from rest (no frequency response, no eigendecomposition) and its steady amplitude fitted;
    each motor's share of each order equals the case's (the sweep) within 1e-4 of itself or
    1e-10 of the largest response, and the sum over both motors (magnitudes: the worst phase)
    and the orders equals the check's alternating amplitude within 1e-4.  The tolerance is that
    of the frequency response against the same reference (tests/model/analysis/
    test_frequency_response.py); measured here: 1e-9 for the sums, at most 1e-6 for one motor's
    share (ID1's 12th harmonic in ID2's driving shaft, three orders below the other shares).
    The reference runs 200 s before its fit: the slowest oscillating mode the motors drive (the
    rotor-with-gears mode, 2.65 Hz, ζ ≈ 0.005 at 10 km/h) decays at about 0.08 1/s, so its
    start-up transient is down to e^-16 of itself (after 12 s it was still a third, and ID2's
    claw clutch at 10 km/h was off by 1.5e-3).  The first two checks are the two driving shafts'
    resonances (ID1's at ζ ≈ 0.002, ID2's more damped by its motor's slope), the third a check
    at the bottom of the speed range."""
    parameters, options, sweep, _, checks = setup
    check = checks[check_name]
    assert check.load_case == "ripple"
    model = cached_model(parameters)
    excitation = load_excitation()
    i = int(np.argmin(np.abs(sweep.v - check.v_kmh * KMH)))
    assert sweep.v[i] == pytest.approx(check.v_kmh * KMH, rel=1e-12)
    op = operating_point(parameters, check.scenario["s0"], float(sweep.v[i]), options)
    system = bogie_system(model, op)
    matrices = output_matrices(model, op)
    row = matrices.index(check.output)
    C = system.state_output(matrices.C_q[[row]], matrices.C_v[[row]])
    ripple = ripple_amplitudes(parameters)
    inputs, labels = [], []
    for m, motor in enumerate(MOTOR_INPUTS):
        b = system.input_map(input_force(model, motor)[0])
        for k, (order, amplitude) in enumerate(ripple.items()):
            f_hz = float(order.frequency_hz(sweep.v[i], parameters, excitation))
            assert f_hz == pytest.approx(check.orders[k]["f_hz"], rel=1e-12)
            inputs.append((amplitude * b, f_hz))
            labels.append((m, k))
    reference = np.abs(_steady_amplitudes(system, C, inputs, t_long=200.0)[0])
    j = sweep.names.index(check.output)
    a = sweep.s0.index(check.scenario["s0"])
    floor = 1e-10 * reference.max()
    for (m, k), value in zip(labels, reference, strict=True):
        assert sweep.by_motor[a, m, k, j, i] == pytest.approx(value, rel=1e-4, abs=floor), (m, k)
    assert check.alternating == pytest.approx(reference.sum(), rel=1e-4)
    for k, share in enumerate(check.orders):
        assert share["amplitude"] == pytest.approx(
            sum(v for (_, kk), v in zip(labels, reference, strict=True) if kk == k), rel=1e-4)


def test_the_refined_grid_finds_the_resonance_peak(setup):
    """ID1's driving shaft peaks where the 6th electrical harmonic meets its 298 Hz mode (ζ ≈
    0.002: a half-power width of 2ζv, 0.35 km/h at 87 km/h, narrower than the 10 km/h grid).  A
    brute-force sweep of the case's amplitude (both motors, both orders, direct solves) over
    401 speeds within ±0.5 % of the case's worst speed — about ±2.5 half-power half-widths, so
    the peak lies inside, at a spacing of 0.0125 half-widths, where the height between two points
    differs from the peak by less than 1e-4 — finds no height more than 1 % above the case's,
    and none below it beyond rounding; without the refinement the grid would miss the peak by
    far more than 1 %."""
    parameters, options, sweep, _, checks = setup
    check = checks["ID1 driving shaft / torsional_fatigue"]
    model = cached_model(parameters)
    excitation = load_excitation()
    ripple = ripple_amplitudes(parameters)
    forces = np.column_stack([input_force(model, motor)[0] for motor in MOTOR_INPUTS])
    v_star = check.v_kmh * KMH
    speeds = v_star * np.linspace(0.995, 1.005, 401)
    heights = np.zeros(len(speeds))
    for i, speed in enumerate(speeds):
        op = operating_point(parameters, check.scenario["s0"], float(speed), options)
        matrices = output_matrices(model, op)
        row = matrices.index(check.output)
        damping = damping_matrix(model, op)
        for order, amplitude in ripple.items():
            w = 2 * np.pi * float(order.frequency_hz(speed, parameters, excitation))
            q = np.linalg.solve(-w * w * model.M + 1j * w * damping + model.K, forces)
            heights[i] += amplitude * np.abs((matrices.C_q[row] + 1j * w * matrices.C_v[row]) @ q).sum()
    assert 0 < np.argmax(heights) < len(speeds) - 1  # the peak is inside the brute-force range
    assert check.alternating >= 0.99 * heights.max()
    assert check.alternating <= heights.max() * (1 + 1e-6)
    j = sweep.names.index(check.output)
    coarse = np.isin(sweep.v, np.asarray(options.ripple_v))
    assert sweep.alternating_by_order[0, :, j, coarse].sum(axis=1).max() < 0.5 * heights.max()


def test_the_case_states_its_speeds_orders_amplitudes_and_mean(setup):
    """The case names its grid, the speeds the refinement added, the orders and amplitudes of the
    set; the mean is the steady traction's static load at the same speed; a load is stated at every
    speed of the refined grid."""
    parameters, options, sweep, case, checks = setup
    assert case.name == "ripple"
    assert case.alternating
    assert case.horizon is None
    assert case.scenario["v_kmh"] == pytest.approx(list(np.asarray(options.ripple_v) / KMH))
    assert case.scenario["v_kmh"][0] == pytest.approx(10.0)
    assert case.scenario["v_kmh"][-1] == pytest.approx(200.0)
    assert len(case.scenario["v_kmh_refined"]) >= 2
    assert case.scenario["orders"] == [{"order": "el:6", "amplitude": parameters["ripple_el6_amplitude"]},
                                       {"order": "el:12", "amplitude": parameters["ripple_el12_amplitude"]}]
    assert case.scenario["motor_bandwidth"] == parameters["motor_bandwidth"]
    assert "magnitudes" in case.description
    assert len(checks) == 16
    model = cached_model(parameters)
    check = checks["ID1 gear seat / press_fit_slip"]
    op = operating_point(parameters, check.scenario["s0_mean"], check.v_kmh * KMH, options)
    matrices = output_matrices(model, op)
    static = (matrices.C_q @ static_deflection(model, op))[matrices.index(check.output)]
    assert check.mean == pytest.approx(static, rel=1e-12)
    assert check.load == pytest.approx(abs(check.mean) + check.alternating, rel=1e-12)
    for load in case.loads.values():
        assert isinstance(load, AlternatingLoad)
        assert len(load.mean) == len(load.alternating) == len(sweep.v)
        np.testing.assert_allclose(load.by_order.sum(axis=0), load.alternating, rtol=1e-12)


def test_the_envelope_over_creepages_keeps_the_largest_mean_and_amplitude():
    """Two creepages: per speed the mean of largest magnitude and the largest amplitude, each
    from its own creepage (a synthetic sweep: the rule, not the physics)."""
    v = np.array([10.0, 20.0]) * KMH
    by_motor = np.zeros((2, 2, 1, 1, 2))
    by_motor[0, :, 0, 0, :] = [[1.0, 5.0], [1.0, 5.0]]  # s0 = 0.002: 2, 10 (both motors)
    by_motor[1, :, 0, 0, :] = [[3.0, 1.0], [3.0, 1.0]]  # s0 = 0.005: 6, 2
    mean = np.array([[[-100.0, 50.0]], [[80.0, -70.0]]])
    sweep = RippleSweep(v, np.array([]), (0.002, 0.005), (Order("el", 6.0),), np.array([256.0]),
                        np.array([[60.0, 120.0]]), ("x",), by_motor, mean)
    (load,) = envelope_loads(sweep).values()
    assert load.mean.tolist() == [-100.0, -70.0]
    assert load.alternating.tolist() == [6.0, 10.0]
    assert [s["s0"] for s in load.scenarios] == [0.005, 0.002]
    assert [s["s0_mean"] for s in load.scenarios] == [0.002, 0.005]


def test_an_override_ripple_and_a_fixed_frequency_are_taken():
    """The options' ripple replaces the set's (a fixed frequency too; the frequency is the same
    at every speed)."""
    parameters = load_parameters()
    options = AssessmentOptions(s0=(0.005,), ripple=parse_amplitudes("el:6=100,fixed:450=50"),
                                ripple_v=tuple(np.array([60.0, 120.0]) * KMH))
    sweep = _sweep(parameters, ["ID1.driving_shaft.torque"], options)
    assert sweep.orders == (Order("el", 6.0), Order("fixed", 450.0))
    assert sweep.ripple.tolist() == [100.0, 50.0]
    np.testing.assert_allclose(sweep.frequencies_hz[1], 450.0)


@pytest.mark.parametrize(("options", "message"), [
    ({"ripple": {Order("el", 6.0): -1.0}}, "the amplitude of el:6 must be a number in [0, 1e7] N m"),
    ({"ripple": {Order("el", 6.0): float("nan")}}, "the amplitude of el:6 must be a number"),
    ({"ripple": {"el:6": 256.0}}, "'el:6' is not an excitation order"),
    ({"ripple": {}}, "give at least one order=amplitude"),
    ({"ripple": {Order("fixed", 1500.0): 10.0}}, "fixed frequency 1500 Hz is beyond the model's"),
    ({"ripple_v": (10.0,)}, "ripple speeds: give 2 to"),
    ({"ripple_v": (20.0, 10.0)}, "ripple speeds: give 2 to"),
    ({"cases": ("ripple", "gale")}, "load cases: give distinct names of"),
])
def test_bad_ripple_options_are_refused_in_one_line(options, message):
    with pytest.raises(AssessmentError) as error:
        AssessmentOptions(**options)
    assert message in str(error.value)
    assert "\n" not in str(error.value)


@pytest.mark.parametrize(("text", "message"), [
    ("el:6=-256", "the amplitude must be in [0, 1e7] N m"),
    ("el:x=256", "the order must be a number"),
    ("el:6=abc", "the amplitude must be a number"),
])
def test_a_bad_ripple_text_is_refused_in_one_line(text, message):
    """What the command line will parse (``--ripple``, as ``bogie ripple`` takes it)."""
    with pytest.raises(ExcitationError) as error:
        parse_amplitudes(text)
    assert message in str(error.value)
    assert "\n" not in str(error.value)


def test_an_unstable_creepage_is_refused_naming_it():
    """A forced response needs stable points: s0 = 0.008 turns unstable at high speed (the
    assessment says so as its own error)."""
    parameters = load_parameters()
    options = AssessmentOptions(s0=(0.008,), ripple_v=tuple(np.array([100.0, 200.0]) * KMH))
    with pytest.raises(RippleCaseError, match=r"s0 = 0.008 is not stable at 200 km/h") as error:
        _sweep(parameters, ["ID1.driving_shaft.torque"], options)
    assert "\n" not in str(error.value)
    from model.studies.assessment import ripple_case

    with pytest.raises(AssessmentError, match=r"s0 = 0.008 is not stable at 200 km/h"):
        ripple_case(parameters, ["ID1.driving_shaft.torque"], options)
