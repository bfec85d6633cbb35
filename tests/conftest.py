"""Shared fixtures: a dashboard server inside pytest and headless Chromium (Debian's).

* ``app_server``: ``pn.serve`` on a free port in a thread (Panel's own test-helper trick to read
  the port back); yields the base URL; waits for ``/liveness?endpoint=/app`` (which builds the
  app) before the tests run.
* ``chromium``: Playwright for Python driving ``/usr/bin/chromium`` (never a downloaded browser:
  ``playwright install`` does not work on these machines); skipped if it is missing.
* ``open_app(page, url)``: load the app and wait until Bokeh has rendered its canvases; the
  console errors and page errors of the page are collected in ``page.errors``.
"""

from __future__ import annotations

import os

# One BLAS thread per process: on a busy 2-core machine OpenBLAS's own threads made one
# eigen-analysis 30-90x slower (measured 0.2 s vs 9-18 s).  Set before numpy is imported.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import time
import urllib.error
import urllib.request
import uuid
from pathlib import Path

import pytest

CHROMIUM = Path("/usr/bin/chromium")
ROOT = Path(__file__).resolve().parent.parent  # the project


def bogie_parsers() -> list[tuple[list[str], object]]:
    """(words, parser) of ``bogie``'s parser and of each of its sub-commands' (``[]`` the top
    one, ``["study", "map"]`` …), parents before their sub-commands: the one walk of the command
    line that the tests of its options and of the pages' option names share."""
    import argparse

    from app.cli.main import build_parser

    def walk(words, parser):
        yield words, parser
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, sub in action.choices.items():
                    yield from walk([*words, name], sub)

    return list(walk([], build_parser()))


