"""Write the golden regression file tests/golden/calibrated.json from a parameter set.

    .venv/bin/python scripts/make_golden.py                 # the calibrated default set
    .venv/bin/python scripts/make_golden.py --params FILE   # another set (same output file)

Stored (SI units; eigenvalues in 1/s): the parameter values themselves (so that the regression
test rebuilds exactly this model even after calibrated.toml moves on), the first 20 complex
eigenvalue pairs (upper half, by ascending imaginary part) and the 10 largest real eigenvalues at
s0 = 0.005 and 0.014, 120 km/h; the steady motor torque there [N m]; the stability limit s0* at
120 km/h; Frobenius norms of M, K, B and of the total damping at each point.

Regenerate after every intended change of the model or of the calibrated parameters, and
commit the JSON with the change that caused it.
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

from model import (  # noqa: E402
    build_model,
    damping_matrix,
    eigen_analysis,
    load_parameters,
    motor_torque,
    stability_limit,
)
from model.mechanics.operating_point import KMH, OperatingPoint  # noqa: E402
from model.mechanics.parameters import OPTIONAL_DEFAULTS, SCHEMA  # noqa: E402

GOLDEN_FILE = ROOT / "tests" / "golden" / "calibrated.json"
SPEED_KMH = 120.0
CREEPAGES = (0.005, 0.014)
N_COMPLEX = 20
N_REAL = 10
COMMAND = ".venv/bin/python scripts/make_golden.py"


def golden_data(parameters) -> dict:
    model = build_model(parameters)
    N0, b_M = parameters["wheel_force"], parameters["motor_slope"]
    points = []
    for s0 in CREEPAGES:
        op = OperatingPoint.from_kmh(s0, SPEED_KMH, N0, b_M)
        result = eigen_analysis(model, op, vectors=False)
        complex_pairs = result.complex_pairs[:N_COMPLEX]
        points.append({
            "s0": s0, "v_kmh": SPEED_KMH, "N0": N0, "b_M": b_M,
            "complex": [[float(z.real), float(z.imag)] for z in complex_pairs],
            "real": [float(x) for x in result.real_eigenvalues[:N_REAL]],
            "max_real_part": result.max_real_part,
            "stable": result.stable,
            "motor_torque": motor_torque(parameters, op),
            "damping_fro": float(np.linalg.norm(damping_matrix(model, op))),
        })
    limit = stability_limit(model, SPEED_KMH * KMH, N0, b_M)
    return {
        "about": "golden regression data of the calibrated set; regenerate with: " + COMMAND,
        "generated_with": {"python": platform.python_version(), "numpy": np.__version__,
                           "scipy": scipy.__version__},
        "parameter_source": Path(parameters.source).name,
        # the values the dynamics depend on (a parameter at its optional default and the
        # strength data left out: a reader takes their defaults)
        "parameters": {name: value for name, value in parameters.values.items()
                       if name in SCHEMA and not (name in OPTIONAL_DEFAULTS
                                                  and value == OPTIONAL_DEFAULTS[name])},
        "operating_points": points,
        "stability_limit": {"v_kmh": SPEED_KMH, "N0": N0, "b_M": b_M,
                            "s0_limit": limit.s0_limit},
        "norms": {"M_fro": float(np.linalg.norm(model.M)), "K_fro": float(np.linalg.norm(model.K)),
                  "B_fro": float(np.linalg.norm(model.B)), "n_dof": model.n},
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--params", default=None, help="parameter file (default: calibrated)")
    parser.add_argument("--out", default=str(GOLDEN_FILE), help="output JSON file")
    args = parser.parse_args(argv)
    with threadpool_limits(1):  # as the tests do; also ~50x faster when other jobs share the CPU
        data = golden_data(load_parameters(args.params))
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(data, indent=1, allow_nan=False) + "\n", encoding="utf-8")
    print(f"wrote {out}: s0*(120 km/h) = {data['stability_limit']['s0_limit']:.6f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
