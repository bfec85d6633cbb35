"""The served dashboard's boundary, attacked as a hostile reviewer would (docs/security.md).

A ``bogie serve`` process of its own, with a studies folder made here, is driven by headless
Chromium.  A page is a hand-made client too: it sets any model's value from the page (hidden and
disabled widgets included, and a Select's options, which a browser can send as well), which
reaches the server as if typed.

* **No network address from a browser.**  A listener of this test counts connections while every
  TextInput and Select of every tab, and the query string, carry its address in the forms Dask
  accepts (``tcp://``, ``tls://``, ``ws://``, bare ``host:port``) and every studies button is
  pressed, a study included: 0 connections.
* **No file outside the studies folder.**  Every "existing" target outside the folder is a named
  pipe (FIFO): opening it for reading is seen by this test (a writer's non-blocking open succeeds
  only while a reader has it open), so "0 bytes read" is measured, not assumed.  Names with
  ``../``, absolute paths, NUL bytes, 10 kB, a symlink inside the folder pointing out (to a file
  and to a folder) and a store holding a symlink are refused; the notice of an existing target
  is the same as that of a missing one, and no notice names a server path.
* **Bounded study work.**  Five sessions ask for studies at once with K = 1: at most one runs,
  the rest wait in the order they asked and finish in that order, the server's process count is
  at most 1 + the local cluster's workers, and a slider answer while they run stays within 3× of
  the idle one (the workers run at a lower priority; ``BOGIE_BUSY_RATIO`` sets the bound, 2 on an
  idle machine is the target that BENCHMARKS.md records).
* **Soak** (1.5 minutes in the suite; ``BOGIE_SOAK_MINUTES`` sets the length, and the 10-minute
  run's figures stand in BENCHMARKS.md with its command): five sessions start studies and move
  sliders; the server's memory stays bounded, every finished store is complete, the server
  answers its liveness probe throughout.
"""

from __future__ import annotations

import errno
import json
import os
import re
import socket
import stat
import statistics
import threading
import time
import urllib.request
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT, start_bogie_serve, stop_process, uncertainty_result_file, wait_for_liveness

from app.services.studies_folder import refusal

pytestmark = [pytest.mark.browser, pytest.mark.slow]

ARTIFACTS = ROOT / "test-artifacts"  # git-ignored
WORKERS = max(1, len(os.sched_getaffinity(0)))  # the server's local cluster (one per core)
MAX_POINTS = 1000
# the busy slider answer's bound, a multiple of the idle one: generous in the suite, where the
# other tests share the machine; the target (2) is measured by this test alone (BENCHMARKS.md)
BUSY_RATIO = float(os.environ.get("BOGIE_BUSY_RATIO", "3"))

# probes of what the page shows
FAST = """() => { const d = Bokeh.documents[0].get_model_by_name('locus_current').data;
  const v = d instanceof Map ? d.get('x') : d.x; return Array.from(v).join(','); }"""
SET_EVERY_INPUT = """(payload) => {
  let count = 0;
  for (const m of Bokeh.documents[0].all_models) {
    const type = m.type || '';
    if (/(TextInput|TextAreaInput|PasswordInput|AutocompleteInput)$/.test(type)) {
      m.value_input = payload; m.value = payload; count++;
    } else if (/Select$/.test(type) && !/Multi/.test(type)) {
      // what a hand-made client may send: the option list too, then the value
      m.options = [...(m.options || []), payload]; m.value = payload; count++;
    }
  }
  return count; }"""
SET_SELECT = """([cls, payload]) => {
  const m = [...Bokeh.documents[0].all_models].find(m => (m.css_classes || []).includes(cls));
  m.options = [...(m.options || []), payload]; m.value = payload; }"""


class Listener:
    """A TCP listener on 127.0.0.1 counting the connections it accepts."""

    def __init__(self):
        self.socket = socket.socket()
        self.socket.bind(("127.0.0.1", 0))
        self.socket.listen(16)
        self.port = self.socket.getsockname()[1]
        self.connections = 0
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self) -> None:
        while True:
            try:
                connection, _ = self.socket.accept()
            except OSError:
                return
            self.connections += 1
            connection.close()

    def close(self) -> None:
        self.socket.close()


