"""Click-through modes: a tapped root-locus point or a clicked row of the mode table (Table 2
layout) shows that mode's shape (the dashboard's side and top views), its description and its
energy shares per subsystem (kinetic: which parts move; strain: what deforms).

A tapped current-point diamond or table row is the mode ν of the current operating point; a
tapped point of the sweep is the mode nearest to that eigenvalue at *that* point of the sweep
(:func:`app.results.compute.mode_near`, one eigen-analysis, kept; served, on a worker thread:
:class:`app.dashboard.jobs.ViewJob`).
"""

from __future__ import annotations

import html
import math
from typing import ClassVar

import panel as pn

from app.dashboard import layout
from app.dashboard.jobs import ViewJob
from app.results import compute
from app.services.thread_pools import FIRST_ANSWER_POOL
from model.analysis.modes import COMPONENT_LABELS, STRAIN_LABELS

SHARE_SHOWN = 0.01  # energy shares below this are not listed [-]


def _bars(shares: dict[str, float], labels: dict[str, str], color: str) -> str:
    rows = []
    for name, share in sorted(shares.items(), key=lambda item: -item[1]):
        if share < SHARE_SHOWN:
            break
        width = max(1, round(160 * share))
        rows.append(f'<tr><td class="text">{html.escape(labels.get(name, name))}</td>'
                    f"<td>{share:.1%}</td><td class='text'><div style='width:{width}px;"
                    f"height:9px;background:{color}'></div></td></tr>")
    return ('<table class="bogie">' + "".join(rows) + "</table>") if rows else "<i>none</i>"


def mode_detail_html(mode: compute.Mode, where: str) -> str:
    """Description, eigenvalue and energy shares of one mode; ``where`` names the operating
    point (and how the mode was picked)."""
    lam = mode.eigenvalue
    number = f"ν = {mode.number}" if mode.number else "real eigenvalue"
    frequency = (f"{lam.real:+.4f} ± i {abs(lam.imag) / (2 * math.pi):.3f} Hz" if lam.imag
                 else f"{lam.real:+.4f} 1/s")
    return (f"<b>{number}</b>: λ = {frequency} [1/s ± i Hz], ζ = {mode.damping_ratio:+.4f}"
            f"<br><i>{html.escape(where)}</i><br><b>{html.escape(mode.description)}</b>"
            "<div style='display:flex;gap:24px;flex-wrap:wrap'>"
            "<div><b>kinetic energy</b> (what moves)"
            f"{_bars(mode.kinetic, COMPONENT_LABELS, '#1f77b4')}</div>"
            "<div><b>strain energy</b> (what deforms)"
            f"{_bars(mode.strain, STRAIN_LABELS, '#d62728')}</div></div>")


class ModeTable:
    """The modes of the current point in the layout of Table 2 as a table whose rows can be
    clicked (a Panel Tabulator, CSS class ``mode-table``; Bokeh's own DataTable failed to lay
    out inside a hidden tab: "Cannot read properties of undefined (reading 'resizeCanvas')")."""

    COLUMNS: ClassVar[dict[str, str]] = {
        "nu": "ν", "im_hz": "Im λ [Hz]", "re": "Re λ [1/s]", "zeta": "ζ [-]",
        "description": "dominant motion (click a row)"}

    def __init__(self):
        self.table = pn.widgets.Tabulator(
            self._frame([]), titles=self.COLUMNS, show_index=False, disabled=True,
            selectable=1, layout="fit_data_stretch", sizing_mode="stretch_width", height=300,
            css_classes=["mode-table"],
            formatters={"im_hz": {"type": "money", "precision": 3, "thousand": ""},
                        "re": {"type": "money", "precision": 4, "thousand": ""},
                        "zeta": {"type": "money", "precision": 4, "thousand": ""}})

    TYPES: ClassVar[dict[str, str]] = {"nu": "int64", "im_hz": "float64", "re": "float64",
                                       "zeta": "float64", "description": "object"}

    @classmethod
    def _frame(cls, modes):
        return layout.typed_frame(cls.TYPES, [
            {"nu": m.number, "im_hz": m.im_hz, "re": m.eigenvalue.real, "zeta": m.damping_ratio,
             "description": m.description} for m in modes])

    @property
    def descriptions(self) -> list[str]:
        return list(self.table.value["description"])

    def update(self, point: compute.PointResult) -> None:
        self.table.selection = []
        self.table.value = self._frame(point.modes)


