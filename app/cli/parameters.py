"""``bogie parameters``: a parameter set as a table, with the calibration's bounds.

    bogie parameters [--params FILE] [--json]

One row per parameter in schema order: name, value, SI unit, the note of the file (where the
value comes from), and for the parameters the calibration fits
(:data:`model.studies.calibration_bounds.FREE_PARAMETERS`) its bounds and whether the value sits on
one (within 0.1 %, :func:`model.studies.calibration_bounds.on_bound`), and where the bounds come
from (the published data on real vehicles of this class, after ``bounds:`` at the end of the
row).  ``--json`` prints ``{"parameters": [{"name", "value", "unit", "note", "lower", "upper",
"on_bound", "bounds_source"}]}`` (``lower``, ``upper``, ``on_bound``, ``bounds_source`` null for
parameters the calibration does not fit).  Bad input (a file
that is missing or not a valid set): one line on stderr, exit status 2.
"""

from __future__ import annotations

import argparse

from app.cli.options import PARAMETER_FILE
from app.cli.output import emit


def register(subparsers) -> None:
    p = subparsers.add_parser("parameters", help="the parameter set as a table, with the "
                              "calibration's bounds")
    p.add_argument("--params", type=PARAMETER_FILE, default=None, metavar="FILE",
                   help="parameter file (TOML; default: the calibrated set)")
    p.add_argument("--json", action="store_true", help="machine-readable JSON output")
    p.set_defaults(func=cmd_parameters)


def parameter_table(rows: list[dict], source: str) -> str:
    """The human-readable table of :func:`model.studies.calibration_bounds.parameter_rows`."""
    calibrated = [row for row in rows if row["lower"] is not None]
    lines = [f"parameter set: {source} ({len(rows)} parameters, {len(calibrated)} fitted by the "
             f"calibration, {sum(1 for row in calibrated if row['on_bound'])} of them on a bound)",
             "", f"{'name':34} {'value':>12} {'unit':9} {'lower':>10} {'upper':>10} "
                 f"{'on bound':8}  note"]
    for row in rows:
        if row["lower"] is None:
            lower = upper = bound = source = ""
        else:
            lower, upper = f"{row['lower']:>10.4g}", f"{row['upper']:>10.4g}"
            bound = "YES" if row["on_bound"] else "no"
            source = f" | bounds: {row['bounds_source']}"
        lines.append(f"{row['name']:34} {row['value']:>12.6g} {row['unit']:9} {lower:>10} "
                     f"{upper:>10} {bound:8}  {row['note']}{source}")
    return "\n".join(lines)


def cmd_parameters(args: argparse.Namespace) -> None:
    from model.mechanics.parameters import load_parameters
    from model.studies.calibration_bounds import parameter_rows

    parameters = load_parameters(args.params)
    rows = parameter_rows(parameters)
    emit(args, {"parameters": rows}, parameter_table(rows, parameters.source))
