"""The numbers docs/model.md, docs/resonance.md and docs/assessment.md quote about the rail–wheel
irregularities on the calibrated set: the running system's suspension mode and where it grows,
the random track's level and a drive torque's RMS, the running load case's least margin; written
as JSON.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/example_running.py

The same numbers come from ``bogie track --s0 0.002 --v 120 --json`` and ``bogie assess --json``
(its running case; the running case alone: ``model.studies.assessment.assess`` with ``cases=("running",)``,
≈ 40 s).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from model import build_model, default_operating_point, load_parameters
from model.analysis.eigen import bogie_system, non_neutral, running_system
from model.analysis.track_spectrum import LOW, random_response
from model.studies.assessment import AssessmentOptions, assess

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))

from docs_numbers import write_results  # noqa: E402

SUSPENSION_BAND_HZ = (1.0, 2.0)  # where the slow suspension mode of the calibrated set lies


def suspension_mode(lam: np.ndarray) -> complex:
    """The least damped complex eigenvalue with its frequency in :data:`SUSPENSION_BAND_HZ`."""
    f = lam.imag / (2 * math.pi)
    inside = lam[(f > SUSPENSION_BAND_HZ[0]) & (f < SUSPENSION_BAND_HZ[1])]
    return complex(inside[np.argmax(inside.real)])


def growth(lam: np.ndarray) -> float:
    return float(lam[non_neutral(lam)].real.max())


def main() -> None:
    parameters = load_parameters()
    model = build_model(parameters)
    study = bogie_system(model, default_operating_point(parameters, 0.005, 120.0)).eigen[0]
    running = {v: running_system(model, default_operating_point(parameters, 0.005, v),
                                 cached=False).eigen[0] for v in (60.0, 70.0, 120.0, 200.0)}
    mode_study, mode_running = suspension_mode(study), suspension_mode(running[120.0])
    stable_002 = {v: growth(running_system(model, default_operating_point(parameters, 0.002, v),
                                           cached=False).eigen[0]) for v in (40.0, 120.0, 200.0)}
    op = default_operating_point(parameters, 0.002, 120.0)
    random = random_response(model, op, LOW, outputs=["ID1.disc_clutch.torque"])
    result = assess(parameters, AssessmentOptions(cases=("running",)))
    g = result.governing
    data = {
        "suspension_mode": {"f_hz": mode_study.imag / (2 * math.pi), "re_study": mode_study.real,
                            "re_running_120": mode_running.real},
        "growth_s0_005": {f"{v:g}": growth(lam) for v, lam in running.items()},
        "growth_s0_002": {f"{v:g}": g_ for v, g_ in stable_002.items()},
        "track_rms_mm": math.sqrt(LOW.variance()) * 1e3,
        "random_120": {"disc_clutch_1_rms": float(random.rms[0]),
                                "stable": random.stable},
        "running_case": {"governing": g.component, "kind": g.kind,
                         "safety_factor": g.safety_factor, "required": g.required,
                         "v_kmh": g.v_kmh, "rms": g.rms, "amplitude": g.amplitude,
                         "mean": g.mean, "alternating": g.alternating,
                         "all_ok": all(c.ok for c in result.checks)},
    }
    out = write_results("running", data, "scripts/example_running.py")
    print(f"wrote {out}: governing {g.component} S = {g.safety_factor:.3g} at {g.v_kmh:g} km/h")


if __name__ == "__main__":
    main()
