"""``bogie study``: parameter studies on Dask (a local cluster by default, a cluster by address).

    bogie study map   --s0 A:B:N --v A:B:N [--n0 LIST] [--bm LIST] [--motor-bandwidth LIST]
                      [--params FILE] [--rail R]
                      --out X.zarr [--scheduler tcp://HOST:PORT] [--workers N] [--resume]
    bogie study limit --v A:B:N [--n0 LIST] [--bm LIST] [--motor-bandwidth LIST] … --out X.zarr …
    bogie study uncertainty --samples N [--seed S] [--params FILE] --out U.json
                      [--posterior | --no-indices] [--speeds LIST]
                      [--scheduler tcp://HOST:PORT] [--workers N] [--serial]

``A:B:N`` is N values from A to B (N = 1: A alone); a LIST is comma-separated values or A:B:N,
increasing.  The lists are the case's quantities (:data:`app.results.case.QUANTITIES`), one option
each as the dashboard's sliders; ``--motor-bandwidth`` (the converter's torque control f_c [Hz],
a value of the parameter set: a model per value) not given: the set's own, and the store has no
such dimension.  Speeds in km/h on the command line (m/s in the store).  Results: an xarray Dataset in a Zarr
store (:mod:`model.studies.store`).  A progress bar with the time left goes to stderr.  Ctrl-C
stops cleanly: the finished chunks stay in the store, ``--resume`` computes the rest.  Bad input
(an empty range, N < 1, a store of another study, an unreachable scheduler): one line on
stderr, exit status 2.  Interrupted: exit status 130.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from app.cli.case_lists import add_case_lists, case_lists
from app.cli.options import (
    PARAMETER_FILE,
    UsageError,
    add_engine_options,
    add_rail,
    add_uncertainty_options,
    bounded,
    check_sample_count,
    non_negative_int,
    positive_int,
    uncertainty_options,
)
from app.cli.output import writable_path
from app.cli.runs import ProgressBar, resume_store, study_engine
from app.results.case import Case

POINT_ROLES = ("point", "override")  # the case's quantities a study lists (the rail: one)


def _common(p: argparse.ArgumentParser, *, creepage: bool) -> None:
    """The value lists of the case's quantities (``creepage``: with ``--s0``; ``--s0`` and ``--v``
    required) and the options every map and limit study has."""
    add_case_lists(p, *POINT_ROLES, names=None if creepage else
                   tuple(name for name in Case.names(*POINT_ROLES) if name != "s0"),
                   required=("s0", "v"))
    p.add_argument("--params", type=PARAMETER_FILE, default=None, metavar="FILE",
                   help="parameter file (TOML; default: the calibrated set)")
    add_rail(p)
    p.add_argument("--out", required=True, metavar="X.zarr", help="Zarr store to write")
    p.add_argument("--resume", action="store_true",
                   help="continue the study in --out (same parameters and arguments only)")
    add_engine_options(p)
    p.add_argument("--json", action="store_true", help="a JSON summary on stdout")


def register(subparsers) -> None:
    p = subparsers.add_parser("study", help="parameter studies on Dask: stability map, s0*(v)")
    sub = p.add_subparsers(dest="study_command", required=True)
    m = sub.add_parser("map", help="stability map over s0 × v (× N0 × b_M × f_c)")
    _common(m, creepage=True)
    m.add_argument("--max-frequency", type=bounded("--max-frequency (Hz)", "(0.5, 500)", "Hz"),
                   default=10.0, help="method reduced: reduction basis disc |λ| < 2π f [Hz] "
                   "(default %(default)s)")
    m.add_argument("--method", choices=("reduced", "continuation", "dense"),
                   default="reduced", help="per s0-line: the Galerkin-reduced model (default, "
                   "cheapest), the exact continuation of all eigenvalues, or a full "
                   "eigen-analysis per point")
    m.set_defaults(func=cmd_map)
    limit = sub.add_parser("limit", help="stability limit s0*(v) for lists of N0, b_M and f_c")
    _common(limit, creepage=False)
    limit.set_defaults(func=cmd_limit)
    u = sub.add_parser("uncertainty", help="the Monte-Carlo/Sobol study of `bogie uncertainty` "
                       "(docs/sensitivity.md) on the same engine")
    u.add_argument("--samples", type=positive_int("--samples"), required=True,
                   help="base sample count n (a power of 2 >= 2); model runs: n (d + 2)")
    u.add_argument("--seed", type=non_negative_int("--seed"), default=12,
                   help="seed of the scrambled Sobol' sequence")
    u.add_argument("--params", type=PARAMETER_FILE, default=None, metavar="FILE",
                   help="parameter file (TOML; default: the calibrated set)")
    u.add_argument("--out", required=True, metavar="U.json", help="JSON result to write")
    u.add_argument("--chunk-size", type=positive_int("--chunk-size"), default=4,
                   help="model runs per task (default %(default)s)")
    add_engine_options(u)
    add_uncertainty_options(u)
    u.add_argument("--json", action="store_true", help="the result as JSON on stdout")
    u.set_defaults(func=cmd_uncertainty)


def _parameters(args):
    from model.mechanics.parameters import load_parameters
    from model.studies.envelope import rail_parameters

    return rail_parameters(load_parameters(args.params), args.rail)


def _grids(args, parameters) -> dict[str, tuple]:
    """The study's axes by its field names (SI) from the value lists of the case's quantities
    (the set's N0 and b_M where not given; no f_c list: the set's own)."""
    lists = case_lists(args, parameters, *POINT_ROLES)
    return {q.target: lists[q.name] for q in Case.of_role(*POINT_ROLES) if q.name in lists}


def cmd_map(args: argparse.Namespace) -> None:
    from model.studies.maps import MapStudy

    parameters = _parameters(args)
    _run(args, MapStudy(**_grids(args, parameters), max_frequency_hz=args.max_frequency,
                        method=args.method), parameters)


def cmd_limit(args: argparse.Namespace) -> None:
    from model.studies.maps import LimitStudy

    parameters = _parameters(args)
    _run(args, LimitStudy(**_grids(args, parameters)), parameters)


def cmd_uncertainty(args: argparse.Namespace) -> None:
    from model.mechanics.parameters import load_parameters
    from model.studies.engine import in_order
    from model.studies.uncertainty import UncertaintyError, run_uncertainty

    n = args.samples
    check_sample_count(n)
    out = writable_path(args.out, "--out")
    options = uncertainty_options(args)
    parameters = load_parameters(args.params)
    bar, start = ProgressBar("study uncertainty", unit="model runs"), time.monotonic()
    with study_engine(args, "study uncertainty", lambda: " (nothing written)") as (mapper, where):
        print(f"study uncertainty: n = {n} on {where}", file=sys.stderr)
        try:
            result = run_uncertainty(parameters, n, seed=args.seed, map_fn=in_order(mapper),
                                     **options, chunk_size=args.chunk_size,
                                     progress=lambda done, total: bar(done, total,
                                                                      time.monotonic() - start))
        except UncertaintyError as error:
            raise UsageError(str(error)) from None
    data = result.as_dict()
    out.write_text(json.dumps(data, indent=1, allow_nan=False), encoding="utf-8")
    if args.json:
        print(json.dumps(data, indent=1, allow_nan=False))
    else:
        print(result.summary())
        print(f"wrote {out}")


def _run(args: argparse.Namespace, study, parameters) -> None:
    from model.studies.store import open_study, run_into_store

    progress = ProgressBar(f"study {study.kind}")
    if not args.resume:  # refuse a bad --out before starting a cluster
        out = writable_path(args.out, "--out", directory=True)
        if out.exists():
            raise UsageError(f"--out '{out}' exists: continue it with --resume, or remove it")
    else:
        resume_store(args.out, study, parameters)
    def interrupted() -> str:
        from model.studies.store import finished_chunks

        done = len(finished_chunks(args.out)) if Path(args.out).exists() else 0
        return (f"; {done} of {len(study.chunks())} chunks finished in {args.out}; continue "
                "with --resume")

    with study_engine(args, f"study {study.kind}", interrupted) as (mapper, where):
        print(f"study {study.kind}: {len(study.chunks())} chunks on {where}", file=sys.stderr)
        run = run_into_store(study, parameters, args.out, mapper, resume=args.resume,
                             progress=progress)
    dataset = open_study(args.out)
    summary = {"out": args.out, "study": study.kind, "chunks": run.total,
               "skipped_chunks": run.skipped, "computed_chunks": run.computed,
               "seconds": round(run.seconds, 3), "parameters_hash": dataset.attrs["parameters_hash"]}
    lines = [f"wrote {args.out}: {run.computed} chunk(s) computed, {run.skipped} already "
             f"finished, {run.seconds:.1f} s"]
    if study.kind == "map":
        stable = dataset["stable"].values
        summary["stable_fraction"] = float(stable.mean())
        lines.append(f"stable at {stable.mean():.1%} of {stable.size} points")
    limits = dataset["s0_limit"].values
    summary["s0_limit"] = [None if np.isnan(x) else float(x) for x in limits.ravel()]
    if args.json:
        print(json.dumps(summary, indent=1, allow_nan=False))
        return
    for index, value in np.ndenumerate(limits):
        i, j, k = index[:3]
        control = (f", f_c = {dataset['motor_bandwidth'].values[index[3]]:g} Hz"
                   if len(index) > 3 else "")
        lines.append(f"  v = {dataset['v_kmh'].values[i]:7.2f} km/h, N0 = {dataset['N0'].values[j]:g} N, "
                     f"b_M = {dataset['b_M'].values[k]:g} N m s/rad{control}: s0* = "
                     + ("none in range" if np.isnan(value) else f"{value:.6f}"))
        if len(lines) > 25:
            lines.append("  … (open the store with xarray for all)")
            break
    print("\n".join(lines))
