"""The dashboard: a :class:`panel.viewable.Viewer` with ``param`` parameters, one per session.

Controls are built per instance (never shared class attributes) and write into the parameters
on ``value_throttled`` (slider release / keyboard step), so a drag triggers one computation.
Heavy work runs in :mod:`app.results.compute` (cached, shared read-only across sessions).  In a served
session it runs on a worker thread without the document lock, so several reviewers on one
server do not queue behind each other; the results are applied on the next tick with the lock.
Without a server (tests) everything runs synchronously.

Two stages per change: *fast* (eigenvalues, status, creep, tables, mode shape, time histories)
and *slow* (stability limit s0*(v), root locus), which only depend on part of the parameters and
are usually cached.  A rejected parameter combination shows a notice and keeps the last valid
results on screen.
"""

from __future__ import annotations

import asyncio
import html
import io
import json
import logging
import re
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import numpy as np
import panel as pn
import param
from bokeh.document import without_document_lock

from app.dashboard.modes_view import ModeClickThrough
from app.dashboard.nonlinear_view import NonlinearView  # issue 10
from app.dashboard.panel_fixes import skip_detached_markup_models
from app.dashboard.sensitivity_view import SensitivityView  # issue 12: sensitivity tornado
from app.dashboard.session import post, run_locked, session_query
from app.dashboard.url_state import make_query, parse_query
from app.dashboard.variant_view import VariantView
from app.results import compute
from app.results.eigenvalue_sweep import Fig6Plot
from app.results.plots import STABLE, UNSTABLE, CreepPlot, ModeShapePlot, ResponsePlots, RootLocusPlot
from app.results.tables import eigen_table_html, peaks_html
from app.services.thread_pools import (
    FIRST_ANSWER_POOL,
    FOLLOW_UP_POOL,
    SIDE_VIEW_POOL,
    LatestRequest,
    ignore_outcome,
    limit_blas_threads,
)
from model import NoStabilityLimit, OperatingPointError, ParameterError
from model.mechanics.parameters import dumps_parameters

log = logging.getLogger(__name__)
skip_detached_markup_models()  # the views' tabs are dynamic (app/dashboard/panel_fixes.py)
# the page loads the script of each extension model up front: the mode table (Tabulator) sits in
# a tab that reaches the browser only when it is opened
pn.extension("tabulator")
ASSETS = Path(__file__).resolve().parents[2] / "assets"  # app/dashboard/ -> project
MODEL_ERRORS = (OperatingPointError, ParameterError, NoStabilityLimit, ValueError,
                np.linalg.LinAlgError)
BUSY_DELAY_MS = 400  # the "computing…" notice appears when a change takes longer [ms]
BUSY_TEXT = '<div class="busy-text">⏳ computing…</div>'
PUBLISHED_CASES = {"stable": 0.005, "unstable": 0.014}  # s0 at 120 km/h (the study's two cases)

CSS = """
.status-box {font-size: 30px; font-weight: 700; padding: 6px 14px; border-radius: 6px;
             color: white; text-align: center; letter-spacing: 0.05em}
.status-box.ok {background: STABLE_COLOR} .status-box.bad {background: UNSTABLE_COLOR}
table.bogie {border-collapse: collapse; font-size: 12px; width: 100%}
table.bogie th, table.bogie td {border-bottom: 1px solid #ddd; padding: 2px 6px; text-align: right}
table.bogie td.text, table.bogie th.text {text-align: left}
table.bogie td.bad {color: UNSTABLE_COLOR; font-weight: 700}
.busy-text {font-size: 13px; color: #555; font-style: italic}
""".replace("UNSTABLE_COLOR", UNSTABLE).replace("STABLE_COLOR", STABLE)


class ControlSlider(pn.widgets.FloatSlider):
    """A control slider that hands a released value on at once.  Panel holds every browser
    event of a widget for ``_debounce`` ms (50 by default) to batch events that arrive
    together; a released slider sends ``value`` and ``value_throttled`` within a millisecond,
    so 5 ms still batches them, and a slider step reaches the model ≈ 45 ms earlier (server
    timeline of one s0 step: event received → the dashboard's watcher 52 ms)."""

    _debounce = 5


