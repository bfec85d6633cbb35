"""HTML tables of results, shared by the dashboard and the report: Table 1's layout (eigenvalues),
Table 2's (mode descriptions), the peaks of the short-circuit response and the crossings of the
Campbell diagram.  Units in every header: Re [1/s], Im [Hz], torques [N m], forces [N],
times [s], speeds [km/h]."""

from __future__ import annotations

import html
import math

from app.results import compute
from app.results.resonance import CampbellView


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
    s0, v = point.key[2], point.key[3]
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


def peaks_html(response: compute.ResponseView) -> str:
    """Peaks (signed total of largest magnitude) and their times, per output, and the first
    limit crossings, of the history ``response`` (the heading says which: linear or nonlinear
    creep, and its fault instant Δt)."""
    rows = []
    for name in response.outputs:
        peak, unit = response.peaks[name], response.units[name]
        over = unit == "N m" and ("disc_clutch" in name or "claw_clutch" in name) \
            and abs(peak) > response.M_ad
        rows.append(f'<tr><td class="text">{name}</td><td class="{"bad" if over else ""}">'
                    f"{format_load(peak)} {unit}</td><td>{response.peak_times[name]:.4f} s</td></tr>")
    note = ""
    if response.truncated_at is not None:
        note = f" — growth: the time grid was cut at {response.truncated_at:.3f} s"
    elif response.plot_cut is not None:
        note = f" — unstable growth (plots end at {response.plot_cut:.3f} s; CSV has all)"
    crossings = "; ".join(f"{o} exceeds {n} at {t:.3f} s" for o, n, t, _ in response.crossings[:4])
    history = (f"<div class='peaks-history'>of the history with <b>{html.escape(response.history)}"
               f"</b>, Δt = {response.fault_instant * 1e3:.4g} ms</div>")
    return (f"<b>Peaks</b> (M_ad = {response.M_ad:,.0f} N m){note}{history}"
            '<table class="bogie"><tr><th class="text">output</th><th>peak</th><th>at</th></tr>'
            + "".join(rows) + "</table>"
            + (f"<div style='font-size:12px'>{html.escape(crossings)}</div>" if crossings else ""))


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


def crossings_html(view: CampbellView, listed: int = CROSSINGS_LISTED) -> str:
    """The crossings with the largest severity as an HTML table."""
    if not view.crossings:
        return "<i>no order line meets a mode in the speed range</i>"
    rows = "".join(
        f"<tr><td>{c.v_kmh:.1f}</td><td>{c.f_hz:.2f}</td><td class='text'>{html.escape(c.label)}"
        f"</td><td>{c.zeta:.4f}</td><td><b>{c.severity:.3g}</b></td>"
        f"<td class='text'>{html.escape(c.worst_output)}</td>"
        f"<td class='text'>{html.escape(c.mode)}</td></tr>" for c in view.crossings[:listed])
    return (f"<b>Crossings</b> ({len(view.crossings)}, the {min(listed, len(view.crossings))} "
            f"most severe; severity = torque amplitude per N m of {html.escape(view.input)} at "
            "that order)<table class='bogie'><tr><th>v [km/h]</th><th>f [Hz]</th>"
            "<th class='text'>order</th><th>ζ [-]</th><th>N m/N m</th>"
            "<th class='text'>in</th><th class='text'>mode</th></tr>" + rows + "</table>")
