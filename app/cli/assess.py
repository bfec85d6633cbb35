"""``bogie assess``: from loads to verdicts — every press fit, shaft section and coupling of both
drives checked in the five load cases, with safety factors and the governing check; with
``--samples`` the verdict under uncertainty.

    bogie assess [--s0 LIST] [--v LIST] [--n0 N] [--bm B] [--motor-bandwidth FC]
                 [--rail calibrated|dry|wet]
                 [--m0 M --f F --decay D] [--t-end T] [--fs FS]
                 [--unstable-s0 S --unstable-v V] [--anti-slip-delay T --anti-slip-threshold W
                 --anti-slip-rate R --anti-slip-floor F] [--starting-v V]
                 [--ripple ORDER=AMPLITUDE,… --ripple-v LIST]
                 [--no-running | --running-s0 LIST --running-v LIST --wheel-polygon N=µm,…
                 --random-multiple K] [--params FILE]
                 [--samples N [--seed S] [--indices] [--ranges FILE] [--write-samples DIR]]
                 [--scheduler tcp://HOST:PORT | --workers N | --serial] [--json]

A LIST is ``A,B,C`` or ``A:B:N``, increasing; speeds in km/h.  ``--s0``/``--v`` are the short-circuit
case's grid (stable creepages only), as ``bogie envelope --phase all`` takes them; without
``--t-end`` its horizon covers the settling to the static response of the vehicle's
deceleration.  ``--n0``, ``--bm`` and ``--motor-bandwidth`` (the converter's torque control
f_c [Hz]; default the set's) hold for every case.  That grid runs on the study engine as
the envelope does (a local Dask cluster by default, ``--scheduler`` a running one, ``--serial`` in
this process); the other cases are single runs in this process.  The ripple case takes the set's
ripple amplitudes or ``--ripple`` (as ``bogie ripple``), over ``--ripple-v`` (default 10:200:20
km/h, refined at every resonance).  The running case (left out with ``--no-running``, and
under ``--samples``): mean traction, the ripple, polygonal wheels (``--wheel-polygon``, default
20=30: order 20, 30 µm, an assumed amplitude) and ``--random-multiple`` (default 3) times the RMS
under the random track, over ``--running-v`` (default 20:200:10 km/h) at ``--running-s0``
(default 0.002,0.005, the ripple case's; a point whose running system has a growing mode is left
out and named).  ``--samples N`` (a power of two) runs the assessment for N
scrambled Sobol' samples of the unknowns' prior ranges (model.studies.verdict_priors; ``--ranges``
a TOML file of others) on the study engine, every sample a work item, and prints each check's
5/50/95 % band and probability of falling below its required factor; ``--indices`` adds the
Sobol indices (N (d + 2) dynamics runs), ``--write-samples DIR`` each sample's complete parameter
set as TOML.  ``--json`` prints
``{"load_cases": [...], "checks": [...], "governing": {...}}``
(model.studies.assessment.Assessment.as_dict, with the creep law ``rail``).  Bad input (an
unstable grid point, unphysical strength data in ``--params``): one line on stderr, exit status 2;
Ctrl-C: exit status 130.
"""

from __future__ import annotations

import argparse
import json
import math
import sys

from app.cli.case_lists import add_case_lists, case_lists
from app.cli.options import (
    MAX_SAMPLES,
    MIN_SAMPLES_PER_PERIOD,
    PARAMETER_FILE,
    WHEEL_POLYGON,
    UsageError,
    add_anti_slip_arguments,
    add_engine_options,
    add_rail,
    add_short_circuit,
    add_time_grid,
    add_wheel_force_and_motor_slope,
    anti_slip_from,
    bounded,
    check_sample_count,
    check_samples,
    input_file,
    load_parameters_from,
    non_negative_int,
    quantity_values,
    short_circuit_from,
)
from app.cli.output import emit, writable_path
from app.cli.runs import ProgressBar, study_engine

GRID = ("s0", "v")  # the quantities the short_circuit case takes a list of


