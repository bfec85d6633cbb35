"""Figures of the sensitivities and the uncertainty band, as PNG under assets/figures/.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/figures_sensitivity.py
        [--uncertainty assets/data/uncertainty_n16.json] [--out assets/figures] [--no-peaks]

* ``sensitivity_limit.png`` — tornado of p/s0* · ds0*/dp at 120 and 200 km/h;
* ``sensitivity_growth_014.png`` — tornado of p · ∂Re λ/∂p [1/s] of the unstable modes among the
  ten lowest pairs and of the divergent real eigenvalue at s0 = 0.014, 120 km/h;
* ``sensitivity_damping.png`` — p · ∂ζ/∂p of the ten lowest modes at s0 = 0.005 (heat map of the
  parameters with the largest effect);
* ``sensitivity_peaks.png`` — tornado of p/peak · d peak/dp of the four peak drive loads
  (central differences of the closed form, ≈ 2 responses per parameter; ``--no-peaks`` skips);
* ``uncertainty_limit.png`` — s0*(v) of the calibrated set, the 5–95 % band of the creep
  maximum s_max(v) over the sampled creep-law parameters, the sampled s0*(120), s0*(200)
  (from ``bogie uncertainty --samples N --out FILE``) and the published 0.0082 at 120 km/h.

Also writes ``docs/results/sensitivity.json``: the numbers and tables docs/sensitivity.md
quotes (§2–§5: the limit's derivatives, the growth and damping tables, the peak loads, the
priors and the stored n = 16 study).  matplotlib only here (test extra).
"""

from __future__ import annotations

import argparse
import json
import sys
import textwrap
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from model import build_model, load_parameters
from model.analysis.peak_sensitivity import peak_load_sensitivities
from model.analysis.sensitivity import eigen_sensitivities, limit_sensitivity
from model.mechanics.operating_point import KMH, OperatingPoint, creep_law
from model.mechanics.parameters import Parameters

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))

from docs_numbers import write_results  # noqa: E402

LINKED = ("wheel_force", "motor_slope")
NUMBERS: dict = {"blocks": {}}  # what the page quotes (docs/results/sensitivity.json)
PUBLISHED_LIMIT = 0.0082  # target only: drawn as a marker, never used by the model


def signed(x: float, digits: int) -> str:
    """+1.23 / −1.23 (the pages' minus sign)."""
    return f"{x:+.{digits}f}".replace("-", "−")


def plain(x: float) -> str:
    """A range end as the pages write it: 445, 0.0001, 1 000, 3.5·10⁴."""
    if 1e-4 <= abs(x) < 1e4:
        return f"{x:,.4g}".replace(",", " ")
    exponent = int(np.floor(np.log10(abs(x))))
    mantissa = f"{x / 10 ** exponent:.3g}"
    return f"{mantissa}·10" + str(exponent).translate(str.maketrans("0123456789-", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻"))


def save(fig, path: Path) -> None:
    fig.savefig(path, dpi=110)
    plt.close(fig)


def at_120(parameters, s0: float) -> OperatingPoint:
    """The operating point (s0, 120 km/h) with N0 and b_M of the set."""
    return OperatingPoint(s0, 120 * KMH, parameters["wheel_force"], parameters["motor_slope"])


def tornado(ax, names, values, title, xlabel, count=12):
    order = np.argsort(-np.abs(np.nan_to_num(values)))[:count][::-1]
    colors = ["tab:red" if values[i] > 0 else "tab:blue" for i in order]
    ax.barh(np.arange(len(order)), values[order], color=colors)
    ax.set_yticks(np.arange(len(order)), [names[i] for i in order], fontsize=7)
    ax.axvline(0, color="k", lw=0.6)
    ax.set_title(title, fontsize=8)
    ax.set_xlabel(xlabel, fontsize=8)
    ax.tick_params(axis="x", labelsize=7)
    ax.grid(axis="x", alpha=0.3)


def figure_limit(model, parameters, out: Path) -> None:
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6), layout="constrained")
    for ax, v_kmh in zip(axes, (120.0, 200.0), strict=True):
        limit = limit_sensitivity(model, v_kmh * KMH, parameters["wheel_force"],
                                  parameters["motor_slope"], linked=LINKED)
        nonzero = int(np.count_nonzero(limit.derivatives))
        NUMBERS.setdefault("limit", {})[f"{v_kmh:g}"] = {
            "s0_limit": limit.s0_limit, "mechanism": limit.mechanism,
            "critical_eigenvalue_re": float(limit.critical_eigenvalue.real),
            "dmu_ds_at_limit": limit.dmu_ds_at_limit, "derivatives": len(limit.names),
            "nonzero": nonzero, "normalized": {n: float(x) for n, x in
                                               zip(limit.names, limit.normalized, strict=True) if x}}
        print(f"s0*({v_kmh:g} km/h) = {limit.s0_limit:.6f}, {limit.mechanism}; {nonzero} of "
              f"{len(limit.names)} derivatives non-zero")
        for i in np.argsort(-np.abs(limit.normalized))[:6]:
            print(f"   {limit.names[i]:<30} p/s0* ds0*/dp = {limit.normalized[i]:+.4f}")
        tornado(ax, limit.names, limit.normalized, f"s0* = {limit.s0_limit:.5f} at {v_kmh:g} km/h "
                f"({limit.mechanism}): {nonzero} of {len(limit.names)} non-zero",
                "p/s0* · ds0*/dp [-]", count=8)
    fig.suptitle("Stability-limit sensitivities: set by the creep maximum, so only the creep law, "
                 "speed and wheel force move it", fontsize=9)
    save(fig, out / "sensitivity_limit.png")


