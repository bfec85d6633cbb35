"""The nonlinear creep model in the dashboard: the creep-model switch, the anti-slip controls,
the nonlinear histories overlaid on the linear ones, each wheel's creepage path on the creep plot,
and the required reaction time of the protection in the status area for unstable points.

The linear closed form stays the fast first answer (the dashboard's fast stage); this view
starts its own computations after it, on worker threads of its own when served, and shows
them when ready, if they still belong to what is on screen (a notice says "computing…" in the
meantime; the page never waits).  Bad anti-slip input shows a notice and keeps the last valid
values and results.

The dashboard builds ``NonlinearView(dashboard)`` and places its ``controls``, ``notice`` and
``status`` in its page; it calls ``prefetch(state)`` when the linear first answer is computed
(served) and ``on_fast(state)`` when that answer is shown.  This view tells the dashboard which
history its peak table, CSV download and report describe (``dashboard.show_history``): the
linear one, or with nonlinear creep on the nonlinear one (none while it is computed); and, with
linear creep at an unstable point, the nonlinear history beside the unbounded linear one
(``dashboard.show_companion``: the peak table's physical answer).  The
nonlinear histories are computed by :func:`app.results.compute.nonlinear_histories` (the report
uses them too); the reaction-time search here is kept in the results cache like them and
returns plain read-only data.  Served, the search and the companion history run in background
worker processes (:mod:`app.services.background`), not on the server's interpreter: no slider
waits for them (the history shown with nonlinear creep on is that mode's first answer and
stays on this view's threads).  Each computation is a
:class:`app.dashboard.jobs.ViewJob`.
"""

from __future__ import annotations

import html
import logging
import weakref
from dataclasses import dataclass
from functools import partial

import numpy as np
import panel as pn

from app.dashboard.jobs import ViewJob
from app.dashboard.session import served_document
from app.results import compute
from app.results.cache import Superseded
from app.results.case import CaseBase
from app.results.compute import HistoryKey, NonlinearHistories, nonlinear_histories
from app.results.plots import SeriesSource
from app.services import background
from app.services.thread_pools import NONLINEAR_POOL, SEARCH_POOL
from model.analysis.antislip import required_reaction_time
from model.analysis.nonlinear import AntiSlip, NonlinearError

log = logging.getLogger(__name__)
CREEP_MODELS = ("linear", "nonlinear")
WHEEL_COLORS = {"ID1.rim12": "#8c564b", "ID1.rim14": "#e377c2", "ID2.rim12": "#17becf",
                "ID2.rim14": "#bcbd22"}
REACTION_DELAYS = np.linspace(0.0, 0.5, 11)  # [s] delay grid of the dashboard's reaction time
REACTION_FS = 5_000.0  # [Hz] its sampling (the CLI's default is 10 kHz)
REACTION_QUIET_MS = 1000  # [ms] the search starts when the operating point has stayed this long
# the views alive in this process: a reaction search that no view wants any more (superseded by
# another operating point, a slider already moved on, or its session closed) stops within one
# block of its nonlinear runs instead of holding the shared worker and the CPU for seconds: its
# step loop is mostly Python and holds the GIL, which thread priorities cannot take away, so a
# search left running slows every session's next answer
_VIEWS: weakref.WeakSet = weakref.WeakSet()


class ReactionSuperseded(Superseded):
    """A reaction search stopped because no session wants its result any more (a session
    waiting for the same search computes it itself)."""


def _stop_unless_wanted(key: tuple) -> None:
    if not any(view.wants_reaction(key) for view in list(_VIEWS)):
        raise ReactionSuperseded(key)


class CompanionSuperseded(Superseded):
    """A companion history stopped because no session wants it any more."""


def _stop_unless_companion_wanted(key: HistoryKey) -> None:
    if not any(view.wants_companion(key) for view in list(_VIEWS)):
        raise CompanionSuperseded(key)


