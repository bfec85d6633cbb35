"""The peak table a reviewer reads (app.results.tables.peaks_html), without a server: at the
published stable case the swing of ID1's disc clutch with its time (not the pre-fault value at
0 s), at the unstable case "unbounded with linear creep" with the growth rate, the limit
crossings and the nonlinear creep's bounded peaks beside them.  Expected values come from the
model, never typed in."""

from __future__ import annotations

import re

import numpy as np
import pytest

from app.results import compute
from app.results.case import Case
from app.results.tables import peaks_html
from model import eigen_analysis, load_parameters
from model.analysis.response import short_circuit_response

M0_KNM, F_HZ, DECAY, T_END = 50.0, 90.0, 0.04, 2.0  # the dashboard's defaults


def _point(s0: float) -> Case:
    p = load_parameters()
    return Case(s0=s0, v=120.0, N0=p["wheel_force"] / 1e3, b_M=p["motor_slope"], M0=M0_KNM,
                f=F_HZ, D=DECAY, dt=None, t_end=T_END)


def _linear(s0: float) -> compute.ResponseView:
    return compute.response_result(_point(s0))


def _cells(table: str, name: str) -> list[str]:
    """The texts of the cells of the row of output ``name``."""
    row = re.search(rf"<tr><td class=\"text\">{re.escape(name)} \[[^<]*\]</td>(.*?)</tr>", table)
    assert row is not None, name
    return [re.sub(r"<[^>]+>", "", cell) for cell in re.findall(r"<td[^>]*>(.*?)</td>",
                                                                  row.group(1))]


def _number(cell: str) -> float:
    return float(cell.replace(",", ""))


def _half_digit(cell: str) -> float:
    """Half the last digit a cell shows (format_kilo: 3 digits or more, so 0.5 from 100 kN m)."""
    decimals = len(cell.split(".")[1]) if "." in cell else 0
    return 0.5 * 10.0 ** -decimals * (1 + 1e-9)


def _assert_shows(cell: str, value: float) -> None:
    """The cell is ``value`` rounded to the digits it shows."""
    assert abs(_number(cell) - value) <= _half_digit(cell), (cell, value)


def test_stable_case_shows_the_swing_of_id1_disc_clutch_at_its_time():
    response = _linear(0.005)
    table = peaks_html(response)
    # the model's history at the same point
    m = compute.model("", "calibrated")
    op = _point(0.005).operating_point()
    r = short_circuit_response(m, op, _point(0.005).short_circuit(), T_END,
                               compute.sampling_rate(F_HZ), ["ID1.disc_clutch.torque"])
    name = "ID1.disc_clutch.torque"
    swing = r.perturbation(name)
    # the fault's first large peak: the first local extremum of the swing within 10 % of its
    # largest magnitude
    extrema = np.flatnonzero(np.diff(np.sign(np.diff(swing))) != 0) + 1
    first = extrema[np.abs(swing[extrema]) >= 0.9 * np.abs(swing).max()][0]
    pre, vmax, tmax, vmin, tmin, vswing, tswing, quasi, dynamic, end_final = _cells(table, name)
    _assert_shows(pre, r.steady[name] / 1e3)
    _assert_shows(vswing, swing[first] / 1e3)
    assert float(tswing) == pytest.approx(r.t[first], abs=0.6e-4)
    assert float(tswing) > 0.0  # not the pre-fault value at 0 s
    y = r.outputs[name]
    _assert_shows(vmin, y.min() / 1e3)
    _assert_shows(vmax, y.max() / 1e3)
    assert float(tmin) == pytest.approx(r.t[np.argmin(y)], abs=0.6e-4)
    assert float(tmax) == pytest.approx(r.t[np.argmax(y)], abs=0.6e-4)
    # the swing's parts add up to it (to the table's rounding) and the quasi-static part is the
    # lost motor torque (ID1's pre-fault torque, within 5 %: the first creep-damped drift)
    # three rounded cells: their rounding errors add up
    assert abs(_number(quasi) + _number(dynamic) - _number(vswing)) <= (
        _half_digit(quasi) + _half_digit(dynamic) + _half_digit(vswing))
    assert _number(quasi) == pytest.approx(-r.steady[name] / 1e3, rel=0.05)
    assert "→" in end_final
    assert "quasi-static" in table
    assert "unbounded" not in table


