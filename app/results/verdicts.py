"""The assessment as the dashboard and the report show it: computed once per operating point and
set (kept in the results cache), the verdict indicator, the checks' table and the bar chart of
safety factors.

At the dashboard's operating point: a stable point is the short-circuit case's grid (that one
point), an unstable one the unstable_adhesion case's point (the short-circuit case then takes the
default grid of :mod:`model.studies.assessment`).
"""

from __future__ import annotations

import html
import math

import numpy as np
from bokeh.models import ColumnDataSource, FactorRange, HoverTool, Span
from bokeh.plotting import figure

from app.results import compute
from app.results.case import CaseBase
from app.results.tables import order_name
from model.analysis.assessment import KIND_NAMES, VERDICT_WORDS, verdict_colour
from model.mechanics.operating_point import KMH
from model.studies.assessment import (
    LOAD_CASES,
    Assessment,
    AssessmentOptions,
    LoadCase,
    assessed_outputs,
    assessment_of,
    ripple_case,
    running_case,
    short_circuit_case,
    starting_case,
    unstable_adhesion_case,
)

CASE_COLOURS = {"short_circuit": "#1f77b4", "unstable_adhesion": "#d62728", "starting": "#2ca02c",
                "ripple": "#9467bd", "running": "#8c564b"}


def _parameters(case: CaseBase, strength: tuple):
    parameters = compute.parameters_for(case)
    return parameters.replace(**dict(strength)) if strength else parameters


def _in_this_thread(function, *args):
    return function(*args)


def assessment_result(case: CaseBase, strength: tuple = (), runner=_in_this_thread,
                      running: bool = False):
    """The assessment at the case's point and short circuit (its Δt and horizon do not count:
    every fault instant, the horizons of the load cases), with the strength data ``strength``
    ((name, value) pairs) replacing the set's.  The same as
    :func:`model.studies.assessment.assess` with these options, except that the unstable and the
    ripple cases are kept apart (:func:`unstable_case`, :func:`ripple_load_case`): at a stable
    point the unstable case is the default one, and the ripple case, steady running over every
    speed, is always at the assessment's default creepages (``AssessmentOptions().s0``, as
    ``bogie assess`` takes them); a step of the creepage or the speed leaves both as they
    were.  ``running``: with the running case as ``bogie assess`` computes it
    (:func:`running_load_case`).  ``runner(function, *args)`` computes it when the cache
    does not hold it (the served dashboard: :func:`app.services.background.run`, a worker
    process)."""
    key = case.without("dt", "t_end")
    strength = tuple(strength)
    if running:
        return compute.cached("assessment", key,
                              lambda: runner(_assessment, key, strength, True), strength, True)
    return compute.cached("assessment", key, lambda: runner(_assessment, key, strength),
                          strength)


def _assessment(key: CaseBase, strength: tuple, running: bool = False) -> Assessment:
    """The assessment of :func:`assessment_result` (in a background worker when served: its load
    cases are cached in that worker)."""
    from model.analysis.eigen import bogie_system

    parameters = _parameters(key, strength)
    op = key.operating_point()
    stable = float(np.max(bogie_system(compute.model_of(parameters),
                                       op).eigenvalues().real)) <= 1e-6
    excitation = key.short_circuit()
    if stable:
        options = AssessmentOptions(s0=(op.s0,), v=(op.v,), N0=op.N0, b_M=op.b_M,
                                    excitation=excitation)
    else:
        options = AssessmentOptions(N0=op.N0, b_M=op.b_M, excitation=excitation,
                                    unstable_s0=op.s0, unstable_v=op.v)
    outputs = assessed_outputs(parameters)
    unstable = unstable_case(key.replace(s0=options.unstable_s0,
                                         v=round(options.unstable_v / KMH, 9)), strength)
    ripple = ripple_load_case(key, strength)
    running_cases = [running_load_case(key, strength)] if running else []
    return assessment_of(parameters, [short_circuit_case(parameters, outputs, options),
                                      unstable, starting_case(parameters, outputs, options),
                                      ripple, *running_cases])


def running_load_case(case: CaseBase, strength: tuple = ()) -> LoadCase:
    """The running case (:func:`model.studies.assessment.running_case`) at the case's set, wheel
    force and motor slope with ``bogie assess``'s running defaults (its creepages, speeds,
    wheel polygon, track and random multiple): a step of the creepage, the speed or the short
    circuit leaves it as it was."""
    key = case.without("dt", "t_end", "v", "M0", "f", "D", "s0")
    strength = tuple(strength)

    def compute_case() -> LoadCase:
        parameters = _parameters(key, strength)
        op = key.replace(s0=AssessmentOptions().s0[0], v=120.0).operating_point()
        options = AssessmentOptions(N0=op.N0, b_M=op.b_M, cases=(*LOAD_CASES, "running"))
        return running_case(parameters, assessed_outputs(parameters), options)
    return compute.cached("running case", key, compute_case, strength)


