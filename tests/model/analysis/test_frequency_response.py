"""Frequency response: the modal form against independent computations (the steady state of a long
time response by the matrix exponential, direct solves of the dynamic stiffness), the static gain
against the torque balance, the grid's peaks against a brute-force search, the model's frequency
limit against its beam meshes, bad input."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest
import scipy.linalg as sla

from model import build_model, default_operating_point, load_parameters
from model.analysis.eigen import bogie_system
from model.analysis.frequency_response import (
    MODEL_FREQUENCY_LIMIT_HZ,
    FrequencyResponseError,
    direct_response,
    frequency_response,
    input_force,
    input_names,
    transfer,
)
from model.mechanics.beam import TubeSection
from model.mechanics.outputs import output_matrices


@pytest.fixture(scope="module")
def setup():
    parameters = load_parameters()
    model = build_model(parameters)
    op = default_operating_point(parameters)  # s0 = 0.005, 120 km/h
    return model, op, frequency_response(model, op)


def _long_time_response(system, C: np.ndarray, f_hz: float, t_long: float, steps: int = 32,
                        periods: int = 40) -> np.ndarray:
    """Steady-state complex amplitude of y = C x under u = cos(2π f t) from rest: the state
    augmented by the generator of (cos, sin) is propagated exactly (matrix exponential of one
    step, the first ``t_long`` seconds by repeated squaring), then a + b cos + c sin + a slow
    quadratic drift is fitted over ``periods`` periods (the slowest modes, |Re λ| ≈ 0.06 1/s,
    have not died out after a minute; over the fitting window they are a smooth drift)."""
    A, b = system.A, system.b
    N = A.shape[0]
    w = 2 * np.pi * f_hz
    h = 1.0 / (f_hz * steps)
    F = np.zeros((N + 2, N + 2))
    F[:N, :N], F[:N, N] = A, b
    F[N:, N:] = [[0.0, -w], [w, 0.0]]
    step = sla.expm(F * h)
    k = round(t_long / h)
    start = np.zeros(N + 2)
    start[N] = 1.0
    z = np.linalg.matrix_power(step, k) @ start
    t = (k + np.arange(periods * steps)) * h
    y = np.empty((len(t), C.shape[0]))
    for j in range(len(t)):
        y[j] = C @ z[:N]
        z = step @ z
    tau = (t - t[0]) / (t[-1] - t[0])
    basis = np.column_stack([np.cos(w * t), np.sin(w * t), np.ones_like(t), tau, tau**2])
    coefficients, *_ = np.linalg.lstsq(basis, y, rcond=None)
    return coefficients[0] - 1j * coefficients[1]  # y = Re(H e^{iωt}) = a cos + b sin


@pytest.mark.parametrize(("f_hz", "t_long"), [
    pytest.param(1.0, 60.0, id="1 Hz"),
    pytest.param(None, 60.0, id="disc-clutch resonance"),
    pytest.param(45.0, 30.0, id="45 Hz"),
    pytest.param(None, 12.0, id="driving-shaft resonance"),
])
def test_frf_equals_the_steady_state_of_a_long_time_response(setup, f_hz, t_long, request):
    """Magnitude within 1e-4 and phase within 0.01° of the steady state of the time response to
    a unit cosine motor torque on ID1 (exact propagation, no eigendecomposition), at two
    frequencies off resonance and at the peaks of the disc clutch (2.7 Hz) and driving shaft
    (298 Hz) modes.  Measured: 1e-9 for ID1's torques, 6e-6 for ID2's (an order of magnitude
    smaller, the slow modes' drift is a larger part of them).  The reference's own error is
    absolute, about 1e-11 of the largest output (the fitted drift of the slow modes): at the
    driving shaft's resonance ID2's disc clutch answers ID1's torque with 2e-6 N m per N m,
    seven orders below ID1's torques, so its magnitude is compared to within 1e-4 of itself or
    1e-10 of the largest output, whichever is larger."""
    model, op, frf = setup
    if f_hz is None:  # the peak the FRF found
        name = ("ID1.disc_clutch.torque" if "disc" in request.node.callspec.id
                else "ID1.driving_shaft.torque")
        f_hz = max(frf.peaks[frf.output(name)], key=lambda peak: peak.abs).f_hz
    names = ["ID1.driving_shaft.torque", "ID1.disc_clutch.torque", "ID2.disc_clutch.torque"]
    system = bogie_system(model, op)
    matrices = output_matrices(model, op)
    rows = [matrices.index(n) for n in names]
    reference = _long_time_response(system, system.state_output(matrices.C_q[rows],
                                                                matrices.C_v[rows]), f_hz, t_long)
    modal, _, _ = transfer(model, op, outputs=names)
    H = modal(np.array([f_hz]))[:, 0]
    floor = 1e-10 * np.abs(reference).max()
    np.testing.assert_allclose(np.abs(H), np.abs(reference), rtol=1e-4, atol=floor)
    phase_error = np.degrees(np.angle(H / reference))
    resolved = np.abs(reference) > 1e4 * floor  # the phase of what is above the floor
    assert np.all(np.abs(phase_error[resolved]) < 0.01), phase_error


def test_grid_values_equal_direct_solves(setup):
    """Every output's H on a sample of the grid (the resonances included) equals the direct
    solve of the dynamic stiffness within 1e-7 of the output's largest |H|."""
    model, op, frf = setup
    sample = np.unique(np.concatenate([frf.f_hz[1::97], [p.f_hz for row in frf.peaks for p in row]]))
    direct = direct_response(model, op, sample)
    columns = np.searchsorted(frf.f_hz, sample)
    modal, _, _ = transfer(model, op)
    H = modal(sample)
    scale = np.abs(frf.H).max(axis=1, keepdims=True)
    assert np.all(np.abs(H - direct) <= 1e-7 * scale)
    on_grid = frf.f_hz[columns] == sample
    assert np.all(np.abs(frf.H[:, columns[on_grid]] - direct[:, on_grid]) <= 1e-7 * scale)


def test_static_gain_is_the_torque_balance(setup, uniform_acceleration_loads):
    """At 0 Hz a motor torque on ID1 accelerates the whole vehicle (no running resistance, and
    ID2's slope measures its rotor against the vehicle's own speed, so it does not take the
    torque back): every load is the torque balance of that uniform acceleration.  ID1's driving
    shaft passes the torque less what its rotor's inertia takes; ID2's disc clutch carries only
    the inertia of ID2's side."""
    model, op, frf = setup
    assert frf.f_hz[0] == 0.0
    gain = dict(zip(frf.names, frf.H[:, 0], strict=True))
    expected = uniform_acceleration_loads(model, op, input_force(model, "ID1.motor.torque")[0])
    for name in ("ID1.driving_shaft.torque", "ID1.disc_clutch.torque", "ID2.disc_clutch.torque",
                 "ID2.driving_shaft.torque"):
        assert gain[name].real == pytest.approx(expected[name], rel=1e-8, abs=1e-10), name
    assert 0.95 < gain["ID1.driving_shaft.torque"].real < 1.0  # the rotor takes a few per cent
    assert abs(gain["ID2.disc_clutch.torque"]) < 0.2 * model.parameters["gear_ratio"]


def test_no_peak_is_missed(setup):
    """A brute-force search (50 000 log-spaced frequencies and 1001 across each resonance's
    ±5 half-power half-widths) finds no local maximum above the listing threshold that the FRF
    does not list (within 1e-6 in frequency), and no height above the listed one."""
    model, op, frf = setup
    modal, _, _ = transfer(model, op)
    lam = modal.eigenvalues
    upper = lam[(lam.imag > 0) & (lam.imag / (2 * np.pi) < MODEL_FREQUENCY_LIMIT_HZ)]
    dense = [np.geomspace(0.1, MODEL_FREQUENCY_LIMIT_HZ, 50_000)]
    for value in upper:
        centre, width = value.imag / (2 * np.pi), abs(value.real) / (2 * np.pi)
        dense.append(np.linspace(centre - 5 * width, centre + 5 * width, 1001))
    f = np.unique(np.concatenate(dense))
    f = f[(f >= 0.1) & (f <= MODEL_FREQUENCY_LIMIT_HZ)]
    magnitude = np.abs(np.hstack([modal(chunk) for chunk in np.array_split(f, 20)]))
    for p, name in enumerate(frf.names):
        m = magnitude[p]
        largest = max(m.max(), abs(frf.static_gain[p]))
        local = np.flatnonzero((m[1:-1] > m[:-2]) & (m[1:-1] >= m[2:])) + 1
        local = local[m[local] >= 1.0001 * 0.01 * largest]  # above the listing threshold
        listed = np.array([peak.f_hz for peak in frf.peaks[p]])
        heights = np.array([peak.abs for peak in frf.peaks[p]])
        for i in local:
            assert len(listed), f"{name}: no peaks listed, one at {f[i]:.6g} Hz"
            nearest = np.argmin(np.abs(listed - f[i]))
            assert abs(listed[nearest] - f[i]) <= max(1e-6 * f[i], f[i + 1] - f[i - 1]), name
            assert m[i] <= heights[nearest] * (1 + 1e-9), name


def test_peaks_state_height_and_amplification(setup):
    """The driving shaft's 298 Hz peak: its height is |H| there, its amplification the height
    over the static gain (1 N m per N m)."""
    _, _, frf = setup
    p = frf.output("ID1.driving_shaft.torque")
    peak = max(frf.peaks[p], key=lambda peak: peak.f_hz)
    assert 290 < peak.f_hz < 305
    assert peak.amplification == pytest.approx(peak.abs / abs(frf.static_gain[p]), rel=1e-12)
    assert peak.abs > 10  # lightly damped: a dynamic amplification of tens


def test_outputs_follow_the_output_matrices(setup):
    """The FRF has a row for every named output, in the order of the output matrices: a new
    output appears without any change here."""
    model, op, frf = setup
    assert frf.names == output_matrices(model, op).names
    assert frf.H.shape == (len(frf.names), len(frf.f_hz))


def test_other_inputs(setup, uniform_acceleration_loads):
    """ID2's motor torque: its steady part accelerates the vehicle as ID1's does (its own slope
    measures against the vehicle's speed and does not take it back), while its 298 Hz mode
    amplifies, less than ID1's (ID2's slope b_M damps it; ID1's motor has none); a creep-force
    disturbance at a wheel is an input in N."""
    model, op, _ = setup
    names = input_names(model)
    assert names[:2] == ("ID1.motor.torque", "ID2.motor.torque")
    other = frequency_response(model, op, input="ID2.motor.torque", points=200)
    row = other.output("ID2.driving_shaft.torque")
    expected = uniform_acceleration_loads(model, op, input_force(model, "ID2.motor.torque")[0])
    assert other.H[row, 0].real == pytest.approx(expected["ID2.driving_shaft.torque"], rel=1e-8)
    amplification = max(peak.abs for peak in other.peaks[row] if peak.f_hz > 290)
    own = frequency_response(model, op, input="ID1.motor.torque", points=200)
    id1 = max(peak.abs for peak in own.peaks[own.output("ID1.driving_shaft.torque")]
              if peak.f_hz > 290)
    assert 3 < amplification < id1
    creep = frequency_response(model, op, input="ID1.rim12.creep_disturbance", points=200)
    assert creep.input_unit == "N"
    force, unit = input_force(model, "ID1.rim12.creep_disturbance")
    assert unit == "N"
    assert np.count_nonzero(force) == 2


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"input": "ID3.motor.torque"}, "unknown input"),
    ({"f_lo": 10.0, "f_hi": 5.0}, "0 < f_lo < f_hi"),
    ({"f_hi": 5000.0}, "beyond the model's validity"),
    ({"points": 1}, "2 to 100000 points"),
    ({"outputs": ["ID1.nothing"]}, "unknown output"),
    ({"min_peak": 1.5}, "min_peak"),
])
def test_bad_input(setup, kwargs, message):
    model, op, _ = setup
    with pytest.raises(FrequencyResponseError, match=message):
        frequency_response(model, op, **kwargs)


