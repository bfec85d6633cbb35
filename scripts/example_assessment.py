"""The worked example of docs/assessment.md: `bogie assess` at the default set, every load case,
the governing check and what qualifies the loads (the short circuit's horizon, the adhesion note,
the starting case's bound).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/example_assessment.py

Writes ``docs/results/assessment.json`` (every number the page quotes; the same as
``bogie assess --no-running --serial --json``: the four cases the Verdicts tab computes by
default; the running case's numbers come from ``scripts/example_running.py``) in a few seconds.
"""

from __future__ import annotations

import sys
from pathlib import Path

from model import load_parameters
from model.studies.assessment import (
    AssessmentOptions,
    assess,
    assessed_outputs,
    assessment_of,
    ripple_case,
)

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))

from docs_numbers import write_results  # noqa: E402

BANDWIDTHS_HZ = (0.0, 10.0, 50.0)  # the converter's torque control: none, a slow and a fast one


def ripple_summary(result) -> dict:
    """The ripple case's checks by key (component and kind: its worst speed, mean, amplitude and
    safety factor) and its check of least margin."""
    checks = [c for c in result.checks if c.load_case == "ripple"]
    worst = max(checks, key=lambda c: c.utilisation)
    return {"checks": {f"{c.component.replace(' ', '_')}.{c.kind}": {
        "v_kmh": c.v_kmh, "mean": c.mean, "alternating": c.alternating,
        "safety_factor": c.safety_factor, "required": c.required} for c in checks},
        "least_margin": {"component": worst.component, "kind": worst.kind,
                         "v_kmh": worst.v_kmh, "safety_factor": worst.safety_factor}}


def main() -> None:
    parameters = load_parameters()
    result = assess(parameters)
    data = result.as_dict()
    cases = {case.name: case for case in result.cases}
    data["horizon_s"] = {name: case.horizon for name, case in cases.items()}
    starting = cases["starting"].scenario
    r0, n = parameters["wheel_radius"], parameters["driven_wheelsets"]
    data["starting"] = {"bound": starting["bound"],
                        "motors_wheelset_torque": parameters["starting_traction_force"] * r0 / n,
                        "adhesion_wheelset_torque": 2 * starting["mu_max"] * starting["N0"] * r0,
                        "s0": starting["s0"]}
    data["short_circuit_beyond_adhesion"] = cases["short_circuit"].scenario["beyond_adhesion"]
    g = result.governing
    data["governing_summary"] = {"component": g.component, "load_case": g.load_case,
                                 "safety_factor": g.safety_factor, "required": g.required}
    data["ripple"] = ripple_summary(result)
    data["ripple_bandwidth"] = {f"{f_c:g}": ripple_summary(assessment_of(
        parameters.replace(motor_bandwidth=f_c),
        [ripple_case(parameters.replace(motor_bandwidth=f_c), assessed_outputs(parameters),
                     AssessmentOptions())]))
        for f_c in BANDWIDTHS_HZ}
    print(f"governing: {g.component} in {g.load_case}: {g.safety_factor:.3g} (required "
          f"{g.required:.3g}); horizons {data['horizon_s']}")
    print(f"wrote {write_results('assessment', data, 'scripts/example_assessment.py')}")


if __name__ == "__main__":
    main()
