"""One way for a view to compute: off the event loop, results no longer wanted dropped, the answer
shown under the document's lock.

A :class:`ViewJob` is one kind of computation of one view of one session (the dense root locus,
s0*(v), the verdict, the Campbell diagram, a preview …).  :meth:`ViewJob.start` says which
result is wanted now (its key: a case record and the view's settings) and how to compute, show
or refuse it:

* served, the work runs on the job's thread pool (:mod:`app.services.thread_pools`: at most one
  request of the job waits there, a newer one replaces it); it is skipped if another key is
  wanted by the time its turn comes; its answer is posted to the session's next tick
  (:func:`app.dashboard.session.post`: the document's lock, one Bokeh hold) and shown only if its
  key is still the one wanted then.  ``after`` (a future) delays the start until it is done,
  ``delay_ms`` until the key has been wanted that long (after ``after``, if both);
* not served (tests, scripts), it is computed and shown at once.

The worker threads compare keys only: they never read the dashboard's parameters, which change
on the event loop under the document's lock.  An error of the model (:data:`MODEL_ERRORS`) goes to
``fail(key, error)``; any other is logged first.  A computation that stops because no session
wants it (:class:`app.results.cache.Superseded`) shows nothing.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Hashable
from concurrent.futures import Future

from app.dashboard.session import post, served_document
from app.dashboard.stages import MODEL_ERRORS
from app.results.cache import Superseded
from app.services.thread_pools import LatestRequest

log = logging.getLogger(__name__)
_SKIPPED = object()  # the work of a key no longer wanted when its turn came


class ViewJob:
    """One view's computations of one kind in one session (``name``: for the log)."""

    def __init__(self, pool, alive: Callable[[], bool], name: str):
        self.name = name
        self._requests = LatestRequest(pool, alive)
        self.wanted: Hashable | None = None  # the key of the result wanted now

    def start(self, key: Hashable, work: Callable[[], object],
              show: Callable[[Hashable, object], None],
              fail: Callable[[Hashable, BaseException], None] | None = None, *,
              after: Future | None = None, delay_ms: float | None = None,
              doc=None) -> Future:
        """Want ``key``: ``work()`` computes it, ``show(key, result)`` shows it (a result None
        shows nothing), ``fail(key, error)`` says why not (call on the session's event loop;
        ``doc``: the session's document, default the one being served).  Returns a future done
        when the work has ended, whatever its outcome (skipped and replaced included): what
        comes after it may start."""
        self.wanted = key
        ended: Future = Future()
        ended.set_running_or_notify_cancel()
        doc = doc if doc is not None else served_document()
        if doc is None:
            try:
                result = work()
            except Exception as error:  # the view says why; the dashboard stays alive
                self._fail(fail, key, error)
            else:
                if result is not None:
                    show(key, result)
            ended.set_result(None)
            return ended

        def run():
            return work() if self.wanted == key else _SKIPPED

        def submit() -> None:
            if self.wanted != key:
                ended.set_result(None)
                return
            future = self._requests.submit(run)
            future.add_done_callback(lambda f: self._done(doc, key, show, fail, f, ended))

        def wait_then_submit() -> None:
            if delay_ms and self.wanted == key:
                doc.add_timeout_callback(submit, delay_ms)
            else:
                submit()

        if after is not None and not after.done():
            after.add_done_callback(lambda _f: post(doc, wait_then_submit))
        else:
            wait_then_submit()
        return ended

    def want(self, key: Hashable | None) -> None:
        """Only ``key`` is wanted from now on (without starting it): a result of another key
        that arrives is not shown."""
        self.wanted = key

    def forget(self) -> None:
        """Nothing is wanted any more: a request waiting is dropped, a running one not shown."""
        self.wanted = None
        self._requests.cancel()

    def _done(self, doc, key, show, fail, future: Future, ended: Future) -> None:
        """A worker thread's end of a computation: its answer to the session's next tick."""
        ended.set_result(None)
        if future.cancelled():
            return
        error = future.exception()
        if isinstance(error, Superseded) or (error is None and future.result() is _SKIPPED):
            return
        post(doc, self._deliver, key, show, fail, future)

    def _deliver(self, key, show, fail, future: Future) -> None:
        if self.wanted != key:
            return  # another result is wanted now
        error = future.exception()
        if error is not None:
            self._fail(fail, key, error)
        elif future.result() is not None:
            show(key, future.result())

    def _fail(self, fail, key, error: BaseException) -> None:
        if not isinstance(error, MODEL_ERRORS):
            log.error("%s failed", self.name, exc_info=error)
        if fail is not None:
            fail(key, error)
