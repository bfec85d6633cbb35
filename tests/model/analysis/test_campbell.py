"""Campbell diagram: its frequencies against the eigen-analysis, tracking at a close approach, the
crossings against the closed-form intersection, the severities against the frequency response,
the ripple's forced response, bad input."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from model import build_model, default_operating_point, eigen_analysis, load_parameters
from model.analysis.campbell import (
    CampbellError,
    campbell,
    intersections,
    ripple_response,
    speeds_kmh,
)
from model.analysis.frequency_response import MODEL_FREQUENCY_LIMIT_HZ, direct_response, transfer
from model.analysis.modes import characterize
from model.mechanics.excitation import DEFAULT_ORDERS, Order, load_excitation, parse_orders


@pytest.fixture(scope="module")
def setup():
    parameters = load_parameters()
    model = build_model(parameters)
    op = default_operating_point(parameters)  # s0 = 0.005, 120 km/h
    excitation = load_excitation()
    diagram = campbell(model, op, speeds_kmh(5, 200, 40), parse_orders(DEFAULT_ORDERS), excitation)
    return model, op, excitation, diagram


def _mode(diagram, words: str):
    (mode,) = [m for m in diagram.modes if words in m.name]
    return mode


def test_frequencies_equal_the_eigen_analysis(setup):
    """At every fourth speed each mode's eigenvalue lies within 1e-6·max(|λ|, 1 1/s) of an
    eigenvalue of `eigen_analysis` there (what `bogie eigen` prints).  The root locus's error
    control holds its estimate below 1e-3 (a first-order estimate that overstates these errors);
    measured errors are about 1e-8."""
    model, op, _, diagram = setup
    for i in range(0, len(diagram.v), 4):
        exact = eigen_analysis(model, replace(op, v=float(diagram.v[i])), vectors=False).eigenvalues
        for mode in diagram.modes:
            value = mode.eigenvalues[i]
            assert np.min(np.abs(exact - value)) <= 1e-6 * max(abs(value), 1.0), (mode.name, i)


def test_modes_are_the_ones_the_motor_drives(setup):
    """Table 2's rotor-with-gears mode (2.7 Hz: the disc clutch twisting) and the two drives'
    driving-shaft modes (mode 58, 298 Hz) are tracked and named by their character."""
    _, op, _, diagram = setup
    index = int(np.argmin(np.abs(diagram.v - op.v)))
    disc = _mode(diagram, "twisting of disc clutch 1")
    assert 2.4 < disc.f_hz[index] < 3.0
    for drive in (1, 2):
        shaft = _mode(diagram, f"twisting of driving shaft {drive}")
        assert 290 < shaft.f_hz[index] < 305


def test_close_twins_do_not_swap(setup):
    """The two drives' driving-shaft modes stay close over the whole range (a close approach
    throughout: their resonances overlap, the gap between their frequencies is below the
    half-power width 2|Re λ| of the lighter damped one), but each is a motion of its own drive
    (MAC between them ≈ 0: unambiguous).  At every fourth speed the branch named for drive k is,
    in the exact eigenvector nearest to its eigenvalue, more than 90 % kinetic energy of drive k.
    (How close depends on the parameter set: without the healthy motor's slope the twins
    coincide; the slope damps drive 2's twin and lowers its frequency, the more the steeper it
    is, so a fixed bound on the relative gap holds for one set and not the next.  The overlap is
    the approach that matters to the diagram: one order line meets both within one resonance.)"""
    model, op, _, diagram = setup
    twins = {k: _mode(diagram, f"twisting of driving shaft {k}") for k in (1, 2)}
    gap = np.abs(twins[1].eigenvalues.imag - twins[2].eigenvalues.imag)
    width = 2 * np.minimum(np.abs(twins[1].eigenvalues.real), np.abs(twins[2].eigenvalues.real))
    assert np.all(gap < width)
    for i in range(0, len(diagram.v), 4):
        result = eigen_analysis(model, replace(op, v=float(diagram.v[i])))
        shapes = {}
        for k, mode in twins.items():
            j = int(np.argmin(np.abs(result.eigenvalues - mode.eigenvalues[i])))
            shape = result.mode_shape(j)
            shapes[k] = shape / np.linalg.norm(shape)
            kinetic = characterize(model, result.eigenvalues[j], shape).kinetic
            assert sum(v for c, v in kinetic.items() if c.startswith(f"ID{k}.")) > 0.9
        assert abs(np.vdot(shapes[1], shapes[2])) ** 2 < 0.01


def test_crossing_speeds_are_the_closed_form_intersections(setup):
    """Each crossing of a straight order line f = a v with a mode lies where the line meets the
    mode's curve interpolated linearly between the two grid speeds around it: v = (f_i − s v_i)
    / (a − s), s the curve's slope there (a fixed line: v = v_i + (f − f_i)/s)."""
    model, _, excitation, diagram = setup
    assert diagram.crossings
    for crossing in diagram.crossings:
        mode = _mode_by_name(diagram, crossing.mode)
        i = int(np.searchsorted(diagram.v, crossing.v)) - 1
        v0, v1, f0, f1 = diagram.v[i], diagram.v[i + 1], mode.f_hz[i], mode.f_hz[i + 1]
        s = (f1 - f0) / (v1 - v0)
        if crossing.order.family == "fixed":
            expected = v0 + (crossing.order.order - f0) / s
        else:
            a = crossing.order.per_speed_hz(model.parameters, excitation)
            expected = (f0 - s * v0) / (a - s)
        assert crossing.v == pytest.approx(expected, rel=1e-10)
        assert crossing.f_hz == pytest.approx(
            crossing.order.frequency_hz(crossing.v, model.parameters, excitation), rel=1e-10)
        assert crossing.f_hz <= MODEL_FREQUENCY_LIMIT_HZ


