"""Command line ``bogie`` (also ``python -m model``).

Every command accepts the operating point ``--s0``, ``--v`` [km/h], ``--n0`` [N], ``--bm``
[N m s/rad] and ``--params FILE``.  Human-readable tables by default, ``--json`` for machines.
Bad input: one line on stderr saying what is wrong and what is allowed, exit status 2.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Callable

import numpy as np

from .parameters import ParameterError, load_parameters

EXIT_BAD_INPUT = 2


class UsageError(Exception):
    """Bad input from the command line (reported in one line, exit status 2)."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one line, no usage block
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message}\n")


def number(label: str, low: float = -math.inf, high: float = math.inf, low_open: bool = True,
           high_open: bool = True, allowed: str = "") -> Callable[[str], float]:
    """argparse type: a finite float within bounds, with a clear message otherwise."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{label} must be a number, got '{text}'") from None
        ok_low = value > low if low_open else value >= low
        ok_high = value < high if high_open else value <= high
        if not math.isfinite(value) or not (ok_low and ok_high):
            raise argparse.ArgumentTypeError(f"{label} = {text} is not allowed: {allowed}")
        return value

    return parse


def positive_int(label: str) -> Callable[[str], int]:
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{label} must be a whole number, got '{text}'") from None
        if value < 1:
            raise argparse.ArgumentTypeError(f"{label} = {text} is not allowed: must be >= 1")
        return value

    return parse


def add_operating_point(parser: argparse.ArgumentParser, s0: float | None = 0.005) -> None:
    parser.add_argument("--s0", type=number("--s0 (creepage)", 0, 1, allowed="must be in (0, 1)"),
                        default=s0, help="longitudinal creepage s0 [-] (default %(default)s)")
    parser.add_argument("--v", type=number("--v (speed, km/h)", 1, 500, False, False,
                                           allowed="must be in [1, 500] km/h"),
                        default=120.0, help="speed [km/h] (default %(default)s)")
    parser.add_argument("--n0", type=number("--n0 (wheel force, N)", 1e3, 1e6, False, False,
                                            allowed="must be in [1e3, 1e6] N"),
                        default=None, help="static wheel force N0 [N] (default: parameter set)")
    parser.add_argument("--bm", type=number("--bm (motor slope, N m s/rad)", 0, 1e9, False, False,
                                            allowed="must be in [0, 1e9] N m s/rad"),
                        default=None, help="motor slope b_M [N m s/rad] (default: parameter set)")
    parser.add_argument("--params", default=None, metavar="FILE",
                        help="parameter file (TOML; default: the calibrated set)")
    parser.add_argument("--json", action="store_true", help="machine-readable JSON output")


def load_model(args: argparse.Namespace):
    """(model, operating point) from the common options."""
    from .assembly import build_model
    from .operating_point import OperatingPoint

    parameters = load_parameters(args.params)
    model = build_model(parameters)
    n0 = parameters["wheel_force"] if args.n0 is None else args.n0
    bm = parameters["motor_slope"] if args.bm is None else args.bm
    op = OperatingPoint.from_kmh(args.s0, args.v, n0, bm) if args.s0 is not None else None
    return model, op, (n0, bm)


def emit(args: argparse.Namespace, data: dict, table: str) -> None:
    if args.json:
        print(json.dumps(data, indent=1, allow_nan=False))
    else:
        print(table)


# --- commands ------------------------------------------------------------------------------------

def cmd_eigen(args: argparse.Namespace) -> None:
    from .eigen import eigen_analysis
    from .modes import describe_modes

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
    from .operating_point import KMH
    from .stability import NoStabilityLimit, stability_limit

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
    from .eigen import eigen_analysis
    from .modes import mode_character

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


def parse_range(text: str, label: str, scale: float = 1.0) -> np.ndarray:
    """'A:B:N' -> N values from A to B (times ``scale``)."""
    parts = text.split(":")
    try:
        start, stop, count = float(parts[0]), float(parts[1]), int(parts[2])
    except (ValueError, IndexError):
        raise UsageError(f"{label} must be A:B:N (two numbers and a whole count), got '{text}'") from None
    if len(parts) != 3 or count < 2 or count > 5000 or not (math.isfinite(start) and math.isfinite(stop)):
        raise UsageError(f"{label} must be A:B:N with finite A, B and 2 <= N <= 5000, got '{text}'")
    return np.linspace(start, stop, count) * scale


def cmd_locus(args: argparse.Namespace) -> None:
    from .locus import root_locus
    from .operating_point import KMH

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

    from .calibration import run
    from .parameters import CALIBRATED_FILE, ESTIMATE_FILE

    start = Path(args.start) if args.start else ESTIMATE_FILE
    out = Path(args.out) if args.out else CALIBRATED_FILE
    if not out.parent.is_dir():
        raise UsageError(f"directory '{out.parent}' does not exist")
    from .calibration import PHASES

    phases = PHASES if args.max_evaluations is None else tuple(
        (min(count, args.max_evaluations), weights) for count, weights in PHASES)
    rows, table = run(start, out, phases=phases,
                      progress=lambda text: print(text, file=sys.stderr, flush=True))
    emit(args, {"out": str(out), "targets": [
        {"name": row.name, "published": row.target, "achieved": row.achieved, "unit": row.unit,
         "error": row.error} for row in rows]}, table)


def cmd_export(args: argparse.Namespace) -> None:
    from .export import export_system

    model, op, _ = load_model(args)
    export_system(model, op, args.out)
    emit(args, {"out": args.out, "n_dof": model.n}, f"wrote {args.out} ({model.n} DOF)")


def cmd_serve(args: argparse.Namespace) -> None:
    from app.serve import serve

    serve(port=args.port, address=args.address, allow_websocket_origin=args.allow_websocket_origin,
          params=args.params)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="bogie", description="Locomotive bogie drive dynamics: eigenvalues, "
                     "stability and traction-motor short-circuit response.")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

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
    p.add_argument("--max-evaluations", type=positive_int("--max-evaluations"), default=None,
                   help="trial parameter sets of each least-squares phase at most (default: "
                        "the calibration's own, as for the bundled set; smaller for a quick "
                        "check)")
    p.add_argument("--json", action="store_true", help="machine-readable JSON output (progress "
                                                       "goes to stderr either way)")
    p.set_defaults(func=cmd_calibrate)

    p = sub.add_parser("export", help="export M, B, K, outputs at an operating point (.npz)")
    add_operating_point(p)
    p.add_argument("--out", required=True, help="output file (.npz)")
    p.set_defaults(func=cmd_export)

    p = sub.add_parser("serve", help="serve the dashboard (panel serve semantics)")
    p.add_argument("--port", type=number("--port", 0, 65536, low_open=False,
                                         allowed="must be 0…65535"), default=5006)
    p.add_argument("--address", default="127.0.0.1")
    p.add_argument("--allow-websocket-origin", action="append", default=None,
                   help="host[:port] allowed to open the websocket (repeatable)")
    p.add_argument("--params", default=None, metavar="FILE", help="parameter file (TOML)")
    p.set_defaults(func=cmd_serve)

    for register in EXTRA_COMMANDS:
        register(sub)
    return parser


EXTRA_COMMANDS: list[Callable] = []  # register(subparsers) functions of other command modules

from .response_cli import register as _register_response  # noqa: E402

EXTRA_COMMANDS.append(_register_response)

from .sensitivity_cli import register as _register_sensitivity  # noqa: E402  (issue 12)

EXTRA_COMMANDS.append(_register_sensitivity)

from .nonlinear_cli import register as _register_antislip  # noqa: E402

EXTRA_COMMANDS.append(_register_antislip)  # issue 10: bogie antislip

from .study_cli import register as _register_study  # noqa: E402 - issue 13: bogie study

EXTRA_COMMANDS.append(_register_study)

from .compare_cli import register as _register_compare  # noqa: E402

EXTRA_COMMANDS.append(_register_compare)

from .report_cli import register as _register_report  # noqa: E402

EXTRA_COMMANDS.append(_register_report)

from .parameters_cli import register as _register_parameters  # noqa: E402 - issue 27

EXTRA_COMMANDS.append(_register_parameters)


def main(argv: list[str] | None = None) -> int:
    from threadpoolctl import threadpool_limits

    from .operating_point import OperatingPointError

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
