"""The worked example of docs/design-loads.md: design loads of the drive parts at the study's two
cases (s0 = 0.005 and 0.014, 120 km/h), calibrated set, default excitation, 2 s at 10 kHz.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/example_design_loads.py [--phases 36]

Prints markdown tables (≈ 1 min on one core):

1. linear creep: max and min of each drive part's total over the two continuity roots (the
   default) and over every fault instant (closed form), with the Δt of each;
2. nonlinear creep, anti-slip off and on (delay 0.1 s): the continuity roots and a grid of
   ``--phases`` fault instants over one period;
3. load spectra of the default histories (Δt = the first continuity root): rainflow cycles and
   damage-equivalent ranges for m = 3 and 5, N_ref = 10⁷.

The same numbers come from ``bogie envelope`` and ``bogie spectrum`` with the options printed
above each table.
"""

from __future__ import annotations

import argparse

import numpy as np

from model import KMH, load_parameters
from model.analysis.load_spectrum import history_spectra
from model.analysis.nonlinear import AntiSlip, nonlinear_response
from model.analysis.response import short_circuit_response
from model.mechanics.operating_point import OperatingPoint
from model.studies.envelope import EnvelopeStudy, resolve_outputs, run_envelope
from model.studies.maps import cached_model

PARTS = ("driving_shaft.torque", "disc_clutch.torque", "claw_clutch.torque", "gear_mesh.force")
OUTPUTS = [f"{drive}.{part}" for drive in ("ID1", "ID2") for part in PARTS]


def envelope_of(parameters, model, s0, **changes):
    op = OperatingPoint.from_kmh(s0, 120.0, parameters["wheel_force"], parameters["motor_slope"])
    outputs, units = resolve_outputs(model, op, OUTPUTS, changes.get("creep", "linear"))
    study = EnvelopeStudy(s0=(s0,), v=(120.0 * KMH,), N0=(parameters["wheel_force"],),
                          b_M=(parameters["motor_slope"],), outputs=outputs, units=units,
                          **changes)
    return run_envelope(study, parameters)


def table(title: str, command: str, columns: dict) -> None:
    """columns: heading -> Envelope (same outputs)."""
    print(f"\n### {title}\n\n    {command}\n")
    heads = list(columns)
    print("| output | unit | " + " | ".join(f"{h} max [Δt ms] | {h} min [Δt ms]" for h in heads)
          + " |")
    print("|---|---|" + "---:|---:|" * len(heads))
    first = columns[heads[0]]
    for j, out in enumerate(first.outputs):
        cells = []
        for h in heads:
            o = columns[h].outputs[j]
            cells.append(f"{o.max:.4g} [{1e3 * o.max_at['phase_s']:.3f}] | "
                         f"{o.min:.4g} [{1e3 * o.min_at['phase_s']:.3f}]")
        print(f"| {out.name} | {out.unit} | " + " | ".join(cells) + " |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--phases", type=int, default=36,
                        help="fault instants of the nonlinear grid over one period")
    args = parser.parse_args()
    parameters = load_parameters()
    model = cached_model(parameters)
    grid = tuple(np.arange(args.phases) / args.phases / 90.0)
    grid_text = f"0:{float(grid[-1]):.6g}:{args.phases}"
    for s0 in (0.005, 0.014):
        outputs = ",".join(OUTPUTS)
        table(f"s0 = {s0}, 120 km/h, linear creep",
              f"bogie envelope --s0 {s0} --outputs {outputs} [--phase all]",
              {"roots": envelope_of(parameters, model, s0),
               "every Δt": envelope_of(parameters, model, s0, fault="all")})
        table(f"s0 = {s0}, 120 km/h, nonlinear creep",
              f"bogie envelope --s0 {s0} --creep nonlinear --anti-slip off|on "
              f"[--phase {grid_text}] --outputs {outputs}",
              {"roots, off": envelope_of(parameters, model, s0, creep="nonlinear"),
               "roots, on": envelope_of(parameters, model, s0, creep="nonlinear",
                                        anti_slip=("on",)),
               f"{args.phases} Δt, off": envelope_of(parameters, model, s0, creep="nonlinear",
                                                     fault="grid", phase=grid)})
    print("\n### Load spectra of the default histories (Δt = first continuity root)\n")
    print("    bogie spectrum --s0 S0 [--creep nonlinear [--anti-slip on]] --outputs …\n")
    print("| history | output | cycles | largest range | ΔM_eq m = 3 | ΔM_eq m = 5 |")
    print("|---|---|---:|---:|---:|---:|")
    for s0 in (0.005, 0.014):
        op = OperatingPoint.from_kmh(s0, 120.0, parameters["wheel_force"],
                                     parameters["motor_slope"])
        histories = {"linear": short_circuit_response(model, op, None, 2.0, 10_000.0, OUTPUTS),
                     "nonlinear, anti-slip off": nonlinear_response(model, op, None, 2.0,
                                                                    10_000.0, outputs=OUTPUTS),
                     "nonlinear, anti-slip on": nonlinear_response(
                         model, op, None, 2.0, 10_000.0, outputs=OUTPUTS, anti_slip=AntiSlip())}
        for label, result in histories.items():
            for s in history_spectra(result):
                print(f"| s0 = {s0}, {label} | {s.name} [{s.unit}] | {s.total_cycles:g} | "
                      f"{s.largest_range:.4g} | {s.equivalent_range[3.0]:.4g} | "
                      f"{s.equivalent_range[5.0]:.4g} |")


if __name__ == "__main__":
    main()