@dataclass(frozen=True)
class State:
    """The primitives a computation depends on (a snapshot of the parameters)."""

    params_path: str
    rail: str
    s0: float
    v: float
    N0: float
    b_M: float
    M0: float
    f: float
    D: float
    dt: float | None
    t_end: float
    locus: str

    @property
    def point(self) -> tuple:
        return (self.params_path, self.rail, self.s0, self.v, self.N0, self.b_M)

    @property
    def locus_key(self) -> tuple:
        """What the root locus depends on: (set, rail, swept parameter, fixed value, N0, b_M)."""
        fixed = self.v if self.locus == "s0" else self.s0
        return (self.params_path, self.rail, self.locus, fixed, self.N0, self.b_M)


class BogieDashboard(pn.viewable.Viewer):
    """Stability and short-circuit load of the bogie at one operating point."""

    s0 = param.Number(0.005, bounds=(0.0005, 0.03), doc="longitudinal creepage s0 [-]")
    v = param.Number(120.0, bounds=(10.0, 250.0), doc="speed v [km/h]")
    N0 = param.Number(100.0, bounds=(40.0, 160.0), doc="static wheel force N0 [kN]")
    b_M = param.Number(3000.0, bounds=(0.0, 20000.0), doc="motor slope b_M [N m s/rad]")
    M0 = param.Number(50.0, bounds=(0.0, 200.0), doc="short-circuit amplitude M0 [kN m]")
    f = param.Number(90.0, bounds=(10.0, 300.0), doc="short-circuit frequency f [Hz]")
    D = param.Number(0.04, bounds=(0.0, 0.3), doc="short-circuit decay D [-]")
    dt_auto = param.Boolean(True, doc="Δt such that the motor torque is continuous at t = 0")
    dt = param.Number(0.0, bounds=(-10.0, 10.0), doc="short-circuit time shift Δt [ms]")
    t_end = param.Number(2.0, bounds=(0.2, 5.0), doc="simulated time [s]")
    rail = param.Selector(default="calibrated", objects=list(compute.RAIL_CONDITIONS),
                          doc="rail condition (creep law)")
    locus = param.Selector(default="s0", objects=["s0", "v"], doc="root locus over s0 or v")
    zoom = param.Selector(default="all", objects=["all", "low"], doc="root locus view")
    mode = param.Integer(1, bounds=(1, compute.N_COMPLEX_TABLE), doc="mode shown (ν)")
    variant = param.String("", doc="design variant: differences from the bundled set, "
                                   "name:value,… in SI units (app.results.variants)")

    def __init__(self, params_path: str | None = None, query=None, **params):
        """``params_path``: the bundled parameter file (None: the calibrated set); ``query``:
        URL query arguments to restore (served: the session's, app.dashboard.url_state); ``params``:
        parameter values (they win over the query)."""
        limit_blas_threads()
        if query is None:
            query = session_query()
        values, variant, self._query_tab, query_notices = parse_query(
            query, type(self).param, None, base=str(params_path or ""))
        params = {**values, **({"variant": variant} if variant else {}), **params}
        super().__init__(**params)
        self._params_path = str(params_path or "")
        base = compute.parameters(self._params_path, "calibrated")
        with param.parameterized.discard_events(self):
            if "N0" not in params:
                self.N0 = base["wheel_force"] / 1e3
            if "b_M" not in params:
                self.b_M = base["motor_slope"]
        self.point: compute.PointResult | None = None  # last valid results
        self.limit: compute.LimitResult | None = None
        self._limit_for: tuple | None = None  # (rail, v, N0, b_M) of self.limit
        self.locus_result: compute.LocusResult | None = None
        self._shown_locus: tuple | None = None  # (locus key, dense?) of the locus on screen
        self.response: compute.ResponseView | None = None
        self.error = ""  # last rejection message ("" if the current parameters are valid)
        self._pending_views: dict[tuple[str, str], tuple] = {}  # (tab, what) -> (function, args)
        self._dirty = False
        self._busy = False
        self.closed = False  # the served session has ended: nothing more is computed for it
        # one waiting follow-up per kind (app.services.thread_pools.LatestRequest): dense locus, s0*(v)
        self._dense_requests = LatestRequest(FOLLOW_UP_POOL, self.alive)
        self._limit_requests = LatestRequest(SIDE_VIEW_POOL, self.alive)
        self._build()
        self.param.watch(self._on_change, ["s0", "v", "N0", "b_M", "M0", "f", "D", "dt_auto",
                                           "dt", "t_end", "rail", "locus", "variant"])
        self._restore_tab(query_notices)
        self.param.watch(self._share, list(self.param))
        self.tabs.param.watch(self._share, "active")
        self.tabs.param.watch(self._tab_shown, "active")
        self._tab_shown()
        self.param.watch(self._on_mode, ["mode"])
        self.param.watch(lambda e: self.locus_plot.zoom(e.new == "low"), ["zoom"])
        doc = pn.state.curdoc
        if doc is not None and doc.session_context is not None:
            doc.on_session_destroyed(self._session_closed)
            # served: show the fast results at once, the root locus and s0* when they are ready
            self.refresh(slow=False)
            self._request(doc, loading=False)
        else:
            self.refresh()

    def alive(self) -> bool:
        """Whether results are still wanted (False once the served session has ended)."""
        return not self.closed

    def _session_closed(self, session_context) -> None:
        """The browser has left: work not yet started for this session is dropped."""
        self.closed = True

    # --- controls ------------------------------------------------------------------------------

    def _slider(self, name: str, label: str, step: float, fmt: str = "0[.]000"):
        p = self.param[name]
        widget = ControlSlider(label=label, start=p.bounds[0], end=p.bounds[1], step=step,
                               value=getattr(self, name), format=fmt, css_classes=[f"ctl-{name}"],
                               sizing_mode="stretch_width")
        widget.param.watch(partial(self._set_control, name), "value_throttled")
        self.param.watch(lambda event: setattr(widget, "value", event.new), name)
        return widget

    def _set_control(self, name: str, event) -> None:
        """A slider's released value into the parameter; a value the parameter refuses (out
        of its bounds, NaN, not a number: only a doctored client sends one) gives a notice and
        changes nothing."""
        try:
            setattr(self, name, event.new)
        except (ValueError, TypeError) as error:
            self.warn(f"{name}: value {str(event.new)[:40]} not used: {str(error)[:200]}")

    def _controls(self):
        sliders = {
            "s0": self._slider("s0", "creepage s0 [-]", 0.0005, "0.0000"),
            "v": self._slider("v", "speed v [km/h]", 5.0, "0"),
            "N0": self._slider("N0", "wheel force N0 [kN]", 1.0, "0"),
            "b_M": self._slider("b_M", "motor slope b_M [N m s/rad]", 100.0, "0"),
            "M0": self._slider("M0", "short circuit M0 [kN m]", 1.0, "0"),
            "f": self._slider("f", "frequency f [Hz]", 1.0, "0"),
            "D": self._slider("D", "decay D [-]", 0.005, "0.000"),
            "dt": self._slider("dt", "time shift Δt [ms]", 0.05, "0.00"),
            "t_end": self._slider("t_end", "simulated time [s]", 0.1, "0.0"),
        }
        sliders["dt"].disabled = self.dt_auto
        self.param.watch(lambda e: setattr(sliders["dt"], "disabled", e.new), "dt_auto")
        dt_auto = pn.widgets.Checkbox.from_param(self.param.dt_auto,
                                                 label="Δt automatic (continuous torque)",
                                                 css_classes=["ctl-dt_auto"])
        rail = pn.widgets.Select.from_param(self.param.rail, label="rail condition (creep law)",
                                            css_classes=["ctl-rail"], sizing_mode="stretch_width")
        cases = []
        for key, s0 in PUBLISHED_CASES.items():
            button = pn.widgets.Button(label=f"Published case s0 = {s0} ({key})",
                                       color="success" if key == "stable" else "danger",
                                       css_classes=[f"case-{key}"], sizing_mode="stretch_width")
            button.on_click(partial(self._published_case, s0))
            cases.append(button)
        self.sliders = sliders
        downloads = [
            pn.widgets.FileDownload(callback=self._csv, filename="time_histories.csv",
                                    label="time histories (CSV)", css_classes=["dl-csv"],
                                    sizing_mode="stretch_width"),
            pn.widgets.FileDownload(callback=self._json, filename="eigenvalues.json",
                                    label="eigenvalues (JSON)", css_classes=["dl-json"],
                                    sizing_mode="stretch_width"),
            pn.widgets.FileDownload(callback=self._toml, filename="parameters.toml",
                                    label="parameter set (TOML)", css_classes=["dl-toml"],
                                    sizing_mode="stretch_width"),
            pn.widgets.FileDownload(callback=self.report_html, filename="bogie-report.html",
                                    label="report (HTML, opens offline)",
                                    css_classes=["dl-report"], sizing_mode="stretch_width"),
        ]
        return pn.Column(
            "### Published cases (120 km/h)", *cases,
            "### Operating point", sliders["s0"], sliders["v"], sliders["N0"], sliders["b_M"],
            rail,
            "### Short circuit M_C(t)", sliders["M0"], sliders["f"], sliders["D"], dt_auto,
            sliders["dt"], sliders["t_end"],
            *self.nonlinear.controls,  # issue 10
            "### Downloads", *downloads, width=300)

    def _published_case(self, s0: float, _event=None) -> None:
        self.param.update(s0=s0, v=120.0)

    # --- layout --------------------------------------------------------------------------------

    def _build(self) -> None:
        m = compute.model(self._params_path, "calibrated")
        self.locus_plot = RootLocusPlot()
        self.fig6 = Fig6Plot()
        self.creep_plot = CreepPlot()
        self.response_plots = ResponsePlots()
        self.mode_plot = ModeShapePlot(m.positions, m.parameters["wheel_radius"])
        self.nonlinear = NonlinearView(self)  # issue 10: creep model, anti-slip, overlays
        html_pane = partial(pn.pane.HTML, sizing_mode="stretch_width", stylesheets=[CSS])
        self.status = html_pane("", css_classes=["stability-status"])
        self.details = html_pane("")
        # a static notice of fixed size, shown only for changes longer than BUSY_DELAY_MS: an
        # overlay over the results made the browser re-lay out every plot (+300 ms per change),
        # and an animated spinner kept every waiting page busy (measured with ten sessions)
        self.busy = pn.pane.HTML("", width=300, height=22, css_classes=["busy"],
                                 stylesheets=[CSS])
        self.notice = pn.pane.Alert("", alert_type="danger", visible=False,
                                    css_classes=["model-notice"], sizing_mode="stretch_width")
        # input that was not used (a bad link, file or value): stays until the next such notice
        self.input_notice = pn.pane.Alert("", alert_type="warning", visible=False,
                                          css_classes=["input-notice"],
                                          sizing_mode="stretch_width")
        self.peaks = html_pane("")
        self.eigen_table = html_pane("")
        self.mode_select = pn.widgets.Select(label="mode ν", options={}, width=420,
                                             css_classes=["ctl-mode"])
        self.mode_select.link(self, value="mode")
        locus_choice = pn.widgets.RadioButtonGroup.from_param(
            self.param.locus, options={"locus over s0": "s0", "locus over speed v": "v"},
            css_classes=["ctl-locus"])
        zoom = pn.widgets.RadioButtonGroup.from_param(
            self.param.zoom, options={"all modes ≤ 20 Hz": "all", "low modes": "low"},
            css_classes=["ctl-zoom"])
        bokeh_pane = partial(pn.pane.Bokeh, sizing_mode="stretch_width")
        self.sensitivity = SensitivityView(self.alive)  # sensitivity tornado
        schematic = ASSETS / "schematic.svg"
        self.variant_view = VariantView(self)
        self.click = ModeClickThrough(self)  # tapped locus points and table rows -> mode views
        # the views below the status and the root locus, one tab each; other modules add theirs
        # with ``self.tabs.append((title, view))``.  Only the open tab is in the browser
        # (dynamic; app/dashboard/panel_fixes.py), and the views of a hidden tab are brought up to date
        # when it is opened (``when_shown``): with every view in the page and updated at every
        # change, the browser re-styled and re-rendered the hidden ones too
        self.tabs = pn.Tabs(
            ("Response", pn.Column(
                pn.Row(bokeh_pane(self.creep_plot.figure), pn.Column(self.peaks, width=520),
                       sizing_mode="stretch_width"),
                pn.Row(*(bokeh_pane(f) for f in self.response_plots.figures[:2]),
                       sizing_mode="stretch_width"),
                pn.Row(*(bokeh_pane(f) for f in self.response_plots.figures[2:]),
                       sizing_mode="stretch_width"), sizing_mode="stretch_width")),
            ("Fig. 6", pn.Column(
                pn.pane.Markdown("Lightly damped complex branches (ζ < 0.3 somewhere on the "
                                 "sweep) and the real eigenvalues of the root locus above, "
                                 "against the swept parameter; red dashed: the stability limit "
                                 "(s0*(v) over s0, the sweep's first unstable speed over v)."),
                pn.Row(*(bokeh_pane(f) for f in self.fig6.figures[:2]),
                       sizing_mode="stretch_width"),
                pn.Row(bokeh_pane(self.fig6.figures[2]), sizing_mode="stretch_width"),
                sizing_mode="stretch_width")),
            ("Modes", pn.Column(
                "#### Eigenvalues (layout of Table 1) and modes (layout of Table 2)",
                pn.Row(pn.Column(self.eigen_table, width=420),
                       pn.Column("**Modes** (dominant motion from kinetic/strain energy "
                                 "shares; click a row, or a point of the root locus)",
                                 self.click.table.table,
                                 sizing_mode="stretch_width"),
                       sizing_mode="stretch_width"),
                "#### Mode shape",
                self.mode_select, self.click.detail,
                pn.Row(*(bokeh_pane(f) for f in self.mode_plot.figures),
                       sizing_mode="stretch_width"), sizing_mode="stretch_width")),
            ("Variant", self.variant_view),
            ("Schematic", pn.pane.SVG(schematic, width=640)
             if schematic.is_file() else pn.pane.Markdown("*(schematic missing)*")),
            dynamic=True, css_classes=["views"], sizing_mode="stretch_width")
        self.main = pn.Column(
            self.notice, self.input_notice, self.nonlinear.notice,  # issue 10
            pn.Row(pn.Column(self.status, self.busy, self.details, self.nonlinear.status,
                             width=330),
                   pn.Column(pn.Row(locus_choice, zoom), bokeh_pane(self.locus_plot.figure),
                             sizing_mode="stretch_width"),
                   sizing_mode="stretch_width"),
            self.tabs, sizing_mode="stretch_width")
        self.tabs.append(("Sensitivity", self.sensitivity.panel))  # issue 12: sensitivity tornado
        # issue 13: the "Studies" view (stability map over s0 × v) lives in app/dashboard/studies_view.py
        from app.dashboard.studies_view import StudiesView

        self.studies = StudiesView(self)
        self.tabs.append(("Studies", self.studies.layout))
        self.layout = pn.Row(
            self._controls(), self.main, sizing_mode="stretch_width",
            stylesheets=[CSS])

    def __panel__(self):
        return self.layout

    # --- state and computations --------------------------------------------------------------

    @property
    def params_path(self) -> str:
        """The bundled parameter file in use ("": the calibrated set); the variant, if any,
        changes it (:attr:`set_key`)."""
        return self._params_path

    @property
    def set_key(self) -> str:
        """The parameter set in use for app.results.compute: the bundled file, or a variant of it."""
        return f"{self._params_path}|{self.variant}" if self.variant else self._params_path

    # --- shareable state (app.dashboard.url_state) -------------------------------------------------------

    @property
    def tab_names(self) -> list[str]:
        """The views' names in the URL (``tab=``): their titles in lower case, words joined
        by '-'."""
        return [re.sub(r"[^a-z0-9]+", "-", str(title).lower()).strip("-")
                for title in self.tabs._names]

    def share_query(self) -> str:
        """The URL query (without '?') that restores this session's settings."""
        return make_query(self, self.tab_names[self.tabs.active] if self.tabs.active else None)

    def _restore_tab(self, notices: list[str]) -> None:
        tab = self._query_tab
        if tab is not None:
            if tab in self.tab_names:
                self.tabs.active = self.tab_names.index(tab)
            else:
                notices.append(f"tab = '{tab[:40]}' is not one of {', '.join(self.tab_names)}")
        if notices:
            self.warn("Some settings of the link were not used (defaults kept): "
                      + "; ".join(notices))

    def _tab_shown(self, *_events) -> None:
        """Views that compute only while shown (the variant comparison) learn it here; the
        updates a hidden view missed are applied."""
        shown = self.tab_names[self.tabs.active]
        self.variant_view.on_shown(shown == "variant")
        self.flush_view(shown)

    def when_shown(self, tab: str, function, *args) -> None:
        """``function(*args)`` now if the view's tab (``tab_names``) is open or the dashboard is
        not served, else when the tab is opened (of several calls of one function for a hidden
        tab, the last one)."""
        served = pn.state.curdoc is not None and pn.state.curdoc.session_context is not None
        if not served or self.tab_names[self.tabs.active] == tab:
            self._pending_views.pop((tab, function.__name__), None)
            function(*args)
        else:
            self._pending_views[tab, function.__name__] = (function, args)

    def flush_view(self, tab: str) -> None:
        """Apply the updates the view ``tab`` missed while hidden, in the order they came."""
        for key in [key for key in self._pending_views if key[0] == tab]:
            function, args = self._pending_views.pop(key)
            function(*args)

    def warn(self, text: str) -> None:
        """Show a notice about input that was not used (the previous state is kept)."""
        self.input_notice.object = html.escape(text)
        self.input_notice.visible = True

    def clear_warning(self) -> None:
        """Hide the notice about unused input (the input it named has been corrected)."""
        self.input_notice.visible = False

    def _share(self, *_events) -> None:
        """Keep the browser's address (served) equal to the settings: a link to share."""
        location = pn.state.location if pn.state.curdoc is not None else None
        if location is not None and pn.state.curdoc.session_context is not None:
            location.search = "?" + self.share_query()

    def state(self) -> State:
        rnd = lambda x, n=6: float(round(x, n))  # noqa: E731 - cache keys without float noise
        return State(self.set_key, self.rail, rnd(self.s0, 7), rnd(self.v, 3),
                     rnd(self.N0, 3), rnd(self.b_M, 3), rnd(self.M0, 3), rnd(self.f, 3),
                     rnd(self.D, 5), None if self.dt_auto else rnd(self.dt, 4), rnd(self.t_end, 3),
                     self.locus)

    # the four computations of a change; each independent of the others (run in parallel
    # when served).  One BLAS thread each: set once per process (app.services.thread_pools.limit_blas_threads)
    @staticmethod
    def _point(state: State):
        return compute.point_result(*state.point)

    @staticmethod
    def _response(state: State):
        return compute.response_result(*state.point, state.M0, state.f, state.D, state.dt,
                                       state.t_end)

    @staticmethod
    def _limit(state: State):
        return compute.limit_result(state.params_path, state.rail, state.v, state.N0, state.b_M)

    @staticmethod
    def _locus(state: State):
        """The coarse root locus (shown first)."""
        return compute.locus_result(*state.locus_key)

    @staticmethod
    def _dense_locus(state: State):
        """The dense root locus (replaces the coarse one)."""
        return compute.dense_locus_result(*state.locus_key)

    def compute_fast(self, state: State):
        """(point result, response result) for a state (raises a MODEL_ERRORS on rejection)."""
        return self._point(state), self._response(state)

    def compute_slow(self, state: State):
        """(stability limit, dense root locus) for a state."""
        return self._limit(state), self._dense_locus(state)

    def refresh(self, slow: bool = True) -> None:
        """Compute and show everything synchronously (initial view, tests); ``slow=False``
        skips the stability limit and the root locus."""
        state = self.state()
        try:
            fast = self.compute_fast(state)
        except MODEL_ERRORS as error:
            self._reject(error)
            return
        self._apply_fast(state, fast)
        if not slow:
            return
        try:
            slow = self.compute_slow(state)
        except MODEL_ERRORS as error:
            self._reject(error)
            return
        self._apply_slow(state, slow)

    def _on_change(self, *_events) -> None:
        doc = pn.state.curdoc
        if doc is None or doc.session_context is None:
            self.refresh()
            return
        self._request(doc)

    def _request(self, doc, loading: bool = True) -> None:
        self._dirty = True
        if self._busy:
            return  # the running worker picks up the newest parameters when it is done
        self._busy = True
        if loading:
            doc.add_timeout_callback(self._show_busy, BUSY_DELAY_MS)
        doc.add_next_tick_callback(without_document_lock(partial(self._worker, doc)))

    async def _worker(self, doc) -> None:
        loop = asyncio.get_running_loop()
        try:
            while self._dirty and not self.closed:
                self._dirty = False
                state = self.state()
                # the coarse root locus (≈ 0.3 s on two threads when not cached) starts at once,
                # beside the fast stage (one thread), and is shown when both are done; then the
                # dense one replaces it when ready.  Nothing to do if the dense locus of this
                # (set, rail, sweep, fixed value, N0, b_M) is on screen already
                need_locus = self._shown_locus != (state.locus_key, True)
                locus_future = (loop.run_in_executor(FIRST_ANSWER_POOL, self._locus, state)
                                if need_locus else None)
                try:
                    fast = await loop.run_in_executor(FIRST_ANSWER_POOL, self.compute_fast, state)
                except MODEL_ERRORS as error:
                    self.post(doc, self._reject, error)
                    if locus_future is not None:
                        ignore_outcome(locus_future)
                    continue
                # issue 10: the nonlinear history, if shown, starts once the linear first answer
                # is computed, not beside it: its step loop is mostly Python and shared the GIL
                # with the fast stage (linear result 304 ms beside it, median of 12 steps)
                self.nonlinear.prefetch(state)
                self.post(doc, self._apply_fast, state, fast)
                if self._dirty:
                    if locus_future is not None:
                        ignore_outcome(locus_future)  # it still fills the cache
                    continue
                if locus_future is not None:
                    try:
                        locus = await locus_future
                    except MODEL_ERRORS as error:
                        self.post(doc, self._reject, error)
                        continue
                    if self._dirty:
                        continue
                    self.post(doc, self._apply_locus, state, locus)
                    dense = self._dense_requests.submit(self._dense_if_current, state)
                    dense.add_done_callback(partial(self._dense_done, doc, state))
                    # s0*(v) after the dense locus (which has a target: ≤ 2 s after a speed
                    # change): at a lower priority beside it, its full eigen-analyses still
                    # took ≈ 1.3 CPU-s of the two cores while the dense sweep ran (py-spy)
                    dense.add_done_callback(lambda _f, s=state: self._start_limit(doc, s))
                else:
                    self._start_limit(doc, state)
        except Exception as error:  # keep the server and the session alive, say what happened
            log.exception("dashboard computation failed")
            self.post(doc, self._reject, error)
        finally:
            self._busy = False
            self.post(doc, self._done)

    def _start_limit(self, doc, state: State) -> None:
        """s0*(v) (≈ 0.7 s when not cached) is not waited for: a change arriving meanwhile
        starts at once; the limit is shown when ready if it still belongs to the parameters."""
        limit = self._limit_requests.submit(self._limit_if_current, state)
        limit.add_done_callback(partial(self._limit_done, doc, state))

    def _limit_current(self, state: State) -> bool:
        """Whether s0*(v) for ``state`` is still the one to show (same v, N0, b_M, rail)."""
        current = self.state()
        return (current.rail, current.v, current.N0, current.b_M) == (state.rail, state.v,
                                                                      state.N0, state.b_M)

    def _limit_if_current(self, state: State) -> compute.LimitResult | None:
        """s0*(v), unless superseded before it started (a speed slider dragged over ten values
        must not queue ten 0.7 s root findings in front of the next change's fast stage)."""
        return self._limit(state) if self._limit_current(state) else None

    def _dense_if_current(self, state: State) -> compute.LocusResult | None:
        """The dense root locus, unless superseded before it started."""
        return self._dense_locus(state) if self.state().locus_key == state.locus_key else None

    def _dense_done(self, doc, state: State, future) -> None:
        self._background_done(doc, state, future, "dense root locus", self._apply_locus,
                              lambda: self.state().locus_key == state.locus_key)

    def _limit_done(self, doc, state: State, future) -> None:
        self._background_done(doc, state, future, "stability limit", self._apply_limit,
                              lambda: self._limit_current(state))

    def _background_done(self, doc, state: State, future, what: str, apply, current) -> None:
        """A background result (``None``: skipped) is shown with ``apply(state, result)`` if
        ``current()`` still holds (nothing otherwise: another speed, sweep … is shown)."""
        if future.cancelled() or not current():
            return
        error = future.exception()
        if error is not None:
            if isinstance(error, MODEL_ERRORS):
                self.post(doc, self._reject, error)
            else:
                log.error("%s failed", what, exc_info=error)
            return
        if future.result() is not None:
            self.post(doc, apply, state, future.result())

    def run_locked(self, function, *args) -> None:
        """Run ``function(*args)`` with the session's document lock: served, on the next tick;
        otherwise at once (:func:`app.dashboard.session.run_locked`)."""
        run_locked(function, *args)

    def post(self, doc, function, *args) -> None:
        """``function(*args)`` on the session's next tick, with its document lock; nothing if the
        session has ended meanwhile (:func:`app.dashboard.session.post`)."""
        post(doc, function, *args)

    def _done(self) -> None:
        if not self._busy and self.busy.object:
            self.busy.object = ""

    def _show_busy(self) -> None:
        if self._busy:
            self.busy.object = BUSY_TEXT

    def _reject(self, error: Exception) -> None:
        message = error.args[0] if error.args else str(error)
        self.error = str(message)
        self.notice.object = (f"**The model rejects this combination:** {html.escape(str(message))}"
                              " — showing the last valid result.")
        self.notice.visible = True

    def _on_mode(self, *_events) -> None:
        if self.point is not None and 1 <= self.mode <= len(self.point.modes):
            self.mode_plot.update(self.point.modes[self.mode - 1].displacement)
            self.mode_select.value = self.mode
            self.click.show_point_mode()
            self.sensitivity.show(mode=self.mode)  # issue 12: sensitivity tornado

    # --- showing results -----------------------------------------------------------------------

    def _apply_fast(self, state: State, fast) -> None:
        point, response = fast
        self.point, self.response, self.error = point, response, ""
        self.notice.visible = False
        self.locus_plot.update_point(point)
        self.creep_plot.update_point(point)
        self.response_plots.update(response)
        self._show_status()
        self.peaks.object = peaks_html(response)
        self.when_shown("modes", self._show_modes, point)
        self.locus_plot.zoom(self.zoom == "low")
        # issue 12: sensitivity tornado (computed when its tab is open, shown when ready)
        self.when_shown("sensitivity", self.sensitivity.request, self, state)

        self.nonlinear.on_fast(state)  # issue 10: the nonlinear result follows

    def _show_modes(self, point: compute.PointResult) -> None:
        """The Modes tab: eigenvalue table, mode table, mode choice and the selected mode."""
        self.eigen_table.object = eigen_table_html(point)
        self.click.table.update(point)
        self.mode_select.options = {f"ν = {m.number}: {m.im_hz:.3f} Hz — {m.description}"[:90]:
                                    m.number for m in point.modes}
        self.mode_select.value = min(self.mode, len(point.modes))
        self._on_mode()

    def _apply_slow(self, state: State, slow) -> None:
        limit, locus = slow
        self._apply_limit(state, limit)
        self._apply_locus(state, locus)

    def _apply_limit(self, state: State, limit: compute.LimitResult) -> None:
        self.limit, self._limit_for = limit, (state.rail, state.v, state.N0, state.b_M)
        self.creep_plot.update_limit(limit)
        self.when_shown("fig-6", self.fig6.update_limit, limit.s0_limit)
        self._show_status()

    def _apply_locus(self, state: State, locus: compute.LocusResult) -> None:
        if self.state().locus_key != state.locus_key:
            return  # a late result of a sweep no longer shown
        self.locus_result = locus
        self._shown_locus = (state.locus_key, locus.dense)
        self.locus_plot.update_locus(locus)
        self.when_shown("fig-6", self.fig6.update_locus, locus)
        self.locus_plot.zoom(self.zoom == "low")

    def _show_status(self) -> None:
        point = self.point
        word = "STABLE" if point.stable else "UNSTABLE"
        self.status.object = (f'<div class="status-box {"ok" if point.stable else "bad"}">'
                              f"{word}</div>")
        s0, v_kmh = point.key[2], point.key[3]
        if self.limit is None or self._limit_for != (point.key[1], *point.key[3:]):
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

    # --- downloads -----------------------------------------------------------------------------

    def _csv(self):
        r = self.response
        names = list(r.outputs)
        header = "t [s]," + ",".join(f"{n} [{r.units[n]}]" for n in names) + ",M_C [N m]"
        data = np.column_stack([r.t, *r.outputs.values(), r.M_C])
        buffer = io.StringIO()
        np.savetxt(buffer, data, delimiter=",", header=header, comments="", fmt="%.8g")
        buffer.seek(0)
        return buffer

    def _json(self):
        p = self.point
        lam = p.eigenvalues
        order = np.lexsort((lam.real, lam.imag))
        data = {"operating_point": {"s0": p.key[2], "v_kmh": p.key[3], "N0": p.key[4] * 1e3,
                                    "b_M": p.key[5], "rail": p.key[1]},
                "stable": p.stable, "max_real_part": p.max_real_part, "flutter_pairs": p.flutter,
                "divergent_real": p.divergence, "rigid_body": p.n_rigid,
                "modes": [{"nu": m.number, "re": m.eigenvalue.real, "im_hz": m.im_hz,
                           "damping_ratio": m.damping_ratio, "description": m.description}
                          for m in p.modes],
                "eigenvalues": [{"re": float(x.real), "im": float(x.imag)} for x in lam[order]]}
        return io.StringIO(json.dumps(data, indent=1))

    def report_html(self):
        """The self-contained HTML report of the current state (app.report.page)."""
        from app.report.page import build_report

        state = self.state()
        return io.StringIO(build_report(state.params_path, state.rail, state.s0, state.v,
                                        state.N0, state.b_M, state.M0, state.f, state.D,
                                        state.dt, state.t_end))

    def _toml(self):
        state = self.state()
        p = compute.parameters(state.params_path, state.rail)
        header = (f"parameter set in use by the dashboard (rail condition: {state.rail})\n"
                  f"operating point: s0 = {state.s0}, v = {state.v} km/h, N0 = {state.N0} kN, "
                  f"b_M = {state.b_M} N m s/rad")
        return io.StringIO(dumps_parameters(p, header))

