"""The worked example of docs/resonance.md: the Campbell diagram of the calibrated set at
s0 = 0.005 over 5…200 km/h with the default orders, the frequency response at 120 km/h and the
forced response to the illustrative ripple; the numbers the page quotes, written as JSON.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/example_resonance.py \
        [--out docs/results/resonance_example.json]

The same numbers come from ``bogie campbell --v 5:200:200 --json``, ``bogie frf --json`` and
``bogie ripple --v 5:200:196 --ripple el:6=256,el:12=128 --json`` (≈ 10 s).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from model import KMH, build_model, default_operating_point, load_parameters
from model.analysis.campbell import DEFAULT_PARTICIPATION, campbell, ripple_response, speeds_kmh
from model.analysis.frequency_response import MODEL_FREQUENCY_LIMIT_HZ, frequency_response
from model.mechanics.excitation import DEFAULT_ORDERS, load_excitation, parse_amplitudes, parse_orders

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))

from docs_numbers import write_results  # noqa: E402

RIPPLE = "el:6=256,el:12=128"  # app.results.resonance.DEFAULT_RIPPLE
DRIVE_TORQUES = ("ID1.driving_shaft.torque", "ID1.disc_clutch.torque", "ID2.driving_shaft.torque",
                 "ID2.disc_clutch.torque")


MODE_KEYS = (  # the modes the page discusses: a key each, found by the words of its description
    ("driving_shaft_1", ("twisting of driving shaft 1",)),
    ("driving_shaft_2", ("twisting of driving shaft 2",)),
    ("rotor_disc_clutch_1", ("torsion of rotor 1", "twisting of disc clutch 1")),
    ("frame_pitch", ("pitch of bogie frame with combined",)),
    ("frame_pitch_motors", ("pitch of bogie frame with TM",)),
    ("wheelsets_longitudinal", ("longitudinal of wheelset",)),
    ("motors_longitudinal_pitch", ("longitudinal–pitch of TM",)),
)


def mode_key(name: str) -> str | None:
    """The page's key of a mode (None: a mode the page does not discuss)."""
    for key, words in MODE_KEYS:
        if all(w in name for w in words):
            return key
    return None


def keyed(modes, crossings) -> tuple[dict, dict]:
    """The page's modes by key and their crossings by key and order (``frame_pitch.el:1``), so
    that the page's numbers do not depend on the order of the lists."""
    by_mode = {}
    for m in modes:
        key = mode_key(m["name"])
        if key is not None and key not in by_mode:
            by_mode[key] = m
    by_crossing = {}
    for c in crossings:
        key = mode_key(c["mode"])
        if key is not None:
            by_crossing.setdefault(f"{key}.{c['order']}", c)
    return by_mode, by_crossing


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=None,
                        help="JSON file (default: docs/results/resonance_example.json)")
    args = parser.parse_args()
    parameters = load_parameters()
    model = build_model(parameters)
    excitation = load_excitation()
    v = speeds_kmh(5, 200, 200)
    middle = default_operating_point(parameters, s0=0.005, v_kmh=float(0.5 * (5 + 200)))
    diagram = campbell(model, middle, v, parse_orders(DEFAULT_ORDERS), excitation)
    index_120 = int(np.argmin(np.abs(diagram.v_kmh - 120.0)))
    op = default_operating_point(parameters, s0=0.005, v_kmh=120.0)
    frf = frequency_response(model, op)
    ripple = ripple_response(model, op, speeds_kmh(5, 200, 196), parse_amplitudes(RIPPLE),
                             excitation)
    ripple_peaks = {}
    for name in DRIVE_TORQUES:
        peak, at = ripple.peak(name)
        ripple_peaks[name] = {"amplitude_Nm": peak, "v_kmh": at / KMH}
    data = {
        "operating_point": {"s0": op.s0, "N0": op.N0, "b_M": op.b_M},
        "excitation": {"motor_pole_pairs": excitation.pole_pairs,
                       "pinion_teeth": excitation.pinion_teeth,
                       "gear_ratio": parameters["gear_ratio"],
                       "wheel_radius": parameters["wheel_radius"]},
        "speeds_kmh": [float(diagram.v_kmh[0]), float(diagram.v_kmh[-1]), len(v)],
        "orders": DEFAULT_ORDERS, "participation": DEFAULT_PARTICIPATION,
        "model_frequency_limit_hz": MODEL_FREQUENCY_LIMIT_HZ,
        "campbell": {"basis_size": diagram.basis_size, "dense_points": diagram.dense_points},
        "modes_count": len(diagram.modes), "crossings_count": len(diagram.crossings),
        "modes": [{"name": m.name, "f_hz_5": float(m.f_hz[0]),
                   "f_hz_120": float(m.f_hz[index_120]), "f_hz_200": float(m.f_hz[-1]),
                   "zeta_120": float(m.zeta[index_120])} for m in diagram.modes],
        "crossings": [{"mode": c.mode, "order": c.order.name, "label": c.order.label,
                       "v_kmh": c.v_kmh, "f_hz": c.f_hz, "zeta": c.zeta,
                       "worst_output": c.worst[0], "severity": c.worst[1],
                       "severity_by_output": c.severity} for c in diagram.crossings],
        "frf_120kmh": {name: {"static_gain": float(abs(frf.static_gain[frf.output(name)])),
                              "peaks": [{"f_hz": p.f_hz, "abs": p.abs,
                                         "amplification": p.amplification}
                                        for p in frf.peaks[frf.output(name)]]}
                       for name in DRIVE_TORQUES},
        "ripple": {"text": RIPPLE, "peaks": ripple_peaks},
    }
    data["mode"], data["crossing"] = keyed(data["modes"], data["crossings"])
    if args.out is None:
        out = write_results("resonance_example", data, "scripts/example_resonance.py")
    else:
        out = Path(args.out)
        out.write_text(json.dumps(data, indent=1, allow_nan=False) + "\n", encoding="utf-8")
    print(f"wrote {out}: {len(diagram.modes)} modes, {len(diagram.crossings)} crossings")
    for c in diagram.crossings[:8]:
        print(f"  {c.v_kmh:7.2f} km/h {c.f_hz:8.3f} Hz {c.order.name:8s} ζ = {c.zeta:.4f} "
              f"{c.worst[1]:8.3g} N m/N m in {c.worst[0]}; {c.mode}")


if __name__ == "__main__":
    main()
