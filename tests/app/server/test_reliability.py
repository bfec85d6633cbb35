"""Reliability of the served dashboard, short versions of ``scripts/reliability_app.py``
(the long runs: 20 sessions, a 10-minute soak, 200 query strings; numbers in BENCHMARKS.md).

Through Bokeh's protocol client (the messages a browser sends, no rendering): concurrent
sessions with different design variants each see their own results; bad query strings, bad
slider values and bad uploads give notices only, the session keeps working and the server stays
alive; a short soak reports the server's memory.

The server is a ``bogie serve`` process of its own, started for this module (``own_server``):
a fresh server (not the one the other served tests have been loading with sessions and
background work), whose memory is its own.
"""

from __future__ import annotations

import importlib.util
from concurrent.futures import ThreadPoolExecutor

import pytest
from conftest import ROOT

pytestmark = pytest.mark.slow

SCRIPT = ROOT / "scripts" / "reliability_app.py"


def in_thread(function, *args, **kwargs):
    """Run Bokeh's protocol client in a thread of its own: an asyncio loop left running in this
    thread by an earlier test (Playwright's) makes bokeh.client refuse to run its own."""
    with ThreadPoolExecutor(max_workers=1) as pool:
        return pool.submit(function, *args, **kwargs).result()


@pytest.fixture(scope="module")
def reliability():
    spec = importlib.util.spec_from_file_location("reliability_app", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_concurrent_sessions_with_different_variants_see_their_own(own_server, reliability):
    result = in_thread(reliability.isolation, own_server[0], sessions=4)
    assert result["failures"] == []
    assert result["own_results"] == result["answered"] == 4
    assert result["distinct"] == 4


def test_fuzz_of_queries_values_and_uploads(own_server, reliability):
    queries = in_thread(reliability.fuzz_queries, own_server[0], count=15)
    assert queries["statuses"] == {200: 15}, queries["failures"]
    assert queries["alive_after"]
    session = in_thread(reliability.fuzz_session, own_server[0])
    assert session["bad_inputs_sent"] > 10
    assert session["session_still_working"]
    assert session["alive_after"]


def test_short_soak_memory(own_server, reliability):
    """A control changed every second for 20 s (the 10-minute run is the script's), over eight
    operating points (four creepages on the slider's page steps, two speeds) that a warm pass
    has computed first, waiting 3 s at each for the slower stages.  Every answer is then in a
    cache, so the server's memory has no reason to grow: the bound, 50 MB, is what a leak of
    one short-circuit history per change (2.7 MB, 20 changes) would exceed; measured here the
    growth is about 1 MB.  From cold, the first minute fills the caches by several hundred MB
    (bounded by their max_items; the boundary soak and the 10-minute run measure that)."""
    result = in_thread(reliability.soak, own_server[0], own_server[1], minutes=20 / 60,
                       sample_every=5.0, s0_values=[0.004, 0.0045, 0.005, 0.0055],
                       speeds_kmh=[120.0, 140.0], warm=3.0)
    assert result["changes"] >= 10
    assert result["timeouts"] == 0
    growth = result["rss_end_mb"] - result["samples"][0][1]
    assert growth < 50, result["samples"]


def test_a_bounded_results_cache_bounds_the_servers_memory(tmp_path, reliability):
    """``bogie serve --cache-mb 100``: after six operating points, eighteen more distinct ones —
    more than the budget holds beside the model (docs/results/memory.json) — each with its root
    locus, s0*(v) and verdict: the server's memory grows by less than the budget (without a
    bound it grew by about 5.5 MB a point; docs/memory.md)."""
    import json

    from conftest import start_bogie_serve, stop_process

    budget = 100
    url, process = start_bogie_serve(tmp_path, "--cache-mb", str(budget))
    try:
        result = in_thread(reliability.distinct_points, url, process.pid, base_points=6,
                           points=18, settle=2.0)
    finally:
        stop_process(process)
    memory = json.loads((ROOT / "docs" / "results" / "memory.json").read_text(encoding="utf-8"))
    held = (budget - memory["model_mb"]) / memory["linear_point_mb"]  # points beside the model
    assert result["base_points"] + result["points"] > held
    assert result["timeouts"] == 0
    assert result["growth_mb"] < budget, result["samples_mb"]


def test_sigterm_stops_the_server_at_once(tmp_path):
    """``docker stop`` sends SIGTERM: the server ends within seconds, with exit status 0 and a
    line in its log, also while a session's computations run (a KeyboardInterrupt raised by the
    old handler was once swallowed by a weakref callback, and the server ran on until killed)."""
    import signal
    import time
    import urllib.request

    from conftest import start_bogie_serve, stop_process

    url, process = start_bogie_serve(tmp_path)
    try:
        with urllib.request.urlopen(f"{url}/app?v=185", timeout=120) as page:  # a new session
            assert page.status == 200
        start = time.monotonic()
        process.send_signal(signal.SIGTERM)
        assert process.wait(timeout=20) == 0
        assert time.monotonic() - start < 10
        assert "bogie serve: stopped" in (tmp_path / "serve.log").read_text()
    finally:
        stop_process(process, timeout=0)
