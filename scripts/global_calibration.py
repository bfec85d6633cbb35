"""The numbers, tables and figure of docs/validation.md's "Global calibration" from a stored run
of ``bogie calibrate --starts N --json`` (the search takes tens of minutes; its output is kept
in ``assets/data/``), and the comparison of the bundled set (start 0, the search's best) with
the best of the Sobol' starts.

    bogie calibrate --starts 16 --from assets/parameters/calibration_start.toml \\
        --divergence-weight 10 --out global_best.toml \\
        --json > assets/data/global_calibration_n16.json
    .venv/bin/python scripts/global_calibration.py      # docs/results/global_calibration.json,
                                                        # assets/figures/global_calibration_front.png
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

from docs_numbers import write_results  # noqa: E402
from threadpoolctl import threadpool_limits  # noqa: E402

from model import load_parameters  # noqa: E402
from model.studies.calibration import (  # noqa: E402
    PHASES,
    calibrated_set,
    stage_j_cost,
    with_divergence_weight,
)
from model.studies.calibration_bounds import SEARCH_PARAMETERS  # noqa: E402
from model.studies.calibration_targets import TABLE1_IM_HZ, evaluate  # noqa: E402
from model.studies.global_calibration import (  # noqa: E402
    StartResult,
    ranking_key,
    spread,
    target_measures,
)

RUN = ROOT / "assets" / "data" / "global_calibration_n16.json"
START = ROOT / "assets" / "parameters" / "calibration_start.toml"  # the search's start 0 and prior
FIGURE = ROOT / "assets" / "figures" / "global_calibration_front.png"


def starts_block(run: dict) -> str:
    lines = ["| start | stage J cost | largest \\|ΔIm\\| by rank | ranks within 5 % | characters "
             "| largest real at 0.014 [1/s] | its error against +7.031 | front |",
             "|---|---|---|---|---|---|---|---|"]
    done = [r for r in run["results"] if not r["failed"]]
    for r in sorted(done, key=lambda r: r["cost"]):
        mark = ("yes" if r["index"] in run["front"] else "") + (" (best)" if r["index"] == run["best"] else "")
        lines.append(f"| {r['index']} | {r['cost']:.1f} | {100 * r['frequency_error']:.1f} % | "
                     f"{r['ranks_within_5_percent']} | {r['characters']} | "
                     f"{r['largest_real_at_0.014']:+.2f} | {100 * r['divergence_error']:.1f} % | "
                     f"{mark.strip()} |")
    for r in run["results"]:
        if r["failed"]:
            lines.append(f"| {r['index']} | failed: {r['failed']} | | | | | | |")
    return "\n".join(lines)


def spread_block(run: dict) -> str:
    lines = ["| parameter | lowest | highest | share of the bounds | identified |", "|---|---|---|---|---|"]
    for s in run["spread"]:
        verdict = "no (held on a bound)" if s["on_bound"] else ("yes" if s["identified"] else "no")
        lines.append(f"| `{s['name']}` | {s['low']:.4g} | {s['high']:.4g} | "
                     f"{100 * s['share']:.0f} % | {verdict} |")
    return "\n".join(lines)


def start_results(run: dict) -> list[StartResult]:
    """The stored starts as the search's results (a failed start's missing numbers: inf, nan)."""
    return [StartResult(r["index"], r["start"], r["values"],
                        math.inf if r["cost"] is None else r["cost"],
                        math.inf if r["frequency_error"] is None else r["frequency_error"],
                        r["ranks_within_5_percent"], r["characters"],
                        math.nan if r["largest_real_at_0.014"] is None else r["largest_real_at_0.014"],
                        math.inf if r["divergence_error"] is None else r["divergence_error"],
                        r["seconds"], r["failed"]) for r in run["results"]]


def best_sobol_start(run: dict, starts: list[StartResult]) -> dict:
    """The best of the Sobol' starts (1 … N) by the search's own rule (ranking_key)."""
    index = min((s for s in starts if s.index > 0 and not s.failed), key=ranking_key).index
    return next(r for r in run["results"] if r["index"] == index)


def lowest_cost(run: dict) -> dict:
    """The start stage J's cost alone would rank first."""
    r = min((r for r in run["results"] if not r["failed"]), key=lambda r: r["cost"])
    return {"index": r["index"], "cost": r["cost"], "ranks_within": r["ranks_within_5_percent"],
            "frequency_error": r["frequency_error"],
            "divergence_error": r["divergence_error"]}


