"""A self-contained HTML report of one dashboard state (opens offline: BokehJS and every style
inline, no external script or stylesheet).

Contents: verdict, operating point and excitation, the parameter set (name, hash, differences
from the bundled baseline), status numbers and s0*(v), Table 1/2 layouts, the root locus (dense
sweep), Fig. 6, the creep characteristic, the time histories, the peak table with the limit
crossings, the code version and the date.  The figures are the dashboard's own
(:mod:`app.results.plots`, :mod:`app.results.eigenvalue_sweep`), fed with the same cached
results (:mod:`app.results.compute`).

``bogie report --s0 … --v … --out report.html`` (:mod:`app.cli.report`) writes the same file
as the dashboard's "report (HTML)" button.
"""

from __future__ import annotations

import datetime
import html
import subprocess
from importlib import metadata
from pathlib import Path

from bokeh.document import Document
from bokeh.embed import components
from bokeh.embed.bundle import bundle_for_objs_and_resources
from bokeh.io.doc import patch_curdoc
from bokeh.layouts import column, row
from bokeh.resources import INLINE

from app.results import compute
from app.results.eigenvalue_sweep import Fig6Plot
from app.results.plots import CreepPlot, ResponsePlots, RootLocusPlot
from app.results.variants import differences, parameters_of_key, set_hash, split_key
from model.mechanics.parameters import SCHEMA

ROOT = Path(__file__).resolve().parents[2]  # the project (app/report/page.py)
STYLE = """
body {font-family: sans-serif; margin: 24px; max-width: 1400px; color: #222}
h1 {margin-bottom: 0} .sub {color: #555; margin-top: 4px}
.verdict {display: inline-block; font-size: 28px; font-weight: 700; color: white;
          padding: 4px 16px; border-radius: 6px}
.ok {background: #1e8449} .bad {background: #c0392b}
table.bogie {border-collapse: collapse; font-size: 12px}
table.bogie th, table.bogie td {border-bottom: 1px solid #ddd; padding: 2px 8px; text-align: right}
table.bogie td.text, table.bogie th.text {text-align: left}
table.bogie td.bad {color: #c0392b; font-weight: 700; background: none}
.cols {display: flex; gap: 32px; flex-wrap: wrap} .cols > div {flex: 1; min-width: 420px}
"""


def code_version() -> str:
    """Package version and, in a git checkout, the commit (``+dirty`` with local changes)."""
    version = metadata.version("bogie-drive-dynamics")
    try:
        commit = subprocess.run(["git", "-C", str(ROOT), "describe", "--always", "--dirty"],
                                capture_output=True, text=True, timeout=10, check=False)
        if commit.returncode == 0 and commit.stdout.strip():
            version += f" (git {commit.stdout.strip()})"
    except OSError:
        pass
    return version


def _table(rows: list[tuple[str, str]]) -> str:
    return ('<table class="bogie">' + "".join(
        f'<tr><td class="text">{html.escape(a)}</td><td class="text">{b}</td></tr>'
        for a, b in rows) + "</table>")


