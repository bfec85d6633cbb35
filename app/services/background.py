"""The server's background processes: the work that no slider waits for, outside the server's
interpreter and at a lower operating-system priority.

The verdict's load cases (the short circuit over every fault instant, the unstable adhesion with
nonlinear creep, the ripple case's speed sweep) and the anti-slip reaction-time search are
seconds of mostly-Python CPU each.  On the server's own worker threads they held the interpreter
(the GIL: thread priorities cannot take it away) beside every session's first answers; with a
review group of ten, one page's answers took 3.2 times as long as alone.  Here they run in
worker processes of their own:

* **local** (the default of ``bogie serve``): :data:`DEFAULT_WORKERS` processes started once
  (``forkserver``: not forked from the threaded server), each at niceness :data:`NICENESS` (a
  core is theirs only while the server does not want it), one BLAS thread, SIGINT ignored (the
  server stops them), a results cache of :data:`WORKER_CACHE_MB` MB of its own (docs/memory.md);
  a worker that dies is replaced and the work tried once more;
* **on a Dask cluster** (``bogie serve --scheduler ADDRESS``): the same functions as tasks of
  that cluster (its workers need the project installed, docs/cluster.md);
* **in the calling thread** where nothing is configured (the command line, the report, tests
  without a server): :func:`run` calls the function itself.

A lower priority is not enough on a small machine: at niceness 10 the workers still took a
third of two cores beside a review group's steps and slowed the answers.  So while any
session's first answer is computed (:func:`held`, around the eigen-analysis, the response and the
coarse root locus), the local workers are paused (SIGSTOP) and they go on (SIGCONT) as soon as no
first answer runs (one page among nine protocol clients: BENCHMARKS.md).  The work of an idle
review goes on at once; under a review group's steady changes it waits for the gaps between
their first answers.

:func:`run` blocks the calling (worker) thread until the answer is back; ``stop`` — a callable
that raises when the answer is no longer wanted — is asked every :data:`POLL_S` seconds, and the
running function sees it at its next :func:`checkpoint` (a flag in shared memory, one slot per
running task).  What crosses to a worker are the server's own records (case records, strength
data as numbers): nothing a browser sent is unpickled anywhere.
"""

from __future__ import annotations

import contextvars
import logging
import multiprocessing
import os
import signal
import threading
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures import TimeoutError as FutureTimeout
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

log = logging.getLogger(__name__)

NICENESS = 10  # the workers' niceness (a niceness-0 thread gets ≈ 90 % of a contended core)
DEFAULT_WORKERS = 2  # local worker processes (one per core of the 2-core machine it serves on)
WORKER_CACHE_MB = 150  # each worker's results cache [MB]: a model (≈ 56 MB) and its cases
POLL_S = 0.1  # how often a waiting thread asks whether the answer is still wanted [s]
SLOTS = 64  # tasks that can run or wait at once (a slot: one stop flag in shared memory)
PID_SLOTS = 256  # worker processes a server records over its life (started and replaced ones)


class Stopped(Exception):
    """Raised in a worker by :func:`checkpoint` when its task's answer is no longer wanted."""


# --- in a worker process -------------------------------------------------------------------------

_stops = None  # the shared stop flags (a worker process: inherited at its start)
_slot: int | None = None  # the slot of the task this worker runs
_in_thread_stop: contextvars.ContextVar[Callable | None] = contextvars.ContextVar(
    "bogie_background_stop", default=None)


def _start_worker(niceness: int, stops, started, setup: Callable | None) -> None:
    """A worker process's start: its process id recorded in ``started`` (shared with the server),
    lower priority, one BLAS thread, then ``setup()`` (the server's: the worker's own results
    cache, :data:`WORKER_CACHE_MB`)."""
    global _stops
    with started.get_lock():
        for index in range(len(started)):
            if started[index] == 0:
                started[index] = os.getpid()
                break
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        os.nice(niceness)
    except (AttributeError, OSError):
        pass  # another OS, or not allowed: the worker keeps the server's priority
    from app.services.thread_pools import limit_blas_threads

    limit_blas_threads()
    if setup is not None:
        setup()
    _stops = stops


