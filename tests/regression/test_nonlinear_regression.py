"""Golden regression of the nonlinear response: today's numbers against tests/golden/nonlinear.json.

Regenerate (after an intended change of the nonlinear model or of the calibrated parameters) with

    .venv/bin/python scripts/make_golden_nonlinear.py

and commit it with the change.  The model is rebuilt from the parameter values stored in the file,
so a change of calibrated.toml alone does not fail these tests.  Tolerance: 1e-7 of each output's
perturbation peak — the runs are deterministic; what may differ between machines is rounding in
the eigendecomposition (the closed form agrees with independent references to ~1e-7 of the peaks
at worst, docs/response.md), and 0.5 s of the nonlinear response does not amplify it measurably.
"""

from __future__ import annotations

import sys

import pytest
from conftest import ROOT, golden_parameters, load_golden

from model import build_model

ROOT = ROOT
GOLDEN_FILE = ROOT / "tests" / "golden" / "nonlinear.json"
REGENERATE = "regenerate with: .venv/bin/python scripts/make_golden_nonlinear.py"
RTOL = 1e-7


@pytest.fixture(scope="module")
def golden() -> dict:
    return load_golden(GOLDEN_FILE, REGENERATE)


@pytest.fixture(scope="module")
def golden_model(golden):
    parameters = golden_parameters(golden, GOLDEN_FILE, REGENERATE)
    return parameters, build_model(parameters)


def test_nonlinear_peaks_and_history(golden, golden_model):
    sys.path.insert(0, str(ROOT / "scripts"))
    from make_golden_nonlinear import run

    parameters, model = golden_model
    for case in golden["cases"]:
        r = run(model, parameters, case["s0"], case["anti_slip_delay"])
        for name, peak in case["peaks"].items():
            scale = abs(case["perturbation_peaks"][name])
            assert abs(r.peaks[name] - peak) <= RTOL * scale, (case["s0"], name, REGENERATE)
        assert (r.detection_time is None) == (case["detection_time"] is None)
        if r.detection_time is not None:
            assert r.detection_time == pytest.approx(case["detection_time"], abs=1e-9)
        for rim, value in case["creepage_max"].items():
            assert r.creepage[rim].max() == pytest.approx(value, abs=1e-9)
            assert r.creepage[rim].min() == pytest.approx(case["creepage_min"][rim], abs=1e-9)
        history = r.outputs["ID2.disc_clutch.torque"][:: round(0.05 * golden["fs"])]
        scale = abs(case["perturbation_peaks"]["ID2.disc_clutch.torque"])
        assert max(abs(a - b) for a, b in zip(history, case["ID2_disc_clutch_every_50ms"],
                                              strict=True)) <= RTOL * scale
