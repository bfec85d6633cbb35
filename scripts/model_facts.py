"""The model's layout and sizes, and the design-variant example of README.md and
docs/own-bogie.md, as numbers the pages quote.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/model_facts.py     # docs/results/model.json

* ``layout``: coordinates per subsystem, the massless ones, the states of the first-order form
  and how many remain after the rigid-body modes are deflated, the rigid-body modes;
* ``masses``: a drive with its wheelset (longitudinal mass of its coordinates), the frame, the
  half car body, the bogie [kg];
* ``operating``: the creep coefficients at 120 km/h (b11 at s0 = 0.005 and 0.014, the steepest
  N0 μ'/v at s ≈ 0) and the rotor speed;
* ``variant``: the driving shaft 30 % softer (``driving_shaft_stiffness`` × 0.7, rounded to
  10⁴ N m/rad as a user would type it) against the
  bundled set at s0 = 0.005, 120 km/h — what ``bogie compare`` and the dashboard's Variant tab
  show (:func:`model.studies.compare.compare_designs`).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

from docs_numbers import write_results  # noqa: E402

from model import KMH, OperatingPoint, build_model, creep_coefficients, load_parameters  # noqa: E402
from model.analysis.eigen import bogie_system  # noqa: E402
from model.studies.compare import compare_designs  # noqa: E402

SOFTER = 0.7  # the variant's driving shaft stiffness / the bundled one (rounded to 10⁴ N m/rad)


def layout(model, op) -> dict:
    names = model.dofs.names
    system = bogie_system(model, op)
    subsystems: dict[str, int] = {}
    for name in names:
        key = name.split(".")[0]
        subsystems[key] = subsystems.get(key, 0) + 1
    rims = sum(1 for name in names if ".rim" in name)
    return {"coordinates": len(names), "by_subsystem": subsystems,
            "massless": len(system.massless), "inertial": len(system.inertial),
            "states": int(system.N), "deflated_states": len(system.eigen[0]),
            "rigid_body_modes": int(model.rigid_body_modes.shape[1]),
            "rim_coordinates": rims, "rigid_wheel_coordinates": len(names) - rims}


def masses(model, parameters) -> dict:
    names = model.dofs.names
    along_x = np.array([1.0 if name.endswith(".x") else 0.0 for name in names])

    def mass(prefix: str) -> float:
        chosen = along_x * np.array([name.startswith(prefix) for name in names])
        return float(chosen @ model.M @ chosen)

    return {"drive_with_wheelset": mass("ID1."), "drive_2_with_wheelset": mass("ID2."),
            "frame": parameters["frame_mass"], "half_car_body": parameters["car_body_mass"],
            "bogie": mass("ID1.") + mass("ID2.") + parameters["frame_mass"]}


def operating(model, parameters) -> dict:
    N0, b_M = parameters["wheel_force"], parameters["motor_slope"]
    result = {}
    for s0 in (0.005, 0.014, 1e-9):
        c = creep_coefficients(parameters, OperatingPoint(s0, 120 * KMH, N0, b_M))
        result[f"b11_{s0:g}"] = float(c.b11)
        result[f"dmu_ds_{s0:g}"] = float(c.dmu_ds)
    result["rotor_speed_120"] = float(parameters["gear_ratio"] * 120 * KMH / parameters["wheel_radius"])
    return result


def variant(parameters) -> dict:
    stiffness = round(SOFTER * parameters["driving_shaft_stiffness"], -4)  # as the page writes it
    softer = parameters.replace(driving_shaft_stiffness=stiffness)
    comparison = compare_designs(parameters, softer, 0.005, 120.0).as_dict()
    base, other = comparison["base"], comparison["variant"]
    frequency_change = max(abs(b["im_hz"] / a["im_hz"] - 1)
                           for a, b in zip(base["pairs"], other["pairs"], strict=True))
    return {"factor": SOFTER, "s0": 0.005, "v_kmh": 120.0,
            "stiffness_base": parameters["driving_shaft_stiffness"],
            "stiffness_variant": softer["driving_shaft_stiffness"],
            "base": {"s0_limit": base["s0_limit"], "max_real_part": base["max_real_part"],
                     "peak_loads": base["peak_loads"], "peak_times": base["peak_times"]},
            "variant": {"s0_limit": other["s0_limit"], "max_real_part": other["max_real_part"],
                        "peak_loads": other["peak_loads"], "peak_times": other["peak_times"]},
            "s0_limit_change": abs(other["s0_limit"] - base["s0_limit"]),
            "largest_frequency_change_ten_pairs": frequency_change}


def main() -> None:
    parameters = load_parameters()
    model = build_model(parameters)
    op = OperatingPoint(0.005, 120 * KMH, parameters["wheel_force"], parameters["motor_slope"])
    data = {"layout": layout(model, op), "masses": masses(model, parameters),
            "operating": operating(model, parameters), "variant": variant(parameters)}
    print(data["layout"], data["masses"], data["operating"], sep="\n")
    example = data["variant"]
    print("variant: ID1 driving shaft peak {:.4g} -> {:.4g} N m; s0* {:.6f} -> {:.6f}".format(
        example["base"]["peak_loads"]["ID1.driving_shaft.torque"],
        example["variant"]["peak_loads"]["ID1.driving_shaft.torque"],
        example["base"]["s0_limit"], example["variant"]["s0_limit"]))
    print(f"wrote {write_results('model', data, 'scripts/model_facts.py')}")


if __name__ == "__main__":
    main()
