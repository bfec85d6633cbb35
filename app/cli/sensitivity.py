"""``bogie sensitivity`` and ``bogie uncertainty``: which parameter moves what, and how sure.

    bogie sensitivity --s0 0.005 --v 120 [--n0 N --bm B --params FILE] [--only a,b] [--json]
    bogie uncertainty --samples N [--seed S] [--posterior | --no-indices] [--speeds LIST]
                      [--json] [--out FILE.json]

``sensitivity`` JSON keys: ``operating_point``; ``modes`` (the ten lowest complex pairs: ``re``
[1/s], ``im_hz`` [Hz], ``description``, ``reliable``); ``parameters``: a list of ``{name, value,
unit, d_re_dp: [10] (1/s per unit), d_im_hz_dp: [10] (Hz per unit), d_s0_limit_dp (1 per unit)}``
with ``name`` as in the parameter file; ``operating_parameters`` (s0, v [m/s], N0, b_M, same
fields); ``limit`` (s0* at the speed, its mechanism and what it means); ``notes``.
Bad input: one line on stderr, exit status 2.
"""

from __future__ import annotations

import argparse
import json
import math

import numpy as np

from app.cli.options import (
    PARAMETER_FILE,
    UsageError,
    add_operating_point,
    add_uncertainty_options,
    check_sample_count,
    load_model,
    non_negative_int,
    uncertainty_options,
)
from app.cli.output import emit, writable_path


def _finite(values) -> list:
    return [None if not math.isfinite(float(v)) else float(v) for v in np.ravel(values)]


def register(subparsers) -> None:
    p = subparsers.add_parser("sensitivity", help="eigenvalue and stability-limit sensitivities "
                              "to every parameter (analytic, at an operating point)")
    add_operating_point(p)
    p.add_argument("--only", default=None, metavar="NAMES",
                   help="comma-separated parameter names (as in the parameter file) to report "
                        "(default: all)")
    p.set_defaults(func=cmd_sensitivity)

    p = subparsers.add_parser("uncertainty", help="quasi-Monte-Carlo uncertainty and Sobol indices "
                              "of s0*, the ten modes and the peak loads (prior ranges)")
    p.add_argument("--samples", type=int, required=True,
                   help="base sample count n (a power of 2 >= 2); model runs: n (d + 2)")
    p.add_argument("--seed", type=non_negative_int("--seed"), default=12,
                   help="seed of the scrambled Sobol' sequence")
    p.add_argument("--params", type=PARAMETER_FILE, default=None, metavar="FILE",
                   help="parameter file (TOML; default: the calibrated set)")
    add_uncertainty_options(p)
    p.add_argument("--json", action="store_true", help="machine-readable JSON output")
    p.add_argument("--out", default=None, metavar="FILE", help="also write the JSON result here")
    p.set_defaults(func=cmd_uncertainty)


def cmd_sensitivity(args: argparse.Namespace) -> None:
    from model.analysis.sensitivity import SensitivityError, eigen_sensitivities, limit_sensitivity
    from model.mechanics.parameters import load_parameters

    only = None
    if args.only is not None:
        only = [name.strip() for name in args.only.split(",") if name.strip()]
        if not only:
            raise UsageError("--only needs at least one parameter name")
    load_parameters(args.params)  # a bad file fails here, before any work
    model, op, (n0, bm) = load_model(args)
    linked = [name for name, given in (("wheel_force", args.n0), ("motor_slope", args.bm))
              if given is None]
    try:
        sens = eigen_sensitivities(model, op, linked=linked, parameters=only)
    except SensitivityError as error:
        raise UsageError(str(error)) from None
    limit = limit_sensitivity(model, op.v, n0, bm, linked=linked, parameters=only)
    d_limit = dict(zip(limit.names, limit.derivatives, strict=True))
    rows = []
    for i, name in enumerate(sens.names):
        rows.append({"name": name, "value": float(sens.values[i]), "unit": sens.units[i],
                     "d_re_dp": _finite(sens.d_re[i]), "d_im_hz_dp": _finite(sens.d_im_hz[i]),
                     "d_s0_limit_dp": _finite([d_limit[name]])[0] if name in d_limit else None})
    n_parameters = len(sens.names) - 4
    modes = [{"re": float(lam.real), "im_hz": float(lam.imag / (2 * np.pi)), "description": text,
              "reliable": bool(ok), "participation": part}
             for lam, text, ok, part in zip(sens.eigenvalues, sens.descriptions, sens.reliable,
                                            sens.participation, strict=True)]
    data = {"operating_point": op.as_dict(), "modes": modes, "parameters": rows[:n_parameters],
            "operating_parameters": rows[n_parameters:],
            "limit": {"v_kmh": op.v_kmh, "s0_limit": limit.s0_limit, "mechanism": limit.mechanism,
                      "creep_maximum": limit.creep_maximum, "note": limit.note},
            "linked": list(sens.linked), "notes": list(sens.notes)}
    # table: the ten largest |p/s0* ds0*/dp| and |p dRe λ/dp| of the least damped mode
    least = int(np.nanargmax(sens.eigenvalues.real))
    growth = sens.growth_per_relative_change[:, least]
    lines = [f"sensitivities at s0 = {op.s0:g}, v = {op.v_kmh:g} km/h, N0 = {op.N0:g} N, "
             f"b_M = {op.b_M:g} N m s/rad ({len(sens.names)} parameters, "
             f"{len(sens.eigenvalues)} modes)", *sens.notes, "",
             f"stability limit: {limit.note}", "",
             f"largest p/s0* · ds0*/dp at {op.v_kmh:g} km/h:"]
    normalized = limit.normalized
    for i in np.argsort(-np.abs(np.nan_to_num(normalized)))[:8]:
        lines.append(f"  {limit.names[i]:<35} {normalized[i]:+.4g}")
    lam = sens.eigenvalues[least]
    lines += ["", f"largest p · ∂Re λ/∂p [1/s] of the least damped mode ({lam.real:.4g} "
              f"{lam.imag / (2 * np.pi):+.4g}i Hz: {sens.descriptions[least]}):"]
    for i in np.argsort(-np.abs(np.nan_to_num(growth)))[:8]:
        lines.append(f"  {sens.names[i]:<35} {growth[i]:+.4g}")
    emit(args, data, "\n".join(lines))


def cmd_uncertainty(args: argparse.Namespace) -> None:
    from model.mechanics.parameters import load_parameters
    from model.studies.uncertainty import UncertaintyError, run_uncertainty

    n = args.samples
    check_sample_count(n)
    out = writable_path(args.out, "--out")
    options = uncertainty_options(args)
    parameters = load_parameters(args.params)
    try:
        result = run_uncertainty(parameters, n, seed=args.seed, **options,
                                 progress=None if args.json else
                                 lambda done, total: print(f"  {done}/{total} model runs",
                                                           flush=True))
    except UncertaintyError as error:
        raise UsageError(str(error)) from None
    data = result.as_dict()
    if out is not None:
        out.write_text(json.dumps(data, indent=1, allow_nan=False), encoding="utf-8")
    emit(args, data, result.summary())
