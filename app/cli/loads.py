"""``bogie envelope`` and ``bogie spectrum``: design loads from the command line.

    bogie envelope [--s0 LIST] [--v LIST] [--n0 LIST] [--bm LIST] [--motor-bandwidth LIST]
                   [--rail calibrated,dry,wet]
                   [--m0 LIST] [--f LIST] [--decay LIST] [--phase LIST|all]
                   [--creep linear|nonlinear|tangent] [--anti-slip off,on] [--anti-slip-delay LIST]
                   [--t-end T --fs FS --outputs a,b --method M] [--params FILE]
                   [--out X.zarr [--resume]] [--scheduler tcp://HOST:PORT | --workers N | --serial]
                   [--json]
    bogie spectrum … the options of ``bogie response`` … [--slopes 3,5] [--out F.npz|.csv|.json]

A LIST is ``A,B,C`` or ``A:B:N`` (N values from A to B), increasing; speeds in km/h.  The lists
are the case's quantities (:data:`app.results.case.QUANTITIES`), one option each as the
dashboard's sliders; ``--motor-bandwidth`` not given: the parameter set's own.  Without
``--phase`` the fault instants are the two continuity roots per period (physics first); a
``--phase`` grid [s] or ``all`` (closed form over every Δt, linear creep) is the explicitly
conservative case.  The envelope runs on the study engine (a local Dask cluster by default, as
``bogie study``); ``--out`` keeps the peaks per scenario in a resumable Zarr store.  Bad input:
one line on stderr, exit status 2; Ctrl-C: exit status 130.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path

import numpy as np

from app.cli.case_lists import add_case_lists, case_lists
from app.cli.options import (
    ANTI_SLIP_OPTIONS,
    PARAMETER_FILE,
    UsageError,
    add_anti_slip_arguments,
    add_engine_options,
    add_history_options,
    add_output_selection,
    add_time_grid,
    check_samples,
    check_sampling,
    output_names,
    parse_values,
    quantity_values,
)
from app.cli.output import check_history_file, writable_path
from app.cli.runs import ProgressBar, history_from_args, resume_store, study_engine
from app.results.case import Case

CASE_ROLES = ("set", "point", "override", "short_circuit")  # the case's quantities it lists
AXIS_LABELS = {"rail": "rail", "s0": "s0", "v": "v [km/h]", "N0": "N0 [N]", "b_M": "b_M",
               "motor_bandwidth": "f_c [Hz]", "M0": "M0 [N m]", "f": "f [Hz]", "D": "D", "anti_slip": "anti-slip",
               "anti_slip_delay": "delay [s]"}


def register(subparsers) -> None:
    p = subparsers.add_parser("envelope", help="design loads: max and min of every output over "
                              "a grid of short-circuit scenarios, and where they occur")
    # every quantity of the case a value list (the fault instant: --phase, below)
    add_case_lists(p, *CASE_ROLES)
    p.add_argument("--phase", default=None, metavar="LIST|all",
                   help="fault instants Δt [s], or 'all' (every Δt in closed form; linear creep) "
                        "(default: the two continuity roots per period)")
    p.add_argument("--creep", choices=("linear", "nonlinear", "tangent"), default="linear",
                   help="longitudinal creep forces (default %(default)s)")
    p.add_argument("--anti-slip", default="off", metavar="off|on|off,on",
                   help="anti-slip protection of ID2 (nonlinear creep; default %(default)s)")
    p.add_argument("--anti-slip-delay", default=None, metavar="LIST",
                   help="reaction delays of the protection [s] (default 0.1)")
    add_anti_slip_arguments(p, with_delay=False)
    add_time_grid(p, "horizon", "output sampling rate")
    add_output_selection(p)
    p.add_argument("--params", type=PARAMETER_FILE, default=None, metavar="FILE",
                   help="parameter file (TOML; default: the calibrated set)")
    p.add_argument("--out", default=None, metavar="X.zarr",
                   help="Zarr store of the peaks of every scenario (xarray dataset)")
    p.add_argument("--resume", action="store_true",
                   help="continue the envelope in --out (same parameters and arguments only)")
    add_engine_options(p)
    p.add_argument("--json", action="store_true", help="machine-readable JSON output")
    p.set_defaults(func=cmd_envelope)

    s = subparsers.add_parser("spectrum", help="load spectrum of a short-circuit history: "
                              "rainflow cycles, load collective, damage-equivalent ranges")
    add_history_options(s)
    s.add_argument("--slopes", default="3,5", metavar="LIST",
                   help="Wöhler slopes m of the equivalent ranges (default %(default)s)")
    s.add_argument("--out", default=None, help="write .npz, .csv or .json")
    s.set_defaults(func=cmd_spectrum)


# --- bogie envelope ----------------------------------------------------------------------------------

def _names(text: str, label: str) -> list[str]:
    names = [x.strip() for x in text.split(",")]
    if not text.strip() or not all(names):
        raise UsageError(f"{label} must be a comma-separated list of names, got '{text}'")
    return names


def study_from_args(args: argparse.Namespace):
    """(:class:`model.studies.envelope.EnvelopeStudy`, parameters) from the options."""
    from model.analysis.response import ResponseError
    from model.mechanics.operating_point import OperatingPoint
    from model.mechanics.parameters import load_parameters
    from model.studies.envelope import (
        SET_VALUE_DIMS,
        DesignLoadError,
        EnvelopeStudy,
        rail_parameters,
        resolve_outputs,
    )

    parameters = load_parameters(args.params)
    lists = case_lists(args, parameters, *CASE_ROLES)  # SI, by quantity name
    f = lists["f"]
    if args.phase is None:
        fault, phase = "roots", ()
    elif args.phase.strip() == "all":
        fault, phase = "all", ()
    else:
        fault, phase = "grid", quantity_values(args.phase, "dt", increasing=True)
    if fault == "all" and args.creep != "linear":
        raise UsageError("--phase all needs --creep linear (the closed form over every fault "
                         "instant is a superposition); give a --phase grid with nonlinear creep")
    anti_slip = _names(args.anti_slip, "--anti-slip")
    given = [name for name in ANTI_SLIP_OPTIONS if getattr(args, name) is not None]
    if given and "on" not in anti_slip:
        raise UsageError(f"--{given[0].replace('_', '-')} needs --anti-slip on")
    delays = (parse_values(args.anti_slip_delay, "--anti-slip-delay", 0, 60, "s", increasing=True)
              if args.anti_slip_delay is not None else [])
    if args.creep != "linear" and args.method != "auto":
        raise UsageError("--method applies to --creep linear only")
    check_sampling(args, max(f), f"the excitation at f = {max(f):g} Hz")
    check_samples(args)
    from model.studies.maps import cached_model

    axes = {q.target: lists[q.name] for q in Case.of_role(*CASE_ROLES) if q.name in lists}
    first_set = parameters.replace(**{name: lists[name][0] for name in SET_VALUE_DIMS
                                      if lists.get(name)})
    model = cached_model(rail_parameters(first_set, lists["rail"][0]))
    first = OperatingPoint(**{q.target: lists[q.name][0] for q in Case.of_role("point")})
    try:
        outputs, units = resolve_outputs(model, first, output_names(args), args.creep)
    except (ResponseError, DesignLoadError) as error:
        raise UsageError(f"--outputs: {error}") from None
    study = EnvelopeStudy(
        **axes, outputs=outputs, units=units, fault=fault, phase=tuple(phase), creep=args.creep,
        anti_slip=tuple(anti_slip), anti_slip_delay=tuple(delays), anti_slip_threshold=args.anti_slip_threshold,
        anti_slip_rate=args.anti_slip_rate, anti_slip_floor=args.anti_slip_floor,
        t_end=args.t_end, fs=args.fs, method=args.method)
    return study, parameters


def _check_first_point(study, parameters, args) -> None:
    """Refuse a sampling rate that cannot resolve the modes the first scenario excites (as
    ``bogie response`` does; the other scenarios are checked after the run)."""
    from model.analysis.fault_instant import phase_families
    from model.mechanics.operating_point import OperatingPoint
    from model.studies.maps import cached_model

    if study.creep != "linear":
        return
    model = cached_model(study.chunk_parameters(parameters, {}))
    op = OperatingPoint(study.s0[0], study.v[0], study.N0[0], study.b_M[0])
    family = phase_families(model, op, [(max(study.f), study.D[0])], study.t_end, study.fs,
                            list(study.outputs), study.method)[0]
    if family.highest_excited_hz:
        check_sampling(args, family.highest_excited_hz,
                       f"the highest excited frequency {family.highest_excited_hz:.4g} Hz", ".4g")


def cmd_envelope(args: argparse.Namespace) -> None:
    from model.studies.envelope import envelope
    from model.studies.store import (
        finished_chunks,
        open_study,
        run_in_memory,
        run_into_store,
        store_layout,
    )

    study, parameters = study_from_args(args)
    out = None if args.out is None else Path(args.out)
    if out is None and args.resume:
        raise UsageError("--resume needs --out (the store to continue)")
    if out is not None and not args.resume:
        writable_path(args.out, "--out", directory=True)
        if out.exists():
            raise UsageError(f"--out '{out}' exists: continue it with --resume, or remove it")
    elif out is not None:
        resume_store(out, study, parameters)
    _check_first_point(study, parameters, args)
    progress = ProgressBar("envelope")

    def interrupted() -> str:
        if out is None:
            return ""
        done = len(finished_chunks(out)) if out.exists() else 0
        return f"; {done} of {len(study.chunks())} chunks finished in {out}; continue with --resume"

    with study_engine(args, "envelope", interrupted) as (mapper, where):
        print(f"envelope: {study.scenarios} scenario(s) in {len(study.chunks())} chunk(s) on "
              f"{where}; fault instants: {study.fault}", file=sys.stderr)
        if out is None:
            arrays = run_in_memory(study, parameters, mapper, progress)
            run = None
        else:
            run = run_into_store(study, parameters, out, mapper, resume=args.resume,
                                 progress=progress)
            dataset = open_study(out)
            arrays = {name: dataset[name].values for name in store_layout(study).variables}
    result = envelope(study, arrays)
    data = result.as_dict()
    data.update({"t_end": study.t_end, "fs": study.fs})
    if out is not None:
        data.update({"out": str(out), "computed_chunks": run.computed,
                     "skipped_chunks": run.skipped})
    if result.highest_excited_hz and study.fs < 2.5 * result.highest_excited_hz:
        print(f"envelope: warning: some scenarios excite {result.highest_excited_hz:.4g} Hz, "
              f"more than --fs / 2.5 = {study.fs / 2.5:.4g} Hz resolves", file=sys.stderr)
    if args.json:
        print(json.dumps(data, indent=1, allow_nan=False))
    else:
        print(envelope_table(study, result, out))


def envelope_table(study, result, out: Path | None) -> str:
    """The envelope as text: per output the max and min and the scenario of each (the axes with
    more than one value, the fault instant Δt and the time)."""
    from model.studies.envelope import FAULT_DESCRIPTIONS

    varying = [d for d, n in study.sizes.items() if n > 1 and d in AXIS_LABELS]
    keys = {"rail": "rail", "s0": "s0", "v": "v_kmh", "N0": "n0", "b_M": "bm",
            "motor_bandwidth": "motor_bandwidth", "M0": "m0",
            "f": "f", "D": "decay", "anti_slip": "anti_slip", "anti_slip_delay":
            "anti_slip_delay_s"}

    def where(at: dict) -> str:
        values = [(AXIS_LABELS[d], at[keys[d]]) for d in varying if at[keys[d]] is not None]
        parts = [f"{label} {value}" if isinstance(value, str) else f"{label} {value:g}"
                 for label, value in values]
        parts += [f"Δt {at['phase_s'] * 1e3:.4g} ms", f"t {at['time_s']:.4f} s"]
        return ", ".join(parts)

    lines = [f"envelope over {result.scenarios} scenario(s), creep {result.creep}, "
             f"t = 0…{study.t_end:g} s at {study.fs:g} Hz; values are totals "
             "(pre-fault + perturbation)",
             f"fault instants: {FAULT_DESCRIPTIONS[result.fault_instants]}"]
    if result.truncated:
        lines.append(f"{result.truncated} scenario(s) grew beyond 1e250 and were cut (linear "
                     "growth): their peaks end there")
    lines += ["", f"{'output':<30} {'unit':<4}     {'value':>12}  scenario"]
    for o in result.outputs:
        lines.append(f"{o.name:<30} {o.unit:<4} max {o.max:>12.5g}  {where(o.max_at)}")
        lines.append(f"{'':<30} {'':<4} min {o.min:>12.5g}  {where(o.min_at)}")
    if out is not None:
        lines.append(f"\nwrote {out} (peaks per scenario; xarray.open_zarr(..., "
                     "consolidated=False))")
    return "\n".join(lines)


# --- bogie spectrum -----------------------------------------------------------------------------------

def _slopes(text: str) -> list[float]:
    from model.analysis.load_spectrum import SpectrumError, check_slope

    values = []
    for part in text.split(","):
        try:
            values.append(check_slope(float(part)))
        except ValueError as error:
            reason = str(error) if isinstance(error, SpectrumError) else f"'{part.strip()}' is " \
                "not a number"
            raise UsageError(f"--slopes: {reason}") from None
    if len(set(values)) != len(values):
        raise UsageError(f"--slopes: a slope is repeated in '{text}'")
    return values


def _fault_instant(result) -> dict:
    excitation = result.excitation
    shift = excitation.shift(result.motor_torque)
    how = ("continuity root: sin(ωΔt) = M(s0, v)/M0" if excitation.dt is None
           else "given by --phase")
    return {"dt": shift, "treatment": how}


def spectrum_data(result, spectra, creep: str) -> dict:
    from model.analysis.load_spectrum import N_REF

    return {
        "history": {"creep": creep, "operating_point": result.operating_point.as_dict(),
                    "excitation": {"M0": result.excitation.M0, "f": result.excitation.f,
                                   "D": result.excitation.D},
                    "fault_instant": _fault_instant(result), "t_end": float(result.t[-1]),
                    "samples": len(result.t)},
        "counting": "rainflow, ASTM E1049-85 (rainflow package), residue as half cycles",
        "n_ref": N_REF,
        "outputs": [{"name": s.name, "unit": s.unit, "cycles": s.cycles.tolist(),
                     "equivalent_range": {f"{m:g}": value
                                          for m, value in s.equivalent_range.items()},
                     "total_cycles": s.total_cycles, "largest_range": s.largest_range,
                     "exceedance": {"range": s.exceedance_range.tolist(),
                                    "cycles": s.exceedance_count.tolist()}}
                    for s in spectra],
    }


def spectrum_table(result, spectra, creep: str) -> str:
    slopes = list(spectra[0].equivalent_range) if spectra else []
    op, fault = result.operating_point, _fault_instant(result)
    lines = [f"load spectrum of the short circuit at s0 = {op.s0:g}, v = {op.v_kmh:g} km/h, creep "
             f"{creep}, Δt = {fault['dt']:.4g} s ({fault['treatment']}), {len(result.t)} samples "
             f"to {result.t[-1]:g} s",
             "rainflow cycles (ASTM E1049-85, residue as half cycles); ΔM_eq = "
             "(Σ n ΔM^m / 1e7)^(1/m)", "",
             f"{'output':<30} {'unit':<4} {'cycles':>9} {'largest range':>14}"
             + "".join(f" {'ΔM_eq m=' + format(m, 'g'):>13}" for m in slopes)]
    for s in spectra:
        lines.append(f"{s.name:<30} {s.unit:<4} {s.total_cycles:>9g} {s.largest_range:>14.5g}"
                     + "".join(f" {s.equivalent_range[m]:>13.5g}" for m in slopes))
    return "\n".join(lines)


def write_spectra(path: Path, spectra, data: dict) -> None:
    """``.json``: ``data``; ``.npz``: per output ``<name>.cycles`` (k x 3: range, mean, count),
    ``<name>.exceedance_range``, ``<name>.exceedance_count``, and ``names``, ``units``,
    ``slopes``, ``equivalent_range`` (outputs x slopes), ``n_ref``; ``.csv``: one row per cycle
    (output, unit, range, mean, count)."""
    if path.suffix == ".json":
        path.write_text(json.dumps(data, allow_nan=False))
        return
    slopes = list(spectra[0].equivalent_range) if spectra else []
    if path.suffix == ".npz":
        arrays = {"names": np.array([s.name for s in spectra], dtype=str),
                  "units": np.array([s.unit for s in spectra], dtype=str),
                  "slopes": np.array(slopes),
                  "equivalent_range": np.array([[s.equivalent_range[m] for m in slopes]
                                                for s in spectra]).reshape(len(spectra), -1),
                  "n_ref": np.array(data["n_ref"])}
        for s in spectra:
            arrays[f"{s.name}.cycles"] = s.cycles
            arrays[f"{s.name}.exceedance_range"] = s.exceedance_range
            arrays[f"{s.name}.exceedance_count"] = s.exceedance_count
        np.savez(path, **arrays)
        return
    with path.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["output", "unit", "range", "mean", "count"])
        for s in spectra:
            for rng, mean, count in s.cycles:
                writer.writerow([s.name, s.unit, repr(float(rng)), repr(float(mean)),
                                 repr(float(count))])


def cmd_spectrum(args: argparse.Namespace) -> None:
    from model.analysis.load_spectrum import history_spectra

    slopes = _slopes(args.slopes)
    out = check_history_file(args.out)
    result = history_from_args(args)
    spectra = history_spectra(result, slopes)
    data = spectrum_data(result, spectra, args.creep)
    if out is not None:
        write_spectra(out, spectra, data)
    if args.json:
        summary = dict(data)
        if out is not None:
            summary["out"] = str(out)
        print(json.dumps(summary, indent=1, allow_nan=False))
    else:
        print(spectrum_table(result, spectra, args.creep) + (f"\nwrote {out}" if out else ""))
