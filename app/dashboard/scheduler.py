"""When and where a dashboard's computations run, and when their results are shown.

Without a server (tests, scripts) a change is computed and shown at once (:meth:`Scheduler.refresh`).

Served, a change marks the parameters dirty and starts the worker coroutine on the session's
event loop unless it runs already; it then computes the newest parameters when it is done, so
changes arriving meanwhile are coalesced.  The worker runs on the thread pools of
:mod:`app.services.thread_pools`, without the session's document lock (several reviewers on one
server do not queue behind each other); each result is shown on the session's next tick with the
lock (:func:`app.dashboard.session.post`), if it still belongs to the parameters on screen.  Per
change:

1. the coarse root locus starts at once beside the fast stage (:mod:`app.dashboard.stages`) and
   is shown when both are done (nothing to do if the dense locus of the same sweep is on screen);
2. follow-ups, not waited for: the dense root locus replaces the coarse one, then s0*(v) starts;
   a follow-up superseded before it starts is skipped.

A static "computing…" notice appears when a change takes longer than :data:`BUSY_DELAY_MS`.
"""

from __future__ import annotations

import asyncio
import logging
from functools import partial

import panel as pn
from bokeh.document import without_document_lock

from app.dashboard import stages
from app.dashboard.layout import CSS
from app.dashboard.session import post
from app.dashboard.stages import MODEL_ERRORS, State
from app.results import compute
from app.services.thread_pools import (
    FIRST_ANSWER_POOL,
    FOLLOW_UP_POOL,
    SIDE_VIEW_POOL,
    LatestRequest,
    ignore_outcome,
)

log = logging.getLogger(__name__)
BUSY_DELAY_MS = 400  # the "computing…" notice appears when a change takes longer [ms]
BUSY_TEXT = '<div class="busy-text">⏳ computing…</div>'


