"""``bogie serve``: run the dashboard with ``panel serve`` semantics (liveness endpoint on).

Each browser session gets a fresh :class:`app.dashboard.dashboard.BogieDashboard`.  Sessions share the
read-only results cache of :mod:`app.results.cache` (bounded in bytes: ``--cache-mb``), the worker
threads of :mod:`app.services.thread_pools` and the study queue of :mod:`app.services.study_queue`,
whose engine, folder and limits are the operator's settings (:mod:`app.services.settings`,
docs/security.md; the memory: docs/memory.md).
"""

from __future__ import annotations

import os
import threading

from app.services.thread_pools import limit_blas_threads

TITLE = "Bogie drive dynamics"


def create_app(params: str | None = None):
    """Build the dashboard for one session: ``params`` is a parameter file (TOML) or ``None``
    for the calibrated default set."""
    import panel as pn
    from panel.io.resources import get_dist_path

    from app.dashboard.dashboard import BogieDashboard

    doc = pn.state.curdoc
    if doc is not None:
        # the address of Panel's own static files, before any pane is made: Panel sets it only
        # when it renders a browser's page, so the documents built without a page (the liveness
        # probe's, a protocol client's) took Panel's CDN for the stylesheet objects, which the
        # sessions of a server share (a browser page then asked the CDN for loading.css: seen
        # with protocol clients beside a page, and possible with a container's health check)
        doc._template_variables.setdefault("dist_url", get_dist_path())
    dashboard = BogieDashboard(base_key=params)
    header = pn.pane.Markdown(
        f"## {TITLE} — stability and short-circuit load of the wheelset drives\n"
        "Move the sliders (left): the status, root locus, creep characteristic and the torque "
        "time histories follow. Units: SI unless a label says otherwise; Im λ in Hz.",
        sizing_mode="stretch_width")
    return pn.Column(header, dashboard, sizing_mode="stretch_width")


def serve(port: int = 5006, address: str = "127.0.0.1",
          allow_websocket_origin: list[str] | None = None, params: str | None = None,
          settings=None) -> None:
    """Serve the dashboard at /app (and Panel's /liveness?endpoint=/app) until SIGINT/SIGTERM.

    Websocket origins: ``allow_websocket_origin``, else the comma-separated host[:port] list in
    the environment variable BOGIE_ALLOWED_ORIGINS, else localhost:port and 127.0.0.1:port only.
    ``settings``: the operator's :class:`app.services.settings.ServerSettings` (default: from the
    environment); the studies folder is created here (raises SettingsError if it cannot be).
    """
    import faulthandler
    import signal

    import panel as pn

    from app.results import cache
    from app.services.settings import ServerSettings, SettingsError, configure
    from app.services.study_queue import StudyQueue, replace_study_queue

    settings = settings or ServerSettings.from_options()
    try:
        settings.studies_dir.mkdir(parents=True, exist_ok=True)
        if not os.access(settings.studies_dir, os.W_OK | os.X_OK):
            raise PermissionError("not writable")
    except OSError as error:
        raise SettingsError(f"--studies-dir {settings.studies_dir}: cannot be used "
                            f"({error.strerror or error})") from None
    configure(settings)
    if settings.cache_mb is not None:
        cache.configure(settings.cache_mb)
    replace_study_queue(StudyQueue(settings))
    start_background_workers(settings)

    # a fatal error in native code (SIGSEGV, SIGABRT...) leaves the Python stack of every thread
    # in the server's log instead of one line from the C library
    faulthandler.enable(all_threads=True)
    limit_malloc_arenas()
    limit_blas_threads()
    port = int(port)  # the command line parses it as a number (float)
    origins = allow_websocket_origin or os.environ.get(
        "BOGIE_ALLOWED_ORIGINS", f"localhost:{port},127.0.0.1:{port}").split(",")
    if threading.current_thread() is threading.main_thread():
        # SIGTERM (a container stops its PID 1 with it; Python would otherwise ignore it there)
        # stops the server from the signal handler itself.  Raising KeyboardInterrupt there
        # instead was lost once in a test run: the signal arrived while the main thread ran a
        # weakref callback, which swallows exceptions ("Exception ignored in … remove"), and the
        # server went on running until it was killed 30 s later.  Ctrl-C: Panel's own handler
        # stops the IO loop, and pn.serve returns
        signal.signal(signal.SIGTERM, _stop_now)
    print(f"bogie serve: dashboard on http://{address}:{port}/app "
          f"(liveness: /liveness?endpoint=/app); studies in {settings.studies_dir} on "
          f"{settings.scheduler or 'a local cluster (started on the first study)'}, at most "
          f"{settings.max_study_points} points, {settings.max_running_studies} running, "
          f"{settings.max_waiting_studies} waiting; results cache "
          f"{cache.RESULTS.budget // cache.MB} MB; background work (verdicts, reaction times) on "
          f"{_background_description()}", flush=True)
    try:
        pn.serve({"app": lambda: create_app(params)}, port=port, address=address,
                 websocket_origin=[o.strip() for o in origins if o.strip()], show=False,
                 liveness=True, title=TITLE)
    except KeyboardInterrupt:  # Ctrl-C before Panel's handler was in place
        pass
    _stop_now()


