"""Benchmark: the Campbell diagram and the frequency response against their yardsticks, in the
same run, on the calibrated default parameters (one BLAS thread, as the CLI and the app use).

    .venv/bin/python scripts/bench_resonance.py [--speeds 200] [--points 2000] [--repeat 3]

* a 200-speed Campbell diagram (5…200 km/h, s0 = 0.005, the default orders and mode selection)
  against the 200-point root locus over s0 of ``scripts/bench_locus.py`` (0.002…0.016 at
  120 km/h, |λ| < 2π·13 Hz) — target: not slower;
* the frequency response of every output at 2000 log-spaced frequencies (plus the points across
  the resonances) from ID1's motor torque against one eigen-analysis with vectors — target: at
  most 5 times;

both cold (the cached decompositions and sweep starts dropped before each call), best of
``--repeat``, the two members of each pair alternated.  Accuracy: the largest relative distance
of the diagram's eigenvalues to those of ``eigen_analysis`` at every tenth speed, relative to
max(|λ|, 1 1/s), and of the FRF to direct solves of the dynamic stiffness at every 50th
frequency, relative to each output's largest |H|.
"""

from __future__ import annotations

import argparse
import json
import platform
import time
from dataclasses import replace

import numpy as np
from threadpoolctl import threadpool_limits

from model import build_model, default_operating_point, eigen_analysis, load_parameters
from model.analysis.campbell import campbell, speeds_kmh
from model.analysis.eigen import forget_systems
from model.analysis.frequency_response import direct_response, frequency_response
from model.analysis.locus import clear_sweep_starts, root_locus
from model.mechanics.excitation import DEFAULT_ORDERS, load_excitation, parse_orders


def cold(model) -> None:
    forget_systems(model)
    clear_sweep_starts()


def timed(function, model):
    cold(model)
    start = time.perf_counter()
    result = function()
    return time.perf_counter() - start, result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--speeds", type=int, default=200)
    parser.add_argument("--points", type=int, default=2000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--json", default=None, metavar="FILE", help="also write the numbers")
    args = parser.parse_args()

    parameters = load_parameters()
    model = build_model(parameters)
    op = default_operating_point(parameters, s0=0.005, v_kmh=120.0)
    excitation = load_excitation()
    orders = parse_orders(DEFAULT_ORDERS)
    v = speeds_kmh(5, 200, args.speeds)
    s0 = np.linspace(0.002, 0.016, args.speeds)

    def run_locus():
        return root_locus(model, op, "s0", s0, max_frequency_hz=13.0)

    def run_campbell():
        return campbell(model, replace(op, v=float(0.5 * (v[0] + v[-1]))), v, orders, excitation)

    def run_eigen():
        return eigen_analysis(model, op)

    def run_frf():
        return frequency_response(model, op, points=args.points)

    times = {name: [] for name in ("locus", "campbell", "eigen", "frf")}
    results = {}
    for _ in range(args.repeat):
        for name, function in (("locus", run_locus), ("campbell", run_campbell),
                               ("eigen", run_eigen), ("frf", run_frf)):
            elapsed, results[name] = timed(function, model)
            times[name].append(elapsed)
    best = {name: min(values) for name, values in times.items()}

    diagram, frf = results["campbell"], results["frf"]
    worst_campbell = 0.0
    for i in range(0, len(v), 10):
        exact = eigen_analysis(model, replace(op, v=float(v[i])), vectors=False).eigenvalues
        for mode in diagram.modes:
            value = mode.eigenvalues[i]
            worst_campbell = max(worst_campbell,
                                 float(np.min(np.abs(exact - value)) / max(abs(value), 1.0)))
    sample = frf.f_hz[1::50]
    direct = direct_response(model, op, sample)
    columns = np.searchsorted(frf.f_hz, sample)
    scale = np.abs(frf.H).max(axis=1, keepdims=True)
    worst_frf = float(np.max(np.abs(frf.H[:, columns] - direct) / scale))

    numbers = {
        "machine": platform.processor() or platform.machine(),
        "locus_s": best["locus"], "campbell_s": best["campbell"],
        "campbell_over_locus": best["campbell"] / best["locus"],
        "eigen_s": best["eigen"], "frf_s": best["frf"], "frf_over_eigen": best["frf"] / best["eigen"],
        "campbell_modes": len(diagram.modes), "campbell_basis": diagram.basis_size,
        "campbell_dense_points": diagram.dense_points, "campbell_crossings": len(diagram.crossings),
        "campbell_newton_refinements": diagram.newton_refinements,
        "campbell_max_error": worst_campbell, "frf_frequencies": len(frf.f_hz),
        "frf_outputs": len(frf.names), "frf_max_error": worst_frf,
        "frf_direct_points": frf.direct_points,
    }
    print(f"{'measure':<58} {'time':>9} {'ratio':>7}")
    print(f"{'200-point root locus over s0 (|λ| < 2π·13 Hz, the yardstick)':<58} "
          f"{best['locus']:>8.3f}s")
    print(f"{f'Campbell diagram, {len(v)} speeds 5…200 km/h':<58} {best['campbell']:>8.3f}s "
          f"{numbers['campbell_over_locus']:>6.2f}x   (target <= 1)")
    print(f"{'one eigen-analysis with vectors (the yardstick)':<58} {best['eigen']:>8.3f}s")
    print(f"{f'FRF of {len(frf.names)} outputs at {len(frf.f_hz)} frequencies':<58} "
          f"{best['frf']:>8.3f}s {numbers['frf_over_eigen']:>6.2f}x   (target <= 5)")
    print(f"Campbell: {len(diagram.modes)} modes, basis {diagram.basis_size}, "
          f"{diagram.dense_points} speeds solved densely, {diagram.newton_refinements} Newton "
          f"refinements, {len(diagram.crossings)} crossings; "
          f"largest deviation from eigen_analysis {worst_campbell:.2e}")
    print(f"FRF: largest deviation from direct solves {worst_frf:.2e} of each output's "
          f"largest |H|; {frf.direct_points} grid values solved directly")
    print("all times: " + ", ".join(f"{k} " + "/".join(f"{t:.3f}" for t in ts)
                                    for k, ts in times.items()))
    if args.json:
        with open(args.json, "w", encoding="utf-8") as handle:
            json.dump(numbers, handle, indent=1)


if __name__ == "__main__":
    with threadpool_limits(1):
        main()
