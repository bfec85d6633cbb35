"""The numbers of docs/validation.md's "Which published numbers a bogie can reach together":
the reduced models of :mod:`model.studies.reachability` for the bundled set.

    .venv/bin/python scripts/reachability.py            # docs/results/reachability.json

(a) the two-inertia torsional chain of mode 2 against each published divergence (+7.031 and
+0.062 1/s at s0 = 0.014), over the plausible J1/J2, disc clutch damping and motor slope;
(b) the suspension modes' real parts (car body bounce, frame pitch, frame bounce) with the
vertical dampers at their hardware bounds, and the dampers each published real part needs;
(c) the wheelsets' longitudinal and yaw modes (ranks 7–10) against the divergence: stage A's
slope relation over the creep-shape box, the single-wheelset reduced model against the full model,
the scan of the plausible drives, the key inequality of the study's yaw real parts, and the full
model at the scan's best case (with the frame side at its bounds).
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
from model.studies.wheelset_reachability import (  # noqa: E402
    RANK7_HZ,
    RANK8_HZ,
    RANK9_HZ,
    RANK10_HZ,
    RANK_TOLERANCE,
    YAW_RE_STABLE,
    YAW_RE_UNSTABLE,
    clamped_modes,
    frame_side_ranks,
    full_ranks,
    realize_case,
    yaw_proof,
)

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


def _yaw_case(case) -> dict:
    return {"kA": case.kA, "kS": case.kS, "creep_slope": case.creep_slope, "ratio": case.ratio,
            "gear_ratio": case.gear_ratio, "J_rotor": case.J_rotor,
            "spin_inertia": case.spin_inertia, "drive_inertia": case.drive_inertia,
            "effective_spin_inertia": case.effective_spin_inertia, "spin_rate": case.spin_rate,
            "b11_unstable": case.b11_unstable, "b11_stable": case.b11_stable,
            "longitudinal_cap_hz": case.longitudinal_cap_hz,
            "guide_stiffness": case.guide_stiffness, "longitudinal_re": case.longitudinal_re,
            "yaw_hz": case.yaw_hz, "yaw_re": case.yaw_re, "yaw_hz_unstable": case.yaw_hz_unstable,
            "yaw_re_unstable": case.yaw_re_unstable,
            "yaw_error_rank9": case.yaw_hz / RANK9_HZ - 1,
            "yaw_error_rank10": case.yaw_hz / RANK10_HZ - 1}


def _ranks(r) -> dict:
    return {"frequencies_hz": list(r.frequencies_hz), "errors": list(r.errors),
            "real_parts": list(r.real_parts), "divergence": r.divergence,
            "divergence_error": r.divergence / DIVERGENCE_RATES[0] - 1,
            "largest_error": max(abs(e) for e in r.errors)}


def _mode(lam: complex) -> dict:
    return {"re": lam.real, "hz": lam.imag / (2 * math.pi)}


def wheelset_numbers(parameters) -> dict:
    """(c): the reduced model against the full one, the scan and the full model at its best."""
    from model.mechanics.operating_point import creep_coefficients
    from model.studies.calibration_targets import reference_point

    proof = yaw_proof(parameters, POINTS, POINTS)
    w = proof.wheelset
    check = {}
    for s0 in (0.005, 0.014):
        b11 = creep_coefficients(parameters, reference_point(parameters, s0)).b11
        clamped = clamped_modes(parameters, b11)
        reduced = {"longitudinal": w.longitudinal(b11), "yaw": w.yaw(b11)}
        entry = {"b11": b11, "spin_reduced": w.spin(b11), "spin_clamped": clamped["spin"].real}
        for key, lam in reduced.items():
            entry[key] = {"reduced": _mode(lam), "clamped": _mode(clamped[key]),
                          "hz_error": lam.imag / clamped[key].imag - 1,
                          "re_error": lam.real / clamped[key].real - 1}
        check[str(s0)] = entry
    full = full_ranks(parameters)
    check["full_rank7_hz_error"] = check["0.005"]["longitudinal"]["reduced"]["hz"] \
        / full.frequencies_hz[0] - 1
    check["full_rank10_hz_error"] = check["0.005"]["yaw"]["reduced"]["hz"] \
        / full.frequencies_hz[3] - 1
    check["full_rank9_below_clamped"] = full.frequencies_hz[2] \
        / check["0.005"]["yaw"]["clamped"]["hz"] - 1
    check["full"] = _ranks(full)
    check["spin_error_full"] = check["0.014"]["spin_reduced"] / full.divergence - 1
    creep = [c for c in proof.creep if c.met]
    low, high = proof.ratio_range
    cap7, cap8 = ((1 + RANK_TOLERANCE) * f for f in (RANK7_HZ, RANK8_HZ))
    scan = {}
    for key, cap in (("rank7_cap", cap7), ("rank8_cap", cap8)):
        inside = [c for c in proof.cases if c.longitudinal_cap_hz == cap and c.within_bounds]
        scan[key] = {"cap_hz": cap, "cases": len(inside),
                     "best": _yaw_case(proof.best(cap)),
                     "best_exact_divergence": _yaw_case(proof.best(cap, exact_divergence=True)),
                     "best_yaw_re": _yaw_case(proof.best(cap, yaw_re_within_acceptance=True))}
    def in_full_model(case) -> dict:
        realized = realize_case(parameters, case)
        sides = frame_side_ranks(realized)
        best_side = max(sides, key=lambda k: sides[k].frequencies_hz[2])
        return {"case": _yaw_case(case), "creep_slope": realized["creep_slope"],
                "gear_ratio": realized["gear_ratio"], **_ranks(full_ranks(realized)),
                "frame_side": {k: _ranks(r) for k, r in sides.items()},
                "frame_side_best": {"change": best_side, **_ranks(sides[best_side])},
                "frame_side_reaches_all": any(
                    max(abs(e) for e in r.errors) <= RANK_TOLERANCE
                    and abs(r.divergence / DIVERGENCE_RATES[0] - 1) <= 0.1
                    for r in sides.values())}

    # J_w is not a calibration parameter (the wheel discs' and rims' polar inertias are
    # estimates): the best case with the set's J_w (the scan's value next to it) as well
    set_spin = 1.01 * w.spin_inertia
    J_eff = [c.effective_spin_inertia for c in proof.cases]
    needed = {str(row): {"least": lo, "largest": hi,
                         "J_eff_largest": w.yaw_inertia / lo, "J_eff_least": w.yaw_inertia / hi}
              for row, (lo, hi) in proof.inertia_ratio_needed.items()}
    return {
        "wheelset": {"mass": w.mass, "yaw_inertia": w.yaw_inertia, "spin_inertia": w.spin_inertia,
                     "drive_inertia": w.drive_inertia, "guide_stiffness": w.guide_stiffness,
                     "drive_share_x": w.drive_share_x, "drive_share_yaw": w.drive_share_yaw,
                     "share_x": w.drive_share_x / w.stiffness_x,
                     "share_yaw": w.drive_share_yaw / w.stiffness_yaw},
        "check": check,
        "creep": {"shapes": len(proof.creep), "met": len(creep), "ratio_least": low,
                  "ratio_largest": high,
                  "gear_ratio_least": min(c.gear_ratio for c in creep),
                  "gear_ratio_largest": max(c.gear_ratio for c in creep),
                  "dmu_unstable_least": min(-c.dmu_unstable for c in creep),
                  "dmu_unstable_largest": max(-c.dmu_unstable for c in creep)},
        "key": {"needed": needed, "J_eff_scan_least": min(J_eff), "J_eff_scan_largest": max(J_eff),
                "ratio_allowed": -YAW_RE_STABLE[0] / YAW_RE_UNSTABLE[0]},
        "scan": scan, "scanned": len(proof.cases),
        "full_best": in_full_model(proof.best(cap7, exact_divergence=True)),
        "full_best_set_spin": in_full_model(proof.best(cap7, exact_divergence=True,
                                                       max_spin_inertia=set_spin)),
        "best_set_spin_rank8_cap": _yaw_case(proof.best(cap8, exact_divergence=True,
                                                        max_spin_inertia=set_spin)),
    }


def main() -> None:
    began = time.perf_counter()
    parameters = load_parameters()
    with threadpool_limits(1):
        data = {"chain": chain_numbers(parameters), "suspension": suspension_numbers(parameters),
                "wheelset": wheelset_numbers(parameters)}
    data["seconds"] = time.perf_counter() - began
    path = write_results("reachability", data, "scripts/reachability.py")
    print(f"wrote {path} ({data['seconds']:.0f} s)")


if __name__ == "__main__":
    main()