def figure_growth(model, parameters, out: Path) -> None:
    op = at_120(parameters, 0.014)
    sens = eigen_sensitivities(model, op, linked=LINKED)
    from model.analysis.eigen import eigen_analysis

    result = eigen_analysis(model, op)
    divergent = int(result.real_index[0])
    real = eigen_sensitivities(model, op, indices=[divergent], linked=LINKED, result=result)
    unstable = [k for k in range(len(sens.eigenvalues)) if sens.eigenvalues[k].real > 0]
    panels = [(sens, k) for k in unstable] + [(real, 0)]
    rows = ["| mode | Re λ [1/s] | leading parameters (p · ∂Re λ/∂p [1/s]) |", "|---|---|---|"]
    NUMBERS["growth"] = []
    for s, k in panels:
        lam, values = s.eigenvalues[k], s.growth_per_relative_change[:, k]
        lead = np.argsort(-np.abs(np.nan_to_num(values)))[:5]
        where = f"{lam.imag / (2 * np.pi):.3f} Hz" if lam.imag else "real"
        rows.append(f"| {where}, {s.descriptions[k]} | {signed(lam.real, 2)} | "
                    + ", ".join(f"{s.names[i]} {signed(values[i], 1)}" for i in lead) + " |")
        NUMBERS["growth"].append({"re": float(lam.real), "im_hz": float(lam.imag / (2 * np.pi)),
                                  "leading": {s.names[i]: float(values[i]) for i in lead}})
    NUMBERS["blocks"]["growth"] = "\n".join(rows)
    fig, axes = plt.subplots(1, len(panels), figsize=(3.9 * len(panels), 4.6), layout="constrained")
    for ax, (s, k) in zip(np.atleast_1d(axes), panels, strict=True):
        lam = s.eigenvalues[k]
        values = s.growth_per_relative_change[:, k]
        label = (f"Re λ = {lam.real:+.3f} 1/s, {lam.imag / (2 * np.pi):.3f} Hz" if lam.imag
                 else f"real λ = {lam.real:+.3f} 1/s")
        print(f"s0 = 0.014: {label}: {s.descriptions[k]}")
        for i in np.argsort(-np.abs(np.nan_to_num(values)))[:5]:
            print(f"   {s.names[i]:<30} p dRe/dp = {values[i]:+.4g} 1/s")
        text = s.descriptions[k]
        wrapped = "\n".join(textwrap.wrap(text, 46)[:2])
        tornado(ax, s.names, values, f"{label}\n{wrapped}", "p · ∂Re λ/∂p [1/s]")
    fig.suptitle("Growth-rate sensitivities of the unstable modes at s0 = 0.014, 120 km/h "
                 "(red: a larger p destabilizes)", fontsize=9)
    save(fig, out / "sensitivity_growth_014.png")


