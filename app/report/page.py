"""A self-contained HTML report of one dashboard state (opens offline: BokehJS and every style
inline, no external script or stylesheet).

Contents: verdict, operating point and excitation, the parameter set (name, hash, differences
from the bundled baseline), status numbers and s0*(v), Table 1/2 layouts, the root locus (dense
sweep), Fig. 6, the creep characteristic, the time histories and the peak table with the limit
crossings (of the linear closed form, or of the nonlinear creep model when the dashboard has it
on; at an unstable point with linear creep the growth rate, when each output passes its limit
and the nonlinear creep's peaks beside them), the design loads (the worst case over every
fault instant, the load collective and the damage-equivalent ranges of the history), the
resonances (the Campbell diagram with its crossings, the frequency response and the forced
response to the default torque ripple of ID1's driving shaft), the verdicts (safety factors of
every press fit, shaft and coupling), the code version and the date.  The figures are the
dashboard's own (:mod:`app.results.plots`, :mod:`app.results.eigenvalue_sweep`), fed with the
same cached results (:mod:`app.results.compute`).

:func:`build_report` runs four stages: the results (:func:`report_results`), the figures
(:func:`report_figures`), their embedding (:mod:`app.report.embedding`) and the page with its
tables (:func:`report_page`).  ``bogie report --s0 … --v … --out report.html``
(:mod:`app.cli.report`) writes the same file as the dashboard's "report (HTML)" button.
"""

from __future__ import annotations

import datetime
import html
import subprocess
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path

from bokeh.layouts import column, row

