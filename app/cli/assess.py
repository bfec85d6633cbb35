"""``bogie assess``: from loads to verdicts — every press fit, shaft section and coupling of both
drives checked in the three load cases, with safety factors and the governing check.

    bogie assess [--s0 LIST] [--v LIST] [--n0 N] [--bm B] [--rail calibrated|dry|wet]
                 [--m0 M --f F --decay D] [--t-end T] [--fs FS]
                 [--unstable-s0 S --unstable-v V] [--anti-slip-delay T --anti-slip-threshold W
                 --anti-slip-rate R --anti-slip-floor F] [--starting-v V] [--params FILE]
                 [--scheduler tcp://HOST:PORT | --workers N | --serial] [--json]

A LIST is ``A,B,C`` or ``A:B:N``, increasing; speeds in km/h.  ``--s0``/``--v`` are the short-circuit
case's grid (stable creepages only), as ``bogie envelope --phase all`` takes them; without
``--t-end`` its horizon covers ID2's quasi-static take-over.  That grid runs on the study engine as
the envelope does (a local Dask cluster by default, ``--scheduler`` a running one, ``--serial`` in
this process); the other two cases are single runs in this process.  ``--json`` prints
``{"load_cases": [...], "checks": [...], "governing": {...}}``
(model.studies.assessment.Assessment.as_dict, with the creep law ``rail``).  Bad input (an
unstable grid point, unphysical strength data in ``--params``): one line on stderr, exit status 2;
Ctrl-C: exit status 130.
"""

from __future__ import annotations

import argparse
import math
import sys

from app.cli.options import (
    MAX_SAMPLES,
    MIN_SAMPLES_PER_PERIOD,
    UsageError,
    add_anti_slip_arguments,
    add_engine_options,
    add_rail,
    add_short_circuit,
    add_time_grid,
    add_wheel_force_and_motor_slope,
    anti_slip_from,
    bounded,
    check_samples,
    load_parameters_from,
    quantity_values,
    short_circuit_from,
)
from app.cli.output import emit
from app.cli.runs import ProgressBar, study_engine


def register(subparsers) -> None:
    p = subparsers.add_parser("assess", help="verdicts: safety factors of every press fit, "
                              "shaft and coupling in the short-circuit, unstable-adhesion and "
                              "starting load cases")
    p.add_argument("--s0", default="0.002,0.005", metavar="LIST",
                   help="short_circuit: stable creepages s0 [-] (default %(default)s)")
    p.add_argument("--v", default="80,120,200", metavar="LIST",
                   help="short_circuit: speeds [km/h] (default %(default)s)")
    add_wheel_force_and_motor_slope(p)
    add_rail(p)
    add_short_circuit(p, phase=False)  # every fault instant: no --phase
    add_time_grid(p, "short_circuit horizon (default: until ID2's quasi-static take-over is "
                  "within 1 %% of its end, at least 2 s, at most 60 s)",
                  "sampling rate of every history", t_end_default=None)
    unstable = p.add_argument_group("unstable_adhesion (nonlinear creep, ID2's anti-slip "
                                    "protection)")
    unstable.add_argument("--unstable-s0", type=bounded("--unstable-s0 (creepage)", "(0, 1)"),
                          default=0.014, help="creepage beyond the adhesion maximum [-] "
                                              "(default %(default)s)")
    unstable.add_argument("--unstable-v", type=bounded("--unstable-v (speed, km/h)", "[1, 500]",
                                                       "km/h"),
                          default=120.0, help="speed [km/h] (default %(default)s)")
    add_anti_slip_arguments(unstable)
    p.add_argument("--starting-v", type=bounded("--starting-v (speed, km/h)", "[1, 500]", "km/h"),
                   default=5.0, help="starting: speed [km/h] (default %(default)s)")
    p.add_argument("--params", default=None, metavar="FILE",
                   help="parameter file (TOML; default: the calibrated set; strength data it "
                        "lacks are the default set's)")
    add_engine_options(p.add_argument_group("where the short_circuit grid runs (as bogie "
                                            "envelope)"))
    p.add_argument("--json", action="store_true", help="machine-readable JSON output")
    p.set_defaults(func=cmd_assess)


