"""The server's study queue: every session's studies on one engine, at most K at a time.

One :class:`StudyQueue` per server process (:func:`study_queue`).  It runs the studies a
session may ask for — stability maps (:class:`model.studies.maps.MapStudy`, the Studies tab) and
design-load envelopes (:class:`model.studies.envelope.EnvelopeStudy`, the Design loads tab) —
under the same rules, and owns the study engine the operator chose
(:mod:`app.services.settings`): a client of the operator's Dask scheduler, or **one** local
cluster of worker processes (one per core), started on the first study and shared by all
sessions.  A session *asks* for a study (:meth:`StudyQueue.submit`); the queue decides when it
runs:

* at most ``max_running_studies`` run at once; the others wait in order of arrival, each session
  sees its position; at most ``max_waiting_studies`` wait (more are refused with a notice);
* a session has at most one study waiting or running (another request is refused);
* a session stops only its own study (it holds its ticket; the owner is checked too): a waiting
  one leaves the queue, a running one stops after the chunk in progress (the store keeps the
  finished chunks);
* a closed session's waiting study is dropped and its running one stops after its chunk
  (:meth:`StudyQueue.drop_owner`, called when Bokeh destroys the session).

Nothing here comes from a browser but the study's grid (bounded by ``max_study_points``: the
s0 × v points of a map, the scenarios of an envelope) and the dashboard's parameter set; the
store's name is the queue's own (:mod:`app.services.studies_folder`).
"""

from __future__ import annotations

import logging
import threading
import time
from collections import deque
from dataclasses import dataclass, field

from app.services.settings import ServerSettings, current, local_workers
from app.services.studies_folder import StudiesFolder

log = logging.getLogger(__name__)

WAITING, RUNNING, DONE, STOPPED, FAILED, DROPPED = (
    "waiting", "running", "done", "stopped", "failed", "dropped")
ENDED = (DONE, STOPPED, FAILED, DROPPED)
STUDY_NICENESS = 10  # the local cluster's workers: the sessions' first answers come first


class StudyRefused(ValueError):
    """A study request the server's limits do not admit (message shown to the reviewer)."""


class _Stop(Exception):
    """Raised in a study's progress callback: its owner stopped it or left."""


@dataclass
class StudyTicket:
    """One requested study and what became of it (read by the session's view)."""

    owner: str  # the asking session's token
    study: object  # model.studies.maps.MapStudy or model.studies.envelope.EnvelopeStudy
    parameters: object  # model.parameters.Parameters
    name: str  # store name in the studies folder
    state: str = WAITING
    finished: int = 0  # chunks written
    total: int = 0  # chunks of the study
    elapsed: float = 0.0  # seconds since the run started
    message: str = ""  # why it failed (one line, no server path)
    stop_requested: threading.Event = field(default_factory=threading.Event)
    ended: threading.Event = field(default_factory=threading.Event)

    @property
    def points(self) -> int:
        """The study's size as the limit counts it (:func:`study_points`)."""
        return study_points(self.study)


STUDY_KINDS = {"map": ("map", "points (s0 points × v points)"),
               "envelope": ("envelope", "scenarios (grid points × fault instants)")}


def study_points(study) -> int:
    """What ``max_study_points`` counts: the s0 × v × N0 × b_M points of a map, the scenarios of
    an envelope (every fault instant and anti-slip setting counted)."""
    if study.kind == "envelope":
        return int(study.scenarios)
    return int(len(study.s0) * len(study.v) * len(study.N0) * len(study.b_M))