def figure_damping(model, parameters, out: Path) -> None:
    op = at_120(parameters, 0.005)
    sens = eigen_sensitivities(model, op, linked=LINKED)
    zeta = -sens.eigenvalues.real / np.abs(sens.eigenvalues)
    values = sens.values[:, None] * sens.d_damping_ratio  # p dζ/dp
    relative = values / zeta[None, :]  # p/ζ dζ/dp: every mode on its own scale
    keep: list[int] = []
    for k in range(len(zeta)):  # each mode's two leading parameters, then the overall leaders
        keep += [int(i) for i in np.argsort(-np.abs(relative[:, k]))[:2] if int(i) not in keep]
    for i in np.argsort(-np.nanmax(np.abs(relative), axis=1)):
        if len(keep) >= 24:
            break
        if int(i) not in keep:
            keep.append(int(i))
    fig, ax = plt.subplots(figsize=(10, 6.4), layout="constrained")
    limit = np.nanpercentile(np.abs(relative[keep]), 97)
    image = ax.imshow(relative[keep], cmap="RdBu_r", vmin=-limit, vmax=limit, aspect="auto")
    ax.set_yticks(np.arange(len(keep)), [sens.names[i] for i in keep], fontsize=7)
    ax.set_xticks(np.arange(len(sens.eigenvalues)),
                  [f"{lam.imag / (2 * np.pi):.2f} Hz\nζ={-lam.real / abs(lam):.3f}"
                   for lam in sens.eigenvalues], fontsize=6)
    fig.colorbar(image, ax=ax, label="p/ζ · ∂ζ/∂p [-] (colour clipped at the 97th percentile)")
    ax.set_title("Relative damping-ratio sensitivities of the ten lowest modes at s0 = 0.005, "
                 "120 km/h (red: a larger p adds damping)", fontsize=9)
    save(fig, out / "sensitivity_damping.png")
    rows = ["| mode | ζ | largest p/ζ · ∂ζ/∂p | participation |", "|---|---|---|---|"]
    for k, lam in enumerate(sens.eigenvalues):
        i = int(np.nanargmax(np.abs(relative[:, k])))
        share = " / ".join(f"{v:.2f}" for v in sens.participation[k].values())
        rows.append(f"| {lam.imag / (2 * np.pi):.3f} Hz | {-lam.real / abs(lam):.4f} | "
                    f"{sens.names[i]} {signed(relative[i, k], 2)} | {share} |")
    NUMBERS["blocks"]["damping"] = "\n".join(rows)
    NUMBERS["damping_participation_order"] = list(sens.participation[0])
    for k, lam in enumerate(sens.eigenvalues):
        i = int(np.nanargmax(np.abs(values[:, k])))
        print(f"mode {k + 1} {lam.imag / (2 * np.pi):.3f} Hz ζ = {-lam.real / abs(lam):.4f}: "
              f"largest p dζ/dp {sens.names[i]} {values[i, k]:+.3g} (p/ζ dζ/dp "
              f"{relative[i, k]:+.3g}); participation "
              + ", ".join(f"{s} {v:.2f}" for s, v in sens.participation[k].items()))


def figure_peaks(parameters, out: Path) -> None:
    op = at_120(parameters, 0.005)
    peaks = peak_load_sensitivities(parameters, op)
    print(f"peak loads: {peaks.seconds:.0f} s for {len(peaks.names)} parameters")
    fig, axes = plt.subplots(1, 4, figsize=(14, 4), layout="constrained")
    rows = ["| load | peak | leading parameters |", "|---|---|---|"]
    NUMBERS["peaks"] = {}
    for j, name in enumerate(peaks.outputs):
        values = peaks.normalized[:, j]
        lead = np.argsort(-np.abs(values))[:5 if name == "ID1.driving_shaft.torque" else 3]
        drive, part = name.split(".")[:2]
        rows.append(f"| {drive} {part.replace('_', ' ')} | {peaks.peaks[j] / 1e3:.1f} kN m at "
                    f"t = {peaks.peak_times[j]:.3g} s | "
                    + ", ".join(f"{peaks.names[i]} {signed(values[i], 2)}" for i in lead) + " |")
        NUMBERS["peaks"][name] = {"peak": float(peaks.peaks[j]), "time": float(peaks.peak_times[j]),
                                  "leading": {peaks.names[i]: float(values[i]) for i in lead}}
    NUMBERS["blocks"]["peaks"] = "\n".join(rows)
    check = peak_load_sensitivities(parameters, op, names=["disc_clutch_torsional_stiffness"], step=1e-4)
    k = list(peaks.names).index("disc_clutch_torsional_stiffness")
    NUMBERS["peak_step_change"] = float(np.max(np.abs(check.normalized[0] - peaks.normalized[k]))
                                        / np.max(np.abs(peaks.normalized[k])))
    for j, (ax, name) in enumerate(zip(axes, peaks.outputs, strict=True)):
        values = peaks.normalized[:, j]
        print(f"{name}: peak {peaks.peaks[j]:.0f} N m at {peaks.peak_times[j]:.4f} s")
        for i in np.argsort(-np.abs(values))[:5]:
            print(f"   {peaks.names[i]:<30} p/peak dpeak/dp = {values[i]:+.4f}")
        tornado(ax, peaks.names, values, f"{name}\npeak {peaks.peaks[j] / 1e3:.1f} kN m at "
                f"{peaks.peak_times[j]:.3f} s", "p/peak · d peak/dp [-]", count=10)
    fig.suptitle("Peak drive loads after the short circuit (s0 = 0.005, 120 km/h; totals)",
                 fontsize=9)
    save(fig, out / "sensitivity_peaks.png")


