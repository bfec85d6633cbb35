"""The verdict under uncertainty: its cost per sample against one assessment, and its parallel
efficiency on the local cluster, in the same run.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/bench_verdict.py [--samples 16] [--repeats 3]
                                                                  [--workers 2] [--json FILE]

1. **reference**: one whole assessment (``model.studies.assessment.assess``, all four load cases,
   the short-circuit grid in this process, as ``bogie assess --serial`` computes it) of a set
   whose dynamics differ from the last one's by a relative 1e-9 (so each builds and decomposes
   its model cold, as every dynamics sample does); the median of ``--repeats``.
2. **per sample**: ``run_verdict_uncertainty`` with ``--samples`` N in this process (N + 1 rows:
   the samples and the set itself, each its own dynamics run); its wall time over the rows,
   against the reference (the target: at most 1.2x).
3. **parallel efficiency**: the same study on a local cluster of ``--workers`` workers (imports
   and a first assessment per worker before the clock runs); efficiency = serial / (workers x
   cluster) (target: at least 80 %), and the governing factors of both runs compared.

Times are wall time [s]; the load average before and after each part is printed, since other
jobs on the machine share the cores.
"""

from __future__ import annotations

import argparse
import json
import statistics
from pathlib import Path

import numpy as np
from bench_timing import load, timed  # the scripts' own helpers

from model import load_parameters
from model.studies.assessment import assess
from model.studies.engine import StudyEngine
from model.studies.verdict_uncertainty import run_verdict_uncertainty

PERTURBED = "rotor_inertia"  # a dynamics parameter nudged by 1e-9 so that a model is built cold


def nudged(parameters, k: int):
    """The set with its ``PERTURBED`` value times (1 + k 1e-9): the same verdict, a new model."""
    return parameters.replace(**{PERTURBED: parameters[PERTURBED] * (1.0 + 1e-9 * k)})


def _warm_up(k: int) -> int:
    """Import everything and assess once in a worker (not timed)."""
    return len(assess(nudged(load_parameters(), 1000 + k)).checks)


def governing(result) -> np.ndarray:
    return np.array([sample.safety_factor for sample in result.samples])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=16, help="N, a power of 2 (default 16)")
    parser.add_argument("--repeats", type=int, default=3,
                        help="repeats of the reference assessment (default 3)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--json", default=None, help="write the measures to this file")
    args = parser.parse_args()
    parameters = load_parameters()
    print(f"# The verdict under uncertainty, N = {args.samples} samples, default set\n")
    print(f"load average before: {load()}", flush=True)
    assess(nudged(parameters, 999))  # imports and one-time set-ups, not timed
    reference = [timed(lambda k=k: assess(nudged(parameters, k + 1)))[0]
                 for k in range(args.repeats)]
    one = statistics.median(reference)
    print(f"1. one assessment (cold model, serial): median {one:.2f} s "
          f"({', '.join(f'{t:.2f}' for t in reference)}); load average {load()}", flush=True)
    t_serial, serial = timed(lambda: run_verdict_uncertainty(parameters, args.samples))
    rows = serial.evaluations
    per_sample = t_serial / rows
    ratio = per_sample / one
    print(f"2. the study in this process: {t_serial:.1f} s for {rows} rows "
          f"({serial.runs} dynamics runs): {per_sample:.2f} s per sample = **{ratio:.2f}x** one "
          f"assessment (target <= 1.2x); load average {load()}", flush=True)
    with StudyEngine(None, args.workers) as engine:
        engine.map(_warm_up, list(range(engine.workers)))
        t_cluster, parallel = timed(lambda: run_verdict_uncertainty(
            parameters, args.samples, map_unordered=engine.map_unordered))
        used = engine.workers
    efficiency = t_serial / (used * t_cluster)
    same = bool(np.allclose(governing(serial), governing(parallel), rtol=1e-9, equal_nan=True))
    print(f"3. the study on a local cluster of {used} workers: {t_cluster:.1f} s; efficiency "
          f"**{efficiency:.0%}** (target >= 80 %); governing factors equal to serial's (1e-9): "
          f"{same}; load average after: {load()}")
    if args.json:
        Path(args.json).write_text(json.dumps({
            "samples": args.samples, "rows": rows, "reference_s": reference,
            "reference_median_s": one, "serial_s": t_serial, "per_sample_ratio": ratio,
            "workers": used, "cluster_s": t_cluster, "parallel_efficiency": efficiency,
            "identical": same}, indent=1))


if __name__ == "__main__":
    main()
