"""When and where a dashboard's computations run, and when their results are shown.

Without a server (tests, scripts) a change is computed and shown at once (:meth:`Scheduler.refresh`).

Served, a change marks the parameters dirty and starts the worker coroutine on the session's
event loop unless it runs already; it then computes the newest parameters when it is done, so
changes arriving meanwhile are coalesced.  The worker runs on the thread pools of
:mod:`app.services.thread_pools`, without the session's document lock (several reviewers on one
server do not queue behind each other); each result is shown on the session's next tick with the
lock (:func:`app.dashboard.session.post`), if it still belongs to the parameters on screen.  Per
change (a case record, :meth:`BogieDashboard.state`, and the root locus's sweep):

1. the state's views are asked for their results with its first answer, or with its rejection
   (the verdict: its computation waits until the state's follow-ups have ended, whatever their
   outcome — rejected, superseded or shown —, so that it does not share the cores with the dense
   root locus);
2. the coarse root locus starts beside the fast stage (:mod:`app.dashboard.stages`) and is
   shown when both are done (nothing to do if the dense locus of the same sweep is on screen);
3. follow-ups (:class:`app.dashboard.jobs.ViewJob`), not waited for: the dense root locus
   replaces the coarse one, then s0*(v) starts; a follow-up superseded before it starts is
   skipped, an s0*(v) search whose speed (wheel force, motor slope) no session wants any more
   stops before its next eigen-analysis.

A static "computing…" notice appears when a change takes longer than :data:`BUSY_DELAY_MS`.
"""

from __future__ import annotations

import asyncio
import logging
import weakref
from concurrent.futures import Future

import panel as pn
from bokeh.document import without_document_lock

from app.dashboard import stages
from app.dashboard.jobs import ViewJob
from app.dashboard.layout import CSS
from app.dashboard.session import post
from app.dashboard.stages import MODEL_ERRORS
from app.results.cache import Superseded
from app.results.case import CaseBase, Sweep
from app.services.background import held
from app.services.thread_pools import (
    FIRST_ANSWER_POOL,
    FOLLOW_UP_POOL,
    SIDE_VIEW_POOL,
    ignore_outcome,
)

log = logging.getLogger(__name__)
BUSY_DELAY_MS = 400  # the "computing…" notice appears when a change takes longer [ms]
BUSY_TEXT = '<div class="busy-text">⏳ computing…</div>'
# the schedulers alive in this process: an s0*(v) search that no session wants any more (its
# speed, wheel force or motor slope has moved on, or its session has ended) stops before its
# next eigen-analysis instead of sharing the cores with the next state's root loci
_SCHEDULERS: weakref.WeakSet = weakref.WeakSet()


class LimitSuperseded(Superseded):
    """An s0*(v) search stopped because no session wants it any more (a session waiting for the
    same limit computes it itself)."""


def _stop_unless_wanted(key) -> None:
    if not any(s._limit.wanted == key and s.dashboard.alive() for s in list(_SCHEDULERS)):
        raise LimitSuperseded(key)


def _open(gate: Future) -> None:
    """Let what waits for ``gate`` start (once)."""
    if not gate.done():
        gate.set_result(None)


