"""Benchmark: the stability map (s0 × v) serial against the Dask cluster, the cost of a map point
against one eigen-analysis, the scheduler's overhead per task, and a projection to a cluster.

    .venv/bin/python scripts/bench_study.py [--s0-points 100] [--v-points 100] [--workers N]
                                            [--scheduler tcp://HOST:PORT] [--check-lines 5]
                                            [--method reduced|continuation]

Default map: s0 = 0.001…0.02 (100 points) × v = 40…250 km/h (100 speeds), calibrated set,
N0 and b_M of the set.  In the same run:

1. one eigen-analysis (``eigen_analysis``, eigenvalues only and with vectors; best of 5), the
   reference of the cost per map point (issue target: a map point ≤ 1/5 of it);
2. the map serially in this process (one BLAS thread): wall time, cost per point, also against
   the reference interleaved with the map (one eigenvalues-only analysis after each line, wall
   and CPU time: on a shared machine the least disturbed ratio);
3. the same map on the default local cluster (as many single-thread worker processes as cores;
   or ``--scheduler``): wall time without the cluster's start (reported apart), parallel
   efficiency = serial time / (workers × cluster time) (target ≥ 80 %); results checked
   identical to the serial ones;
4. the scheduler's overhead per task: ``--tasks`` no-op tasks through the same engine;
5. one stability-limit search s0*(v) (``stability_limit``; the unit of a Monte-Carlo sample);
6. accuracy: ``--check-lines`` s0-lines (evenly spread speeds) against a full eigen-analysis at
   every point (largest real part, counts, verdicts; for the continuation also every
   eigenvalue, and the fallbacks), each line timed against the dense line in the same run;
7. a projection to W workers: T(W) = chunks × (t_chunk + overhead) / W for the map and for a
   2¹⁰-sample Sobol study of 12 parameters (Saltelli: 2¹⁰ × (12 + 2) limit searches).

On a machine shared with other jobs the times and the efficiency are disturbed: the script
prints the load average before and after; re-run it on an idle machine for figures to compare.
"""

from __future__ import annotations

import argparse
import os
import platform
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.optimize import linear_sum_assignment
from threadpoolctl import threadpool_limits

from model import KMH, build_model, eigen_analysis, load_parameters, stability_limit
from model.analysis.continuation import continue_line
from model.analysis.eigen import forget_systems
from model.mechanics.operating_point import OperatingPoint
from model.studies.engine import StudyEngine, serial_map_unordered
from model.studies.maps import MapStudy
from model.studies.s0_line import dense_line, s0_line
from model.studies.store import open_study, run_into_store


def _noop(x):
    return x