def comparison(run: dict, starts: list[StartResult]) -> dict:
    """The bundled set (start 0) against the best Sobol' start, target by target."""
    bundled = load_parameters()
    prior = load_parameters(START)
    weights = with_divergence_weight(PHASES, run.get("divergence_weight", 1.0))[-1][1]
    other = best_sobol_start(run, starts)
    with threadpool_limits(1):
        rows = evaluate(bundled)
        other_rows = evaluate(calibrated_set(other["values"], prior))
        cost = stage_j_cost(bundled, prior, weights, clip=False)

    def by_name(rows):
        return {row.name.split(" [")[0].replace(" OTHER CHARACTER:", ""): row for row in rows}

    others = by_name(other_rows)
    table = ["| target | published | bundled set (start 0) | best Sobol' start |",
             "|---|---|---|---|"]
    for name, row in by_name(rows).items():
        if name not in others:
            continue
        table.append(f"| {name} | {row.target:.5g} | {row.achieved:.5g} ({100 * row.error:+.1f} %) | "
                     f"{others[name].achieved:.5g} ({100 * others[name].error:+.1f} %) |")
    on_bound = {}
    for label, values in (("bundled", bundled.values), ("other", other["values"])):
        on_bound[label] = [f.name for f in SEARCH_PARAMETERS if f.on_bound(values[f.name])
                           or not f.low <= values[f.name] <= f.high]
    return {"bundled": {"cost": cost, **target_measures(rows),
                        "outside_or_on_bound": on_bound["bundled"]},
            "best_sobol": {"index": other["index"], "cost": other["cost"],
                           "frequency_error": other["frequency_error"],
                           "ranks_within": other["ranks_within_5_percent"],
                           "characters": other["characters"],
                           "largest_real_unstable": other["largest_real_at_0.014"],
                           "divergence_error": other["divergence_error"],
                           "outside_or_on_bound": on_bound["other"]},
            "block": "\n".join(table)}


def figure(run: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.2), dpi=110)
    for r in (r for r in run["results"] if not r["failed"]):
        on_front = r["index"] in run["front"]
        ax.scatter(100 * r["frequency_error"], 100 * r["divergence_error"],
                   color="tab:red" if on_front else "tab:blue", zorder=3)
        ax.annotate(str(r["index"]), (100 * r["frequency_error"], 100 * r["divergence_error"]),
                    textcoords="offset points", xytext=(4, 3), fontsize=8)
    front = sorted((r for r in run["results"] if r["index"] in run["front"]),
                   key=lambda r: r["frequency_error"])
    ax.plot([100 * r["frequency_error"] for r in front], [100 * r["divergence_error"] for r in front],
            color="tab:red", lw=1, label="front")
    ax.axvline(5, color="grey", ls=":", lw=1, label="5 % (Table 1 by rank)")
    ax.axhline(10, color="grey", ls="--", lw=1, label="10 % of +7.031 1/s")
    ax.set_xlabel("largest |ΔIm| of the ten pairs by rank at s0 = 0.005 [%]")
    ax.set_ylabel("largest real at s0 = 0.014 against +7.031 1/s [%]")
    ax.set_title(f"global calibration: start 0 and {run['starts']} Sobol' starts (number: "
                 "start index)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    FIGURE.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURE)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--run", default=str(RUN), help="stored output of bogie calibrate --starts N --json")
    args = parser.parse_args()
    run = json.loads(Path(args.run).read_text(encoding="utf-8"))
    # the spread by the module's rule as it stands (a parameter held on a bound by every best
    # start is not identified), from the stored starts
    starts = start_results(run)
    run["spread"] = [{"name": s.name, "low": s.low, "high": s.high, "share": s.share,
                      "identified": s.identified, "on_bound": s.on_bound} for s in spread(starts)]
    compared = comparison(run, starts)
    best = next(r for r in run["results"] if r["index"] == run["best"])
    identified = [s["name"] for s in run["spread"] if s["identified"]]
    held = [s["name"] for s in run["spread"] if s["on_bound"]]
    data = {"starts": run["starts"], "best": run["best"], "front": run["front"],
            "seconds": run["seconds"], "minutes": run["seconds"] / 60, "where": run["where"],
            "divergence_weight": run.get("divergence_weight", 1.0),
            "per_start_seconds_mean": sum(r["seconds"] for r in run["results"])
            / len(run["results"]),
            "runs": len(run["results"]),
            "failed": [r["index"] for r in run["results"] if r["failed"]],
            "failed_count": sum(bool(r["failed"]) for r in run["results"]),
            "identified": identified, "identified_count": len(identified),
            "held_on_bound": held, "held_count": len(held),
            "parameters": len(run["spread"]), "front_count": len(run["front"]),
            "best_start": {k: best[k] for k in best if k not in ("start", "values")},
            "lowest_cost": lowest_cost(run),
            "comparison": {k: v for k, v in compared.items() if k != "block"},
            "ranks_published": len(TABLE1_IM_HZ),
            "blocks": {"starts": starts_block(run), "spread": spread_block(run),
                       "comparison": compared["block"]}}
    path = write_results("global_calibration", data, "scripts/global_calibration.py")
    figure(run)
    print(f"wrote {path} and {FIGURE}")


if __name__ == "__main__":
    main()