@pytest.fixture(scope="session", autouse=True)
def _one_blas_thread():
    """Dense 386 x 386 eigenproblems run fastest on one BLAS thread, and OpenBLAS threads that
    busy-wait against another process on the same cores slow an eigen-analysis from ~0.1 s to
    ~9 s (measured on the 2-core machine).  The environment variable above covers a numpy that
    is imported after this file; threadpoolctl also covers one imported before."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(1):
        yield


# --- running in parallel (pytest-xdist: ``pytest -n auto``, as ``bash run.sh test`` runs it) -------------
#
# A work unit goes to one worker as a whole.  Tests that share something expensive built once per
# worker run in one unit: every test of a module that serves the dashboard or drives a browser
# (one server in this process, one Chromium, the attacks on a ``bogie serve`` process of their own
# whose cluster workers must not meet another server's), the image build, the Dask cluster of the
# engine tests.  The reliability runs on a fresh ``bogie serve`` of their own (no browser, no
# timing bound: their waits are minutes) are a unit apart, started right after the served unit,
# so that they run on the other core beside its browser tests (the file order puts those first),
# not beside the attacks' timing of a slider answer.  The other
# test modules go as one unit each (their module fixtures are built once), but for the few whose
# tests are long and share nothing costly: those go test by test, so that both cores work on them.
# The units are named from the test's id alone (``work_unit``): the scheduler sees nothing else.
SERVED_FIXTURES = {"app_server", "chromium", "own_server"}
SERVED_MODULES = {
    "tests/app/server/test_boundary.py",
    "tests/app/dashboard/test_dashboard.py",
    "tests/app/dashboard/test_dashboard_browser.py",
    "tests/app/dashboard/test_design_loads_browser.py",
    "tests/app/dashboard/test_drag_preview_browser.py",
    "tests/app/dashboard/test_nonlinear_view_browser.py",
    "tests/app/dashboard/test_resonance_browser.py",
    "tests/app/dashboard/test_review_browser.py",
    "tests/app/dashboard/test_uncertainty_band_browser.py",
    "tests/app/dashboard/test_verdicts_browser.py",
    "tests/app/dashboard/test_verdicts_life_browser.py",
    "tests/app/dashboard/test_tables_browser.py",
}
OWN_SERVER_MODULES = {"tests/app/server/test_reliability.py"}
GROUPS = {
    **dict.fromkeys(SERVED_MODULES, "served"),
    **dict.fromkeys(OWN_SERVER_MODULES, "own-server"),
    "tests/image/test_docker_image.py": "image",
    "tests/model/studies/test_engine.py": "dask-cluster",
}
TEST_BY_TEST = {
    "tests/model/analysis/test_response_model.py",
    "tests/model/analysis/test_sensitivity.py",
    "tests/model/analysis/test_continuation.py",
    "tests/model/studies/test_s0_line.py",
    "tests/app/cli/test_cli_antislip.py",
    "tests/test_benchmark_scripts.py",
}
FIRST = ("image", "served", "own-server", "dask-cluster")  # the longest units start first


def work_unit(nodeid: str) -> str:
    """The work unit of a test, from its id: a group's name, the test's own id, or its module."""
    module = nodeid.split("::", 1)[0]
    if module in GROUPS:
        return GROUPS[module]
    return nodeid if module in TEST_BY_TEST else module


@pytest.hookimpl(optionalhook=True)  # a hook of pytest-xdist: unknown without it (-p no:xdist)
def pytest_xdist_make_scheduler(config, log):
    """Whole work units to a worker (xdist's scope scheduling, with our units as scopes)."""
    from xdist.scheduler import LoadScopeScheduling

    class WorkUnitScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return work_unit(nodeid)

    return WorkUnitScheduling(config, log)


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config, items):
    """Order the collection so that the longest work units come first (the scheduler hands them
    out in this order): the image build (mostly waiting for downloads) and the served tests
    start at once beside the rest, and no core idles at the end waiting for one of them.  Within
    a unit and a module the order is the file's (module fixtures are built once).  A test that
    serves the app or drives a browser outside the served modules is refused: it would start a
    second server or browser beside the first."""
    strays = sorted({item.nodeid.split("::", 1)[0] for item in items
                     if SERVED_FIXTURES & set(item.fixturenames)}
                    - SERVED_MODULES - OWN_SERVER_MODULES)
    if strays:
        raise pytest.UsageError(f"tests/conftest.py: add {', '.join(strays)} to SERVED_MODULES "
                                "(it serves the app or drives a browser)")

    def rank(item) -> int:
        unit = work_unit(item.nodeid)
        if unit in FIRST:
            return FIRST.index(unit)
        return len(FIRST) + (0 if item.get_closest_marker("slow") else 1)

    units: dict[str, tuple[int, int]] = {}  # unit -> (best rank of its tests, first position)
    for position, item in enumerate(items):
        unit = work_unit(item.nodeid)
        best, first = units.get(unit, (rank(item), position))
        units[unit] = (min(best, rank(item)), first)
    order = {id(item): (*units[work_unit(item.nodeid)], position)
             for position, item in enumerate(items)}
    items.sort(key=lambda item: order[id(item)])


CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update",
                 "--disable-sync"]


def wait_for_liveness(base_url: str, timeout: float = 120.0) -> None:
    """Poll the liveness endpoint (it builds the app: 200 only if that succeeds)."""
    deadline = time.monotonic() + timeout
    last = None
    while time.monotonic() < deadline:
        try:
            with urllib.request.urlopen(f"{base_url}/liveness?endpoint=/app", timeout=60) as r:
                if r.status == 200:
                    return
        except (urllib.error.URLError, ConnectionError, TimeoutError) as error:
            last = error
        time.sleep(0.3)
    raise RuntimeError(f"dashboard not live at {base_url} after {timeout} s: {last}")