def wanted_companion(key: HistoryKey) -> NonlinearHistories:
    """The nonlinear history beside a linear one that grows without bound (the peak table's
    companion), in a background worker process (:mod:`app.services.background`): no slider
    waits for it, and its step loop is mostly Python (in the server's threads it held the
    interpreter beside every session's first answers).  It stops (CompanionSuperseded) as soon
    as no live view wants it — before it starts and between the integration's blocks."""
    stop = partial(_stop_unless_companion_wanted, key)
    stop()
    return nonlinear_histories(key.case, key.anti_slip,
                               runner=partial(background.run, stop=stop),
                               checkpoint=background.checkpoint)


def wanted_reaction(case: CaseBase, threshold: float, rate: float) -> Reaction:
    """:func:`reaction` for the dashboard's views, in a background worker process
    (:mod:`app.services.background`): it stops (ReactionSuperseded) as soon as no live view
    wants it any more — checked before it starts and between the blocks of every run of its
    delay grid.  Called directly, :func:`reaction` always completes in the calling thread."""
    key = reaction_key(case, threshold, rate)
    _stop_unless_wanted(key)
    return reaction(case, threshold, rate,
                    runner=partial(background.run, stop=partial(_stop_unless_wanted, key)))


@dataclass(frozen=True)
class Reaction:
    """Required reaction time at an operating point (plain data)."""

    required_delay: float | None  # [s] after detection
    reason: str
    detection_time: float | None  # [s] after the fault
    after_fault: float | None  # [s]
    limit: float  # [N m]


def anti_slip_key(enabled: bool, delay: float, threshold: float, rate: float) -> tuple:
    """A validated anti-slip key (raises NonlinearError with a one-line message)."""
    AntiSlip(bool(enabled), float(delay), float(threshold), float(rate))
    return (bool(enabled), float(delay), float(threshold), float(rate))


def reaction_key(case: CaseBase, threshold: float, rate: float) -> tuple:
    """What a reaction search depends on: the case (its horizon left out: 2 s) and the
    protection's threshold and rate."""
    return (case.without("t_end"), float(threshold), float(rate))


def _in_this_thread(function, *args):
    return function(*args)


def reaction(case: CaseBase, threshold: float, rate: float, runner=_in_this_thread) -> Reaction:
    """Required reaction time against M_ad (model.analysis.antislip) on a coarse grid: 11 delays,
    5 kHz, 2 s — about 20 nonlinear runs (kept in the results cache); ``runner(function,
    *args)`` runs the search when the cache does not hold it."""
    key = reaction_key(case, threshold, rate)
    point = key[0]
    return compute.cached("reaction", point, lambda: runner(_search, point, key[1], key[2]),
                          key[1], key[2])


def _search(point: CaseBase, threshold: float, rate: float) -> Reaction:
    """The search of :func:`reaction` (a background worker's task when served): it asks
    :func:`app.services.background.checkpoint` between the blocks of every run."""
    background.checkpoint()
    result = required_reaction_time(
        compute.model_for(point), point.operating_point(), point.short_circuit(),
        anti_slip=AntiSlip(True, 0.1, threshold, rate),
        delays=REACTION_DELAYS, t_end=2.0, fs=max(REACTION_FS, 20.0 * float(point.f)),
        checkpoint=background.checkpoint)
    return Reaction(result.required_delay, result.reason, result.detection_time,
                    result.reaction_after_fault, result.limit)