class FifoWatch:
    """Named pipes outside the studies folder; counts the times any was opened by a reader."""

    def __init__(self, paths: list[Path]):
        self.paths = paths
        for path in paths:
            os.mkfifo(path)
        self.opened: list[str] = []
        self._stop = threading.Event()
        threading.Thread(target=self._watch, daemon=True).start()

    def _watch(self) -> None:
        while not self._stop.wait(0.005):
            for path in self.paths:
                try:
                    fd = os.open(path, os.O_WRONLY | os.O_NONBLOCK)
                except OSError as error:
                    if error.errno != errno.ENXIO:  # ENXIO: no reader has it open
                        raise
                    continue
                self.opened.append(str(path))
                os.close(fd)

    def close(self) -> None:
        self._stop.set()


def _result_json(parameters) -> str:
    """A small uncertainty result of ``parameters`` at the dashboard's conditions (the model's
    own writer, as tests/app/dashboard/test_uncertainty_band.py makes it)."""
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        return uncertainty_result_file(Path(folder) / "u.json", parameters).read_text(encoding="utf-8")


@pytest.fixture(scope="module")
def setup(tmp_path_factory):
    """(URL, server pid, studies folder, FIFO watch, listed names) of a server whose studies
    folder holds a valid map and result, and traps pointing out of it."""
    from app.results import compute
    from model import KMH
    from model.studies.engine import serial_map_unordered
    from model.studies.maps import MapStudy
    from model.studies.store import run_into_store

    root = tmp_path_factory.mktemp("boundary")
    studies, outside = root / "studies", root / "outside"
    studies.mkdir()
    outside.mkdir()
    (outside / "secret.zarr").mkdir()
    watch = FifoWatch([outside / "secret.json", outside / "secret.zarr" / "zarr.json",
                       outside / "plain.json"])
    parameters = compute.parameters("", "calibrated")
    run_into_store(MapStudy([0.004, 0.012], [100 * KMH, 140 * KMH], [parameters["wheel_force"]],
                            [parameters["motor_slope"]]),
                   parameters, studies / "good.zarr", serial_map_unordered)
    (studies / "good.json").write_text(_result_json(parameters), encoding="utf-8")
    (studies / "link.json").symlink_to(outside / "secret.json")
    (studies / "linkdir.zarr").symlink_to(outside / "secret.zarr", target_is_directory=True)
    (studies / "holed.zarr").mkdir()
    (studies / "holed.zarr" / "zarr.json").symlink_to(outside / "secret.zarr" / "zarr.json")
    log_dir = root / "server"
    log_dir.mkdir()
    url, process = start_bogie_serve(
        log_dir, "--studies-dir", str(studies), "--max-study-points", str(MAX_POINTS),
        "--max-running-studies", "1", environment={"DASK_SCHEDULER_ADDRESS": ""})
    try:
        yield {"url": url, "pid": process.pid, "studies": studies, "outside": outside,
               "watch": watch, "log": log_dir / "serve.log"}
    finally:
        stop_process(process)
        watch.close()


def _page(browser, url: str, query: str = ""):
    page = browser.new_page(viewport={"width": 1600, "height": 1000})
    page.errors = []
    page.on("pageerror", lambda e: page.errors.append(str(e)))
    page.goto(f"{url}/app{'?' + query if query else ''}", timeout=180_000)
    page.wait_for_function("() => window.Bokeh && Bokeh.documents.length > 0", timeout=180_000)
    page.locator(".stability-status", has_text="STABLE").wait_for(timeout=180_000)
    return page


def _tab(page, title: str) -> None:
    tab = page.locator(".bk-tab", has_text=title).first
    tab.click()
    page.wait_for_function("(el) => el.classList.contains('bk-active')", arg=tab.element_handle(),
                           timeout=60_000)


def _fill(page, css: str, value: str) -> None:
    box = page.locator(f".{css} input")
    box.fill(value)
    box.press("Enter")


