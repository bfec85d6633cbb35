"""Design loads: the three-term family over the fault instant, the closed-form worst
case, the scenario grid and its envelope against brute force (single responses).

Tolerances, and why:

* **1e-6 of each output's peak** (family and envelope against single ``short_circuit_response``
  runs): the target.  Both sides are the same exact closed form, so they agree far better
  (measured ≤ 7.3e-9 of the perturbation peak at s0 = 0.005, ≤ 5e-13 at 0.014: the modal form
  skips a decayed mode's terms below 1e-13 of the largest term, and which terms are skipped
  depends on the input); 1e-6 is also the modal form's own error against the exact reference
  (docs/response.md), so a wrong combination (a sign, the phase origin, the decay) fails by
  orders of magnitude more.
* **1e-9 of the peak** for "every fault instant ≥ any grid of fault instants": both sides are
  formed from the same three responses, so the inequality a + √(b² + c²) ≥ a + b cos φ + c sin φ
  holds to rounding (≈ 1e-15 relative); 1e-9 is the target.
* **1 % of the peak** for "every fault instant within a 360-phase grid": the grid misses the
  worst phase by at most 0.5°, so the gap is at most √(b² + c²)(1 − cos 0.5°) = 3.8e-5 of the
  oscillating part (the target is 1 %).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from model import build_model, load_parameters
from model.analysis.response import ShortCircuit, short_circuit_response
from model.mechanics.operating_point import KMH, OperatingPoint, motor_torque
from model.studies.envelope import (
    DesignLoadError,
    EnvelopeStudy,
    PhaseFamily,
    continuity_phases,
    envelope,
    history_peaks,
    phase_families,
    rail_parameters,
    resolve_outputs,
    run_envelope,
    worst_fault_instant,
    wrap_shift,
)

T_END, FS = 0.5, 2000.0  # 2000 Hz resolves the 297.6 Hz driving-shaft mode (≥ 2.5 ×)
OUTPUTS = ("ID1.driving_shaft.torque", "ID1.disc_clutch.torque", "ID1.gear_mesh.force",
           "ID2.disc_clutch.torque", "ID2.wheelset.adhesion_moment", "ID1.rotor.ry")


@pytest.fixture(scope="module")
def bogie():
    parameters = load_parameters()
    return parameters, build_model(parameters)


def point(parameters, s0: float, v_kmh: float = 120.0) -> OperatingPoint:
    return OperatingPoint.from_kmh(s0, v_kmh, parameters["wheel_force"], parameters["motor_slope"])


def single(model, op, M0, dt, f=90.0, D=0.04, outputs=OUTPUTS):
    """Totals of one ``short_circuit_response`` (N x p, OUTPUTS order)."""
    r = short_circuit_response(model, op, ShortCircuit(M0=M0, f=f, D=D, dt=dt), T_END, FS,
                               list(outputs))
    return r, np.column_stack([r.outputs[name] for name in outputs])


# --- fault instants -------------------------------------------------------------------------------

def test_continuity_roots_make_the_motor_torque_continuous():
    step, M0, f = 12_800.0, 50_000.0, 90.0
    roots = continuity_phases(step, M0, f)
    omega = 2 * math.pi * f
    assert roots[0] == ShortCircuit(M0=M0, f=f).shift(step)  # bogie response's choice
    assert abs(roots[0] - roots[1]) > 1e-4  # two distinct instants per period
    for dt in roots:
        assert math.sin(omega * dt) == pytest.approx(step / M0, rel=1e-12)
        # M(s0, v) + M_C(0+) = M(s0, v): the total motor torque does not jump
        excitation = ShortCircuit(M0=M0, f=f, dt=dt)
        assert step + float(excitation.torque(np.array([0.0]), step)[0]) == pytest.approx(
            step, abs=1e-9 * M0)
        assert -0.5 / f < dt <= 0.5 / f
    # |M| ≥ M0: one instant (ωΔt = π/2), given twice; no oscillation: Δt is void
    assert continuity_phases(60_000.0, M0, f) == pytest.approx((0.25 / f, 0.25 / f))
    assert continuity_phases(step, 0.0, f) == (0.0, 0.0)


def test_wrap_shift_takes_phases_into_half_open_period():
    omega = 2 * math.pi * 90.0
    for phase in (-7.0, -math.pi, 0.0, 1.0, math.pi, 4.0, 12.5):
        dt = wrap_shift(phase, omega)
        assert -math.pi < omega * dt <= math.pi + 1e-12
        assert math.cos(omega * dt) == pytest.approx(math.cos(phase), abs=1e-12)
        assert math.sin(omega * dt) == pytest.approx(math.sin(phase), abs=1e-12)


# --- the three-term family ------------------------------------------------------------------------

@pytest.mark.parametrize("s0", [0.005, 0.014])
def test_family_reproduces_single_responses_at_any_fault_instant(bogie, s0):
    """total(t; M0, Δt) = steady + step + M0 [cos ωΔt · cos_part + sin ωΔt · sin_part]."""
    parameters, model = bogie
    op = point(parameters, s0)
    family = phase_families(model, op, [(90.0, 0.04), (60.0, 0.1)], T_END, FS, list(OUTPUTS))
    for fam in family:
        roots = fam.continuity_phases(50_000.0)
        for M0, dt in [(50_000.0, None), (50_000.0, roots[1]), (20_000.0, 0.0031),
                       (80_000.0, -0.0047), (0.0, 0.002)]:
            r, y = single(model, op, M0, dt, fam.f, fam.D)
            scale = np.abs(y - fam.steady).max(axis=0)
            error = np.abs(fam.totals(M0, r.phase_shift) - y).max(axis=0) / scale
            assert error.max() < 1e-6, (fam.f, M0, dt, error.max())


def test_worst_case_of_a_known_family_is_exact():
    """a + b cos φ + c sin φ with b = cos(2πt), c = sin(2πt): the worst Δt turns with time."""
    t = np.linspace(0.0, 1.0, 101)
    ones = np.ones((len(t), 1))
    family = PhaseFamily(
        t=t, names=("y",), units={"y": "N"}, steady=np.array([1.0]), step=0.5 * t[:, None],
        cos_part=np.cos(2 * np.pi * t)[:, None] * ones, sin_part=np.sin(2 * np.pi * t)[:, None],
        f=10.0, D=0.0, motor_torque=0.0, operating_point=None, methods=("modal",) * 3,
        truncated_at=None, highest_excited_hz=10.0)
    worst = worst_fault_instant(family, 2.0)
    np.testing.assert_allclose(worst.upper[:, 0], 1.0 + 0.5 * t + 2.0, rtol=1e-15)
    np.testing.assert_allclose(worst.lower[:, 0], 1.0 + 0.5 * t - 2.0, rtol=1e-15)
    # φ* = atan2(sin 2πt, cos 2πt) = 2πt (wrapped): the history with that Δt reaches the upper
    for k in (10, 37, 80):
        dt = worst.phase_of_upper[k, 0]
        assert family.totals(2.0, dt)[k, 0] == pytest.approx(worst.upper[k, 0], rel=1e-14)
        assert family.totals(2.0, worst.phase_of_lower[k, 0])[k, 0] == pytest.approx(
            worst.lower[k, 0], rel=1e-14)
    assert worst.peaks.max[0] == pytest.approx(3.5)
    assert worst.peaks.time_of_max[0] == 1.0
    assert worst.peaks.min[0] == pytest.approx(-1.0)
    assert worst.peaks.time_of_min[0] == 0.0


def test_history_peaks_are_max_and_min_with_times():
    t = np.array([0.0, 0.1, 0.2, 0.3])
    y = np.array([[0.0, 5.0], [3.0, -1.0], [-2.0, 7.0], [1.0, 7.0]])
    peaks = history_peaks(t, y, 0.004)
    np.testing.assert_array_equal(peaks.max, [3.0, 7.0])
    np.testing.assert_array_equal(peaks.min, [-2.0, -1.0])
    np.testing.assert_array_equal(peaks.time_of_max, [0.1, 0.2])  # the first of equal maxima
    np.testing.assert_array_equal(peaks.time_of_min, [0.2, 0.1])
    np.testing.assert_array_equal(peaks.phase_of_max, [0.004, 0.004])


@pytest.mark.parametrize("s0", [0.005, 0.014])
def test_every_fault_instant_bounds_grids_and_is_reached(bogie, s0):
    parameters, model = bogie
    op = point(parameters, s0)
    family = phase_families(model, op, [(90.0, 0.04)], T_END, FS, list(OUTPUTS))[0]
    M0 = 50_000.0
    worst = worst_fault_instant(family, M0)
    scale = np.maximum(np.abs(worst.peaks.max), np.abs(worst.peaks.min))
    grid = np.arange(360) / 360 / 90.0  # one period in 1° steps
    grid_max = np.max([family.totals(M0, dt).max(axis=0) for dt in grid], axis=0)
    grid_min = np.min([family.totals(M0, dt).min(axis=0) for dt in grid], axis=0)
    for dt in (*grid[::7], *family.continuity_phases(M0)):  # any grid of phases
        y = family.totals(M0, dt)
        assert np.all(worst.peaks.max >= y.max(axis=0) - 1e-9 * scale)
        assert np.all(worst.peaks.min <= y.min(axis=0) + 1e-9 * scale)
    assert np.all(worst.peaks.max - grid_max <= 1e-2 * scale)
    assert np.all(grid_min - worst.peaks.min <= 1e-2 * scale)
    # a single response at the reported Δt reaches the max at the reported time
    for j, name in enumerate(OUTPUTS):
        _, y = single(model, op, M0, float(worst.peaks.phase_of_max[j]))
        k = round(worst.peaks.time_of_max[j] * FS)
        assert y[k, j] == pytest.approx(worst.peaks.max[j], abs=1e-6 * scale[j]), name
        assert y[:, j].max() == pytest.approx(worst.peaks.max[j], abs=1e-6 * scale[j]), name
        _, y = single(model, op, M0, float(worst.peaks.phase_of_min[j]))
        assert y[:, j].min() == pytest.approx(worst.peaks.min[j], abs=1e-6 * scale[j]), name


# --- the scenario grid ------------------------------------------------------------------------------

def study(parameters, model, **changes):
    outputs, units = resolve_outputs(model, point(parameters, 0.005), list(OUTPUTS))
    arguments = dict(s0=(0.005, 0.014), v=(80 * KMH, 120 * KMH), N0=(parameters["wheel_force"],),
                     b_M=(parameters["motor_slope"],), outputs=outputs, units=units, t_end=T_END,
                     fs=FS)
    arguments.update(changes)
    return EnvelopeStudy(**arguments)


def brute_force(parameters, study_, index) -> tuple[np.ndarray, np.ndarray, float]:
    """(max, min per output, Δt) of the scenario at grid ``index`` by one single response."""
    i = dict(zip(("rail", "s0", "v", "N0", "b_M", "M0", "f", "D", "fault"), index, strict=False))
    model = build_model(rail_parameters(parameters, study_.rail[i["rail"]]))
    op = OperatingPoint(study_.s0[i["s0"]], study_.v[i["v"]], study_.N0[i["N0"]],
                        study_.b_M[i["b_M"]])
    M0, f = study_.M0[i["M0"]], study_.f[i["f"]]
    dt = study_.fault_phases(motor_torque(model.parameters, op), M0, f)[i["fault"]]
    _, y = single(model, op, M0, dt, f, study_.D[i["D"]], study_.outputs)
    return y.max(axis=0), y.min(axis=0), dt


@pytest.mark.parametrize(("fault", "phase"), [("roots", ()), ("grid", (-0.004, 0.0, 0.0023))])
def test_envelope_equals_brute_force(bogie, fault, phase):
    parameters, model = bogie
    s = study(parameters, model, M0=(30_000.0, 50_000.0), fault=fault, phase=phase)
    assert s.scenarios == 2 * 2 * 2 * s.fault_count
    arrays = _arrays(s, parameters)
    result = envelope(s, arrays)
    for index in np.ndindex(*arrays["max"].shape[1:]):
        maxima, minima, dt = brute_force(parameters, s, index)
        scale = np.maximum(np.abs(maxima), np.abs(minima))
        got_max = arrays["max"][(slice(None), *index)]
        got_min = arrays["min"][(slice(None), *index)]
        assert np.all(np.abs(got_max - maxima) <= 1e-6 * scale), index
        assert np.all(np.abs(got_min - minima) <= 1e-6 * scale), index
        np.testing.assert_array_equal(arrays["phase_of_max"][(slice(None), *index)], dt)
    # the envelope is the extreme over the scenarios, and max_at names a scenario that has it
    for j, out in enumerate(result.outputs):
        assert out.max == arrays["max"][j].max()
        assert out.min == arrays["min"][j].min()
        _reproduce(parameters, s, out, j)


def _arrays(s, parameters):
    from model.studies.engine import serial_map_unordered
    from model.studies.store import run_in_memory

    return run_in_memory(s, parameters, serial_map_unordered)


def _reproduce(parameters, s, out, j):
    """A single response at ``max_at`` / ``min_at`` gives the max / min (1e-6 of the peak)."""
    for at, value, pick in ((out.max_at, out.max, np.max), (out.min_at, out.min, np.min)):
        model = build_model(rail_parameters(parameters, at["rail"]))
        op = OperatingPoint.from_kmh(at["s0"], at["v_kmh"], at["n0"], at["bm"])
        _, y = single(model, op, at["m0"], at["phase_s"], at["f"], at["decay"], s.outputs)
        scale = np.abs(y[:, j]).max()
        assert pick(y[:, j]) == pytest.approx(value, abs=1e-6 * scale), (out.name, at)
        k = round(at["time_s"] * FS)
        assert y[k, j] == pytest.approx(value, abs=1e-6 * scale), (out.name, at)


def test_every_fault_instant_envelope_bounds_the_grid_envelope(bogie):
    parameters, model = bogie
    grid = tuple(np.arange(360) / 360 / 90.0)
    every = _arrays(study(parameters, model, fault="all"), parameters)
    gridded = _arrays(study(parameters, model, fault="grid", phase=grid), parameters)
    roots = _arrays(study(parameters, model), parameters)
    scale = np.maximum(np.abs(every["max"]), np.abs(every["min"]))
    for other in (gridded, roots):
        assert np.all(every["max"] >= other["max"].max(axis=-3, keepdims=True) - 1e-9 * scale)
        assert np.all(every["min"] <= other["min"].min(axis=-3, keepdims=True) + 1e-9 * scale)
    assert np.all(every["max"] - gridded["max"].max(axis=-3, keepdims=True) <= 1e-2 * scale)
    assert np.all(gridded["min"].min(axis=-3, keepdims=True) - every["min"] <= 1e-2 * scale)
    result = envelope(study(parameters, model, fault="all"), every)
    for j, out in enumerate(result.outputs):
        _reproduce(parameters, study(parameters, model, fault="all"), out, j)


def test_rails_and_excitation_axes(bogie):
    """A rail changes the creep law (the parameter set), f and D the excitation: each scenario
    still equals its single response."""
    parameters, model = bogie
    s = study(parameters, model, s0=(0.005,), v=(120 * KMH,), rail=("calibrated", "wet"),
              f=(60.0, 90.0), D=(0.04, 0.2))
    arrays = _arrays(s, parameters)
    assert arrays["max"].shape == (len(OUTPUTS), 2, 1, 1, 1, 1, 1, 2, 2, 2, 1, 1)
    for index in [(1, 0, 0, 0, 0, 0, 1, 1, 1, 0, 0), (0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0),
                  (1, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0)]:
        maxima, minima, _ = brute_force(parameters, s, index)
        scale = np.maximum(np.abs(maxima), np.abs(minima))
        assert np.all(np.abs(arrays["max"][(slice(None), *index)] - maxima) <= 1e-6 * scale)
        assert np.all(np.abs(arrays["min"][(slice(None), *index)] - minima) <= 1e-6 * scale)
    # the wet rail's lower adhesion changes the loads: the axis is not ignored
    assert not np.allclose(arrays["max"][:, 0], arrays["max"][:, 1])


def test_nonlinear_scenarios_equal_their_runs(bogie):
    from model.analysis.nonlinear import nonlinear_response

    parameters, model = bogie
    loads = [name for name in OUTPUTS if name != "ID1.rotor.ry"]
    outputs, units = resolve_outputs(model, point(parameters, 0.014), loads, "nonlinear")
    s = EnvelopeStudy(s0=(0.014,), v=(120 * KMH,), N0=(parameters["wheel_force"],),
                      b_M=(parameters["motor_slope"],), outputs=outputs, units=units,
                      creep="nonlinear", anti_slip=("off", "on"), anti_slip_delay=(0.0, 0.05),
                      t_end=0.3, fs=2000.0)
    assert s.scenarios == 2 * (1 + 2)  # two roots × (off, on at two delays)
    assert len(s.chunks()) == 4
    arrays = _arrays(s, parameters)
    op = point(parameters, 0.014)
    step = motor_torque(parameters, op)
    for fault, dt in enumerate(continuity_phases(step, 50_000.0, 90.0)):
        for a, delay, protection in [(0, 0, None), (0, 1, None), (1, 0, s.protection(0.0)),
                                     (1, 1, s.protection(0.05))]:
            r = nonlinear_response(model, op, ShortCircuit(dt=dt), 0.3, 2000.0,
                                   anti_slip=protection, outputs=loads)
            index = (slice(None), 0, 0, 0, 0, 0, 0, 0, 0, fault, a, delay)
            np.testing.assert_allclose(arrays["max"][index], [r.outputs[n].max() for n in loads],
                                       rtol=1e-12)
            np.testing.assert_allclose(arrays["min"][index], [r.outputs[n].min() for n in loads],
                                       rtol=1e-12)
    result = envelope(s, arrays)
    assert {"anti_slip", "anti_slip_delay_s"} <= set(result.outputs[0].max_at)


def test_run_envelope_without_a_store(bogie):
    parameters, model = bogie
    s = study(parameters, model, s0=(0.005,), v=(120 * KMH,))
    result = run_envelope(s, parameters)
    assert result.scenarios == 2
    assert result.fault_instants == "roots"
    data = result.as_dict()
    assert [o["name"] for o in data["outputs"]] == list(OUTPUTS)
    assert data["outputs"][0]["unit"] == "N m"
    assert set(data["outputs"][0]["max_at"]) == {"s0", "v_kmh", "phase_s", "rail", "n0", "bm",
                                                 "m0", "f", "decay", "time_s"}


@pytest.mark.parametrize(("changes", "message"), [
    ({"s0": ()}, "empty grid"),
    ({"rail": ("icy",)}, "icy"),
    ({"fault": "all", "creep": "nonlinear"}, "--phase all needs --creep linear"),
    ({"fault": "grid", "phase": ()}, "empty grid"),
    ({"anti_slip": ("on",)}, "needs --creep nonlinear"),
    ({"anti_slip_delay": (0.1,)}, "need --anti-slip on"),
    ({"v": (0.1,)}, "speed"),
    ({"M0": (-1.0,)}, "M0"),
    ({"s0": (0.005, 0.005)}, "repeated"),
    ({"t_end": 0.0}, "t_end"),
])
def test_bad_study(bogie, changes, message):
    parameters, model = bogie
    with pytest.raises(ValueError, match=message):
        study(parameters, model, **changes)


def test_nonlinear_refuses_dof_outputs(bogie):
    parameters, model = bogie
    with pytest.raises(DesignLoadError, match="not available with nonlinear creep"):
        resolve_outputs(model, point(parameters, 0.014), ["ID1.rotor.ry"], "nonlinear")
