"""``bogie eigen``, ``limit``, ``modes``, ``locus`` and ``export``: the linear analyses of one
operating point from the command line.

    bogie eigen  --s0 0.005 --v 120 [--n0 N --bm B --params FILE] [--count 10] [--json]
    bogie limit  --v 120 [--n0 N --bm B --params FILE] [--json]
    bogie modes  --s0 0.005 --v 120 […] [--count 10] [--json]
    bogie locus  --s0-range A:B:N | --v-range A:B:N [--max-frequency 20] […] [--json]
    bogie export --s0 0.005 --v 120 […] --out system.npz

Human-readable tables by default, ``--json`` for machines.  Bad input: one line on stderr, exit
status 2.
"""

from __future__ import annotations

import argparse

import numpy as np

from app.cli.options import UsageError, add_operating_point, bounded, load_model, parse_range, positive_int
from app.cli.output import emit, writable_path


def register(subparsers) -> None:
    """eigen, limit, modes and locus (export: :func:`register_export`)."""
    p = subparsers.add_parser("eigen", help="eigenvalues and stability at an operating point")
    add_operating_point(p)
    p.add_argument("--count", type=positive_int("--count"), default=10,
                   help="complex pairs / real values to list (default %(default)s)")
    p.set_defaults(func=cmd_eigen)

    p = subparsers.add_parser("limit", help="stability limit s0*(v) at a speed")
    add_operating_point(p, s0=None)
    p.set_defaults(func=cmd_limit)

    p = subparsers.add_parser("modes", help="mode table (Table 2 layout): energy shares and descriptions")
    add_operating_point(p)
    p.add_argument("--count", type=positive_int("--count"), default=10, help="modes to list")
    p.set_defaults(func=cmd_modes)

    p = subparsers.add_parser("locus", help="root locus over s0 or v, branches tracked by MAC")
    add_operating_point(p)
    p.add_argument("--s0-range", default=None, metavar="A:B:N", help="creepage sweep")
    p.add_argument("--v-range", default=None, metavar="A:B:N", help="speed sweep [km/h]")
    p.add_argument("--max-frequency", type=bounded("--max-frequency (Hz)", "(0.5, 500)", "Hz"),
                   default=20.0, help="track eigenvalues with |λ| < 2π f [Hz] (default %(default)s)")
    p.set_defaults(func=cmd_locus)


def register_export(subparsers) -> None:
    """export (M, B, K and the output matrices at an operating point); ``bogie --help`` has always
    listed it after calibrate, so it registers apart from the other analyses."""
    p = subparsers.add_parser("export", help="export M, B, K, outputs at an operating point (.npz)")
    add_operating_point(p)
    p.add_argument("--out", required=True, help="output file (.npz)")
    p.set_defaults(func=cmd_export)


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
    real_rows = [{"re": float(value)} for value in result.real_eigenvalues[: args.count]]
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


def cmd_export(args: argparse.Namespace) -> None:
    from model.analysis.export import export_system

    writable_path(args.out, "--out", suffixes=(".npz",))  # refused before the model is built
    model, op, _ = load_model(args)
    export_system(model, op, args.out)
    emit(args, {"out": args.out, "n_dof": model.n}, f"wrote {args.out} ({model.n} DOF)")
