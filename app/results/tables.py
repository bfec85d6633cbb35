"""HTML tables of results, shared by the dashboard and the report: Table 1's layout (eigenvalues),
Table 2's (mode descriptions), the peaks of the short-circuit response and the crossings of the
Campbell diagram.  Units in every header: Re [1/s], Im [Hz], torques [N m], forces [N],
times [s], speeds [km/h]."""

from __future__ import annotations

import html
import math

from app.results import compute
from app.results.resonance import CampbellView
from model.analysis.assessment import KIND_NAMES
from model.analysis.load_peaks import LIMITED
from model.analysis.response import QUASI_STATIC_HZ


def _complex(lam: complex) -> str:
    return f"{lam.real:+.4f} ± i {abs(lam.imag) / (2 * math.pi):.3f}"


def eigen_table_html(point: compute.PointResult) -> str:
    """Table 1 layout: first complex pairs (Re [1/s] ± i Im [Hz]) and real eigenvalues [1/s]."""
    rows = []
    for i in range(max(len(point.modes), len(point.real))):
        c = point.modes[i].eigenvalue if i < len(point.modes) else None
        r = float(point.real[i]) if i < len(point.real) else None
        c_cell = (f'<td class="{"bad" if c.real > 0 else ""}">{_complex(c)}</td>' if c is not None
                  else "<td></td>")
        r_cell = (f'<td class="{"bad" if r > 0 else ""}">{r:+.4g}</td>' if r is not None
                  else "<td></td>")
        rows.append(f"<tr><td>{i + 1}</td>{c_cell}{r_cell}</tr>")
    s0, v = point.case.s0, point.case.v
    return (f"<b>Eigenvalues at s0 = {s0:g}, v = {v:g} km/h</b> (Re [1/s] ± i Im [Hz]; "
            f"{point.n_rigid} rigid-body zeros deflated)"
            '<table class="bogie"><tr><th>#</th><th>complex</th><th>real (largest first)</th></tr>'
            + "".join(rows) + "</table>")


def mode_table_html(point: compute.PointResult) -> str:
    """Table 2 layout: ν, Im λ [Hz], damping ratio and the generated description."""
    rows = "".join(
        f"<tr><td>{m.number}</td><td>{m.im_hz:.3f}</td><td>{m.damping_ratio:+.4f}</td>"
        f'<td class="text">{html.escape(m.description)}</td></tr>' for m in point.modes)
    return ('<b>Mode shapes</b> (dominant motion from kinetic/strain energy shares)'
            '<table class="bogie"><tr><th>ν</th><th>Im λ [Hz]</th><th>ζ [-]</th>'
            '<th class="text">dominant motion</th></tr>' + rows + "</table>")


def format_load(x: float) -> str:
    """A load for a table: thousands separated, or in exponent form beyond 10⁷ (growth)."""
    return f"{x:,.0f}" if abs(x) < 1e7 else f"{x:.3e}"


KILO_UNITS = {"N m": "kN m", "N": "kN"}  # the peak table's units: kN m and kN


def format_kilo(x: float, unit: str) -> str:
    """A load in the peak table's unit (kN m, kN; other units as they are), 3 digits or more;
    exponent form beyond 10⁷ of it (growth)."""
    v = x / 1e3 if unit in KILO_UNITS else x
    if not math.isfinite(v):
        return "—"
    if abs(v) >= 1e7:
        return f"{v:.2e}"
    if abs(v) >= 100:
        return f"{v:,.0f}"
    return f"{v:.1f}" if abs(v) >= 10 else f"{v:.2f}"


def _at(value: float, time: float, unit: str, bad: bool = False) -> str:
    return (f'<td class="{"bad" if bad else ""}">{format_kilo(value, unit)}</td>'
            f'<td class="t">{time:.4f}</td>')


def _limit_of(name: str, response: compute.ResponseView) -> tuple[str, float] | None:
    """(limit name, magnitude) an output is checked against (model.analysis.load_peaks.LIMITED),
    None if none."""
    for suffix, limit in LIMITED:
        if name.endswith(suffix) and limit in response.limits:
            return limit, response.limits[limit]
    return None


def _row_label(name: str, unit: str) -> str:
    return f'<td class="text">{html.escape(name)} [{KILO_UNITS.get(unit, unit)}]</td>'


