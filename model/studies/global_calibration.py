"""Global calibration: stage J of :mod:`model.studies.calibration` from many starts.

A local least squares from one start lands where its start and its character assignment lead
it; this module runs the same least squares (stages A and J, unchanged) from ``N`` starts spread
over the calibration bounds and compares where they land:

* **Starts**: start 0 is the start file's own values (``start_file``: what ``bogie calibrate``
  without ``--starts`` fits, so the single calibration is start 0 of every search); starts 1 … N
  are the points 0 … N − 1 of a scrambled Sobol' sequence (``scipy.stats.qmc.Sobol``, seed
  :data:`SOBOL_SEED`) in the unit cube of the search parameters
  (:data:`~model.studies.calibration_bounds.SEARCH_PARAMETERS`), mapped onto their bounds (log
  parameters log-uniformly, heights linearly); start ``k`` is the same whatever ``N``
  (``fast_forward``), so one start re-runs alone (``bogie calibrate --start K``).  Stage A solves
  the creep law and the gear ratio at each start; the prior of stage J stays the start file.
* **Each start** is a pure function of its index (:func:`run_start`; one BLAS thread): the study
  engine (:mod:`model.studies.engine`) runs them on its workers.
* **Ranking** (:func:`ranking_key`), the rule the bundled set is chosen by (docs/validation.md):
  the starts that meet the divergence within :data:`DIVERGENCE_TOLERANCE` first, then the most
  pairs of Table 1 by rank within :data:`FREQUENCY_TOLERANCE` (the target's own count), then the
  smaller largest frequency error, then stage J's own cost at its last phase's weights
  (:func:`model.studies.calibration.stage_j_cost`, with ``--divergence-weight`` where given; it
  weighs the characters and real parts the counts do not see).
* **The trade**: per start the largest frequency error of the ten pairs by rank at s0 = 0.005
  (Table 1) and the divergence error (the largest real eigenvalue at s0 = 0.014 against
  +7.031 1/s); the starts that no other start beats in both form the front (:func:`front`).
* **Spread**: over the best quarter of the starts (at least four), each parameter's range as a
  share of its bounds (on the log scale for log parameters): a parameter whose best starts span
  at most :data:`IDENTIFIED_SHARE` of its bounds is identified by the targets (:func:`spread`),
  unless they all sit on the same bound (then the bound holds it, not the targets).

Plain dataclasses; the engine is passed in as a ``map_unordered`` function.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path

import numpy as np

from model.mechanics.parameters import ESTIMATE_FILE, Parameters, load_parameters
from model.studies.calibration import PHASES, calibrate, calibrated_set, stage_j_cost
from model.studies.calibration_bounds import SEARCH_PARAMETERS
from model.studies.calibration_targets import DIVERGENCE_RATES, TABLE1_IM_HZ, TargetRow

SOBOL_SEED = 20_261_206  # fixed: start k is the same point on every run
DEFAULT_STARTS = 16
BEST_SHARE = 0.25  # the best quarter of the starts (at least MIN_BEST) gives the spread
MIN_BEST = 4
IDENTIFIED_SHARE = 0.25  # best starts within a quarter of the bounds: identified by the targets
FREQUENCY_TOLERANCE = 0.05  # [-] Table 1 by rank (tests/literature/test_table1.py)
DIVERGENCE_TOLERANCE = 0.10  # [-] the largest real at s0 = 0.014 against +7.031 1/s (the same)


def sobol_unit_point(k: int, dimension: int) -> np.ndarray:
    """The ``k``-th point (from 0) of the scrambled Sobol' sequence of :data:`SOBOL_SEED` in the
    unit cube of ``dimension`` (the same whatever the number of starts)."""
    from scipy.stats import qmc

    if k < 0:
        raise ValueError(f"start index must be >= 0, got {k}")
    sampler = qmc.Sobol(dimension, scramble=True, seed=SOBOL_SEED)
    if k:
        sampler.fast_forward(k)
    return sampler.random(1)[0]


def start_values(k: int, free=SEARCH_PARAMETERS) -> dict[str, float]:
    """Start ``k``'s values of the search parameters [SI]: none for start 0 (the start file's
    own), else Sobol' point ``k − 1`` mapped onto each parameter's bounds (log-uniformly for log
    parameters, linearly for heights)."""
    if k < 0:
        raise ValueError(f"start index must be >= 0, got {k}")
    if k == 0:
        return {}
    u = sobol_unit_point(k - 1, len(free))
    values = {}
    for f, ui in zip(free, u, strict=True):
        if f.log:
            values[f.name] = float(math.exp(math.log(f.low) + ui * math.log(f.high / f.low)))
        else:
            values[f.name] = float(f.low + ui * (f.high - f.low))
    return values


@dataclass(frozen=True)
class StartResult:
    """Where one start of the global calibration lands."""

    index: int
    start: dict  # the start's values of the search parameters [SI]
    values: dict  # the calibrated set's values, every parameter [SI]
    cost: float  # stage J's cost at full weights (the ranking)
    frequency_error: float  # [-] the largest |ΔIm|/Im of the ten pairs by rank at s0 = 0.005
    ranks_within: int  # pairs by rank within FREQUENCY_TOLERANCE
    characters: int  # pairs by rank with Table 2's character
    largest_real_unstable: float  # [1/s] the largest real eigenvalue at s0 = 0.014
    divergence_error: float  # [-] |largest real − 7.031| / 7.031
    seconds: float  # wall time of the start [s]
    failed: str = ""  # why the start could not be calibrated (its cost and errors are inf)

    def as_dict(self) -> dict:
        def finite(x):
            return x if math.isfinite(x) else None

        return {"index": self.index, "cost": finite(self.cost),
                "frequency_error": finite(self.frequency_error),
                "ranks_within_5_percent": self.ranks_within, "characters": self.characters,
                "largest_real_at_0.014": finite(self.largest_real_unstable),
                "divergence_error": finite(self.divergence_error), "seconds": self.seconds,
                "failed": self.failed, "start": self.start, "values": self.values}


def target_measures(rows: list[TargetRow]) -> dict:
    """The two sides of the trade from a set's target rows (:func:`calibration_targets.evaluate`):
    the frequency error by rank, the ranks within 5 %, the characters, the divergence."""
    ranked = rows[:len(TABLE1_IM_HZ)]
    largest = next(row.achieved for row in rows if row.name.startswith("real eigenvalue 1"))
    return {"frequency_error": float(max(abs(row.error) for row in ranked)),
            "ranks_within": int(sum(bool(abs(row.error) <= FREQUENCY_TOLERANCE) for row in ranked)),
            "characters": int(sum("OTHER CHARACTER" not in row.name for row in ranked)),
            "largest_real_unstable": float(largest),
            "divergence_error": float(abs(largest - DIVERGENCE_RATES[0]) / DIVERGENCE_RATES[0])}


def run_start(k: int, start_file: str | Path | None = None, phases: tuple = PHASES,
              progress: Callable[[str], None] = lambda _text: None) -> StartResult:
    """Stages A and J from start ``k`` (one BLAS thread; a pure function of its arguments, for
    the study engine's workers); ``progress`` gets the stages' lines."""
    from threadpoolctl import threadpool_limits

    began = time.perf_counter()
    estimate = load_parameters(ESTIMATE_FILE if start_file is None else start_file)
    values = start_values(k)
    try:
        with threadpool_limits(1):
            calibrated, rows = calibrate(estimate, progress, phases,
                                         initial=estimate.replace(**values) if values else None)
            cost = stage_j_cost(calibrated, estimate, phases[-1][1])
    except (ValueError, np.linalg.LinAlgError) as error:  # a start the model cannot analyse
        # (e.g. a creep shape whose law has no maximum below s = 1 for any μ0, A, B, p)
        return StartResult(k, values, {}, math.inf, math.inf, 0, 0, math.nan, math.inf,
                           time.perf_counter() - began, failed=str(error))
    return StartResult(k, values, {name: float(v) for name, v in calibrated.values.items()},
                       float(cost), **target_measures(rows),
                       seconds=time.perf_counter() - began)


def start_set(result: StartResult, start_file: str | Path | None = None) -> Parameters:
    """The calibrated set of a start, with the notes ``bogie calibrate`` writes."""
    estimate = load_parameters(ESTIMATE_FILE if start_file is None else start_file)
    return calibrated_set(result.values, estimate)


def front(results: Iterable[StartResult]) -> list[int]:
    """Indices of the starts that no other start beats in both the frequency error and the
    divergence error (the trade between Table 1 by rank and the +7.031 1/s divergence)."""
    results = [r for r in results if not r.failed]
    return sorted(r.index for r in results
                  if not any((o.frequency_error <= r.frequency_error
                              and o.divergence_error <= r.divergence_error)
                             and (o.frequency_error < r.frequency_error
                                  or o.divergence_error < r.divergence_error)
                             for o in results))


@dataclass(frozen=True)
class SpreadRow:
    name: str
    low: float  # [SI] the smallest value among the best starts
    high: float  # [SI] the largest
    share: float  # [-] (high − low) as a share of the bounds (log scale for log parameters)
    identified: bool  # share <= IDENTIFIED_SHARE and not held on a bound
    on_bound: bool = False  # every best start on the same bound: the bound, not the targets


def ranking_key(result: StartResult) -> tuple:
    """Sort key of a start (smaller: better; module docstring): meets the divergence, ranks
    within 5 %, largest frequency error, stage J's cost, index."""
    return (not result.divergence_error <= DIVERGENCE_TOLERANCE, -result.ranks_within,
            result.frequency_error, result.cost, result.index)


def best_starts(results: Iterable[StartResult]) -> list[StartResult]:
    """The best quarter of the starts by :func:`ranking_key` (at least :data:`MIN_BEST`, at
    most all)."""
    ranked = sorted((r for r in results if not r.failed), key=ranking_key)
    count = min(len(ranked), max(MIN_BEST, math.ceil(BEST_SHARE * len(ranked))))
    return ranked[:count]


def spread(results: Iterable[StartResult], free=SEARCH_PARAMETERS) -> list[SpreadRow]:
    """Per search parameter, the range of the best starts' values and its share of the bounds."""
    best = best_starts(results)
    rows = []
    for f in free:
        values = [r.values[f.name] for r in best]
        low, high = min(values), max(values)
        if f.log:
            share = math.log(high / low) / math.log(f.high / f.low)
        else:
            share = (high - low) / (f.high - f.low)
        held = all(f.on_bound(v) for v in values) and share <= IDENTIFIED_SHARE
        rows.append(SpreadRow(f.name, float(low), float(high), float(share),
                              bool(share <= IDENTIFIED_SHARE and not held), bool(held)))
    return rows


@dataclass(frozen=True)
class GlobalResult:
    results: list[StartResult]  # by start index: 0 (the start file), then the Sobol' starts
    best: int  # index of the best start (ranking_key)
    front: list[int]
    spread: list[SpreadRow]
    seconds: float  # wall time of the whole search [s]
    where: str = ""  # the engine it ran on
    extra: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        return {"starts": len(self.results) - 1, "best": self.best, "front": self.front,
                **self.extra,
                "seconds": self.seconds, "where": self.where, "sobol_seed": SOBOL_SEED,
                "results": [r.as_dict() for r in self.results],
                "spread": [{"name": s.name, "low": s.low, "high": s.high, "share": s.share,
                            "identified": s.identified, "on_bound": s.on_bound}
                           for s in self.spread]}


def global_search(starts: int, map_unordered: Callable[[Callable, list], Iterator[tuple]],
                  start_file: str | Path | None = None, phases: tuple = PHASES,
                  progress: Callable[[StartResult], None] = lambda _result: None,
                  where: str = "") -> GlobalResult:
    """Start 0 (the start file) and the Sobol' starts 1 … ``starts`` on ``map_unordered`` (the
    study engine's, or :func:`model.studies.engine.serial_map_unordered`); ``progress`` is
    called with each start's result as it finishes."""
    if starts < 1:
        raise ValueError(f"starts must be >= 1, got {starts}")
    began = time.perf_counter()
    function = partial(run_start, start_file=None if start_file is None else str(start_file),
                       phases=phases)
    results = {}
    for _, result in map_unordered(function, list(range(starts + 1))):
        results[result.index] = result
        progress(result)
    ordered = [results[k] for k in sorted(results)]
    if all(r.failed for r in ordered):
        raise ValueError(f"no start could be calibrated: {ordered[0].failed}")
    best = min((r for r in ordered if not r.failed), key=ranking_key).index
    return GlobalResult(ordered, best, front(ordered), spread(ordered),
                        time.perf_counter() - began, where,
                        {"divergence_weight": phases[-1][1].divergence})


def write_start(result: StartResult, out_file: str | Path, start_file: str | Path | None = None,
                divergence_weight: float | None = None) -> tuple[list[TargetRow], str]:
    """Write a start's calibrated set to ``out_file`` with its targets and the stability limit
    in the header (one BLAS thread: ``--start K`` and the best of ``--starts N`` write the same
    bytes); returns the target rows and their table."""
    from threadpoolctl import threadpool_limits

    from model.analysis.stability import stability_limit
    from model.mechanics.assembly import build_model
    from model.mechanics.parameters import save_parameters
    from model.studies.calibration_targets import V_REF, evaluate, format_table

    parameters = start_set(result, start_file)
    with threadpool_limits(1):
        rows = evaluate(parameters)
        limit = stability_limit(build_model(parameters), V_REF, parameters["wheel_force"],
                                parameters["motor_slope"]).s0_limit
    table = format_table(rows, limit)
    name = Path(ESTIMATE_FILE if start_file is None else start_file).name
    how = "" if divergence_weight is None else f" --divergence-weight {divergence_weight:g}"
    if result.index == 0:
        what = (f"Calibrated parameter set of start 0 of the global calibration: from {name}'s "
                "own values.\n"
                f"Produced by `bogie calibrate --from {name}{how}` (the same as `--start 0`);\n"
                "`bogie calibrate --starts N` writes the same file when start 0 is its best.")
    else:
        what = (f"Calibrated parameter set of start {result.index} of the global calibration "
                f"(scrambled Sobol' sequence, seed {SOBOL_SEED}, its point {result.index - 1}, "
                "within the calibration bounds).\n"
                f"Produced by `bogie calibrate --start {result.index} --from {name}{how}`; "
                f"`bogie calibrate --starts N` writes the same file\nwhen start {result.index} is "
                "its best.")
    header = f"{what} Stage J's cost {result.cost:.6g}. Targets and results:\n" + table
    save_parameters(parameters, out_file, header)
    return rows, table
