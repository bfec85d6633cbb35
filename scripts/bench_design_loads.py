"""Benchmark of the design loads: the closed form over every fault instant against
single responses, a nonlinear scenario against ``scipy.signal.lsim``, and the parallel efficiency
of a nonlinear envelope on the default local cluster.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/bench_design_loads.py [--t-end 2] [--fs 10000]
        [--scenarios 1000] [--scenario-t-end 2] [--workers N] [--parts 1,2,3,4]

In one run, calibrated set, all 20 outputs, 2 s at 10 kHz unless said otherwise:

1. **every fault instant** (``--phase all``): the envelope's chunk of one operating point (three
   closed-form evaluations, :func:`model.studies.envelope.phase_families`, then
   :func:`~model.studies.envelope.worst_fault_instant`) against one ``short_circuit_response`` at the
   same point (all its post-processing: peaks, spectra, limits).  Cold (the point's
   eigendecomposition not cached: what a grid over (s0, v) pays per point) and warm (cached).
   Six points: s0 = 0.005, 0.014 × v = 80, 120, 200 km/h; best of 3 per point, interleaved, summed.
   Target: ≤ 3 single responses per (s0, v).  Also the 360-phase grid by the same family (the
   brute-force equivalent is 360 single responses).
2. **a nonlinear scenario** (the envelope's chunk with ``--creep nonlinear``: one
   ``nonlinear_response`` and its peaks) at s0 = 0.014, 120 km/h, cold and warm, against
   ``scipy.signal.lsim`` of the *linear* system on the same grid (the reference of the
   target ≤ 1×, as in ``bench_nonlinear.py``); best of 3, lsim in between.
3. **parallel efficiency**: a nonlinear envelope of ``--scenarios`` scenarios (s0 = 0.005, 0.014
   × speeds × continuity roots × a phase grid, horizon ``--scenario-t-end``) serially in this
   process and on the default local cluster (one single-thread worker process per core, started
   before the clock runs); efficiency = serial / (workers × cluster) (target ≥ 80 %), results
   checked identical.
4. **the dashboard's design loads** (``--parts 4``; ``app.results.compute``, 2 s at 10 kHz, the
   operating point's eigendecomposition warm, as after the dashboard's first answer): the fast
   stage's short-circuit response with the 10 plotted outputs (before the Design loads tab) and
   with the 14 of the peak table and CSV (the plotted ones and the drive parts), each with its
   11 decimated plot series (``compute.history_view``); the Design loads tab's worst case
   over every fault instant (three closed-form evaluations of the 8 drive parts, the closed form
   over Δt, decimated bands) and its load spectra (rainflow, collective, matrix of the 8 drive
   parts), each against the fast stage's response; s0 = 0.005 and 0.014 at 120 km/h, median
   of 15, interleaved.

Times are wall clock.  The machine may be shared: the load average is printed before and after.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from functools import partial

import numpy as np
import scipy
import scipy.signal
from bench_timing import load, timed  # the scripts' own helpers

from model import KMH, load_parameters
from model.analysis.eigen import bogie_system, forget_systems
from model.analysis.response import short_circuit_response
from model.mechanics.operating_point import OperatingPoint
from model.mechanics.outputs import output_matrices
from model.studies.engine import StudyEngine, serial_map_unordered
from model.studies.envelope import EnvelopeStudy, resolve_outputs
from model.studies.maps import cached_model
from model.studies.store import MemoryWriter


def study_for(parameters, model, s0, v_kmh, **changes) -> EnvelopeStudy:
    op = OperatingPoint.from_kmh(s0[0], v_kmh[0], parameters["wheel_force"],
                                 parameters["motor_slope"])
    creep = changes.get("creep", "linear")
    outputs, units = resolve_outputs(model, op, None, creep)
    return EnvelopeStudy(s0=tuple(s0), v=tuple(x * KMH for x in v_kmh),
                         N0=(parameters["wheel_force"],), b_M=(parameters["motor_slope"],),
                         outputs=outputs, units=units, **changes)


def every_fault_instant(parameters, model, t_end, fs, repeats=3) -> None:
    points = [(s0, v) for s0 in (0.005, 0.014) for v in (80.0, 120.0, 200.0)]
    rows = {"single response": [], "--phase all (3 responses + closed form)": [],
            "continuity roots (the default)": [], "360-phase grid by the family": []}
    warm = {"single response": [], "--phase all (3 responses + closed form)": []}
    for s0, v in points:
        op = OperatingPoint.from_kmh(s0, v, parameters["wheel_force"], parameters["motor_slope"])
        studies = {
            "--phase all (3 responses + closed form)": study_for(
                parameters, model, [s0], [v], fault="all", t_end=t_end, fs=fs),
            "continuity roots (the default)": study_for(parameters, model, [s0], [v],
                                                        t_end=t_end, fs=fs),
            "360-phase grid by the family": study_for(
                parameters, model, [s0], [v], fault="grid", phase=tuple(np.arange(360) / 360 / 90),
                t_end=t_end, fs=fs)}
        best = {name: np.inf for name in rows}
        best_warm = {name: np.inf for name in warm}
        for _ in range(repeats):
            forget_systems(model)
            seconds, _ = timed(lambda op=op: short_circuit_response(model, op, None, t_end, fs))
            best["single response"] = min(best["single response"], seconds)
            seconds, _ = timed(lambda op=op: short_circuit_response(model, op, None, t_end, fs))
            best_warm["single response"] = min(best_warm["single response"], seconds)
            for name, study in studies.items():
                forget_systems(model)
                seconds, _ = timed(lambda study=study: study.run_chunk(parameters, (0,) * 5))
                best[name] = min(best[name], seconds)
                if name in warm:
                    seconds, _ = timed(lambda study=study: study.run_chunk(parameters, (0,) * 5))
                    best_warm[name] = min(best_warm[name], seconds)
        for name in rows:
            rows[name].append(best[name])
        for name in warm:
            warm[name].append(best_warm[name])
    single, single_warm = sum(rows["single response"]), sum(warm["single response"])
    print(f"\n## 1. Every fault instant against one response per (s0, v) ({len(points)} points, "
          f"{t_end:g} s at {fs:g} Hz, 20 outputs; best of {repeats}, summed)\n")
    print("| per operating point | cold [ms] | / single response | warm [ms] | / single response |")
    print("|---|---:|---:|---:|---:|")
    for name, times in rows.items():
        total = sum(times)
        warm_text = (f"{1e3 * sum(warm[name]) / len(points):.1f} | "
                     f"**{sum(warm[name]) / single_warm:.2f}**" if name in warm else "– | –")
        print(f"| {name} | {1e3 * total / len(points):.1f} | **{total / single:.2f}** | "
              f"{warm_text} |")
    print(f"\n360 single responses (the brute-force 360-phase grid) would cost "
          f"{360 * single / len(points):.1f} s cold per point ({360 * single_warm / len(points):.1f} s "
          "warm).")


def nonlinear_scenario(parameters, model, t_end, fs, repeats=3) -> None:
    s0, v = 0.014, 120.0
    op = OperatingPoint.from_kmh(s0, v, parameters["wheel_force"], parameters["motor_slope"])
    study = study_for(parameters, model, [s0], [v], creep="nonlinear", t_end=t_end, fs=fs)
    key = (0,) * 10
    system = bogie_system(model, op)
    outputs = output_matrices(model, op)
    C = system.state_output(outputs.C_q, outputs.C_v)  # on the state [q; q̇ of the inertial coordinates]
    response = short_circuit_response(model, op, None, t_end, fs)
    cold, warm, lsim = np.inf, np.inf, np.inf
    for _ in range(repeats):
        forget_systems(model)
        cold = min(cold, timed(lambda: study.run_chunk(parameters, key))[0])
        warm = min(warm, timed(lambda: study.run_chunk(parameters, key))[0])
        lsim = min(lsim, timed(lambda: scipy.signal.lsim(
            (system.A, system.b[:, None], C, np.zeros((C.shape[0], 1))), response.M_C,
            response.t))[0])
    print(f"\n## 2. A nonlinear scenario against scipy.signal.lsim (s0 = {s0}, {v:g} km/h, "
          f"{t_end:g} s at {fs:g} Hz; best of {repeats})\n")
    print("| | time [ms] | / lsim |")
    print("|---|---:|---:|")
    for name, seconds in (("nonlinear scenario, cold (eigendecomposition + set-up + run + peaks)",
                           cold),
                          ("nonlinear scenario, warm (decomposition and set-up cached)", warm),
                          ("scipy.signal.lsim of the linear system", lsim)):
        print(f"| {name} | {1e3 * seconds:.0f} | **{seconds / lsim:.2f}** |")


def parallel_efficiency(parameters, model, scenarios, t_end, fs, workers) -> None:
    speeds = max(1, scenarios // (2 * 10))  # 2 creepages × speeds × 10 fault instants
    phases_per_point = max(1, scenarios // (2 * speeds))
    v_kmh = list(np.linspace(60.0, 240.0, speeds)) if speeds > 1 else [120.0]
    grid = tuple(np.arange(phases_per_point) / phases_per_point / 90.0)
    study = study_for(parameters, model, [0.005, 0.014], v_kmh, creep="nonlinear",
                      fault="grid", phase=grid, t_end=t_end, fs=fs)
    keys = study.chunks()
    print(f"\n## 3. Parallel efficiency: a nonlinear envelope of {study.scenarios} scenarios "
          f"(s0 = 0.005, 0.014 × {len(v_kmh)} speeds × {len(grid)} fault instants; "
          f"{t_end:g} s at {fs:g} Hz each)\n")
    print(f"load average before: {load()}", flush=True)
    forget_systems(model)
    cpu = time.process_time()
    t_serial, serial = timed(lambda: _collect(study, keys, serial_map_unordered(
        partial(_timed_chunk, study, parameters), keys)))
    cpu_serial = time.process_time() - cpu
    print(f"serial in this process: {t_serial:.1f} s wall, {cpu_serial:.1f} s CPU "
          f"({1e3 * t_serial / study.scenarios:.0f} ms per scenario); load average {load()}",
          flush=True)
    with StudyEngine(None, workers) as engine:
        engine.map(_warm_up, [parameters] * (4 * engine.workers))  # imports, model per worker
        t_cluster, parallel = timed(lambda: _collect(study, keys, engine.map_unordered(
            partial(_timed_chunk, study, parameters), keys)))
        used = engine.workers
    identical = all(np.array_equal(serial[0][name], parallel[0][name], equal_nan=True)
                    for name in serial[0])
    efficiency = t_serial / (used * t_cluster)
    print(f"local cluster of {used} workers: {t_cluster:.1f} s wall; efficiency "
          f"**{efficiency:.0%}** (target >= 80 %); results identical to serial: {identical}")
    print(f"the tasks' own CPU time (thread time inside each task): serial {serial[1]:.1f} s, "
          f"in the workers {parallel[1]:.1f} s (ratio {serial[1] / parallel[1]:.2f}: what the "
          f"efficiency would be on idle cores, scheduling aside); "
          f"busy share of the workers' wall time {parallel[1] / (used * t_cluster):.0%}")
    print(f"load average after: {load()}")


def _timed_chunk(study, parameters, key):
    """(thread CPU time [s], chunk result) of one chunk."""
    start = time.thread_time()
    result = study.run_chunk(parameters, key)
    return time.thread_time() - start, result


def _collect(study, keys, finished) -> tuple[dict, float]:
    """(arrays as run_in_memory gives them, summed CPU time of the tasks [s])."""
    writer = MemoryWriter(study)
    cpu = 0.0
    for index, (seconds, result) in finished:
        writer.write(keys[index], result)
        cpu += seconds
    return writer.arrays, cpu


def dashboard_design_loads(repeats: int = 15) -> None:
    """Part 4 (module docstring)."""
    from app.results import compute
    from app.results.case import Case

    print("\n4. the dashboard's design loads (ms, median of "
          f"{repeats}; ratio to the fast stage's response with 14 outputs)")
    for s0 in (0.005, 0.014):
        case = Case(s0=s0, v=120.0, N0=100.0, b_M=3000.0)
        excitation = case.short_circuit()
        model = compute.model_for(case)
        op = case.operating_point()
        compute.point_result(case)  # the eigendecomposition, as after the first answer

        # the fast stage's response before: 10 outputs, 11 series decimated
        def before(model=model, op=op, excitation=excitation):
            r = short_circuit_response(model, op, excitation, t_end=2.0, fs=10_000.0,
                                       outputs=list(compute.RESPONSE_OUTPUTS))
            return [compute.decimate(r.t, [y]) for y in [*r.outputs.values(), r.M_C]]

        # 14 outputs (the peak table's and the CSV's), the same 11 series decimated
        def now(model=model, op=op, excitation=excitation):
            r = short_circuit_response(model, op, excitation, t_end=2.0, fs=10_000.0,
                                       outputs=list(compute.HISTORY_OUTPUTS))
            return compute.history_view(r, compute.LINEAR_HISTORY, True,
                                        compute.RESPONSE_OUTPUTS)

        def cold(kind: str, function):
            """``function()`` with its kind of result dropped from the results cache first."""
            def run():
                compute.RESULTS.drop(kind)
                return function()
            return run

        cases = {
            "response, 10 outputs + plot series (before)": before,
            "response, 14 outputs + plot series (now)": now,
            "worst case over every fault instant (8 parts)":
                cold("worst case", lambda case=case: compute.worst_case_result(case)),
            "load spectra of the linear history (8 parts)":
                cold("spectra", lambda case=case: compute.spectra_result(case, None)),
        }
        compute.response_result(case)  # the spectra's history
        times = {name: [] for name in cases}
        for _ in range(repeats):
            for name, function in cases.items():
                times[name].append(timed(function)[0])
        reference = float(np.median(times["response, 14 outputs + plot series (now)"]))
        print(f"  s0 = {s0}, 120 km/h (load {load()})")
        for name, values in times.items():
            median = float(np.median(values))
            print(f"    {name:<52} {median * 1e3:7.1f} ms  {median / reference:5.2f}x")


def _warm_up(parameters) -> int:
    """Import the model and build it once in a worker (not timed)."""
    return cached_model(parameters).n


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=2.0)
    parser.add_argument("--fs", type=float, default=10_000.0)
    parser.add_argument("--scenarios", type=int, default=1000,
                        help="scenarios of the parallel-efficiency envelope (default 1000)")
    parser.add_argument("--scenario-t-end", type=float, default=2.0,
                        help="horizon of each scenario of part 3 [s] (default 2)")
    parser.add_argument("--workers", type=int, default=None,
                        help="workers of the local cluster (default: one per core)")
    parser.add_argument("--parts", default="1,2,3",
                        help="which parts to run (default 1,2,3; 4: the dashboard's)")
    args = parser.parse_args()
    parts = {int(x) for x in args.parts.split(",")}
    parameters = load_parameters()
    model = cached_model(parameters)
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, load "
          f"average {load()}; numpy {np.__version__}, scipy {scipy.__version__}; "
          f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}")
    if 1 in parts:
        every_fault_instant(parameters, model, args.t_end, args.fs)
    if 2 in parts:
        nonlinear_scenario(parameters, model, args.t_end, args.fs)
    if 3 in parts:
        parallel_efficiency(parameters, model, args.scenarios, args.scenario_t_end, args.fs,
                            args.workers)
    if 4 in parts:
        dashboard_design_loads()
    print(f"\nload average at the end: {load()}")


if __name__ == "__main__":
    main()