def _creep_maximum(law, v: float) -> float:
    """The creep maximum s_max(v) [-], NaN where the law has none below s = 1."""
    try:
        return law.maximum(v)[0]
    except ValueError:
        return float("nan")


def figure_uncertainty(model, parameters, path: Path, out: Path) -> None:
    data = json.loads(path.read_text(encoding="utf-8"))
    names = [p["name"] for p in data["parameters"]]
    outputs = {o["name"]: o for o in data["outputs"]}
    samples = np.array(data["samples"], dtype=float)
    values = np.array(data["values"], dtype=float)
    speeds = np.linspace(60, 220, 33)
    curves = []
    for row in samples:
        changed = {n: v for n, v in zip(names, row, strict=True)
                   if n.startswith("polach_") or n == "creep_slope"}
        law = creep_law(Parameters({**parameters.values, **changed}))
        curves.append([_creep_maximum(law, v * KMH) for v in speeds])
    curves = np.array(curves)
    nominal = [_creep_maximum(creep_law(parameters), v * KMH) for v in speeds]
    fig, ax = plt.subplots(figsize=(8, 4.2), layout="constrained")
    # a sample whose law has no maximum below s = 1 at a speed has none there (NaN, left out)
    low, mid, high = np.nanpercentile(curves, [5, 50, 95], axis=0)
    ax.fill_between(speeds, low, high, color="tab:blue", alpha=0.25,
                    label="5–95 % of the creep maximum over the prior samples")
    ax.plot(speeds, mid, color="tab:blue", lw=0.8, ls="--", label="median")
    ax.plot(speeds, nominal, color="k", lw=1.2, label="calibrated set")
    for k, v in enumerate((120.0, 200.0)):
        column = list(outputs).index(f"s0_limit_{v:g}")
        ax.plot(np.full(len(values), v) + np.linspace(-2, 2, len(values)), values[:, column], ".",
                ms=3, color="tab:red", label="s0* of each sample (model run)" if k == 0 else None)
        at_maximum = np.abs(values[:, column] - curves[:, np.argmin(np.abs(speeds - v))]) <= 1e-9
        NUMBERS.setdefault("uncertainty", {})[f"at_creep_maximum_{v:g}"] = int(at_maximum.sum())
        NUMBERS["uncertainty"]["samples"] = len(values)
        print(f"s0*({v:g} km/h) equals the creep maximum for {int(at_maximum.sum())} of "
              f"{len(values)} prior samples")
        o = outputs[f"s0_limit_{v:g}"]
        print(f"s0*({v:g} km/h): nominal {o['nominal']:.5f}, 5/50/95 % {o['p5']:.5f} "
              f"{o['p50']:.5f} {o['p95']:.5f}; leading S_T "
              + ", ".join(f"{n} {t:.2f}" for n, t in sorted(zip(names, o["total_order"], strict=True),
                                                               key=lambda x: -(x[1] or 0))[:3]))
    ax.plot([120], [PUBLISHED_LIMIT], "k*", ms=12, label="published s0* = 0.0082 at 120 km/h")
    ax.set(xlabel="speed v [km/h]", ylabel="stability limit s0* [-]",
           title=f"Uncertainty band of s0*(v): prior ranges of {len(names)} unpublished parameters, "
                 f"n = {data['base_samples']} ({data['runs']} runs)")
    ax.title.set_fontsize(9)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    save(fig, out / "uncertainty_limit.png")
    uncertainty_table(data)