def test_frequency_limit_is_below_half_the_shortest_wave_of_any_beam_element():
    """The limit's reasoning holds for the default set: every beam element of hollow shaft and
    axle (the nodes as docs/model.md lays them out: the hollow shaft evenly from the gear to the
    claw clutch, the axle at the journals, wheels, claw clutch, centre and gear) has its first
    clamped–clamped bending frequency (βL)² / (2π L²) √(EI/ρA), βL = 4.730, at least twice the
    limit."""
    p = load_parameters()
    hollow = TubeSection(p["hollow_shaft_outer_radius"], p["hollow_shaft_inner_radius"])
    solid = TubeSection(p["axle_radius"])
    hs = np.linspace(p["gear_lateral_position"], p["claw_clutch_lateral_position"], 5)
    j, c = p["journal_half_distance"], p["contact_half_distance"]
    axle = np.sort([-j, -c, p["claw_clutch_lateral_position"], 0.0, p["gear_lateral_position"], c, j])
    elements = [(abs(b - a), hollow) for a, b in pairwise(hs)]
    elements += [(b - a, solid) for a, b in pairwise(axle)]
    lowest = min(4.730**2 / (2 * np.pi * length**2)
                 * np.sqrt(p["young_modulus"] * s.second_moment / (p["steel_density"] * s.area))
                 for length, s in elements)
    assert lowest >= 2 * MODEL_FREQUENCY_LIMIT_HZ


def test_irregularity_input_equals_direct_solves_of_the_running_system(setup):
    """A rail–wheel surface deviation [m]: the modal form with its feed-through (H_q + s H_v +
    s² H_a as residues and D0 + D1 s) against the running system's dynamic stiffness solved at
    each frequency, to 1e-8 of each output's largest |H| (the modal rounding tolerance); the
    running system is not the study's (the wheel-force coupling), so the creep-force input of
    the same wheel differs from the vertical one."""
    model, op, _ = setup
    name = "ID2.rim14.irregularity"
    assert name in input_names(model)
    frf = frequency_response(model, op, input=name, points=300)
    assert frf.input_unit == "m"
    picks = np.arange(1, len(frf.f_hz), 17)
    direct = direct_response(model, op, frf.f_hz[picks], input=name)
    largest = np.abs(frf.H).max(axis=1, keepdims=True)
    assert np.all(np.abs(frf.H[:, picks] - direct) <= 1e-8 * largest)
    with pytest.raises(FrequencyResponseError, match="displacement input"):
        input_force(model, name)