class Scheduler:
    """Computes a dashboard's changes and hands the results to it (one per session).

    The dashboard provides ``state()`` (a case record), ``sweep()`` (the root locus on the
    controls), ``alive()``, ``shown_locus`` (the sweep and density on screen),
    ``nonlinear.prefetch(case)``, ``state_changed(case, settled)`` and the display methods
    ``show_fast(case, (point, response))`` (not served), ``show_point(case, point)`` and
    ``show_response(case, response)`` (served: the status first), ``show_locus(sweep, locus)``,
    ``show_limit(case, limit)`` and ``reject(error)``.
    """

    def __init__(self, dashboard):
        self.dashboard = dashboard
        self._dirty = False
        self._running = False
        # the follow-ups (app.dashboard.jobs): dense locus, s0*(v)
        self._dense = ViewJob(FOLLOW_UP_POOL, dashboard.alive, "dense root locus")
        self._limit = ViewJob(SIDE_VIEW_POOL, dashboard.alive, "stability limit")
        _SCHEDULERS.add(self)
        # a static notice of fixed size, shown only for changes longer than BUSY_DELAY_MS: an
        # overlay over the results made the browser re-lay out every plot (+300 ms per change),
        # and an animated spinner kept every waiting page busy (measured with ten sessions)
        self.busy_notice = pn.pane.HTML("", width=300, height=22, css_classes=["busy"],
                                        stylesheets=[CSS])

    # --- without a server -----------------------------------------------------------------------

    def refresh(self, slow: bool = True) -> None:
        """Compute and show everything synchronously (initial view, tests); ``slow=False``
        skips the stability limit and the root locus."""
        dashboard = self.dashboard
        case, sweep = dashboard.state(), dashboard.sweep()
        settled: Future = Future()
        _open(settled)
        dashboard.state_changed(case, settled)
        try:
            fast = stages.fast(case)
        except MODEL_ERRORS as error:
            dashboard.reject(error)
            return
        dashboard.show_fast(case, fast)
        if not slow:
            return
        try:
            limit, locus = stages.slow(case, sweep)
        except MODEL_ERRORS as error:
            dashboard.reject(error)
            return
        dashboard.show_limit(case, limit)
        dashboard.show_locus(sweep, locus)

    # --- served ---------------------------------------------------------------------------------

    def request(self, doc, loading: bool = True) -> None:
        """Compute the current parameters on worker threads (``loading``: with the busy notice
        for a long change)."""
        self._dirty = True
        if self._running:
            return  # the running worker picks up the newest parameters when it is done
        self._running = True
        if loading:
            doc.add_timeout_callback(self._show_busy, BUSY_DELAY_MS)
        doc.add_next_tick_callback(without_document_lock(self._worker_of(doc)))

    def _worker_of(self, doc):
        async def worker() -> None:
            await self._worker(doc)
        return worker

    async def _worker(self, doc) -> None:
        dashboard = self.dashboard
        loop = asyncio.get_running_loop()
        settled: Future = Future()
        handed = False  # settled is opened by the state's s0*(v) when it has ended
        try:
            while self._dirty and dashboard.alive():
                self._dirty = False
                if not handed:
                    _open(settled)  # the previous state's: rejected or superseded
                handed = False
                case, sweep = dashboard.state(), dashboard.sweep()
                # the results of another sweep or speed that arrive from now on are not shown
                self._dense.want(sweep)
                self._limit.want(case.limit_key())
                settled = Future()  # open when this state's follow-ups have ended
                # the coarse root locus (≈ 0.3 s on two threads when not kept) starts at once,
                # beside the fast stage (one thread), and is shown when both are done; then the
                # dense one replaces it when ready.  Nothing to do if the dense locus of this
                # sweep is on screen already
                need_locus = dashboard.shown_locus != (sweep, True)
                locus_future = (loop.run_in_executor(FIRST_ANSWER_POOL, held(stages.coarse_locus),
                                                     sweep)
                                if need_locus else None)
                # the fast stage in two answers: the status first (the eigen-analysis), then the
                # short-circuit history, which shares its decomposition; the first answers run
                # with the background worker processes paused (app.services.background.held)
                # (the state's views are asked for their results with the first answer, in one
                # message to the browser: state_changed)
                try:
                    point = await loop.run_in_executor(FIRST_ANSWER_POOL, held(stages.point), case)
                except MODEL_ERRORS as error:
                    post(doc, self._rejected_state, case, settled, error)
                    if locus_future is not None:
                        ignore_outcome(locus_future)
                    continue
                post(doc, self._first_answer, case, settled, point)
                try:
                    response = await loop.run_in_executor(FIRST_ANSWER_POOL, held(stages.response),
                                                          case)
                except MODEL_ERRORS as error:
                    post(doc, dashboard.reject, error)
                    if locus_future is not None:
                        ignore_outcome(locus_future)
                    continue
                # the nonlinear history, if shown, starts once the linear first answer is
                # computed, not beside it: its step loop is mostly Python and shared the GIL
                # with the fast stage (linear result 304 ms beside it, median of 12 steps)
                dashboard.nonlinear.prefetch(case, doc)
                post(doc, dashboard.show_response, case, response)
                if self._dirty:
                    if locus_future is not None:
                        ignore_outcome(locus_future)  # it still fills the cache
                    continue
                if locus_future is None:
                    self._start_limit(doc, case, settled)
                    handed = True
                    continue
                try:
                    locus = await locus_future
                except MODEL_ERRORS as error:
                    post(doc, dashboard.reject, error)
                    continue
                if self._dirty:
                    continue
                post(doc, dashboard.show_locus, sweep, locus)
                # s0*(v) after the dense locus (which has a target: ≤ 2 s after a speed
                # change): at a lower priority beside it, its full eigen-analyses still took
                # ≈ 1.3 CPU-s of the two cores while the dense sweep ran (py-spy)
                dense = self._dense.start(sweep, lambda s=sweep: stages.dense_locus(s),
                                          self._show_locus, self._rejected, doc=doc)
                self._start_limit(doc, case, settled, after=dense)
                handed = True
        except Exception as error:  # keep the server and the session alive, say what happened
            log.exception("dashboard computation failed")
            post(doc, dashboard.reject, error)
        finally:
            if not handed:
                _open(settled)
            self._running = False
            post(doc, self._hide_busy)

    def _first_answer(self, case: CaseBase, settled: Future, point) -> None:
        self.dashboard.state_changed(case, settled)
        self.dashboard.show_point(case, point)

    def _rejected_state(self, case: CaseBase, settled: Future, error: BaseException) -> None:
        self.dashboard.state_changed(case, settled)
        self.dashboard.reject(error)

    def _show_busy(self) -> None:
        if self._running:
            self.busy_notice.object = BUSY_TEXT

    def _hide_busy(self) -> None:
        if not self._running and self.busy_notice.object:
            self.busy_notice.object = ""

    # --- follow-ups: the dense root locus, then s0*(v) ----------------------------------------

    def _start_limit(self, doc, case: CaseBase, settled: Future, after: Future | None = None
                     ) -> None:
        """s0*(v) (≈ 0.7 s when not kept) is not waited for: a change arriving meanwhile
        starts at once; the limit is shown when ready if it still belongs to the parameters.
        ``settled`` opens when it has ended."""
        key = case.limit_key()

        def start() -> None:
            if self._limit.wanted != key:  # superseded while the dense locus ran
                _open(settled)
                return
            def work() -> object:
                return stages.limit(case, lambda: _stop_unless_wanted(key))

            done = self._limit.start(key, work,
                                     lambda _k, limit: self.dashboard.show_limit(case, limit),
                                     self._rejected, doc=doc)
            done.add_done_callback(lambda _f: _open(settled))

        if after is None:
            start()
        else:  # on the session's tick once the dense locus has ended
            after.add_done_callback(lambda _f: post(doc, start))

    def _show_locus(self, sweep: Sweep, locus) -> None:
        self.dashboard.show_locus(sweep, locus)

    def _rejected(self, _key, error: BaseException) -> None:
        if isinstance(error, MODEL_ERRORS):
            self.dashboard.reject(error)