def _extremes_cells(name: str, response: compute.ResponseView) -> str:
    """Pre-fault, max and min with their times, the swing from the pre-fault value with its time
    (a value beyond the output's limit in red)."""
    e, unit = response.load_peaks.extremes[name], response.units[name]
    limit = _limit_of(name, response)
    over = (lambda x: abs(x) > limit[1]) if limit else (lambda _x: False)
    return (f"<td>{format_kilo(e.pre_fault, unit)}</td>"
            + _at(e.maximum, e.time_of_maximum, unit, over(e.maximum))
            + _at(e.minimum, e.time_of_minimum, unit, over(e.minimum))
            + _at(e.swing, e.time_of_swing, unit))


EXTREMES_HEAD = ("<th>pre-fault</th><th>max</th><th>at [s]</th><th>min</th><th>at [s]</th>"
                 "<th>swing</th><th>at [s]</th>")


def _history_line(response: compute.ResponseView) -> str:
    return (f"<div class='peaks-history'>of the history with <b>{html.escape(response.history)}"
            f"</b>, Δt = {response.fault_instant * 1e3:.4g} ms, 0 … {response.t[-1]:g} s</div>")


def _crossings_line(response: compute.ResponseView) -> str:
    crossings = "; ".join(f"{o} exceeds {n} at {t:.3f} s"
                          for o, n, t, _ in response.crossings[:4])
    return f"<div style='font-size:12px'>{html.escape(crossings)}</div>" if crossings else ""


def peaks_html(response: compute.ResponseView, companion: compute.ResponseView | None = None,
               companion_note: str = "") -> str:
    """The peak table of the history ``response`` (the heading says which: linear or nonlinear
    creep, and its fault instant Δt): per output the pre-fault value, the maximum, the minimum
    and the swing from the pre-fault value, each with its time, and (linear creep) the swing
    split into its quasi-static and dynamic parts; the first limit crossings below.  A linear
    history that grows without bound (:attr:`model.analysis.load_peaks.LoadPeaks.bounded`)
    gets the growth rate and when each output passes its limit instead, beside the bounded
    peaks of ``companion``, the nonlinear creep's history (``companion_note`` while there is
    none).  Torques in kN m, forces in kN, times in s after the fault."""
    peaks = response.load_peaks
    if not peaks.bounded:
        return _unbounded_html(response, companion, companion_note)
    split = not peaks.split_note
    rows = []
    for name in response.outputs:
        e, unit = peaks.extremes[name], response.units[name]
        cells = _row_label(name, unit) + _extremes_cells(name, response)
        if split:
            cells += (f"<td>{format_kilo(e.quasi_static, unit)}</td><td>{format_kilo(e.dynamic, unit)}</td>"
                      f"<td>{format_kilo(e.quasi_static_at_end, unit)} → "
                      f"{format_kilo(e.quasi_static_final, unit)}</td>")
        rows.append(f"<tr>{cells}</tr>")
    head = ('<table class="bogie peaks"><tr><th class="text">output</th>' + EXTREMES_HEAD
            + ("<th>quasi-static</th><th>dynamic</th>"
               f"<th>quasi-static at {peaks.t_end:g} s → final</th>" if split else "")
            + "</tr>")
    if split:
        explain = ("swing = total − pre-fault value of largest magnitude = its quasi-static part "
                   "(the static response to the lost motor torque and the modes slower than "
                   f"{QUASI_STATIC_HZ:g} Hz: the vehicle decelerating under the lost torque) "
                   "+ its dynamic part (the oscillation about it), both at the swing's time")
    else:
        explain = f"swings not split into quasi-static and dynamic parts: {peaks.split_note}"
    M_ad = response.M_ad
    return (f"<b>Peaks</b> (M_ad = {M_ad / 1e3:,.1f} kN m; torques in kN m, forces in kN, "
            f"times in s after the fault; red: beyond M_ad, the driving shaft beyond M_ad/p)"
            f"{_note(response)}{_history_line(response)}"
            + head + "".join(rows) + "</table>"
            + f"<div style='font-size:12px'>{html.escape(explain)}.</div>"
            + _crossings_line(response))


def _note(response: compute.ResponseView) -> str:
    if response.truncated_at is not None:
        return f" — growth: the time grid was cut at {response.truncated_at:.3f} s"
    if response.plot_cut is not None:
        return f" — unstable growth (plots end at {response.plot_cut:.3f} s; CSV has all)"
    return ""


