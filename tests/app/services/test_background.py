"""The background workers (app.services.background): the work runs in other processes at a lower
priority, answers and errors come back, a task no longer wanted stops at its next checkpoint, a
worker that dies is replaced; without workers the function runs in the calling thread, its stop
seen at the same checkpoints."""

from __future__ import annotations

import os
import threading
import time
from pathlib import Path

import pytest

from app.services import background

pytestmark = pytest.mark.slow  # worker processes start (about a second each)


def whoami() -> tuple[int, int]:
    """(process id, niceness) of the process that runs it."""
    return os.getpid(), os.nice(0)


def fail(message: str) -> None:
    raise ValueError(message)


def count_checkpoints(limit: float) -> int:
    """Call the checkpoint every 10 ms for at most ``limit`` seconds; how many times it passed."""
    passed = 0
    deadline = time.monotonic() + limit
    while time.monotonic() < deadline:
        background.checkpoint()
        passed += 1
        time.sleep(0.01)
    return passed


def die() -> None:
    os._exit(3)


class NoLongerWanted(Exception):
    pass


@pytest.fixture(scope="module")
def workers():
    local = background.LocalWorkers(2)
    local.start()
    yield local
    local.close()


def test_the_work_runs_in_other_processes_at_a_lower_priority(workers):
    pids = {workers.run(whoami, (), None) for _ in range(6)}
    assert all(pid != os.getpid() for pid, _ in pids)
    assert {nice for _, nice in pids} == {os.nice(0) + background.NICENESS}
    assert {pid for pid, _ in pids} <= set(workers.pids())
    with pytest.raises(ValueError, match="the model says no"):
        workers.run(fail, ("the model says no",), None)


def test_a_task_no_longer_wanted_stops_and_frees_its_worker(workers):
    asked = {"n": 0}

    def stop():
        asked["n"] += 1
        if asked["n"] > 3:  # wanted for about 0.3 s
            raise NoLongerWanted

    start = time.monotonic()
    with pytest.raises(NoLongerWanted):
        workers.run(count_checkpoints, (30.0,), stop)
    assert time.monotonic() - start < 5.0
    # the stopped task has ended: its worker takes the next task at once
    start = time.monotonic()
    assert workers.run(count_checkpoints, (0.05,), None) >= 1
    assert time.monotonic() - start < 5.0


def test_a_worker_that_dies_is_replaced(workers):
    before = set(workers.pids())
    with pytest.raises(background.BrokenProcessPool):
        workers.run(die, (), None)  # dies twice: the second attempt's error reaches the caller
    pid, _ = workers.run(whoami, (), None)
    assert pid not in before


def test_without_workers_the_calling_thread_runs_it_and_sees_the_stop():
    assert background.current() is None
    assert background.run(whoami) == (os.getpid(), os.nice(0))

    def stop():
        raise NoLongerWanted

    with pytest.raises(NoLongerWanted):
        background.run(count_checkpoints, 5.0, stop=stop)


def _states(pids: list[int]) -> set[str]:
    """The processes' scheduling states (R running, S sleeping, T stopped …: /proc/PID/stat)."""
    return {Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] for pid in pids}


def _paused(pids: list[int], paused: bool, within: float = 5.0) -> bool:
    """Whether every one of ``pids`` is stopped (``paused``) or none is, within ``within`` s (a
    signal is delivered a moment after ``kill`` returns)."""
    deadline = time.monotonic() + within
    while True:
        states = _states(pids)
        if (states == {"T"}) if paused else ("T" not in states):
            return True
        if time.monotonic() > deadline:
            return False
        time.sleep(0.005)


def test_the_workers_pause_while_a_first_answer_runs(workers):
    """held(f): the local workers are stopped (SIGSTOP) while f runs, nested or side by side,
    and go on (SIGCONT) when the last one ends; a task handed to them meanwhile is answered
    after that; an error inside f leaves them going on."""
    pids = workers.pids()
    previous = background.configure(workers)
    try:
        seen = {}

        def inner():
            seen["inner"] = _paused(pids, True)

        def outer():
            seen["before"] = _paused(pids, True)
            background.held(inner)()
            seen["after inner"] = _paused(pids, True, within=0.0)  # the outer one still runs
            return "answer"

        assert background.held(outer)() == "answer"
        assert seen == {"before": True, "inner": True, "after inner": True}
        assert _paused(pids, False)
        # a task given to the paused workers ends once they go on
        result = {}

        def ask():
            result["pid"] = background.run(whoami)[0]

        def first_answer():
            asking = threading.Thread(target=ask)
            asking.start()
            asking.join(timeout=1.0)
            result["during"] = "pid" in result
            return asking

        asking = background.held(first_answer)()
        asking.join(timeout=30.0)
        assert result["during"] is False
        assert result["pid"] in pids
        with pytest.raises(ValueError, match="refused"):
            background.held(fail)("refused")
        assert _paused(pids, False)
    finally:
        background.configure(previous)
