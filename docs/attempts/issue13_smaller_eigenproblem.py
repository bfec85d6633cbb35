"""Issue 13, eighth session: two ideas for a smaller per-point eigenproblem, measured and rejected
(BENCHMARKS.md, "Issue 13, eighth session").  Not part of the tool; kept so the numbers can be
re-run:

    OPENBLAS_NUM_THREADS=1 .venv/bin/python docs/attempts/issue13_smaller_eigenproblem.py

1. *Modal block*: at an anchor with eigendecomposition A = X Λ X⁻¹, every eigenvalue at creep
   coefficient c is one of Λ + Δc Ũ Ṽᵀ (Ũ = X⁻¹U, Ṽ = VᵀX, rank 4, model.continuation).  Keep
   the block of the modes that can matter (Re λ > −5 1/s, |λ| < 2π·10 Hz, or a first-order
   shift ‖ũ_j‖‖ṽ_j‖·max|Δc| > τ) and solve it at every point from the nearest anchor (in c).
   Printed: block sizes, worst relative error of the decisive eigenvalues (Re within 1 1/s of
   min(top, 0)) against a full eigen-analysis, points whose summary differs, eig time per point.
2. *Frozen modes*: how many of the modes the reduced method's basis takes at an end of a line
   move by less than 1e-9 / 1e-7 / 1e-5 / 1e-3 of max(|λ|, 1 1/s) over the line (first order):
   those could leave the basis and be reported from the anchor.
"""

import numpy as np
from threadpoolctl import threadpool_limits

from model import KMH, eigen_analysis, load_parameters
from model.continuation import creep_coefficient, make_anchor
from model.operating_point import OperatingPoint
from model.study import cached_model, spectrum_summary

threadpool_limits(1)
parameters = load_parameters()
model = cached_model(parameters)
N0, b_M = parameters["wheel_force"], parameters["motor_slope"]
s0 = np.linspace(0.001, 0.02, 100)
RADIUS, MARGIN = 2 * np.pi * 10.0, 5.0

for v_kmh in (40, 120, 250):
    points = [OperatingPoint(float(s), v_kmh * KMH, N0, b_M) for s in s0]
    dense = [eigen_analysis(model, op, vectors=False).eigenvalues for op in points]
    c = np.array([creep_coefficient(model, op) for op in points])
    for anchor_indices, tau in (((0, 99), 1.0), ((0, 3, 10, 40, 99), 1.0),
                                ((0, 2, 5, 10, 20, 40, 70, 99), 0.01)):
        anchors = [make_anchor(model, points[i]) for i in anchor_indices]
        sizes, worst, differ = [], 0.0, 0
        for i, reference in enumerate(dense):
            a = min(anchors, key=lambda a: abs(c[i] - a.c_ref) / (abs(a.c_ref) + abs(c[i]) + 1))
            dc = c[i] - a.c_ref
            keep = ((a.poles.real > -MARGIN) | (np.abs(a.poles) < RADIUS)
                    | (a.weight * abs(dc) > tau))
            mu = np.linalg.eigvals(np.diag(a.poles[keep]) + dc * a.Ut[keep] @ a.Vt[:, keep])
            sizes.append(int(keep.sum()))
            decisive = reference[reference.real > min(reference.real.max(), 0.0) - 1.0]
            error = np.abs(decisive[:, None] - mu[None, :]).min(axis=1)
            worst = max(worst, float((error / np.maximum(np.abs(decisive), 1.0)).max()))
            ref, got = spectrum_summary(reference), spectrum_summary(mu)
            differ += ref[1:] != got[1:] or abs(ref[0] - got[0]) > 1e-3
        print(f"{v_kmh} km/h, {len(anchors)} anchors, tau {tau:g}: block {min(sizes)}-{max(sizes)},"
              f" decisive eigenvalues within {worst:.1e} (relative), {differ}/100 summaries differ")
    for s in (0, 99):
        a = make_anchor(model, points[s])
        shift = a.weight * np.abs(c - a.c_ref).max() / np.maximum(np.abs(a.poles), 1.0)
        taken = ((a.poles.real > -MARGIN) | (np.abs(a.poles) < RADIUS)) & (a.poles.imag >= 0)
        counts = ", ".join(f"< {t:g}: {np.count_nonzero(shift[taken] < t)}"
                           for t in (1e-9, 1e-7, 1e-5, 1e-3))
        print(f"{v_kmh} km/h, end s0 = {s0[s]:g}: {taken.sum()} modes taken (one of each pair); "
              f"relative first-order shift over the line {counts}")
