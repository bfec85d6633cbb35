"""``bogie antislip``: the required reaction time of the anti-slip protection (nonlinear creep)
and the curve peak(delay) from the command line.

    bogie antislip --s0 0.014 --v 120 [--n0 --bm --params] [--limit N_m] [--delays A:B:N]
                   [--drives ID2|both] [--anti-slip-threshold … --anti-slip-rate … ] [--json]

Each delay of the grid is one run of :func:`model.analysis.nonlinear.nonlinear_response`
(:func:`model.analysis.antislip.required_reaction_time`); progress goes to stderr unless
``--json``.  The nonlinear response itself is ``bogie response --creep nonlinear``
(:mod:`app.cli.response`).  Bad input: one line on stderr, exit status 2.
"""

from __future__ import annotations

import argparse

import numpy as np

from app.cli.options import (
    UsageError,
    add_anti_slip_arguments,
    add_operating_point,
    add_time_grid,
    anti_slip_from,
    bounded,
    check_samples,
    load_model,
    parse_range,
)
from app.cli.output import emit


def register(subparsers) -> None:
    p = subparsers.add_parser("antislip", help="required reaction time of the anti-slip "
                              "protection (nonlinear creep) and the curve peak(delay)")
    add_operating_point(p, s0=0.014)
    p.add_argument("--limit", type=bounded("--limit (N m)", "(0, 1e9)", "N m"), default=None,
                   help="wheel-side torque limit [N m] (default M_ad = 2 N0 r0 μ_max)")
    p.add_argument("--delays", default="0:0.5:26", metavar="A:B:N",
                   help="delays of the curve [s] (default %(default)s)")
    p.add_argument("--drives", choices=("ID2", "both"), default="ID2",
                   help="whose disc clutch and driving shaft torques are limited (default ID2, "
                        "the drive the protection acts on)")
    # --fs is the step rate of the nonlinear runs: above 250 Hz so that the 90 Hz short circuit
    # (fixed here) gets more than the 2.5 steps per period bogie response asks of --fs
    add_time_grid(p, "horizon of each run", "sampling rate = step rate", fs="(250, 1e6)")
    add_anti_slip_arguments(p, with_delay=False)
    p.set_defaults(func=cmd_antislip)


def cmd_antislip(args: argparse.Namespace) -> None:
    import sys

    from model.analysis.antislip import required_reaction_time

    delays = parse_range(args.delays, "--delays")
    if delays[0] < 0 or np.any(np.diff(delays) <= 0) or delays[-1] > 60:
        raise UsageError(f"--delays must increase from a value >= 0 to at most 60 s, got "
                         f"'{args.delays}'")
    check_samples(args)
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
