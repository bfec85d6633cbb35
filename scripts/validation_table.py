"""The tables and numbers of docs/validation.md for a parameter set (default: the calibrated set).

    .venv/bin/python scripts/validation_table.py            # docs/results/validation.json
    .venv/bin/python scripts/validation_table.py --params FILE --out FILE.json

Writes (120 km/h, N0 = 10^5 N) and prints: Table 1 by rank at s0 = 0.005 and 0.014, published
against the model (Re [1/s], Im [Hz]), with whether the k-th pair has Table 2's k-th character
and the generated description; the real eigenvalues at both creepages; the calibration's target
table; the stability limit; and the numbers of the mode-2 argument (the damping of ID1's rotor
mode at both creepages and with the longitudinal creep switched off, b11 = 0).  The JSON holds
the rendered tables (``blocks``) and every number the page quotes.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

from docs_numbers import write_results  # noqa: E402

from model import build_model, eigen_analysis, load_parameters, mode_character  # noqa: E402
from model.analysis.eigen import state_space  # noqa: E402
from model.analysis.linear_system import LinearSystem  # noqa: E402
from model.analysis.stability import stability_limit  # noqa: E402
from model.mechanics.operating_point import (  # noqa: E402
    OperatingPoint,
    creep_coefficients,
    creep_damping,
)
from model.studies.calibration_bounds import parameter_rows  # noqa: E402
from model.studies.calibration_targets import (  # noqa: E402
    MODE_SIGNATURES,
    TABLE1_IM_HZ,
    TABLE1_RE,
    TABLE1_UNSTABLE,
    V_REF,
    evaluate,
    format_table,
    match_table1_modes,
)


def _hz(z: complex) -> float:
    return z.imag / (2 * np.pi)


def _slug(name: str) -> str:
    """A target's name as a key without spaces: ``Im λ3 by rank OTHER CHARACTER: [...]`` →
    ``Im_λ3_by_rank``, ``Re of pair 7 at s0=0.014 (Im 8.428 Hz)`` → ``Re_of_pair_7_at_s0=0.014``."""
    name = name.split(" [")[0].split(" OTHER")[0].split(" (Im")[0]
    return name.replace(" ", "_")


def _pair(z: complex) -> dict:
    return {"re": float(z.real), "im_hz": float(_hz(z))}


def rank_table(model, parameters) -> tuple[dict, dict]:
    """(rendered tables, numbers) of Table 1 by rank and the real eigenvalues."""
    N0, b_M = parameters["wheel_force"], parameters["motor_slope"]
    stable = eigen_analysis(model, OperatingPoint(0.005, V_REF, N0, b_M))
    unstable = eigen_analysis(model, OperatingPoint(0.014, V_REF, N0, b_M), vectors=False)
    matched, _ = match_table1_modes(model, stable)
    lines = ["| # | published s0=0.005 | model s0=0.005 | ΔIm | Table 2 character at this rank "
             "| published s0=0.014 | model s0=0.014 |", "|---|---|---|---|---|---|---|"]
    numbers: dict = {"pairs_005": [], "pairs_014": [], "character": [], "delta_im": []}
    for k in range(10):
        index = stable.complex_index[k]
        z, w = stable.eigenvalues[index], unstable.complex_pairs[k]
        ok = "yes" if matched[k] == index else "**no**"
        re14, im14 = TABLE1_UNSTABLE[k]
        delta = _hz(z) / TABLE1_IM_HZ[k] - 1
        lines.append(
            f"| {k + 1} | {TABLE1_RE[k]:+.3f} ± i {TABLE1_IM_HZ[k]:.3f} | {z.real:+.3f} ± i "
            f"{_hz(z):.3f} | {100 * delta:+.1f} % | {ok} "
            f"| {re14:+.3f} ± i {im14:.3f} | {w.real:+.3f} ± i {_hz(w):.3f} |")
        numbers["pairs_005"].append(_pair(z))
        numbers["pairs_014"].append(_pair(w))
        numbers["character"].append(bool(matched[k] == index))
        numbers["delta_im"].append(float(delta))
    descriptions = ["| # | Table 2 | generated |", "|---|---|---|"]
    for k in range(10):
        description = mode_character(model, stable, stable.complex_index[k]).description
        descriptions.append(f"| {k + 1} | {MODE_SIGNATURES[k][0]} | {description} |")
    reals = ["s0 = 0.005: " + ", ".join(f"{x:.4g}" for x in stable.real_eigenvalues[:10]),
             "s0 = 0.014: " + ", ".join(f"{x:+.4g}" for x in unstable.real_eigenvalues[:10]),
             f"unstable pairs at s0 = 0.014: {unstable.flutter} in all, "
             f"{int(np.count_nonzero(unstable.complex_pairs[:10].real > 0))} among the first ten; "
             f"positive reals: {unstable.divergence}"]
    delta = np.abs(numbers["delta_im"])
    numbers |= {
        "reals_005": stable.real_eigenvalues[:10].tolist(), "reals_014": unstable.real_eigenvalues[:10].tolist(),
        "n_rigid": int(stable.n_rigid), "flutter_014": int(unstable.flutter),
        "flutter_014_first_ten": int(np.count_nonzero(unstable.complex_pairs[:10].real > 0)),
        "unstable_ranks_014": [k + 1 for k in range(10) if unstable.complex_pairs[k].real > 0],
        "divergent_014": int(unstable.divergence),
        "character_count": int(sum(numbers["character"])),
        "delta_im_abs_min": float(delta.min()), "delta_im_abs_max": float(delta.max()),
        "stable_005": bool(stable.stable), "stable_014": bool(unstable.stable),
        # ranks 3 and 4 apart (relative, the 4th over the 3rd)
        "rank_3_4_gap": float(_hz(stable.eigenvalues[stable.complex_index[3]])
                              / _hz(stable.eigenvalues[stable.complex_index[2]]) - 1),
    }
    # the mode of each Table 2 character, wherever its rank (1-based)
    ranks = list(stable.complex_index)
    numbers["matched_005"] = [{"rank": ranks.index(index) + 1, **_pair(stable.eigenvalues[index])}
                              for index in matched]
    blocks = {"rank_table": "\n".join(lines), "descriptions": "\n".join(descriptions),
              "reals": "\n".join(reals)}
    return blocks, numbers


def mode2_argument(model, parameters) -> tuple[str, list]:
    """Re of ID1's rotor mode (Table 2 row 2) at s0 = 0.005, 0.014 and with b11 = 0."""
    N0, b_M = parameters["wheel_force"], parameters["motor_slope"]
    space = state_space(model)
    rows = ["| s0 | ∂μ/∂s | b11 [N s/m] | mode 2 (ID1 rotor) Re [1/s] | Im [Hz] |",
            "|---|---|---|---|---|"]
    numbers = []
    reference = eigen_analysis(model, OperatingPoint(0.005, V_REF, N0, b_M))
    matched, _ = match_table1_modes(model, reference)
    shape = reference.mode_shape(matched[1])
    for s0, switch_off in ((0.005, False), (0.014, False), (0.005, True)):
        op = OperatingPoint(s0, V_REF, N0, b_M)
        coefficients = creep_coefficients(parameters, op)
        if switch_off:
            coefficients = replace(coefficients, b11=0.0)
        B = model.B + b_M * model.motor_pattern + creep_damping(model, coefficients)
        system = LinearSystem(model.M, B, model.K, model.short_circuit_force,
                              model.rigid_body_modes, space.inverse_mass)
        values, vectors = system.eigen[0], system.state_vectors()
        n = model.n
        candidates = np.flatnonzero((values.imag > 0) & (values.imag < 2 * np.pi * 20))
        overlap = [abs(np.vdot(shape, vectors[:n, i])) / np.linalg.norm(vectors[:n, i])
                   for i in candidates]
        z = values[candidates[int(np.argmax(overlap))]]
        label = "0.005, b11 = 0" if switch_off else f"{s0}"
        rows.append(f"| {label} | {coefficients.dmu_ds:+.3f} | {coefficients.b11:+.4g} "
                    f"| {z.real:+.3f} | {_hz(z):.3f} |")
        numbers.append({"s0": s0, "b11_off": switch_off, "dmu_ds": float(coefficients.dmu_ds),
                        "b11": float(coefficients.b11), **_pair(z)})
    return "\n".join(rows), numbers