STATUS = """() => { const m = [...Bokeh.documents[0].all_models]
  .find(m => (m.css_classes || []).includes('study-status')); return m ? m.text : ''; }"""


def _status(page) -> str:
    """The Studies view's status line (the HTML pane's text; its element is in a shadow root)."""
    return page.evaluate(STATUS)


def _wait_status(page, prefix: str, timeout_ms: float = 600_000, log: Path | None = None,
                 server_pid: int | None = None) -> None:
    """Wait until the study ends (done, failed, stopped or dropped) and check that its status
    line starts with ``prefix``; if not, or if it has not ended within ``timeout_ms``, the
    message gives the line, the server's processes (state, CPU seconds, niceness) and the
    server log's tail."""
    from playwright.sync_api import TimeoutError as PlaywrightTimeout

    def what_the_server_shows() -> str:
        tail = log.read_text(errors="replace")[-3000:] if log is not None else ""
        processes = ("" if server_pid is None else "; its processes:\n" + "\n".join(
            _process_line(pid) for pid in [server_pid, *descendants(server_pid)]))
        return f"{_status(page)!r}{processes}\nserver log ends:\n{tail}"

    try:
        page.wait_for_function(f"() => /^(done|failed|stopped|dropped): /.test(({STATUS})())",
                               timeout=timeout_ms)
    except PlaywrightTimeout:
        pytest.fail(f"the study did not end within {timeout_ms / 1000:g} s: "
                    f"{what_the_server_shows()}")
    assert _status(page).startswith(prefix), what_the_server_shows()


def _stat_fields(pid: int) -> list[str]:
    """The fields of ``/proc/PID/stat`` after the command name (Linux): [0] the state, [1] the
    parent's id, [11] and [12] user and system clock ticks, [16] the niceness, [17] the threads;
    OSError if the process has ended."""
    return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()


