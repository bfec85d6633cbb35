"""``bogie calibrate --out FILE``: fit the uncertain parameters to the published results
(:mod:`model.studies.calibration`: stage A, the creep law and gear ratio to the operating data;
stage J, bounded least squares on the analytic Jacobian) and write the set to FILE; progress on
stderr, the table of the targets (or ``--json``) on stdout.  ``--out`` is required: the command
writes only where it is told, and replacing the bundled default set
(``assets/parameters/calibrated.toml``) is said on stderr.  Bad input: one line on stderr, exit
status 2.
"""

from __future__ import annotations

import argparse
import sys

from app.cli.options import PARAMETER_FILE, UsageError, positive_int
from app.cli.output import emit, writable_path


def register(subparsers) -> None:
    p = subparsers.add_parser("calibrate", help="fit the uncertain parameters to the published results")
    p.add_argument("--start", type=PARAMETER_FILE, default=None, metavar="FILE",
                   help="starting set (default: estimate.toml)")
    p.add_argument("--out", default=None, metavar="FILE",
                   help="where to write the calibrated set (required; the bundled default set is "
                        "assets/parameters/calibrated.toml)")
    p.add_argument("--max-evaluations", type=positive_int("--max-evaluations"), default=None,
                   help="trial parameter sets of each least-squares phase at most (default: "
                        "the calibration's own, as for the bundled set; smaller for a quick "
                        "check)")
    p.add_argument("--json", action="store_true", help="machine-readable JSON output (progress "
                                                       "goes to stderr either way)")
    p.set_defaults(func=cmd_calibrate)


def cmd_calibrate(args: argparse.Namespace) -> None:
    from pathlib import Path

    from model.mechanics.parameters import CALIBRATED_FILE, ESTIMATE_FILE
    from model.studies.calibration import PHASES, run

    if not args.out:
        raise UsageError("--out FILE is required: where to write the calibrated set (the bundled "
                         f"default set is {CALIBRATED_FILE.relative_to(CALIBRATED_FILE.parents[2])})")
    start = Path(args.start) if args.start else ESTIMATE_FILE
    out = writable_path(args.out, "--out")
    if out.resolve() == CALIBRATED_FILE.resolve():
        print(f"bogie calibrate: replacing the bundled default set {CALIBRATED_FILE}", file=sys.stderr)
    phases = PHASES if args.max_evaluations is None else tuple(
        (min(count, args.max_evaluations), weights) for count, weights in PHASES)
    rows, table = run(start, out, phases=phases,
                      progress=lambda text: print(text, file=sys.stderr, flush=True))
    emit(args, {"out": str(out), "targets": [
        {"name": row.name, "published": row.target, "achieved": row.achieved, "unit": row.unit,
         "error": row.error} for row in rows]}, table)