def _unbounded_html(response: compute.ResponseView, companion: compute.ResponseView | None,
                    companion_note: str) -> str:
    """An unbounded linear history: the growth rate, when each output passes its limit, and
    the nonlinear creep's bounded peaks beside it."""
    peaks = response.load_peaks
    largest = max(abs(peaks.extremes[n].swing) for n in response.outputs
                  if response.units[n] == "N m")
    ready = companion is not None and companion.load_peaks is not None
    rows = []
    for name in response.outputs:
        unit = response.units[name]
        limit = _limit_of(name, response)
        crossing = peaks.crossings.get(name)
        if limit is None:
            passes = "<td class='text'>—</td><td>—</td>"
        else:
            when = (f"{crossing.time:.4f}" if crossing is not None
                    else f"not within {peaks.t_end:g} s")
            passes = f"<td class='text'>{html.escape(limit[0])}</td><td>{when}</td>"
        nonlinear = (_extremes_cells(name, companion) if ready else "")
        rows.append(f"<tr>{_row_label(name, unit)}{passes}{nonlinear}</tr>")
    if ready:
        physical = (f"<th colspan='7'>{html.escape(companion.history)}: "
                    "the physical answer</th>")
        second = "<tr><th></th><th></th><th></th>" + EXTREMES_HEAD + "</tr>"
    else:
        physical = (f"<th class='text'>nonlinear creep: "
                    f"{html.escape(companion_note or 'not computed')}</th>")
        second = ""
    head = ('<table class="bogie peaks unbounded"><tr><th class="text">output</th>'
            "<th class='text'>limit</th><th>linear: passes it at [s]</th>" + physical
            + "</tr>" + second)
    M_ad = response.M_ad
    return (f"<b>Peaks: unbounded with linear creep</b> — the linear history grows as "
            f"e^(σt), σ = <b>{peaks.growth_rate:+.4g} 1/s</b> (the largest Re λ){_note(response)}"
            f"; its torques at {peaks.t_end:g} s (up to {largest:.3g} N m) are no load any shaft "
            f"sees. Limits: M_ad = {M_ad / 1e3:,.1f} kN m, M_ad/p for the driving shafts; "
            "torques in kN m, forces in kN, times in s after the fault."
            f"{_history_line(response)}" + head + "".join(rows) + "</table>")
# --- design loads ------------------------------------------------------------------------------

def _part(name: str) -> str:
    drive, part = name.split(".", 1)
    return f"{drive} {compute.PART_LABELS.get(part, part)}"


def worst_case_html(worst: compute.WorstCaseView) -> str:
    """Per drive part: the max and the min over every fault instant Δt (closed form), the Δt [s]
    and the time [s] of each, and the max and min of the history at the dashboard's Δt."""
    rows = []
    for name, unit in worst.units.items():
        rows.append(
            f'<tr><td class="text">{_part(name)} [{unit}]</td>'
            f"<td><b>{format_load(worst.max[name])}</b></td><td>{worst.phase_of_max[name]:.6f}</td>"
            f"<td>{worst.time_of_max[name]:.4f}</td>"
            f"<td><b>{format_load(worst.min[name])}</b></td><td>{worst.phase_of_min[name]:.6f}</td>"
            f"<td>{worst.time_of_min[name]:.4f}</td>"
            f"<td>{format_load(worst.at_dt_max[name])}</td><td>{format_load(worst.at_dt_min[name])}</td>"
            "</tr>")
    which = ("the continuity root (the Response tab's)" if worst.dt_auto
             else "the given Δt (the Response tab's)")
    return ('<table class="bogie worst-case"><tr><th class="text" rowspan="2">drive part</th>'
            '<th colspan="3">max over every fault instant</th>'
            '<th colspan="3">min over every fault instant</th>'
            f'<th colspan="2">at Δt = {worst.dt:.6f} s</th></tr>'
            "<tr><th>value</th><th>Δt [s]</th><th>t [s]</th><th>value</th><th>Δt [s]</th>"
            "<th>t [s]</th><th>max</th><th>min</th></tr>" + "".join(rows) + "</table>"
            f"<div style='font-size:12px'>Totals (pre-fault + perturbation) over t = 0 … "
            f"the simulated time; Δt in (−T/2, T/2], T = {worst.period * 1e3:.4g} ms; the last "
            f"two columns: the history at {which}; continuity roots Δt = "
            f"{worst.roots[0]:.6f} s and {worst.roots[1]:.6f} s.</div>")


