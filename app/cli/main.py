"""Command line ``bogie`` (also ``python -m app``).

Every command accepts the operating point ``--s0``, ``--v`` [km/h], ``--n0`` [N], ``--bm``
[N m s/rad] and ``--params FILE``.  Human-readable tables by default, ``--json`` for machines.
Bad input: one line on stderr saying what is wrong and what is allowed, exit status 2.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable

import numpy as np

from app.cli.options import (
    EXIT_BAD_INPUT,
    BogieParser,
    UsageError,
    add_operating_point,
    load_model,
    non_negative_int,
    number,
    parse_range,
    positive_int,
)
from app.cli.output import emit
from model.mechanics.parameters import ParameterError

# --- commands ------------------------------------------------------------------------------------

def cmd_eigen(args: argparse.Namespace) -> None:
    from model.analysis.eigen import eigen_analysis
    from model.analysis.modes import describe_modes

    model, op, _ = load_model(args)
    result = eigen_analysis(model, op)
    descriptions = describe_modes(model, result, result.complex_index[: args.count])
    complex_rows = [{"re": float(lam.real), "im_hz": float(lam.imag / (2 * np.pi)),
                     "description": text}
                    for lam, text in zip(result.complex_pairs[: args.count], descriptions,
                                         strict=False)]
    real_rows = [{"re": float(value)} for value in result.real[: args.count]]
    data = {"operating_point": op.as_dict(), "stable": result.stable,
            "max_real_part": result.max_real_part, "flutter_pairs": result.flutter,
            "divergent_real": result.divergence, "rigid_body": result.n_rigid,
            "complex": complex_rows, "real": real_rows}
    lines = [f"operating point: s0 = {op.s0:g}, v = {op.v_kmh:g} km/h, N0 = {op.N0:g} N, "
             f"b_M = {op.b_M:g} N m s/rad",
             f"verdict: {'STABLE' if result.stable else 'UNSTABLE'} (largest Re = "
             f"{result.max_real_part:.4g} 1/s; {result.flutter} flutter pair(s), "
             f"{result.divergence} divergent real eigenvalue(s); {result.n_rigid} rigid-body "
             "zero eigenvalues identified)", "",
             f"{'#':>3} {'Re [1/s]':>10} {'Im [Hz]':>9}  description"]
    for i, row in enumerate(complex_rows, start=1):
        lines.append(f"{i:>3} {row['re']:>10.4f} {row['im_hz']:>9.3f}  {row['description']}")
    lines += ["", "real eigenvalues [1/s], largest first: "
              + ", ".join(f"{row['re']:.4g}" for row in real_rows)]
    emit(args, data, "\n".join(lines))


def cmd_limit(args: argparse.Namespace) -> None:
    from model.analysis.stability import NoStabilityLimit, stability_limit
    from model.mechanics.operating_point import KMH

    model, _, (n0, bm) = load_model(args)
    try:
        limit = stability_limit(model, args.v * KMH, n0, bm)
    except NoStabilityLimit as reason:
        emit(args, {"v_kmh": args.v, "s0_limit": None, "N0": n0, "b_M": bm, "reason": str(reason)},
             f"no stability limit at {args.v:g} km/h: {reason}")
        return
    emit(args, {"v_kmh": args.v, "s0_limit": limit.s0_limit, "N0": n0, "b_M": bm},
         f"stability limit at {args.v:g} km/h: s0* = {limit.s0_limit:.6f} "
         f"({limit.evaluations} eigen-analyses)")


def cmd_modes(args: argparse.Namespace) -> None:
    from model.analysis.eigen import eigen_analysis
    from model.analysis.modes import mode_character

    model, op, _ = load_model(args)
    result = eigen_analysis(model, op)
    rows = []
    for nu, index in enumerate(result.complex_index[: args.count], start=1):
        c = mode_character(model, result, index)
        top = sorted(c.kinetic.items(), key=lambda item: -item[1])[:3]
        rows.append({"nu": nu, "re": float(c.eigenvalue.real), "im_hz": c.frequency_hz,
                     "damping_ratio": c.damping_ratio, "description": c.description,
                     "kinetic_energy_shares": {k: round(v, 4) for k, v in top}})
    lines = [f"modes at s0 = {op.s0:g}, v = {op.v_kmh:g} km/h (Table 2 layout)", "",
             f"{'ν':>3} {'Im λ [Hz]':>10} {'ζ [-]':>7}  dominant motion"]
    lines += [f"{r['nu']:>3} {r['im_hz']:>10.3f} {r['damping_ratio']:>7.4f}  {r['description']}"
              for r in rows]
    emit(args, {"operating_point": op.as_dict(), "modes": rows}, "\n".join(lines))


def cmd_locus(args: argparse.Namespace) -> None:
    from model.analysis.locus import root_locus
    from model.mechanics.operating_point import KMH

    model, op, _ = load_model(args)
    if (args.s0_range is None) == (args.v_range is None):
        raise UsageError("give exactly one of --s0-range A:B:N or --v-range A:B:N (km/h)")
    if args.s0_range is not None:
        parameter, values = "s0", parse_range(args.s0_range, "--s0-range")
    else:
        parameter, values = "v", parse_range(args.v_range, "--v-range", KMH)
    locus = root_locus(model, op, parameter, values, max_frequency_hz=args.max_frequency)
    shown = values if parameter == "s0" else values / KMH
    upper = locus.upper_branches
    data = {"parameter": parameter, "unit": "-" if parameter == "s0" else "km/h",
            "values": shown.tolist(), "operating_point": op.as_dict(),
            "branches": [{"re": locus.eigenvalues[:, b].real.tolist(),
                          "im_hz": (locus.eigenvalues[:, b].imag / (2 * np.pi)).tolist()}
                         for b in upper],
            "max_real_part": locus.max_real_part.tolist(),
            "max_error_estimate": float(locus.error_estimate.max())}
    lines = [f"root locus over {parameter} ({len(values)} points, {len(upper)} branches with "
             f"Im >= 0 of {locus.eigenvalues.shape[1]} tracked, |λ| < 2π·{args.max_frequency:g} Hz)",
             f"{'value':>10} {'max Re [1/s]':>13}  stable"]
    step = max(1, len(values) // 20)
    for value, growth in list(zip(shown, locus.max_real_part, strict=True))[::step]:
        lines.append(f"{value:>10.5g} {growth:>13.4g}  {'yes' if growth <= 0 else 'NO'}")
    emit(args, data, "\n".join(lines))


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


def cmd_export(args: argparse.Namespace) -> None:
    from model.analysis.export import export_system

    model, op, _ = load_model(args)
    export_system(model, op, args.out)
    emit(args, {"out": args.out, "n_dof": model.n}, f"wrote {args.out} ({model.n} DOF)")


def cmd_serve(args: argparse.Namespace) -> None:
    from app.server.serve import serve
    from app.services.settings import ServerSettings

    settings = ServerSettings.from_options(
        scheduler=args.scheduler, studies_dir=args.studies_dir,
        max_study_points=args.max_study_points, max_running_studies=args.max_running_studies,
        max_waiting_studies=args.max_waiting_studies)
    serve(port=args.port, address=args.address, allow_websocket_origin=args.allow_websocket_origin,
          params=args.params, settings=settings)


def build_parser() -> argparse.ArgumentParser:
    parser = BogieParser(prog="bogie", description="Locomotive bogie drive dynamics: eigenvalues, "
                     "stability and traction-motor short-circuit response.")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=BogieParser)

    p = sub.add_parser("eigen", help="eigenvalues and stability at an operating point")
    add_operating_point(p)
    p.add_argument("--count", type=positive_int("--count"), default=10,
                   help="complex pairs / real values to list (default %(default)s)")
    p.set_defaults(func=cmd_eigen)

    p = sub.add_parser("limit", help="stability limit s0*(v) at a speed")
    add_operating_point(p, s0=None)
    p.set_defaults(func=cmd_limit)

    p = sub.add_parser("modes", help="mode table (Table 2 layout): energy shares and descriptions")
    add_operating_point(p)
    p.add_argument("--count", type=positive_int("--count"), default=10, help="modes to list")
    p.set_defaults(func=cmd_modes)

    p = sub.add_parser("locus", help="root locus over s0 or v, branches tracked by MAC")
    add_operating_point(p)
    p.add_argument("--s0-range", default=None, metavar="A:B:N", help="creepage sweep")
    p.add_argument("--v-range", default=None, metavar="A:B:N", help="speed sweep [km/h]")
    p.add_argument("--max-frequency", type=number("--max-frequency (Hz)", 0.5, 500, allowed="must be in (0.5, 500) Hz"),
                   default=20.0, help="track eigenvalues with |λ| < 2π f [Hz] (default %(default)s)")
    p.set_defaults(func=cmd_locus)

    p = sub.add_parser("calibrate", help="fit the uncertain parameters to the published results")
    p.add_argument("--start", default=None, metavar="FILE", help="starting set (default: estimate.toml)")
    p.add_argument("--out", default=None, metavar="FILE", help="output (default: calibrated.toml)")
    p.add_argument("--max-evaluations", type=positive_int("--max-evaluations"), default=2400,
                   help="trial parameter sets of stages B1 and B2 (the characters, then Table 1 "
                        "by rank), each up to three eigen-analyses (default %(default)s)")
    p.add_argument("--budget-scale", type=number("--budget-scale", 0.001, 10, high_open=False,
                                                 allowed="must be in (0.001, 10]"),
                   default=1.0, help="multiply the evaluation budgets of stages D-F (the ranking; "
                                     "default %(default)s; smaller for a quick check)")
    p.add_argument("--json", action="store_true", help="progress to stderr")
    p.set_defaults(func=cmd_calibrate)

    p = sub.add_parser("export", help="export M, B, K, outputs at an operating point (.npz)")
    add_operating_point(p)
    p.add_argument("--out", required=True, help="output file (.npz)")
    p.set_defaults(func=cmd_export)

    p = sub.add_parser(
        "serve", help="serve the dashboard (panel serve semantics)",
        description="Serve the dashboard at /app (liveness: /liveness?endpoint=/app).  The options "
                    "below are the operator's: no browser can change them (docs/security.md).  "
                    "Each study option has an environment variable of the same meaning (named in "
                    "its help); the option wins over the variable.")
    p.add_argument("--port", type=number("--port", 0, 65536, low_open=False,
                                         allowed="must be 0…65535"), default=5006)
    p.add_argument("--address", default="127.0.0.1", help="interface to listen on (default "
                   "%(default)s; 0.0.0.0: every interface)")
    p.add_argument("--allow-websocket-origin", action="append", default=None,
                   help="host[:port] allowed to open the websocket (repeatable; environment: "
                        "BOGIE_ALLOWED_ORIGINS, comma-separated)")
    p.add_argument("--params", default=None, metavar="FILE", help="parameter file (TOML)")
    p.add_argument("--scheduler", default=None, metavar="ADDR",
                   help="Dask scheduler the dashboard's studies run on (tcp://host:port; "
                        "environment: BOGIE_SCHEDULER); default: one local cluster of this server, "
                        "started on the first study, one worker process per core, shared by all "
                        "sessions")
    p.add_argument("--studies-dir", default=None, metavar="DIR",
                   help="folder studies are written to and opened from (created if missing; "
                        "environment: BOGIE_STUDIES_DIR; default ~/.local/share/bogie/studies)")
    p.add_argument("--max-study-points", type=positive_int("--max-study-points"), default=None,
                   metavar="N", help="largest study a session may ask for, s0 points × v points "
                                     "(environment: BOGIE_MAX_STUDY_POINTS; default 10000)")
    p.add_argument("--max-running-studies", type=positive_int("--max-running-studies"),
                   default=None, metavar="K",
                   help="studies running at once; more wait in a queue (environment: "
                        "BOGIE_MAX_RUNNING_STUDIES; default 1)")
    p.add_argument("--max-waiting-studies", type=non_negative_int("--max-waiting-studies"),
                   default=None, metavar="W",
                   help="studies waiting at most; more requests are refused with a notice "
                        "(environment: BOGIE_MAX_WAITING_STUDIES; default 16)")
    p.set_defaults(func=cmd_serve)

    for register in EXTRA_COMMANDS:
        register(sub)
    return parser


EXTRA_COMMANDS: list[Callable] = []  # register(subparsers) functions of other command modules

from app.cli.response import register as _register_response  # noqa: E402

EXTRA_COMMANDS.append(_register_response)

from app.cli.sensitivity import register as _register_sensitivity  # noqa: E402  (issue 12)

EXTRA_COMMANDS.append(_register_sensitivity)

from app.cli.antislip import register as _register_antislip  # noqa: E402

EXTRA_COMMANDS.append(_register_antislip)  # issue 10: bogie antislip

from app.cli.study import register as _register_study  # noqa: E402 - issue 13: bogie study

EXTRA_COMMANDS.append(_register_study)

from app.cli.compare import register as _register_compare  # noqa: E402

EXTRA_COMMANDS.append(_register_compare)

from app.cli.report import register as _register_report  # noqa: E402

EXTRA_COMMANDS.append(_register_report)


def main(argv: list[str] | None = None) -> int:
    from threadpoolctl import threadpool_limits

    from model.mechanics.operating_point import OperatingPointError

    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        with threadpool_limits(1):  # dense 200-400 sized problems: one BLAS thread is fastest
            args.func(args)
    except (UsageError, ParameterError, OperatingPointError, KeyError, ValueError) as error:
        message = error.args[0] if error.args else str(error)
        print(f"bogie {args.command}: error: {message}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except BrokenPipeError:
        return 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
