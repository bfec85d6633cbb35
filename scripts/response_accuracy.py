"""How exact the closed-form short-circuit response is: the numbers of docs/response.md's
"Choice", "Measured accuracy" sections.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/response_accuracy.py [--points 120]

Writes ``docs/results/response_accuracy.json``:

* ``reference``: the closed form against exact stepping of the *exported* system (the
  independent reference of ``tests/model/analysis/test_response_model.py``, imported from there),
  every output, 0…1 s at 2 kHz, s0 = 0.005 and 0.014 at 120 km/h: the largest error relative to
  each output's peak and which output has it;
* ``limit_scan``: around the stability limit s0* (relative offsets −1e-2 … +1e-2, 0.5 s at
  2 kHz): the modal form's rounding estimate and its error against the augmented-exponential
  form, and which form the automatic choice takes;
* ``operating_range``: ``--points`` random operating points and excitations over the dashboard's
  slider ranges (seed 2): the automatic choice against the augmented-exponential form, the
  largest and the median of the per-point errors, how often the modal form was taken.
"""

from __future__ import annotations

import argparse
import importlib.util
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

from docs_numbers import write_results  # noqa: E402

from model import build_model, default_operating_point, load_parameters  # noqa: E402
from model.analysis.export import export_system  # noqa: E402
from model.analysis.response import ShortCircuit, short_circuit_response  # noqa: E402
from model.analysis.stability import stability_limit  # noqa: E402
from model.mechanics.operating_point import OperatingPoint  # noqa: E402

OFFSETS = (-1e-2, -1e-3, -1e-4, -1e-5, 0.0, 1e-5, 1e-4, 1e-3, 1e-2)


def _reference_module():
    path = ROOT / "tests" / "model" / "analysis" / "test_response_model.py"
    spec = importlib.util.spec_from_file_location("response_reference", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def worst_relative(a, b_outputs) -> tuple[float, str]:
    """max over outputs of max|Δy_a − Δy_b| / max|Δy_b|, and that output."""
    worst, which = 0.0, ""
    for name, reference in b_outputs.items():
        scale = np.abs(reference).max()
        if scale == 0:
            continue
        error = np.abs(a.perturbation(name) - reference).max() / scale
        if error > worst:
            worst, which = float(error), name
    return worst, which


def against_reference(model, parameters, reference) -> dict:
    result = {}
    with tempfile.TemporaryDirectory() as folder:
        for s0 in (0.005, 0.014):
            op = default_operating_point(parameters, s0)
            path = Path(folder) / "system.npz"
            export_system(model, op, path)
            response = short_circuit_response(model, op, ShortCircuit(), 1.0, 2000.0)
            names, y = reference.exported_reference(path, ShortCircuit(), response.phase_shift,
                                                    1.0, 2000.0)
            worst, which = worst_relative(response, {n: y[:, j] for j, n in enumerate(names)})
            others = [np.abs(response.perturbation(n) - y[:, j]).max() / np.abs(y[:, j]).max()
                      for j, n in enumerate(names) if n != which and np.abs(y[:, j]).max() > 0]
            result[f"{s0:g}"] = {"method": response.method, "worst": worst, "worst_output": which,
                                 "worst_output_peak": float(np.abs(response.perturbation(which)).max()),
                                 "second": float(max(others))}
    return result


def limit_scan(model, parameters) -> dict:
    op0 = default_operating_point(parameters, 0.005)
    limit = stability_limit(model, op0.v, op0.N0, op0.b_M).s0_limit
    rows = []
    for offset in OFFSETS:
        op = default_operating_point(parameters, limit * (1.0 + offset))
        modal = short_circuit_response(model, op, ShortCircuit(), 0.5, 2000.0, method="modal")
        exact = short_circuit_response(model, op, ShortCircuit(), 0.5, 2000.0, method="expm")
        auto = short_circuit_response(model, op, ShortCircuit(), 0.5, 2000.0)
        error, _ = worst_relative(modal, {n: exact.perturbation(n) for n in exact.outputs})
        rows.append({"offset": offset, "estimate": modal.error_estimate, "modal_error": error,
                     "auto_method": auto.method})
    def short(x: float, digits: int = 1) -> str:  # 1.4e-9, not 1.4e-09
        mantissa, exponent = f"{x:.{digits}e}".split("e")
        return f"{mantissa}e{int(exponent)}"

    cells = lambda key: " | ".join(short(r[key]) for r in rows)  # noqa: E731
    table = "\n".join([
        "| s0 / s0* − 1 | " + " | ".join("0" if r["offset"] == 0 else
                                          ("+" if r["offset"] > 0 else "−") + short(abs(r["offset"]), 0)
                                          for r in rows) + " |",
        "|---|" + "---|" * len(rows),
        "| estimate | " + cells("estimate") + " |",
        "| modal error | " + cells("modal_error") + " |",
        "| automatic choice | " + " | ".join(r["auto_method"] for r in rows) + " |"])
    modal = [r for r in rows if r["auto_method"] == "modal"]
    return {"s0_limit": limit, "rows": rows, "table": table,
            "estimate_at_limit": rows[OFFSETS.index(0.0)]["estimate"],
            "error_at_limit": rows[OFFSETS.index(0.0)]["modal_error"],
            "error_where_modal_max": max((r["modal_error"] for r in modal), default=None),
            "expm_band": max((abs(r["offset"]) for r in rows if r["auto_method"] == "expm"),
                             default=0.0),
            "estimate_far": min(r["estimate"] for r in rows)}


def operating_range(model, points: int) -> dict:
    rng = np.random.default_rng(2)
    errors, modal = [], 0
    for _ in range(points):
        op = OperatingPoint.from_kmh(rng.uniform(0.0005, 0.03), rng.uniform(10.0, 250.0),
                                     rng.uniform(40e3, 160e3), rng.uniform(0.0, 20_000.0))
        excitation = ShortCircuit(M0=rng.uniform(0.0, 200e3), f=rng.uniform(10.0, 300.0),
                                  D=rng.uniform(0.0, 0.3))
        fs = max(2000.0, 20.0 * excitation.f)
        auto = short_circuit_response(model, op, excitation, 0.5, fs)
        exact = short_circuit_response(model, op, excitation, 0.5, fs, method="expm")
        modal += auto.method == "modal"
        errors.append(worst_relative(auto, {n: exact.perturbation(n) for n in exact.outputs})[0])
    return {"points": points, "modal": modal, "max": float(np.max(errors)),
            "median": float(np.median(errors))}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=120, help="random operating points")
    args = parser.parse_args()
    parameters = load_parameters()
    model = build_model(parameters)
    data = {"reference": against_reference(model, parameters, _reference_module())}
    print(data["reference"], flush=True)
    data["limit_scan"] = limit_scan(model, parameters)
    print(data["limit_scan"]["table"], flush=True)
    data["operating_range"] = operating_range(model, args.points)
    print(data["operating_range"])
    print(f"wrote {write_results('response_accuracy', data, 'scripts/response_accuracy.py')}")


if __name__ == "__main__":
    main()
