"""The "Design loads" view: what a design review signs off for each drive part (driving shaft,
disc clutch, claw clutch torques, gear mesh force; ID1 and ID2) at the dashboard's point.

* **The worst case over every fault instant**, live with the sliders: the short-circuit torque's
  time shift Δt was not published, and with linear creep the response is linear in sin ωΔt and
  cos ωΔt, so three closed-form responses give the max and the min over every Δt at each time
  (:mod:`model.analysis.fault_instant`; cached: :func:`app.results.compute.worst_case_result`).
  A table per drive part (max and min over every Δt, the Δt and the time of each, the peaks of
  the history at the dashboard's Δt) and the band of the selected part against time, with the
  Response tab's history (and the nonlinear one, with nonlinear creep on) for comparison.
* **A grid envelope on the server's study engine** (:mod:`app.dashboard.envelope_grid`).
* **The load spectrum of the history on screen** — the linear one, or the nonlinear one with the
  nonlinear creep model on: rainflow counts, the load collective (cumulative exceedance), the
  rainflow matrix and the damage-equivalent ranges for Wöhler slopes m = 3 and 5
  (:mod:`model.analysis.load_spectrum`; cached: :func:`app.results.compute.spectra_result`).

The computations run off the main thread when served, on the shared pools of
:mod:`app.services.thread_pools` with one waiting request per session and kind
(:class:`app.dashboard.jobs.ViewJob`), and only while the tab is shown (the dashboard calls
:meth:`DesignLoadsView.request_worst_case` and :meth:`DesignLoadsView.show_history` through
``when_shown``).  The nonlinear history's spectrum runs on the nonlinear creep model's own
worker, after that history (one worker: it never computes the same history twice).
"""

from __future__ import annotations

import html
from functools import partial

import panel as pn

from app.dashboard.envelope_grid import EnvelopeGrid
from app.dashboard.jobs import ViewJob
from app.results import compute
from app.results.case import CaseBase
from app.results.load_plots import LoadCollectivePlot, RainflowMatrixPlot, WorstCasePlot
from app.results.tables import spectra_html, worst_case_html
from app.services.thread_pools import FOLLOW_UP_POOL, NONLINEAR_POOL

PARTS = {compute.PART_LABELS[part]: part for part in compute.PARTS}
INTRO = """The largest load each drive part can see decides its size.  The short circuit's time
shift Δt was not published: the **worst case over every fault instant** (linear creep, closed
form: three responses give every Δt) is the conservative bound, the **continuity root** (the
motor torque does not jump at the fault) the physical instant.  A **grid envelope** varies two
more quantities on the server's study engine; the **load spectrum** counts the cycles of the
history on screen.  Definitions and what the numbers do not include: docs/design-loads.md."""


