"""HTML tables of results, shared by the dashboard and the report: Table 1's layout (eigenvalues),
Table 2's (mode descriptions) and the peaks of the short-circuit response.  Units in every
header: Re [1/s], Im [Hz], torques [N m], forces [N], times [s]."""

from __future__ import annotations

import html
import math

from app.results import compute


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


def peaks_html(response: compute.ResponseView) -> str:
    """Peaks (signed total of largest magnitude) and their times, per output."""
    rows = []
    for name in response.outputs:
        peak, unit = response.peaks[name], response.units[name]
        over = unit == "N m" and "disc_clutch" in name and abs(peak) > response.M_ad
        value = f"{peak:,.0f}" if abs(peak) < 1e7 else f"{peak:.3e}"
        rows.append(f'<tr><td class="text">{name}</td><td class="{"bad" if over else ""}">'
                    f"{value} {unit}</td><td>{response.peak_times[name]:.4f} s</td></tr>")
    note = ""
    if response.truncated_at is not None:
        note = f" — growth: the time grid was cut at {response.truncated_at:.3f} s"
    elif response.plot_cut is not None:
        note = f" — unstable growth (plots end at {response.plot_cut:.3f} s; CSV has all)"
    crossings = "; ".join(f"{o} exceeds {n} at {t:.3f} s" for o, n, t, _ in response.crossings[:4])
    return (f"<b>Peaks</b> (M_ad = {response.M_ad:,.0f} N m){note}"
            '<table class="bogie"><tr><th class="text">output</th><th>peak</th><th>at</th></tr>'
            + "".join(rows) + "</table>"
            + (f"<div style='font-size:12px'>{html.escape(crossings)}</div>" if crossings else ""))