def options_from_args(args: argparse.Namespace):
    """(parameters, :class:`model.studies.assessment.AssessmentOptions`) from the options."""
    from model.mechanics.operating_point import KMH
    from model.studies.assessment import AssessmentOptions
    from model.studies.envelope import rail_parameters

    parameters = rail_parameters(load_parameters_from(args), args.rail)
    s0 = quantity_values(args.s0, "s0", increasing=True)
    v = [x * KMH for x in quantity_values(args.v, "v", increasing=True)]
    if args.t_end is not None:
        check_samples(args)
    elif 60.0 * args.fs > MAX_SAMPLES:
        raise UsageError(f"--fs = {args.fs:g} Hz: the automatic horizon may reach 60 s, at most "
                         f"{MAX_SAMPLES / 60:.0f} Hz (or give --t-end)")
    if args.fs < MIN_SAMPLES_PER_PERIOD * args.f:
        raise UsageError(f"--fs = {args.fs:g} Hz is too low to resolve the excitation at f = "
                         f"{args.f:g} Hz: must be at least {MIN_SAMPLES_PER_PERIOD * args.f:g} Hz")
    options = AssessmentOptions(
        s0=tuple(s0), v=tuple(v), N0=args.n0, b_M=args.bm, excitation=short_circuit_from(args),
        t_end=args.t_end, fs=args.fs, unstable_s0=args.unstable_s0,
        unstable_v=args.unstable_v * KMH, anti_slip=anti_slip_from(args),
        starting_v=args.starting_v * KMH)
    return parameters, options


def assessment_table(result) -> str:
    """The checks as text: per load case its description and horizon, then one row per check."""
    from model.analysis.assessment import KIND_NAMES, VERDICT_WORDS, verdict_colour

    lines = []
    for case in result.cases:
        horizon = "steady" if case.horizon is None else f"horizon {case.horizon:g} s"
        lines.append(f"{case.name} ({horizon}): {case.description}")
    lines += ["", f"{'component':<20} {'check':<16} {'load case':<18} {'load [N m]':>11} "
                  f"{'capacity [N m]':>14} {'safety factor':>13} {'required':>8}  "
                  f"{'verdict':<12}  at"]
    for c in result.checks:
        at = "steady" if math.isnan(c.time) else f"t = {c.time:.4g} s"
        if "v_kmh" in c.scenario:
            at += f", s0 = {c.scenario['s0']:.4g}, {c.scenario['v_kmh']:g} km/h"
        lines.append(f"{c.component:<20} {KIND_NAMES[c.kind]:<16} {c.load_case:<18} "
                     f"{c.load:>11.4g} {c.capacity:>14.4g} {c.safety_factor:>13.3g} "
                     f"{c.required:>8.3g}  {VERDICT_WORDS[verdict_colour(c)]:<12}  {at}")
    g = result.governing
    failed = sum(not c.ok for c in result.checks)
    lines += ["", f"governing: {g.component} ({KIND_NAMES[g.kind]}) in {g.load_case}: safety "
                  f"factor {g.safety_factor:.3g} against {g.required:.3g} required — "
                  f"{'ok' if g.ok else 'NOT MET'}; {failed} of {len(result.checks)} checks "
                  "below their required factor",
              "margin short: the capacity holds, the safety factor is below the required one; "
              "overloaded: the load exceeds the capacity.  Strength data marked 'estimate' in "
              "the parameter set are assumptions (bogie parameters); not a certification to "
              "EN 13103-1 / EN 13260."]
    return "\n".join(lines)


def cmd_assess(args: argparse.Namespace) -> None:
    from model.studies.assessment import assess, short_circuit_points

    parameters, options = options_from_args(args)
    short_circuit_points(parameters, options)  # an unstable grid point: refused before any work
    with study_engine(args, "assess") as (mapper, where):
        print(f"assess: short_circuit ({len(options.s0) * len(options.v)} point(s) on {where}), "
              "unstable_adhesion, starting …", file=sys.stderr)
        result = assess(parameters, options, mapper, ProgressBar("assess: short_circuit",
                                                                 unit="points"))
    emit(args, {**result.as_dict(), "rail": args.rail}, assessment_table(result))