class DesignLoadsView:
    """The Design loads tab of one dashboard (``layout``)."""

    def __init__(self, dashboard, queue=None):
        """``dashboard``: its public interface (``state()``, ``alive()``, ``post()``,
        ``point``, ``nonlinear``) and what :class:`app.dashboard.envelope_grid.EnvelopeGrid`
        reads; ``queue``: the server's study queue (default: the process's)."""
        self.dash = dashboard
        self._worst_job = ViewJob(FOLLOW_UP_POOL, dashboard.alive, "worst case")
        self._spectra_job = ViewJob(NONLINEAR_POOL, dashboard.alive, "load spectrum")
        self.worst: compute.WorstCaseView | None = None  # shown
        self.spectra: compute.SpectraView | None = None  # shown
        self.nonlinear_history: compute.ResponseView | None = None  # overlaid (nonlinear creep)
        self._spectra_key: compute.HistoryKey | None = None  # the key of the spectra shown
        self.part = pn.widgets.RadioButtonGroup(options=PARTS, value="disc_clutch.torque",
                                                css_classes=["ctl-loads-part"])
        self.worst_note = pn.pane.HTML("", css_classes=["loads-worst-note"],
                                       sizing_mode="stretch_width")
        self.worst_table = pn.pane.HTML("", css_classes=["loads-worst"],
                                        sizing_mode="stretch_width")
        self.spectra_note = pn.pane.HTML("", css_classes=["loads-spectra-note"],
                                         sizing_mode="stretch_width")
        self.spectra_table = pn.pane.HTML("", css_classes=["loads-spectra"],
                                          sizing_mode="stretch_width")
        self.worst_plot = WorstCasePlot()
        self.collective = LoadCollectivePlot()
        self.matrix = RainflowMatrixPlot()
        self.grid = EnvelopeGrid(dashboard, queue)
        self.part.param.watch(lambda _event: self._redraw(), "value")
        bokeh = partial(pn.pane.Bokeh, sizing_mode="stretch_width")
        self.layout = pn.Column(
            pn.pane.Markdown(INTRO, sizing_mode="stretch_width"),
            pn.Row(pn.pane.HTML("<b>drive part in the plots</b>"), self.part),
            "#### Worst case over every fault instant at this point",
            self.worst_note, self.worst_table,
            pn.Row(*(bokeh(f) for f in self.worst_plot.figure_list),
                   sizing_mode="stretch_width"),
            "#### Load spectrum of the history on screen",
            self.spectra_note, self.spectra_table,
            pn.Row(bokeh(self.collective.figure),
                   *(bokeh(f) for f in self.matrix.figure_list), sizing_mode="stretch_width"),
            "#### Grid envelope on the server's study engine",
            self.grid.layout,
            sizing_mode="stretch_width", css_classes=["design-loads-view"])

    # --- requests ------------------------------------------------------------------------------

    def request_worst_case(self, state: CaseBase) -> None:
        """The worst case over every fault instant at the dashboard's ``state`` (its point, the
        excitation and the simulated time)."""
        if self.worst is not None and self.worst.case == state:
            self._worst_job.want(state)
            self._apply_worst(state, self.worst)  # back to the point shown: its note again
            return
        self.worst_note.object = "<i>computing the worst case over every fault instant…</i>"
        self._worst_job.start(state, lambda: compute.worst_case_result(state), self._apply_worst,
                              partial(self._failed, self.worst_note, "the worst case"))

    def show_history(self, key: compute.HistoryKey, history: compute.ResponseView) -> None:
        """The history on screen changed (the linear one, or the nonlinear one with nonlinear
        creep on): overlay it and count its cycles.  ``key``: which history."""
        self.nonlinear_history = history if history.nonlinear else None
        if self.worst is not None:
            self._redraw_worst()
        if self.spectra is not None and self._spectra_key == key:
            self._spectra_job.want(key)
            self._apply_spectra(key, self.spectra)
            return
        self.spectra_note.object = "<i>counting the cycles…</i>"
        self._spectra_job.start(key, lambda: compute.spectra_result(key.case, key.anti_slip),
                                self._apply_spectra,
                                partial(self._failed, self.spectra_note, "the load spectrum"))

    def _failed(self, note, what: str, _key, error: BaseException) -> None:
        message = error.args[0] if error.args else type(error).__name__
        note.object = f"<i>{what} is not available here: {html.escape(str(message))}</i>"

    # --- showing -------------------------------------------------------------------------------

    def _apply_worst(self, case: CaseBase, worst: compute.WorstCaseView) -> None:
        self.worst = worst
        self.worst_table.object = worst_case_html(worst)
        point = self.dash.point
        text = (f"At s0 = {case.s0:g}, v = {case.v:g} km/h, rail {html.escape(case.rail)}: "
                "linear creep, closed form over every fault instant Δt (totals: pre-fault + "
                "perturbation).")
        if point is not None and point.case == case.point() and not point.stable:
            text += (" <b>The operating point is unstable:</b> the linear response grows "
                     "without bound, and so does its worst case — it says “unstable”, not a "
                     "design load.  The nonlinear creep model bounds the history (the creep "
                     "switch; its curves are drawn in red), and a grid envelope with nonlinear "
                     "creep gives its peaks over the continuity roots.")
        if worst.truncated_at is not None:
            text += f" The time grid was cut at {worst.truncated_at:.3f} s (growth beyond 1e250)."
        self.worst_note.object = f"<div style='font-size:13px'>{text}</div>"
        self._redraw_worst()

    def _apply_spectra(self, key: compute.HistoryKey, spectra: compute.SpectraView) -> None:
        self.spectra, self._spectra_key = spectra, key
        self.spectra_table.object = spectra_html(spectra)
        point = self.dash.point
        text = (f"Cycles of the history with <b>{html.escape(spectra.history)}</b> "
                f"(Δt = {spectra.fault_instant * 1e3:.4g} ms), the one the Response tab's peak "
                "table describes.")
        if spectra.history == compute.LINEAR_HISTORY and point is not None \
                and point.case == key.case.point() and not point.stable:
            text += (" <b>Unstable point, linear creep:</b> this is the spectrum of a blow-up "
                     "and means nothing; switch the creep model to nonlinear.")
        self.spectra_note.object = f"<div style='font-size:13px'>{text}</div>"
        self._redraw_spectra()

    def _redraw(self) -> None:
        if self.worst is not None:
            self._redraw_worst()
        if self.spectra is not None:
            self._redraw_spectra()

    def _redraw_worst(self) -> None:
        part = self.part.value
        if part in compute.PARTS:
            self.worst_plot.update(self.worst, part, self.nonlinear_history)

    def _redraw_spectra(self) -> None:
        part = self.part.value
        if part in compute.PARTS:
            self.collective.update(self.spectra, part)
            self.matrix.update(self.spectra, part)
