"""Regenerate everything numeric that follows the default parameter set or the model, then the
numbers quoted in the pages.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/regenerate_docs_results.py          # all
    .venv/bin/python scripts/regenerate_docs_results.py --no-app     # without Chromium (no screenshots)
    .venv/bin/python scripts/regenerate_docs_results.py --only validation,response
    .venv/bin/python scripts/regenerate_docs_results.py --list       # the steps, what each writes
    .venv/bin/python scripts/regenerate_docs_results.py --pages-only # only rewrite the pages

Run it after a change of the model or of ``assets/parameters/calibrated.toml`` (``bogie calibrate
--out assets/parameters/calibrated.toml``).  The steps run in dependency order, each a script of
``scripts/`` (or a ``bogie`` command) in its own process; the results files go to
``docs/results/*.json``, figures to ``assets/figures``, screenshots to ``assets/screenshots``,
golden data to ``tests/golden``, stored studies to ``assets/data``.  Then every tagged number and
block of README.md and docs/*.md is rewritten from the results (``scripts/docs_numbers.py
--update``, same digits as before) and what it cannot rewrite is listed: a bound ("within
0.05 %") the new value breaks, a key that is gone.  Read ``git diff`` afterwards: a sentence
around a number may need new words (≈ 40 min on two cores, most of it the nonlinear runs and
the screenshots).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))

from docs_numbers import check_pages  # noqa: E402


@dataclass(frozen=True)
class Step:
    name: str
    commands: tuple[tuple[str, ...], ...]
    writes: str
    needs_browser: bool = False


def _python(script: str, *arguments: str) -> tuple[str, ...]:
    return (sys.executable, f"scripts/{script}", *arguments)


def _bogie(*arguments: str) -> tuple[str, ...]:
    return (sys.executable, "-m", "app", *arguments)


SPEEDS = "40,80,120,160,200,250"
STEPS = (
    Step("golden", (_python("make_golden.py"), _python("make_golden_nonlinear.py")),
         "tests/golden/*.json (regression data)"),
    Step("uncertainty", (
        _bogie("uncertainty", "--samples", "16", "--out", "assets/data/uncertainty_n16.json"),
        _bogie("uncertainty", "--samples", "32", "--no-indices", "--speeds", SPEEDS,
               "--out", "assets/data/uncertainty_no-indices_n32.json"),
        _bogie("uncertainty", "--samples", "32", "--posterior", "--speeds", SPEEDS,
               "--out", "assets/data/uncertainty_posterior_n32.json")),
         "assets/data/uncertainty_*.json (stored studies the dashboard and docs/sensitivity.md use)"),
    Step("model", (_python("model_facts.py"),),
         "docs/results/model.json (layout, sizes, masses, the variant example)"),
    Step("parameters", (_python("parameter_schema.py"),),
         "docs/results/parameters.json (the parameter file's schema, docs/own-bogie.md)"),
    Step("dashboard", (_python("dashboard_controls.py"),),
         "docs/results/dashboard.json (the dashboard's controls, README.md)"),
    Step("memory", (_python("memory_model.py"),),
         "docs/results/memory.json (the results cache's entries, docs/memory.md)"),
    Step("validation", (_python("validation_table.py"),),
         "docs/results/validation.json (Table 1 by rank, targets, real eigenvalues)"),
    Step("global-calibration", (_python("global_calibration.py"),),
         "docs/results/global_calibration.json, assets/figures/global_calibration_front.png (from "
         "the stored run assets/data/global_calibration_n16.json; the search itself: bogie "
         "calibrate --starts 16, docs/validation.md)"),
    Step("bundled-set", (_python("bundled_set.py"),),
         "docs/results/bundled_set.json, assets/figures/divergence_trade.png (the calibration by "
         "divergence weight, the rule's choice, the previous bundled set against the bundled one)"),
    Step("bound-lifting", (_python("bound_lifting.py"),),
         "docs/results/bound_lifting.json (the bundled set's calibration with each bound it sits "
         "on moved out of the hardware range)"),
    Step("reachability", (_python("reachability.py"),),
         "docs/results/reachability.json (the reduced models of the study's contradictions)"),
    Step("response", (_python("figures_response.py"),),
         "docs/results/response.json, assets/figures/response_*.png"),
    Step("response-accuracy", (_python("response_accuracy.py"),),
         "docs/results/response_accuracy.json (the closed form against exact references)"),
    Step("nonlinear", (_python("figures_nonlinear.py"),),
         "docs/results/nonlinear.json, assets/figures/nonlinear_*.png"),
    Step("sensitivity", (_python("figures_sensitivity.py"),),
         "docs/results/sensitivity.json, assets/figures/sensitivity_*.png, uncertainty_limit.png"),
    Step("posterior", (_python("figures_posterior.py"),),
         "docs/results/posterior.json, assets/figures/uncertainty_prior_posterior.png"),
    Step("posterior-app", (_python("figures_posterior.py", "--app"),),
         "assets/figures/uncertainty_band_app.png (Chromium)", needs_browser=True),
    Step("design-loads", (_python("example_design_loads.py"),),
         "docs/results/design_loads.json (the worked example of docs/design-loads.md)"),
    Step("resonance", (_python("example_resonance.py"),),
         "docs/results/resonance_example.json (the worked example of docs/resonance.md)"),
    Step("running", (_python("example_running.py"),),
         "docs/results/running.json (the running system, the random track, the running case)"),
    Step("assessment", (_python("example_assessment.py"), _python("example_verdict_uncertainty.py")),
         "docs/results/assessment.json, verdict_uncertainty.json (docs/assessment.md's examples)"),
    Step("life", (_python("example_life.py"),),
         "docs/results/life.json (docs/assessment.md's fatigue life over the bundled route)"),
    Step("screenshots", (_python("bench_app.py", "--only-screenshots"),
                         _python("screenshot_design_loads.py"), _python("screenshot_resonances.py")),
         "assets/screenshots/*.png (Chromium)", needs_browser=True),
)


def run_step(step: Step, env: dict) -> float:
    began = time.perf_counter()
    for command in step.commands:
        shown = " ".join(command[1:]) if command[0] == sys.executable else " ".join(command)
        print(f"  $ {shown}", flush=True)
        subprocess.run(command, cwd=ROOT, env=env, check=True)
    return time.perf_counter() - began


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", default=None, help="comma list of steps (see --list)")
    parser.add_argument("--skip", default="", help="comma list of steps to leave out")
    parser.add_argument("--no-app", action="store_true", help="leave out the steps that need Chromium")
    parser.add_argument("--list", action="store_true", help="list the steps and exit")
    parser.add_argument("--pages-only", action="store_true",
                        help="run no step: rewrite the pages from the results files as they are")
    args = parser.parse_args(argv)
    names = [step.name for step in STEPS]
    if args.list:
        for step in STEPS:
            print(f"{step.name:<14} {step.writes}")
        return 0
    chosen = names if args.only is None else [n.strip() for n in args.only.split(",") if n.strip()]
    skipped = {n.strip() for n in args.skip.split(",") if n.strip()}
    unknown = sorted((set(chosen) | skipped) - set(names))
    if unknown:
        print(f"regenerate_docs_results.py: error: unknown step(s) {', '.join(unknown)}; "
              f"known: {', '.join(names)}", file=sys.stderr)
        return 2
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    if not args.pages_only:
        for step in STEPS:
            if step.name not in chosen or step.name in skipped or (args.no_app and step.needs_browser):
                continue
            print(f"=== {step.name}: {step.writes}", flush=True)
            print(f"    {run_step(step, env):.0f} s", flush=True)
    found, count = check_pages(update=True)
    remaining, _ = check_pages()
    print(f"=== pages: {count} tagged numbers and blocks, {len(found) - len(remaining)} rewritten, "
          f"{len(remaining)} left to edit by hand")
    for item in remaining:
        print(f"  {item}")
    return 1 if remaining else 0


if __name__ == "__main__":
    sys.exit(main())
