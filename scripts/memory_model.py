"""What the results cache holds per result: the bytes of each kind of entry (app.results.cache's
accounting) after a dashboard (no server) has shown the published cases with every view open —
the numbers of docs/memory.md.

    .venv/bin/python scripts/memory_model.py        # docs/results/memory.json, prints it

Sizes are what :func:`app.results.cache.deep_size` counts (array data and the objects around
them); the model's entry holds the decompositions of its last operating points
(:data:`model.analysis.linear_system.CACHED_POINTS`), which this run fills.

The background worker processes (app.services.background, as ``bogie serve`` starts them) are
measured apart: their resident memory (the kernel's VmRSS) at start and after the verdicts of the
same points and one anti-slip reaction search.
"""

from __future__ import annotations

import json
import os
import sys
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

MB = 1e6
# the points shown: the published cases and six more (the model keeps eight decompositions)
POINTS = ((0.005, 120.0), (0.014, 120.0), (0.004, 80.0), (0.006, 100.0), (0.007, 140.0),
          (0.005, 160.0), (0.003, 200.0), (0.008, 60.0))


def measure() -> dict:
    from bokeh.document import Document

    from app.dashboard.dashboard import BogieDashboard
    from app.results.cache import RESULTS, deep_size
    from model.analysis import locus
    from model.analysis.linear_system import CACHED_POINTS

    dashboard = BogieDashboard(query={})
    doc = Document()
    doc.add_root(dashboard.layout.get_root(doc))
    for tab in ("verdicts", "resonances", "sensitivity", "design-loads"):
        dashboard.tabs.active = dashboard.view_tabs.names.index(tab)  # every view computes
    dashboard.nonlinear.creep.value = "nonlinear"
    for s0, v in POINTS:
        dashboard.param.update(s0=s0, v=v)
    RESULTS.measure()
    sizes = defaultdict(list)
    for key, size in RESULTS.sizes():
        sizes[key[0]].append(size)
    entries = {kind.replace(" ", "_"): round(max(values) / MB, 3)
               for kind, values in sorted(sizes.items())}
    # what one more operating point adds with every view open (the model aside): its own entries
    # the root-locus sweep starts the model keeps outside the cache (model.analysis.locus), each
    # without the model it refers to (that one is the cache's)
    starts = list(locus._SWEEP_STARTS.values())
    models = {id(start.model) for start in starts}
    sweep_start = max(deep_size(start, set(models)) for start in starts)
    per_point = ("point", "response", "nonlinear", "worst_case", "spectra", "assessment",
                 "sensitivities", "frf")
    return {"entries_mb": entries, "model_mb": entries["model"],
            "model_decompositions": CACHED_POINTS,
            "point_mb": round(sum(entries.get(kind, 0.0) for kind in per_point), 3),
            "linear_point_mb": round(entries["point"] + entries["response"], 3),
            "sweep_start_mb": round(sweep_start / MB, 1),
            "sweep_starts_kept": locus._SWEEP_STARTS_KEPT,
            "points": [f"{s0:g} at {v:g} km/h" for s0, v in POINTS]}


def _resident_mb(pid: int) -> float:
    """A process's resident memory (VmRSS) [MB]."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) * 1024 / MB
    raise RuntimeError(f"no VmRSS for process {pid}")


def measure_workers() -> dict:
    """The background worker processes' resident memory [MB] at start and after the verdicts of
    :data:`POINTS` and one reaction search, computed in them (each worker's own results cache of
    :data:`app.services.background.WORKER_CACHE_MB` MB)."""
    from functools import partial

    from app.dashboard.nonlinear_view import reaction
    from app.results import cache, compute
    from app.results.case import Case
    from app.results.verdicts import assessment_result
    from app.services import background
    from model.analysis.nonlinear import AntiSlip

    workers = background.LocalWorkers(setup=partial(cache.configure, background.WORKER_CACHE_MB))
    workers.start()
    previous = background.configure(workers)
    try:
        at_start = [_resident_mb(pid) for pid in workers.pids()]
        parameters = compute.parameters("", "calibrated")
        case = Case.from_outer("", {}, parameters)
        for s0, v in POINTS:
            assessment_result(case.replace(s0=s0, v=v), runner=background.run)
        protection = AntiSlip()
        reaction(case.replace(s0=0.014), protection.threshold, protection.rate,
                 runner=background.run)
        after = [_resident_mb(pid) for pid in workers.pids()]
    finally:
        background.configure(previous)
        workers.close()
    return {"background_workers": workers.workers,
            "worker_cache_mb": background.WORKER_CACHE_MB,
            "worker_start_mb": round(max(at_start), 1),
            "worker_after_mb": round(max(after), 1)}


def main() -> None:
    from docs_numbers import write_results

    data = measure() | measure_workers()
    print(json.dumps(data, indent=1))
    print(f"wrote {write_results('memory', data, 'scripts/memory_model.py')}")


if __name__ == "__main__":
    main()
