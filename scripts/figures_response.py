"""Figures of the short-circuit response, one per published plot, as PNG under assets/figures/.

    .venv/bin/python scripts/figures_response.py [--params FILE] [--out assets/figures]

* ``response_mc.png`` — the short-circuit torque M_C(t) and the total motor torque;
* ``response_driving_shaft.png`` — M_DS of ID1 and ID2 (s0 = 0.005, 120 km/h), 0…2 s and a
  zoom on the first 0.25 s;
* ``response_disc_clutch_moment.png`` — M_xDC of ID1 and ID2 against ±M_ad;
* ``response_disc_clutch_forces.png`` — the three disc clutch force components of ID1 and ID2;
* ``response_unstable.png`` — M_DS and M_xDC of ID1 at s0 = 0.014 (log of |Δ| and totals up
  to the first M_ad crossing).

Values are totals (pre-fault + perturbation) unless a label says Δ.  matplotlib is used here
only (test extra), never in model/ or app/.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from model import build_model, default_operating_point, load_parameters
from model.analysis.response import ShortCircuit, short_circuit_response

COLORS = {"ID1": "tab:red", "ID2": "tab:blue"}


def kilo(y):
    return np.asarray(y) / 1e3


def figure_mc(result, out: Path) -> None:
    fig, ax = plt.subplots(figsize=(8, 3.5), layout="constrained")
    ax.plot(result.t, kilo(result.M_C), lw=0.8, label="M_C(t) (eq. 23)")
    ax.plot(result.t, kilo(result.motor_torque + result.M_C), lw=0.8,
            label="total torque of ID1's motor M(s0,v) + M_C")
    ax.axvline(0.2, color="0.5", ls=":", lw=0.8)
    ax.set(xlim=(0, 0.3), xlabel="t [s]", ylabel="torque [kN m]",
           title=f"Short-circuit torque: M0 = {result.excitation.M0 / 1e3:g} kN m, "
                 f"f = {result.excitation.f:g} Hz, D = {result.excitation.D:g}, "
                 f"Δt = {1e3 * result.phase_shift:.3f} ms")
    ax.legend(loc="lower right", fontsize=8)
    ax.grid(alpha=0.3)
    fig.savefig(out / "response_mc.png", dpi=110)
    plt.close(fig)


def two_panels(result, quantity: str, label: str, out: Path, filename: str,
               limit: float | None = None) -> None:
    fig, axes = plt.subplots(2, 1, figsize=(9, 6), layout="constrained")
    for ax, xlim in zip(axes, ((0, result.t[-1]), (0, 0.25)), strict=True):
        for drive in ("ID1", "ID2"):
            name = f"{drive}.{quantity}"
            ax.plot(result.t, kilo(result.outputs[name]), lw=0.6, color=COLORS[drive],
                    label=f"{drive} (peak |Δ| {abs(result.perturbation_peaks[name]) / 1e3:.1f} "
                          f"at {result.perturbation_peak_times[name]:.3f} s)")
        if limit is not None:
            for sign in (1, -1):
                ax.axhline(sign * limit / 1e3, color="k", ls="--", lw=0.8)
            ax.text(xlim[1], limit / 1e3, " M_ad", va="bottom", ha="right", fontsize=8)
        ax.set(xlim=xlim, xlabel="t [s]", ylabel=f"{label} [k{result.units[name]}]")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8, loc="center right")
    op = result.operating_point
    axes[0].set_title(f"{label}, totals — s0 = {op.s0:g}, v = {op.v_kmh:g} km/h "
                      f"(lower: first 0.25 s)")
    fig.savefig(out / filename, dpi=110)
    plt.close(fig)


def figure_forces(result, out: Path) -> None:
    fig, axes = plt.subplots(3, 1, figsize=(9, 7.5), sharex=True, layout="constrained")
    for ax, axis in zip(axes, "xyz", strict=True):
        for drive in ("ID1", "ID2"):
            name = f"{drive}.disc_clutch.force_{axis}"
            ax.plot(result.t, kilo(result.outputs[name]), lw=0.6, color=COLORS[drive],
                    label=drive)
        ax.set(ylabel=f"F_{axis} [kN]")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    axes[-1].set(xlabel="t [s]", xlim=(0, result.t[-1]))
    op = result.operating_point
    axes[0].set_title(f"Disc clutch force components (global axes), totals — s0 = {op.s0:g}, "
                      f"v = {op.v_kmh:g} km/h")
    fig.savefig(out / "response_disc_clutch_forces.png", dpi=110)
    plt.close(fig)


def figure_unstable(result, out: Path) -> None:
    fig, axes = plt.subplots(2, 1, figsize=(9, 6.5), layout="constrained")
    crossing = next((c for c in result.limit_crossings
                     if c.output == "ID1.disc_clutch.torque"), None)
    t_stop = 0.5
    ax = axes[0]
    for name, color in (("ID1.driving_shaft.torque", "tab:purple"),
                        ("ID1.disc_clutch.torque", "tab:red")):
        ax.plot(result.t, kilo(result.outputs[name]), lw=0.7, color=color, label=name)
    M_ad = result.limits["M_ad"]
    for sign in (1, -1):
        ax.axhline(sign * M_ad / 1e3, color="k", ls="--", lw=0.8)
    if crossing is not None:
        ax.axvline(crossing.time, color="tab:red", ls=":", lw=1)
        ax.text(crossing.time, -M_ad / 1e3, f" |M_xDC| > M_ad at {crossing.time:.3f} s",
                fontsize=8, va="top")
    ax.axvline(0.35, color="0.4", ls="-.", lw=0.8)
    ax.text(0.35, M_ad / 1e3, " 0.35 s (published: anti-slip)", fontsize=8, va="bottom")
    ax.set(xlim=(0, t_stop), ylim=(-3 * M_ad / 1e3, 3 * M_ad / 1e3), xlabel="t [s]",
           ylabel="torque [kN m]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    op = result.operating_point
    ax.set_title(f"Unstable case s0 = {op.s0:g}, v = {op.v_kmh:g} km/h: ID1 torques (totals)")
    ax = axes[1]
    for name, color in (("ID1.driving_shaft.torque", "tab:purple"),
                        ("ID1.disc_clutch.torque", "tab:red"),
                        ("ID2.disc_clutch.torque", "tab:blue")):
        ax.semilogy(result.t, np.abs(result.perturbation(name)) + 1e-3, lw=0.6, color=color,
                    label=f"|Δ {name}|")
    ax.set(xlim=(0, result.t[-1]), xlabel="t [s]", ylabel="|Δ| [N m]")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8, loc="lower right")
    fig.savefig(out / "response_unstable.png", dpi=110)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--params", default=None)
    parser.add_argument("--out", default="assets/figures")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    parameters = load_parameters(args.params)
    model = build_model(parameters)
    stable = short_circuit_response(model, default_operating_point(parameters, 0.005, 120.0),
                                    ShortCircuit(), 2.0, 10_000.0)
    unstable = short_circuit_response(model, default_operating_point(parameters, 0.014, 120.0),
                                      ShortCircuit(), 2.0, 10_000.0)
    figure_mc(stable, out)
    two_panels(stable, "driving_shaft.torque", "driving shaft torque M_DS", out,
               "response_driving_shaft.png")
    two_panels(stable, "disc_clutch.torque", "disc clutch moment M_xDC", out,
               "response_disc_clutch_moment.png", limit=stable.limits["M_ad"])
    figure_forces(stable, out)
    figure_unstable(unstable, out)
    for name in ("ID1.driving_shaft.torque", "ID1.disc_clutch.torque"):
        print(f"{name}: peak |Δ| {abs(stable.perturbation_peaks[name]):.4g} at "
              f"{stable.perturbation_peak_times[name]:.3f} s, dominant "
              f"{stable.dominant_frequencies[name]} Hz")
    print(f"wrote 5 figures to {out}/")


if __name__ == "__main__":
    main()
