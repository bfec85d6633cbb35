"""The verdicts in the dashboard: the indicator beside the stability status (the governing safety
factor of the operating point, green / amber / red against its required factor) and the Verdicts
tab — every check as a table (a row opens the history that produced its load) and a bar chart of
the safety factors per load case — and a strength-data file that replaces the set's (a bad one is
refused with a notice; the previous data are kept).

The assessment (:func:`app.results.verdicts.assessment_result`) runs on a worker thread for each
state of the dashboard (:class:`app.dashboard.jobs.ViewJob`), asked for when the state changes
and started once that state's follow-ups (dense root locus, s0*(v)) have ended, whatever their
outcome, and the state has stayed for a moment (:data:`VERDICT_QUIET_MS`); it takes a few
seconds (the short-circuit case's grid over every fault instant, the ripple case's speed sweep),
so the indicator says "computing" meanwhile.  The "running case" checkbox adds the running load
case (``bogie assess``'s running defaults; seconds of work) to the same assessment.

Once a verdict is shown and the tab is open, each shaft section's fatigue life over the bundled route
(:mod:`app.results.life`, 25 s to 2 min) is computed in a background worker process, its thread
of the :data:`~app.services.thread_pools.LIFE_POOL`, never on a slider's path: the table's life
column says "computing…" meanwhile and the result is kept in the results cache; it stops at the
next checkpoint when no view of a live session wants it any more.  Not served (tests without a
server), it waits for :meth:`VerdictsView.compute_life`.
"""

from __future__ import annotations

import html
import json
import logging
import weakref
from functools import partial

import panel as pn

from app.dashboard import layout
from app.dashboard.jobs import ViewJob
from app.dashboard.session import served_document
from app.results import life as route_life
from app.results.cache import Superseded
from app.results.case import Case
from app.results.verdicts import (
    assessment_result,
    check_rows,
    indicator_html,
    safety_factor_figure,
)
from app.services import background
from app.services.thread_pools import LIFE_POOL, SIDE_VIEW_POOL
from model.mechanics.parameters import ASSESSMENT_SCHEMA, ParameterError, parse_entries

log = logging.getLogger(__name__)

MAX_STRENGTH_BYTES = 50_000
# the assessment starts when its state has stayed this long after the state's follow-ups [ms]:
# a sequence of slider steps asks for the verdict of its last state only (an assessment is
# mostly Python and would share the interpreter with the next state's first answer and loci,
# its own session's and every other session's on the server; as the reaction-time search)
VERDICT_QUIET_MS = 1000
TEXT, NUMBER = "object", "float64"
# the table's columns and their types (text drawn as text, numbers with their decimals)
COLUMNS = {"component": TEXT, "check": TEXT, "load case": TEXT, "load [kN m]": NUMBER,
           "capacity [kN m]": NUMBER, "safety factor": NUMBER, "band 5–95 %": TEXT,
           "required": NUMBER, "verdict": TEXT, "life [km]": TEXT, "where": TEXT, "note": TEXT}
PENDING = "computing…"  # a fatigue row's life while it is computed
RUNNING_LABEL = "running case (track, wheels, ripple; adds seconds)"
_LIFE_VIEWS: weakref.WeakSet = weakref.WeakSet()  # the views that may want a route life


class LifeSuperseded(Superseded):
    """A route life stopped because no view of a live session wants it any more."""


def _stop_unless_life_wanted(key: tuple) -> None:
    if not any(view.wants_life(key) for view in list(_LIFE_VIEWS)):
        raise LifeSuperseded(key)


def strength_from_toml(data: bytes, base) -> tuple:
    """The strength data of an uploaded TOML file (entries ``name = { value = …, unit = "…" }``
    of :data:`model.mechanics.parameters.ASSESSMENT_SCHEMA`, read as a parameter file's entries
    are), checked against ``base`` (a :class:`model.mechanics.parameters.Parameters`):
    ((name, value), …); raises ParameterError naming what is wrong."""
    import tomllib

    if len(data) > MAX_STRENGTH_BYTES:
        raise ParameterError(f"strength file too large ({len(data)} bytes, at most "
                             f"{MAX_STRENGTH_BYTES})")
    try:
        table = tomllib.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as error:
        raise ParameterError(f"strength file is not valid TOML: {error}") from None
    for name in table:
        if name not in ASSESSMENT_SCHEMA:
            raise ParameterError(f"'{name[:60]}' is not a strength datum (allowed: "
                                 f"{', '.join(list(ASSESSMENT_SCHEMA)[:4])}, …)")
    changes, _ = parse_entries(table, "strength file", unit_required=False)
    base.replace(**changes)  # validates each value and the geometry (names the parameter)
    return tuple(sorted((name, float(value)) for name, value in changes.items()))


