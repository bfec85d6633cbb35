"""``bogie report``: the dashboard's self-contained HTML report from the command line.

    bogie report --s0 0.005 --v 120 [--n0 N --bm B] [--m0 M0 --f F --decay D --phase DT]
                 [--t-end T] [--rail calibrated|dry|wet] [--params FILE] [--variant TEXT]
                 --out report.html

Units as in ``bogie response``: ``--n0`` [N], ``--m0`` [N m], ``--phase`` [s].  ``--variant``:
a design variant as ``name:value,…`` (SI) applied to the set, as in the dashboard's links.  The
report itself is built by :mod:`app.report.page` (imported when the command runs, so that the
other commands do not load Bokeh).  Bad input: one line on stderr, exit status 2.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from app.cli.options import (
    UsageError,
    add_operating_point,
    add_rail,
    add_short_circuit,
    add_time_grid,
    case_from_args,
    dashboard_interval,
)
from app.cli.output import writable_path
from app.results.case import Case


def register(subparsers) -> None:
    p = subparsers.add_parser("report", help="self-contained HTML report of an operating point")
    add_operating_point(p)
    # the report reproduces the dashboard: its sliders' ranges (app/dashboard/dashboard.py, there
    # in kN m and ms) bound the short circuit and the simulated time
    add_short_circuit(p, dashboard=True)
    add_time_grid(p, "simulated time", t_end=dashboard_interval(Case.quantity("t_end")))
    add_rail(p)
    p.add_argument("--variant", default="", metavar="TEXT",
                   help="design variant: name:value,… (SI units) applied to the set")
    p.add_argument("--out", required=True, help="output file (.html)")
    p.set_defaults(func=cmd_report)


def cmd_report(args: argparse.Namespace) -> None:
    import sys

    from app.report.page import build_report
    from app.results.variants import VariantError, apply_variant, base_parameters, decode, set_key

    out = writable_path(args.out, "--out", suffixes=(".html", ".htm", ".HTML", ".HTM"))
    if args.s0 is None:
        raise UsageError("--s0 is required")
    base = str(Path(args.params).resolve()) if args.params else ""
    try:
        changes = decode(args.variant)
        parameters = apply_variant(base_parameters(base), changes)
    except VariantError as error:
        raise UsageError(f"--variant: {error}") from None
    case = case_from_args(args, set_key(base, changes), parameters)
    text = build_report(case, progress=lambda step: print(f"bogie report: {step}…",
                                                           file=sys.stderr, flush=True))
    out.write_text(text, encoding="utf-8")
    print(f"wrote {out} ({len(text.encode()) / 1e6:.1f} MB, self-contained)")