class StudyQueue:
    """The process's studies: a FIFO queue in front of at most K running studies."""

    def __init__(self, settings: ServerSettings, engine_factory=None):
        """``engine_factory()``: an object with ``start()``, ``close()`` and ``map_unordered``
        (default: :class:`model.studies.engine.StudyEngine` of the settings; tests pass one that
        runs in this process)."""
        self.settings = settings
        self.folder = StudiesFolder(settings.studies_dir)
        self._engine_factory = engine_factory or self._default_engine
        self._engine = None
        self._engine_lock = threading.Lock()
        self._lock = threading.Lock()
        self._waiting: deque[StudyTicket] = deque()
        self._running: list[StudyTicket] = []
        self._by_owner: dict[str, StudyTicket] = {}

    # --- the engine ----------------------------------------------------------------------------

    def _default_engine(self):
        from model.studies.engine import StudyEngine

        return StudyEngine(self.settings.scheduler, workers=local_workers(),
                           use_environment=False, supervised=False,
                           niceness=0 if self.settings.scheduler else STUDY_NICENESS)

    def engine(self):
        """The shared engine, started on first use and again when it has lost workers (raises
        what starting it raises)."""
        with self._engine_lock:
            if self._engine is not None and not _healthy(self._engine):
                log.warning("the study engine lost workers: starting a new one")
                self._engine.close()
                self._engine = None
            if self._engine is None:
                engine = self._engine_factory()
                engine.start()
                self._engine = engine
            return self._engine

    def _engine_failed(self, engine) -> None:
        """Forget an engine a study could not use (the next study starts a new one)."""
        with self._engine_lock:
            if self._engine is engine:
                self._engine = None
        try:
            engine.close()
        except Exception:  # already broken: nothing more to release
            log.debug("closing a failed study engine", exc_info=True)

    def close(self) -> None:
        """Stop every study and the engine (the server stops)."""
        with self._lock:
            for ticket in self._running:
                ticket.stop_requested.set()
            while self._waiting:
                self._end(self._waiting.popleft(), DROPPED)
        with self._engine_lock:
            engine, self._engine = self._engine, None
        if engine is not None:
            engine.close()

    # --- requests ------------------------------------------------------------------------------

    def submit(self, owner: str, study, parameters, prefix: str | None = None) -> StudyTicket:
        """Queue ``study`` (a map or an envelope) for the session ``owner``; its store gets a
        name of the folder starting with ``prefix`` (default: the study's kind).  Raises
        :class:`StudyRefused`."""
        if study.kind not in STUDY_KINDS:
            raise StudyRefused(f"the server runs map and envelope studies, not '{study.kind}'")
        kind, counted = STUDY_KINDS[study.kind]
        points = study_points(study)
        limit = self.settings.max_study_points
        if points > limit:
            unit = counted.split(" ", 1)[0]
            raise StudyRefused(f"{points} {unit} asked; the server runs studies of at most "
                               f"{limit} {counted}")
        with self._lock:
            previous = self._by_owner.get(owner)
            if previous is not None and previous.state in (WAITING, RUNNING):
                raise StudyRefused(f"this session's {previous.study.kind} study is still "
                                   f"{previous.state}: stop it or wait for it (a session runs "
                                   "one study at a time)")
            if len(self._waiting) >= self.settings.max_waiting_studies and (
                    len(self._running) >= self.settings.max_running_studies):
                raise StudyRefused(f"the server's study queue is full "
                                   f"({len(self._waiting)} waiting); try again later")
            ticket = StudyTicket(owner, study, parameters,
                                 self.folder.new_name(kind, prefix or study.kind),
                                 total=len(study.chunks()))
            self._by_owner[owner] = ticket
            self._waiting.append(ticket)
            self._dispatch()
        return ticket

    def position(self, ticket: StudyTicket) -> int | None:
        """Studies ahead of a waiting ticket (0: it runs next), None when it is not waiting."""
        with self._lock:
            try:
                return self._waiting.index(ticket)
            except ValueError:
                return None

    def status_line(self, ticket: StudyTicket, unit: str) -> tuple[str, bool]:
        """(the line a session shows for its ``ticket``, whether the ticket has ended), read in
        one snapshot of the queue, so that the server's counts in it never disagree with each
        other (``unit``: what a chunk is, e.g. "s0-lines")."""
        with self._lock:
            state, ended = ticket.state, ticket.ended.is_set()
            finished, total, elapsed = ticket.finished, ticket.total, ticket.elapsed
            running, waiting = len(self._running), len(self._waiting)
            ahead = self._waiting.index(ticket) if state == WAITING else None
        limit = self.settings.max_running_studies
        if ended:
            return f"{state}: {finished}/{total} {unit} in {elapsed:.1f} s", True
        if state == WAITING:
            return (f"waiting: {ahead} stud{'y' if ahead == 1 else 'ies'} ahead in the queue, "
                    f"{running} running"), False
        left = ""
        if 0 < finished < total:
            left = f", ~{elapsed / finished * (total - finished):.0f} s left"
        return (f"running: {finished}/{total} {unit}, {elapsed:.0f} s{left}; server: {running} "
                f"of at most {limit} running, {waiting} waiting"), False

    def counts(self) -> tuple[int, int]:
        """(running, waiting) studies of the server."""
        with self._lock:
            return len(self._running), len(self._waiting)

    def stop(self, ticket: StudyTicket, owner: str) -> bool:
        """Stop ``owner``'s ``ticket``: a waiting one leaves the queue, a running one stops after
        its chunk.  False (nothing done) for another session's ticket or an ended one."""
        with self._lock:
            if ticket.owner != owner or self._by_owner.get(owner) is not ticket:
                return False
            if ticket.state == WAITING:
                self._waiting.remove(ticket)
                self._end(ticket, STOPPED)
                return True
            if ticket.state == RUNNING:
                ticket.stop_requested.set()
                return True
            return False

    def drop_owner(self, owner: str) -> None:
        """The session ``owner`` has closed: its waiting study is dropped, its running one stops
        after its chunk."""
        with self._lock:
            ticket = self._by_owner.pop(owner, None)
            if ticket is None:
                return
            if ticket.state == WAITING:
                self._waiting.remove(ticket)
                self._end(ticket, DROPPED)
            elif ticket.state == RUNNING:
                ticket.stop_requested.set()

    # --- running -------------------------------------------------------------------------------

    def _dispatch(self) -> None:
        """Start waiting studies while fewer than K run (called with the lock held)."""
        while self._waiting and len(self._running) < self.settings.max_running_studies:
            ticket = self._waiting.popleft()
            ticket.state = RUNNING
            self._running.append(ticket)
            threading.Thread(target=self._run, args=(ticket,), name="bogie-study",
                             daemon=True).start()

    @staticmethod
    def _end(ticket: StudyTicket, state: str, message: str = "") -> None:
        ticket.state, ticket.message = state, message
        ticket.ended.set()

    def _run(self, ticket: StudyTicket) -> None:
        from model.studies.store import run_into_store

        def progress(finished: int, total: int, elapsed: float) -> None:
            ticket.finished, ticket.total, ticket.elapsed = finished, total, elapsed
            if ticket.stop_requested.is_set():
                raise _Stop

        state, message, engine = FAILED, "", None
        try:
            if ticket.stop_requested.is_set():
                raise _Stop
            try:
                engine = self.engine()
            except Exception as error:
                log.error("the study engine could not be started: %s", error)
                raise RuntimeError("the server's study engine is not available (the server's "
                                   "log says why)") from None
            path = self.folder.ensure() / ticket.name
            run_into_store(ticket.study, ticket.parameters, path, engine.map_unordered,
                           progress=progress)
            state = DONE
        except _Stop:
            state = STOPPED
        except Exception as error:  # the reviewer sees one line; the log has the details
            log.error("study %s failed", ticket.name, exc_info=error)
            message = _one_line(error)
            if engine is not None and _engine_broken(error):
                self._engine_failed(engine)
        finally:
            with self._lock:
                self._running.remove(ticket)
                self._end(ticket, state, message)
                self._dispatch()