def _mode_by_name(diagram, name):
    return next(m for m in diagram.modes if m.name == name)


def test_intersections_of_a_known_curve():
    """A parabola sampled at 11 speeds against the line f = 2.1 v (they meet at v = 1.83 and
    6.57): the intersections with the linear interpolant in closed form from the interval's two
    points, one per sign change."""
    v = np.linspace(0.0, 10.0, 11)
    mode = 3.0 + 0.25 * v**2
    line = 2.1 * v
    found = intersections(v, mode, np.full_like(v, 0.01), line)
    expected = []
    for i in range(10):
        g0, g1 = mode[i] - line[i], mode[i + 1] - line[i + 1]
        if g0 * g1 < 0:
            s = mode[i + 1] - mode[i]
            expected.append((mode[i] - s * v[i]) / (2.1 - s))
    assert len(found) == len(expected) == 2
    np.testing.assert_allclose([c[0] for c in found], expected, rtol=1e-12)
    np.testing.assert_allclose([c[1] for c in found], 2.1 * np.array(expected), rtol=1e-12)


def test_severity_is_the_frequency_response_at_the_crossing(setup):
    """A crossing's severity is |H| of every torque output at its speed and frequency, from ID1's
    motor torque (the modal form at that speed agrees with the direct solve it was made with,
    within 1e-7 and 1e-9 of the largest); the crossings are sorted by their largest torque."""
    model, op, _, diagram = setup
    worst = [c.worst[1] for c in diagram.crossings]
    assert worst == sorted(worst, reverse=True)
    for crossing in diagram.crossings[:3]:
        names = list(crossing.severity)
        modal, matrices, rows = transfer(model, replace(op, v=crossing.v), outputs=names)
        assert all(matrices.units[r] == "N m" for r in rows)
        H = np.abs(modal(np.array([crossing.f_hz]))[:, 0])
        np.testing.assert_allclose([crossing.severity[n] for n in names], H, rtol=1e-7,
                                   atol=1e-9 * H.max())


