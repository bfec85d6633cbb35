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
uses them too); the reaction-time search here takes primitives only (``pn.cache`` keys) and
returns plain read-only data, like :mod:`app.results.compute`.
"""

from __future__ import annotations

import html
import logging
import weakref
from contextvars import ContextVar
from dataclasses import dataclass
from functools import partial

import numpy as np
import panel as pn

from app.results import compute
from app.results.compute import NonlinearHistories, nonlinear_histories
from app.results.plots import SeriesSource
from app.services.thread_pools import NONLINEAR_POOL, SEARCH_POOL, LatestRequest, ignore_outcome
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


class ReactionSuperseded(Exception):
    """A reaction search stopped because no session wants its result any more."""


_WATCHED: ContextVar[bool] = ContextVar("bogie_reaction_watched", default=False)


def _stop_unless_wanted(key: tuple) -> None:
    if _WATCHED.get() and not any(view.wants_reaction(key) for view in list(_VIEWS)):
        raise ReactionSuperseded(key)


def wanted_reaction(*key) -> Reaction:
    """:func:`reaction` for the dashboard's views: it stops (ReactionSuperseded) as soon as no
    live view wants ``key`` any more — checked before it starts and after every run of its
    delay grid.  Called directly, :func:`reaction` always completes."""
    token = _WATCHED.set(True)
    try:
        return reaction(*key)
    finally:
        _WATCHED.reset(token)


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


@pn.cache(max_items=64)
def reaction(params_path: str, rail: str, s0: float, v_kmh: float, N0_kN: float, b_M: float,
             M0_kNm: float, f: float, D: float, dt_ms: float | None, threshold: float,
             rate: float) -> Reaction:
    """Required reaction time against M_ad (model.analysis.antislip) on a coarse grid: 11 delays,
    5 kHz, 2 s — about 20 nonlinear runs."""
    key = (params_path, rail, s0, v_kmh, N0_kN, b_M, M0_kNm, f, D, dt_ms, threshold, rate)
    _stop_unless_wanted(key)
    m = compute.model(params_path, rail)
    op = compute.operating_point(params_path, rail, s0, v_kmh, N0_kN, b_M)
    result = required_reaction_time(
        m, op, compute.excitation(M0_kNm, f, D, dt_ms),
        anti_slip=AntiSlip(True, 0.1, threshold, rate),
        delays=REACTION_DELAYS, t_end=2.0, fs=max(REACTION_FS, 20.0 * float(f)),
        checkpoint=lambda: _stop_unless_wanted(key))  # between blocks of every run
    return Reaction(result.required_delay, result.reason, result.detection_time,
                    result.reaction_after_fault, result.limit)


class NonlinearView:
    """Controls, overlays and status of the nonlinear creep model inside a dashboard."""

    def __init__(self, dashboard):
        self.dash = dashboard
        # one waiting history and one waiting reaction search per session (app.services.thread_pools)
        self._histories = LatestRequest(NONLINEAR_POOL, dashboard.alive)
        self._searches = LatestRequest(SEARCH_POOL, dashboard.alive)
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
        self._reaction_key = None
        self._progress = ""
        _VIEWS.add(self)
        doc = self._served_doc()
        if doc is not None:  # a closed session wants no reaction time any more
            doc.on_session_destroyed(lambda _context: setattr(self, "_reaction_key", None))
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

    def _served_doc(self):
        doc = pn.state.curdoc
        return doc if doc is not None and doc.session_context is not None else None

    def _on_change(self, *_events) -> None:
        if self.dash.point is None or self._state is None:
            return
        self.update()

    def prefetch(self, state) -> None:
        """Served: start the nonlinear history of ``state`` as soon as the linear first answer
        is computed (it shares the operating point's eigendecomposition; its result is cached for
        :meth:`on_fast`), before that answer is sent and drawn."""
        if self.creep.value != "nonlinear":
            return
        key = self._key(state)
        if key != self._shown_key:
            future = self._histories.submit(nonlinear_histories, *key)
            ignore_outcome(future)  # on_fast shows its result or its error

    def on_fast(self, state) -> None:
        """Hook: the dashboard has shown the linear result for ``state``."""
        self._state = state
        self.update()

    def _key(self, state=None):
        """The nonlinear history's cache key for ``state`` (default: the one shown)."""
        s = self._state if state is None else state
        return (*s.point, s.M0, s.f, s.D, s.dt, s.t_end, self.valid)

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
            self.dash.show_history((*key[:-1], None), self.dash.response)
            self._request_companion(key)
        elif key != self._shown_key:
            self._progress = "nonlinear creep: computing…"
            self.dash.show_history(key, None, "computing the nonlinear history…")
            self._start(key, partial(nonlinear_histories, *key), self._apply_histories)
        else:
            self.dash.show_history(key, self.histories.response)
        if self.creep.value == "nonlinear" and self.dash.companion_key is not None:
            self.dash.show_companion(None, None)  # the table shows the nonlinear history itself
        self._request_reaction()
        self._render_status()

    def _request_companion(self, key) -> None:
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
        self._start(key, partial(nonlinear_histories, *key), self._apply_companion)

    def _apply_companion(self, key, histories: NonlinearHistories) -> None:
        if self.creep.value != "linear" or key != self._key():
            return  # superseded
        self.dash.show_companion(key, histories.response)

    def _reaction_key_of(self, state) -> tuple:
        """The reaction search's cache key at the dashboard ``state``."""
        return (*state.point, state.M0, state.f, state.D, state.dt, self.valid[2], self.valid[3])

    def wants_reaction(self, key: tuple) -> bool:
        """Whether this view still waits for the reaction search ``key`` (any thread): the one it
        asked for, its session open, and the sliders not moved on since (a change whose linear
        answer is still being computed stops the search at once, not when that answer is shown)."""
        return (key == self._reaction_key and self.dash.alive()
                and self._reaction_key_of(self.dash.state()) == key)

    def _request_reaction(self) -> None:
        point = self.dash.point
        if point is None or point.stable:
            self.reaction, self._reaction_key = None, None
            return
        key = self._reaction_key_of(self._state)
        if key == self._reaction_key and self.reaction is not None:
            return
        self._reaction_key = key
        self.reaction = None
        self._start(key, partial(wanted_reaction, *key), self._apply_reaction)

    def _start(self, key, work, apply) -> None:
        doc = self._served_doc()
        if doc is None:  # tests without a server: synchronous
            try:
                apply(key, work())
            except compute.ModelRejected as error:
                self._reject(error)
            except (NonlinearError, ValueError, np.linalg.LinAlgError) as error:
                self._reject(error)
            return

        def if_current():
            return work() if self._current(key, apply) else None

        # workers of their own (app.services.thread_pools), at a lower priority than the linear first answer;
        # a request superseded before it starts is skipped
        if apply == self._apply_reaction:
            # a reaction-time search (tens of nonlinear runs, mostly Python: it holds the GIL
            # most of the time, which thread priorities cannot take away) starts only when the
            # operating point has stayed for REACTION_QUIET_MS: not while a slider is stepped
            def start_if_quiet() -> None:
                if self._current(key, apply):
                    future = self._searches.submit(if_current)
                    future.add_done_callback(partial(self._done, doc, key, apply))

            doc.add_timeout_callback(start_if_quiet, REACTION_QUIET_MS)
            return
        future = self._histories.submit(if_current)
        future.add_done_callback(partial(self._done, doc, key, apply))

    def _current(self, key, apply) -> bool:
        """Whether a request is still the one to show (checked before it starts)."""
        if apply == self._apply_reaction:
            return key == self._reaction_key
        creep = "linear" if apply == self._apply_companion else "nonlinear"
        return self.creep.value == creep and self._state is not None and key == self._key()

    def _done(self, doc, key, apply, future) -> None:
        if future.cancelled():
            return  # replaced by a newer request, or the session has ended
        error = future.exception()
        if isinstance(error, ReactionSuperseded):
            return  # no longer wanted (module comment at _VIEWS)
        if error is not None:
            if not isinstance(error, ValueError | np.linalg.LinAlgError):
                log.error("nonlinear computation failed", exc_info=error)
            self.dash.post(doc, self._reject, error)
            return
        if future.result() is not None:
            self.dash.post(doc, apply, key, future.result())

    def _apply_histories(self, key, histories: NonlinearHistories) -> None:
        if self.creep.value != "nonlinear" or key != self._key():
            return  # superseded
        self._show(key, histories)

    def _apply_reaction(self, key, result: Reaction) -> None:
        if key != self._reaction_key:
            return
        self.reaction = result
        self._render_status()

    def _reject(self, error: Exception) -> None:
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