class Scheduler:
    """Computes a dashboard's changes and hands the results to it (one per session).

    The dashboard provides ``state()``, ``alive()``, ``shown_locus`` (the locus key and density
    on screen), ``nonlinear.prefetch(state)`` and the display methods ``show_fast(state, (point,
    response))``, ``show_locus(state, locus)``, ``show_limit(state, limit)`` and
    ``reject(error)``.
    """

    def __init__(self, dashboard):
        self.dashboard = dashboard
        self._dirty = False
        self._running = False
        # one waiting follow-up per kind (app.services.thread_pools.LatestRequest): dense locus, s0*(v)
        self._dense_requests = LatestRequest(FOLLOW_UP_POOL, dashboard.alive)
        self._limit_requests = LatestRequest(SIDE_VIEW_POOL, dashboard.alive)
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
        state = dashboard.state()
        try:
            fast = stages.fast(state)
        except MODEL_ERRORS as error:
            dashboard.reject(error)
            return
        dashboard.show_fast(state, fast)
        if not slow:
            return
        try:
            limit, locus = stages.slow(state)
        except MODEL_ERRORS as error:
            dashboard.reject(error)
            return
        dashboard.show_limit(state, limit)
        dashboard.show_locus(state, locus)

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
        doc.add_next_tick_callback(without_document_lock(partial(self._worker, doc)))

    async def _worker(self, doc) -> None:
        dashboard = self.dashboard
        loop = asyncio.get_running_loop()
        try:
            while self._dirty and dashboard.alive():
                self._dirty = False
                state = dashboard.state()
                # the coarse root locus (≈ 0.3 s on two threads when not cached) starts at once,
                # beside the fast stage (one thread), and is shown when both are done; then the
                # dense one replaces it when ready.  Nothing to do if the dense locus of this
                # (set, rail, sweep, fixed value, N0, b_M) is on screen already
                need_locus = dashboard.shown_locus != (state.locus_key, True)
                locus_future = (loop.run_in_executor(FIRST_ANSWER_POOL, stages.coarse_locus, state)
                                if need_locus else None)
                try:
                    fast = await loop.run_in_executor(FIRST_ANSWER_POOL, stages.fast, state)
                except MODEL_ERRORS as error:
                    post(doc, dashboard.reject, error)
                    if locus_future is not None:
                        ignore_outcome(locus_future)
                    continue
                # the nonlinear history, if shown, starts once the linear first answer is
                # computed, not beside it: its step loop is mostly Python and shared the GIL
                # with the fast stage (linear result 304 ms beside it, median of 12 steps)
                dashboard.nonlinear.prefetch(state)
                post(doc, dashboard.show_fast, state, fast)
                if self._dirty:
                    if locus_future is not None:
                        ignore_outcome(locus_future)  # it still fills the cache
                    continue
                if locus_future is not None:
                    try:
                        locus = await locus_future
                    except MODEL_ERRORS as error:
                        post(doc, dashboard.reject, error)
                        continue
                    if self._dirty:
                        continue
                    post(doc, dashboard.show_locus, state, locus)
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
            post(doc, dashboard.reject, error)
        finally:
            self._running = False
            post(doc, self._hide_busy)

    def _show_busy(self) -> None:
        if self._running:
            self.busy_notice.object = BUSY_TEXT

    def _hide_busy(self) -> None:
        if not self._running and self.busy_notice.object:
            self.busy_notice.object = ""

    # --- follow-ups: the dense root locus, then s0*(v) ----------------------------------------

    def _start_limit(self, doc, state: State) -> None:
        """s0*(v) (≈ 0.7 s when not cached) is not waited for: a change arriving meanwhile
        starts at once; the limit is shown when ready if it still belongs to the parameters."""
        limit = self._limit_requests.submit(self._limit_if_current, state)
        limit.add_done_callback(partial(self._limit_done, doc, state))

    def _limit_current(self, state: State) -> bool:
        """Whether s0*(v) for ``state`` is still the one to show (same v, N0, b_M, rail)."""
        return self.dashboard.state().limit_key == state.limit_key

    def _locus_current(self, state: State) -> bool:
        """Whether the root locus of ``state`` is still the one to show (same sweep)."""
        return self.dashboard.state().locus_key == state.locus_key

    def _limit_if_current(self, state: State) -> compute.LimitResult | None:
        """s0*(v), unless superseded before it started (a speed slider dragged over ten values
        must not queue ten 0.7 s root findings in front of the next change's fast stage)."""
        return stages.limit(state) if self._limit_current(state) else None

    def _dense_if_current(self, state: State) -> compute.LocusResult | None:
        """The dense root locus, unless superseded before it started."""
        return stages.dense_locus(state) if self._locus_current(state) else None

    def _dense_done(self, doc, state: State, future) -> None:
        self._follow_up_done(doc, state, future, "dense root locus", self.dashboard.show_locus,
                             lambda: self._locus_current(state))

    def _limit_done(self, doc, state: State, future) -> None:
        self._follow_up_done(doc, state, future, "stability limit", self.dashboard.show_limit,
                             lambda: self._limit_current(state))
        # s0*(v) is the last follow-up (after the dense root locus when one was needed): the
        # verdict of the same state starts now (its own check skips a superseded state)
        if not future.cancelled():
            post(doc, self.dashboard.verdicts.start, state)

    def _follow_up_done(self, doc, state: State, future, what: str, show, current) -> None:
        """A follow-up's result (``None``: skipped) is shown with ``show(state, result)`` if
        ``current()`` still holds (nothing otherwise: another speed, sweep … is shown)."""
        if future.cancelled() or not current():
            return
        error = future.exception()
        if error is not None:
            if isinstance(error, MODEL_ERRORS):
                post(doc, self.dashboard.reject, error)
            else:
                log.error("%s failed", what, exc_info=error)
            return
        if future.result() is not None:
            post(doc, show, state, future.result())
