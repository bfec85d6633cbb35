"""The numbers of docs/validation.md's "What the bounds hold": for each calibrated parameter that
the bundled set has on a bound, the bundled set's calibration run again with that bound moved out
of the hardware range, alone and all of them together.

    .venv/bin/python scripts/bound_lifting.py [--workers 2]  # runs itself with pinned numerics
        # docs/results/bound_lifting.json (≈ 4 min on 2 cores)

Each run is ``bogie calibrate --from assets/parameters/calibration_start.toml --divergence-weight
W`` (W: the bundled set's weight, ``docs/results/bundled_set.json``) with other ranges for the
lifted parameters: an upper bound times three (a scale parameter) or moved up by the range's
width (a height), a lower bound divided by three or moved down by the width.  The first run keeps
every range: the bundled set (the script gives the largest relative difference of its
values from the bundled ones).

What the runs tell: whether Table 1 by rank and the divergence come within reach once the bound
is gone (then the bound is what stops the calibration, and the study asks for hardware outside
it), or not (then the parameter sits on its bound because the least squares trades it against
other targets, and the bound costs Table 1 nothing a bogie could buy back).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

from bundled_set import BUNDLED, calibrate_at, pin_numerics  # noqa: E402  (the bundled set's command)
from docs_numbers import RESULTS, write_results  # noqa: E402

from model import load_parameters  # noqa: E402
from model.mechanics.parameters import ALL_SCHEMA  # noqa: E402
from model.studies.calibration_bounds import FREE_PARAMETERS  # noqa: E402

BUNDLED_SET_RESULTS = RESULTS / "bundled_set.json"
SCALE_FACTOR = 3.0  # a scale parameter's bound moves out by this factor


def lifted_range(parameter, value: float):
    """``parameter``'s range with the bound ``value`` sits on moved out of it."""
    upper = abs(value - parameter.high) <= abs(value - parameter.low)
    width = parameter.high - parameter.low
    if parameter.log:
        ends = ((parameter.low, parameter.high * SCALE_FACTOR) if upper
                else (parameter.low / SCALE_FACTOR, parameter.high))
    else:
        ends = (parameter.low, parameter.high + width) if upper else (parameter.low - width,
                                                                    parameter.high)
    return dataclasses.replace(parameter, low=ends[0], high=ends[1])


def calibrate_with(job: tuple[tuple[str, ...], float]) -> dict:
    """The bundled set's calibration with the ranges of ``names`` lifted (one BLAS thread;
    :func:`bundled_set.calibrate_at` with those ranges, which also judge the bounds)."""
    from model.studies.calibration import SEARCH_PARAMETERS

    names, weight = job
    bundled = load_parameters(BUNDLED)
    free = tuple(lifted_range(p, bundled[p.name]) if p.name in names else p
                 for p in SEARCH_PARAMETERS)
    run = calibrate_at(weight, free)
    lifted = {p.name: p for p in free}
    hardware = {p.name: p for p in FREE_PARAMETERS}
    landed = {name: run["values"][name] for name in names}
    return {"lifted": list(names),
            "ranges": {name: [lifted[name].low, lifted[name].high] for name in names},
            "hardware_ranges": {name: [hardware[name].low, hardware[name].high] for name in names},
            "landed": landed,
            "outside_hardware": [name for name in names
                                 if not hardware[name].low <= landed[name] <= hardware[name].high],
            **run}


def _value(name: str, value: float) -> str:
    """``value`` in the parameter's unit (its schema's), a large one in millions (M…)."""
    unit = ALL_SCHEMA[name][0]
    if abs(value) >= 1e5:
        return f"{value / 1e6:.2f} M{unit}"
    shown = np.format_float_positional(value, precision=3, fractional=False, trim="-")
    return f"{shown} {unit}"


def table_block(runs: list[dict]) -> str:
    lines = ["| bound lifted | range: hardware → lifted | where it lands | largest \\|ΔIm\\| by rank "
             "| ranks within 5 % | characters | largest real at 0.014 [1/s] | on a bound |",
             "|---|---|---|---|---|---|---|---|"]
    for run in runs:
        names = run["lifted"]
        if not names:
            label, ranges, landed = "none (the bundled set)", "—", "—"
        else:
            label = ", ".join(f"`{n}`" for n in names) if len(names) < 3 else "all of them"
            ranges = "; ".join(
                f"{_value(n, run['hardware_ranges'][n][0])}…{_value(n, run['hardware_ranges'][n][1])}"
                f" → {_value(n, run['ranges'][n][0])}…{_value(n, run['ranges'][n][1])}"
                for n in names)
            landed = "; ".join(_value(n, run["landed"][n]) +
                               (" (outside)" if n in run["outside_hardware"] else "")
                               for n in names)
        lines.append(f"| {label} | {ranges} | {landed} | {100 * run['frequency_error']:.1f} % | "
                     f"{run['ranks_within']} | {run['characters']} | "
                     f"{run['largest_real_unstable']:+.2f} | {len(run['on_bound'])} |")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2, help="processes for the calibrations")
    args = parser.parse_args()
    pin_numerics()
    weight = json.loads(BUNDLED_SET_RESULTS.read_text())["chosen_weight"]
    bundled = load_parameters(BUNDLED)
    held = tuple(p.name for p in FREE_PARAMETERS if p.on_bound(bundled[p.name]))
    jobs = [((), weight), *(((name,), weight) for name in held), (held, weight)]
    with ProcessPoolExecutor(args.workers) as pool:
        runs = list(pool.map(calibrate_with, jobs))
    # the first run against the bundled set: the same least squares in the pinned numerics,
    # the same numbers (0 where this machine's libraries are the bundled set's releases)
    difference = max(abs(runs[0]["values"][p.name] / bundled[p.name] - 1) for p in FREE_PARAMETERS)
    lifted = runs[1:]
    data = {"divergence_weight": weight, "held": list(held), "held_count": len(held),
            "bundled_max_relative_difference": difference,
            "runs": [{k: v for k, v in run.items() if k != "values"} for run in runs],
            "best_ranks_within_lifted": max(run["ranks_within"] for run in lifted),
            "least_frequency_error_lifted": min(run["frequency_error"] for run in lifted),
            "blocks": {"table": table_block(runs)}}
    path = write_results("bound_lifting", data, "scripts/bound_lifting.py")
    print(data["blocks"]["table"])
    print(f"the first run against the bundled set: {difference:.1e} relative at most")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