def ripple_load_case(case: CaseBase, strength: tuple = ()) -> LoadCase:
    """The ripple case (:func:`model.studies.assessment.ripple_case`) at the case's set, wheel
    force, motor slope and bandwidth, at the assessment's default creepages over the whole speed
    range (``bogie assess``'s): a step of the creepage or the speed slider leaves it as it
    was."""
    key = case.without("dt", "t_end", "v", "M0", "f", "D", "s0")
    strength = tuple(strength)

    def compute_case() -> LoadCase:
        parameters = _parameters(key, strength)
        s0_values = AssessmentOptions().s0
        op = key.replace(s0=s0_values[0], v=120.0).operating_point()
        options = AssessmentOptions(s0=s0_values, N0=op.N0, b_M=op.b_M)
        return ripple_case(parameters, assessed_outputs(parameters), options)
    return compute.cached("ripple case", key, compute_case, strength)


def unstable_case(case: CaseBase, strength: tuple = ()) -> LoadCase:
    """The unstable_adhesion case at the case's point (its creepage and speed) with nonlinear
    creep and the default anti-slip protection
    (:func:`model.studies.assessment.unstable_adhesion_case`)."""
    key = case.without("dt", "t_end")
    strength = tuple(strength)

    def compute_case() -> LoadCase:
        parameters = _parameters(key, strength)
        op = key.operating_point()
        options = AssessmentOptions(N0=op.N0, b_M=op.b_M, excitation=key.short_circuit(),
                                    unstable_s0=op.s0, unstable_v=op.v)
        return unstable_adhesion_case(parameters, assessed_outputs(parameters), options)
    return compute.cached("unstable case", key, compute_case, strength)


def failure_words(uncertainty) -> str:
    """The governing check's probability of falling below its required factor, with its sampling
    error, from a result of the verdict under uncertainty (plain text: a tooltip)."""
    p = uncertainty.governing.failure
    low, high = p.interval
    return (f"probability of the governing check below its required factor: {p.value:.2f} ± "
            f"{p.standard_error:.2f} (95 %: {low:.2f}–{high:.2f}; {uncertainty.n} samples over "
            "the prior ranges of the unknowns — not a service failure rate)")


def indicator_html(result: Assessment | None, note: str = "", uncertainty=None) -> str:
    """The verdict box: the governing safety factor against its required factor, green / amber /
    red (:func:`model.analysis.assessment.verdict_colour`); with ``uncertainty`` (a result of the
    verdict under uncertainty of the same set) its probability of failure as the tooltip."""
    if result is None:
        return f'<div class="status-box verdict-box pending">VERDICT: {html.escape(note)}</div>'
    g = result.governing
    colour = verdict_colour(g)
    title = "" if uncertainty is None else f' title="{html.escape(failure_words(uncertainty))}"'
    return (f'<div class="status-box verdict-box {colour}" data-verdict="{colour}"{title}>'
            f"{VERDICT_WORDS[colour].upper()}</div>"
            f"<div class='verdict-detail' style='font-size:13px'>governing safety factor "
            f"<b>{g.safety_factor:.3g}</b> (required {g.required:.3g}): "
            f"{html.escape(g.component)}, {KIND_NAMES[g.kind]}, {g.load_case}</div>")


def band_words(uncertainty, check) -> str:
    """A check's 5–95 % safety-factor band and probability of failure from a result of the
    verdict under uncertainty ("" when the result has no such check)."""
    if uncertainty is None:
        return ""
    try:
        band = uncertainty.band(check.component, check.kind, check.load_case)
    except KeyError:
        return ""
    return (f"{band.quantiles[0]:.3g}–{band.quantiles[2]:.3g} "
            f"(P = {band.failure.value:.2f})")


