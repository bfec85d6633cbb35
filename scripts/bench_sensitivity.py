"""Benchmark of the sensitivities and of the uncertainty study's cost.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/bench_sensitivity.py [--repeats 3]
        [--uncertainty assets/data/uncertainty_n16.json] [--timed-runs 6] [--json FILE]

In one run, on the calibrated set at s0 = 0.005, 120 km/h:

* reference: one eigen-analysis with vectors at a fresh operating point (cold decomposition);
* sensitivities: every parameter and s0, v, N0, b_M for the ten lowest modes
  (:func:`model.analysis.sensitivity.eigen_sensitivities`, the decomposition cached, ``describe=False``)
  plus ds0*/dp at a known s0* (:func:`model.analysis.sensitivity.limit_sensitivity`, its eigenvalues-only
  analysis at s0* included); the ratio (reference + sensitivities)/reference is the
  "≤ 2×" target; the modes' energy shares and descriptions are timed separately;
* cold: the derivative matrices of the parameter set (complex step, once per set);
* peak loads: central differences of the response for three parameters (cost per parameter);
* Sobol: the widths of the 95 % bootstrap intervals of each output's leading total index in a
  stored study (``bogie uncertainty --samples 16 --out assets/data/uncertainty_n16.json``), the
  cost of one model run timed here, and the n projected for width 0.05 on every output
  (width ∝ n^(−1/2)) with its serial cost and on N workers (the runs are independent);
* s0*: where it equals the creep maximum for every sample, its Sobol indices from the creep law
  alone (:func:`model.studies.uncertainty.creep_maximum_study`) at ``--creep-n`` (4096).

Times are the median of ``--repeats`` repeats, wall clock; the machine may be shared (ratios are
from the same run).
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import time
from pathlib import Path

import numpy as np

from model import build_model, load_parameters
from model.analysis.eigen import eigen_analysis, forget_systems
from model.analysis.peak_sensitivity import peak_load_sensitivities
from model.analysis.sensitivity import (
    eigen_sensitivities,
    limit_sensitivity,
    structural_derivatives,
)
from model.analysis.stability import stability_limit
from model.mechanics.operating_point import KMH, OperatingPoint
from model.studies.uncertainty import UNCERTAIN_PARAMETERS, creep_maximum_study, evaluate_chunk


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--uncertainty", default="assets/data/uncertainty_n16.json",
                        help="a stored `bogie uncertainty --out` result (interval widths)")
    parser.add_argument("--timed-runs", type=int, default=6, help="model runs timed here")
    parser.add_argument("--creep-n", type=int, default=4096,
                        help="base sample count of the creep-maximum Sobol study")
    parser.add_argument("--json", default=None)
    args = parser.parse_args()
    parameters = load_parameters()
    model = build_model(parameters)
    N0, b_M, v = parameters["wheel_force"], parameters["motor_slope"], 120 * KMH
    report: dict = {}

    start = time.perf_counter()
    derivatives = structural_derivatives(model)
    report["derivative_matrices_s"] = time.perf_counter() - start
    report["derivative_parameters"] = len(derivatives)
    print(f"derivative matrices (cold, once per set): {report['derivative_matrices_s']:.2f} s "
          f"for {len(derivatives)} parameters")
    s0_limit = stability_limit(model, v, N0, b_M).s0_limit

    eig_times, sens_times, limit_times, describe_times = [], [], [], []
    for k in range(args.repeats):
        op = OperatingPoint(0.005 * (1 + 1e-6 * k), v, N0, b_M)  # a fresh point each repeat
        forget_systems(model)
        start = time.perf_counter()
        eigen_analysis(model, op)
        eig_times.append(time.perf_counter() - start)
        start = time.perf_counter()
        eigen_sensitivities(model, op, linked=("wheel_force", "motor_slope"), describe=False)
        sens_times.append(time.perf_counter() - start)
        start = time.perf_counter()
        eigen_sensitivities(model, op, linked=("wheel_force", "motor_slope"))
        describe_times.append(time.perf_counter() - start - sens_times[-1])
        start = time.perf_counter()
        limit_sensitivity(model, v, N0, b_M, linked=("wheel_force", "motor_slope"), s0_limit=s0_limit)
        limit_times.append(time.perf_counter() - start)
    t_eig, t_sens, t_limit, t_describe = (statistics.median(x) for x in (
        eig_times, sens_times, limit_times, describe_times))
    ratio = (t_eig + t_sens + t_limit) / t_eig
    report.update(eigen_s=t_eig, sensitivities_s=t_sens, limit_s=t_limit, ratio=ratio,
                  descriptions_s=t_describe, ratio_without_limit=(t_eig + t_sens) / t_eig)
    print(f"one eigen-analysis with vectors: {1e3 * t_eig:.0f} ms; sensitivities of 10 modes to "
          f"{len(parameters.values) + 4} parameters: +{1e3 * t_sens:.0f} ms; ds0*/dp at known s0*: "
          f"+{1e3 * t_limit:.0f} ms; all together {ratio:.2f}x one eigen-analysis "
          f"({(t_eig + t_sens) / t_eig:.2f}x without s0*); the modes' energy shares and "
          f"descriptions (optional, the dashboard has them): +{1e3 * t_describe:.0f} ms")

    op = OperatingPoint(0.005, v, N0, b_M)
    peaks = peak_load_sensitivities(parameters, op, names=["disc_clutch_torsional_stiffness",
                                                           "gear_ratio", "motor_slope"])
    report["peak_per_parameter_s"] = peaks.seconds / 3
    print(f"peak-load sensitivities: {peaks.seconds / 3:.2f} s per parameter "
          f"(x{len(parameters.values)} parameters = {peaks.seconds / 3 * len(parameters.values):.0f} s)")

    # Sobol: interval widths from a stored study, the cost of one model run timed here
    data = json.loads(Path(args.uncertainty).read_text(encoding="utf-8"))
    n, d = data["base_samples"], len(data["parameters"])
    lead_width = []
    for output in data["outputs"]:
        total = np.array(output["total_order"], dtype=float)
        low, high = (np.array(x, dtype=float) for x in output["total_order_ci"])
        k = int(np.nanargmax(total))
        lead_width.append(high[k] - low[k])
    lead_width = np.array(lead_width)
    worst, median = float(np.nanmax(lead_width)), float(np.nanmedian(lead_width))
    base = dict(parameters.values)
    names = [item.name for item in UNCERTAIN_PARAMETERS]
    rng = np.random.default_rng(1)
    rows = np.array([[item.low + (item.high - item.low) * rng.random() for item in UNCERTAIN_PARAMETERS]
                     for _ in range(args.timed_runs)])
    start = time.perf_counter()
    evaluate_chunk(rows, base, names)
    per_run = (time.perf_counter() - start) / args.timed_runs
    # projected from the median output's leading interval (the widest belongs to an output whose
    # variance is nearly zero at n = 16, see docs/sensitivity.md)
    needed = 2 ** math.ceil(math.log2(n * (median / 0.05) ** 2)) if median > 0.05 else n
    cost = needed * (d + 2) * per_run
    report.update(sobol_n=n, per_run_s=per_run, widest_leading_ci=worst,
                  median_leading_ci=median, n_needed=needed, cost_serial_s=cost)
    print(f"Sobol ({args.uncertainty}: n = {n}, {n * (d + 2)} runs): widest 95 % interval of a "
          f"leading total index {worst:.2f} (median {median:.2f}); one model run {per_run:.2f} s "
          f"(mean of {args.timed_runs})")
    print(f"projected for width <= 0.05 on the median output (width ∝ n^-1/2): n = {needed}, "
          f"{needed * (d + 2)} runs, {cost / 3600:.1f} h serial, {cost / 3600 / 8:.2f} h on 8 "
          f"workers, {cost / 3600 / 32:.2f} h on 32")
    # s0* = s_max for every sample of the stored study: its indices from the creep law alone
    start = time.perf_counter()
    creep = creep_maximum_study(parameters, args.creep_n, n_resamples=499)
    seconds = time.perf_counter() - start
    _, _, outputs, _, total, _, total_ci = creep
    for j, v_kmh in enumerate((120, 200)):
        missing = int(np.count_nonzero(np.isnan(outputs[:, j])))
        if missing:
            print(f"s0*({v_kmh} km/h): {missing} of the {len(outputs)} samples A, B have no creep "
                  "maximum below s = 1 (a corner of the prior box): no indices from the creep law")
            report[f"creep_n{args.creep_n}_missing_{v_kmh}"] = missing
            continue
        k = int(np.nanargmax(total[j]))
        width = total_ci[1, j] - total_ci[0, j]
        leading = np.argsort(-np.nan_to_num(total[j]))[:3]
        print(f"s0*({v_kmh} km/h) = s_max from the creep law alone, n = {args.creep_n} "
              f"({creep[0]} evaluations, {seconds:.0f} s for both speeds): widest interval of the "
              f"three leading total indices {np.nanmax(width[leading]):.3f}; leading "
              + ", ".join(f"{UNCERTAIN_PARAMETERS[i].name} S_T {total[j, i]:.3f} "
                          f"[{total_ci[0, j, i]:.3f}, {total_ci[1, j, i]:.3f}]" for i in leading))
        report[f"creep_n{args.creep_n}_leading_width_{v_kmh}"] = float(width[k])
    if args.json:
        with open(args.json, "w", encoding="utf-8") as handle:
            json.dump(report, handle, indent=1)


if __name__ == "__main__":
    main()