@pytest.fixture(scope="session")
def app_server():
    """Base URL of the dashboard served in this process (``/app``, ``/liveness``)."""
    import panel as pn
    from panel.io.state import state

    from app.server.serve import create_app
    from app.services.thread_pools import limit_blas_threads

    limit_blas_threads()
    server_id = f"bogie-test-{uuid.uuid4().hex[:8]}"
    thread = pn.serve({"app": create_app}, port=0, address="127.0.0.1", websocket_origin="*",
                      threaded=True, show=False, liveness=True, server_id=server_id)
    deadline = time.monotonic() + 30
    while server_id not in state._servers and time.monotonic() < deadline:
        time.sleep(0.05)
    port = state._servers[server_id][0].port
    url = f"http://127.0.0.1:{port}"
    wait_for_liveness(url)
    yield url
    thread.stop()


def start_bogie_serve(log_dir: Path, *options: str, environment: dict | None = None):
    """(base URL, process) of a ``bogie serve`` process on a free port of 127.0.0.1 (more
    ``options`` of ``bogie serve`` and ``environment`` variables may be given), its stderr in
    ``log_dir/serve.log``, answering its liveness endpoint.  Its studies folder is
    ``log_dir/studies`` unless the options name one."""
    import socket
    import subprocess
    import sys

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    with open(log_dir / "serve.log", "w") as stderr:
        if "--studies-dir" not in options:
            options = (*options, "--studies-dir", str(log_dir / "studies"))
        process = subprocess.Popen([sys.executable, "-m", "app", "serve", "--port", str(port),
                                    *options],
                                   cwd=Path(__file__).resolve().parent.parent,
                                   stdout=subprocess.DEVNULL, stderr=stderr,
                                   env={**os.environ, "OPENBLAS_NUM_THREADS": "1",
                                        **(environment or {})})
    url = f"http://127.0.0.1:{port}"
    try:
        wait_for_liveness(url, timeout=180)
    except BaseException:
        stop_process(process)
        raise
    return url, process


def stop_process(process, timeout: float = 30) -> None:
    """SIGTERM, then SIGKILL after ``timeout`` s; the process is reaped either way (no "still
    running" warning at teardown)."""
    import subprocess

    if process.poll() is None:
        process.terminate()
        try:
            process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(timeout=10)


@pytest.fixture(scope="module")
def own_server(tmp_path_factory):
    """(base URL, process id, studies folder) of a ``bogie serve`` process started for one test
    module: a fresh
    server as a reviewer gets it, sharing no state (sessions, caches, background work, Bokeh's
    and Panel's process-wide settings) with the tests that ran before in this process."""
    log_dir = tmp_path_factory.mktemp("server")
    url, process = start_bogie_serve(log_dir)
    try:
        yield url, process.pid, log_dir / "studies"
    finally:
        stop_process(process)


@pytest.fixture(scope="session")
def chromium():
    """A headless Chromium (Debian's binary) driven by Playwright."""
    if not CHROMIUM.exists():
        pytest.skip("needs /usr/bin/chromium (apt-get install chromium; bash run.sh test does)")
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        yield browser
        browser.close()


def _unknown_model(message: str) -> str:
    """For BokehJS's "reference p123 isn't known" (the server sent a change that names a model
    the page never received): which model of this process has that id, and whether it is in a
    document — the served app runs in the test's process, so the garbage collector finds it."""
    import gc
    import re

    found = re.search(r"reference (\S+) isn't known", message)
    if not found:
        return ""
    from bokeh.model import Model

    for obj in gc.get_objects():
        if isinstance(obj, Model) and obj.id == found.group(1):
            what = {key: value for key in ("name", "tags", "css_classes", "text", "data")
                    if (value := getattr(obj, key, None))}
            if "data" in what:
                what["data"] = sorted(what["data"])  # its columns
            return f" [{type(obj).__name__} {what}, in a document: {obj.document is not None}]"
    return " [no model of this process has that id]"


