"""Benchmark of the nonlinear response (docs/nonlinear.md): speed against scipy.signal.lsim on the linear
system and against Radau on the same nonlinear system; accuracy against Radau at tight tolerance
(short horizon) and by step halving (2 s).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/bench_nonlinear.py [--s0 0.014] [--v 120]
        [--t-end 2] [--fs 10000] [--radau-budget 300] [--reference-t-end 0.05]

One run, one system (calibrated set; default s0 = 0.014, 120 km/h, the unstable case), the default
excitation, anti-slip off (a plain ODE for Radau), all 20 outputs.

* nonlinear, cold: a fresh operating point (eigendecomposition, the stepping set-up) + the run +
  all post-processing of :func:`model.analysis.nonlinear.nonlinear_response`;
* nonlinear, warm: the same with the decomposition and the set-up cached (what a second run at
  the same point, e.g. another anti-slip delay, costs);
* first call in this process: the same as cold, plus the first imports of the step loop;
* lsim: ``scipy.signal.lsim`` on the *linear* system (eq. 20) with the sampled M_C, as in
  ``bench_response.py`` — the reference the target is stated against;
* Radau: ``scipy.integrate.Radau`` on the same nonlinear system written out independently here
  (``M q̈ + B_nl q̇ + K q = f M_C + G N0 [μ(s0 + H q̇/v) − μ(s0)]`` from the model's matrices,
  exact Jacobian), rtol 1e-8, stopped after ``--radau-budget`` CPU seconds: its time for 2 s and
  the speed-up over it are then lower bounds.

Accuracy: (1) Radau with rtol 1e-10, atol 1e-12 over ``--reference-t-end`` seconds (or as far
as ``--reference-budget`` CPU seconds take it), error of the 10 kHz run
max over outputs of max|y − y_ref| / max|Δy_ref| on that horizon; (2) step halving over 2 s:
runs with 1, 2 and 4 steps per sample, the error of each against the 4-step run and the observed
order.  Times are best of three (Radau: one run), wall clock; the machine was shared.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time

import numpy as np
import scipy
import scipy.signal
from bench_response import best_of, run_radau  # the same Radau loop and timing as there

from model import build_model, default_operating_point, load_parameters
from model.analysis.eigen import bogie_system, forget_systems
from model.analysis.linear_system import (
    first_order_matrix,
    inertial_inverse_mass,
    massless_coordinates,
)
from model.analysis.nonlinear import (
    creep_force_map,
    creep_velocity_map,
    damping_without_longitudinal_creep,
    nonlinear_response,
)
from model.analysis.response import ShortCircuit
from model.mechanics.operating_point import creep_law
from model.mechanics.outputs import output_matrices


def radau_system(model, op, excitation, step):
    """ẋ = F(t, x) and its Jacobian for the state x = [q; q̇ of the inertial coordinates] (the
    massless coordinates of the Maxwell elements are first order,
    :mod:`model.analysis.linear_system`), built from the model's matrices alone; returns (F, its
    Jacobian, the creep law, the velocity map V with q̇ = V x)."""
    n = model.n
    massless = massless_coordinates(model.M)
    inertial = np.setdiff1d(np.arange(n), massless)
    Minv = inertial_inverse_mass(model.M, inertial)
    B_nl = damping_without_longitudinal_creep(model, op)
    G, H = creep_force_map(model), creep_velocity_map(model)
    if np.any(G[massless]) or np.any(model.short_circuit_force[massless]):
        raise ValueError("an input acts on a massless coordinate")
    law = creep_law(model.parameters, op.N0)
    mu0 = float(law.mu(op.s0, op.v))
    A = first_order_matrix(Minv, B_nl, model.K, inertial, massless)
    V = A[:n]  # q̇ = V x (no input acts on a massless coordinate)
    b = np.concatenate([np.zeros(n), Minv @ model.short_circuit_force[inertial]])
    MG = Minv @ G[inertial]
    HV = H @ V  # contact velocities from the state
    u0, a, mu = excitation.terms(step)

    def fun(t, x):
        z = HV @ x
        force = op.N0 * (np.asarray(law.mu(op.s0 + z / op.v, op.v)) - mu0)
        dx = A @ x + b * (u0 + (a * np.exp(mu * t)).real)
        dx[n:] += MG @ force
        return dx

    def jac(t, x):
        z = HV @ x
        slope = op.N0 * np.asarray(law.dmu_ds(op.s0 + z / op.v, op.v)) / op.v
        J = A.copy()
        J[n:] += (MG * slope) @ HV
        return J

    return fun, jac, law, V


def outputs_from_states(model, op, X, law, names, V):
    """The result's outputs from states [q; q̇ of the inertial coordinates] (totals; q̇ = V x)."""
    n = model.n
    matrices = output_matrices(model, op)
    H = creep_velocity_map(model)
    velocities = X @ V.T
    forces = op.N0 * np.asarray(law.mu(op.s0 + (velocities @ H.T) / op.v, op.v))
    rims = list(model.rims)
    r0 = model.parameters["wheel_radius"]
    out = {}
    for name in names:
        if name.endswith("creep_force"):
            out[name] = forces[:, rims.index(name.rsplit(".", 1)[0])]
        elif name.endswith("adhesion_moment"):
            drive = name.split(".")[0]
            out[name] = r0 * sum(forces[:, rims.index(f"{drive}.rim{k}")] for k in (12, 14))
        else:
            i = matrices.index(name)
            out[name] = X[:, :n] @ matrices.C_q[i] + velocities @ matrices.C_v[i] \
                + matrices.steady[i]
    return out


