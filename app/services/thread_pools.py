"""The dashboard's worker threads, one pool per priority, shared by all sessions of a process.

A change must show its first answer (eigenvalues, status, time histories) within ≈ 300 ms, while
the results that follow it (dense root locus, s0*(v), sensitivities, nonlinear histories,
reaction times, a variant's comparison) may take seconds of CPU on a 2-core machine.  Python
threads cannot be given priorities, but Linux schedules each thread on its own: the pools below
run their threads at a higher niceness (lower priority), so a background computation keeps a
core only while nothing more urgent wants it, and the next change's first answer is not slowed
down by the previous change's follow-ups.  (The computations release the GIL in LAPACK; the
Python parts still share it.)  Where the niceness cannot be set (another OS), the threads keep
the process's priority.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor

from model.analysis.locus import set_thread_niceness

# niceness (0 .. 19; CPU share against a niceness-0 thread: 5 → 33 %, 10 → 11 %, 19 → 1.5 %)
FIRST_ANSWER = 0  # eigenvalues, status, time histories; the coarse root locus
FOLLOW_UP = 5  # dense root locus, nonlinear histories: awaited on screen
SIDE_VIEW = 10  # s0*(v), sensitivities, the variant comparison
SEARCH = 19  # reaction-time searches (tens of nonlinear runs)


def prioritized_pool(workers: int, niceness: int, name: str) -> ThreadPoolExecutor:
    """A pool of ``workers`` threads running at ``niceness``."""
    return ThreadPoolExecutor(max_workers=workers, thread_name_prefix=name,
                              initializer=set_thread_niceness, initargs=(niceness,))


# the first answers of several sessions run side by side (one BLAS thread each)
FIRST_ANSWER_POOL = prioritized_pool(3, FIRST_ANSWER, "bogie-compute")
FOLLOW_UP_POOL = prioritized_pool(2, FOLLOW_UP, "bogie-follow-up")
SIDE_VIEW_POOL = prioritized_pool(2, SIDE_VIEW, "bogie-side-view")
# the nonlinear runs have workers of their own: a running reaction search never holds up the
# next nonlinear history
NONLINEAR_POOL = prioritized_pool(1, FOLLOW_UP, "bogie-nonlinear")
SEARCH_POOL = prioritized_pool(1, SEARCH, "bogie-reaction")
# the life over a route (25 s to 2 min in a background worker process): a thread of its own that
# waits for it, so that it never holds up a side view's thread
LIFE_POOL = prioritized_pool(1, SEARCH, "bogie-life")
# a dragged slider's previews (app.results.preview: at most one reduced eigenproblem each) yield
# the cores to the first answers, so a preview never delays the answer to the release
PREVIEW_POOL = prioritized_pool(2, FOLLOW_UP, "bogie-preview")


def ignore_outcome(future) -> None:
    """Retrieve ``future``'s outcome (a concurrent or an asyncio future) when it ends, for a
    computation whose result is no longer shown: no "exception was never retrieved" warning for a
    rejected, superseded parameter set."""
    future.add_done_callback(lambda f: f.cancelled() or f.exception())


class LatestRequest:
    """One view's requests of one session on a shared pool: at most one waits in the pool's queue.

    :meth:`submit` returns a future.  A request that has not started when a newer one arrives is
    cancelled (its future reports ``cancelled()``) and the newer one takes its place in the queue;
    a request whose session has closed (``alive()`` false when its turn comes) is cancelled
    instead of run.  So the pools' queues hold at most one entry per session and view, however
    fast a client sends changes, and a closed session's waiting work costs no CPU.
    """

    def __init__(self, pool: ThreadPoolExecutor, alive=lambda: True):
        self._pool = pool
        self._alive = alive
        self._lock = threading.Lock()
        self._next: tuple[Future, Callable, tuple] | None = None
        self._queued = False

    def submit(self, function: Callable, *args) -> Future:
        future: Future = Future()
        with self._lock:
            replaced, self._next = self._next, (future, function, args)
            start, self._queued = not self._queued, True
        if replaced is not None:
            replaced[0].cancel()
        if start:
            self._pool.submit(self._run)
        return future

    def cancel(self) -> None:
        """Drop the request waiting in the queue, if any (a running one runs to its end)."""
        with self._lock:
            waiting, self._next = self._next, None
        if waiting is not None:
            waiting[0].cancel()

    def _run(self) -> None:
        with self._lock:
            item, self._next, self._queued = self._next, None, False
        if item is None:
            return
        future, function, args = item
        if not self._alive():
            future.cancel()
            return
        if not future.set_running_or_notify_cancel():
            return
        try:
            result = function(*args)
        except BaseException as error:  # handed to the future's callbacks, as the pool does
            future.set_exception(error)
        else:
            future.set_result(result)


_BLAS_LIMITED = threading.Lock()
_blas_limited = False


def limit_blas_threads() -> None:
    """One BLAS thread per computation, set once per process before any computation thread
    starts (never per call from worker threads: OpenBLAS's thread count is process-wide).  The
    dashboard runs computations of several sessions in parallel, and OpenBLAS's own threads on a
    busy 2-core machine made a single eigen-analysis 30-90x slower (measured: 0.2 s vs 9-18 s)."""
    global _blas_limited
    with _BLAS_LIMITED:
        if _blas_limited:
            return
        import numpy  # noqa: F401 - load both BLAS libraries before limiting them
        import scipy.linalg  # noqa: F401
        from threadpoolctl import threadpool_limits

        threadpool_limits(1)
        _blas_limited = True
