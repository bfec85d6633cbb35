"""``bogie calibrate --out FILE``: fit the uncertain parameters to the published results
(:mod:`model.studies.calibration`: stage A, the creep law and gear ratio to the operating data;
stage J, bounded least squares on the analytic Jacobian) and write the set to FILE; progress on
stderr, the table of the targets (or ``--json``) on stdout.  ``--out`` is required: the command
writes only where it is told, and replacing the bundled default set
(``assets/parameters/calibrated.toml``) is said on stderr.

    bogie calibrate --out FILE [--from FILE] [--divergence-weight W] [--max-evaluations M] [--json]
    bogie calibrate --starts N --out FILE [--scheduler tcp://HOST:PORT | --workers W | --serial]
    bogie calibrate --start K --out FILE

``--starts N`` (default 16) is the global calibration (:mod:`model.studies.global_calibration`):
the same least squares from start 0 (the ``--from`` file's own values: what the command without
``--starts`` fits) and from N points of a scrambled Sobol' sequence within the bounds (starts 1 …
N), on the study engine (a local cluster by default); it writes the best start's set to FILE and
prints every start (cost, frequency and divergence errors, the front between them) and the
spread of the best starts per parameter.  ``--start K`` runs start K alone in this process and
writes its set: the same bytes the global search writes when K is its best (the command without
``--start`` is ``--start 0``).  ``--divergence-weight W``
weighs the two divergence rates at s0 = 0.014 in the last phase (default 1): the knob of the
trade between Table 1's frequencies and the divergence (docs/validation.md).  Bad input: one line on stderr,
exit status 2.

The command runs itself again with its numerics pinned (:mod:`model.studies.numerics`: OpenBLAS's
Haswell kernels on one thread, NumPy's loops without AVX-512), so that it writes the same bytes
on every x86-64 processor with AVX2 (given the same NumPy and SciPy releases); the local
cluster's workers inherit the pins.  A cluster reached by ``--scheduler`` runs in its workers'
own environment.
"""

from __future__ import annotations

import argparse
import os
import sys

from app.cli.options import (
    PARAMETER_FILE,
    UsageError,
    add_engine_options,
    non_negative_int,
    number,
    positive_int,
)
from app.cli.output import emit, writable_path


def register(subparsers) -> None:
    p = subparsers.add_parser("calibrate", help="fit the uncertain parameters to the published results")
    p.add_argument("--from", dest="from_file", type=PARAMETER_FILE, default=None, metavar="FILE",
                   help="the estimate: the prior, and the start of the single calibration "
                        "(default: estimate.toml)")
    p.add_argument("--out", default=None, metavar="FILE",
                   help="where to write the calibrated set (required; the bundled default set is "
                        "assets/parameters/calibrated.toml)")
    starts = p.add_mutually_exclusive_group()
    starts.add_argument("--starts", type=positive_int("--starts"), default=None, metavar="N",
                        help="global calibration from N Sobol' starts within the bounds "
                             "(the bundled runs: 16) on the study engine; writes the best "
                             "start's set")
    starts.add_argument("--start", type=non_negative_int("--start"), default=None, metavar="K",
                        help="run start K of the global calibration alone and write its set")
    p.add_argument("--max-evaluations", type=positive_int("--max-evaluations"), default=None,
                   help="trial parameter sets of each least-squares phase at most (default: "
                        "the calibration's own, as for the bundled set; smaller for a quick "
                        "check)")
    p.add_argument("--divergence-weight", type=number("--divergence-weight", 0.0, 1000.0,
                                                       allowed="a weight in (0, 1000)"),
                   default=None, metavar="W",
                   help="weight of the two divergence rates at s0 = 0.014 in the last phase "
                        "(default 1; the bundled set: see its header)")
    p.add_argument("--json", action="store_true", help="machine-readable JSON output (progress "
                                                       "goes to stderr either way)")
    add_engine_options(p)
    p.set_defaults(func=cmd_calibrate)


def _rows_json(rows) -> list[dict]:
    return [{"name": row.name, "published": row.target, "achieved": row.achieved,
             "unit": row.unit, "error": row.error} for row in rows]


def starts_table(result) -> str:
    """Every start (cost, the two errors, on the front) and the spread of the best starts."""
    lines = [f"{'start':>5} {'cost':>10} {'max |ΔIm|':>10} {'ranks ≤5%':>9} {'characters':>10} "
             f"{'λmax(0.014)':>12} {'Δ(+7.031)':>10} {'s':>6}  front"]
    for r in result.results:
        if r.failed:
            lines.append(f"{r.index:>5} failed: {r.failed}")
            continue
        mark = "best" if r.index == result.best else ""
        lines.append(f"{r.index:>5} {r.cost:>10.4g} {100 * r.frequency_error:>9.1f}% "
                     f"{r.ranks_within:>9} {r.characters:>10} {r.largest_real_unstable:>+12.3f} "
                     f"{100 * r.divergence_error:>9.1f}% {r.seconds:>6.0f}  "
                     f"{'yes' if r.index in result.front else ''} {mark}".rstrip())
    lines += ["", "spread of the best starts (share of the bounds; identified if at most 25 %):",
              f"{'parameter':34} {'low':>11} {'high':>11} {'share':>7}  identified"]
    for s in result.spread:
        lines.append(f"{s.name:34} {s.low:>11.4g} {s.high:>11.4g} {100 * s.share:>6.0f}%  "
                     f"{'yes' if s.identified else 'no'}")
    lines.append(f"\n{len(result.results)} starts (0: the start file's own values, 1 … "
                 f"{len(result.results) - 1}: Sobol' points) in {result.seconds:.0f} s on "
                 f"{result.where}; best: start {result.best}")
    return "\n".join(lines)