from app.report.embedding import EmbeddedFigures, embed_inline
from app.results import compute, resonance
from app.results.case import CaseBase
from app.results.eigenvalue_sweep import Fig6Plot
from app.results.load_plots import LoadCollectivePlot
from app.results.plots import CreepPlot, ResponsePlots, RootLocusPlot
from app.results.resonance_plots import CampbellPlot, FrfPlot, RipplePlot
from app.results.tables import (
    crossings_html,
    eigen_table_html,
    mode_table_html,
    peaks_html,
    spectra_html,
    worst_case_html,
)
from app.results.variants import differences, parameters_of_key, set_hash, split_key
from app.results.verdicts import (
    assessment_result,
    checks_html,
    indicator_html,
    safety_factor_figure,
)
from model.analysis.frequency_response import FrequencyResponse
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
table.bogie td.t {color: #666}
table.bogie.peaks td {white-space: nowrap; padding: 2px 4px} table.bogie.peaks th {padding: 2px 4px}
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


@dataclass(frozen=True)
class ReportHistory:
    """Which history the report describes besides its case."""

    # nonlinear creep: ID2's anti-slip key (enabled, delay [s], threshold [m/s], rate [1/s]);
    # None: the linear closed form
    anti_slip: tuple | None = None
    # the anti-slip key of the nonlinear history shown beside a linear one that grows without
    # bound (default: the protection off, its parameters the defaults)
    companion_anti_slip: tuple = compute.ANTI_SLIP_OFF


@dataclass(frozen=True)
class ReportResults:
    """The results a report shows (cached, plain data)."""

    point: compute.PointResult
    response: compute.ResponseView  # the history shown: linear, or nonlinear creep
    locus: compute.LocusResult  # the dense root locus over s0 at the case's speed
    limit: compute.LimitResult
    worst: compute.WorstCaseView  # the worst case over every fault instant (linear)
    spectra: compute.SpectraView  # load spectra of the history shown
    campbell: resonance.CampbellView  # over the dashboard's speeds, the default orders
    frf: FrequencyResponse  # from ID1's motor torque at the case's point
    ripple: resonance.RippleView  # the default ripple over the dashboard's speeds
    assessment: object = None  # the checks at the point (app.results.verdicts.assessment_result)
    # beside a linear history that grows without bound: the nonlinear creep's (the physical
    # answer of the peak table)
    companion: compute.ResponseView | None = None


def report_results(case: CaseBase, history: ReportHistory = ReportHistory(),
                   say=lambda _text: None) -> ReportResults:
    """Compute (or take from the results cache) what the report of ``case`` shows;
    ``say(text)`` names each step."""
    say("eigenvalues and modes")
    point = compute.point_result(case)
    say("short-circuit response" + (" (nonlinear creep)" if history.anti_slip is not None
                                    else ""))
    response = compute.history_result(case, history.anti_slip)
    companion = None
    if not response.load_peaks.bounded:
        say("short-circuit response with nonlinear creep (the linear one grows without bound)")
        companion = compute.history_result(case, history.companion_anti_slip)
    say("root locus (dense sweep over s0)")
    locus = compute.dense_locus_result(case.sweep("s0"))
    say("stability limit s0*(v)")
    limit = compute.limit_result(case)
    say("design loads: worst case over the fault instant, load spectra")
    worst = compute.worst_case_result(case)
    spectra = compute.spectra_result(case, history.anti_slip)
    say("resonances: Campbell diagram, frequency response, torque ripple")
    campbell = resonance.campbell_result(case)
    frf = resonance.frf_result(case)
    ripple = resonance.ripple_result(case)
    say("verdicts: safety factors of every fit, shaft and coupling")
    assessment = assessment_result(case)
    return ReportResults(point, response, locus, limit, worst, spectra, campbell, frf, ripple,
                         assessment, companion)


def report_figures(results: ReportResults) -> dict:
    """The dashboard's figures fed with the results: name -> Bokeh model (``locus``, ``fig6``,
    ``creep``, ``response``)."""
    locus_plot = RootLocusPlot()
    locus_plot.update_locus(results.locus)
    locus_plot.update_point(results.point)
    locus_plot.zoom(False)
    fig6 = Fig6Plot()
    fig6.update_locus(results.locus)
    fig6.update_limit(results.limit.s0_limit)
    creep = CreepPlot()
    creep.update_point(results.point)
    creep.update_limit(results.limit)
    responses = ResponsePlots()
    responses.update(results.response)
    collectives = []
    for part in compute.PARTS:
        plot = LoadCollectivePlot()
        plot.update(results.spectra, part)
        collectives.append(plot.figure)
    campbell = CampbellPlot()
    campbell.update(results.campbell)
    campbell.mark_speed(results.point.case.v)
    frf = FrfPlot()
    frf.update(results.frf, resonance.DEFAULT_OUTPUT)
    ripple = RipplePlot()
    ripple.update(results.ripple, resonance.DEFAULT_OUTPUT)
    ripple.mark_speed(results.point.case.v)
    figures = {} if results.assessment is None else {
        "verdicts": safety_factor_figure(results.assessment)}
    return {
        **figures,
        "locus": locus_plot.figure,
        "fig6": column(row(*fig6.figures[:2], sizing_mode="stretch_width"), fig6.figures[2],
                       sizing_mode="stretch_width"),
        "creep": creep.figure,
        "response": column(row(*responses.figures[:2], sizing_mode="stretch_width"),
                           row(*responses.figures[2:], sizing_mode="stretch_width"),
                           sizing_mode="stretch_width"),
        "collective": column(row(*collectives[:2], sizing_mode="stretch_width"),
                             row(*collectives[2:], sizing_mode="stretch_width"),
                             sizing_mode="stretch_width"),
        "campbell": campbell.figure,
        "resonance": row(column(frf.magnitude, frf.phase, sizing_mode="stretch_width"),
                         ripple.figure, sizing_mode="stretch_width"),
    }


# --- the page's tables ---------------------------------------------------------------------------

def _table(rows: list[tuple[str, str]]) -> str:
    return ('<table class="bogie">' + "".join(
        f'<tr><td class="text">{html.escape(a)}</td><td class="text">{b}</td></tr>'
        for a, b in rows) + "</table>")


def operating_table(case: CaseBase, history: ReportHistory) -> str:
    """The operating point, the excitation and the horizon, in SI units (N, N m, s), and the
    creep model."""
    return _table([*case.rows(),
                   ("longitudinal creep", compute.anti_slip_description(history.anti_slip))])


def stability_table(case: CaseBase, results: ReportResults) -> str:
    """The status numbers, s0*(v) and the margin to it, the adhesion limit."""
    point, limit = results.point, results.limit
    if limit.s0_limit is None:
        limit_text = f"none ({html.escape(limit.message)})"
    else:
        margin = limit.s0_limit - case.s0
        limit_text = (f"{limit.s0_limit:.5f} (margin s0* − s0 = {margin:+.5f}, "
                      f"{margin / limit.s0_limit:+.0%})")
    return _table([
        ("largest Re λ [1/s]", f"{point.max_real_part:+.4f}"),
        ("flutter pairs (Re > 0)", str(point.flutter)),
        ("divergent real eigenvalues", str(point.divergence)),
        (f"s0*({case.v:g} km/h) [-]", limit_text),
        ("μ(s0), μ_max", f"{point.mu0:.4f}, {point.mu_max:.4f} at s = {point.s_max:.4f}"),
        ("M_ad = 2 N0 r0 μ_max [N m]", f"{point.M_ad:,.0f}")])


def differences_table(diff: dict[str, tuple[float, float]]) -> str:
    """The parameters that differ from the bundled baseline (name -> (baseline, this set), SI)."""
    if not diff:
        return "<p>none: the bundled set itself</p>"
    return ('<table class="bogie"><tr><th class="text">parameter</th><th>baseline</th>'
            "<th>this set</th><th class='text'>unit</th></tr>" + "".join(
                f'<tr><td class="text">{html.escape(n)}</td><td>{a:.6g}</td>'
                f"<td><b>{b:.6g}</b></td><td class='text'>{html.escape(SCHEMA[n][0])}</td></tr>"
                for n, (a, b) in diff.items()) + "</table>")


def design_loads_section(results: ReportResults, collective_div: str) -> str:
    """The design loads (docs/design-loads.md): the worst case over every fault instant at the
    point (linear closed form, table per drive part) and the load spectrum of the history shown
    (equivalent ranges, the load collective of each drive part)."""
    unstable = "" if results.point.stable else (
        "<p><b>The operating point is unstable:</b> the linear response grows without bound, "
        "and so does its worst case over the fault instant — it says “unstable”, not a design "
        "load.  The nonlinear creep model bounds it (the dashboard's creep switch).</p>")
    meaningless = "" if results.point.stable or results.spectra.history != \
        compute.LINEAR_HISTORY else ("<p>The load spectrum below is that of a linear blow-up "
                                     "and means nothing.</p>")
    return f"""<h2>Design loads</h2>
<h3>Worst case over every fault instant (linear creep, closed form)</h3>
{unstable}{worst_case_html(results.worst)}
<h3>Load spectrum of the history above ({html.escape(results.spectra.history)})</h3>
{meaningless}{spectra_html(results.spectra)}
{collective_div}"""


def resonance_section(results: ReportResults, campbell_div: str, resonance_div: str) -> str:
    """Where the drive resonates (docs/resonance.md): the Campbell diagram with its crossings,
    the frequency response and the forced response of ID1's driving shaft."""
    view = results.campbell
    ripple = ", ".join(f"{label} = {a:g} N m" for label, a in zip(
        results.ripple.labels, results.ripple.amplitudes, strict=True))
    return f"""<h2>Resonances</h2>
<p>The modes a motor's torque drives over {view.v_kmh[0]:g}…{view.v_kmh[-1]:g} km/h at this
creepage (coloured by their damping ratio), the excitation orders and their crossings (named at
{view.reference_kmh:g} km/h; the dotted line: this report's speed).</p>
{campbell_div}
{crossings_html(view)}
<p>The frequency response of {resonance.DEFAULT_OUTPUT} at this operating point, and its
steady amplitude over speed under the torque ripple {html.escape(ripple)} of
{html.escape(results.ripple.input)} (the sum over the orders: the largest the steady state
reaches).</p>
{resonance_div}"""
def verdicts_section(results: ReportResults, chart_div: str) -> str:
    """The checks of every press fit, shaft and coupling in every load case
    (docs/assessment.md): the governing one, the table and the bar chart."""
    if results.assessment is None:
        return ""
    return f"""<h2>Verdicts: safety factors</h2>
{indicator_html(results.assessment)}
{checks_html(results.assessment)}
{chart_div}
<p class="sub">Strength data marked “estimate” in the parameter set are assumptions; not a
certification to EN 13103-1 / EN 13260 (docs/assessment.md).</p>"""


# --- the page --------------------------------------------------------------------------------------

def report_page(case: CaseBase, history: ReportHistory, results: ReportResults,
                figures: EmbeddedFigures, now: datetime.datetime) -> str:
    """The report as one HTML text: the tables of ``results``, the embedded ``figures``."""
    base_name, changes = split_key(case.set_key)
    parameters = parameters_of_key(case.set_key)
    diff = differences(parameters_of_key(base_name), parameters)
    point, divs = results.point, figures.divs
    verdict = "STABLE" if point.stable else "UNSTABLE"
    name = html.escape(base_name or "calibrated (bundled: assets/parameters/calibrated.toml)")
    s0, v_kmh = case.s0, case.v
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<title>Bogie drive dynamics — report: {verdict} at s0 = {s0:g}, v = {v_kmh:g} km/h</title>
{figures.resources}
<style>{STYLE}</style>
</head><body>
<h1>Bogie drive dynamics — design-review report</h1>
<p class="sub">{now:%Y-%m-%d %H:%M} UTC · code {html.escape(code_version())} ·
parameter set {name}{' (variant)' if changes else ''}, hash <code>{set_hash(parameters)}</code></p>
<p><span class="verdict {'ok' if point.stable else 'bad'}">{verdict}</span></p>
<div class="cols"><div><h2>Operating point and excitation</h2>{operating_table(case, history)}</div>
<div><h2>Stability</h2>{stability_table(case, results)}</div>
<div><h2>Differences from the baseline</h2>{differences_table(diff)}</div></div>
<h2>Root locus over s0 at {v_kmh:g} km/h ({len(results.locus.values)} points)</h2>{divs['locus']}
<h2>Fig. 6: eigenvalues against s0</h2>{divs['fig6']}
<div class="cols"><div>{eigen_table_html(point)}</div><div>{mode_table_html(point)}</div></div>
<h2>Short-circuit response ({html.escape(results.response.history)})</h2>
<div class="cols"><div>{divs['creep']}</div>
<div>{peaks_html(results.response, results.companion)}</div></div>
{divs['response']}
<p class="sub">Time histories min/max-decimated for plotting (every extreme kept); the peaks are
from the full 10 kHz history.</p>
{design_loads_section(results, divs['collective'])}
{resonance_section(results, divs['campbell'], divs['resonance'])}
{verdicts_section(results, divs.get('verdicts', ''))}
<p class="sub">Generated by the dashboard's report button or <code>bogie report</code>.</p>
{figures.script}
</body></html>
"""


def build_report(case: CaseBase, history: ReportHistory = ReportHistory(), progress=None,
                 now: datetime.datetime | None = None) -> str:
    """The report of ``case`` (:class:`app.results.case.Case`: its parameter set — a bundled file
    or a variant of it, :mod:`app.results.variants` —, operating point, short circuit and
    simulated time) as one HTML text.  ``history``: with nonlinear creep, ID2's anti-slip key
    (the histories, peaks and spectra are then the nonlinear ones) and the key of the nonlinear
    history the peak table shows beside a linear one that grows without bound; ``progress``:
    called with the name of each step; ``now``: the date shown (default: now, UTC)."""
    say = progress or (lambda _text: None)
    results = report_results(case, history, say)
    say("writing the report")
    now = now or datetime.datetime.now(datetime.UTC)
    return report_page(case, history, results, embed_inline(report_figures(results)), now)