def _run_in_slot(slot: int, function: Callable, args: tuple):
    global _slot
    _slot = slot
    try:
        return function(*args)
    finally:
        _slot = None


def checkpoint() -> None:
    """Raise (:class:`Stopped`, or the ``stop`` callable's own exception in the calling thread)
    if the running task's answer is no longer wanted; nothing otherwise.  Long functions call
    it between their steps."""
    if _stops is not None and _slot is not None:
        if _stops[_slot]:
            raise Stopped
        return
    stop = _in_thread_stop.get()
    if stop is not None:
        stop()


def _ready() -> bool:
    return True


# --- in the server -------------------------------------------------------------------------------

class LocalWorkers:
    """:data:`DEFAULT_WORKERS` worker processes at niceness :data:`NICENESS`."""

    def __init__(self, workers: int = DEFAULT_WORKERS, niceness: int = NICENESS,
                 setup: Callable | None = None):
        """``setup``: a picklable callable each worker calls once at its start."""
        self.workers, self.niceness, self.setup = int(workers), int(niceness), setup
        self._context = multiprocessing.get_context("forkserver")
        self._context.set_forkserver_preload(["numpy", "scipy.linalg", "model"])
        self._stops = self._context.RawArray("b", SLOTS)
        self._started = self._context.Array("i", PID_SLOTS)  # the workers' process ids
        self._free = list(range(SLOTS))
        self._lock = threading.Lock()
        self._slot_free = threading.Condition(self._lock)
        self._pool: ProcessPoolExecutor | None = None

    @property
    def description(self) -> str:
        return f"{self.workers} local worker process(es) at niceness {self.niceness}"

    def _executor(self) -> ProcessPoolExecutor:
        with self._lock:
            if self._pool is None:
                self._pool = ProcessPoolExecutor(
                    self.workers, mp_context=self._context, initializer=_start_worker,
                    initargs=(self.niceness, self._stops, self._started, self.setup))
            return self._pool

    def start(self) -> None:
        """Start the workers now (each imports the model once: a first verdict does not wait
        for it)."""
        pool = self._executor()
        for future in [pool.submit(_ready) for _ in range(self.workers)]:
            future.result(timeout=120)

    def pids(self) -> list[int]:
        """The ids of the worker processes that run now (for the memory and reliability
        checks)."""
        # read without the array's lock: a worker paused while it records its id holds it
        recorded = [pid for pid in self._started.get_obj() if pid]
        return sorted(pid for pid in recorded if _alive(pid))

    def signal_workers(self, signal_number: int) -> None:
        """Send ``signal_number`` to every worker process (pause: SIGSTOP, go on: SIGCONT)."""
        for pid in self.pids():
            try:
                os.kill(pid, signal_number)
            except OSError:  # ended meanwhile
                pass

    def _take_slot(self) -> int:
        with self._slot_free:
            while not self._free:
                self._slot_free.wait()
            slot = self._free.pop()
            self._stops[slot] = 0
            return slot

    def _give_back(self, slot: int) -> None:
        with self._slot_free:
            self._free.append(slot)
            self._slot_free.notify()

    def run(self, function: Callable, args: tuple, stop: Callable | None):
        for attempt in (1, 2):
            try:
                return self._run_once(function, args, stop)
            except BrokenProcessPool:
                with self._lock:
                    broken, self._pool = self._pool, None
                if broken is not None:
                    broken.shutdown(wait=False, cancel_futures=True)
                if attempt == 2:
                    raise
                log.warning("a background worker process died: starting new ones")
        raise AssertionError("unreachable")

    def _run_once(self, function: Callable, args: tuple, stop: Callable | None):
        slot = self._take_slot()
        try:
            future = self._executor().submit(_run_in_slot, slot, function, args)
        except BaseException:
            self._give_back(slot)
            raise
        # the slot is free again only when its task has ended (a stopped task may still run)
        future.add_done_callback(lambda _f: self._give_back(slot))
        while True:
            try:
                return future.result(timeout=POLL_S)
            except FutureTimeout:
                pass
            except Stopped:
                if stop is not None:
                    stop()  # its own exception, as in the calling thread
                raise
            if stop is not None:
                try:
                    stop()
                except BaseException:
                    self._stops[slot] = 1
                    future.cancel()
                    raise

    def close(self) -> None:
        """Stop the worker processes at once (the server is stopping; a paused one too)."""
        with self._lock:
            pool, self._pool = self._pool, None
        if pool is None:
            return
        self.signal_workers(signal.SIGKILL)
        pool.shutdown(wait=False, cancel_futures=True)


