"""The study engine: Dask distributed around the pure chunk functions of :mod:`model.studies.maps`.

This is the only module of ``model/`` that imports dask.  It knows nothing of the physics: it
runs ``function(item)`` for many items on a cluster and hands back the results as they finish.

* Default: a ``LocalCluster`` of worker *processes*, one thread each, as many as cores, each with
  one BLAS thread (environment ``OPENBLAS_NUM_THREADS=1`` etc. and ``threadpoolctl`` once per
  process: two workers on two cores must not fight over four BLAS threads).
* ``supervised=False`` (the dashboard server's cluster): the scheduler in this process and each
  worker a plain subprocess (``python -m dask spec``), no nanny: exactly one process per worker
  (a nanny's ``multiprocessing`` adds Python's resource-tracker process).  A worker that dies is
  not restarted: :meth:`StudyEngine.healthy` tells, and the caller starts a new engine.
* ``niceness``: the worker threads run at this niceness (a local cluster beside an interactive
  server leaves it the CPU it needs first).
* ``scheduler="tcp://HOST:PORT"`` (or the environment variable ``DASK_SCHEDULER_ADDRESS``)
  attaches to a running cluster; the workers need the project installed (docs/cluster.md).  An
  unreachable scheduler raises :class:`EngineUnavailable` after ``connect_timeout`` seconds.
* Faults: Dask reschedules the tasks of a worker that dies (its finished results were already
  handed back and written); a task is retried on up to ``distributed.scheduler.allowed-failures``
  worker deaths (default 3).

Generic use (e.g. the Monte-Carlo study of :mod:`model.studies.uncertainty` with a pluggable ``map``)::

    with StudyEngine(scheduler=None) as engine:          # local cluster
        results = engine.map(function, items)            # ordered list, like builtins.map
        for index, result in engine.map_unordered(function, items):  # as they finish
            ...
        run_uncertainty(parameters, n, map_fn=in_order(engine.map_unordered))  # in order, live

``function`` must be picklable (a module-level function or a ``functools.partial`` of one) and
pure: a task may run twice (after a worker death), and must give the same result.
"""

from __future__ import annotations

import logging
import os
import signal
import threading
from collections.abc import Callable, Iterable, Iterator
from functools import partial