def test_unstable_case_says_unbounded_with_the_growth_rate_beside_the_nonlinear_peaks():
    response = _linear(0.014)
    m = compute.model("", "calibrated")
    op = _point(0.014).operating_point()
    growth = eigen_analysis(m, op, vectors=False).max_real_part
    assert growth > 0
    waiting = peaks_html(response, None, "computing…")
    assert "unbounded with linear creep" in waiting
    assert f"σ = <b>{growth:+.4g} 1/s</b>" in waiting
    assert "nonlinear creep: computing…" in waiting
    companion = compute.nonlinear_histories(_point(0.014), compute.ANTI_SLIP_OFF).response
    table = peaks_html(response, companion)
    assert "the physical answer" in table
    name = "ID1.disc_clutch.torque"
    limit, passes, pre, vmax, tmax, vmin, tmin, vswing, tswing = _cells(table, name)
    _assert_shows(pre, response.load_peaks.extremes[name].pre_fault / 1e3)
    first = min(c.time for c in short_circuit_response(
        m, op, _point(0.014).short_circuit(), T_END, compute.sampling_rate(F_HZ),
        [name]).limit_crossings if c.output == name)
    assert limit == "M_ad"
    assert float(passes) == pytest.approx(first, abs=0.6e-4)
    y, t = companion.outputs[name], companion.t
    _assert_shows(vmax, y.max() / 1e3)
    _assert_shows(vmin, y.min() / 1e3)
    assert float(tmax) == pytest.approx(t[np.argmax(y)], abs=0.6e-4)
    assert float(tmin) == pytest.approx(t[np.argmin(y)], abs=0.6e-4)
    k = np.argmax(np.abs(y - y[0]))
    _assert_shows(vswing, (y[k] - y[0]) / 1e3)
    assert float(tswing) == pytest.approx(t[k], abs=0.6e-4)
    assert abs(_number(vswing)) < 10 * response.M_ad / 1e3  # bounded: no 1e32
    # an output without a limit
    assert _cells(table, "ID1.disc_clutch.force_y")[:2] == ["—", "—"]


def test_a_wheel_order_crossing_names_the_running_check_it_drives():
    """A crossing of the Campbell diagram's ``wheel:20`` line drives the running case's check
    whose polygon orders hold order 20 at (within 2 % of) the crossing's speed; a ripple check
    still matches its own order by name; none: "—"."""
    from types import SimpleNamespace

    from app.results.tables import driven_check, order_name

    wheels = [{"input": "ID1.rim12.irregularity", "phase_deg": 0.0}]
    running = SimpleNamespace(v_kmh=100.0, component="ID1 gear seat", kind="press_fit_slip",
                              safety_factor=1.8, utilisation=1.5 / 1.8,
                              orders=({"order": 20, "f_hz": 141.5, "input_amplitude": 3e-5,
                                       "wheels": wheels, "amplitude": 1.0},))
    ripple = SimpleNamespace(v_kmh=100.0, component="ID1 axle", kind="torsional_fatigue",
                             safety_factor=4.0, utilisation=0.25,
                             orders=({"order": "el:6", "f_hz": 300.0, "amplitude": 1.0,
                                      "ripple_amplitude": 256.0},))
    assert order_name(running.orders[0]) == "wheel:20"
    assert order_name(ripple.orders[0]) == "el:6"
    at = SimpleNamespace(v_kmh=101.0, order="wheel:20")
    assert driven_check(at, (running, ripple)).startswith("ID1 gear seat")
    assert driven_check(SimpleNamespace(v_kmh=99.0, order="el:6"),
                        (running, ripple)).startswith("ID1 axle")
    assert driven_check(SimpleNamespace(v_kmh=120.0, order="wheel:20"), (running,)) == "—"
