"""Print the tables of docs/validation.md for a parameter set (default: the calibrated set).

    .venv/bin/python scripts/validation_table.py            # markdown tables on stdout
    .venv/bin/python scripts/validation_table.py --params FILE

Prints (120 km/h, N0 = 10^5 N): Table 1 by rank at s0 = 0.005 and 0.014, published against the
model (Re [1/s], Im [Hz]), with whether the k-th pair has Table 2's k-th character and the
generated description; the real eigenvalues at both creepages; the calibration's target table;
the stability limit; and the numbers of the mode-2 argument (the damping of ID1's rotor mode at
both creepages and with the longitudinal creep switched off, b11 = 0).
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from model import build_model, eigen_analysis, load_parameters, mode_character  # noqa: E402
from model.analysis.eigen import state_space  # noqa: E402
from model.analysis.linear_system import LinearSystem  # noqa: E402
from model.analysis.stability import stability_limit  # noqa: E402
from model.mechanics.operating_point import (  # noqa: E402
    OperatingPoint,
    creep_coefficients,
    creep_damping,
)
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


def rank_table(model, parameters) -> str:
    N0, b_M = parameters["wheel_force"], parameters["motor_slope"]
    stable = eigen_analysis(model, OperatingPoint(0.005, V_REF, N0, b_M))
    unstable = eigen_analysis(model, OperatingPoint(0.014, V_REF, N0, b_M), vectors=False)
    matched, _ = match_table1_modes(model, stable)
    lines = ["| # | published s0=0.005 | model s0=0.005 | ΔIm | Table 2 character at this rank "
             "| published s0=0.014 | model s0=0.014 |", "|---|---|---|---|---|---|---|"]
    for k in range(10):
        index = stable.complex_index[k]
        z, w = stable.eigenvalues[index], unstable.complex_pairs[k]
        ok = "yes" if matched[k] == index else "**no**"
        re14, im14 = TABLE1_UNSTABLE[k]
        lines.append(
            f"| {k + 1} | {TABLE1_RE[k]:+.3f} ± i {TABLE1_IM_HZ[k]:.3f} | {z.real:+.3f} ± i "
            f"{_hz(z):.3f} | {100 * (_hz(z) / TABLE1_IM_HZ[k] - 1):+.1f} % | {ok} "
            f"| {re14:+.3f} ± i {im14:.3f} | {w.real:+.3f} ± i {_hz(w):.3f} |")
    lines += ["", "Generated descriptions by rank (s0 = 0.005):", "",
              "| # | Table 2 | generated |", "|---|---|---|"]
    for k in range(10):
        description = mode_character(model, stable, stable.complex_index[k]).description
        lines.append(f"| {k + 1} | {MODE_SIGNATURES[k][0]} | {description} |")
    lines += ["", "Real eigenvalues [1/s], largest first (rigid-body zeros deflated, "
              f"{stable.n_rigid} of them):",
              "s0 = 0.005: " + ", ".join(f"{x:.4g}" for x in stable.real[:10]),
              "s0 = 0.014: " + ", ".join(f"{x:+.4g}" for x in unstable.real[:10]),
              f"unstable pairs at s0 = 0.014: {unstable.flutter} in all, "
              f"{int(np.count_nonzero(unstable.complex_pairs[:10].real > 0))} among the first ten; "
              f"positive reals: {unstable.divergence}"]
    return "\n".join(lines)


def mode2_argument(model, parameters) -> str:
    """Re of ID1's rotor mode (Table 2 row 2) at s0 = 0.005, 0.014 and with b11 = 0."""
    N0, b_M = parameters["wheel_force"], parameters["motor_slope"]
    space = state_space(model)
    rows = ["| s0 | ∂μ/∂s | b11 [N s/m] | mode 2 (ID1 rotor) Re [1/s] | Im [Hz] |",
            "|---|---|---|---|---|"]
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
    return "\n".join(rows)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--params", default=None, help="parameter file (default: calibrated)")
    args = parser.parse_args(argv)
    with threadpool_limits(1):
        parameters = load_parameters(args.params)
        model = build_model(parameters)
        print(rank_table(model, parameters))
        print("\nCalibration targets:\n")
        limit = stability_limit(model, V_REF, parameters["wheel_force"],
                                parameters["motor_slope"]).s0_limit
        print(format_table(evaluate(parameters), limit))
        print("\nMode 2 (ID1's rotor torsion) against the longitudinal creep:\n")
        print(mode2_argument(model, parameters))
    return 0


if __name__ == "__main__":
    sys.exit(main())