class VerdictsView:
    """Indicator, table, bar chart and strength file of one dashboard."""

    def __init__(self, dashboard):
        self.dashboard = dashboard
        self._job = ViewJob(SIDE_VIEW_POOL, dashboard.alive, "verdict")
        self._life_job = ViewJob(LIFE_POOL, dashboard.alive, "route life")
        self.life_route = str(route_life.ROUTE)  # the route file the life column is over
        self.life_sources = route_life.SOURCES  # its load sources
        self.life = None  # the route life on screen (model.studies.life.LifeResult)
        self.life_for: tuple | None = None  # its key
        self._life_waiting: tuple | None = None  # not served: the key compute_life computes
        # served, a figure made while the tab is closed waits for it: {pane's role: (pane, maker)}
        self._pending_figures: dict[str, tuple] = {}
        self._life_pending = False  # the life of the verdict on screen waits for the tab
        _LIFE_VIEWS.add(self)
        self.running = pn.widgets.Checkbox(label=RUNNING_LABEL, value=False,
                                           css_classes=["ctl-verdict-running"])
        self.running.param.watch(lambda _e: self.request(self.dashboard.state()), "value")
        self.life_text = pn.pane.Markdown("", css_classes=["verdict-life-text"],
                                          sizing_mode="stretch_width")
        self.life_chart = pn.pane.Bokeh(sizing_mode="stretch_width", css_classes=["life-chart"])
        self.strength: tuple = ()  # uploaded strength data ((name, value), …)
        self.result = None  # the assessment on screen
        self.shown_for = None  # its point and short circuit (a case record)
        self.rows: list[dict] = []
        self._waiting: tuple | None = None  # not served: the key to assess when the tab opens
        self._tab_open = False
        self.indicator = layout.html_pane(indicator_html(None, "computing…"),
                                          css_classes=["verdict-status"])
        self.cases = layout.html_pane("")
        self.table = pn.widgets.Tabulator(
            self._frame([]), show_index=False, disabled=True, selectable=1,
            layout="fit_data_stretch", sizing_mode="stretch_width", height=330,
            css_classes=["verdict-table"])
        self.table.on_click(self._clicked)
        self.chart = pn.pane.Bokeh(sizing_mode="stretch_width", css_classes=["verdict-chart"])
        self.upload = pn.widgets.FileInput(accept=".toml", css_classes=["verdict-strength"])
        self.upload.param.watch(self._uploaded, "value")
        # a result of the verdict under uncertainty (bogie assess --samples … --out) of the
        # server's studies folder, picked by name from its list
        self.uncertainty = None
        self.uncertainty_select = pn.widgets.Select(
            label="verdict under uncertainty (bogie assess --samples … --out, in the folder)",
            options=[], width=380, css_classes=["verdict-uncertainty"])
        self.uncertainty_open = pn.widgets.Button(label="Show bands", width=110,
                                                  css_classes=["verdict-open-uncertainty"])
        self.uncertainty_refresh = pn.widgets.Button(label="↻", width=40,
                                                     css_classes=["verdict-refresh-uncertainty"])
        self.uncertainty_open.on_click(lambda _e: self.open_uncertainty(
            self.uncertainty_select.value))
        self.uncertainty_refresh.on_click(lambda _e: self.refresh_results())
        self.notice = pn.pane.Alert("", alert_type="warning", visible=False,
                                    css_classes=["verdict-notice"], sizing_mode="stretch_width")
        self.layout = pn.Column(
            pn.pane.Markdown(
                "Every press fit (slip, DIN 7190), shaft (torsional shear) and coupling (rating) "
                "of both drives in every load case listed below; safety factor = capacity / load. "
                "Click a row for the history that produced its load (the starting case's are "
                "static; a ripple row opens the Resonances tab at its speed). "
                "Strength data (TOML, entries as in the parameter file, e.g. "
                "`wheel_seat_friction_min = { value = 0.1, unit = \"1\" }`) replace the set's; "
                "docs/assessment.md. The running case (mean traction with the converters' "
                "ripple, a polygon of order 20 and 30 µm on every wheel and 3 × the RMS under "
                "the low-level track spectrum, 20–200 km/h) is added on request. Each shaft "
                "section's fatigue row gets its life over the bundled route in km (years in "
                "the note), computed after the verdict (25 s to 2 min)."),
            pn.Row(pn.pane.Markdown("**strength data (TOML):**"), self.upload, self.running),
            pn.Row(self.uncertainty_select, self.uncertainty_open, self.uncertainty_refresh),
            self.notice, self.cases, self.table, self.life_text, self.chart, self.life_chart,
            sizing_mode="stretch_width")

    @staticmethod
    def _frame(rows):
        return layout.typed_frame(COLUMNS, rows)

    # --- computing ----------------------------------------------------------------------------

    def _key(self, case: Case) -> tuple:
        """What the assessment of ``case`` depends on: its point and short circuit (every
        fault instant, the load cases' horizons) and the strength data."""
        return (case.without("dt", "t_end"), self.strength, bool(self.running.value))

    def request(self, case: Case, after=None) -> None:
        """Assess ``case``'s operating point (served: on a worker thread, started once
        ``after`` — a future: the state's follow-ups — is done and the state has stayed for
        :data:`VERDICT_QUIET_MS`; its short-circuit envelope, mostly Python, would share the GIL
        with the dense root locus and delay it by about a second after a speed step; not
        served, as in tests without a server: when the Verdicts tab is opened)."""
        key = self._key(case)
        if served_document() is None:
            self._waiting = key
            if self._tab_open:
                self.on_shown(True)
            else:
                self.indicator.object = indicator_html(None, "open the Verdicts tab")
            return
        if key == self._job.wanted:
            return  # asked for already (its answer, or the one on screen, stands)
        self.indicator.object = indicator_html(None, "computing…")
        # served: the assessment in a background worker process (app.services.background)
        self._job.start(key, lambda: assessment_result(key[0], key[1], runner=background.run,
                                                       running=key[2]),
                        self._show, self._failed, after=after, delay_ms=VERDICT_QUIET_MS)

    def on_shown(self, shown: bool) -> None:
        """The Verdicts tab opened (``shown``) or closed; not served, the assessment waiting
        for it is computed now."""
        self._tab_open = shown
        if shown:
            self.refresh_results()
        if shown and self._life_pending and self.shown_for is not None:
            self._life_pending = False
            self._request_life(self.shown_for)
        if shown:
            for pane, make in self._pending_figures.values():
                pane.object = make()
            self._pending_figures.clear()
        if shown and self._waiting is not None:
            key, self._waiting = self._waiting, None
            self._show(key, assessment_result(key[0], key[1], running=key[2]))

    def _failed(self, _key, error: BaseException) -> None:
        self.indicator.object = indicator_html(None, f"not assessed: {error}")

    def _show(self, key, result) -> None:
        self.result = result
        self.shown_for = key[0]  # the point and short circuit of the result on screen
        uncertainty = self._matching_uncertainty()
        self.indicator.object = indicator_html(result, uncertainty=uncertainty)
        self._fill_table()
        self.cases.object = "<ul>" + "".join(
            f"<li><b>{c.name}</b> ({'steady' if c.horizon is None else f'horizon {c.horizon:g} s'}"
            f"): {html.escape(c.description)}</li>" for c in result.cases) + "</ul>"
        self._set_figure("safety factors", self.chart, partial(safety_factor_figure, result))
        self.dashboard.resonances.show_crossings()
        if len(key) > 1:  # a new assessment (not new bands): the life of its set, asked for
            # while the tab is open (minutes of CPU in a background worker: not for a session
            # that never looks at it)
            self._life_pending = not self._tab_open
            if self._tab_open:
                self._request_life(key[0])

    def _fill_table(self) -> None:
        """The checks' rows with each fatigue row's life (computing…, or the life on screen
        when it is of the verdict's set)."""
        rows = check_rows(self.result, self._matching_uncertainty())
        life = self.life if self.life_for == self._life_key(self.shown_for) else None
        self.rows = route_life.with_life(rows, life)
        self.table.value = self._frame(self.rows)

    # --- the life over the route --------------------------------------------------------------

    def _life_key(self, case) -> tuple:
        return (route_life.life_key(case), self.strength, self.life_route,
                tuple(self.life_sources))

    def wants_life(self, key: tuple) -> bool:
        """Whether this view still waits for the route life ``key`` (any thread)."""
        return key == self._life_job.wanted and self.dashboard.alive()

    def _request_life(self, case) -> None:
        """The life of ``case``'s set over the route: at once if kept, else in a background
        worker process (served) or by :meth:`compute_life` (not served)."""
        key = self._life_key(case)
        if key == self.life_for:
            return
        kept = route_life.known_life(*key)
        if kept is not None:
            self._life_job.want(key)
            return self._show_life(key, kept)
        self.life_text.object = (f"**Life over the route:** {PENDING} (25 s to 2 min, "
                                 "in the background)")
        if served_document() is None:
            self._life_waiting = key
            return
        if key == self._life_job.wanted:
            return
        stop = partial(_stop_unless_life_wanted, key)
        self._life_job.start(
            key, lambda: route_life.life_result(*key, runner=partial(background.run, stop=stop),
                                           checkpoint=background.checkpoint),
            self._show_life, self._life_failed)

    def compute_life(self) -> None:
        """Not served: compute the route life the verdict on screen waits for, and show it."""
        key, self._life_waiting = self._life_waiting, None
        if key is not None:
            self._life_job.start(key, lambda: route_life.life_result(*key), self._show_life,
                                 self._life_failed)

    def _show_life(self, key, result) -> None:
        self.life, self.life_for = result, key
        self.life_text.object = route_life.description(result, key[2])
        self._set_figure("life", self.life_chart, partial(route_life.damage_figure, result))
        if self.result is not None:
            self._fill_table()

    def _set_figure(self, role: str, pane, make) -> None:
        """Show the figure ``make()`` in ``pane``; served, only while the tab is drawn, else when
        it is opened (the newest figure of each ``role``): a figure replaced in a tab the page has
        left had models the page never received ("reference … isn't known")."""
        if self._tab_open or served_document() is None:
            self._pending_figures.pop(role, None)
            pane.object = make()
        else:
            self._pending_figures[role] = (pane, make)

    def _life_failed(self, _key, error: BaseException) -> None:
        self.life_text.object = f"**Life over the route:** not computed: {html.escape(str(error))}"

    # --- the verdict under uncertainty --------------------------------------------------------

    def _folder(self):
        return self.dashboard.studies.queue.folder

    def refresh_results(self) -> None:
        """The verdict results of the server's studies folder, newest first."""
        try:
            self.uncertainty_select.options = self._folder().names("verdict")
        except OSError as error:
            log.error("the studies folder cannot be listed: %s", error)

    def open_uncertainty(self, name) -> None:
        """Show the bands of a verdict result of the folder's list beside the checks; a name not
        in the list, a file that is not such a result, or one of another parameter set or
        strength data: a notice, the previous bands kept."""
        from app.services.studies_folder import StudyNameRefused
        from model.studies.verdict_result import VerdictUncertainty

        try:
            path = self._folder().path(name, "verdict")
            result = VerdictUncertainty.from_dict(json.loads(path.read_text(encoding="utf-8")))
        except StudyNameRefused as error:
            return self._warn(str(error))
        except (OSError, ValueError, KeyError, TypeError):
            return self._warn("that file is not a result of bogie assess --samples")
        if self.result is not None and self._matching_uncertainty(result) is None:
            return self._warn("that result is of another parameter set or other strength data "
                              "than the checks shown: its bands are not shown (the previous "
                              "ones are kept)")
        self.uncertainty = result
        self.notice.visible = False
        if self.result is not None:
            self._show((self.shown_for,), self.result)

    def _warn(self, message: str) -> None:
        self.notice.object = message
        self.notice.visible = True

    def _matching_uncertainty(self, candidate=None):
        """The opened verdict result (or ``candidate``) if it is of the set and strength data on
        screen, else None."""
        from app.results import compute
        from model.studies.verdict_uncertainty import set_hash

        uncertainty = self.uncertainty if candidate is None else candidate
        if uncertainty is None or self.shown_for is None:
            return None
        parameters = compute.parameters_for(self.shown_for)
        if self.strength:
            parameters = parameters.replace(**dict(self.strength))
        return uncertainty if uncertainty.set_hash == set_hash(parameters) else None

    # --- input --------------------------------------------------------------------------------

    def _uploaded(self, event) -> None:
        from app.results import compute

        if not event.new:
            return
        state = self.dashboard.state()
        try:
            strength = strength_from_toml(event.new, compute.parameters_for(state))
        except ParameterError as error:
            self.notice.object = (f"**Strength data not used:** {html.escape(str(error))} — the "
                                  "previous data are kept.")
            self.notice.visible = True
            return
        self.notice.visible = False
        self.strength = strength
        self.request(state)  # at once: the state's follow-ups are not waited for

    def _clicked(self, event) -> None:
        """A row: its load's history on the Response tab (its s0 and v; the nonlinear creep
        model with anti-slip for the unstable_adhesion case); a ripple row: the Resonances tab at
        its worst speed with its section as the output.  The starting case's loads are static:
        no history produced them."""
        if not 0 <= event.row < len(self.rows):
            return
        row = self.rows[event.row]
        dash = self.dashboard
        if row["s0"] is None or row["v_kmh"] is None or row["load case"] == "starting":
            return
        bounds = {name: dash.case_type.quantity(name).bounds for name in ("s0", "v")}
        dash.param.update(s0=min(max(row["s0"], bounds["s0"][0]), bounds["s0"][1]),
                          v=min(max(row["v_kmh"], bounds["v"][0]), bounds["v"][1]))
        if row["load case"] == "ripple":
            if row["output"] in dash.resonances.output.options:
                dash.resonances.output.value = row["output"]
            dash.tabs.active = dash.view_tabs.names.index("resonances")
            return
        nonlinear = row["load case"] == "unstable_adhesion"
        dash.nonlinear.creep.value = "nonlinear" if nonlinear else "linear"
        if nonlinear:
            dash.nonlinear.anti_slip.value = True
        dash.tabs.active = dash.view_tabs.names.index("response")