def uncertainty_table(data: dict) -> None:
    """The table of §5: each output's calibrated value, 5/50/95 % and its leading total indices."""
    names = [p["name"] for p in data["parameters"]]
    labels = {"s0_limit_120": ("s0*(120 km/h)", ".5f"), "s0_limit_200": ("s0*(200 km/h)", ".5f"),
              "mode1_im_hz": ("mode 1 (CB bounce) [Hz]", ".4f"),
              "mode2_im_hz": ("mode 2 (rotor torsion, DC) [Hz]", ".3f"),
              "peak.ID1.driving_shaft.torque": ("peak ID1 driving-shaft torque [N m]", ",.0f"),
              "peak.ID2.driving_shaft.torque": ("peak ID2 driving-shaft torque [N m]", ",.0f"),
              "peak.ID2.disc_clutch.torque": ("peak ID2 disc-clutch torque [N m]", ",.0f"),
              "peak.ID1.disc_clutch.torque": ("peak ID1 disc-clutch torque [N m]", ",.0f")}
    rows = ["| output | calibrated | 5 % | 50 % | 95 % | leading total indices |",
            "|---|---|---|---|---|---|"]
    outputs = {o["name"]: o for o in data["outputs"]}
    for key, (label, fmt) in labels.items():
        if key not in outputs:
            continue
        o = outputs[key]
        lead = sorted(zip(names, o.get("total_order") or [], strict=False), key=lambda x: -(x[1] or 0))[:3]
        cells = [format(o[k], fmt).replace(",", " ") for k in ("nominal", "p5", "p50", "p95")]
        rows.append(f"| {label} | " + " | ".join(cells) + " | "
                    + ", ".join(f"{n} {t:.2f}" for n, t in lead if t is not None) + " |")
    NUMBERS["blocks"]["uncertainty_n16"] = "\n".join(rows)
    widths = []
    for o in data["outputs"]:
        total, ci = o.get("total_order"), o.get("total_order_ci")
        if total and ci and any(t is not None for t in total):
            j = int(np.nanargmax(np.array(total, dtype=float)))
            widths.append(ci[1][j] - ci[0][j])
    NUMBERS["uncertainty"] |= {"runs": data["runs"], "base_samples": data["base_samples"],
                               "leading_ci_median_width": float(np.median(widths)),
                               "outputs": {k: {f: outputs[k][f] for f in ("nominal", "p5", "p50", "p95")}
                                           for k in labels if k in outputs}}


def priors_table() -> None:
    """The table of §5: the sampled parameters, their prior ranges and why."""
    from model.mechanics.parameters import SCHEMA
    from model.studies.uncertainty import UNCERTAIN_PARAMETERS

    rows = ["| parameter | range | why |", "|---|---|---|"]
    for r in UNCERTAIN_PARAMETERS:
        unit = SCHEMA[r.name][0]
        unit = "" if unit == "1" else f" {unit.replace('^2', '²')}"
        rows.append(f"| {r.name} | {plain(r.low)} – {plain(r.high)}{unit} | {r.reason} |")
    NUMBERS["blocks"]["priors"] = "\n".join(rows)
    NUMBERS["uncertain_parameters"] = len(UNCERTAIN_PARAMETERS)


def twins(model, parameters) -> None:
    """How far apart the ten lowest pairs are, and the near-repeated pairs among the first 80."""
    from model.analysis.eigen import eigen_analysis

    result = eigen_analysis(model, at_120(parameters, 0.005), vectors=False)
    pairs = result.complex_pairs
    gaps = np.array([np.min(np.abs(np.delete(pairs, k) - z)) / abs(z) for k, z in enumerate(pairs)])
    twin = np.flatnonzero(gaps[:80] < 1e-6)
    NUMBERS["twins"] = {"smallest_gap_ten": float(gaps[:10].min()), "count_80": len(twin),
                        "lowest_hz": float(pairs[twin[0]].imag / (2 * np.pi)) if len(twin) else None,
                        "largest_gap": float(gaps[twin].max()) if len(twin) else None,
                        "smallest_gap": float(gaps[twin].min()) if len(twin) else None}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--params", default=None)
    parser.add_argument("--uncertainty", default="assets/data/uncertainty_n16.json")
    parser.add_argument("--out", default="assets/figures")
    parser.add_argument("--no-peaks", action="store_true")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    parameters = load_parameters(args.params)
    model = build_model(parameters)
    figure_limit(model, parameters, out)
    figure_growth(model, parameters, out)
    figure_damping(model, parameters, out)
    if Path(args.uncertainty).is_file():
        figure_uncertainty(model, parameters, Path(args.uncertainty), out)
    else:
        print(f"no {args.uncertainty}: run `bogie uncertainty --samples 16 --out {args.uncertainty}`")
    if not args.no_peaks:
        figure_peaks(parameters, out)
    priors_table()
    twins(model, parameters)
    if args.params is None and not args.no_peaks and Path(args.uncertainty).is_file():
        print(f"wrote {write_results('sensitivity', NUMBERS, 'scripts/figures_sensitivity.py')}")


if __name__ == "__main__":
    main()