BLAS_ENVIRONMENT = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
SCHEDULER_VARIABLE = "DASK_SCHEDULER_ADDRESS"
# Dask's nanny starts workers with MALLOC_TRIM_THRESHOLD_=65536 (to return memory to the OS).
# Setting it disables glibc's dynamic mmap threshold, so every array above 128 KiB (the
# coordinate-sized and state-sized matrices of an eigen-analysis) is mmap-ed, page-faulted and unmapped again: a
# chunk cost 1.6-1.8x the CPU time in a worker that it costs in a plain process (measured).
# Unset for the local cluster; for ``dask worker`` set the environment variable
# DASK_DISTRIBUTED__NANNY__PRE_SPAWN_ENVIRON__MALLOC_TRIM_THRESHOLD_=None (docs/cluster.md).
WORKER_CONFIG = {"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}


class EngineUnavailable(RuntimeError):
    """The cluster could not be reached or started (one-line message)."""


_BLAS_LIMITED = False


def _one_blas_thread() -> None:
    """One BLAS thread in this (worker) process, set once."""
    global _BLAS_LIMITED
    if not _BLAS_LIMITED:
        import numpy  # noqa: F401 - load both BLAS libraries before limiting them
        import scipy.linalg  # noqa: F401
        from threadpoolctl import threadpool_limits

        threadpool_limits(1)
        _BLAS_LIMITED = True


_THREAD = threading.local()  # niceness already set for this (worker task) thread


def _call(function: Callable, item, niceness: int = 0):
    _one_blas_thread()
    if niceness and getattr(_THREAD, "niceness", 0) != niceness:
        from model.analysis.locus import set_thread_niceness

        set_thread_niceness(niceness)
        _THREAD.niceness = niceness
    return function(item)


def scheduler_address(explicit: str | None = None) -> str | None:
    """The scheduler to attach to: ``explicit``, else ``$DASK_SCHEDULER_ADDRESS``, else None
    (a local cluster)."""
    return explicit or os.environ.get(SCHEDULER_VARIABLE) or None


class StudyEngine:
    """A Dask client (to a given scheduler or to a new local cluster) as a context manager."""

    def __init__(self, scheduler: str | None = None, workers: int | None = None,
                 connect_timeout: float = 10.0, use_environment: bool = True,
                 supervised: bool = True, niceness: int = 0, worker_timeout: float = 120.0):
        """``use_environment=False``: ``scheduler=None`` means a local cluster even when
        ``$DASK_SCHEDULER_ADDRESS`` is set (a server whose operator chose the engine);
        ``supervised``, ``niceness``: the local cluster's workers (module docstring);
        ``worker_timeout`` [s]: how long :meth:`start` waits for all of a local cluster's workers
        to join (a study never waits for workers that will not come)."""
        self.scheduler = scheduler_address(scheduler) if use_environment else (scheduler or None)
        self.supervised = supervised
        self.niceness = niceness
        self.workers = workers or os.cpu_count() or 1
        self.connect_timeout = connect_timeout
        self.worker_timeout = worker_timeout
        self.client = None
        self.cluster = None

    def __enter__(self) -> StudyEngine:
        self.start()
        return self

    def __exit__(self, *_exc) -> None:
        self.close()

    @property
    def description(self) -> str:
        if self.scheduler:
            return f"cluster at {self.scheduler}"
        return f"local cluster of {self.workers} worker process(es), one thread each"

    def start(self) -> None:
        import dask
        from distributed import Client, LocalCluster

        if self.scheduler:
            from distributed.comm.addressing import parse_address, parse_host_port

            try:  # a malformed address: refused before a client exists (its clean-up would hang)
                parse_host_port(parse_address(self.scheduler)[1])
            except ValueError as error:
                raise EngineUnavailable(f"the Dask scheduler's address '{self.scheduler}' is not "
                                        f"valid: {error}") from None
            try:
                self.client = Client(self.scheduler, timeout=self.connect_timeout,
                                     set_as_default=False)
            except (OSError, TimeoutError, ValueError) as error:
                reason = str(error).splitlines()[0] if str(error) else type(error).__name__
                raise EngineUnavailable(f"cannot reach the Dask scheduler at {self.scheduler} "
                                        f"within {self.connect_timeout:g} s: {reason}") from None
            return
        os.environ.update(BLAS_ENVIRONMENT)  # inherited by the worker processes
        # the worker processes inherit an ignored SIGINT: a Ctrl-C in the terminal reaches the
        # whole process group, and only this (client) process should handle it, by closing the
        # cluster cleanly (the workers would print KeyboardInterrupt tracebacks otherwise)
        main = threading.current_thread() is threading.main_thread()
        previous = signal.signal(signal.SIGINT, signal.SIG_IGN) if main else None
        try:
            if not self.supervised:
                self.cluster = _plain_worker_cluster(self.workers)
            else:
                with dask.config.set(WORKER_CONFIG):
                    self.cluster = LocalCluster(n_workers=self.workers, threads_per_worker=1,
                                                processes=True, dashboard_address=None,
                                                scheduler_kwargs=SCHEDULER_HTTP,
                                                silence_logs=logging.CRITICAL,  # shutdown races log heartbeat errors
                                                env=dict(BLAS_ENVIRONMENT))
        finally:
            if previous is not None:
                signal.signal(signal.SIGINT, previous)
        self.client = Client(self.cluster, set_as_default=False)
        try:
            self.client.wait_for_workers(self.workers, timeout=self.worker_timeout)
        except TimeoutError:
            joined = len(self.client.scheduler_info()["workers"])
            self.close()
            raise EngineUnavailable(f"only {joined} of the local cluster's {self.workers} "
                                    f"workers joined within {self.worker_timeout:g} s") from None

    def healthy(self) -> bool:
        """Whether the engine still has its workers (a local cluster: all it started; a cluster at
        an address: at least one)."""
        if self.client is None:
            return False
        try:
            count = len(self.client.scheduler_info()["workers"])
        except (OSError, TimeoutError, KeyError):
            return False
        return count >= (1 if self.scheduler else self.workers)

    def close(self) -> None:
        if self.client is not None:
            self.client.close()
            self.client = None
        if self.cluster is not None:
            self.cluster.close()
            self.cluster = None

    def map_unordered(self, function: Callable, items: Iterable) -> Iterator[tuple[int, object]]:
        """(index of the item, result) as the tasks finish.  Leaving the iteration early (an
        exception, Ctrl-C) cancels the tasks not yet finished."""
        from distributed import as_completed

        items = list(items)
        if not items:
            return
        futures = self.client.map(partial(_call, function, niceness=self.niceness), items,
                                  pure=False)
        index = {future.key: i for i, future in enumerate(futures)}
        try:
            for future in as_completed(futures, loop=self.client.loop):
                yield index[future.key], future.result()
        finally:
            self.client.cancel([f for f in futures if not f.done()])

    def map(self, function: Callable, items: Iterable) -> list:
        """Results in the order of ``items`` (a drop-in for ``builtins.map`` that returns a list)."""
        items = list(items)
        results = [None] * len(items)
        for i, result in self.map_unordered(function, items):
            results[i] = result
        return results


# A scheduler always serves HTTP (health, metrics), by default on port 8787: when that port is
# taken (another cluster, another server on the machine) Dask warns and moves.  Ours asks for any
# free port on the loopback interface instead, so that nothing depends on 8787 being free and
# nothing listens beyond this machine.
SCHEDULER_HTTP = {"dashboard_address": "127.0.0.1:0"}

# environment of the plain worker subprocesses (inherited): one BLAS thread, quiet logs
PLAIN_WORKER_ENVIRONMENT = {**BLAS_ENVIRONMENT, "DASK_LOGGING__DISTRIBUTED": "error"}


def _plain_worker_cluster(workers: int):
    """A cluster on 127.0.0.1: the scheduler in this process, ``workers`` plain worker
    subprocesses of one thread each (they exit 60 s after losing the scheduler)."""
    from distributed import Scheduler
    from distributed.deploy.spec import SpecCluster
    from distributed.deploy.subprocess import SubprocessWorker

    os.environ.update(PLAIN_WORKER_ENVIRONMENT)  # inherited by the worker subprocesses
    worker = {"cls": SubprocessWorker,
              "options": {"worker_class": "distributed.Worker",
                          "worker_kwargs": {"nthreads": 1, "death_timeout": 60,
                                            "host": "127.0.0.1"}}}
    scheduler = {"cls": Scheduler, "options": {"host": "127.0.0.1", "port": 0, "dashboard": False,
                                               **SCHEDULER_HTTP}}
    return SpecCluster(workers={i: worker for i in range(workers)}, scheduler=scheduler,
                       worker=worker, silence_logs=logging.CRITICAL, name="bogie-local")


def serial_map_unordered(function: Callable, items: Iterable) -> Iterator[tuple[int, object]]:
    """The same interface in this process, in order (the reference of the tests)."""
    for i, item in enumerate(items):
        yield i, function(item)


def in_order(map_unordered):
    """A ``map(function, items)`` that yields the results in the order of the items, each as soon
    as it and all before it are finished (for callers that consume results in order)."""
    def map_fn(function, items):
        buffer, following = {}, 0
        for index, result in map_unordered(function, list(items)):
            buffer[index] = result
            while following in buffer:
                yield buffer.pop(following)
                following += 1
    return map_fn
