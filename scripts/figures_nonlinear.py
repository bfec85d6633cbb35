"""Figures and numbers of the nonlinear response (docs/nonlinear.md).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/figures_nonlinear.py [--params FILE]
        [--out assets/figures] [--quick]

Writes under ``--out``:

* ``nonlinear_histories.png`` — disc clutch torques of ID1 and ID2, nonlinear (solid) against
  the linear closed form (dashed), s0 = 0.005 / 0.014 at 120 / 200 km/h, no protection;
* ``nonlinear_creepage.png`` — each wheel's creepage over time for the same four cases;
* ``nonlinear_creep_path.png`` — the path of each wheel's creepage over the creep
  characteristic (s0 = 0.005 and 0.014, 120 km/h);
* ``nonlinear_reaction_time.png`` — peak(τ) of ID2's limited torques against the delay τ, and
  the required reaction time against the limit (M_ad … a design strength), 120 and 200 km/h;
and ``docs/results/nonlinear.json``: every number docs/nonlinear.md quotes (also printed).

``--quick`` uses a coarser delay grid (for a check of the script, not for the docs).
matplotlib is used here only (test extra).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from model import build_model, default_operating_point, load_parameters
from model.analysis.antislip import required_reaction_time
from model.analysis.nonlinear import AntiSlip, nonlinear_response
from model.analysis.response import ShortCircuit, dominant_frequencies, short_circuit_response
from model.mechanics.operating_point import OperatingPoint, creep_law

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))

from docs_numbers import write_results  # noqa: E402

CASES = [(0.005, 120.0), (0.014, 120.0), (0.005, 200.0), (0.014, 200.0)]
CASE_KEYS = {(0.005, 120.0): "stable_120", (0.014, 120.0): "unstable_120",
             (0.005, 200.0): "stable_200", (0.014, 200.0): "unstable_200"}
COLORS = {"ID1": "tab:red", "ID2": "tab:blue"}
RIM_STYLE = {"rim12": "-", "rim14": ":"}
PARTING = 0.05  # linear and nonlinear "part" when they differ by 5 % of the linear total so far


def parting_time(nonlinear: np.ndarray, linear: np.ndarray, t: np.ndarray) -> float | None:
    """First time |y_nl − y_lin| exceeds 5 % of the largest |y_lin| up to then (totals) [s]."""
    envelope = np.maximum.accumulate(np.abs(linear))
    over = np.flatnonzero((np.abs(nonlinear - linear) > PARTING * envelope) & (envelope > 0))
    return float(t[over[0]]) if len(over) else None


def case_numbers(model, op, fs):
    """Runs of one case: (nonlinear result 2 s, linear result 2 s, long nonlinear 6 s, numbers)."""
    nl = nonlinear_response(model, op, ShortCircuit(), 2.0, fs)
    lin = short_circuit_response(model, op, ShortCircuit(), 2.0, fs)
    long = nonlinear_response(model, op, ShortCircuit(), 6.0, 5000.0)
    numbers = {"M_ad": nl.limits["M_ad"], "mu_max": nl.mu_max, "slip_speed_0": op.s0 * op.v}
    late = long.t >= 4.0
    for drive in ("ID1", "ID2"):
        name = f"{drive}.disc_clutch.torque"
        y_late = long.outputs[name][late]
        freqs = dominant_frequencies(y_late - y_late.mean(), 5000.0)[0]
        creep = np.column_stack([long.creepage[f"{drive}.rim{k}"] for k in (12, 14)])
        numbers[drive] = {
            "disc_clutch_peak_nonlinear": abs(nl.peaks[name]),
            "disc_clutch_peak_linear": abs(lin.peaks[name]),
            "disc_clutch_peak_over_M_ad": abs(nl.peaks[name]) / nl.limits["M_ad"],
            "disc_clutch_peak_linear_over_M_ad": abs(lin.peaks[name]) / nl.limits["M_ad"],
            "disc_clutch_min_nonlinear": float(nl.outputs[name].min()),
            "disc_clutch_min_linear": float(lin.outputs[name].min()),
            "disc_clutch_swing_2s_nonlinear": float(0.5 * np.ptp(nl.outputs[name][nl.t >= 1.5])),
            "parting_time_5pct": parting_time(nl.outputs[name], lin.outputs[name], nl.t),
            "late_mean_4_6s": float(y_late.mean()),
            "late_amplitude_4_6s": float(0.5 * (y_late.max() - y_late.min())),
            "late_frequency_hz": float(freqs[0]) if freqs else None,
            "creepage_min": float(creep.min()), "creepage_max": float(creep.max()),
            "creepage_at_6s": float(creep[-1].mean()),
            "slip_velocity_max": float(np.abs(creep).max() * op.v),
            "slip_velocity_at_6s": float(creep[-1].mean() * op.v),
            "disc_clutch_steady_over_M_ad": lin.steady[name] / nl.limits["M_ad"],
            "disc_clutch_late_mean_over_M_ad": float(y_late.mean()) / nl.limits["M_ad"],
        }
    return nl, lin, long, numbers


def figure_histories(runs, out: Path) -> None:
    fig, axes = plt.subplots(2, 2, figsize=(11, 7), layout="constrained", sharex=True)
    for ax, ((s0, v), (nl, lin, _, numbers)) in zip(axes.T.ravel(), runs.items(), strict=True):
        M_ad = numbers["M_ad"]
        for drive, color in COLORS.items():
            name = f"{drive}.disc_clutch.torque"
            ax.plot(lin.t, np.clip(lin.outputs[name], -3 * M_ad, 3 * M_ad) / 1e3, color=color,
                    lw=0.6, ls="--", alpha=0.7, label=f"{drive} linear (clipped at ±3 M_ad)")
            ax.plot(nl.t, nl.outputs[name] / 1e3, color=color, lw=0.8, label=f"{drive} nonlinear")
        for sign in (1, -1):
            ax.axhline(sign * M_ad / 1e3, color="0.3", lw=0.7, ls=":")
        ax.set(title=f"s0 = {s0:g}, {v:g} km/h", ylabel="disc clutch torque [kN m]",
               ylim=(-3.2 * M_ad / 1e3, 3.2 * M_ad / 1e3))
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("t [s]")
    axes[0, 0].legend(fontsize=7, loc="lower right")
    fig.suptitle("Short circuit of ID1's motor: linear closed form vs nonlinear creep (no "
                 "anti-slip); dotted: ±M_ad")
    fig.savefig(out / "nonlinear_histories.png", dpi=110)
    plt.close(fig)


def figure_creepage(runs, out: Path, s_max: dict) -> None:
    fig, axes = plt.subplots(2, 2, figsize=(11, 7), layout="constrained", sharex=True)
    for ax, ((s0, v), (_, _, long, _)) in zip(axes.T.ravel(), runs.items(), strict=True):
        for rim, s in long.creepage.items():
            drive, wheel = rim.split(".")
            ax.plot(long.t, s, color=COLORS[drive], ls=RIM_STYLE[wheel], lw=0.8, label=rim)
        ax.axhline(s_max[v], color="0.3", lw=0.7, ls="--", label="creep maximum")
        ax.axhline(s0, color="0.6", lw=0.7, ls=":", label="s0")
        ax.set(title=f"s0 = {s0:g}, {v:g} km/h", ylabel="creepage s [-]")
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("t [s]")
    axes[0, 0].legend(fontsize=7, loc="upper right")
    fig.suptitle("Creepage of each wheel, nonlinear creep, no anti-slip (6 s)")
    fig.savefig(out / "nonlinear_creepage.png", dpi=110)
    plt.close(fig)


def figure_creep_path(runs, out: Path, law, v_kmh=120.0) -> None:
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained", sharey=True)
    v = v_kmh / 3.6
    s = np.linspace(-0.01, 0.06, 2001)
    for ax, s0 in zip(axes, (0.005, 0.014), strict=True):
        _, _, long, _ = runs[(s0, v_kmh)]
        ax.plot(s, law.mu(s, v), color="0.3", lw=1.2, label="μ(s, v)")
        for rim, creep in long.creepage.items():
            drive, wheel = rim.split(".")
            ax.plot(creep, long.utilisation[rim] * long.mu_max, color=COLORS[drive],
                    ls=RIM_STYLE[wheel], lw=0.5, alpha=0.8, label=f"{rim} path")
        ax.plot([s0], [law.mu(s0, v)], "ko", ms=4, label="pre-fault")
        ax.set(title=f"s0 = {s0:g}, {v_kmh:g} km/h (0…6 s)", xlabel="creepage s [-]")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("μ [-]")
    axes[0].legend(fontsize=7, loc="lower right")
    fig.savefig(out / "nonlinear_creep_path.png", dpi=110)
    plt.close(fig)


def figure_reaction(curves, out: Path) -> None:
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
    for (v, result), color in zip(curves.items(), ("tab:blue", "tab:orange"), strict=True):
        axes[0].plot(result.delays, result.peak_torque / result.limit, "o-", ms=3, color=color,
                     label=f"{v:g} km/h (detected {result.detection_time:.3f} s after the fault)")
        if result.required_delay is not None:
            axes[0].axvline(result.required_delay, color=color, ls=":", lw=0.8)
        # required delay against the limit: the largest grid delay whose peak stays below it
        limits = np.linspace(result.peak_torque.min(), result.peak_torque.max(), 200)
        required = [result.delays[np.flatnonzero(result.peak_torque <= lim)].max()
                    for lim in limits]
        axes[1].plot(limits / result.limit, required, color=color, label=f"{v:g} km/h")
    axes[0].axhline(1.0, color="0.3", lw=0.8, ls="--", label="limit M_ad")
    axes[0].set(xlabel="reaction delay τ after detection [s]",
                ylabel="peak of ID2's DC / DS·p torque / M_ad [-]",
                title="peak(τ), s0 = 0.014, threshold 0.3 m/s, ramp 10 1/s")
    axes[0].legend(fontsize=7)
    axes[1].set(xlabel="limit (design strength) / M_ad [-]",
                ylabel="required reaction time after detection [s]",
                title="required τ against the limit (on the delay grid)")
    axes[1].axvline(1.0, color="0.3", lw=0.8, ls="--")
    axes[1].legend(fontsize=7)
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.savefig(out / "nonlinear_reaction_time.png", dpi=110)
    plt.close(fig)


def reaction_numbers(result) -> dict:
    peaks = result.peak_torque / result.limit
    rising = np.flatnonzero(peaks >= peaks.max() - 1e-3)
    flat = np.flatnonzero(np.abs(peaks - peaks[0]) <= 1e-3)
    return {"required_delay_s": result.required_delay, "reason": result.reason,
            "flat_until_s": float(result.delays[flat[-1]]) if len(flat) else None,
            "full_from_s": float(result.delays[rising[0]]),
            "peak_over_limit_max": float(peaks.max()),
            "detection_time_s": result.detection_time,
            "reaction_after_fault_s": result.reaction_after_fault,
            "limit": result.limit, "unprotected_peak_over_limit":
                result.unprotected_peak / result.limit,
            "peak_over_limit_at_0": float(result.peak_torque[0] / result.limit)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--params", default=None)
    parser.add_argument("--out", default="assets/figures")
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    parameters = load_parameters(args.params)
    model = build_model(parameters)
    law = creep_law(parameters)
    delays = np.linspace(0, 0.5, 6 if args.quick else 26)
    s_max = {v: law.maximum(v / 3.6)[0] for v in (120.0, 200.0)}
    runs, numbers = {}, {"cases": {}, "reaction": {}, "sensitivity": {}}
    for s0, v in CASES:
        op = default_operating_point(parameters, s0, v)
        nl, lin, long, case = case_numbers(model, op, 10_000.0)
        runs[(s0, v)] = (nl, lin, long, case)
        numbers["cases"][CASE_KEYS[(s0, v)]] = case
        print(f"s0 = {s0:g}, {v:g} km/h: " + json.dumps(case), flush=True)
    figure_histories(runs, out)
    figure_creepage(runs, out, s_max)
    figure_creep_path(runs, out, law)
    curves = {}
    for v in (120.0, 200.0):
        op = default_operating_point(parameters, 0.014, v)
        curves[v] = required_reaction_time(model, op, delays=delays)
        key = f"{v:g}"
        numbers["reaction"][key] = {"M_ad": reaction_numbers(curves[v])}
        numbers["reaction"][key]["curve"] = {
            "delays_s": curves[v].delays.tolist(),
            "peak_over_M_ad": (curves[v].peak_torque / curves[v].limit).tolist()}
        strength = 1.03 * curves[v].limit
        design = required_reaction_time(model, op, limit=strength, delays=delays)
        numbers["reaction"][key]["strength_1.03"] = reaction_numbers(design)
        both = required_reaction_time(model, op, delays=delays[:3], drives=("ID1", "ID2"))
        numbers["reaction"][key]["both_drives"] = reaction_numbers(both) | {
            "fault_drive_peaks_over_M_ad": {k: x / both.limit
                                            for k, x in both.fault_drive_peaks.items()}}
        print(f"reaction {v:g} km/h: " + json.dumps(numbers["reaction"][key]["M_ad"]),
              flush=True)
    figure_reaction(curves, out)
    # sensitivity to the assumptions at s0 = 0.014, 120 km/h
    base = AntiSlip()
    op = default_operating_point(parameters, 0.014, 120.0)
    variants = {
        "threshold_0.1": AntiSlip(threshold=0.1), "threshold_1.0": AntiSlip(threshold=1.0),
        "rate_5": AntiSlip(rate=5.0), "rate_50": AntiSlip(rate=50.0),
        "floor_0.3": AntiSlip(floor=0.3), "floor_0.6": AntiSlip(floor=0.6),
    }
    for label, protection in variants.items():
        result = required_reaction_time(model, op, anti_slip=protection, delays=delays)
        numbers["sensitivity"][label] = reaction_numbers(result)
        print(f"sensitivity {label}: " + json.dumps(numbers["sensitivity"][label]), flush=True)
    for factor in (0.9, 1.1):  # N0 (the wheel force is constant in the run: its level matters)
        op_n = OperatingPoint(0.014, 120.0 / 3.6, factor * parameters["wheel_force"],
                              parameters["motor_slope"])
        result = required_reaction_time(model, op_n, anti_slip=base, delays=delays)
        numbers["sensitivity"][f"N0_x{factor:g}"] = reaction_numbers(result)
        print(f"sensitivity N0 x {factor:g}: " + json.dumps(numbers["sensitivity"][
            f"N0_x{factor:g}"]), flush=True)
    print(f"wrote {out}/nonlinear_*.png")
    if args.params is None and not args.quick:
        print(f"wrote {write_results('nonlinear', numbers, 'scripts/figures_nonlinear.py')}")


if __name__ == "__main__":
    main()