def constant_reference_pattern(model) -> np.ndarray:
    """B_M (b_M = 1) with the slope measured against the initial speed instead of the vehicle's
    (the car body's column dropped): the form the comparison below contrasts."""
    pattern = model.motor_pattern.copy()
    pattern[:, model.dofs.index("CB.x")] = 0.0
    return pattern


def reference_comparison(model, parameters) -> tuple[str, dict]:
    """The ten lowest pairs and the positive real eigenvalues at s0 = 0.005 and 0.014, and s0* at
    120 km/h, of the same set with the healthy motor's slope measured against the vehicle's
    speed (the model) and against the initial speed (a constant reference; its rolling velocity
    is then damped, so only the four rigid-body modes are deflated)."""
    from scipy.optimize import brentq

    N0, b_M = parameters["wheel_force"], parameters["motor_slope"]
    space = state_space(model)
    constant = constant_reference_pattern(model)

    def constant_system(s0: float) -> LinearSystem:
        op = OperatingPoint(s0, V_REF, N0, b_M)
        B = model.B + b_M * constant + creep_damping(model, creep_coefficients(parameters, op))
        return LinearSystem(model.M, B, model.K, model.short_circuit_force,
                            model.rigid_body_modes, space.inverse_mass)

    numbers: dict = {}
    rows = ["| s0 | reference | pairs 1–10: Im [Hz] (Re [1/s]) | positive reals [1/s] |",
            "|---|---|---|---|"]
    for s0 in (0.005, 0.014):
        vehicle = eigen_analysis(model, OperatingPoint(s0, V_REF, N0, b_M), vectors=False)
        for label, values in (("vehicle's speed", vehicle.eigenvalues),
                              ("initial speed", constant_system(s0).eigenvalues())):
            pairs = values[values.imag > 0]
            pairs = pairs[np.argsort(pairs.imag)][:10]
            reals = np.sort(values.real[values.imag == 0])[::-1]
            positive = reals[reals > 1e-9]
            reference = "vehicle" if label.startswith("vehicle") else "initial"
            numbers.setdefault(f"{s0:g}", {})[reference] = {
                "pairs": [_pair(z) for z in pairs], "positive_reals": [float(x) for x in positive]}
            text = ", ".join(f"{_hz(z):.3f} ({z.real:+.2f})" for z in pairs)
            rows.append(f"| {s0:g} | {label} | {text} | "
                        f"{', '.join(f'{x:+.3f}' for x in positive) or 'none'} |")
    limit_vehicle = stability_limit(model, V_REF, N0, b_M).s0_limit
    limit_initial = brentq(lambda s: float(np.max(constant_system(s).eigenvalues().real)),
                           0.005, 0.014, xtol=1e-9)
    numbers["s0_limit"] = {"vehicle": float(limit_vehicle), "initial": float(limit_initial)}
    return "\n".join(rows), numbers


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--params", default=None, help="parameter file (default: calibrated)")
    parser.add_argument("--out", default=None,
                        help="JSON file (default: docs/results/validation.json for the bundled set)")
    args = parser.parse_args(argv)
    with threadpool_limits(1):
        parameters = load_parameters(args.params)
        model = build_model(parameters)
        blocks, numbers = rank_table(model, parameters)
        limit = stability_limit(model, V_REF, parameters["wheel_force"],
                                parameters["motor_slope"]).s0_limit
        rows = evaluate(parameters)
        blocks["targets"] = "```\n" + format_table(rows, limit) + "\n```"
        blocks["mode2"], numbers["mode2"] = mode2_argument(model, parameters)
        blocks["reference"], numbers["reference"] = reference_comparison(model, parameters)
    numbers["s0_limit"] = float(limit)
    numbers["targets"] = {_slug(row.name): {
        "published": row.target, "achieved": float(row.achieved), "error": float(row.error),
        "ratio": float(row.achieved / row.target)} for row in rows}
    bounds = parameter_rows(parameters)
    numbers["free_parameters"] = sum(1 for row in bounds if row["lower"] is not None)
    numbers["on_bound"] = [row["name"] for row in bounds if row["on_bound"]]
    numbers["on_bound_count"] = len(numbers["on_bound"])
    nominal = OperatingPoint(0.005, V_REF, parameters["wheel_force"], parameters["motor_slope"])
    numbers["rotor_speed_120"] = float(parameters["gear_ratio"] * nominal.v / parameters["wheel_radius"])
    for name in ("rank_table", "descriptions", "reals", "targets", "mode2", "reference"):
        print(blocks[name], end="\n\n")
    if args.out or args.params is None:
        out = Path(args.out) if args.out else None
        data = {"blocks": blocks, **numbers}
        if out is None:
            print(f"wrote {write_results('validation', data, 'scripts/validation_table.py')}")
        else:
            out.write_text(json.dumps(data, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
            print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
