"""``bogie response``: short-circuit time response (spec §4) from the command line.

    bogie response --s0 0.005 --v 120 [--n0 N --bm B] [--m0 M0 --f F --decay D --phase DT]
                   --t-end T --fs FS [--out FILE.npz|.csv|.json] [--outputs a,b,…]
                   [--creep linear|nonlinear|tangent [--anti-slip off|on --anti-slip-delay S
                   --anti-slip-threshold M_S --anti-slip-rate PER_S --anti-slip-floor F]
                   [--strength N_m]]

``--creep linear`` (default) is the closed form of :mod:`model.analysis.response`; ``nonlinear``
and ``tangent`` run :func:`model.analysis.nonlinear.nonlinear_response`.

Without ``--out``: a table of peaks (totals), their times and dominant frequencies, and the
limit crossings.  Files: ``.npz`` (array ``t`` [s], one array per output name (totals), ``M_C``,
plus ``units``/``steady``), ``.csv`` (a column per output, the unit in the header), ``.json``.
The nonlinear runs write the same output names plus per wheel ``<rim>.creepage`` [-],
``<rim>.slip_velocity`` [m/s], ``<rim>.utilisation`` [-] and the motor torques
``ID1.motor.torque``, ``ID2.motor.torque`` [N m].  Bad input: one line on stderr, exit status 2.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from app.cli.options import (
    add_creep_arguments,
    add_operating_point,
    add_output_selection,
    add_short_circuit,
    add_time_grid,
)
from app.cli.output import check_history_file, finish, limit_lines, write_series
from app.cli.runs import history_from_args


def register(subparsers) -> None:
    p = subparsers.add_parser("response", help="short-circuit time response of the drive loads")
    # add_history_options, with --out before the creep options (their order in --help)
    add_operating_point(p)
    add_short_circuit(p)
    add_time_grid(p, "horizon", "output sampling rate")
    add_output_selection(p)
    p.add_argument("--out", default=None, help="write .npz, .csv or .json")
    add_creep_arguments(p)
    p.set_defaults(func=cmd_response)


def cmd_response(args: argparse.Namespace) -> None:
    out = check_history_file(args.out)
    result = history_from_args(args)
    if args.creep != "linear":
        finish(args, result, out, write_nonlinear, nonlinear_summary, nonlinear_table)
        return
    finish(args, result, out, write_linear, linear_summary, linear_table)


def linear_summary(result) -> dict:
    op = result.operating_point
    return {
        "operating_point": op.as_dict(),
        "excitation": {"M0": result.excitation.M0, "f": result.excitation.f,
                       "D": result.excitation.D, "dt": result.phase_shift},
        "motor_torque": result.motor_torque, "method": result.method,
        "error_estimate": None if math.isnan(result.error_estimate) else result.error_estimate,
        "truncated_at": result.truncated_at, "limits": result.limits,
        "highest_excited_hz": result.highest_excited_hz,
        "outputs": {name: {"unit": result.units[name], "steady": result.steady[name],
                           "peak": result.peaks[name], "peak_time": result.peak_times[name],
                           "perturbation_peak": result.perturbation_peaks[name],
                           "perturbation_peak_time": result.perturbation_peak_times[name],
                           "dominant_frequencies_hz": list(result.dominant_frequencies[name])}
                    for name in result.outputs},
        "limit_crossings": [{"output": c.output, "limit": c.limit_name, "limit_value": c.limit,
                             "time": c.time, "value": c.value} for c in result.limit_crossings],
    }


def linear_table(result) -> str:
    op, e = result.operating_point, result.excitation
    lines = [f"short circuit of ID1's motor at s0 = {op.s0:g}, v = {op.v_kmh:g} km/h, "
             f"N0 = {op.N0:g} N: M(s0, v) = {result.motor_torque:.6g} N m, M0 = {e.M0:g} N m, "
             f"f = {e.f:g} Hz, D = {e.D:g}, Δt = {result.phase_shift:.4g} s",
             f"{len(result.t)} points to t = {result.t[-1]:g} s, method {result.method}"
             + ("" if math.isnan(result.error_estimate)
                else f" (rounding-error indicator {result.error_estimate:.1e}, not a bound)")
             + (f"; TRUNCATED at {result.truncated_at:g} s (growth)" if result.truncated_at
                else ""),
             "values are totals (pre-fault + perturbation)", "",
             f"{'output':<30} {'unit':<4} {'steady':>11} {'peak':>11} {'at [s]':>8} "
             f"{'Δpeak':>11}  dominant frequencies [Hz]"]
    for name in result.outputs:
        freqs = ", ".join(f"{x:.4g}" for x in result.dominant_frequencies[name])
        lines.append(f"{name:<30} {result.units[name]:<4} {result.steady[name]:>11.4g} "
                     f"{result.peaks[name]:>11.4g} {result.peak_times[name]:>8.4f} "
                     f"{result.perturbation_peaks[name]:>11.4g}  {freqs}")
    return "\n".join(lines + limit_lines(result))


def write_linear(result, path: Path) -> None:
    write_series(path, result.t, result.M_C,
                 {name: (result.outputs[name], result.units[name]) for name in result.outputs},
                 result.steady, linear_summary(result))


# --- --creep nonlinear | tangent: the step-by-step solution with creep forces, anti-slip --------

def nonlinear_series(result) -> dict[str, tuple[np.ndarray, str]]:
    """Every time series of a nonlinear result: name -> (values, unit)."""
    out = {name: (y, result.units[name]) for name, y in result.outputs.items()}
    for rim in result.creepage:
        out[f"{rim}.creepage"] = (result.creepage[rim], "-")
        out[f"{rim}.slip_velocity"] = (result.slip_velocity[rim], "m/s")
        out[f"{rim}.utilisation"] = (result.utilisation[rim], "-")
    for name, y in result.motor_torques.items():
        out[name] = (y, "N m")
    return out


def nonlinear_summary(result) -> dict:
    a = result.anti_slip
    return {
        "operating_point": result.operating_point.as_dict(),
        "excitation": {"M0": result.excitation.M0, "f": result.excitation.f,
                       "D": result.excitation.D},
        "creep": result.creep_model, "motor_torque": result.motor_torque,
        "mu_max": result.mu_max, "limits": result.limits,
        "anti_slip": None if a is None else {"delay_s": a.delay, "threshold_m_s": a.threshold,
                                             "rate_per_s": a.rate, "floor": a.floor},
        "detection_time": result.detection_time, "action_time": result.action_time,
        "newton_iterations_per_step": result.newton_iterations,
        "outputs": {name: {"unit": result.units[name], "steady": result.steady[name],
                           "peak": result.peaks[name], "peak_time": result.peak_times[name],
                           "perturbation_peak": result.perturbation_peaks[name]}
                    for name in result.outputs},
        "wheels": {rim: {"creepage_min": float(result.creepage[rim].min()),
                         "creepage_max": float(result.creepage[rim].max()),
                         "slip_velocity_max": float(np.abs(result.slip_velocity[rim]).max()),
                         "utilisation_max": float(np.abs(result.utilisation[rim]).max())}
                   for rim in result.creepage},
        "limit_crossings": [{"output": c.output, "limit": c.limit_name, "limit_value": c.limit,
                             "time": c.time, "value": c.value} for c in result.limit_crossings],
    }


def nonlinear_table(result) -> str:
    op, a = result.operating_point, result.anti_slip
    protection = "anti-slip off" if a is None else (
        f"anti-slip on: threshold {a.threshold:g} m/s, delay {a.delay:g} s, rate {a.rate:g} 1/s, "
        f"floor {a.floor:g}; " + ("never detected" if result.detection_time is None else
                                  f"detected at {result.detection_time:.4f} s, acts at "
                                  f"{result.action_time:.4f} s"))
    lines = [f"short circuit of ID1's motor at s0 = {op.s0:g}, v = {op.v_kmh:g} km/h, "
             f"N0 = {op.N0:g} N, creep {result.creep_model}: M(s0, v) = "
             f"{result.motor_torque:.6g} N m, μ_max = {result.mu_max:.4g}",
             protection,
             f"{len(result.t)} points to t = {result.t[-1]:g} s; values are totals "
             f"(pre-fault + perturbation); {result.newton_iterations:.2f} Newton iterations/step",
             "", f"{'output':<30} {'unit':<4} {'steady':>11} {'peak':>11} {'at [s]':>8} "
             f"{'Δpeak':>11}"]
    for name in result.outputs:
        lines.append(f"{name:<30} {result.units[name]:<4} {result.steady[name]:>11.4g} "
                     f"{result.peaks[name]:>11.4g} {result.peak_times[name]:>8.4f} "
                     f"{result.perturbation_peaks[name]:>11.4g}")
    lines += ["", f"{'wheel':<12} {'creepage min':>12} {'max':>10} {'|slip v| max [m/s]':>19} "
              f"{'|μ|/μ_max max':>14}"]
    for rim in result.creepage:
        lines.append(f"{rim:<12} {result.creepage[rim].min():>12.5f} "
                     f"{result.creepage[rim].max():>10.5f} "
                     f"{np.abs(result.slip_velocity[rim]).max():>19.4g} "
                     f"{np.abs(result.utilisation[rim]).max():>14.4f}")
    for name, y in result.motor_torques.items():
        lines.append(f"{name}: from {y[0]:.5g} to {y[-1]:.5g} N m (min {y.min():.5g}, max "
                     f"{y.max():.5g})")
    return "\n".join(lines + limit_lines(result))


def write_nonlinear(result, path: Path) -> None:
    write_series(path, result.t, result.M_C, nonlinear_series(result), result.steady,
                 nonlinear_summary(result))
