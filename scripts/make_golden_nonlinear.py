"""Write the golden regression file tests/golden/nonlinear.json (the nonlinear response, docs/nonlinear.md).

    .venv/bin/python scripts/make_golden_nonlinear.py                 # the calibrated default set
    .venv/bin/python scripts/make_golden_nonlinear.py --params FILE   # another set

Stored (SI units): the parameter values themselves (the regression test rebuilds exactly this
model), and for s0 = 0.005 and 0.014 at 120 km/h, 0.5 s at 10 kHz, default excitation: every
output's peak (total) and perturbation peak of the nonlinear response without protection and
with the default anti-slip protection at a delay of 0.05 s, its detection time, each wheel's
creepage extremes, and ID2's disc clutch torque every 50 ms.  Regenerate after an intended change
of the nonlinear model or of the calibrated parameters, and commit the JSON with that change.
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
from pathlib import Path

import numpy as np
import scipy
from threadpoolctl import threadpool_limits

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from model import build_model, load_parameters  # noqa: E402
from model.analysis.nonlinear import AntiSlip, nonlinear_response  # noqa: E402
from model.analysis.response import ShortCircuit  # noqa: E402
from model.mechanics.operating_point import OperatingPoint  # noqa: E402

GOLDEN_FILE = ROOT / "tests" / "golden" / "nonlinear.json"
COMMAND = ".venv/bin/python scripts/make_golden_nonlinear.py"
CASES = ((0.005, None), (0.014, None), (0.014, 0.05))  # (s0, anti-slip delay [s] or None)
T_END, FS = 0.5, 10_000.0


def run(model, parameters, s0: float, delay: float | None):
    op = OperatingPoint.from_kmh(s0, 120.0, parameters["wheel_force"], parameters["motor_slope"])
    protection = None if delay is None else AntiSlip(delay=delay)
    return nonlinear_response(model, op, ShortCircuit(), T_END, FS, anti_slip=protection)


def golden_data(parameters) -> dict:
    model = build_model(parameters)
    cases = []
    for s0, delay in CASES:
        r = run(model, parameters, s0, delay)
        every = round(0.05 * FS)
        cases.append({
            "s0": s0, "v_kmh": 120.0, "anti_slip_delay": delay,
            "peaks": r.peaks, "perturbation_peaks": r.perturbation_peaks,
            "detection_time": r.detection_time,
            "creepage_min": {k: float(v.min()) for k, v in r.creepage.items()},
            "creepage_max": {k: float(v.max()) for k, v in r.creepage.items()},
            "ID2_disc_clutch_every_50ms": r.outputs["ID2.disc_clutch.torque"][::every].tolist(),
        })
    return {
        "about": "golden regression data of the nonlinear response; regenerate with: " + COMMAND,
        "generated_with": {"python": platform.python_version(), "numpy": np.__version__,
                           "scipy": scipy.__version__},
        "parameter_source": Path(parameters.source).name,
        "parameters": dict(parameters.values),
        "t_end": T_END, "fs": FS, "cases": cases,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--params", default=None)
    args = parser.parse_args()
    with threadpool_limits(1):
        data = golden_data(load_parameters(args.params))
    GOLDEN_FILE.write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")
    print(f"wrote {GOLDEN_FILE}")


if __name__ == "__main__":
    main()