class ModeClickThrough:
    """Wires the dashboard's root locus and mode table to the mode views (one per session)."""

    def __init__(self, dashboard):
        self.dashboard = dashboard
        self.table = ModeTable()
        self.detail = pn.pane.HTML("", sizing_mode="stretch_width", css_classes=["mode-detail"])
        self.shown: compute.Mode | None = None  # the mode in the detail view
        self._job = ViewJob(FIRST_ANSWER_POOL, dashboard.alive, "tapped mode")
        plot = dashboard.locus_plot
        plot.current.selected.on_change("indices", self._on_current)
        plot.points.selected.on_change("indices", self._on_sweep)
        self.table.table.param.watch(self._on_row, "selection")

    def _on_current(self, _attr, _old, new) -> None:
        if new:
            self.dashboard.run_locked(self.select, int(new[0]) + 1)

    def _on_row(self, event) -> None:
        if event.new:
            self.dashboard.run_locked(self.select, int(event.new[0]) + 1)

    def select(self, number: int) -> None:
        """Show mode ν = ``number`` of the current operating point."""
        self.dashboard.flush_view("modes")  # the tables and views of the current point first
        point = self.dashboard.point
        if point is None or not 1 <= number <= len(point.modes):
            return
        self.dashboard.mode = number  # the dashboard's mode views follow

    def show_point_mode(self) -> None:
        """Detail of the dashboard's selected mode ν at the current point."""
        point = self.dashboard.point
        if point is None or not 1 <= self.dashboard.mode <= len(point.modes):
            return
        mode = point.modes[self.dashboard.mode - 1]
        self.shown = mode
        s0, v = point.case.s0, point.case.v
        self.detail.object = mode_detail_html(mode, f"at the current point s0 = {s0:g}, "
                                                    f"v = {v:g} km/h")

    def _on_sweep(self, _attr, _old, new) -> None:
        if new:
            self.dashboard.run_locked(self.select_sweep_point, int(new[0]))

    def select_sweep_point(self, index: int) -> None:
        """Show the mode of the root-locus point ``index`` (of the points source): the mode
        nearest to that eigenvalue at that value of the swept parameter."""
        dashboard = self.dashboard
        dashboard.flush_view("modes")  # the tables and views of the current point first
        data = dashboard.locus_plot.points.data
        locus = dashboard.locus_result
        if locus is None or not 0 <= index < len(data["x"]):
            return
        state = dashboard.state()
        value = float(data["value"][index])
        s0, v = (value, state.v) if locus.parameter == "s0" else (state.s0, value)
        re, im = float(data["x"][index]), float(data["y"][index]) * 2 * math.pi
        case = state.replace(s0=s0, v=v)
        where = (f"tapped on the root locus: s0 = {s0:.5g}, v = {v:.4g} km/h "
                 f"(nearest mode to λ = {re:+.3f} + i {im / (2 * math.pi):.3f} Hz)")
        # a model rejection: say so, keep the views
        self._job.start((case, re, im), lambda: compute.mode_near(case, re, im),
                        lambda _key, mode: self.show_mode(mode, where),
                        lambda _key, error: dashboard.warn(
                            f"Mode at the tapped point not shown: {error}"))

    def show_mode(self, mode: compute.Mode, where: str) -> None:
        """Show ``mode`` (picked anywhere: a locus point, a Campbell point) in the mode views;
        ``where`` says where it was picked."""
        self.dashboard.flush_view("modes")  # the tables and views of the current point first
        self.shown = mode
        self.dashboard.mode_plot.update(mode.displacement)
        self.detail.object = mode_detail_html(mode, where)