def relative_error(result_outputs, reference, steady, rows=None) -> tuple[float, str]:
    worst, which = 0.0, ""
    for name, ref in reference.items():
        y = result_outputs[name] if rows is None else result_outputs[name][rows]
        peak = np.abs(ref - steady[name]).max()
        error = float(np.abs(y - ref).max() / peak) if peak > 0 else 0.0
        if error > worst:
            worst, which = error, name
    return worst, which


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--s0", type=float, default=0.014)
    parser.add_argument("--v", type=float, default=120.0, help="speed [km/h]")
    parser.add_argument("--t-end", type=float, default=2.0)
    parser.add_argument("--fs", type=float, default=10_000.0)
    parser.add_argument("--radau-budget", type=float, default=300.0,
                        help="CPU seconds after which the speed Radau run is stopped")
    parser.add_argument("--reference-t-end", type=float, default=0.05,
                        help="horizon of the tight-tolerance Radau reference [s]")
    parser.add_argument("--reference-budget", type=float, default=900.0,
                        help="CPU seconds for the tight reference (its horizon is reported)")
    parser.add_argument("--skip-radau", action="store_true")
    args = parser.parse_args()
    parameters = load_parameters()
    model = build_model(parameters)
    op = default_operating_point(parameters, args.s0, args.v)
    excitation = ShortCircuit()
    steps = round(args.t_end * args.fs) + 1
    t = np.arange(steps) / args.fs

    start = time.perf_counter()
    forget_systems(model)
    nonlinear_response(model, op, excitation, args.t_end, args.fs)
    t_first = time.perf_counter() - start

    def cold():
        forget_systems(model)
        return nonlinear_response(model, op, excitation, args.t_end, args.fs)

    t_cold, result = best_of(cold, 3)
    t_warm, result = best_of(
        lambda: nonlinear_response(model, op, excitation, args.t_end, args.fs), 3)

    system = bogie_system(model, op)
    outputs = output_matrices(model, op)
    C = system.state_output(outputs.C_q, outputs.C_v)  # on the state [q; q̇ of the inertial coordinates]
    start = time.perf_counter()
    scipy.signal.lsim((system.A, system.b[:, None], C, np.zeros((C.shape[0], 1))),
                      result.M_C, t)
    t_lsim = time.perf_counter() - start

    rows = {"nonlinear, cold (eig + set-up + run + post-processing)": t_cold,
            "nonlinear, warm (cached decomposition and set-up)": t_warm,
            "nonlinear, first call in the process": t_first,
            "scipy.signal.lsim (linear system)": t_lsim}
    report = {"times": rows}
    print(f"timed: {json.dumps(rows)}", file=sys.stderr, flush=True)

    # accuracy 2: step halving over the whole horizon
    runs = {k: nonlinear_response(model, op, excitation, args.t_end, args.fs, substeps=k)
            for k in (1, 2, 4)}
    halving = {k: relative_error(runs[k].outputs, {n: runs[4].outputs[n] for n in runs[4].outputs},
                                 runs[4].steady) for k in (1, 2)}
    order = float(np.log2(halving[1][0] / halving[2][0])) if halving[2][0] > 0 else float("nan")
    report["step_halving"] = {"h": {"error": halving[1][0], "output": halving[1][1]},
                              "h/2": {"error": halving[2][0], "output": halving[2][1]},
                              "order": order}
    print(f"halving: {json.dumps(report['step_halving'])}", file=sys.stderr, flush=True)

    radau_note = ""
    if not args.skip_radau:
        fun, jac, law, V = radau_system(model, op, excitation, result.motor_torque)
        size = V.shape[1]
        # accuracy 1: tight Radau on a short horizon
        k_ref = round(args.reference_t_end * args.fs) + 1
        start = time.process_time()
        _, X_ref, _ = run_radau(fun, jac, size, t[:k_ref], 1e-10, 1e-12, args.reference_budget)
        t_reference = time.process_time() - start
        reference = outputs_from_states(model, op, X_ref, law, list(result.outputs), V)
        error_ref, which_ref = relative_error(result.outputs, reference, result.steady,
                                              rows=slice(0, len(X_ref)))
        report["radau_reference"] = {"t_end": float(t[len(X_ref) - 1]), "error": error_ref,
                                     "output": which_ref, "cpu_seconds": t_reference}
        print(f"reference: {json.dumps(report['radau_reference'])}", file=sys.stderr, flush=True)
        # speed: Radau rtol 1e-8 on the whole horizon under the budget
        x_scale = 1e-3
        t_radau, X_radau, reached = run_radau(fun, jac, size, t, 1e-8, 1e-8 * 1e-3 * x_scale,
                                              args.radau_budget)
        name = "scipy.integrate Radau rtol 1e-8 (nonlinear)"
        if len(X_radau) < steps:
            name += f" (budget {args.radau_budget:g} s CPU: reached t = {reached:.4f} s)"
            radau_note = (f"Radau stopped by its budget at t = {reached:.4f} s of {args.t_end:g} s:"
                          " its time for the whole horizon is longer, its speed-ups are lower "
                          "bounds (≥).")
        rows[name] = t_radau
    print(f"system: {model.n} DOF, s0 = {args.s0:g}, {args.v:g} km/h, {len(result.outputs)} "
          f"outputs + wheels, {steps} points ({args.t_end:g} s at {args.fs:g} Hz), "
          f"{result.newton_iterations:.2f} Newton iterations per step")
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"load average {os.getloadavg()[0]:.2f} (shared); numpy {np.__version__}, scipy "
          f"{scipy.__version__}; OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')}")
    print()
    print("| method | time [ms] | time / lsim | speed-up vs Radau |")
    print("|---|---:|---:|---:|")
    radau = next((s for name, s in rows.items() if "Radau" in name), np.nan)
    bound = "≥ " if radau_note else ""
    for name, seconds in rows.items():
        print(f"| {name} | {1e3 * seconds:.1f} | {seconds / t_lsim:.2f} | "
              f"{bound if 'Radau' not in name else ''}{radau / seconds:.1f} |")
    print()
    if radau_note:
        print(radau_note)
    h = report["step_halving"]
    print(f"step halving over {args.t_end:g} s (against 4 steps per sample): h = 1/fs: "
          f"{h['h']['error']:.2e} ({h['h']['output']}), h/2: {h['h/2']['error']:.2e} "
          f"({h['h/2']['output']}); observed order {h['order']:.2f}")
    if "radau_reference" in report:
        r = report["radau_reference"]
        print(f"against Radau rtol 1e-10 over 0…{r['t_end']:g} s ({r['cpu_seconds']:.0f} s CPU): "
              f"{r['error']:.2e} of the perturbation peak ({r['output']})")
    print()
    print(json.dumps(report))


if __name__ == "__main__":
    main()