def spectra_html(spectra: compute.SpectraView) -> str:
    """Per drive part: rainflow cycles, the largest range and the damage-equivalent ranges
    (N_ref cycles) of the history ``spectra`` describes."""
    first = next(iter(spectra.spectra.values()))
    slopes = list(first.equivalent_range)
    rows = "".join(
        f'<tr><td class="text">{_part(name)} [{s.unit}]</td><td>{s.total_cycles:g}</td>'
        f"<td>{format_load(s.largest_range)}</td>"
        + "".join(f"<td>{s.equivalent_range[m]:,.4g}</td>" for m in slopes) + "</tr>"
        for name, s in spectra.spectra.items())
    return ('<table class="bogie spectra"><tr><th class="text">drive part</th><th>cycles</th>'
            "<th>largest range</th>"
            + "".join(f"<th>ΔM_eq, m = {m:g}</th>" for m in slopes) + "</tr>" + rows + "</table>"
            f"<div style='font-size:12px'>Rainflow (ASTM E1049-85, residue as half cycles) of "
            f"the history with {html.escape(spectra.history)}, Δt = "
            f"{spectra.fault_instant * 1e3:.4g} ms; ΔM_eq = (Σ nᵢ ΔMᵢ^m / N_ref)^(1/m), "
            f"N_ref = {first.n_ref:.0e} cycles, in the part's unit.</div>")


CROSSINGS_LISTED = 8  # rows of the crossings table


CROSSING_SPEED_RTOL = 0.02  # a ripple check is driven by a crossing within 2 % of its speed


def order_name(order: dict) -> str:
    """The Campbell diagram's name of a check's order: a ripple order's own (``el:6``), a wheel
    polygon's of the running case (``{"order": 20, "wheels": …}``) ``wheel:20``."""
    if "wheels" in order:
        return f"wheel:{float(order['order']):g}"
    return str(order["order"])


def driven_check(crossing, checks) -> str:
    """The check a crossing drives: of the checks under alternating load (``checks``: the
    converters' ripple, and the running case, whose orders are the wheel polygon's) whose worst
    speed lies within :data:`CROSSING_SPEED_RTOL` of the crossing's and whose orders include the
    crossing's, the one with the least margin, as "component, check: S = safety factor"; "—" if
    none."""
    driven = [c for c in checks if abs(c.v_kmh - crossing.v_kmh) <= CROSSING_SPEED_RTOL * crossing.v_kmh
              and any(order_name(o) == crossing.order for o in c.orders)]
    if not driven:
        return "—"
    c = max(driven, key=lambda c: c.utilisation)
    return f"{c.component}, {KIND_NAMES[c.kind]}: S = {c.safety_factor:.3g}"


def crossings_html(view: CampbellView, listed: int = CROSSINGS_LISTED,
                   checks: tuple | None = None) -> str:
    """The crossings with the largest severity as an HTML table; with ``checks`` (the verdict's
    checks under the ripple, :func:`model.studies.assessment.ripple_case`) the check each drives
    and its safety factor."""
    if not view.crossings:
        return "<i>no order line meets a mode in the speed range</i>"
    if checks is None:
        drives = ["(when the verdict is computed)"] * len(view.crossings)
    else:
        drives = [driven_check(c, checks) for c in view.crossings]
    rows = "".join(
        f"<tr><td>{c.v_kmh:.1f}</td><td>{c.f_hz:.2f}</td><td class='text'>{html.escape(c.label)}"
        f"</td><td>{c.zeta:.4f}</td><td><b>{c.severity:.3g}</b></td>"
        f"<td class='text'>{html.escape(c.worst_output)}</td>"
        f"<td class='text'>{html.escape(c.mode)}</td><td class='text'>{html.escape(d)}</td></tr>"
        for c, d in zip(view.crossings[:listed], drives, strict=False))
    return (f"<b>Crossings</b> ({len(view.crossings)}, the {min(listed, len(view.crossings))} "
            f"most severe; severity = torque amplitude per N m of {html.escape(view.input)} at "
            "that order; the verdict's ripple check each drives)<table class='bogie'><tr>"
            "<th>v [km/h]</th><th>f [Hz]</th><th class='text'>order</th><th>ζ [-]</th>"
            "<th>N m/N m</th><th class='text'>in</th><th class='text'>mode</th>"
            "<th class='text'>drives</th></tr>" + rows + "</table>")
