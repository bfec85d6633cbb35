"""Benchmark of the short-circuit response: closed form vs scipy.signal.lsim vs solve_ivp (Radau).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/bench_response.py [--t-end 2] [--fs 10000]

One run, one system (calibrated set, s0 = 0.005, 120 km/h; all 20 outputs), default excitation.
Accuracy of every method against an exact reference: the exported system (M, B, K, f_mc, C_q,
C_v) with the state augmented by the generator of M_C, stepped sample by sample with
Φ = expm(F/fs); the figure is max over outputs of max|y − y_ref| / max|y_ref|.

* closed form, cold: a fresh operating point (eigendecomposition included) + all the
  post-processing of :func:`short_circuit_response` (peaks, spectra, limit checks);
* closed form, warm: the same call with the per-operating-point decomposition cached (changing
  the excitation, the horizon or the sampling, as the dashboard does);
* closed form, solve only: the warm time history alone (:func:`model.analysis.response.solve_linear`);
* lsim: ``scipy.signal.lsim`` on the same state space and the sampled M_C (first-order hold);
* Radau: ``scipy.integrate.Radau`` (rtol 1e-8, the exact Jacobian) stepped as ``solve_ivp`` does,
  its dense output evaluated on the grid; stopped after ``--radau-budget`` seconds of CPU time
  (it takes hours for 2 s: steps of ≈ 1e-6 s), in which case its time and the speed-ups over it
  are lower bounds — the time for the whole horizon is at least the time for its first part.

Times are the best of several repeats (lsim and Radau: one run), wall clock (Radau: CPU time of
its one thread), on this machine.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time

import numpy as np
import scipy
import scipy.linalg as sla
import scipy.signal
from scipy.integrate import Radau

from model import build_model, default_operating_point, load_parameters
from model.analysis.eigen import bogie_system, forget_systems
from model.analysis.response import ShortCircuit, short_circuit_response, solve_linear
from model.mechanics.outputs import output_matrices


def exact_reference(A, b, C, u0, M0, w, sigma, shift, steps, dt):
    n2 = A.shape[0]
    F = np.zeros((n2 + 3, n2 + 3))
    F[:n2, :n2] = A
    F[:n2, n2] = u0 * b
    F[:n2, n2 + 1] = -M0 * b
    F[n2 + 1:, n2 + 1:] = [[-sigma, w], [-w, -sigma]]
    z = np.zeros(n2 + 3)
    z[n2:] = [1.0, np.sin(-w * shift), np.cos(-w * shift)]
    Phi = sla.expm(F * dt)
    Z = np.empty((steps, n2 + 3))
    for k in range(steps):
        Z[k] = z
        z = Phi @ z
    return Z[:, :n2] @ C.T


def error(y, reference) -> float:
    return float(np.max(np.abs(y - reference).max(axis=0) / np.abs(reference).max(axis=0)))


def run_radau(fun, jac, size, t_eval, rtol, atol, budget):
    """``solve_ivp(method="Radau")``'s loop, stopped after ``budget`` seconds of CPU time:
    (CPU seconds, states at the grid points reached (k x size), time reached [s])."""
    solver = Radau(fun, 0.0, np.zeros(size), t_eval[-1], rtol=rtol, atol=atol, jac=jac)
    states, i = [], 0
    start = time.process_time()
    while solver.status == "running" and time.process_time() - start < budget:
        solver.step()
        if solver.status == "failed":
            raise RuntimeError(f"Radau failed: {solver.message}")
        j = np.searchsorted(t_eval, solver.t, side="right")
        if j > i:
            states.append(solver.dense_output()(t_eval[i:j]).T)
            i = j
    seconds = time.process_time() - start
    return seconds, np.vstack(states) if states else np.zeros((0, size)), solver.t


def best_of(function, repeats):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        value = function()
        times.append(time.perf_counter() - start)
    return min(times), value


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=2.0)
    parser.add_argument("--fs", type=float, default=10_000.0)
    parser.add_argument("--skip-radau", action="store_true")
    parser.add_argument("--radau-t-end", type=float, default=None,
                        help="horizon of the Radau run [s] (default: --t-end); a shorter one is "
                             "reported as such, its error against the reference's first part")
    parser.add_argument("--radau-budget", type=float, default=600.0,
                        help="CPU seconds after which Radau is stopped (its speed-ups then "
                             "become lower bounds)")
    args = parser.parse_args()
    parameters = load_parameters()
    model = build_model(parameters)
    op = default_operating_point(parameters, 0.005, 120.0)
    excitation = ShortCircuit()
    steps = round(args.t_end * args.fs) + 1
    dt = 1.0 / args.fs
    t = np.arange(steps) * dt

    def cold():
        forget_systems(model)
        return short_circuit_response(model, op, excitation, args.t_end, args.fs)

    t_cold, result = best_of(cold, 3)
    t_warm, result = best_of(
        lambda: short_circuit_response(model, op, excitation, args.t_end, args.fs), 5)
    system = bogie_system(model, op)
    outputs = output_matrices(model, op)
    C = system.state_output(outputs.C_q, outputs.C_v)  # on the state [q; q̇ of the inertial coordinates]
    u0, a, mu = excitation.terms(result.motor_torque)
    t_solve, (y_solve, method, estimate) = best_of(
        lambda: solve_linear(system, C, u0, a, mu, steps, dt), 5)
    y_ours = np.column_stack([result.perturbation(name) for name in outputs.names])

    A, b = system.A, system.b
    start = time.perf_counter()
    reference = exact_reference(A, b, C, u0, excitation.M0, excitation.omega,
                                excitation.D * excitation.omega, result.phase_shift, steps, dt)
    t_reference = time.perf_counter() - start

    u = result.M_C
    start = time.perf_counter()
    _, y_lsim, _ = scipy.signal.lsim((A, b[:, None], C, np.zeros((C.shape[0], 1))), u, t)
    t_lsim = time.perf_counter() - start

    rows = {
        "closed form, cold (eig + all post-processing)": (t_cold, error(y_ours, reference)),
        "closed form, warm (cached decomposition, all post-processing)":
            (t_warm, error(y_ours, reference)),
        "closed form, solve only (warm)": (t_solve, error(y_solve, reference)),
        "scipy.signal.lsim": (t_lsim, error(y_lsim, reference)),
    }
    radau_note = ""
    if not args.skip_radau:
        t_radau_end = args.t_end if args.radau_t_end is None else min(args.radau_t_end, args.t_end)
        k = round(t_radau_end * args.fs) + 1
        x_scale = np.abs(np.linalg.lstsq(A, -b * u0, rcond=None)[0]).max()
        t_radau, y_radau, reached = run_radau(
            lambda tt, x: A @ x + b * (u0 + (a * np.exp(mu * tt)).real), A, len(b), t[:k],
            1e-8, 1e-8 * 1e-3 * x_scale, args.radau_budget)
        done = len(y_radau)
        name = "scipy.integrate Radau rtol 1e-8"
        if done < k:  # stopped by the budget: its time for the whole horizon is longer
            name += f" (budget {args.radau_budget:g} s: reached t = {reached:.4f} s)"
            radau_note = (f"Radau stopped by its budget of {args.radau_budget:g} s CPU at "
                          f"t = {reached:.4f} s of {t[k - 1]:g} s; its time for the whole "
                          "horizon is longer, so its speed-ups are lower bounds (≥).")
        elif k < steps:
            name += f" (0…{t_radau_end:g} s only)"
        rows[name] = (t_radau, error(y_radau @ C.T, reference[:done]) if done else np.nan)
    system = bogie_system(model, op)
    print(f"system: {model.n} coordinates, {system.N} states ({len(system.eigen[0])} deflated), "
          f"{len(outputs.names)} outputs, "
          f"{steps} points ({args.t_end:g} s at {args.fs:g} Hz); method {method}, "
          f"rounding-error indicator {estimate:.1e} (not a bound); reference (exact stepping) took {t_reference:.2f} s")
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"load average {os.getloadavg()[0]:.2f}; numpy {np.__version__}, scipy "
          f"{scipy.__version__}; OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}")
    print()
    print("| method | time [ms] | speed-up vs lsim | speed-up vs Radau | max error / peak |")
    print("|---|---:|---:|---:|---:|")
    radau = next((v[0] for name, v in rows.items() if "Radau" in name), np.nan)
    bound = "≥ " if radau_note else ""
    for name, (seconds, err) in rows.items():
        print(f"| {name} | {1e3 * seconds:.1f} | {t_lsim / seconds:.1f} | "
              f"{bound if 'Radau' not in name else ''}{radau / seconds:.1f} | {err:.1e} |")
    print()
    if radau_note:
        print(radau_note)
        print()
    print(json.dumps({name: {"seconds": s, "error": e} for name, (s, e) in rows.items()}))


if __name__ == "__main__":
    main()
