"""The dashboard: a :class:`panel.viewable.Viewer` with ``param`` parameters, one per session.

It owns the parameters, the last valid results and the first answers on screen (status, root
locus, time histories, tables); its pieces have modules of their own:

* :mod:`.controls` — the controls column (they write into the parameters);
* :mod:`.stages` — the state a computation depends on, and the computations of a change;
* :mod:`.scheduler` — when and where they run (served: on worker threads, the results shown on
  the session's next tick) and the follow-ups (dense root locus, s0*(v));
* :mod:`.layout` — the page, the tabs of the views and the views of the first tabs;
* :mod:`.downloads` — the files (CSV, JSON, TOML, HTML report);
* :mod:`.session` — the served session's document, its URL query, showing results with its lock.

The views (modes, nonlinear creep, sensitivity, studies, variant, design loads, resonances) get the
dashboard object and use its public interface only: ``state()`` (the case record on the
controls, :class:`app.results.case.Case`), ``latest`` (the newest one, readable from any thread),
``sweep()``, ``alive()``, ``post(doc, function, *args)``, ``run_locked(function, *args)``,
``warn(text)``, ``clear_warning()``, ``when_shown(tab, function, *args)``, ``flush_view(tab)``,
``base_key``, ``set_key``, ``study_owner`` (the session's claim in the server's study queue),
``show_history(key, history)`` and ``show_companion(key, history)`` (the nonlinear view: which
history the peak table describes, and the nonlinear one beside an unbounded linear one),
``show_mode(mode, where)`` (a mode picked elsewhere, shown in the Modes view), the parameters,
the last valid results (``point``, ``response``, ``history``, ``locus_result``), the nonlinear
view's creep switch and anti-slip key (``nonlinear``) and the plots they draw on.  A rejected
parameter combination shows a notice and keeps the last valid results on screen.

The case's quantities (:data:`app.results.case.QUANTITIES`) are the dashboard's parameters
(:func:`app.dashboard.controls.case_parameters`): a new quantity is a new parameter, slider,
link argument and part of :meth:`BogieDashboard.state` without a line here.
"""

from __future__ import annotations

import html
import secrets

import panel as pn
import param

from app.dashboard import layout
from app.dashboard.controls import PUBLISHED_SPEED_KMH, Controls, automatic_name, case_parameters
from app.dashboard.design_loads_view import DesignLoadsView
from app.dashboard.downloads import Downloads
from app.dashboard.drag_preview import DragPreview
from app.dashboard.modes_view import ModeClickThrough
from app.dashboard.nonlinear_view import NonlinearView
from app.dashboard.panel_fixes import skip_detached_markup_models
from app.dashboard.resonance_view import ResonanceView
from app.dashboard.scheduler import Scheduler
from app.dashboard.sensitivity_view import SensitivityView
from app.dashboard.session import post, run_locked, served_document, session_query
from app.dashboard.studies_view import StudiesView
from app.dashboard.url_state import make_query, parse_query
from app.dashboard.variant_view import VariantView
from app.dashboard.verdicts_view import VerdictsView
from app.results import compute
from app.results.case import Case, CaseBase, Sweep
from app.results.eigenvalue_sweep import Fig6Plot
from app.results.plots import CreepPlot, ModeShapePlot, ResponsePlots, RootLocusPlot
from app.results.tables import eigen_table_html, peaks_html
from app.services.thread_pools import limit_blas_threads

skip_detached_markup_models()  # the views' tabs are dynamic (app/dashboard/panel_fixes.py)
# the page loads the script of each extension model up front: the mode table (Tabulator) sits in
# a tab that reaches the browser only when it is opened
pn.extension("tabulator")

