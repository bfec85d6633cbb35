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

Also writes ``docs/results/response.json``: the numbers docs/response.md quotes (peaks, swings,
limit crossings, dominant frequencies, the drive modes of the model, the ratio of ID1's to ID2's
loads, the growth of the unstable case at 2 s and 5 s, the defaults of the excitation and the
sizes of the closed form).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from model import build_model, default_operating_point, eigen_analysis, load_parameters
from model.analysis.eigen import bogie_system
from model.analysis.modes import strongest_strain_modes
from model.analysis.response import ShortCircuit, short_circuit_response

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))

from docs_numbers import write_results  # noqa: E402

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


DRIVE_PARTS = ("driving_shaft.torque", "disc_clutch.torque", "claw_clutch.torque", "gear_mesh.force")


def drive_modes(model, op) -> dict:
    """Frequency [Hz] of the complex mode with the largest strain-energy share of ID1's disc
    clutch and of ID1's driving shaft (:func:`model.analysis.modes.strongest_strain_modes`, as
    tests/literature/test_response_literature.py finds them)."""
    best = strongest_strain_modes(model, eigen_analysis(model, op),
                                  ("ID1.disc_clutch", "ID1.driving_shaft"))
    return {group: hz for group, (_, hz) in best.items()}


def summary(result, names) -> dict:
    """Per output: total peak and time, perturbation peak and time, pre-fault value, max, min,
    dominant frequencies."""
    return {name: {"peak": result.peaks[name], "peak_time": result.peak_times[name],
                   "swing": result.perturbation_peaks[name],
                   "swing_time": result.perturbation_peak_times[name],
                   "steady": result.steady[name], "max": float(result.outputs[name].max()),
                   "min": float(result.outputs[name].min()),
                   "dominant_hz": list(result.dominant_frequencies[name])} for name in names}


def crossings(result) -> dict:
    return {f"{c.output}>{c.limit_name}": c.time for c in result.limit_crossings}


def id1_over_id2(result, t_max: float) -> dict:
    """|Δ| peak of ID1 over that of ID2, per drive part, over 0…t_max."""
    window = result.t <= t_max
    ratios = {}
    for part in DRIVE_PARTS:
        id1 = np.abs(result.perturbation(f"ID1.{part}")[window]).max()
        id2 = np.abs(result.perturbation(f"ID2.{part}")[window]).max()
        ratios[part] = float(id1 / id2)
    ratios["smallest"] = min(ratios.values())
    return ratios


def numbers(model, parameters, stable, unstable) -> dict:
    names = [f"{drive}.{part}" for drive in ("ID1", "ID2") for part in DRIVE_PARTS] + [
        f"{drive}.wheelset.adhesion_moment" for drive in ("ID1", "ID2")]
    op = stable.operating_point
    excitation = stable.excitation
    decay = excitation.D * 2 * np.pi * excitation.f
    total_motor = stable.motor_torque + stable.M_C
    long_stable = short_circuit_response(model, op, ShortCircuit(), 5.0, 2000.0)
    long_unstable = short_circuit_response(model, unstable.operating_point, ShortCircuit(), 5.0,
                                           2000.0)
    at = {t: int(np.argmin(np.abs(long_stable.t - t))) for t in (2.0, 4.0, 5.0)}
    system = bogie_system(model, op)
    values = system.eigen[0]
    pairs = int(np.count_nonzero(values.imag > 0))
    reals = int(np.count_nonzero(values.imag == 0))
    unstable_dc = unstable.perturbation("ID1.disc_clutch.torque")
    return {
        "excitation": {"M0": excitation.M0, "f": excitation.f, "D": excitation.D,
                       "decay_rate": decay, "envelope_0.1": float(np.exp(-decay * 0.1)),
                       "envelope_0.2": float(np.exp(-decay * 0.2)),
                       "phase_shift": stable.phase_shift, "motor_torque": stable.motor_torque,
                       "M0_over_M": excitation.M0 / stable.motor_torque,
                       "total_motor_torque_min": float(total_motor.min())},
        "modes_hz": drive_modes(model, op),
        "M_ad": stable.limits["M_ad"],
        "stable": {"outputs": summary(stable, names), "crossings": crossings(stable),
                   "id1_over_id2_2s": id1_over_id2(stable, 2.0),
                   "id1_over_id2_0.4s": id1_over_id2(stable, 0.4),
                   "ID2.disc_clutch.torque_at": {f"{t:g}": float(long_stable.outputs[
                       "ID2.disc_clutch.torque"][i]) for t, i in at.items()},
                   "ID2.driving_shaft.torque_perturbation_at": {f"{t:g}": float(
                       long_stable.perturbation("ID2.driving_shaft.torque")[i])
                       for t, i in at.items()},
                   "ID2.driving_shaft.torque_peak_0.5s": float(np.abs(stable.outputs[
                       "ID2.driving_shaft.torque"][stable.t <= 0.5]).max()),
                   "ID1_disc_clutch_half_period": 0.5 / drive_modes(model, op)["ID1.disc_clutch"]},
        "unstable": {"outputs": summary(unstable, names), "crossings": crossings(unstable),
                     "ID1.disc_clutch.torque_at_2s": float(unstable.outputs[
                         "ID1.disc_clutch.torque"][-1]),
                     "ID1.disc_clutch.perturbation_max_2s": float(np.abs(unstable_dc).max()),
                     "ID1.disc_clutch.torque_at_5s": float(long_unstable.outputs[
                         "ID1.disc_clutch.torque"][-1]),
                     "truncated_at_5s": long_unstable.truncated_at,
                     "dominant_hz": list(unstable.dominant_frequencies["ID1.disc_clutch.torque"])},
        "sizes": {"outputs": len(stable.outputs), "samples": len(stable.t),
                  "states": int(system.N), "deflated_states": len(values),
                  "modal_terms": pairs + reals, "complex_pairs": pairs, "real_modes": reals,
                  "augmented_states": int(system.N) + 3},
    }


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
    if args.params is None:
        data = numbers(model, parameters, stable, unstable)
        print(f"wrote {write_results('response', data, 'scripts/figures_response.py')}")


if __name__ == "__main__":
    main()