def test_driving_shaft_resonance_is_the_worst_crossing(setup):
    """The lightly damped driving-shaft modes (ζ ≈ 0.002–0.007) give the largest torque in ID1's
    driving shaft where an order line meets them: tens of N m per N m of ripple."""
    _, _, _, diagram = setup
    shaft = [c for c in diagram.crossings if "twisting of driving shaft" in c.mode]
    assert shaft
    best = max(shaft, key=lambda c: c.severity["ID1.driving_shaft.torque"])
    assert best.severity["ID1.driving_shaft.torque"] > 10
    assert 0 < best.zeta < 0.02


def test_ripple_response_over_speed(setup):
    """A ripple of 100 N m at 6× the electrical frequency: each output's amplitude over speed is
    100 |H(f(v); v)| (direct solve), the total is the sum over orders; the speed grid is refined
    at the resonance, so ID1's driving shaft peaks where that order crosses its 298 Hz mode with
    the crossing's severity (the 2 km/h grid alone sees a fraction of it)."""
    model, op, excitation, diagram = setup
    order = Order("el", 6.0)
    v = speeds_kmh(60, 120, 31)
    ripple = ripple_response(model, op, v, {order: 100.0, Order("wheel", 1.0): 0.0}, excitation)
    assert len(ripple.v) > len(v)
    assert set(v) <= set(ripple.v)
    name = "ID1.driving_shaft.torque"
    row = ripple.names.index(name)
    for i in (0, len(ripple.v) // 2, len(ripple.v) - 1):
        f = order.frequency_hz(ripple.v[i], model.parameters, excitation)
        H = direct_response(model, replace(op, v=float(ripple.v[i])), [f], outputs=[name])[0, 0]
        assert ripple.by_order[0, row, i] == pytest.approx(100 * abs(H), rel=1e-12)
    np.testing.assert_allclose(ripple.total, ripple.by_order.sum(axis=0), rtol=1e-12)
    peak, at = ripple.peak(name)
    crossing = next(c for c in diagram.crossings
                    if c.order == order and "twisting of driving shaft 1" in c.mode)
    assert abs(at - crossing.v) < 0.05 / 3.6  # [m/s]: within 0.05 km/h
    assert peak == pytest.approx(100 * crossing.severity[name], rel=0.01)
    coarse = ripple_response(model, op, v, {order: 100.0}, excitation, refine=False)
    assert coarse.peak(name)[0] < 0.9 * peak


def test_ripple_beyond_the_model_frequency_is_left_out(setup):
    model, op, excitation, _ = setup
    ripple = ripple_response(model, op, speeds_kmh(100, 200, 5), {Order("mesh", 1.0): 10.0},
                             excitation)
    beyond = Order("mesh", 1.0).frequency_hz(ripple.v, model.parameters, excitation) > 1000
    assert beyond.any()
    assert np.all(np.isnan(ripple.total[:, beyond]))
    assert np.all(np.isfinite(ripple.total[:, ~beyond]))


@pytest.mark.parametrize(("call", "message"), [
    (lambda m, op, e: speeds_kmh(200, 100, 10), "empty"),
    (lambda m, op, e: speeds_kmh(100, 200, 1), "2 to"),
    (lambda m, op, e: campbell(m, op, speeds_kmh(100, 200, 5), (Order("fixed", 5000.0),), e),
     "beyond the model's validity"),
    (lambda m, op, e: campbell(m, op, speeds_kmh(100, 200, 5), (), e, participation_threshold=2),
     "participation"),
    (lambda m, op, e: campbell(m, op, speeds_kmh(100, 200, 5), (), e,
                               input="ID1.rim12.creep_disturbance"), "not a motor"),
    (lambda m, op, e: ripple_response(m, op, speeds_kmh(100, 200, 5), {}, e), "no ripple"),
])
def test_bad_input(setup, call, message):
    model, op, excitation, _ = setup
    with pytest.raises(CampbellError, match=message):
        call(model, op, excitation)
