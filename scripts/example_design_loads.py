"""The worked example of docs/design-loads.md: design loads of the drive parts at the study's two
cases (s0 = 0.005 and 0.014, 120 km/h), calibrated set, default excitation, 2 s at 10 kHz.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/example_design_loads.py [--phases 36]

Writes ``docs/results/design_loads.json`` (every number and table the page quotes) and prints
the tables (≈ 2 min on one core):

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
import sys
from pathlib import Path

import numpy as np

from model import KMH, load_parameters
from model.analysis.load_spectrum import history_spectra
from model.analysis.nonlinear import AntiSlip, nonlinear_response
from model.analysis.response import short_circuit_response
from model.mechanics.operating_point import OperatingPoint
from model.studies.envelope import EnvelopeStudy, resolve_outputs, run_envelope
from model.studies.maps import cached_model

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))

from docs_numbers import write_results  # noqa: E402

PARTS = ("driving_shaft.torque", "disc_clutch.torque", "claw_clutch.torque", "gear_mesh.force")
OUTPUTS = [f"{drive}.{part}" for drive in ("ID1", "ID2") for part in PARTS]
LABELS = {"driving_shaft.torque": "driving shaft torque [N m]",
          "disc_clutch.torque": "disc clutch torque [N m]",
          "claw_clutch.torque": "claw clutch torque [N m]", "gear_mesh.force": "gear mesh force [N]"}
LINEAR_ROWS = ("ID1.driving_shaft.torque", "ID1.disc_clutch.torque", "ID1.claw_clutch.torque",
               "ID1.gear_mesh.force", "ID2.disc_clutch.torque", "ID2.driving_shaft.torque")
NONLINEAR_ROWS = ("ID1.driving_shaft.torque", "ID1.disc_clutch.torque", "ID1.gear_mesh.force",
                  "ID2.disc_clutch.torque", "ID2.driving_shaft.torque", "ID2.gear_mesh.force")
SPECTRUM_ROWS = ("ID1.driving_shaft.torque", "ID1.disc_clutch.torque", "ID2.disc_clutch.torque")
WORSE = 1e-3  # a column's value is set in bold where it exceeds the first column's by this


def envelope_of(parameters, model, s0, **changes):
    op = OperatingPoint.from_kmh(s0, 120.0, parameters["wheel_force"], parameters["motor_slope"])
    outputs, units = resolve_outputs(model, op, OUTPUTS, changes.get("creep", "linear"))
    study = EnvelopeStudy(s0=(s0,), v=(120.0 * KMH,), N0=(parameters["wheel_force"],),
                          b_M=(parameters["motor_slope"],), outputs=outputs, units=units,
                          **changes)
    return run_envelope(study, parameters)


def as_data(envelope) -> dict:
    """{output: max, min, the fault instant [s] and time [s] of each} of an envelope."""
    return {o.name: {"max": o.max, "min": o.min, "max_phase_s": o.max_at["phase_s"],
                     "min_phase_s": o.min_at["phase_s"], "max_time_s": o.max_at["time_s"],
                     "min_time_s": o.min_at["time_s"]} for o in envelope.outputs}


def number(x: float) -> str:
    """A load as the page writes it: 4 significant digits, ·10ⁿ above 10⁴ in magnitude."""
    if abs(x) < 1e4:
        text = f"{abs(x):,.0f}".replace(",", " ")
    else:
        exponent = int(np.floor(np.log10(abs(x))))
        text = f"{abs(x) / 10 ** exponent:.3f}·10" + str(exponent).translate(
            str.maketrans("0123456789-", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻"))
    return ("−" if x < 0 else "") + text


def cell(column: dict, reference: dict, name: str, with_phase: bool) -> str:
    parts = []
    for side, sign in (("max", 1), ("min", -1)):
        value = column[name][side]
        text = number(value)
        if sign * (value - reference[name][side]) > WORSE * abs(reference[name][side]):
            text = f"**{text}**"
        if with_phase:
            text += f" [{1e3 * column[name][f'{side}_phase_s']:.3f}]".replace("-", "−")
        parts.append(text)
    return " / ".join(parts)


def table(columns: dict, rows, phases: set) -> str:
    """Markdown: a row per output, a column per envelope (max / min, [Δt ms] where asked)."""
    heads = list(columns)
    lines = ["| output | " + " | ".join(heads) + " |", "|---|" + "---|" * len(heads)]
    reference = columns[heads[0]]
    for name in rows:
        drive, part = name.split(".", 1)
        cells = [cell(columns[h], reference, name, h in phases) for h in heads]
        lines.append(f"| {drive} {LABELS[part]} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def spectra_rows(label: str, result) -> tuple[list[str], dict]:
    lines, data = [], {}
    for k, spectrum in enumerate(s for s in history_spectra(result) if s.name in SPECTRUM_ROWS):
        drive, part = spectrum.name.split(".", 1)
        lines.append(f"| {label if k == 0 else ''} | {drive} {LABELS[part]} | "
                     f"{spectrum.total_cycles:g} | {number(spectrum.largest_range)} | "
                     f"{spectrum.equivalent_range[3.0]:.4g} | "
                     f"{number(spectrum.equivalent_range[5.0])} |")
        data[spectrum.name] = {"cycles": spectrum.total_cycles,
                               "largest_range": spectrum.largest_range,
                               "eq_3": spectrum.equivalent_range[3.0],
                               "eq_5": spectrum.equivalent_range[5.0]}
    return lines, data


def derived(data: dict, model, parameters) -> dict:
    """The comparisons the page's sentences make."""
    from model.analysis.eigen import eigen_analysis
    from model.analysis.modes import mode_character

    lin = data["envelopes"]["linear_0.005"]
    nl14 = data["envelopes"]["nonlinear_0.014"]
    M_ad = data["M_ad"]
    change = {name: max(abs(lin["every"][name][side] / lin["roots"][name][side] - 1)
                        for side in ("max", "min")) for name in OUTPUTS}
    direct = ("ID1.driving_shaft.torque", "ID1.gear_mesh.force")
    op = OperatingPoint.from_kmh(0.005, 120.0, parameters["wheel_force"], parameters["motor_slope"])
    result = eigen_analysis(model, op)
    shaft_hz = max((float(result.eigenvalues[i].imag / (2 * np.pi)) for i in result.complex_index
                    if mode_character(model, result, int(i)).strain.get("ID1.driving_shaft", 0) > 0.5),
                   default=float("nan"))
    period_ms = 1e3 / 90.0
    return {
        "ds_worst_over_roots": lin["every"]["ID1.driving_shaft.torque"]["max"]
        / lin["roots"]["ID1.driving_shaft.torque"]["max"],
        "others_max_change": max(v for k, v in change.items() if k not in direct),
        "id2_dc_over_M_ad_linear": lin["roots"]["ID2.disc_clutch.torque"]["max"] / M_ad,
        "id2_dc_over_M_ad_nonlinear_off": nl14["roots_off"]["ID2.disc_clutch.torque"]["max"] / M_ad,
        "id2_dc_over_M_ad_nonlinear_on": nl14["roots_on"]["ID2.disc_clutch.torque"]["max"] / M_ad,
        "grid_over_every": nl14["grid_off"]["ID1.driving_shaft.torque"]["max"]
        / lin["every"]["ID1.driving_shaft.torque"]["max"],
        "every_ds_phase_in_period_ms": (1e3 * lin["every"]["ID1.driving_shaft.torque"]["max_phase_s"])
        % period_ms,
        "id2_range_on_over_off": data["spectra"]["nonlinear, on_0.014".replace(", ", "_")][
            "ID2.disc_clutch.torque"]["largest_range"]
        / data["spectra"]["nonlinear_off_0.014"]["ID2.disc_clutch.torque"]["largest_range"],
        "driving_shaft_mode_hz": shaft_hz,
        "sampling_loss": float(1 - np.cos(np.pi * shaft_hz / 10_000.0)),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--phases", type=int, default=36,
                        help="fault instants of the nonlinear grid over one period")
    args = parser.parse_args()
    parameters = load_parameters()
    model = cached_model(parameters)
    grid = tuple(np.arange(args.phases) / args.phases / 90.0)
    data: dict = {"phases": args.phases, "envelopes": {}, "spectra": {}, "blocks": {}}
    for s0 in (0.005, 0.014):
        key = f"{s0:g}"
        linear = {"roots": envelope_of(parameters, model, s0),
                  "every": envelope_of(parameters, model, s0, fault="all")}
        nonlinear = {"roots_off": envelope_of(parameters, model, s0, creep="nonlinear"),
                     "roots_on": envelope_of(parameters, model, s0, creep="nonlinear",
                                             anti_slip=("on",)),
                     "grid_off": envelope_of(parameters, model, s0, creep="nonlinear",
                                             fault="grid", phase=grid)}
        data["envelopes"][f"linear_{key}"] = {k: as_data(e) for k, e in linear.items()}
        data["envelopes"][f"nonlinear_{key}"] = {k: as_data(e) for k, e in nonlinear.items()}
        print(f"s0 = {s0}: envelopes done", flush=True)
    lin = data["envelopes"]["linear_0.005"]
    data["blocks"]["linear_0.005"] = table(
        {"continuity roots": lin["roots"], "every Δt (closed form)": lin["every"]},
        LINEAR_ROWS, {"continuity roots", "every Δt (closed form)"})
    nl = data["envelopes"]["nonlinear_0.014"]
    data["blocks"]["nonlinear_0.014"] = table(
        {"roots, anti-slip off": nl["roots_off"], "roots, anti-slip on (delay 0.1 s)": nl["roots_on"],
         f"{args.phases} Δt over a period, off": nl["grid_off"]},
        NONLINEAR_ROWS, {f"{args.phases} Δt over a period, off"})
    op = OperatingPoint.from_kmh(0.005, 120.0, parameters["wheel_force"], parameters["motor_slope"])
    data["roots_s"] = sorted({lin["roots"][name][f"{side}_phase_s"] for name in OUTPUTS
                              for side in ("max", "min")})
    reference = short_circuit_response(model, op, None, 2.0, 10_000.0, OUTPUTS)
    data["M_ad"] = reference.limits["M_ad"]
    data["motor_torque"] = reference.motor_torque
    lines = ["| history | output | cycles | largest range | ΔM_eq, m = 3 | ΔM_eq, m = 5 |",
             "|---|---|---:|---:|---:|---:|"]
    for s0 in (0.005, 0.014):
        op = OperatingPoint.from_kmh(s0, 120.0, parameters["wheel_force"],
                                     parameters["motor_slope"])
        histories = {"linear": short_circuit_response(model, op, None, 2.0, 10_000.0, OUTPUTS),
                     "nonlinear, off": nonlinear_response(model, op, None, 2.0, 10_000.0,
                                                          outputs=OUTPUTS),
                     "nonlinear, on": nonlinear_response(
                         model, op, None, 2.0, 10_000.0, outputs=OUTPUTS, anti_slip=AntiSlip())}
        for label, result in histories.items():
            rows, numbers = spectra_rows(f"s0 = {s0:g}, {label}", result)
            key = f"{label.replace(', ', '_')}_{s0:g}"
            data["spectra"][key] = numbers
            if (s0, label) in ((0.005, "linear"), (0.014, "nonlinear, off"), (0.014, "nonlinear, on")):
                lines += rows
            if label == "linear" and s0 == 0.014:
                data["unstable_linear_at_2s"] = {name: float(result.outputs[name][-1])
                                                 for name in OUTPUTS}
    data["blocks"]["spectra"] = "\n".join(lines)
    data["derived"] = derived(data, model, parameters)
    for name in ("linear_0.005", "nonlinear_0.014", "spectra"):
        print(data["blocks"][name], end="\n\n")
    print(f"wrote {write_results('design_loads', data, 'scripts/example_design_loads.py')}")


if __name__ == "__main__":
    main()