def _load_ranges(path: str):
    from model.studies.verdict_priors import load_ranges

    return load_ranges(path)


def register(subparsers) -> None:
    p = subparsers.add_parser("assess", help="verdicts: safety factors of every press fit, "
                              "shaft and coupling in the short-circuit, unstable-adhesion and "
                              "starting load cases")
    # the short_circuit grid: lists of s0 and v (stable creepages around the operating creepage,
    # the speed range of service); one value of each other quantity of the point, for every case
    add_case_lists(p, "point", names=GRID, defaults={"s0": "0.002,0.005", "v": "80,120,200"},
                   what="short_circuit: ")
    add_wheel_force_and_motor_slope(p)
    add_rail(p)
    add_short_circuit(p, phase=False)  # every fault instant: no --phase
    add_time_grid(p, "short_circuit horizon (default: until the quasi-static part is within "
                  "1 %% of the static response to the lost torque, at least 2 s, at most 60 s)",
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
    ripple = p.add_argument_group("ripple (both converters' torque ripple, steady forced response)")
    ripple.add_argument("--ripple", default=None, metavar="ORDER=AMPLITUDE,…",
                        help="each converter's ripple [N m] per order, e.g. el:6=256,el:12=128 "
                             "or fixed:450=50 (default: the set's ripple_el6_amplitude and "
                             "ripple_el12_amplitude)")
    ripple.add_argument("--ripple-v", default="10:200:20", metavar="LIST",
                        help="speeds [km/h] before the refinement at the resonances "
                             "(default %(default)s)")
    running = p.add_argument_group("running (mean traction, ripple, wheel polygon, random track)")
    running.add_argument("--running", action=argparse.BooleanOptionalAction, default=None,
                         help="the running load case (docs/assessment.md): one of the default "
                              "cases; --no-running leaves it out (seconds less)")
    running.add_argument("--running-s0", default="0.002,0.005", metavar="LIST",
                         help="creepages of the running case (default %(default)s)")
    running.add_argument("--running-v", default="20:200:10", metavar="LIST",
                         help="speeds [km/h] of the running case (default %(default)s)")
    running.add_argument("--wheel-polygon", type=WHEEL_POLYGON, default="20=30", metavar="N=µm,…",
                         help="polygonal wheels: order = radial amplitude [µm] (default "
                              "%(default)s: an assumed amplitude, docs/resonance.md)")
    running.add_argument("--random-multiple", type=bounded("--random-multiple", "[0, 10]"),
                         default=3.0, help="the random track's part as this multiple of its "
                                           "RMS (default %(default)s)")
    samples = p.add_argument_group("the verdict under uncertainty")
    samples.add_argument("--samples", type=int, default=None, metavar="N",
                         help="N scrambled Sobol' samples (a power of two) of the unknowns' "
                              "prior ranges, each a whole assessment")
    samples.add_argument("--seed", type=non_negative_int("--seed"), default=12,
                         help="the scrambling's seed (default %(default)s)")
    samples.add_argument("--indices", action="store_true",
                         help="first-order and total Sobol indices (N (d + 2) dynamics runs)")
    samples.add_argument("--ranges", type=input_file(_load_ranges), default=None, metavar="FILE",
                         help="TOML file of prior ranges: name = { low = …, high = … }")
    samples.add_argument("--write-samples", default=None, metavar="DIR",
                         help="write each sample's complete parameter set as TOML into DIR")
    samples.add_argument("--out", default=None, metavar="FILE.json",
                         help="write the result as JSON (into the server's studies folder: the "
                              "Verdicts tab shows its bands)")
    p.add_argument("--params", type=PARAMETER_FILE, default=None, metavar="FILE",
                   help="parameter file (TOML; default: the calibrated set; strength data it "
                        "lacks are the default set's)")
    add_engine_options(p.add_argument_group("where the short_circuit grid runs (as bogie "
                                            "envelope)"))
    p.add_argument("--json", action="store_true", help="machine-readable JSON output")
    p.set_defaults(func=cmd_assess)


def options_from_args(args: argparse.Namespace):
    """(parameters, :class:`model.studies.assessment.AssessmentOptions`) from the options."""
    from model.mechanics.excitation import ExcitationError, parse_amplitudes
    from model.mechanics.operating_point import KMH
    from model.studies.assessment import LOAD_CASES, AssessmentOptions
    from model.studies.envelope import rail_parameters

    parameters = rail_parameters(load_parameters_from(args), args.rail)
    grid = case_lists(args, parameters, "point", names=GRID)  # SI
    s0, v = grid["s0"], grid["v"]
    if args.t_end is not None:
        check_samples(args)
    elif 60.0 * args.fs > MAX_SAMPLES:
        raise UsageError(f"--fs = {args.fs:g} Hz: the automatic horizon may reach 60 s, at most "
                         f"{MAX_SAMPLES / 60:.0f} Hz (or give --t-end)")
    if args.fs < MIN_SAMPLES_PER_PERIOD * args.f:
        raise UsageError(f"--fs = {args.fs:g} Hz is too low to resolve the excitation at f = "
                         f"{args.f:g} Hz: must be at least {MIN_SAMPLES_PER_PERIOD * args.f:g} Hz")
    try:
        ripple = None if args.ripple is None else parse_amplitudes(args.ripple)
    except ExcitationError as error:
        raise UsageError(f"--ripple: {error}") from None
    ripple_v = [x * KMH for x in quantity_values(args.ripple_v, "v", increasing=True,
                                                 option="--ripple-v")]
    running = {}
    if with_running(args):
        from model.analysis.wheel_excitation import parse_polygon

        running = {"cases": (*LOAD_CASES, "running"),
                   "running_s0": tuple(quantity_values(args.running_s0, "s0", increasing=True,
                                                       option="--running-s0")),
                   "running_v": tuple(x * KMH for x in quantity_values(
                       args.running_v, "v", increasing=True, option="--running-v")),
                   "wheel_polygon": parse_polygon(args.wheel_polygon),
                   "random_multiple": args.random_multiple}
    options = AssessmentOptions(
        s0=tuple(s0), v=tuple(v), N0=args.n0, b_M=args.bm, excitation=short_circuit_from(args),
        t_end=args.t_end, fs=args.fs, unstable_s0=args.unstable_s0,
        unstable_v=args.unstable_v * KMH, anti_slip=anti_slip_from(args),
        starting_v=args.starting_v * KMH, ripple=ripple, ripple_v=tuple(ripple_v), **running)
    return parameters, options


def with_running(args: argparse.Namespace) -> bool:
    """Whether the running case is computed: by default, except under ``--samples`` (the
    verdict under uncertainty has the four other cases); ``--running`` with ``--samples`` is
    refused (:class:`UsageError`)."""
    if args.samples is None:
        return args.running is not False
    if args.running:
        raise UsageError("--running and --samples: the running case is not part of the verdict "
                         "under uncertainty (leave --running out)")
    return False


def assessment_table(result) -> str:
    """The checks as text: per load case its description and horizon, then one row per check."""
    from model.analysis.assessment import KIND_NAMES, VERDICT_WORDS, verdict_colour

    lines = []
    for case in result.cases:
        horizon = "steady" if case.horizon is None else f"horizon {case.horizon:g} s"
        lines.append(f"{case.name} ({horizon}): {case.description}")
    lines += ["", f"{'component':<20} {'check':<26} {'load case':<18} {'load [N m]':>11} "
                  f"{'capacity [N m]':>14} {'safety factor':>13} {'required':>8}  "
                  f"{'verdict':<12}  at"]
    notes = list(dict.fromkeys(c.note for c in result.checks if c.note))  # numbered in order
    for c in result.checks:
        at = "steady" if math.isnan(c.time) else f"t = {c.time:.4g} s"
        if not math.isnan(c.rms):  # running: its worst speed, mean ± amplitude, the random RMS
            at = (f"{c.v_kmh:.4g} km/h, mean {c.mean:.4g} ± {c.alternating:.4g} N m (polygon "
                  f"{c.amplitude:.3g}, RMS {c.rms:.4g}; s0 = {c.scenario['s0']:g})")
        elif not math.isnan(c.alternating):  # under the ripple: its worst speed, mean ± amplitude
            at = (f"{c.v_kmh:.4g} km/h, mean {c.mean:.4g} ± {c.alternating:.4g} N m "
                  f"({', '.join(o['order'] for o in c.orders)})")
        elif "v_kmh" in c.scenario:
            at += f", s0 = {c.scenario['s0']:.4g}, {c.scenario['v_kmh']:g} km/h"
        if c.note:
            at += f" [{notes.index(c.note) + 1}]"
        lines.append(f"{c.component:<20} {KIND_NAMES[c.kind]:<26} {c.load_case:<18} "
                     f"{c.load:>11.4g} {c.capacity:>14.4g} {c.safety_factor:>13.3g} "
                     f"{c.required:>8.3g}  {VERDICT_WORDS[verdict_colour(c)]:<12}  {at}")
    lines += [f"[{k}] {note}" for k, note in enumerate(notes, start=1)]
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

    writable_path(args.write_samples, "--write-samples", directory=True,  # before any work
                  parents=True)
    writable_path(args.out, "--out", suffixes=(".json",))
    if args.samples is not None:
        check_sample_count(args.samples)
    parameters, options = options_from_args(args)
    short_circuit_points(parameters, options)  # an unstable grid point: refused before any work
    if args.samples is not None:
        return assess_under_uncertainty(args, parameters, options)
    for name in ("indices", "ranges", "write_samples", "out"):
        if getattr(args, name):
            raise UsageError(f"--{name.replace('_', '-')} needs --samples")
    with study_engine(args, "assess") as (mapper, where):
        print(f"assess: short_circuit ({len(options.s0) * len(options.v)} point(s) on {where}), "
              f"unstable_adhesion, starting, ripple{', running' if 'running' in options.cases else ''} …",
              file=sys.stderr)
        result = assess(parameters, options, mapper, ProgressBar("assess: short_circuit",
                                                                 unit="points"))
    emit(args, {**result.as_dict(), "rail": args.rail}, assessment_table(result))


def assess_under_uncertainty(args: argparse.Namespace, parameters, options) -> None:
    """``--samples N``: the verdict under uncertainty (model.studies.verdict_uncertainty) on the
    study engine, a progress bar per dynamics run."""
    from pathlib import Path

    from model.studies.verdict_priors import (
        check_ranges,
        default_ranges,
        load_ranges,
        merge_ranges,
        relevant_ranges,
    )
    from model.studies.verdict_uncertainty import run_verdict_uncertainty, save_sample_parameters

    ranges = None if args.ranges is None else merge_ranges(load_ranges(args.ranges))
    check_ranges(parameters, relevant_ranges(default_ranges() if ranges is None else ranges,
                                             options)[0])  # refused before any work
    with study_engine(args, "assess") as (mapper, where):
        print(f"assess: {args.samples} samples{' with indices' if args.indices else ''} on "
              f"{where} …", file=sys.stderr)
        result = run_verdict_uncertainty(
            parameters, args.samples, seed=args.seed, indices=args.indices, options=options,
            ranges=ranges, map_unordered=mapper,
            progress=ProgressBar("assess: samples", unit="dynamics runs"))
    if args.out is not None:
        Path(args.out).write_text(json.dumps({**result.as_dict(), "rail": args.rail}, indent=1,
                                             allow_nan=False) + "\n", encoding="utf-8")
        print(f"assess: wrote {args.out}", file=sys.stderr)
    if args.write_samples is not None:
        written = save_sample_parameters(parameters, result, args.write_samples)
        print(f"assess: wrote {len(written)} parameter sets to {args.write_samples}",
              file=sys.stderr)
    emit(args, {**result.as_dict(), "rail": args.rail}, result.summary())