def open_app(browser, url: str, timeout_ms: float = 120_000, viewport=(1600, 1000),
             query: str = ""):
    """A new page with the app loaded (``/app?<query>``) and rendered; ``page.errors`` collects
    console errors and uncaught page errors."""
    page = browser.new_page(viewport={"width": viewport[0], "height": viewport[1]})
    errors: list[str] = []
    page.on("console", lambda m: errors.append(f"console: {m.text}") if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(f"pageerror: {e}{_unknown_model(str(e))}"))
    # which resource failed (the console message does not say)
    page.on("requestfailed", lambda r: errors.append(f"requestfailed: {r.url} ({r.failure})"))
    page.errors = errors
    page.goto(f"{url}/app" + (f"?{query}" if query else ""), timeout=timeout_ms)
    page.wait_for_function("() => window.Bokeh && Bokeh.documents.length > 0",
                           timeout=timeout_ms)
    page.wait_for_selector("canvas", timeout=timeout_ms)
    page.wait_for_selector(".stability-status", timeout=timeout_ms)
    return page


def until(condition, what: str, timeout: float = 300.0, poll: float = 0.25):
    """Poll ``condition()`` until it returns something true (its value), with a deadline [s]."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = condition()
        if value:
            return value
        time.sleep(poll)
    raise AssertionError(f"not within {timeout:g} s: {what}")


def live_dashboards(t_end: float) -> list:
    """The served dashboards (this process's server) that are alive with simulated time
    ``t_end`` [s]: a browser test's page picks its own session by a t_end no other uses."""
    import math

    from app.dashboard.scheduler import _SCHEDULERS

    return [s.dashboard for s in list(_SCHEDULERS)
            if s.dashboard.alive() and math.isclose(s.dashboard.state().t_end, t_end)]


# --- the server's study queue without a server ---------------------------------------------------

class InProcessEngine:
    """A study engine that runs the chunks in this process, in order (the reference of the
    tests; the served app always uses the operator's Dask engine)."""

    def start(self) -> None:
        pass

    def close(self) -> None:
        pass

    @staticmethod
    def map_unordered(function, items):
        from model.studies.engine import serial_map_unordered

        return serial_map_unordered(function, items)


def install_study_queue(folder: Path, engine_factory=InProcessEngine, **settings):
    """Install a study queue on ``folder`` as the process's (dashboards built afterwards use it);
    returns (queue, restore) where ``restore()`` puts the previous queue back."""
    from app.services.settings import ServerSettings
    from app.services.study_queue import StudyQueue, replace_study_queue

    queue = StudyQueue(ServerSettings(studies_dir=folder, **settings),
                       engine_factory=engine_factory)
    previous = replace_study_queue(queue)

    def restore() -> None:
        replace_study_queue(previous)
        queue.close()

    return queue, restore


def dashboard_with_study_queue(folder: Path):
    """A dashboard in a document of its own (not served), with a study queue on ``folder``: a
    module fixture's body (``yield from``), the previous queue put back afterwards."""
    from bokeh.document import Document

    from app.dashboard.dashboard import BogieDashboard

    _queue, restore = install_study_queue(folder)
    try:
        dashboard = BogieDashboard()
        doc = Document()
        doc.add_root(dashboard.layout.get_root(doc))
        yield dashboard
    finally:
        restore()


# --- shared test data and checks ------------------------------------------------------------------

SPEEDS = (40.0, 120.0, 200.0)  # speeds of the small uncertainty results [km/h]


def uncertainty_result_file(path: Path, parameters, method="posterior", names=None, seed=3) -> Path:
    """A small uncertainty result of ``parameters`` written by the model's own
    ``UncertaintyResult.as_dict`` (the band's logic needs its provenance and percentiles, not a
    model run; a real CLI run is in the posterior tests)."""
    import json

    import numpy as np

    from model.mechanics.parameters import parameter_hash
    from model.studies.uncertainty import (
        UNCERTAIN_PARAMETERS,
        UncertaintyResult,
        output_names,
        output_units,
    )

    names = tuple(p.name for p in UNCERTAIN_PARAMETERS) if names is None else names
    outputs = output_names(SPEEDS)
    rng = np.random.default_rng(seed)
    n = 8
    values = rng.uniform(0.5, 1.5, (n, len(outputs)))
    values[:, :len(SPEEDS)] *= np.array([0.012, 0.0082, 0.006])  # s0* [-]
    blank = np.full((len(outputs), len(names)), np.nan)
    result = UncertaintyResult(names, tuple((1.0, 2.0) for _ in names), outputs,
                               output_units(SPEEDS), n, n, rng.uniform(1, 2, (n, len(names))),
                               values, blank, blank, np.array([blank, blank]),
                               np.array([blank, blank]), seed, values.mean(axis=0),
                               method=method, indices=False, speeds_kmh=SPEEDS,
                               parameters_hash=parameter_hash(parameters),
                               wheel_force=parameters["wheel_force"],
                               motor_slope=parameters["motor_slope"])
    path.write_text(json.dumps(result.as_dict(), allow_nan=False), encoding="utf-8")
    return path


def assert_self_contained_html(text: str) -> None:
    """An HTML page that opens offline: no external script, stylesheet or image; BokehJS inline."""
    import re

    assert re.search(r"<script[^>]*\bsrc=", text) is None
    assert re.search(r"<link\b", text) is None
    assert re.search(r"<img[^>]*\bsrc=[\"']?https?:", text) is None
    assert "Bokeh" in text  # BokehJS itself is inline


# --- golden files (tests/golden/*.json) ------------------------------------------------------------

def load_golden(path: Path, regenerate: str) -> dict:
    """A golden file's contents; fails (naming the regeneration command) if it is missing."""
    import json

    if not path.is_file():
        pytest.fail(f"{path} is missing; {regenerate}")
    return json.loads(path.read_text(encoding="utf-8"))


def golden_parameters(golden: dict, path: Path, regenerate: str):
    """The parameter set stored in a golden file (its values, units from the schema); fails if
    they no longer fit the schema."""
    from model import ParameterError
    from model.mechanics.parameters import ALL_SCHEMA, parse_parameters

    table = {name: {"value": value, "unit": ALL_SCHEMA[name][0] if name in ALL_SCHEMA else "?"}
             for name, value in golden["parameters"].items()}
    try:
        return parse_parameters(table, source=str(path))
    except ParameterError as error:
        pytest.fail(f"the golden parameters no longer fit the schema ({error}); {regenerate}")


def _uniform_acceleration_loads(model, op, force) -> dict[str, float]:
    """The loads [per unit input] under a constant generalized force ``f`` in the steady state:
    the whole vehicle accelerates uniformly along its free rolling at a (nothing in the model
    resists a vehicle rolling faster without slip), the other rigid-body motions drift at
    constant velocities v = R c (a wheelset slipping at a constant rate against the creep
    damping), the structure deflects by q0: one linear solve of
    ``K q0 + B R c + M r a = f``, ``Rᵀ q0 = 0``, ``rᵀ R c = 0`` (the rolling part of v is free:
    no load sees it); the loads C_q q0 + C_v R c.  Independent of the modal form."""
    import numpy as np

    from model.mechanics.operating_point import damping_matrix
    from model.mechanics.outputs import output_matrices

    r, R, n = model.rolling_mode, model.rigid_body_modes, model.n
    k = R.shape[1]
    B = damping_matrix(model, op)
    system = np.zeros((n + k + 1, n + k + 1))
    system[:n, :n], system[:n, n:n + k], system[:n, -1] = model.K, B @ R, model.M @ r
    system[n:n + k, :n] = R.T
    system[-1, n:n + k] = r @ R
    solution = np.linalg.solve(system, np.concatenate([force, np.zeros(k + 1)]))
    matrices = output_matrices(model, op)
    loads = matrices.C_q @ solution[:n] + matrices.C_v @ (R @ solution[n:n + k])
    return dict(zip(matrices.names, loads, strict=True))


@pytest.fixture(scope="session")
def uniform_acceleration_loads():
    """:func:`_uniform_acceleration_loads` (model, op, generalized force) -> load per output."""
    return _uniform_acceleration_loads