def start_background_workers(settings) -> None:
    """The worker processes of the work no slider waits for (:mod:`app.services.background`):
    the operator's cluster with ``--scheduler``, else ``--background-workers`` local processes
    (started now, beside the server's start; 0: the server's own threads)."""
    from functools import partial

    from app.results import cache
    from app.services import background

    if settings.background_workers == 0:
        workers = None
    elif settings.scheduler:
        workers = background.ClusterWorkers(settings.scheduler)
    else:
        workers = background.LocalWorkers(
            settings.background_workers,
            setup=partial(cache.configure, background.WORKER_CACHE_MB))
    previous = background.configure(workers)
    if previous is not None:
        previous.close()
    if workers is not None:
        threading.Thread(target=_start_quietly, args=(workers,), name="bogie-background-start",
                         daemon=True).start()


def _background_description() -> str:
    from app.services import background

    workers = background.current()
    return "the server's own threads" if workers is None else workers.description


def _start_quietly(workers) -> None:
    try:
        workers.start()
    except Exception as error:  # the first task starts them again and its view says why
        print(f"bogie serve: the background workers did not start: {error}", flush=True)


MALLOC_ARENAS = 2  # glibc malloc arenas of the server process (MALLOC_ARENA_MAX wins)


def limit_malloc_arenas(arenas: int = MALLOC_ARENAS) -> None:
    """At most ``arenas`` glibc malloc arenas in this process, set before the worker threads
    start, unless the environment sets ``MALLOC_ARENA_MAX``.  glibc gives each thread that
    allocates under contention an arena of its own (up to 8 per core); the server's dozen
    worker threads each kept freed result memory in theirs: 30 distinct points after the first
    six grew the server by 209–221 MB with a 100 MB results cache, 82 MB with two arenas
    (docs/memory.md, BENCHMARKS.md).  Nothing on another C library."""
    import ctypes
    import ctypes.util

    if os.environ.get("MALLOC_ARENA_MAX"):
        return
    name = ctypes.util.find_library("c")
    try:
        libc = ctypes.CDLL(name)
        mallopt = libc.mallopt
    except (OSError, AttributeError, TypeError):  # not glibc
        return
    M_ARENA_MAX = -8
    mallopt(M_ARENA_MAX, int(arenas))


def _stop_now(*_signal) -> None:
    """Stop the server process at once.  Nothing to save: the computations queued or running for
    sessions that are gone are dropped (``os._exit``: Python would otherwise join every worker
    thread at exit, and a reaction-time search at the lowest priority can run for a minute).
    The study engine's worker processes are stopped first (a study's store keeps its finished
    chunks).  Called from the signal handler: the message may wait for another thread's write to
    stderr (that thread goes on and releases it); one interrupted in this thread is skipped."""
    import sys

    _close_studies()
    from app.services import background

    workers = background.configure(None)
    if workers is not None:
        workers.close()

    try:
        print("bogie serve: stopped", file=sys.stderr, flush=True)
        sys.stdout.flush()
    except (OSError, RuntimeError, ValueError):  # a closed or busy stream: stop anyway
        pass
    os._exit(0)


def _close_studies(timeout: float = 10.0) -> None:
    """Stop the studies and the local cluster's worker processes, waiting at most ``timeout`` s
    (they must not outlive the server: nothing else would stop them)."""
    from app.services.study_queue import replace_study_queue

    queue = replace_study_queue(None)
    if queue is None:
        return
    closer = threading.Thread(target=queue.close, name="bogie-close-studies", daemon=True)
    closer.start()
    closer.join(timeout)
