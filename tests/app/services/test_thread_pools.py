"""app.services.thread_pools.LatestRequest: at most one waiting request per session and kind on a shared pool;
a newer request replaces one that has not started; a closed session's request is not run."""

from __future__ import annotations

import threading
from concurrent.futures import ThreadPoolExecutor

from app.services.thread_pools import LatestRequest


def test_a_newer_request_replaces_the_waiting_one_and_the_queue_stays_short():
    pool = ThreadPoolExecutor(max_workers=1)
    gate, started = threading.Event(), threading.Event()

    def block():
        started.set()
        gate.wait(30)
        return "first"

    try:
        blocker = pool.submit(block)
        started.wait(30)
        requests = LatestRequest(pool)
        futures = [requests.submit(lambda i=i: i) for i in range(1000)]
        assert pool._work_queue.qsize() == 1  # one entry for all 1000 requests
        gate.set()
        assert blocker.result(30) == "first"
        assert futures[-1].result(30) == 999
        assert all(f.cancelled() for f in futures[:-1])
    finally:
        gate.set()
        pool.shutdown(wait=True)


def test_a_closed_sessions_request_is_not_run():
    pool = ThreadPoolExecutor(max_workers=1)
    gate, started = threading.Event(), threading.Event()
    alive = [True]
    ran = []

    def block():
        started.set()
        gate.wait(30)

    try:
        pool.submit(block)
        started.wait(30)
        future = LatestRequest(pool, alive=lambda: alive[0]).submit(ran.append, 1)
        alive[0] = False  # the session ends while the request waits
        gate.set()
        pool.shutdown(wait=True)
        assert future.cancelled()
        assert ran == []
    finally:
        gate.set()


def test_errors_reach_the_future():
    with ThreadPoolExecutor(max_workers=1) as pool:
        future = LatestRequest(pool).submit(lambda: 1 / 0)
        assert isinstance(future.exception(30), ZeroDivisionError)