def _alive(pid: int) -> bool:
    """Whether process ``pid`` runs (a zombie, ended but not yet reaped, does not)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        try:
            os.kill(pid, 0)  # no /proc (another OS): whether the process exists
        except OSError:
            return False
        return True
    return state != "Z"


class ClusterWorkers:
    """The functions as tasks of the Dask cluster at ``scheduler`` (connected on first use)."""

    def __init__(self, scheduler: str):
        self.scheduler = scheduler
        self._engine = None
        self._lock = threading.Lock()

    @property
    def description(self) -> str:
        return f"the Dask cluster at {self.scheduler}"

    def start(self) -> None:
        pass  # connected on the first task: the server starts whether the cluster is up or not

    def pids(self) -> list[int]:
        return []

    def run(self, function: Callable, args: tuple, stop: Callable | None):
        from model.studies.engine import StudyEngine

        with self._lock:
            if self._engine is None:
                engine = StudyEngine(self.scheduler, use_environment=False)
                engine.start()  # EngineUnavailable: the view says why
                self._engine = engine
        future = self._engine.client.submit(_run_in_slot, None, function, args, pure=False)
        while True:
            try:
                return future.result(timeout=POLL_S)
            except TimeoutError:
                pass
            if stop is not None:
                try:
                    stop()
                except BaseException:
                    future.cancel()
                    raise

    def close(self) -> None:
        with self._lock:
            engine, self._engine = self._engine, None
        if engine is not None:
            engine.close()


_workers: LocalWorkers | ClusterWorkers | None = None


def configure(workers: LocalWorkers | ClusterWorkers | None) -> LocalWorkers | ClusterWorkers | None:
    """Where :func:`run` sends its work from now on (None: the calling thread); returns the
    previous workers (the caller closes them)."""
    global _workers
    previous, _workers = _workers, workers
    return previous


def current() -> LocalWorkers | ClusterWorkers | None:
    return _workers


_holds = 0  # first answers computing now (held)
_holds_lock = threading.Lock()


def _hold(change: int) -> None:
    """One more (``change`` 1) or one fewer (−1) first answer computing: the local workers pause
    when the first one starts and go on when the last one ends."""
    global _holds
    with _holds_lock:
        _holds += change
        edge = (_holds == 1 and change > 0) or (_holds == 0 and change < 0)
        workers = _workers
        if edge and isinstance(workers, LocalWorkers):
            workers.signal_workers(signal.SIGSTOP if _holds else signal.SIGCONT)


def held(function: Callable) -> Callable:
    """``function`` with the local workers paused while it runs (a session's first answer: the
    cores are the server's while it is computed)."""
    def run_held(*args, **kwargs):
        _hold(1)
        try:
            return function(*args, **kwargs)
        finally:
            _hold(-1)
    return run_held


def run(function: Callable, *args, stop: Callable | None = None):
    """``function(*args)`` on the background workers (in the calling thread if none are
    configured); ``function`` is a module-level function and ``args`` the server's own plain
    records.  ``stop()`` raises when the answer is no longer wanted: the function sees it at its
    next :func:`checkpoint` and ``run`` raises that exception."""
    workers = _workers
    if workers is None:
        token = _in_thread_stop.set(stop)
        try:
            return function(*args)
        finally:
            _in_thread_stop.reset(token)
    return workers.run(function, args, stop)