class NonlinearView:
    """Controls, overlays and status of the nonlinear creep model inside a dashboard."""

    def __init__(self, dashboard):
        self.dash = dashboard
        # one waiting history and one waiting reaction search per session (app.dashboard.jobs)
        self._histories = ViewJob(NONLINEAR_POOL, dashboard.alive, "nonlinear history")
        self._searches = ViewJob(SEARCH_POOL, dashboard.alive, "reaction time")
        self.creep = pn.widgets.RadioButtonGroup(
            options=list(CREEP_MODELS), value="linear",
            css_classes=["ctl-creep"], sizing_mode="stretch_width")
        self.anti_slip = pn.widgets.Checkbox(label="anti-slip protection on ID2",
                                             value=False, css_classes=["ctl-antislip"])
        defaults = AntiSlip()
        self.delay = pn.widgets.FloatInput(label="anti-slip delay τ after detection [s]",
                                           value=defaults.delay, step=0.01,
                                           css_classes=["ctl-antislip-delay"],
                                           sizing_mode="stretch_width")
        self.threshold = pn.widgets.FloatInput(label="anti-slip threshold Δ slip velocity [m/s]",
                                               value=defaults.threshold, step=0.05,
                                               css_classes=["ctl-antislip-threshold"],
                                               sizing_mode="stretch_width")
        self.rate = pn.widgets.FloatInput(label="anti-slip ramp rate [1/s]", value=defaults.rate,
                                          step=1.0, css_classes=["ctl-antislip-rate"],
                                          sizing_mode="stretch_width")
        self.controls = [pn.pane.Markdown("### Creep model and anti-slip (nonlinear)"),
                         self.creep, self.anti_slip, self.delay, self.threshold, self.rate]
        self.notice = pn.pane.Alert("", alert_type="warning", visible=False,
                                    css_classes=["nonlinear-notice"], sizing_mode="stretch_width")
        self.status = pn.pane.HTML("", css_classes=["reaction-status"],
                                   sizing_mode="stretch_width")
        self.valid = compute.ANTI_SLIP_OFF
        self.histories: NonlinearHistories | None = None  # last shown
        self.reaction: Reaction | None = None
        self._state = None  # the dashboard state of the linear result on screen
        self._shown_key = None
        self._progress = ""
        _VIEWS.add(self)
        doc = served_document()
        if doc is not None:  # a closed session wants no reaction time any more
            doc.on_session_destroyed(lambda _context: self._searches.forget())
        self._add_glyphs()
        for widget in (self.creep, self.anti_slip, self.delay, self.threshold, self.rate):
            widget.param.watch(self._on_change, "value")

    # --- plots -----------------------------------------------------------------------------

    def _add_glyphs(self) -> None:
        plots = self.dash.response_plots
        self.sources = SeriesSource(compute.RESPONSE_OUTPUTS, name="nonlinear")
        self.renderers = []
        for drive in ("ID1", "ID2"):
            fig = plots.torque[drive]
            for quantity, color in zip(compute.TORQUES, ("#0b3d66", "#7a1010"), strict=True):
                label = {"driving_shaft.torque": "M_DS nonlinear",
                         "disc_clutch.torque": "M_xDC nonlinear"}[quantity]
                self.renderers.append(self.sources.line(
                    fig, f"{drive}.{quantity}", color=color, line_width=1.5, line_dash="solid",
                    alpha=0.8, legend_label=label))
        creep_fig = self.dash.creep_plot.figure
        self.paths = SeriesSource(WHEEL_COLORS, name="creep_path", x="s", y="mu")
        for rim, color in WHEEL_COLORS.items():
            self.renderers.append(self.paths.line(creep_fig, rim, color=color, line_width=1.2,
                                                  alpha=0.8, legend_label=f"{rim} path (nonlinear)"))

    def _clear(self) -> None:
        self.sources.clear()
        self.paths.clear()
        self.histories = None
        self._shown_key = None

    def _show(self, key, histories: NonlinearHistories) -> None:
        self.histories, self._shown_key = histories, key
        self.dash.show_history(key, histories.response)  # the peak table describes it
        self.sources.update(histories.plot)
        self.paths.update(histories.paths)
        self._progress = self._describe(histories)
        self._render_status()

    @staticmethod
    def _describe(histories: NonlinearHistories) -> str:
        text = (f"nonlinear creep shown: peak ID2 M_xDC = "
                f"{abs(histories.peaks['ID2.disc_clutch.torque']):,.0f} N m "
                f"({abs(histories.peaks['ID2.disc_clutch.torque']) / histories.M_ad:.2f} M_ad), "
                f"largest creepage {histories.max_creepage:.4f}")
        if histories.detection_time is not None:
            text += (f"; anti-slip detected at {histories.detection_time:.3f} s, acts at "
                     f"{histories.action_time:.3f} s")
        return text

    # --- requests --------------------------------------------------------------------------

    def _on_change(self, *_events) -> None:
        if self.dash.point is None or self._state is None:
            return
        self.update()

    def prefetch(self, state: CaseBase, doc=None) -> None:
        """Served: start the nonlinear history of ``state`` as soon as the linear first answer
        is computed (it shares the operating point's eigendecomposition; its result is kept for
        :meth:`on_fast`), before that answer is sent and drawn (``doc``: the session's
        document)."""
        if self.creep.value != "nonlinear":
            return
        key = self._key(state)
        if key != self._shown_key:
            self._histories.start(("history", key), lambda: nonlinear_histories(
                key.case, key.anti_slip), lambda _k, _r: None, doc=doc)

    def on_fast(self, state) -> None:
        """Hook: the dashboard has shown the linear result for ``state``."""
        self._state = state
        self.update()

    def _key(self, state=None, anti_slip=...) -> HistoryKey:
        """The nonlinear history of ``state`` (default: the one shown) with the anti-slip key
        in use."""
        return HistoryKey(self._state if state is None else state,
                          self.valid if anti_slip is ... else anti_slip)

    def update(self) -> None:
        try:
            self.valid = anti_slip_key(self.anti_slip.value, self.delay.value,
                                       self.threshold.value, self.rate.value)
            self.notice.visible = False
        except (NonlinearError, TypeError, ValueError) as error:
            # the last valid values stay in use (nothing is recomputed for the bad input)
            message = error.args[0] if error.args else str(error)
            self.notice.object = (f"**Anti-slip input rejected:** {html.escape(str(message))} — "
                                  "keeping the last valid values and results.")
            self.notice.visible = True
        key = self._key()
        if self.creep.value == "linear":
            self._clear()
            self._progress = ""
            self.dash.show_history(self._key(anti_slip=None), self.dash.response)
            self._request_companion(key)
        elif key != self._shown_key:
            self._progress = "nonlinear creep: computing…"
            self.dash.show_history(key, None, "computing the nonlinear history…")
            self._start_history("history", key, self._apply_histories)
        else:
            self._histories.want(("history", key))
            self.dash.show_history(key, self.histories.response)
        if self.creep.value == "nonlinear" and self.dash.companion_key is not None:
            self.dash.show_companion(None, None)  # the table shows the nonlinear history itself
        self._request_reaction()
        self._render_status()

    def _start_history(self, kind: str, key: HistoryKey, apply) -> None:
        """The nonlinear history ``key`` on the nonlinear creep model's worker (``kind``:
        "history" shown as such, or "companion" beside a linear one: served, that one in a
        background worker process, :func:`wanted_companion`)."""
        work = ((lambda: wanted_companion(key)) if kind == "companion"
                else (lambda: nonlinear_histories(key.case, key.anti_slip)))
        self._histories.start((kind, key), work, lambda _k, histories: apply(key, histories),
                              lambda _k, error: self._reject(error))

    def wants_companion(self, key: HistoryKey) -> bool:
        """Whether this view still waits for the companion history ``key`` (any thread)."""
        return self._histories.wanted == ("companion", key) and self.dash.alive()

    def _request_companion(self, key: HistoryKey) -> None:
        """Linear creep on: beside a linear history that grows without bound, the nonlinear
        history of ``key`` (the anti-slip controls as set) for the peak table."""
        response = self.dash.response
        if response is None or response.load_peaks is None or response.load_peaks.bounded:
            if self.dash.companion_key is not None:
                self.dash.show_companion(None, None)
            return
        if key == self.dash.companion_key and self.dash.companion is not None:
            return
        self.dash.show_companion(key, None, "computing…")
        self._start_history("companion", key, self._apply_companion)

    def _apply_companion(self, key: HistoryKey, histories: NonlinearHistories) -> None:
        if self.creep.value != "linear" or key != self._key():
            return  # superseded
        self.dash.show_companion(key, histories.response)

    def _reaction_key_of(self, state) -> tuple:
        """The reaction search's key at the dashboard ``state``."""
        return reaction_key(state, self.valid[2], self.valid[3])

    def wants_reaction(self, key: tuple) -> bool:
        """Whether this view still waits for the reaction search ``key`` (any thread): the one it
        asked for, its session open, and the sliders not moved on since (a change whose linear
        answer is still being computed stops the search at once, not when that answer is
        shown; ``dash.latest`` is the newest state, set on the session's event loop)."""
        return (key == self._searches.wanted and self.dash.alive()
                and self._reaction_key_of(self.dash.latest) == key)

    def _request_reaction(self) -> None:
        point = self.dash.point
        if point is None or point.stable:
            self.reaction = None
            self._searches.forget()
            return
        key = self._reaction_key_of(self._state)
        if key == self._searches.wanted and self.reaction is not None:
            return
        self.reaction = None
        # a reaction-time search (tens of nonlinear runs, mostly Python: it holds the GIL most
        # of the time, which thread priorities cannot take away) starts only when the
        # operating point has stayed for REACTION_QUIET_MS: not while a slider is stepped
        self._searches.start(key, lambda: wanted_reaction(*key), self._apply_reaction,
                             lambda _k, error: self._reject(error), delay_ms=REACTION_QUIET_MS)

    def _apply_histories(self, key: HistoryKey, histories: NonlinearHistories) -> None:
        if self.creep.value != "nonlinear" or key != self._key():
            return  # superseded
        self._show(key, histories)

    def _apply_reaction(self, _key, result: Reaction) -> None:
        self.reaction = result
        self._render_status()

    def _reject(self, error: BaseException) -> None:
        message = error.args[0] if error.args else str(error)
        if self.creep.value == "nonlinear" and self._state is not None \
                and self._key() != self._shown_key:
            self.dash.show_history(self._key(), None, "the nonlinear history was rejected "
                                   "(see the notice above)")
        if self.creep.value == "linear" and self.dash.companion_key is not None \
                and self.dash.companion is None:
            self.dash.show_companion(self.dash.companion_key, None,
                                     "rejected (see the notice above)")
        self.notice.object = (f"**Nonlinear computation rejected:** {html.escape(str(message))} — "
                              "showing the last valid result.")
        self.notice.visible = True

    # --- status ----------------------------------------------------------------------------

    def _render_status(self) -> None:
        lines = []
        point = self.dash.point
        if point is not None and not point.stable:
            r = self.reaction
            if r is None:
                lines.append("required anti-slip reaction time: computing…")
            elif r.required_delay is not None:
                lines.append(f"required anti-slip reaction time (ID2 below M_ad, nonlinear): "
                             f"<b>{r.required_delay:.2f} s</b> after detection "
                             f"({r.after_fault:.2f} s after the fault)")
            elif r.reason == "no delay suffices":
                lines.append("required anti-slip reaction time: <b>none suffices</b> (M_ad is "
                             "passed even at once)")
            else:
                lines.append("required anti-slip reaction time: <b>any delay ≤ 0.5 s</b> keeps "
                             "ID2 below M_ad")
        if self._progress:
            lines.append(self._progress)
        self.status.object = ("<div style='font-size:13px;line-height:1.5'>"
                              + "<br>".join(lines) + "</div>") if lines else ""