def best_of(repeat: int, function, before=None) -> float:
    times = []
    for _ in range(repeat):
        if before is not None:
            before()
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def report_accuracy(args, serial, worst, worst_eig, counts_equal, fallbacks, t_line,
                    t_dense) -> None:
    """Print the checked lines' accuracy against the dense reference and their timing."""
    print(f"accuracy on {args.check_lines} lines x {args.s0_points} points against a full "
          f"eigen-analysis: max |d largest real part| {worst:.2e} 1/s, flutter/divergent counts "
          f"identical: {counts_equal}")
    if args.method == "continuation":
        print(f"  every eigenvalue within {worst_eig:.2e} relative (to max(|lambda|, 1 1/s)); "
              f"fallbacks (points solved densely after failed checks, s0* included): "
              f"{fallbacks} on {args.check_lines * args.s0_points} points")
    else:
        print(f"  outside-basis eigenvalues at the densely solved creepages <= "
              f"{float(serial['outside_max_real_part'].max()):.3f} 1/s")
    print(f"  the same lines timed in this run: s0_line {t_line:.2f} s, dense_line {t_dense:.2f} s "
          f"-> a line costs {t_line / t_dense:.3f} of the dense line (both with s0*)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--s0-points", type=int, default=100)
    parser.add_argument("--v-points", type=int, default=100)
    parser.add_argument("--workers", type=int, default=None, help="local cluster (default: cores)")
    parser.add_argument("--scheduler", default=None, help="measure on a running cluster instead")
    parser.add_argument("--tasks", type=int, default=400, help="no-op tasks for the overhead")
    parser.add_argument("--check-lines", type=int, default=5)
    parser.add_argument("--sobol-samples", type=int, default=2**10)
    parser.add_argument("--sobol-parameters", type=int, default=12)
    parser.add_argument("--method", default="reduced", choices=["reduced", "continuation"],
                        help="s0_line's method for the map (default: the map's, reduced)")
    args = parser.parse_args()
    print(f"python {platform.python_version()}, numpy {np.__version__}, {os.cpu_count()} cores, "
          f"load average {os.getloadavg()[0]:.2f} (1 min) at start")

    parameters = load_parameters()
    model = build_model(parameters)
    N0, b_M = parameters["wheel_force"], parameters["motor_slope"]
    study = MapStudy(np.linspace(0.001, 0.02, args.s0_points),
                     np.linspace(40.0, 250.0, args.v_points) * KMH, [N0], [b_M],
                     method=args.method)
    points = args.s0_points * args.v_points

    with threadpool_limits(1):
        op = OperatingPoint(0.005, 120 * KMH, N0, b_M)
        cold = lambda: forget_systems(model)  # noqa: E731
        t_values = best_of(5, lambda: eigen_analysis(model, op, vectors=False), cold)
        t_vectors = best_of(5, lambda: eigen_analysis(model, op), cold)
        t_limit = best_of(2, lambda: stability_limit(model, 120 * KMH, N0, b_M, xtol=1e-7), cold)
        # the reference interleaved with the map: one cold eigenvalues-only analysis after each
        # line (wall and CPU time), so that map and reference see the same load; excluded from
        # the map's time
        reference_wall, reference_cpu = [], []

        def serial_with_reference(function, items):
            for index, result in serial_map_unordered(function, items):
                cold()
                wall, cpu = time.perf_counter(), time.process_time()
                eigen_analysis(model, op, vectors=False)
                reference_cpu.append(time.process_time() - cpu)
                reference_wall.append(time.perf_counter() - wall)
                yield index, result

        with tempfile.TemporaryDirectory() as folder:
            start, start_cpu = time.perf_counter(), time.process_time()
            run_into_store(study, parameters, Path(folder) / "serial.zarr", serial_with_reference)
            t_serial = time.perf_counter() - start - sum(reference_wall)
            cpu_serial = time.process_time() - start_cpu - sum(reference_cpu)
            serial = open_study(Path(folder) / "serial.zarr")

    t_chunk = t_serial / len(study.chunks())
    per_point = t_serial / points
    print(f"\nmap {args.s0_points} (s0 0.001-0.02) x {args.v_points} (v 40-250 km/h) = {points} "
          f"points, {len(study.chunks())} chunks (s0-lines), method {args.method}")
    print(f"one eigen-analysis: eigenvalues only {t_values * 1e3:.1f} ms, with vectors "
          f"{t_vectors * 1e3:.1f} ms (best of 5, cold)")
    print(f"serial map: {t_serial:.2f} s, {t_chunk * 1e3:.0f} ms per s0-line, "
          f"{per_point * 1e3:.2f} ms per point = {per_point / t_values:.3f} of an eigen-analysis "
          f"(eigenvalues only), {per_point / t_vectors:.3f} (with vectors); target <= 0.2")
    print(f"  against the reference interleaved with the map (one eigenvalues-only analysis after "
          f"each line, median of {len(reference_wall)}: {np.median(reference_wall) * 1e3:.1f} ms "
          f"wall, {np.median(reference_cpu) * 1e3:.1f} ms CPU): a point costs "
          f"{per_point / np.median(reference_wall):.3f} (wall), "
          f"{cpu_serial / points / np.median(reference_cpu):.3f} (CPU time of this process, "
          f"the measure least disturbed by other processes)")

    start = time.perf_counter()
    engine = StudyEngine(args.scheduler, args.workers, connect_timeout=30)
    engine.start()
    t_start = time.perf_counter() - start
    try:
        workers = len(engine.client.scheduler_info(n_workers=-1)["workers"])
        # warm-up: every worker imports the model and assembles it once (as a real study does on
        # its first chunk); timed apart
        start = time.perf_counter()
        engine.map(_warm, [parameters] * (2 * workers))
        t_warm = time.perf_counter() - start
        with tempfile.TemporaryDirectory() as folder:
            start = time.perf_counter()
            run_into_store(study, parameters, Path(folder) / "cluster.zarr", engine.map_unordered)
            t_cluster = time.perf_counter() - start
            clustered = open_study(Path(folder) / "cluster.zarr")
        start = time.perf_counter()
        engine.map(_noop, range(args.tasks))
        t_tasks = time.perf_counter() - start
    finally:
        engine.close()
    identical = all(np.array_equal(serial[name].values, clustered[name].values, equal_nan=True)
                    for name in ("largest_real_part", "stable", "flutter_pairs", "divergent_real",
                                 "s0_limit"))
    overhead = t_tasks / args.tasks
    efficiency = t_serial / (workers * t_cluster)
    print(f"\n{engine.description}: {workers} workers; start {t_start:.1f} s, warm-up "
          f"(model assembly per worker) {t_warm:.1f} s")
    print(f"cluster map: {t_cluster:.2f} s -> speed-up {t_serial / t_cluster:.2f}x, parallel "
          f"efficiency {efficiency:.0%} (target >= 80 %); results identical to serial: {identical}")
    print(f"scheduler overhead: {args.tasks} no-op tasks in {t_tasks:.2f} s = "
          f"{overhead * 1e3:.2f} ms per task (round trip through the scheduler, {workers} workers)")
    print(f"one stability-limit search s0*(120 km/h): {t_limit:.2f} s (best of 2)")

    with threadpool_limits(1):
        v_check = np.linspace(40.0, 250.0, args.check_lines) * KMH
        worst, worst_eig, counts_equal, s0 = 0.0, 0.0, True, np.array(study.s0)
        fallbacks, t_line, t_dense = 0, 0.0, 0.0
        for v in v_check:
            start = time.perf_counter()
            line = s0_line(model, s0, v, N0, b_M, method=args.method)
            t_line += time.perf_counter() - start
            start = time.perf_counter()
            reference = dense_line(model, s0, v, N0, b_M)
            t_dense += time.perf_counter() - start
            fallbacks += line.fallbacks
            worst = max(worst, float(np.abs(line.largest_real_part
                                            - reference.largest_real_part).max()))
            counts_equal &= bool(np.array_equal(line.flutter_pairs, reference.flutter_pairs)
                                 and np.array_equal(line.divergent_real, reference.divergent_real))
            if args.method == "continuation":
                spectra = continue_line(model, s0, v, N0, b_M).spectra
                for s, spectrum in zip(s0, spectra, strict=True):
                    dense = eigen_analysis(model, OperatingPoint(float(s), v, N0, b_M),
                                           vectors=False).eigenvalues
                    cost = np.abs(spectrum[:, None] - dense[None, :])
                    rows, cols = linear_sum_assignment(cost)
                    worst_eig = max(worst_eig, float((cost[rows, cols] / np.maximum(
                        np.abs(dense[cols]), 1.0)).max()))
    if args.check_lines > 0:
        report_accuracy(args, serial, worst, worst_eig, counts_equal, fallbacks, t_line, t_dense)
    else:
        print("accuracy: not checked (--check-lines 0)")

    sobol = args.sobol_samples * (args.sobol_parameters + 2)
    print(f"\nprojection T(W) = tasks x (t_task + overhead) / W (t_task measured here, one core "
          f"each; the scheduler's {overhead * 1e3:.2f} ms per task counted as if serial):")
    print(f"{'workers W':>10} {'map (' + str(len(study.chunks())) + ' lines)':>22} "
          f"{'100x100 map':>14} {'Sobol 2^10 x (12+2) limits':>28}")
    for w in (2, 8, 32, 128, 512):
        t_map = len(study.chunks()) * (t_chunk / w + overhead)
        t_full = 100 * (t_chunk * 100 / args.s0_points / w + overhead)
        t_sobol = sobol * (t_limit / w + overhead)
        print(f"{w:>10} {t_map:>20.1f} s {t_full:>12.1f} s {t_sobol / 60:>26.1f} min")
    print(f"\nload average {os.getloadavg()[0]:.2f} (1 min) at the end")


def _warm(parameters):
    from model.studies.maps import cached_model

    cached_model(parameters)
    return os.getpid()


if __name__ == "__main__":
    main()