def build_report(set_key: str, rail: str, s0: float, v_kmh: float, N0_kN: float, b_M: float,
                 M0_kNm: float, f: float, D: float, dt_ms: float | None, t_end: float,
                 progress=None, now: datetime.datetime | None = None) -> str:
    """The report as one HTML text.  Arguments as in :mod:`app.results.compute` (``set_key``: the
    parameter set, a bundled file or a variant of it, :mod:`app.results.variants`)."""
    from app.results.tables import eigen_table_html, mode_table_html, peaks_html

    say = progress or (lambda _text: None)
    point_args = (set_key, rail, s0, v_kmh, N0_kN, b_M)
    say("eigenvalues and modes")
    point = compute.point_result(*point_args)
    say("short-circuit response")
    response = compute.response_result(*point_args, M0_kNm, f, D, dt_ms, t_end)
    say("root locus (dense sweep over s0)")
    locus = compute.dense_locus_result(set_key, rail, "s0", v_kmh, N0_kN, b_M)
    say("stability limit s0*(v)")
    limit = compute.limit_result(set_key, rail, v_kmh, N0_kN, b_M)
    say("writing the report")

    base_name, changes = split_key(set_key)
    parameters = parameters_of_key(set_key)
    diff = differences(parameters_of_key(base_name), parameters)
    now = now or datetime.datetime.now(datetime.UTC)

    locus_plot = RootLocusPlot()
    locus_plot.update_locus(locus)
    locus_plot.update_point(point)
    locus_plot.zoom(False)
    fig6 = Fig6Plot()
    fig6.update_locus(locus)
    fig6.update_limit(limit.s0_limit)
    creep = CreepPlot()
    creep.update_point(point)
    creep.update_limit(limit)
    responses = ResponsePlots()
    responses.update(response)
    figures = {
        "locus": locus_plot.figure,
        "fig6": column(row(*fig6.figures[:2], sizing_mode="stretch_width"), fig6.figures[2],
                       sizing_mode="stretch_width"),
        "creep": creep.figure,
        "response": column(row(*responses.figures[:2], sizing_mode="stretch_width"),
                           row(*responses.figures[2:], sizing_mode="stretch_width"),
                           sizing_mode="stretch_width"),
    }
    # bokeh's embedding asks curdoc() for its settings; in a served callback that can be another
    # session's document (bokeh keeps one global stack of patched documents for all threads),
    # destroyed by the time it is read: give it a fresh one of its own
    fresh = Document()
    with patch_curdoc(fresh):
        script, divs = components(figures)
    # only what these figures need, inline: BokehJS and its styles as text.  Files to load
    # (``bundle.js_files``: Panel adds its module shim to every bundle once imported) are left
    # out: they would be fetched from a server, and plain Bokeh figures do not use them
    bundle = bundle_for_objs_and_resources(list(figures.values()), INLINE)
    inline_resources = "\n".join([*(f"<style>{css}</style>" for css in bundle.css_raw),
                                   *(f"<script>{js}</script>" for js in bundle.js_raw)])

    verdict = "STABLE" if point.stable else "UNSTABLE"
    if limit.s0_limit is None:
        limit_text = f"none ({html.escape(limit.message)})"
    else:
        margin = limit.s0_limit - s0
        limit_text = (f"{limit.s0_limit:.5f} (margin s0* − s0 = {margin:+.5f}, "
                      f"{margin / limit.s0_limit:+.0%})")
    operating = _table([
        ("creepage s0 [-]", f"{s0:g}"), ("speed v [km/h]", f"{v_kmh:g}"),
        ("static wheel force N0 [N]", f"{N0_kN * 1e3:g}"),
        ("motor slope b_M [N m s/rad]", f"{b_M:g}"), ("rail condition (creep law)", rail),
        ("short circuit M0 [N m]", f"{M0_kNm * 1e3:g}"), ("frequency f [Hz]", f"{f:g}"),
        ("decay D [-]", f"{D:g}"),
        ("time shift Δt [s]", "automatic (continuous motor torque)" if dt_ms is None
         else f"{dt_ms * 1e-3:g}"),
        ("simulated time [s]", f"{t_end:g}")])
    status = _table([
        ("largest Re λ [1/s]", f"{point.max_real_part:+.4f}"),
        ("flutter pairs (Re > 0)", str(point.flutter)),
        ("divergent real eigenvalues", str(point.divergence)),
        (f"s0*({v_kmh:g} km/h) [-]", limit_text),
        ("μ(s0), μ_max", f"{point.mu0:.4f}, {point.mu_max:.4f} at s = {point.s_max:.4f}"),
        ("M_ad = 2 N0 r0 μ_max [N m]", f"{point.M_ad:,.0f}")])
    if diff:
        diff_html = ('<table class="bogie"><tr><th class="text">parameter</th><th>baseline</th>'
                     "<th>this set</th><th class='text'>unit</th></tr>" + "".join(
                         f'<tr><td class="text">{html.escape(n)}</td><td>{a:.6g}</td>'
                         f"<td><b>{b:.6g}</b></td><td class='text'>{html.escape(SCHEMA[n][0])}</td></tr>"
                         for n, (a, b) in diff.items()) + "</table>")
    else:
        diff_html = "<p>none: the bundled set itself</p>"
    name = html.escape(base_name or "calibrated (bundled: assets/parameters/calibrated.toml)")
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<title>Bogie drive dynamics — report: {verdict} at s0 = {s0:g}, v = {v_kmh:g} km/h</title>
{inline_resources}
<style>{STYLE}</style>
</head><body>
<h1>Bogie drive dynamics — design-review report</h1>
<p class="sub">{now:%Y-%m-%d %H:%M} UTC · code {html.escape(code_version())} ·
parameter set {name}{' (variant)' if changes else ''}, hash <code>{set_hash(parameters)}</code></p>
<p><span class="verdict {'ok' if point.stable else 'bad'}">{verdict}</span></p>
<div class="cols"><div><h2>Operating point and excitation</h2>{operating}</div>
<div><h2>Stability</h2>{status}</div>
<div><h2>Differences from the baseline</h2>{diff_html}</div></div>
<h2>Root locus over s0 at {v_kmh:g} km/h ({len(locus.values)} points)</h2>{divs['locus']}
<h2>Fig. 6: eigenvalues against s0</h2>{divs['fig6']}
<div class="cols"><div>{eigen_table_html(point)}</div><div>{mode_table_html(point)}</div></div>
<h2>Short-circuit response</h2>
<div class="cols"><div>{divs['creep']}</div><div>{peaks_html(response)}</div></div>
{divs['response']}
<p class="sub">Time histories min/max-decimated for plotting (every extreme kept); the peaks are
from the full 10 kHz history.  Generated by the dashboard's report button or
<code>bogie report</code>.</p>
{script}
</body></html>
"""
