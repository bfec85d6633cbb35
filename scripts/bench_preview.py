"""What a held slider's preview costs the server, against one dense eigen-analysis measured in the
same run, and whether its verdicts are the eigen-analysis's.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/bench_preview.py [--quick] [--json FILE]

Calibrated set, 120 km/h, the set's N0 and b_M, with what the dashboard has once a page's
follow-ups are done (the dense root locus over s0 and s0*(v)); then :func:`app.results.preview.preview`
at every s0 slider step from 0.005 to 0.012 (s0*(v) and the locus's branches), and at speeds,
wheel forces and motor slopes no computation has visited (the reduced model of the locus on
screen).  Per kind: the median time of one preview, its ratio to one eigen-analysis (with
vectors: what a release computes first; eigenvalues only), the dense eigendecompositions the
previews ran (:func:`model.analysis.linear_system.dense_decompositions`; must be 0) and the
verdicts that differ from the dense eigen-analysis at the same point (computed afterwards).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from app.results import compute, preview
from app.results.case import Case
from app.services.thread_pools import limit_blas_threads
from model import eigen_analysis
from model.analysis.eigen import forget_systems
from model.analysis.linear_system import dense_decompositions

SET, RAIL, V_KMH = "", "calibrated", 120.0


def best_of(function, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        function()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a few points of each kind")
    parser.add_argument("--json", default=None, help="write the numbers here")
    args = parser.parse_args()
    limit_blas_threads()
    p = compute.parameters(SET, RAIL)
    base = Case(**{**Case.defaults(p), "set_key": SET, "rail": RAIL, "v": V_KMH})
    N0, b_M = base.N0, base.b_M
    key = base.sweep("s0")
    m = compute.model(SET, RAIL)
    compute.dense_locus_result(key)
    s0_limit = compute.limit_result(base).s0_limit

    def dense(vectors: bool) -> None:
        forget_systems(m)
        eigen_analysis(m, base.replace(s0=0.0061).operating_point(), vectors)

    with_vectors, values_only = best_of(lambda: dense(True), 5), best_of(lambda: dense(False), 5)
    n = 3 if args.quick else 10
    s0_steps = [round(0.005 + 0.0001 * k, 7) for k in range(0, 71, 7 if args.quick else 1)]
    start = base.replace(s0=0.005)
    kinds = {
        "s0 (s0*(v), root locus)": [base.replace(s0=s0) for s0 in s0_steps],
        "v (reduced model)": [start.replace(v=V_KMH + 1.0 + k) for k in range(n)],
        "N0 (reduced model)": [start.replace(N0=N0 + 1.0 + k) for k in range(n)],
        "b_M (reduced model)": [start.replace(b_M=b_M + 500.0 * (k + 1)) for k in range(n)],
    }
    print(f"one eigen-analysis: with vectors {with_vectors * 1e3:.1f} ms, eigenvalues only "
          f"{values_only * 1e3:.1f} ms (best of 5); s0*(120 km/h) = {s0_limit:.5f}")
    print("| previews of | n | median per preview | / eigen-analysis with vectors | dense "
          "solves | verdicts unlike the eigen-analysis's | not decided |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    results = {"eigen_vectors_s": with_vectors, "eigen_values_s": values_only,
               "s0_limit": s0_limit, "kinds": {}}
    for kind, points in kinds.items():
        dragged = kind.split()[0]
        before = dense_decompositions()
        times, previews = [], []
        for point in points:
            t0 = time.perf_counter()
            previews.append(preview.preview(point, key, dragged))
            times.append(time.perf_counter() - t0)
        solves = dense_decompositions() - before
        exact = [eigen_analysis(m, point.operating_point(), vectors=False).stable
                 for point in points]
        unlike = sum(r.stable is not None and r.stable != e
                     for r, e in zip(previews, exact, strict=True))
        undecided = sum(r.stable is None for r in previews)
        median = statistics.median(times)
        print(f"| {kind} | {len(points)} | {median * 1e3:.2f} ms | {median / with_vectors:.3f} | "
              f"{solves} | {unlike} | {undecided} |")
        results["kinds"][kind] = {"times_s": times, "dense_solves": solves, "unlike": unlike,
                                  "undecided": undecided}
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