class BogieDashboard(pn.viewable.Viewer):
    """Stability and short-circuit load of the bogie at one operating point."""

    case_type = Case  # the record of the case's quantities (their declarations: case_type.quantities)
    locals().update(case_parameters(Case.quantities))  # one parameter per quantity
    locus = param.Selector(default="s0", objects=["s0", "v"], doc="root locus over s0 or v")
    zoom = param.Selector(default="all", objects=["all", "low"], doc="root locus view")
    mode = param.Integer(1, bounds=(1, compute.N_COMPLEX_TABLE), doc="mode shown (ν)")
    variant = param.String("", doc="design variant: differences from the bundled set, "
                                   "name:value,… in SI units (app.results.variants)")

    def __init__(self, base_key: str | None = None, query=None, **params):
        """``base_key``: the bundled parameter set (a parameter file; None: the calibrated set),
        the set a variant refers to; ``query``: URL query arguments to restore (served: the
        session's, app.dashboard.url_state); ``params``: parameter values (they win over the
        query)."""
        limit_blas_threads()
        if query is None:
            query = session_query()
        values, variant, query_tab, query_notices = parse_query(
            query, type(self).param, None, base=str(base_key or ""),
            quantities=self.case_type.quantities)
        params = {**values, **({"variant": variant} if variant else {}), **params}
        super().__init__(**params)
        self._base_key = str(base_key or "")
        base = compute.parameters(self._base_key)
        with param.parameterized.discard_events(self):
            # a quantity whose default is the set's (N0, b_M, …) starts at the set's value
            for name, value in self.case_type.defaults(base).items():
                if self.case_type.quantity(name).from_set and name not in params:
                    setattr(self, name, value)
        self.point: compute.PointResult | None = None  # last valid results
        self.limit: compute.LimitResult | None = None
        self._limit_for: CaseBase | None = None  # the limit key of self.limit
        self.locus_result: compute.LocusResult | None = None
        self.shown_locus: tuple[Sweep, bool] | None = None  # (sweep, dense?) of the locus on screen
        self.response: compute.ResponseView | None = None  # the linear history
        # the history the peak table, the CSV and the report describe: the linear one, or the
        # nonlinear one with nonlinear creep on (None while it is computed); and its key
        self.history: compute.ResponseView | None = None
        self.history_key: compute.HistoryKey | None = None
        self._peaks_note = ""  # why there is no history yet
        # beside an unbounded linear history: the nonlinear creep's (show_companion) and its key
        self.companion: compute.ResponseView | None = None
        self.companion_key: compute.HistoryKey | None = None
        self._companion_note = ""
        self.error = ""  # last rejection message ("" if the current parameters are valid)
        self.closed = False  # the served session has ended: nothing more is computed for it
        # the session's claim on its study in the server's queue (Studies and Design loads tabs:
        # one study at a time per session)
        self.study_owner = secrets.token_hex(8)
        self.latest: CaseBase = self.state()  # the newest state (read by worker threads)
        self.scheduler = Scheduler(self)
        self._build()
        self.param.watch(self._on_change, self.computed_parameters())
        self._restore_tab(query_tab, query_notices)
        self.param.watch(self._share, list(self.param))
        self.tabs.param.watch(self._share, "active")
        self.view_tabs.on_opening(self._tab_shown)
        self._tab_shown()
        self.param.watch(self._on_mode, ["mode"])
        self.param.watch(lambda e: self.locus_plot.zoom(e.new == "low"), ["zoom"])
        doc = served_document()
        if doc is not None:
            doc.on_session_destroyed(self._session_closed)
            # served: show the fast results at once, the root locus and s0* when they are ready
            self.scheduler.refresh(slow=False)
            self.scheduler.request(doc, loading=False)
        else:
            self.scheduler.refresh()

    def __panel__(self):
        return self.layout

    # --- the page ------------------------------------------------------------------------------

    def _build(self) -> None:
        m = compute.model(self._base_key)
        self.locus_plot = RootLocusPlot()
        self.fig6 = Fig6Plot()
        self.creep_plot = CreepPlot()
        self.response_plots = ResponsePlots()
        self.mode_plot = ModeShapePlot(m.positions, m.parameters["wheel_radius"])
        self.nonlinear = NonlinearView(self)  # creep model, anti-slip, overlays
        self.status = layout.html_pane("", css_classes=["stability-status"])
        # a dragged operating-point slider's preview on the status and the markers
        self.drag_preview = DragPreview(self)
        self.details = layout.html_pane("", css_classes=["stability-details"])
        self.notice = pn.pane.Alert("", alert_type="danger", visible=False,
                                    css_classes=["model-notice"], sizing_mode="stretch_width")
        # input that was not used (a bad link, file or value): stays until the next such notice
        self.input_notice = pn.pane.Alert("", alert_type="warning", visible=False,
                                          css_classes=["input-notice"],
                                          sizing_mode="stretch_width")
        self.peaks = layout.html_pane("", css_classes=["peak-table"])
        self.eigen_table = layout.html_pane("", css_classes=["eigen-table"])
        self.mode_select = pn.widgets.Select(label="mode ν", options={}, width=420,
                                             css_classes=["ctl-mode"])
        self.mode_select.link(self, value="mode")
        locus_choice = pn.widgets.RadioButtonGroup.from_param(
            self.param.locus, options={"locus over s0": "s0", "locus over speed v": "v"},
            css_classes=["ctl-locus"])
        zoom = pn.widgets.RadioButtonGroup.from_param(
            self.param.zoom, options={"all modes ≤ 20 Hz": "all", "low modes": "low"},
            css_classes=["ctl-zoom"])
        self.sensitivity = SensitivityView(self.alive)  # sensitivity tornado
        self.variant_view = VariantView(self)
        self.click = ModeClickThrough(self)  # tapped locus points and table rows -> mode views
        self.verdicts = VerdictsView(self)  # safety factors of every fit, shaft and coupling
        self.view_tabs = layout.ViewTabs(
            ("Response", layout.response_view(self.creep_plot, self.peaks, self.response_plots)),
            ("Fig. 6", layout.fig6_view(self.fig6)),
            ("Modes", layout.modes_view(self.eigen_table, self.click, self.mode_select,
                                        self.mode_plot)),
            ("Variant", self.variant_view),
            ("Schematic", layout.schematic_view()))
        self.tabs = self.view_tabs.tabs
        self.main = pn.Column(
            self.notice, self.input_notice, self.nonlinear.notice,
            pn.Row(pn.Column(self.status, self.verdicts.indicator, self.scheduler.busy_notice,
                             self.details, self.nonlinear.status, width=330),
                   pn.Column(pn.Row(locus_choice, zoom), layout.bokeh_pane(self.locus_plot.figure),
                             sizing_mode="stretch_width"),
                   sizing_mode="stretch_width"),
            self.tabs, sizing_mode="stretch_width")
        self.view_tabs.add("Sensitivity", self.sensitivity.panel)
        self.studies = StudiesView(self)  # stability maps over s0 × v from the server's queue
        self.view_tabs.add("Studies", self.studies.layout)
        # the worst case over the fault instant, grid envelopes, load spectra
        self.design_loads = DesignLoadsView(self)
        self.view_tabs.add("Design loads", self.design_loads.layout)
        # the Campbell diagram, the frequency response, the forced response to a torque ripple
        self.resonances = ResonanceView(self)
        self.view_tabs.add("Resonances", self.resonances.layout)
        self.view_tabs.add("Verdicts", self.verdicts.layout)
        self.downloads = Downloads(self)
        self.controls = Controls(self, self.nonlinear.controls, self.downloads.widgets)
        self.sliders = self.controls.sliders
        self.layout = pn.Row(self.controls.column, self.main, sizing_mode="stretch_width",
                             stylesheets=[layout.CSS])

    # --- the public interface of the views -----------------------------------------------------

    def alive(self) -> bool:
        """Whether results are still wanted (False once the served session has ended)."""
        return not self.closed

    def _session_closed(self, session_context) -> None:
        """The browser has left: work not yet started for this session is dropped."""
        self.closed = True

    @property
    def base_key(self) -> str:
        """The key of the bundled parameter set in use (a parameter file; "": the calibrated
        set); the variant, if any, changes it (:attr:`set_key`)."""
        return self._base_key

    @property
    def set_key(self) -> str:
        """The parameter set in use for app.results.compute: the bundled file, or a variant of it."""
        return f"{self._base_key}|{self.variant}" if self.variant else self._base_key

    def computed_parameters(self) -> list[str]:
        """The parameters whose change is computed (the others only change the view): every
        quantity's, its "automatic" switch, the root locus's sweep and the variant."""
        names = []
        for q in self.case_type.quantities:
            names += [automatic_name(q), q.name] if q.automatic else [q.name]
        return [*names, "locus", "variant"]

    def state(self) -> CaseBase:
        """The case on the controls (:class:`app.results.case.Case`): what a computation depends
        on, each value rounded as the record keeps it (no float noise in the cache's keys)."""
        values = {}
        for q in self.case_type.quantities:
            automatic = q.automatic and getattr(self, automatic_name(q))
            values[q.name] = None if automatic else getattr(self, q.name)
        return self.case_type(set_key=self.set_key, **values)

    def sweep(self, case: CaseBase | None = None) -> Sweep:
        """The root locus on the controls through ``case``'s point (default: the state's)."""
        return (self.state() if case is None else case).sweep(self.locus)

    def state_changed(self, case: CaseBase, settled) -> None:
        """The views that compute from every state start (called with the session's lock):
        the verdict, once ``settled`` (a future: the state's follow-ups have ended)."""
        self.verdicts.request(case, after=settled)

    def post(self, doc, function, *args) -> None:
        """``function(*args)`` on the session's next tick, with its document lock; nothing if the
        session has ended meanwhile (:func:`app.dashboard.session.post`)."""
        post(doc, function, *args)

    def run_locked(self, function, *args) -> None:
        """Run ``function(*args)`` with the session's document lock: served, on the next tick;
        otherwise at once (:func:`app.dashboard.session.run_locked`)."""
        run_locked(function, *args)

    def warn(self, text: str) -> None:
        """Show a notice about input that was not used (the previous state is kept)."""
        self.input_notice.object = html.escape(text)
        self.input_notice.visible = True

    def clear_warning(self) -> None:
        """Hide the notice about unused input (the input it named has been corrected)."""
        self.input_notice.visible = False

    def when_shown(self, tab: str, function, *args) -> None:
        """``function(*args)`` now if the view's tab (``tab_names``) is open or the dashboard is
        not served, else when the tab is opened (of several calls of one function for a hidden
        tab, the last one)."""
        self.view_tabs.when_shown(tab, function, *args)

    def flush_view(self, tab: str) -> None:
        """Apply the updates the view ``tab`` missed while hidden, in the order they came."""
        self.view_tabs.flush(tab)

    def show_mode(self, mode: compute.Mode, where: str) -> None:
        """Open the Modes view on ``mode`` (its shape, description and energy shares); ``where``
        says where it was picked (the Resonances view's tapped Campbell point)."""
        self.tabs.active = self.view_tabs.names.index("modes")
        self.click.show_mode(mode, where)

    def show_published_case(self, s0: float) -> None:
        """The operating point of one of the study's published cases: ``s0`` at 120 km/h."""
        self.param.update(s0=s0, v=PUBLISHED_SPEED_KMH)

    # --- shareable state (app.dashboard.url_state) ----------------------------------------------

    @property
    def tab_names(self) -> list[str]:
        """The views' names in the URL (``tab=``): their titles in lower case, words joined
        by '-'."""
        return list(self.view_tabs.names)

    def share_query(self) -> str:
        """The URL query (without '?') that restores this session's settings."""
        return make_query(self, self.view_tabs.shown if self.tabs.active else None)

    def _restore_tab(self, tab: str | None, notices: list[str]) -> None:
        if tab is not None:
            if tab in self.view_tabs.names:
                self.tabs.active = self.view_tabs.names.index(tab)
            else:
                notices.append(f"tab = '{tab[:40]}' is not one of {', '.join(self.tab_names)}")
        if notices:
            self.warn("Some settings of the link were not used (defaults kept): "
                      + "; ".join(notices))

    def _tab_shown(self) -> None:
        """Views that compute only while shown (the variant comparison, the resonances) learn it
        here; the updates a hidden view missed are applied (before the opened view's models are
        made: :class:`app.dashboard.layout.OpeningTabs`)."""
        shown = self.view_tabs.shown
        self.variant_view.on_shown(shown == "variant")
        self.resonances.on_shown(shown == "resonances")
        self.verdicts.on_shown(shown == "verdicts")
        self.flush_view(shown)

    def _share(self, *_events) -> None:
        """Keep the browser's address (served) equal to the settings: a link to share."""
        location = pn.state.location if pn.state.curdoc is not None else None
        if location is not None and pn.state.curdoc.session_context is not None:
            location.search = "?" + self.share_query()

    # --- computing and showing results ---------------------------------------------------------

    def _on_change(self, *_events) -> None:
        self.latest = self.state()
        doc = served_document()
        if doc is None:
            self.scheduler.refresh()
        else:
            self.scheduler.request(doc)

    def show_fast(self, state: CaseBase, fast) -> None:
        """Show the first answer ``(point result, response result)`` for ``state``."""
        point, response = fast
        self.show_point(state, point)
        self.show_response(state, response)

    def show_point(self, state: CaseBase, point: compute.PointResult) -> None:
        """Show the eigen-analysis of ``state``'s point: the status, the point on the root locus
        and the creep characteristic, the tables and mode shapes (served, the short-circuit
        history follows: :meth:`show_response`)."""
        self.drag_preview.end()
        self.point, self.error = point, ""
        self.notice.visible = False
        self.locus_plot.update_point(point)
        self.creep_plot.update_point(point)
        self._show_status()
        self.when_shown("modes", self._show_modes, point)
        self.locus_plot.zoom(self.zoom == "low")

    def show_response(self, state: CaseBase, response: compute.ResponseView) -> None:
        """Show the short-circuit history of ``state`` and start the views that follow it."""
        self.response = response
        self.response_plots.update(response)
        # the sensitivity tornado is computed when its tab is open, shown when ready
        self.when_shown("sensitivity", self.sensitivity.request, state)
        self.when_shown("design-loads", self.design_loads.request_worst_case, state)
        self.resonances.request(state)  # computed while its tab is open
        # the nonlinear result follows; the peak table shows the history of the creep model in
        # use (show_history, called by the nonlinear view)
        self.nonlinear.on_fast(state)

    def show_history(self, key: compute.HistoryKey, history: compute.ResponseView | None,
                     note: str = "") -> None:
        """The history the peak table, its limit crossings, the CSV download and the report
        describe: the linear one, or the nonlinear one when the nonlinear creep model is on
        (``history`` None: not ready, ``note`` says why).  ``key``: which history."""
        self.history, self.history_key = history, key
        self._peaks_note = note
        self._show_peaks()
        self.downloads.describe(history)
        if history is not None:
            self.when_shown("design-loads", self.design_loads.show_history, key, history)

    def show_companion(self, key: compute.HistoryKey | None,
                       companion: compute.ResponseView | None, note: str = "") -> None:
        """The nonlinear creep's history beside a linear one that grows without bound (the peak
        table's physical answer at an unstable point; ``companion`` None: not ready or not
        wanted, ``note`` says why).  ``key``: which history (None: none)."""
        self.companion, self.companion_key, self._companion_note = companion, key, note
        self._show_peaks()

    def _show_peaks(self) -> None:
        history = self.history
        self.peaks.object = (
            peaks_html(history, self.companion, self._companion_note) if history is not None
            else f"<b>Peaks</b> — {html.escape(self._peaks_note)}")

    def described_history(self) -> compute.ResponseView:
        """The history the peak table describes; computed now (cached) if it is not ready yet
        (raises what the model raises)."""
        if self.history is not None:
            return self.history
        return self.history_key.result

    def _show_modes(self, point: compute.PointResult) -> None:
        """The Modes tab: eigenvalue table, mode table, mode choice and the selected mode."""
        self.eigen_table.object = eigen_table_html(point)
        self.click.table.update(point)
        self.mode_select.options = {f"ν = {m.number}: {m.im_hz:.3f} Hz — {m.description}"[:90]:
                                    m.number for m in point.modes}
        self.mode_select.value = min(self.mode, len(point.modes))
        self._on_mode()

    def _on_mode(self, *_events) -> None:
        if self.point is not None and 1 <= self.mode <= len(self.point.modes):
            self.mode_plot.update(self.point.modes[self.mode - 1].displacement)
            self.mode_select.value = self.mode
            self.click.show_point_mode()
            self.sensitivity.show(mode=self.mode)

    def show_limit(self, state: CaseBase, limit: compute.LimitResult) -> None:
        """Show the stability limit s0*(v) computed for ``state``."""
        self.limit, self._limit_for = limit, state.limit_key()
        self.creep_plot.update_limit(limit)
        self.when_shown("fig-6", self.fig6.update_limit, limit.s0_limit)
        self._show_status()

    def show_locus(self, sweep: Sweep, locus: compute.LocusResult) -> None:
        """Show the root locus computed for ``sweep`` (nothing if another sweep is shown now)."""
        if self.sweep() != sweep:
            return  # a late result of a sweep no longer shown
        self.locus_result = locus
        self.shown_locus = (sweep, locus.dense)
        self.locus_plot.update_locus(locus)
        self.when_shown("fig-6", self.fig6.update_locus, locus)
        self.locus_plot.zoom(self.zoom == "low")

    def reject(self, error: Exception) -> None:
        """The model rejects the parameters: say why, keep the last valid results on screen."""
        message = error.args[0] if error.args else str(error)
        self.drag_preview.end()
        self.error = str(message)
        self.notice.object = (f"**The model rejects this combination:** {html.escape(str(message))}"
                              " — showing the last valid result.")
        self.notice.visible = True

    def _show_status(self) -> None:
        point = self.point
        word = "STABLE" if point.stable else "UNSTABLE"
        self.status.object = (f'<div class="status-box {"ok" if point.stable else "bad"}">'
                              f"{word}</div>")
        s0, v_kmh = point.case.s0, point.case.v
        if self.limit is None or self._limit_for != point.case.limit_key():
            limit = "s0*(v): computing…"
        elif self.limit.s0_limit is None:
            limit = f"s0*(v): none ({html.escape(self.limit.message)})"
        else:
            margin = self.limit.s0_limit - s0
            limit = (f"s0*({v_kmh:g} km/h) = <b>{self.limit.s0_limit:.5f}</b><br>"
                     f"margin s0* − s0 = <b>{margin:+.5f}</b> ({margin / self.limit.s0_limit:+.0%})")
        self.details.object = (
            f"<div style='font-size:13px;line-height:1.5'>"
            f"largest Re λ = <b>{point.max_real_part:+.4f}</b> 1/s<br>"
            f"flutter pairs (Re &gt; 0): <b>{point.flutter}</b><br>"
            f"divergent real eigenvalues: <b>{point.divergence}</b><br>{limit}<br>"
            f"μ(s0) = {point.mu0:.4f}, μ_max = {point.mu_max:.4f} at s = {point.s_max:.4f}<br>"
            f"M_ad = 2 N0 r0 μ_max = {point.M_ad:,.0f} N m</div>")