def _process_line(pid: int) -> str:
    """One process's state, CPU seconds (user + system), niceness and command line (Linux)."""
    try:
        fields = _stat_fields(pid)
    except OSError:
        return f"{pid}: ended"
    cpu_s = (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    return (f"{pid} state {fields[0]}, {cpu_s:.1f} CPU-s, nice {fields[16]}, "
            f"threads {fields[17]}: {_command_line(pid)}")


def descendants(pid: int) -> list[int]:
    """The process ids below ``pid`` (Linux /proc)."""
    children: dict[int, list[int]] = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                parent = int(_stat_fields(int(entry))[1])
            except OSError:
                continue
            children.setdefault(parent, []).append(int(entry))
    found, todo = [], list(children.get(pid, []))
    while todo:
        child = todo.pop()
        found.append(child)
        todo.extend(children.get(child, []))
    return found


def _command_line(pid: int) -> str:
    """A process's command line, or what became of it (for a failure's message)."""
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode()[:200]
    except OSError:
        return f"{pid}: ended"


def _slider_answer(page) -> float:
    """Seconds from a key press on the s0 slider until the browser shows the new eigenvalues
    (one page step, 0.0005, up while s0 < 0.025, so the first 40 presses of a page from 0.005
    ask for values the server has not computed yet, and a page's values repeat after 80)."""
    before = page.evaluate(FAST)
    handle = page.locator(".ctl-s0 .noUi-handle")
    handle.focus()
    start = time.perf_counter()
    handle.press("PageUp" if page.evaluate(
        "() => [...Bokeh.documents[0].all_models].find(m => (m.css_classes || [])"
        ".includes('ctl-s0')).value") < 0.025 else "PageDown")
    page.wait_for_function(f"(before) => ({FAST})() !== before", arg=before, polling=5,
                           timeout=120_000)
    return time.perf_counter() - start


def _alive(url: str) -> bool:
    try:
        with urllib.request.urlopen(f"{url}/liveness?endpoint=/app", timeout=60) as reply:
            return reply.status == 200
    except OSError:
        return False


# --- no network address ---------------------------------------------------------------------------

def test_no_browser_input_makes_the_server_connect(setup, chromium, request):
    listener = Listener()
    port = listener.port
    payloads = [f"tcp://127.0.0.1:{port}", f"127.0.0.1:{port}", f"tls://127.0.0.1:{port}",
                f"ws://127.0.0.1:{port}/", f"inproc://127.0.0.1:{port}", f"localhost:{port}"]
    query = "&".join(f"{name}=tcp://127.0.0.1:{port}" for name in
                     ("scheduler", "address", "dask", "store", "studies_dir", "s0", "variant"))
    page = _page(chromium, setup["url"], query)
    ARTIFACTS.mkdir(exist_ok=True)
    try:
        tabs = page.locator(".bk-tab").all_inner_texts()
        assert "Studies" in tabs
        for title in tabs:
            _tab(page, title)
            page.wait_for_timeout(300)
            for payload in payloads:
                assert page.evaluate(SET_EVERY_INPUT, payload) >= 0
                page.wait_for_timeout(100)
        _tab(page, "Studies")
        for payload in payloads:
            page.evaluate(SET_EVERY_INPUT, payload)
            for button in ("study-open", "study-open-uncertainty", "study-refresh"):
                page.locator(f".{button} button").click()
            page.wait_for_timeout(200)
        # a real study on the server's engine, started with the address in every input
        page.evaluate(SET_EVERY_INPUT, payloads[0])
        page.wait_for_timeout(1000)  # the refused values are processed before the valid ones
        _fill(page, "study-s0-points", "3")
        _fill(page, "study-v-points", "2")
        page.wait_for_timeout(500)
        page.locator(".study-start button").click()
        _wait_status(page, "done: 2/2", log=setup["log"], server_pid=setup["pid"])
        page.wait_for_timeout(1000)
        assert listener.connections == 0
        assert _alive(setup["url"])
        text = page.locator("body").inner_text()
        assert str(setup["studies"]) not in text
    except BaseException:
        page.screenshot(path=str(ARTIFACTS / f"{request.node.name}.png"), full_page=True)
        raise
    finally:
        page.close()
        listener.close()


# --- no file outside the studies folder ------------------------------------------------------------

ATTACKS = {  # name -> the same name's twin whose target does not exist
    "link.json": "missing.json",  # a symlink in the folder to a FIFO outside
    "../outside/plain.json": "../outside/nothing.json",
    "{outside}/plain.json": "{outside}/nothing.json",
    "{outside}/secret.zarr": "{outside}/nothing.zarr",
    "linkdir.zarr": "missing.zarr",  # a symlink in the folder to a folder outside
    "holed.zarr": "nothing.zarr",  # a store in the folder holding a symlink out
    "good.json\x00.zarr": "bad.json\x00.zarr",
    "good.zarr/../good.json": "good.zarr/../nothing.json",
    "a" * 10_000 + ".json": "b" * 10_000 + ".json",
}


PAGE_TEXT = """() => [...Bokeh.documents[0].all_models]
  .filter(m => typeof m.text === 'string' && m.visible !== false).map(m => m.text).join('\\n')"""


def _text_after(page, select: str, button: str, name: str, reset: str) -> str:
    """What the page shows after asking to open ``name`` (``reset``, a listed name, is opened
    first): the body's text and every visible text model (notices, status lines; they render
    in shadow roots), with ``name`` replaced by a placeholder."""
    page.evaluate(SET_SELECT, [select, reset])
    page.locator(f".{button} button").click()
    page.wait_for_timeout(700)
    page.evaluate(SET_SELECT, [select, name])
    page.locator(f".{button} button").click()
    page.wait_for_timeout(1200)
    text = page.locator("body").inner_text() + "\n" + page.evaluate(PAGE_TEXT)
    return text.replace(name, "<NAME>")


def test_names_outside_the_list_reveal_nothing(setup, chromium):
    """Served: the list is the only way in (Panel's Select refuses a value that is not one of
    its options, whatever options the page claims), and what the page shows afterwards is the
    same for an existing and a missing target; nothing outside the folder is opened.  The
    server's own check behind the list (a name given straight to the view) is tested without a
    server below."""
    page = _page(chromium, setup["url"])
    outside = str(setup["outside"])
    try:
        _tab(page, "Studies")
        page.wait_for_function("""() => [...Bokeh.documents[0].all_models]
          .some(m => (m.css_classes || []).includes('study-store'))""", timeout=60_000)
        listed = page.evaluate("""() => [...Bokeh.documents[0].all_models]
          .find(m => (m.css_classes || []).includes('study-store')).options""")
        assert "good.zarr" in listed  # (with the maps the other tests made)
        assert not {"linkdir.zarr", "holed.zarr"} & set(listed)
        # the page's own answers (its verdict, s0*(v)) settled first: the texts compared below
        # are the whole page's, and an answer arriving between two of them is not a difference
        # the attack made
        page.wait_for_function(f"() => !({PAGE_TEXT})().includes('computing…')",
                               timeout=300_000)
        for select, button, reset in (("study-store", "study-open", "good.zarr"),
                                      ("study-uncertainty", "study-open-uncertainty",
                                       "good.json")):
            for existing, missing in ATTACKS.items():
                pair = [_text_after(page, select, button, name.format(outside=outside), reset)
                        for name in (existing, missing)]
                assert pair[0] == pair[1], existing
                assert outside not in pair[0]
                assert str(setup["studies"]) not in pair[0]
        assert setup["watch"].opened == []  # 0 bytes read outside the studies folder
        assert _alive(setup["url"])
    finally:
        page.close()


def test_names_given_straight_to_the_view_are_refused_alike(tmp_path):
    """No server: the check behind the list.  Every attack name given to the view's open
    methods (as if a value got past the widget) gives the one refusal notice, the same for an
    existing and a missing target, and opens nothing outside the folder."""
    from bokeh.document import Document
    from conftest import install_study_queue

    from app.dashboard.dashboard import BogieDashboard

    studies, outside = tmp_path / "studies", tmp_path / "outside"
    studies.mkdir()
    outside.mkdir()
    (outside / "secret.zarr").mkdir()
    watch = FifoWatch([outside / "secret.json", outside / "secret.zarr" / "zarr.json",
                       outside / "plain.json"])
    (studies / "link.json").symlink_to(outside / "secret.json")
    (studies / "linkdir.zarr").symlink_to(outside / "secret.zarr", target_is_directory=True)
    (studies / "holed.zarr").mkdir()
    (studies / "holed.zarr" / "zarr.json").symlink_to(outside / "secret.zarr" / "zarr.json")
    _queue, restore = install_study_queue(studies)
    try:
        dashboard = BogieDashboard()
        doc = Document()
        doc.add_root(dashboard.layout.get_root(doc))
        view = dashboard.studies
        for kind, open_, notice in (("map", view.open, view.notice),
                                    ("uncertainty", view.open_uncertainty, view.band_notice)):
            seen = set()
            for existing, missing in ATTACKS.items():
                for name in (existing, missing):
                    notice.visible = False
                    open_(name.format(outside=str(outside)))
                    assert notice.visible
                    seen.add(notice.object)
            assert len(seen) == 1, seen
            assert refusal(kind) in seen.pop()
        assert watch.opened == []
    finally:
        restore()
        watch.close()


# --- bounded study work ------------------------------------------------------------------------------

def _server_running(status: str) -> int | None:
    """The studies the server runs, as a session's status line reports them: "running: 3/24
    s0-lines, …; server: 1 of at most 1 running, 2 waiting" or "waiting: 2 studies ahead in the
    queue, 1 running".  The queue writes each line from one snapshot of itself, so these counts
    are the server's at one instant (the pages' own "running" lines are not: a page refreshes
    every 0.5 s, and one whose study has just ended may still read "running: 23/24" while the
    next study runs)."""
    match = re.search(r"server: (\d+) of at most \d+ running", status) or re.search(
        r"^waiting: .* ahead in the queue, (\d+) running", status)
    return int(match.group(1)) if match else None


def test_five_sessions_queue_with_one_running(setup, chromium):
    pages = [_page(chromium, setup["url"]) for _ in range(5)]
    try:
        for page in pages:
            _tab(page, "Studies")
            _fill(page, "study-s0-points", "40")
            _fill(page, "study-v-points", "8")  # 320 points, 8 s0-lines: several seconds
        idle = [_slider_answer(pages[0]) for _ in range(5)]
        ahead: dict[int, int] = {}  # page -> studies ahead of it when it asked
        for index, page in enumerate(pages):
            page.locator(".study-start button").click()
            page.wait_for_function(f"() => /^(waiting|running): /.test(({STATUS})())",
                                   timeout=60_000)
            text = _status(page)
            if text.startswith("waiting: "):
                ahead[index] = int(text.split()[1])
        done_at: dict[int, float] = {}
        busy: list[float] = []
        most_running, most_processes, crowd = 0, 0, []
        deadline = time.monotonic() + 600
        while len(done_at) < len(pages) and time.monotonic() < deadline:
            texts = [_status(page) for page in pages]
            most_running = max([most_running, *filter(None, map(_server_running, texts))])
            # the study processes (the engine's scheduler and workers)
            below = _study_processes(setup["pid"])
            if 1 + len(below) > most_processes:
                most_processes, crowd = 1 + len(below), [_command_line(pid) for pid in below]
            for index, text in enumerate(texts):
                if text.startswith("done") and index not in done_at:
                    done_at[index] = time.monotonic()
                assert not text.startswith(("failed", "stopped")), text
            if len(busy) < 9 and any(t.startswith("running") for t in texts):
                # on the page the idle answers were measured on, so that every answer asks for
                # a value not computed before (the sessions share the server's cache: another
                # page's first step would land on one the idle presses computed)
                busy.append(_slider_answer(pages[0]))
            time.sleep(0.2)
        assert len(done_at) == 5, [_status(page) for page in pages]
        assert most_running == 1, [_status(page) for page in pages]
        assert 1 < most_processes <= 1 + WORKERS, (crowd, setup["log"].read_text()[-3000:])
        # the four that waited, in the order they asked, finished in that order
        waited = sorted(ahead, key=ahead.get)
        assert len(waited) == 4
        assert sorted(ahead.values()) == [0, 1, 2, 3]
        finish = sorted(done_at, key=done_at.get)
        assert finish[1:] == waited
        assert len(busy) >= 5  # the median of several: one answer may meet a study's start or end
        # idle again after the studies, so that the idle median spans the same stretch of the run
        # as the busy one (the other tests beside this one load the machine unevenly)
        idle += [_slider_answer(pages[0]) for _ in range(5)]
        ratio = statistics.median(busy) / statistics.median(idle)
        print(json.dumps({"idle_median_s": statistics.median(idle),
                          "busy_median_s": statistics.median(busy), "ratio": ratio}))
        # an answer within BUSY_RATIO x the idle one while the studies run, compared like for like
        # (each to a value not computed before); the target, 2x on an idle machine, is measured
        # by this test alone with BOGIE_BUSY_RATIO=2 (BENCHMARKS.md)
        assert ratio <= BUSY_RATIO, (idle, busy)
        for page in pages:
            assert page.errors == [], page.errors
    finally:
        for page in pages:
            page.close()


# --- soak ----------------------------------------------------------------------------------------------

def _rss_mb(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    raise RuntimeError(f"no VmRSS for process {pid}")


def _complete(store: Path) -> bool:
    import xarray as xr

    with xr.open_zarr(str(store), consolidated=False) as dataset:
        return bool((dataset["chunk_done"].values == 1).all()
                    and np.isfinite(dataset["largest_real_part"].values).all())


SOAK_STUDIES = 10  # studies the soak starts at least
SOAK_GRACE_S = 600  # how much longer than its minutes the soak may take to start them [s]


def test_soak_five_sessions_with_studies_and_sliders(setup, chromium):
    minutes = float(os.environ.get("BOGIE_SOAK_MINUTES", "1.5"))
    pages = [_page(chromium, setup["url"]) for _ in range(5)]
    before = {p.name for p in setup["studies"].iterdir()}
    samples: list[tuple[float, float]] = []
    alive_checks, started, answers = [], 0, []
    try:
        for page in pages:
            _tab(page, "Studies")
            _fill(page, "study-s0-points", "20")
            _fill(page, "study-v-points", "8")
        start = time.monotonic()
        turn = 0
        # the soak's length, and at least SOAK_STUDIES studies started however slow the machine
        # (each turn waits for a slider answer; on a loaded machine fewer turns fit in a minute)
        while ((time.monotonic() - start < minutes * 60 or started < SOAK_STUDIES)
               and time.monotonic() - start < minutes * 60 + SOAK_GRACE_S):
            page = pages[turn % len(pages)]
            turn += 1
            status = _status(page)
            if not status.startswith(("running", "waiting")):
                page.locator(".study-start button").click()
                started += 1
            answers.append(_slider_answer(page))
            if turn % 5 == 0:
                samples.append((time.monotonic() - start, _rss_mb(setup["pid"])))
                alive_checks.append(_alive(setup["url"]))
        deadline = time.monotonic() + 300
        while time.monotonic() < deadline and any(
                _status(p).startswith(("running", "waiting")) for p in pages):
            time.sleep(1)
        stores = [p for p in setup["studies"].iterdir()
                  if p.name not in before and p.suffix == ".zarr"]
        assert all(alive_checks)
        assert alive_checks
        assert started >= SOAK_STUDIES
        assert len(stores) >= started - len(pages)
        incomplete = [p.name for p in stores if not _complete(p)]
        assert incomplete == []
        warm = [m for t, m in samples if t >= min(120.0, minutes * 20)]
        growth = samples[-1][1] - warm[0]
        print(json.dumps({"minutes": minutes, "studies": started, "slider_answers": len(answers),
                          "median_answer_s": statistics.median(answers), "rss_warm_mb": warm[0],
                          "rss_end_mb": samples[-1][1], "rss_max_mb": max(m for _, m in samples),
                          "stores": len(stores)}))
        assert growth < 150, samples  # caches are bounded; a leak per study or change would grow
        for page in pages:
            assert page.errors == [], page.errors
    finally:
        for page in pages:
            page.close()


def test_server_options_and_environment_are_the_operators(tmp_path):
    """Bad operator settings: one line, exit status 2; the environment variables have the
    options' meaning (the option wins)."""
    import subprocess
    import sys

    from app.services.settings import ServerSettings, SettingsError

    def serve(*args, env=None):
        return subprocess.run([sys.executable, "-m", "app", "serve", "--port", "0", *args],
                              capture_output=True, text=True, timeout=120,
                              env={**os.environ, **(env or {})})

    blocked = tmp_path / "file"
    blocked.write_text("")
    for args, env, expected in (
            (["--max-study-points", "0"], None, "--max-study-points = 0 is not allowed"),
            (["--max-running-studies", "x"], None, "--max-running-studies must be a whole number"),
            (["--max-waiting-studies", "-1"], None, "--max-waiting-studies = -1 is not allowed"),
            ([], {"BOGIE_MAX_RUNNING_STUDIES": "two"}, "BOGIE_MAX_RUNNING_STUDIES = 'two'"),
            ([], {"BOGIE_MAX_STUDY_POINTS": "0"}, "--max-study-points (BOGIE_MAX_STUDY_POINTS)"),
            (["--studies-dir", str(blocked / "sub")], None, "cannot be used")):
        result = serve(*args, env=env)
        assert result.returncode == 2, (args, result.stderr)
        lines = result.stderr.strip().splitlines()
        assert len(lines) == 1, (args, result.stderr)
        assert expected in lines[0], (args, result.stderr)
    settings = ServerSettings.from_options(
        max_study_points=50, environ={"BOGIE_MAX_STUDY_POINTS": "70", "BOGIE_SCHEDULER":
                                      "tcp://10.0.0.1:8786", "BOGIE_STUDIES_DIR": str(tmp_path)})
    assert settings.max_study_points == 50
    assert settings.scheduler == "tcp://10.0.0.1:8786"
    assert settings.studies_dir == tmp_path
    assert "tcp://" not in settings.engine_description  # what a reviewer reads
    with pytest.raises(SettingsError, match="BOGIE_MAX_WAITING_STUDIES"):
        ServerSettings.from_options(environ={"BOGIE_MAX_WAITING_STUDIES": "many"})
    help_text = subprocess.run([sys.executable, "-m", "app", "serve", "--help"],
                               capture_output=True, text=True, timeout=60).stdout
    for variable in ("BOGIE_SCHEDULER", "BOGIE_STUDIES_DIR", "BOGIE_MAX_STUDY_POINTS",
                     "BOGIE_MAX_RUNNING_STUDIES", "BOGIE_MAX_WAITING_STUDIES"):
        assert variable in help_text


def test_a_stopped_server_leaves_no_worker_behind(tmp_path, chromium):
    """The shared local cluster's workers end with the server (SIGTERM, as ``docker stop``)."""
    url, process = start_bogie_serve(tmp_path, "--studies-dir", str(tmp_path / "studies"))
    try:
        wait_for_liveness(url)
        page = _page(chromium, url)
        _tab(page, "Studies")
        _fill(page, "study-s0-points", "3")
        _fill(page, "study-v-points", "2")
        page.locator(".study-start button").click()
        _wait_status(page, "done: 2/2", log=tmp_path / "serve.log", server_pid=process.pid)
        workers = descendants(process.pid)  # the study engine's and the background processes
        assert len(_study_processes(process.pid)) == WORKERS
        assert len(workers) > WORKERS
        page.close()
    finally:
        stop_process(process)
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline and any(Path(f"/proc/{w}").exists() and
                                              _running(w) for w in workers):
        time.sleep(0.2)
    assert not any(Path(f"/proc/{w}").exists() and _running(w) for w in workers)


def _study_processes(server_pid: int) -> list[int]:
    """The server's live descendant processes but its background ones and short-lived helpers.

    Not counted: the background processes (their command line is Python's multiprocessing start
    code: the forkserver, the workers it forks and the resource tracker); the `git describe` a
    study's store runs to record the code's version; and a process that has ended, whether gone
    or a zombie its parent has not reaped yet (a zombie's command line is empty, so a finished
    `git` would otherwise count as a study process), or one forked and not yet running its own
    program (its command line is still the server's).
    """
    server = _command_line(server_pid)
    found = []
    for pid in descendants(server_pid):
        command = _command_line(pid)
        if (_running(pid) and command.strip() and command != server
                and "multiprocessing" not in command and not command.startswith("git ")):
            found.append(pid)
    return found


def _running(pid: int) -> bool:
    try:
        state = _stat_fields(pid)[0]
    except OSError:
        return False
    return state != "Z"


def test_the_folder_is_listed_without_following_links(tmp_path):
    """Unit level: what the list holds (no server)."""
    from app.services.studies_folder import StudiesFolder, StudyNameRefused

    folder = StudiesFolder(tmp_path / "studies")
    root = folder.ensure()
    (root / "a.json").write_text("{}")
    (root / ".hidden.json").write_text("{}")
    (root / "s.zarr").mkdir()
    (root / "s.zarr" / "zarr.json").write_text("{}")
    (root / "noindex.zarr").mkdir()
    (tmp_path / "out.json").write_text("{}")
    (root / "out.json").symlink_to(tmp_path / "out.json")
    os.mkfifo(root / "pipe.json")
    assert folder.names("uncertainty") == ["a.json"]
    assert folder.names("map") == ["s.zarr"]
    assert stat.S_ISFIFO(os.lstat(root / "pipe.json").st_mode)
    for name in ("out.json", "pipe.json", ".hidden.json", "../out.json", str(root / "a.json"),
                 "a.json\x00", None, 7, "s.zarr"):
        with pytest.raises(StudyNameRefused) as refused:
            folder.path(name, "uncertainty")
        assert str(refused.value) == refusal("uncertainty")
    assert folder.path("a.json", "uncertainty") == root / "a.json"
    name = folder.new_name("map", "map")
    assert name.endswith(".zarr")
    assert name not in folder.names("map")
