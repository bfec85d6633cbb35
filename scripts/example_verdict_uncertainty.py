"""The worked example of docs/assessment.md's verdict under uncertainty: ``bogie assess --samples
128`` at the default set (default options), on a local cluster of two worker processes.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/example_verdict_uncertainty.py [--samples 128]

Writes ``docs/results/verdict_uncertainty.json``: the governing check's nominal safety factor,
its 5/50/95 % band with the quantiles' intervals, its probability of falling below the required
factor with the binomial error, which checks govern how many samples, the convergence of the 95 %
quantile over growing leading parts of the samples (8, 16, … n: the first part from which it
stays within 2 % of the n-sample value), and the checks of least median margin.  About four
minutes on two cores; the study is deterministic (scrambled Sobol' points of a fixed seed).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))

from docs_numbers import write_results  # noqa: E402

from model import load_parameters  # noqa: E402
from model.studies.engine import StudyEngine  # noqa: E402
from model.studies.verdict_uncertainty import run_verdict_uncertainty  # noqa: E402

STABLE_WITHIN = 0.02  # the 95 % quantile within 2 % of the n-sample value


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=128)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    parameters = load_parameters()
    with StudyEngine(workers=args.workers) as engine:
        result = run_verdict_uncertainty(parameters, args.samples, seed=12,
                                         map_unordered=engine.map_unordered)
    g = result.governing
    convergence = result.convergence(95.0)
    final = convergence[-1][1]
    stable_from = next(n for n, (count, _) in enumerate(convergence)
                       if all(abs(q - final) <= STABLE_WITHIN * abs(final)
                              for _, q in convergence[n:]))
    nominal = result.checks[result.nominal_check]
    counts = sorted(((count, band.label) for band, count in
                     zip(result.checks, result.governing_counts, strict=True) if count),
                    reverse=True)
    least = sorted(result.checks, key=lambda band: band.quantiles[1] / band.required)[:5]
    data = {
        "n": result.n, "unknowns": len(result.unknowns),
        "dynamics": sum(1 for group in result.groups if group == "dynamics"),
        "strength": sum(1 for group in result.groups if group != "dynamics"),
        "nominal": {"label": nominal.label, "safety_factor": nominal.nominal,
                    "required": nominal.required},
        "governing": {"p5": g.quantiles[0], "p50": g.quantiles[1], "p95": g.quantiles[2],
                      "p95_interval": list(g.quantile_intervals[2]),
                      "p_fail": g.failure.value, "p_fail_se": g.failure.standard_error,
                      "p_fail_interval": list(g.failure.interval)},
        "governing_counts": [{"label": label, "samples": count} for count, label in counts],
        "convergence": [{"samples": count, "p95": q} for count, q in convergence],
        "p95_stable_from": convergence[stable_from][0],
        "least_margin": [{"label": band.label, "p50": band.quantiles[1],
                          "required": band.required, "p_fail": band.failure.value}
                         for band in least],
    }
    print(result.summary())
    print(f"wrote {write_results('verdict_uncertainty', data, 'scripts/example_verdict_uncertainty.py')}")


if __name__ == "__main__":
    main()
