"""``bogie response --creep …`` and ``bogie antislip``: the nonlinear response and the required
reaction time of the anti-slip protection from the command line (issue 10).

    bogie response … --creep linear|nonlinear|tangent [--anti-slip off|on --anti-slip-delay S
                   --anti-slip-threshold M_S --anti-slip-rate PER_S --anti-slip-floor F]
    bogie antislip --s0 0.014 --v 120 [--n0 --bm --params] [--limit N_m] [--delays A:B:N]
                   [--drives ID2|both] [--anti-slip-threshold … --anti-slip-rate … ] [--json]

``--creep linear`` (default) is the closed form of :mod:`model.analysis.response`; ``nonlinear`` and
``tangent`` run :func:`model.analysis.nonlinear.nonlinear_response`.  Files as ``bogie response`` writes
them, with the same output names (totals), plus per wheel ``<rim>.creepage`` [-],
``<rim>.slip_velocity`` [m/s], ``<rim>.utilisation`` [-] and the motor torques
``ID1.motor.torque``, ``ID2.motor.torque`` [N m].  Bad input: one line, exit status 2.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from app.cli.options import (
    UsageError,
    add_anti_slip_arguments,
    add_operating_point,
    anti_slip_from,
    load_model,
    number,
    parse_range,
)
from app.cli.output import emit, finish, limit_lines, write_series


def series(result) -> dict[str, tuple[np.ndarray, str]]:
    """Every time series of a nonlinear result: name -> (values, unit)."""
    out = {name: (y, result.units[name]) for name, y in result.outputs.items()}
    for rim in result.creepage:
        out[f"{rim}.creepage"] = (result.creepage[rim], "-")
        out[f"{rim}.slip_velocity"] = (result.slip_velocity[rim], "m/s")
        out[f"{rim}.utilisation"] = (result.utilisation[rim], "-")
    for name, y in result.motor_torques.items():
        out[name] = (y, "N m")
    return out


def summary_data(result) -> dict:
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


def summary_table(result) -> str:
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


def write_result(result, path: Path) -> None:
    write_series(path, result.t, result.M_C, series(result), result.steady, summary_data(result))


def cmd_nonlinear_response(args: argparse.Namespace, excitation, names, out: Path | None) -> None:
    """The ``--creep nonlinear|tangent`` branch of ``bogie response``."""
    from model.analysis.nonlinear import nonlinear_response

    anti_slip = anti_slip_from(args) if args.anti_slip == "on" else None
    model, op, _ = load_model(args)
    result = nonlinear_response(model, op, excitation, args.t_end, args.fs, creep=args.creep,
                                anti_slip=anti_slip, outputs=names, strength=args.strength)
    finish(args, result, out, write_result, summary_data, summary_table)


# --- bogie antislip ------------------------------------------------------------------------------

def register(subparsers) -> None:
    p = subparsers.add_parser("antislip", help="required reaction time of the anti-slip "
                              "protection (nonlinear creep) and the curve peak(delay)")
    add_operating_point(p, s0=0.014)
    p.add_argument("--limit", type=number("--limit (N m)", 0, 1e9, allowed="must be in (0, 1e9) "
                                          "N m"), default=None,
                   help="wheel-side torque limit [N m] (default M_ad = 2 N0 r0 μ_max)")
    p.add_argument("--delays", default="0:0.5:26", metavar="A:B:N",
                   help="delays of the curve [s] (default %(default)s)")
    p.add_argument("--drives", choices=("ID2", "both"), default="ID2",
                   help="whose disc clutch and driving shaft torques are limited (default ID2, "
                        "the drive the protection acts on)")
    p.add_argument("--t-end", type=number("--t-end (horizon, s)", 0, 60, high_open=False,
                                          allowed="must be in (0, 60] s"),
                   default=2.0, help="horizon of each run [s] (default %(default)s)")
    p.add_argument("--fs", type=number("--fs (sampling rate, Hz)", 250, 1e6,
                                       allowed="must be in (250, 1e6) Hz"),
                   default=10_000.0, help="sampling rate = step rate [Hz] (default %(default)s)")
    add_anti_slip_arguments(p, with_delay=False)
    p.set_defaults(func=cmd_antislip)


def cmd_antislip(args: argparse.Namespace) -> None:
    import sys

    from model.analysis.antislip import required_reaction_time

    delays = parse_range(args.delays, "--delays")
    if delays[0] < 0 or np.any(np.diff(delays) <= 0) or delays[-1] > 60:
        raise UsageError(f"--delays must increase from a value >= 0 to at most 60 s, got "
                         f"'{args.delays}'")
    if args.t_end * args.fs > 2_000_000:
        raise UsageError(f"--t-end × --fs = {args.t_end * args.fs:.0f} samples is too many: at "
                         "most 2000000")
    model, op, _ = load_model(args)
    drives = ("ID2",) if args.drives == "ID2" else ("ID1", "ID2")
    result = required_reaction_time(
        model, op, limit=args.limit, anti_slip=anti_slip_from(args, delay=False), delays=delays,
        drives=drives, t_end=args.t_end, fs=args.fs,
        progress=None if args.json else lambda text: print(text, file=sys.stderr, flush=True))
    a = result.anti_slip
    data = {"required_delay_s": result.required_delay, "reason": result.reason,
            "limit": result.limit, "limit_name": result.limit_name,
            "delays_s": result.delays.tolist(), "peak_torque": result.peak_torque.tolist(),
            "peak_output": list(result.peak_output),
            "detection_time_s": result.detection_time,
            "reaction_after_fault_s": result.reaction_after_fault,
            "unprotected_peak": result.unprotected_peak,
            "limited_outputs": list(result.limited_outputs),
            "fault_drive_peaks": result.fault_drive_peaks,
            "anti_slip": {"threshold_m_s": a.threshold, "rate_per_s": a.rate, "floor": a.floor},
            "operating_point": op.as_dict(), "t_end": args.t_end, "fs": args.fs}
    if result.required_delay is not None:
        verdict = (f"required reaction time: {result.required_delay:.3f} s after detection "
                   f"({result.reaction_after_fault:.3f} s after the fault)")
    elif result.reason == "no delay suffices":
        verdict = ("required reaction time: none of the delays suffices (the limit is passed "
                   f"already with delay {result.delays[0]:g} s)")
    else:
        verdict = ("required reaction time: every delay up to "
                   f"{result.delays[-1]:g} s keeps the torques below the limit")
    lines = [f"anti-slip at s0 = {op.s0:g}, v = {op.v_kmh:g} km/h: limit {result.limit_name} = "
             f"{result.limit:.6g} N m on |total| of {', '.join(result.limited_outputs)} "
             "(driving shaft × p)",
             f"protection: threshold {a.threshold:g} m/s, rate {a.rate:g} 1/s, floor {a.floor:g}; "
             + ("never detected" if result.detection_time is None
                else f"detected at {result.detection_time:.4f} s after the fault"),
             f"without protection: peak {result.unprotected_peak:.6g} N m", verdict, "",
             f"{'delay [s]':>9} {'peak [N m]':>12} {'peak/limit':>10}  output"]
    for delay, value, name in zip(result.delays, result.peak_torque, result.peak_output,
                                  strict=True):
        lines.append(f"{delay:>9.3f} {value:>12.6g} {value / result.limit:>10.4f}  {name}")
    emit(args, data, "\n".join(lines))