def check_rows(result: Assessment, uncertainty=None) -> list[dict]:
    """One row per check, the worst margin first (what the Verdicts table and the report list);
    with ``uncertainty`` each check's 5–95 % band of its safety factor and its probability of
    falling below the required factor."""
    rows = []
    for c in sorted(result.checks, key=lambda c: -c.utilisation):
        where = "steady" if math.isnan(c.time) else f"t = {c.time:.4g} s"
        if not math.isnan(c.rms):  # running: its worst speed, mean ± amplitude, the random RMS
            where = (f"{c.v_kmh:.4g} km/h, mean {c.mean / 1e3:.1f} ± {c.alternating / 1e3:.3g} "
                     f"kN m (ripple, {', '.join(order_name(o) for o in c.orders)}, "
                     f"RMS {c.rms / 1e3:.3g} kN m)")
        elif not math.isnan(c.alternating):  # under the ripple: its worst speed, mean ± amplitude
            where = (f"{c.v_kmh:.4g} km/h, mean {c.mean / 1e3:.1f} ± {c.alternating / 1e3:.3g} "
                     f"kN m ({', '.join(o['order'] for o in c.orders)})")
        elif "v_kmh" in c.scenario:
            where += f", s0 = {c.scenario['s0']:.4g}, {c.scenario['v_kmh']:g} km/h"
        rows.append({"component": c.component, "check": KIND_NAMES[c.kind],
                     "load case": c.load_case, "load [kN m]": round(c.load / 1e3, 2),
                     "capacity [kN m]": round(c.capacity / 1e3, 2),
                     "safety factor": round(c.safety_factor, 3),
                     "band 5–95 %": band_words(uncertainty, c), "required": c.required,
                     "verdict": VERDICT_WORDS[verdict_colour(c)], "colour": verdict_colour(c),
                     "where": where, "note": c.note, "output": c.output,
                     "s0": c.scenario.get("s0"), "v_kmh": c.scenario.get("v_kmh")})
    return rows


def checks_html(result: Assessment) -> str:
    """The checks as an HTML table (the report)."""
    head = ("<table class='bogie'><tr><th class='text'>component</th><th class='text'>check</th>"
            "<th class='text'>load case</th><th>load [kN m]</th><th>capacity [kN m]</th>"
            "<th>safety factor</th><th>required</th><th class='text'>verdict</th>"
            "<th class='text'>where</th><th class='text'>note</th></tr>")
    body = "".join(
        f"<tr><td class='text'>{html.escape(r['component'])}</td><td class='text'>{r['check']}</td>"
        f"<td class='text'>{r['load case']}</td><td>{r['load [kN m]']:.4g}</td>"
        f"<td>{r['capacity [kN m]']:.4g}</td><td class='{'' if r['colour'] == 'green' else 'bad'}'>"
        f"{r['safety factor']:.3g}</td><td>{r['required']:.3g}</td>"
        f"<td class='text'>{r['verdict']}</td>"
        f"<td class='text'>{html.escape(r['where'])}</td>"
        f"<td class='text'>{html.escape(r['note'])}</td></tr>" for r in check_rows(result))
    cases = "".join(
        f"<li><b>{c.name}</b> ({'steady' if c.horizon is None else f'horizon {c.horizon:g} s'})"
        f": {html.escape(c.description)}</li>" for c in result.cases)
    return f"<ul class='load-cases'>{cases}</ul>{head}{body}</table>"


def safety_factor_figure(result: Assessment):
    """Bar chart of the safety factors of every component, one bar per load case (log scale),
    with the required factors as lines."""
    components = list(dict.fromkeys(c.component for c in result.checks))
    x, top, colours, cases, names = [], [], [], [], []
    for c in result.checks:
        x.append((c.component, c.load_case))
        top.append(min(c.safety_factor, 1e3))
        colours.append(CASE_COLOURS[c.load_case])
        cases.append(c.load_case)
        names.append(c.component)
    source = ColumnDataSource({"x": x, "top": top, "colour": colours, "case": cases,
                               "component": names})
    fig = figure(x_range=FactorRange(*[(n, case) for n in components
                                       for case in CASE_COLOURS if case in set(cases)]),
                 y_axis_type="log", height=400, sizing_mode="stretch_width",
                 y_axis_label="safety factor = capacity / load [-]", name="verdict-bars",
                 title="Safety factor of every check, per load case (blue short circuit, red "
                       "unstable adhesion, green starting, purple ripple, brown running)",
                 toolbar_location="above")
    fig.vbar(x="x", top="top", bottom=0.05, width=0.8, color="colour", source=source)
    for required in sorted({c.required for c in result.checks}):
        fig.add_layout(Span(location=required, dimension="width", line_dash="dashed",
                            line_color="black", line_width=1))
    fig.add_layout(Span(location=1.0, dimension="width", line_color="red", line_width=2))
    fig.add_tools(HoverTool(tooltips=[("component", "@component"), ("load case", "@case"),
                                      ("safety factor", "@top{0.000}")]))
    # the colour says the load case (title): only the components are written under the bars
    fig.xaxis.major_label_text_font_size = "0pt"
    fig.xaxis.group_label_orientation = 0.9
    fig.x_range.range_padding = 0.02
    return fig
