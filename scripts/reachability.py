"""The numbers of docs/validation.md's "Which published numbers a bogie can reach together":
the reduced models of :mod:`model.studies.reachability` for the bundled set.

    .venv/bin/python scripts/reachability.py            # docs/results/reachability.json

(a) the two-inertia torsional chain of mode 2 against each published divergence (+7.031 and
+0.062 1/s at s0 = 0.014), over the plausible J1/J2, disc clutch damping and motor slope;
(b) the suspension modes' real parts (car body bounce, frame pitch, frame bounce) with the
vertical dampers at their hardware bounds, and the dampers each published real part needs.
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

from docs_numbers import write_results  # noqa: E402
from threadpoolctl import threadpool_limits  # noqa: E402

from model import load_parameters  # noqa: E402
from model.studies.calibration_targets import DIVERGENCE_RATES  # noqa: E402
from model.studies.reachability import suspension_proof, torsional_chain_proof  # noqa: E402

POINTS = 5  # values per scanned quantity (5^5 = 3 125 chains per divergence)


def _case(case) -> dict:
    return {"J_rotor": case.J_rotor, "gear_ratio": case.gear_ratio, "J1": case.J1, "J2": case.J2,
            "zeta_disc_clutch": case.zeta_dc, "motor_slope": case.motor_slope,
            "c_unstable": case.c_unstable, "re_unstable": case.re_unstable,
            "re_stable_least": case.re_stable_least, "difference": case.difference,
            "f_unstable_hz": case.frequency_unstable_hz, "f_stable_hz": case.frequency_stable_hz}


def chain_numbers(parameters) -> dict:
    out = {}
    for rate, key in zip(DIVERGENCE_RATES, ("spin_7.031", "spin_0.062"), strict=True):
        proof = torsional_chain_proof(parameters["gear_inertia"], parameters["pinion_inertia"],
                                      rate, POINTS)
        inside = proof.within_bounds()
        zero = [c for c in proof.cases if c.motor_slope == 0]
        mode2, mode2_zero = proof.with_mode2_frequency(), proof.with_mode2_frequency(zero)
        entry = {
            "spin_rate": rate, "scanned": proof.scanned, "oscillating": len(proof.cases),
            "within_bounds": len(inside), "reachable": proof.reachable,
            "published_difference": proof.published_difference,
            "f_unstable_max_hz": max(c.frequency_unstable_hz for c in inside),
            "re_stable_least_max": max(c.re_stable_least for c in inside),
            "re_stable_least_max_b0": max(c.re_stable_least for c in zero),
            "with_mode2_frequency": len(mode2), "with_mode2_frequency_b0": len(mode2_zero),
            "mode2_always_less_damped_at_0.014": all(c.difference > 0 for c in mode2 + mode2_zero)}
        for suffix, cases in (("", mode2), ("_b0", mode2_zero)):
            if cases:
                least = proof.least(cases)
                entry["least" + suffix] = _case(least)
                entry["least_difference" + suffix] = least.difference
                entry["margin" + suffix] = least.difference - proof.published_difference
        out[key] = entry
    return out


def suspension_numbers(parameters) -> dict:
    proof = suspension_proof(parameters)
    modes = {}
    for m in proof.modes:
        modes[m.name.replace(" ", "_")] = {
            "row": m.row, "published_re": m.published_re, "published_zeta": m.published_zeta,
            "re_at_set": m.re_at_set, "re_at_lower_bounds": m.re_at_lower_bounds,
            "zeta_at_lower_bounds": m.zeta_at_lower_bounds, "slopes": m.slopes,
            "re_without_dampers": m.re_without_dampers, "scale_needed": m.scale_needed,
            # null: no positive damper rate gives the published Re (the mode is damped more than
            # that with both vertical dampers at zero)
            "factor_below_bounds": (m.factor_below_bounds if math.isfinite(m.factor_below_bounds)
                                    else None),
            "damping_needed": {d: m.scale_needed * proof.lower_bounds[d] for d in proof.lower_bounds},
            "re_at_half_bounds": m.re_at_half_bounds, "re_first_order": m.re_first_order,
            "reachable": m.reachable}
    return {"lower_bounds": proof.lower_bounds, "set_values": proof.set_values, "modes": modes}


def main() -> None:
    began = time.perf_counter()
    parameters = load_parameters()
    with threadpool_limits(1):
        data = {"chain": chain_numbers(parameters), "suspension": suspension_numbers(parameters)}
    data["seconds"] = time.perf_counter() - began
    path = write_results("reachability", data, "scripts/reachability.py")
    print(f"wrote {path} ({data['seconds']:.0f} s)")


if __name__ == "__main__":
    main()
