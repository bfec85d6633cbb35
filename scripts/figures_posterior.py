"""Prior against linearized posterior: the numbers docs/sensitivity.md quotes and one figure.

    OPENBLAS_NUM_THREADS=1 .venv/bin/bogie uncertainty --samples 32 --no-indices \\
        --speeds 40,80,120,160,200,250 --out assets/data/uncertainty_no-indices_n32.json
    OPENBLAS_NUM_THREADS=1 .venv/bin/bogie uncertainty --samples 32 --posterior \\
        --speeds 40,80,120,160,200,250 --out assets/data/uncertainty_posterior_n32.json
    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/figures_posterior.py [--out assets/figures] [--app]

Prints the prior and posterior standard deviations of ln p per uncertain parameter
(:mod:`model.studies.posterior`) with the targets that pin each (largest Jacobian entries), the linear
prediction of the posterior spread of the creep maximum at 120 km/h, and the 5–95 % widths of
every output of both studies; draws ``uncertainty_prior_posterior.png`` (s0*(v) of the set,
both 5–95 % bands with their medians, the published 0.0082 at 120 km/h).  ``--app`` also
computes a 25 × 6 stability map (≈ 10 s, serial) and renders the dashboard's Studies figure with
the posterior band over it in headless Chromium (/usr/bin/chromium):
``uncertainty_band_app.png``.  The two studies take ≈ 35 CPU-s each (n = 32, six speeds).

Writes ``docs/results/posterior.json``: the numbers and tables docs/sensitivity.md §5b quotes.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from scipy import stats

from model.mechanics.parameters import load_parameters, parameter_hash
from model.studies.calibration_targets import STABILITY_LIMIT
from model.studies.posterior import linearized_posterior
from model.studies.uncertainty import UNCERTAIN_PARAMETERS

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))

from docs_numbers import write_results  # noqa: E402

LABELS = {"s0_limit_120": "s0*(120 km/h)", "s0_limit_200": "s0*(200 km/h)",
          "s0_limit_40": "s0*(40 km/h)", "s0_limit_250": "s0*(250 km/h)",
          "mode2_im_hz": "mode 2 (rotor torsion, DC) [Hz]",
          "peak.ID1.driving_shaft.torque": "peak ID1 driving-shaft torque [N m]",
          "peak.ID2.disc_clutch.torque": "peak ID2 disc-clutch torque [N m]"}


def _value(x: float) -> str:
    return f"{x:.5f}" if abs(x) < 0.1 else (f"{x:.3g}" if abs(x) < 100 else f"{x:,.0f}".replace(",", " "))


def band_table(prior: dict, posterior: dict) -> str:
    """Markdown: each output of LABELS, its calibrated value, the prior and posterior 5–95 % bands
    and their widths (relative to the calibrated value)."""
    rows = ["| output | calibrated | prior 5–95 % | width | posterior 5–95 % | width |",
            "|---|---|---|---|---|---|"]
    a = {o["name"]: o for o in prior["outputs"]}
    b = {o["name"]: o for o in posterior["outputs"]}
    for key, label in LABELS.items():
        o, q = a[key], b[key]
        rows.append(f"| {label} | {_value(o['nominal'])} | {_value(o['p5'])} – {_value(o['p95'])} | "
                    f"{100 * (o['p95'] - o['p5']) / abs(o['nominal']):.0f} % | {_value(q['p5'])} – "
                    f"{_value(q['p95'])} | {100 * (q['p95'] - q['p5']) / abs(q['nominal']):.1f} % |")
    return "\n".join(rows)


def clipped_per_parameter(data: dict) -> dict:
    """How many sampled coordinates sit on an end of their range, per parameter."""
    samples = np.array(data["samples"], dtype=float)
    counts = {}
    for j, p in enumerate(data["parameters"]):
        low, high = p.get("low"), p.get("high")
        counts[p["name"]] = int(np.sum(np.isclose(samples[:, j], low, rtol=1e-12)
                                       | np.isclose(samples[:, j], high, rtol=1e-12)))
    return counts


def limits(data: dict) -> tuple[np.ndarray, np.ndarray]:
    """(speeds [km/h], rows nominal/p5/p50/p95 of s0*) of a result."""
    rows = [o for o in data["outputs"] if o["name"].startswith("s0_limit_")]
    speeds = np.array([float(o["name"][len("s0_limit_"):]) for o in rows])
    return speeds, np.array([[o[k] for o in rows] for k in ("nominal", "p5", "p50", "p95")],
                            dtype=float)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--prior", default="assets/data/uncertainty_no-indices_n32.json")
    parser.add_argument("--posterior", default="assets/data/uncertainty_posterior_n32.json")
    parser.add_argument("--out", default="assets/figures")
    parser.add_argument("--app", action="store_true", help="also the dashboard's figure (Chromium)")
    args = parser.parse_args()
    parameters = load_parameters()
    # cost: the posterior (one eigen-analysis with vectors, the analytic sensitivities with the
    # derivative matrices of a fresh model, 24 operating-data evaluations) against one
    # eigen-analysis with vectors of the same set, same run
    from model.analysis.eigen import eigen_analysis
    from model.mechanics.assembly import build_model
    from model.mechanics.operating_point import OperatingPoint
    from model.studies.calibration_targets import S0_STABLE, V_REF

    op = OperatingPoint(S0_STABLE, V_REF, parameters["wheel_force"], parameters["motor_slope"])
    model = build_model(parameters)
    eigen_analysis(model, op)  # warm-up (the state-space pieces of the model)
    began = time.perf_counter()
    eigen_analysis(model, OperatingPoint(S0_STABLE * 1.001, V_REF, op.N0, op.b_M))  # a fresh point
    reference = time.perf_counter() - began
    began = time.perf_counter()
    post = linearized_posterior(parameters, UNCERTAIN_PARAMETERS)
    cost = time.perf_counter() - began
    print(f"cost: one eigen-analysis with vectors {reference * 1e3:.0f} ms; the linearized "
          f"posterior {cost:.2f} s = {cost / reference:.0f}x (machine shared)\n")
    numbers: dict = {"blocks": {}, "parameters": {}}
    pin = ["| parameter | prior sd | posterior sd | ratio | pinned by (the two largest entries of its "
           "Jacobian column) |", "|---|---|---|---|---|"]
    print(f"{'parameter':<34} {'prior sd ln p':>13} {'posterior':>10} {'ratio':>6}  "
          "largest whitened Jacobian entries ∂r/∂ln p")
    for j, (name, s0, s) in enumerate(zip(post.names, post.prior_sd_log, post.sd_log, strict=True)):
        column = post.jacobian[:, j]
        lead = ", ".join(f"{post.targets[i][:24]} {column[i]:+.3g}"
                         for i in np.argsort(-np.abs(column))[:2])
        print(f"{name:<34} {s0:>13.3f} {s:>10.3f} {s / s0:>6.2f}  {lead}")
        top = [(post.targets[i], column[i]) for i in np.argsort(-np.abs(column))[:2]]
        pin.append(f"| {name} | {s0:.3f} | {s:.3f} | {s / s0:.2f} | "
                   + ", ".join(f"{t} ({x:+.{2 if abs(x) < 10 else 0}f})".replace("(-", "(−")
                               for t, x in top) + " |")
        numbers["parameters"][name] = {"prior_sd": float(s0), "posterior_sd": float(s),
                                       "ratio": float(s / s0),
                                       "largest_entry": float(np.abs(column).max())}
    numbers["blocks"]["pinned"] = "\n".join(pin)
    print("targets used:", len(post.targets), "dropped:", list(post.dropped) or "none")
    k = post.targets.index("creep maximum s (stability-limit proxy)")
    g = post.jacobian[k] * post.sigmas[k]  # ∂ ln s_max(120) / ∂θ
    print(f"linear sd of ln s_max(120 km/h): prior {np.sqrt(g @ (post.prior_sd_log**2 * g)):.4f}, "
          f"posterior {np.sqrt(g @ post.covariance_log @ g):.4f}")
    numbers["linear_sd_ln_smax_120"] = float(np.sqrt(g @ post.covariance_log @ g))

    studies = {}
    for label, path in (("prior", args.prior), ("posterior", args.posterior)):
        data = json.loads(Path(path).read_text(encoding="utf-8"))
        if data.get("parameters_hash") != parameter_hash(parameters):
            print(f"WARNING: {path} belongs to another parameter set: re-run the commands above")
        studies[label] = data
        samples = np.array(data["samples"], dtype=float)
        mean = np.log([parameters[p["name"]] for p in data["parameters"]])
        mean_ = np.log([parameters[p["name"]] for p in data["parameters"]])
        study = numbers.setdefault(label, {})
        study |= {"clipped": int(data.get("clipped_coordinates", 0)),
                  "coordinates": int(np.array(data["samples"]).size),
                  "clipped_by_parameter": clipped_per_parameter(data),
                  "sd_g_theta": float(np.std((np.log(np.array(data["samples"], dtype=float)) - mean_) @ g)),
                  "outputs": {o["name"]: {k: o[k] for k in ("nominal", "p5", "p50", "p95")}
                              for o in data["outputs"]},
                  "width": {o["name"]: (o["p95"] - o["p5"]) / abs(o["nominal"]) for o in data["outputs"]},
                  "band_low": {o["name"]: o["p5"] / o["nominal"] - 1 for o in data["outputs"]},
                  "band_high": {o["name"]: o["p95"] / o["nominal"] - 1 for o in data["outputs"]}}
        modes = [w for k, w in study["width"].items() if k.endswith("_im_hz")]
        study["mode_width_max"], study["mode_width_min"] = max(modes), min(modes)
        others = [w for k, w in study["width"].items()
                  if k.endswith("_im_hz") and k not in ("mode2_im_hz", "mode7_im_hz")]
        study["mode_width_others_max"] = max(others)
        values_ = np.array(data["values"], dtype=float)
        column = [o["name"] for o in data["outputs"]].index("s0_limit_120")
        study["sd_ln_s0_120"] = float(np.nanstd(np.log(values_[:, column])))
        print(f"\n{label}: {data['method']}, n = {data['base_samples']}, {data['runs']} runs, "
              f"{data.get('clipped_coordinates', 0)} coordinates clipped; sampled sd of "
              f"g·(ln p − ln p_set) = {np.std((np.log(samples) - mean) @ g):.4f}")
        if data["method"] == "posterior":  # the same points without the clip to the ranges
            u = stats.qmc.Sobol(len(post.names), scramble=True,
                                rng=np.random.default_rng(data["seed"])).random(len(samples))
            theta = stats.norm.ppf(np.clip(u, 1e-12, 1 - 1e-12)) @ np.linalg.cholesky(
                post.covariance_log).T
            print(f"  the same points unclipped: sd of g·(ln p − ln p_set) = {np.std(theta @ g):.4f}")
            study["sd_g_theta_unclipped"] = float(np.std(theta @ g))
        values = np.array(data["values"], dtype=float)
        for j, o in enumerate(data["outputs"]):
            width = o["p95"] - o["p5"]
            extra = ""
            if o["name"].startswith("s0_limit_"):
                extra = f"  sd of ln: {np.nanstd(np.log(values[:, j])):.4f}"
            print(f"  {o['name']:<32} nominal {o['nominal']:>10.5g}  5–95 % {o['p5']:>10.5g} … "
                  f"{o['p95']:>10.5g}  width {width / abs(o['nominal']):>7.1%} of nominal{extra}")

    fig, ax = plt.subplots(figsize=(8, 4.2), layout="constrained")
    for label, color in (("prior", "tab:blue"), ("posterior", "tab:red")):
        speeds, (nominal, p5, p50, p95) = limits(studies[label])
        data = studies[label]
        ax.fill_between(speeds, p5, p95, color=color, alpha=0.25,
                        label=f"5–95 % {label} (n = {data['base_samples']})")
        ax.plot(speeds, p50, color=color, lw=0.9, ls="--", label=f"median {label}")
    ax.plot(speeds, nominal, "k.-", lw=1.2, label="calibrated set")
    ax.plot([120], [STABILITY_LIMIT], "k*", ms=12, label="published s0* = 0.0082 at 120 km/h")
    ax.set(xlabel="speed v [km/h]", ylabel="stability limit s0* [-]",
           title="s0*(v): prior ranges against the linearized posterior given the calibration's "
                 "targets")
    ax.title.set_fontsize(9)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    fig.savefig(out / "uncertainty_prior_posterior.png", dpi=110)
    print(f"\nwrote {out / 'uncertainty_prior_posterior.png'}")
    numbers["blocks"]["bands"] = band_table(studies["prior"], studies["posterior"])
    s120 = numbers["prior"]["outputs"]["s0_limit_120"]
    numbers["prior_vs_published_120"] = [s120["p5"] / STABILITY_LIMIT - 1, s120["p95"] / STABILITY_LIMIT - 1]
    numbers["peak_shrink"] = {k: numbers["prior"]["width"][k] / numbers["posterior"]["width"][k]
                              for k in numbers["prior"]["width"] if k.startswith("peak.")}
    numbers["published_limit"] = STABILITY_LIMIT
    print(numbers["blocks"]["pinned"], numbers["blocks"]["bands"], sep="\n\n")
    if not args.app:
        print(f"wrote {write_results('posterior', numbers, 'scripts/figures_posterior.py')}")
    if args.app:
        app_figure(parameters, Path(args.posterior), out / "uncertainty_band_app.png")


def app_figure(parameters, result: Path, png: Path) -> None:
    """The Studies tab's figure (app.dashboard.studies_view.StudyMapPlot) with a fresh map and the band."""
    import tempfile

    from bokeh.embed import file_html
    from bokeh.resources import INLINE
    from playwright.sync_api import sync_playwright

    from app.dashboard.studies_view import StudyMapPlot, read_map
    from app.dashboard.uncertainty_band import band_mismatch, read_band
    from model.mechanics.operating_point import KMH
    from model.studies.engine import serial_map_unordered
    from model.studies.maps import MapStudy
    from model.studies.store import run_into_store

    with tempfile.TemporaryDirectory() as folder:
        store = Path(folder) / "map.zarr"
        study = MapStudy(np.linspace(0.004, 0.016, 25), np.array([40, 80, 120, 160, 200, 250]) * KMH,
                         [parameters["wheel_force"]], [parameters["motor_slope"]])
        run_into_store(study, parameters, store, serial_map_unordered)
        view = read_map(store)
        band = read_band(result)
        reason = band_mismatch(band, view.attrs["parameters_hash"], view.N0, view.b_M, None)
        if reason is not None:
            raise SystemExit(f"{result} does not match the map: {reason}")
        plot = StudyMapPlot()
        plot.update(view)
        plot.band.update(band)
        plot.figure.sizing_mode, plot.figure.width = "fixed", 1000
        page_file = Path(folder) / "map.html"
        page_file.write_text(file_html(plot.figure, INLINE, "Studies"), encoding="utf-8")
        with sync_playwright() as playwright:
            browser = playwright.chromium.launch(executable_path="/usr/bin/chromium",
                                                 args=["--no-sandbox", "--headless=new"])
            page = browser.new_page(viewport={"width": 1100, "height": 400})
            page.goto(page_file.as_uri())
            page.wait_for_timeout(1500)
            page.screenshot(path=str(png))
            browser.close()
    print(f"wrote {png}")


if __name__ == "__main__":
    main()