def _healthy(engine) -> bool:
    healthy = getattr(engine, "healthy", None)
    return healthy() if healthy is not None else True


def _one_line(error: Exception) -> str:
    """A failure as the reviewer sees it: its first line, server paths and addresses cut."""
    text = str(error).splitlines()[0] if str(error) else type(error).__name__
    if "/" in text or "tcp:" in text:
        return f"{type(error).__name__} (details in the server's log)"
    return text


def _engine_broken(error: Exception) -> bool:
    """Whether a failure says that the engine (not the study) is broken."""
    return isinstance(error, OSError | TimeoutError) or type(error).__module__.startswith(
        ("distributed", "tornado"))


_QUEUE: StudyQueue | None = None
_QUEUE_LOCK = threading.Lock()


def study_queue() -> StudyQueue:
    """The process's study queue (made of :func:`app.services.settings.current` on first use)."""
    global _QUEUE
    with _QUEUE_LOCK:
        if _QUEUE is None:
            _QUEUE = StudyQueue(current())
        return _QUEUE


def replace_study_queue(queue: StudyQueue | None) -> StudyQueue | None:
    """Install ``queue`` as the process's (tests; ``bogie serve`` with its settings); returns the
    previous one (not closed)."""
    global _QUEUE
    with _QUEUE_LOCK:
        previous, _QUEUE = _QUEUE, queue
    return previous


def wait_until_ended(ticket: StudyTicket, timeout: float | None = None) -> bool:
    """Wait for a ticket to end (tests, scripts); whether it did within ``timeout`` [s]."""
    deadline = None if timeout is None else time.monotonic() + timeout
    while not ticket.ended.wait(0.1):
        if deadline is not None and time.monotonic() > deadline:
            return False
    return True
