"""``bogie calibrate``: fit the uncertain parameters to the published results
(:mod:`model.studies.calibration`); progress on stdout, or on stderr with ``--json``.
Bad input: one line on stderr, exit status 2.
"""

from __future__ import annotations

import argparse
import sys

from app.cli.options import UsageError, bounded, positive_int


def register(subparsers) -> None:
    p = subparsers.add_parser("calibrate", help="fit the uncertain parameters to the published results")
    p.add_argument("--start", default=None, metavar="FILE", help="starting set (default: estimate.toml)")
    p.add_argument("--out", default=None, metavar="FILE", help="output (default: calibrated.toml)")
    p.add_argument("--max-evaluations", type=positive_int("--max-evaluations"), default=2400,
                   help="trial parameter sets of stages B1 and B2 (the characters, then Table 1 "
                        "by rank), each up to three eigen-analyses (default %(default)s)")
    p.add_argument("--budget-scale", type=bounded("--budget-scale", "(0.001, 10]"),
                   default=1.0, help="multiply the evaluation budgets of stages D-F (the ranking; "
                                     "default %(default)s; smaller for a quick check)")
    p.add_argument("--json", action="store_true", help="progress to stderr")
    p.set_defaults(func=cmd_calibrate)


def cmd_calibrate(args: argparse.Namespace) -> None:
    from pathlib import Path

    from model.mechanics.parameters import CALIBRATED_FILE, ESTIMATE_FILE
    from model.studies.calibration import run

    start = Path(args.start) if args.start else ESTIMATE_FILE
    out = Path(args.out) if args.out else CALIBRATED_FILE
    if not out.parent.is_dir():
        raise UsageError(f"directory '{out.parent}' does not exist")
    run(start, out, max_evaluations=args.max_evaluations, scale=args.budget_scale,
        progress=lambda text: print(text, file=sys.stderr if args.json else sys.stdout, flush=True))