def cmd_calibrate(args: argparse.Namespace) -> None:
    from pathlib import Path

    from model.mechanics.parameters import CALIBRATED_FILE, ESTIMATE_FILE

    if not args.out:
        raise UsageError("--out FILE is required: where to write the calibrated set (the bundled "
                         f"default set is {CALIBRATED_FILE.relative_to(CALIBRATED_FILE.parents[2])})")
    start = Path(args.from_file) if args.from_file else ESTIMATE_FILE
    out = writable_path(args.out, "--out")
    _pin_numerics(args)
    if out.resolve() == CALIBRATED_FILE.resolve():
        print(f"bogie calibrate: replacing the bundled default set {CALIBRATED_FILE}", file=sys.stderr)
    from model.studies.calibration import PHASES, with_divergence_weight

    phases = PHASES if args.max_evaluations is None else tuple(
        (min(count, args.max_evaluations), weights) for count, weights in PHASES)
    if args.divergence_weight is not None:
        phases = with_divergence_weight(phases, args.divergence_weight)

    def progress(text: str) -> None:
        print(text, file=sys.stderr, flush=True)

    if args.starts is not None:
        _global(args, start, out, phases, progress)
        return
    from model.studies.global_calibration import run_start, write_start
    from model.studies.numerics import in_effect

    k = 0 if args.start is None else args.start  # without --start: start 0, the file's own values
    progress(f"calibrating from start {k} of the global calibration"
             f"{' (the values of ' + start.name + ')' if k == 0 else ''} …")
    result = run_start(k, start, phases, progress)
    if result.failed:
        raise UsageError(f"start {k} cannot be calibrated: {result.failed}")
    rows, table = write_start(result, out, start, args.divergence_weight)
    progress(f"wrote {out}")
    emit(args, {"out": str(out), "start": k, "cost": result.cost,
                "targets": _rows_json(rows), "numerics": in_effect()}, table)


def _pin_numerics(args: argparse.Namespace) -> None:
    """Run this command again in the pinned environment (before any work).  Only a command of
    its own: a call of :func:`app.cli.main.main` from Python runs in its caller's numerics."""
    if getattr(args, "command_line", False):
        run_pinned("bogie calibrate: ")


def run_pinned(prefix: str = "") -> None:
    """Run this process's command line again in the calibration's pinned environment
    (:mod:`model.studies.numerics`; NumPy's dispatch is chosen when it is imported, so the pins
    need a new process), unless it runs in it already; a processor that cannot take the pins is
    told so on stderr (``prefix``: the program's name there) and the process goes on."""
    from model.studies.numerics import description, is_pinned, reproducible_environment

    if is_pinned(os.environ):
        return
    environment = reproducible_environment(os.environ)
    if environment is None:
        print(f"{prefix}this processor cannot take the pinned numerics (x86-64 with AVX2 "
              "and FMA): the values written may differ in their last digits from another "
              "machine's", file=sys.stderr, flush=True)
        return
    print(f"{prefix}numerics pinned for reproducible bytes ({description()})",
          file=sys.stderr, flush=True)
    sys.stdout.flush()
    os.execve(sys.executable, [sys.executable, *sys.orig_argv[1:]], environment)


def _global(args, start, out, phases, progress) -> None:
    from app.cli.runs import study_engine
    from model.studies.global_calibration import global_search, write_start
    from model.studies.numerics import in_effect

    def done(result) -> None:
        if result.failed:
            progress(f"  start {result.index}: failed: {result.failed}")
            return
        progress(f"  start {result.index}: cost {result.cost:.5g}, max |ΔIm| "
                 f"{100 * result.frequency_error:.1f} %, largest real at 0.014 "
                 f"{result.largest_real_unstable:+.3f} 1/s ({result.seconds:.0f} s)")

    with study_engine(args, "calibrate") as (mapper, where):
        progress(f"global calibration: start 0 and {args.starts} Sobol' starts on {where} …")
        result = global_search(args.starts, mapper, start, phases, done, where)
    best = next(r for r in result.results if r.index == result.best)
    rows, table = write_start(best, out, start, args.divergence_weight)
    progress(f"wrote {out} (start {result.best})")
    data = {"out": str(out), **result.as_dict(), "targets": _rows_json(rows),
            "numerics": in_effect()}  # this process's; the local cluster's workers inherit it
    emit(args, data, starts_table(result) + "\n\nbest start's targets:\n" + table)
