"""Measure the dashboard in a real browser (headless Debian Chromium via Playwright).

    .venv/bin/python scripts/bench_app.py [--presses 15] [--sessions 10] [--screenshots]

Starts ``bogie serve`` on a free port (a separate process, as users run it), then:

1. single session: keyboard steps (PageUp: 0.0005) on the s0 slider handle (each a new value, so no cache
   hit); latency = key press → the browser holds new eigenvalues (root-locus current point)
   *and* new time histories (both must have changed); and key press → the stability status
   shows the new point (its text changed: the browser's own clock from the key event).
   The steps follow each other at once (the next key press as soon as the previous result is
   in: a held arrow key); ``--isolated`` more steps are each taken after the session is idle
   (1 b: a reviewer moves a slider and looks);
1 c. ``--drags``: on a page of its own, the s0 handle dragged with the mouse from 0.005 to
   0.012 and back, 2 s each way (40 moves): the previews the status shows while the button is
   held (app.dashboard.drag_preview), their number and rate;
2. root-locus refresh: keyboard steps on the speed slider (new v → new s0*(v) and a new locus
   over s0); latency = key press → new (coarse, 25-point) locus branches in the browser, and
   key press → the dense 200-point locus has replaced it (its title no longer says
   "computing"). The steps follow each other once the dense locus is shown (the previous
   speed's s0*(v) and verdict may still run); with ``--settled-speed-steps`` each waits until
   they are done (a reviewer who looks at the new speed's results first);
3. ``--sessions`` pages at once, each with its own wheel force N0 (so no session profits from
   another's cache), pressing s0 steps at random moments (0.3–1.5 s apart);
4. the same page's s0 steps alone (as in 3, before any other session connects: the reference),
   then the same number of sessions, but only one of them a Chromium page (measured as in 3) and the
   others *protocol clients*: Bokeh's Python client (``bokeh.client``) in a separate process,
   one thread per session, changing s0 exactly as a page does (new ``value_throttled``, own
   N0) and waiting for the same two results, but drawing nothing.  On this 2-core machine ten
   headless Chromium pages take most of the CPU themselves; in a design review every reviewer's
   browser runs on their own computer, so 4 is the load the *server* sees from ten reviewers,
   and 3 the worst case of everything on one machine.  Both are reported;
5. ``--screenshots``: assets/screenshots/stable.png and unstable.png (published cases) and
   tab_*.png (the review tabs at the unstable case).

Prints medians and writes the numbers as JSON (``--json FILE``).
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import random
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))
import served_app  # noqa: E402 - the scripts' own helpers
from served_app import free_port  # noqa: E402 - also used by bench_nonlinear_app

CHROMIUM = "/usr/bin/chromium"
# an s0 step: PageUp moves the slider by five of its 0.0001 steps, 0.0005, the values the
# benchmarks have always stepped through (0.005, 0.0055, … across s0* ≈ 0.0082 at 120 km/h)
S0_KEY = "PageUp"
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync"]
# the probe runs every 5 ms on the page's main thread while a step is measured, beside the work
# it measures: it looks each model up once (``get_model_by_name`` searches all ≈ 440 models) and
# copies 60 values, not the column (a JavaScript profile of four steps with the first probe,
# which did both each time, counted ≈ 50 ms of main-thread time per step in it)
DATA = """(name, col) => { const cache = window.__bench_models || (window.__bench_models = {});
  let model = cache[name];
  if (model === undefined || model.document == null) {
    model = cache[name] = Bokeh.documents[0].get_model_by_name(name); }
  const d = model.data; const v = d instanceof Map ? d.get(col) : d[col];
  return Array.prototype.slice.call(v, 0, 60).join(','); }"""
FAST = f"() => ({DATA})('locus_current', 'x') + '|' + ({DATA})('response', 'y:ID1.disc_clutch.torque')"
SLOW = f"() => ({DATA})('locus_points', 'x')"
LOCUS_TITLE = "() => Bokeh.documents[0].get_model_by_name('root-locus').title.text"


def log(message: str) -> None:
    print(f"bench_app: {time.strftime('%H:%M:%S')} {message}", file=sys.stderr, flush=True)


# the command line of the server's background worker processes (app/services/background.py
# starts them from a forkserver; nothing else of a benchmark run does)
BACKGROUND_WORKERS = "multiprocessing.forkserver"


def cpu_seconds(match: str) -> float:
    """CPU time [s] (user + system) used so far by the processes whose command line contains
    ``match`` (Linux /proc)."""
    total = 0.0
    tick = os.sysconf("SC_CLK_TCK")
    for proc in Path("/proc").iterdir():
        if not proc.name.isdigit():
            continue
        try:
            if match not in (proc / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace"):
                continue
            fields = (proc / "stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        total += (int(fields[11]) + int(fields[12])) / tick
    return total


def start_server(port: int):
    return served_app.start_server(port, "bench_app")


async def open_page(browser, url: str):
    page = await browser.new_page(viewport={"width": 1600, "height": 1000})
    page.errors = []
    page.on("console", lambda m: page.errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: page.errors.append(str(e)))
    await page.goto(f"{url}/app", timeout=180_000)
    await page.wait_for_function("() => window.Bokeh && Bokeh.documents.length > 0",
                                 timeout=180_000)
    await page.locator(".stability-status", has_text="STABLE").wait_for(timeout=180_000)
    await page.wait_for_function(f"() => ({SLOW})().length > 0", timeout=300_000)
    # the session's own dense locus too: else it arrives after the next change (settle_n0) and
    # is taken for that change's locus
    await page.wait_for_function(f"() => !({LOCUS_TITLE})().includes('computing')",
                                 timeout=300_000)
    return page


# JS: the page's clock at the last key press and at the first change of the stability status's
# numbers after it (the largest Re λ, the flutter and divergence counts: every new point changes
# them; the STABLE/UNSTABLE box itself changes only across the limit)
WATCH_PRESS = """() => { if (window.__press_watched) { window.__status_at = null; return; }
  window.__press_watched = true; window.__status_at = null;
  document.addEventListener('keydown', () => { window.__press_at = performance.now();
    window.__status_at = null; }, true);
  const status = [...Bokeh.documents[0].all_models]
    .find(m => (m.css_classes || []).includes('stability-details'));
  status.properties.text.change.connect(() => {
    if (window.__status_at === null) window.__status_at = performance.now(); }); }"""
STATUS_TIMES: list[float] = []  # [s] key press → status changed, of every step() measured


async def step(page, control: str, key: str, probe: str, timeout: float = 120_000) -> float:
    """Seconds from a key press on a slider handle until ``probe`` changed in the browser (the
    time until the stability status changed is appended to STATUS_TIMES)."""
    before = (await page.evaluate(probe)).split("|")
    await page.evaluate(WATCH_PRESS)
    handle = page.locator(f".{control} .noUi-handle")
    await handle.focus()
    t0 = time.perf_counter()
    await handle.press(key)
    # every part of the probe must have changed (eigenvalues AND time histories): they may
    # arrive in separate messages
    await page.wait_for_function(
        f"() => {{ const now = ({probe})().split('|'); const before = {json.dumps(before)};"
        " return now.every((part, i) => part !== before[i]); }", polling=5, timeout=timeout)
    elapsed = time.perf_counter() - t0
    status = await page.evaluate("() => window.__status_at === null ? null : "
                                 "(window.__status_at - window.__press_at) / 1e3")
    if status is not None:
        STATUS_TIMES.append(status)
    return elapsed


async def speed_step(page) -> tuple[float, float]:
    """A speed step: seconds from the key press until the coarse root locus is in the browser,
    and until the dense one has replaced it (its title no longer says "computing")."""
    before = await page.evaluate(SLOW)
    handle = page.locator(".ctl-v .noUi-handle")
    await handle.focus()
    t0 = time.perf_counter()
    await handle.press("ArrowRight")
    await page.wait_for_function(f"() => ({SLOW})() !== {json.dumps(before)}", polling=5,
                                 timeout=300_000)
    coarse = time.perf_counter() - t0
    await page.wait_for_function(f"() => !({LOCUS_TITLE})().includes('computing')", polling=5,
                                 timeout=300_000)
    return coarse, time.perf_counter() - t0


async def wait_idle(page) -> None:
    """Let the session's background stage (s0*, root locus) finish."""
    await page.wait_for_function(f"() => ({SLOW})().length > 0", timeout=300_000)
    await asyncio.sleep(2.0)


async def wait_settled(page) -> None:
    """Wait until the follow-ups of a change of speed, N0 or b_M are done: the dense root locus,
    s0*(v) and the verdict (else they run beside the steps measured next: steps 5-7 after an N0
    change took 1.6-2.2 s instead of 0.7 s, the time of s0*'s search, not of the steps; the
    verdict at a new wheel force computes its unstable and ripple cases, about 2 CPU-s, which
    later s0 steps keep)."""
    await page.wait_for_function(f"() => !({LOCUS_TITLE})().includes('computing')",
                                 timeout=300_000)
    await page.get_by_text("s0*(v): computing").first.wait_for(state="hidden", timeout=300_000)
    await page.locator(".verdict-status", has_text="computing").wait_for(state="hidden",
                                                                         timeout=300_000)
    await asyncio.sleep(1.0)


# JS: record every text of the status pane with its time [ms] (the previews of a held slider)
WATCH_STATUS = """() => { const doc = Bokeh.documents[0];
  const status = [...doc.all_models].find(m => (m.css_classes || []).includes('stability-status'));
  window.statusLog = [];
  status.properties.text.change.connect(() => window.statusLog.push([performance.now(), status.text]));
}"""
DRAG_S0 = (0.005, 0.012)  # the drag of s0 at 120 km/h, across s0* ≈ 0.0082 [-]
DRAG_SECONDS, DRAG_MOVES = 2.0, 40


async def drag_s0(page, start: float, end: float) -> tuple[int, float]:
    """Drag the s0 handle with the mouse from ``start`` to ``end`` in DRAG_MOVES moves over
    DRAG_SECONDS, hold it 0.4 s, release, wait for the full answer: (previews the status showed
    while the button was held, their rate [1/s] from the first to the last)."""
    low, high = await page.evaluate(
        "() => { const m = [...Bokeh.documents[0].all_models].find(m => (m.css_classes || [])"
        ".includes('ctl-s0')); return [m.start, m.end]; }")
    track = await page.locator(".ctl-s0 .noUi-base").bounding_box()
    handle = await page.locator(".ctl-s0 .noUi-handle").bounding_box()
    x_of = lambda s0: track["x"] + (s0 - low) / (high - low) * track["width"]  # noqa: E731
    y = handle["y"] + handle["height"] / 2
    await page.evaluate("() => { window.statusLog.length = 0; }")
    await page.mouse.move(handle["x"] + handle["width"] / 2, y)
    await page.mouse.down()
    t0 = time.perf_counter()
    for k in range(1, DRAG_MOVES + 1):
        await page.mouse.move(x_of(start + (end - start) * k / DRAG_MOVES), y)
        await asyncio.sleep(max(0.0, t0 + DRAG_SECONDS * k / DRAG_MOVES - time.perf_counter()))
    await asyncio.sleep(0.4)
    times = [t for t, text in await page.evaluate("() => window.statusLog") if "preview" in text]
    await page.mouse.up()
    await page.wait_for_function("() => window.statusLog.length && "
                                 "!window.statusLog.at(-1)[1].includes('preview')", timeout=120_000)
    rate = (len(times) - 1) / ((times[-1] - times[0]) / 1e3) if len(times) > 1 else 0.0
    return len(times), rate


async def drags(browser, url: str, count: int) -> list[tuple[int, float]]:
    """``count`` drags of s0 on a page of its own (the default point, 120 km/h), there and back,
    after its s0*(v) and dense root locus are on screen."""
    page = await open_page(browser, url)
    await wait_settled(page)
    await page.evaluate(WATCH_STATUS)
    out = []
    for k in range(count):
        out.append(await drag_s0(page, *(DRAG_S0 if k % 2 == 0 else DRAG_S0[::-1])))
        await asyncio.sleep(1.0)
    await page.close()
    return out


async def settle_n0(page, presses: int) -> None:
    for _ in range(presses):
        await step(page, "ctl-N0", "ArrowLeft", SLOW, timeout=300_000)


def protocol_clients(url: str, count: int) -> None:
    """Run ``count`` protocol clients (one thread each; see the module docstring, 4).  Talks on
    stdin/stdout: prints ``ready`` once every client has its own N0 and its results, presses
    after ``go`` until ``stop``, then prints the latencies [s] as one JSON line."""
    import importlib
    import pkgutil
    import threading

    import panel.models
    from bokeh.client import pull_session

    # registers all of Panel's Bokeh models (to deserialize the document: it holds e.g. the
    # mode table's DataTabulator)
    for module in pkgutil.iter_modules(panel.models.__path__):
        try:
            importlib.import_module(f"panel.models.{module.name}")
        except ImportError:  # optional extras
            pass
    go, stop = threading.Event(), threading.Event()
    ready = threading.Barrier(count + 1)
    latencies: list[float] = []
    failures: list[str] = []

    def client(index: int) -> None:
        session = pull_session(url=f"{url}/app")
        try:
            doc = session.document

            def control(name):
                return next(m for m in doc.models
                            if f"ctl-{name}" in (getattr(m, "css_classes", None) or []))

            def change(slider, value, sources, timeout=300.0) -> float:
                """Seconds from a new value_throttled until every source's data changed."""
                seen = set()
                callbacks = []
                for source in sources:
                    def changed(attr, old, new, source=source):
                        seen.add(source.id)
                    source.on_change("data", changed)
                    callbacks.append((source, changed))
                t0 = time.perf_counter()
                slider.value = value
                slider.set_from_json("value_throttled", value)  # as BokehJS does on release
                deadline = t0 + timeout
                session._connection._loop_until(
                    lambda: len(seen) == len(sources) or time.perf_counter() > deadline)
                elapsed = time.perf_counter() - t0
                for source, changed in callbacks:
                    source.remove_on_change("data", changed)
                if len(seen) < len(sources):
                    raise TimeoutError(f"client {index}: no new results after {timeout:.0f} s")
                return elapsed

            fast = [doc.get_model_by_name("locus_current"),
                    doc.get_model_by_name("response")]
            locus = [doc.get_model_by_name("locus_points")]
            s0, n0 = control("s0"), control("N0")
            # settled as the single session (wait_settled): the dense root locus, s0*(v) and the
            # verdict shown, else the clients' steps are measured beside the other clients'
            # follow-ups (≈ 3 CPU-s each, the verdict's unstable and ripple cases ≈ 2 CPU-s
            # more), not beside their steps
            title = doc.get_model_by_name("root-locus").title

            def settled() -> bool:
                texts = [t for t in (getattr(m, "text", None) for m in doc.models)
                         if isinstance(t, str)]
                return (len(locus[0].data.get("x", ())) > 0 and "computing" not in title.text
                        and not any("s0*(v): computing" in t or "VERDICT: computing" in t
                                    for t in texts))

            def wait_settled() -> None:
                deadline = time.perf_counter() + 300.0
                session._connection._loop_until(
                    lambda: settled() or time.perf_counter() > deadline)
                if not settled():
                    raise TimeoutError(f"client {index}: follow-ups not done in 300 s")

            # the new session's own first results first: the locus of the default N0 arriving
            # after the change below would be taken for the new N0's, and the clients would
            # step while their new N0's dense locus, s0*(v) and verdict still run
            wait_settled()
            change(n0, 60.0 + index, locus)  # own wheel force [kN]: no shared cache hits
            wait_settled()
            time.sleep(1.0)
        except Exception as error:  # reported; the run fails
            failures.append(repr(error))
            ready.abort()
            return
        ready.wait()
        go.wait()
        rng = random.Random(1000 + index)
        try:
            while not stop.is_set():
                time.sleep(rng.uniform(0.3, 1.5))
                value = s0.value + s0.step if s0.value + s0.step <= s0.end else s0.start
                latencies.append(change(s0, round(value, 6), fast))
        except Exception as error:
            failures.append(repr(error))
        finally:
            session.close()

    threads = [threading.Thread(target=client, args=(i,), daemon=True) for i in range(count)]
    for thread in threads:
        thread.start()
    try:
        ready.wait()
    except threading.BrokenBarrierError:
        print(json.dumps({"failures": failures}), flush=True)
        return
    print("ready", flush=True)
    for line in sys.stdin:
        if line.strip() == "go":
            go.set()
        elif line.strip() == "stop":
            break
    stop.set()
    for thread in threads:
        thread.join(timeout=120)
    print(json.dumps({"latencies": latencies, "failures": failures}), flush=True)


async def session(page, seed: int, presses: int) -> list[float]:
    """``presses`` s0 steps at random moments (0.3–1.5 s apart); their latencies [s]."""
    rng = random.Random(seed)
    out = []
    for _ in range(presses):
        await asyncio.sleep(rng.uniform(0.3, 1.5))
        out.append(await step(page, "ctl-s0", S0_KEY, FAST))
    return out


async def variant_screenshot(page, path: Path) -> None:
    """The Variant tab with a variant (driving shaft 30 % softer) uploaded and compared with the
    baseline; then back to the baseline and the Response tab."""
    from model.mechanics.parameters import dumps_parameters, load_parameters

    await page.locator(".bk-tab", has_text="Variant").first.click()
    base = load_parameters()
    with tempfile.TemporaryDirectory() as tmp:
        toml = Path(tmp) / "softer_driving_shaft.toml"
        toml.write_text(dumps_parameters(base.replace(
            driving_shaft_stiffness=0.7 * base["driving_shaft_stiffness"])))
        await page.locator(".var-upload input[type=file]").set_input_files(str(toml))
    await page.locator(".variant-comparison td.changed").first.wait_for(timeout=300_000)
    await asyncio.sleep(6.0)  # the s0*(v) curves drawn
    await page.screenshot(path=str(path), full_page=True)
    await page.locator(".var-reset button").click()
    await page.wait_for_function("() => !window.location.search.includes('variant=')",
                                 timeout=60_000)
    await page.locator(".bk-tab", has_text="Response").first.click()


async def screenshots(browser, url: str) -> None:
    out = ROOT / "assets" / "screenshots"
    out.mkdir(parents=True, exist_ok=True)
    page = await open_page(browser, url)
    for case in ("stable", "unstable"):
        await page.locator(f".case-{case} button").click()
        word = "UNSTABLE" if case == "unstable" else "STABLE"
        await page.locator(".stability-status", has_text=word).wait_for()
        await page.wait_for_function(f"() => !({LOCUS_TITLE})().includes('computing')",
                                     polling=100, timeout=300_000)  # the dense locus is shown
        if case == "unstable":  # the required anti-slip reaction time (≈ 20 nonlinear runs)
            await page.locator(".reaction-status", has_text=re.compile(
                r"after detection|any delay|none suffices")).wait_for(
                timeout=300_000)
        await wait_idle(page)
        await page.screenshot(path=str(out / f"{case}.png"), full_page=True)
        if case == "stable":
            await variant_screenshot(page, out / "tab_variant.png")
    # the review tabs at the unstable case (s0 = 0.014, 120 km/h)
    for title, name in (("Fig. 6", "fig6"), ("Modes", "modes"), ("Sensitivity", "sensitivity"),
                        ("Studies", "studies")):
        await page.locator(".bk-tab", has_text=title).first.click()
        await asyncio.sleep(6.0)  # the tab's views are brought up to date, then drawn
        await page.screenshot(path=str(out / f"tab_{name}.png"), full_page=True)
    await page.close()


async def run(args) -> dict:
    from playwright.async_api import async_playwright

    if args.url:  # a server started elsewhere (e.g. under a profiler)
        server, url = None, args.url.rstrip("/")
    else:
        port = free_port()
        server = start_server(port)
        url = f"http://127.0.0.1:{port}"
    results: dict = {}
    try:
        async with async_playwright() as p:
            browser = await p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
            if args.only_screenshots:
                await screenshots(browser, url)
                return results
            # 1 + 2: one session
            log("single session: opening the page")
            page = await open_page(browser, url)
            log("single session: own wheel force")
            await settle_n0(page, 1)
            await wait_settled(page)
            log("single session: s0 steps, then speed steps")  # own N0 = 99 kN: nothing cached from earlier runs
            STATUS_TIMES.clear()
            fast = [await step(page, "ctl-s0", S0_KEY, FAST) for _ in range(args.presses)]
            results["single_status_s"] = list(STATUS_TIMES)
            # the same steps one at a time: each after the previous one's work is done (its
            # s0*, locus, ranges and drawing), as a reviewer moves a slider and looks
            isolated = []
            for _ in range(args.isolated):
                await wait_idle(page)
                isolated.append(await step(page, "ctl-s0", S0_KEY, FAST))
            results["single_isolated_s"] = isolated
            speeds = []
            for _ in range(args.locus_presses):
                if args.settled_speed_steps:
                    await wait_settled(page)
                speeds.append(await speed_step(page))
            results["single_fast_s"] = fast
            results["locus_refresh_s"] = [coarse for coarse, _ in speeds]
            results["dense_locus_s"] = [dense for _, dense in speeds]
            results["errors_single"] = list(page.errors)
            await page.close()
            if args.drags:
                log(f"single session: {args.drags} drags of s0 (previews)")
                results["drags"] = await drags(browser, url, args.drags)
            # 3: concurrent sessions, each with its own N0 (no shared cache hits)
            if args.sessions == 0:
                return results
            if not args.skip_pages:
                await pages_at_once(browser, url, args, results)
            await page_among_clients(browser, url, args, results)
            if args.screenshots:
                await screenshots(browser, url)
            await browser.close()
    finally:
        if server is not None:
            server.terminate()
            server.wait(timeout=30)
    return results


async def pages_at_once(browser, url: str, args, results: dict) -> None:
    """3: ``args.sessions`` Chromium pages at once."""
    log(f"{args.sessions} sessions: opening the pages")
    pages = [await open_page(browser, url) for _ in range(args.sessions)]
    log(f"{args.sessions} sessions: own wheel forces")
    await asyncio.gather(*(settle_n0(pg, 2 + i) for i, pg in enumerate(pages)))
    for pg in pages:
        await wait_settled(pg)

    log(f"{args.sessions} sessions: s0 steps")
    cpu_server, cpu_browser = cpu_seconds("bogie serve"), cpu_seconds("chrom")
    began = time.perf_counter()
    latencies = await asyncio.gather(*(session(pg, i, args.concurrent_presses)
                                       for i, pg in enumerate(pages)))
    results["concurrent_fast_s"] = [x for xs in latencies for x in xs]
    wall = time.perf_counter() - began
    changes = len(results["concurrent_fast_s"])
    # where the 2 cores went: the server and the ten browsers share this machine
    results["concurrent_cpu"] = {
        "wall_s": wall, "changes": changes,
        "server_cpu_s": cpu_seconds("bogie serve") - cpu_server,
        "browser_cpu_s": cpu_seconds("chrom") - cpu_browser}
    results["errors_concurrent"] = [e for pg in pages for e in pg.errors]
    for pg in pages:
        await pg.close()


async def page_among_clients(browser, url: str, args, results: dict) -> None:
    """4: one Chromium page among ``args.sessions − 1`` protocol clients, and the same page's
    steps alone first (the same protocol and count, before the clients connect): the ratio's
    reference."""
    page = await open_page(browser, url)
    await settle_n0(page, 2 + args.sessions)  # an N0 no other session has
    await wait_settled(page)
    log(f"1 page alone: {args.mixed_presses} s0 steps")
    results["alone_page_s"] = await session(page, 98, args.mixed_presses)
    await wait_settled(page)  # its follow-ups done, as the clients' before they step
    log(f"1 page + {args.sessions - 1} protocol clients: connecting")
    load = subprocess.Popen([sys.executable, __file__, "--protocol-clients", url,
                             "--sessions", str(args.sessions - 1)],
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        line = await asyncio.to_thread(load.stdout.readline)
        if line.strip() != "ready":
            raise SystemExit(f"bench_app: protocol clients failed: {line.strip()}")
        log("1 page + protocol clients: s0 steps")
        load.stdin.write("go\n")
        load.stdin.flush()
        cpu = (cpu_seconds("bogie serve"), cpu_seconds("chrom"),
               cpu_seconds("--protocol-clients"), cpu_seconds(BACKGROUND_WORKERS))
        began = time.perf_counter()
        results["mixed_page_s"] = await session(page, 99, args.mixed_presses)
        wall = time.perf_counter() - began
        load.stdin.write("stop\n")
        load.stdin.flush()
        results["mixed_cpu"] = {
            "wall_s": wall,
            "server_cpu_s": cpu_seconds("bogie serve") - cpu[0],
            "browser_cpu_s": cpu_seconds("chrom") - cpu[1],
            "clients_cpu_s": cpu_seconds("--protocol-clients") - cpu[2],
            "background_cpu_s": cpu_seconds(BACKGROUND_WORKERS) - cpu[3]}
        report = json.loads(await asyncio.to_thread(load.stdout.readline))
        if report["failures"]:
            raise SystemExit(f"bench_app: protocol clients failed: {report['failures']}")
        results["mixed_clients_s"] = report["latencies"]
        results["errors_mixed"] = list(page.errors)
        await page.close()
    finally:
        if load.poll() is None:
            load.kill()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--presses", type=int, default=15)
    parser.add_argument("--isolated", type=int, default=5,
                        help="s0 steps each after the session is idle (1 b)")
    parser.add_argument("--locus-presses", type=int, default=5)
    parser.add_argument("--settled-speed-steps", action="store_true",
                        help="each speed step after the previous one's s0*(v) and verdict (2)")
    parser.add_argument("--drags", type=int, default=4,
                        help="mouse drags of s0 from 0.005 to 0.012 and back over 2 s each "
                             "(1 c: the previews while the handle is held)")
    parser.add_argument("--sessions", type=int, default=10)
    parser.add_argument("--concurrent-presses", type=int, default=5)
    parser.add_argument("--mixed-presses", type=int, default=20,
                        help="s0 steps of the page among protocol clients (4)")
    parser.add_argument("--skip-pages", action="store_true",
                        help="leave out 3 (ten Chromium pages)")
    parser.add_argument("--screenshots", action="store_true")
    parser.add_argument("--only-screenshots", action="store_true")
    parser.add_argument("--protocol-clients", metavar="URL", default=None,
                        help=argparse.SUPPRESS)  # internal: the load process of 4
    parser.add_argument("--json", default=None, help="write the raw numbers here")
    parser.add_argument("--url", default=None,
                        help="measure a running server (e.g. http://127.0.0.1:5006) instead of "
                             "starting one")
    args = parser.parse_args()
    if args.protocol_clients:
        protocol_clients(args.protocol_clients.rstrip("/"), args.sessions)
        return
    results = asyncio.run(run(args))
    if args.only_screenshots:
        return
    print(served_app.machine_yardstick())
    single = statistics.median(results["single_fast_s"])
    if results["single_isolated_s"]:
        isolated = results["single_isolated_s"]
        print(f"slider change, one at a time (session idle before each): median "
              f"{statistics.median(isolated) * 1e3:.0f} ms (n = {len(isolated)}, "
              f"max {max(isolated) * 1e3:.0f})")
    locus = statistics.median(results["locus_refresh_s"])
    print(f"slider change -> eigenvalues, status, time histories: median {single * 1e3:.0f} ms "
          f"(n = {len(results['single_fast_s'])}, max {max(results['single_fast_s']) * 1e3:.0f})")
    if results.get("single_status_s"):
        status = results["single_status_s"]
        print(f"slider change -> stability status on screen: median "
              f"{statistics.median(status) * 1e3:.0f} ms (n = {len(status)}, "
              f"max {max(status) * 1e3:.0f})")
    print(f"root-locus refresh (new speed): median {locus * 1e3:.0f} ms "
          f"(n = {len(results['locus_refresh_s'])}, max {max(results['locus_refresh_s']) * 1e3:.0f})")
    dense = results["dense_locus_s"]
    print(f"dense root locus (200 points) after a speed change: median "
          f"{statistics.median(dense) * 1e3:.0f} ms (n = {len(dense)}, max {max(dense) * 1e3:.0f})")
    if results.get("drags"):
        counts = [n for n, _ in results["drags"]]
        rates = [r for _, r in results["drags"]]
        print(f"s0 dragged 0.005 <-> 0.012 over 2 s: previews before the release median "
              f"{statistics.median(counts):.0f} (min {min(counts)}), "
              f"{statistics.median(rates):.1f} per second (min {min(rates):.1f}; n = {len(rates)})")
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1))
    errors = results["errors_single"] + results.get("errors_mixed", [])
    if "concurrent_fast_s" in results:
        errors += results["errors_concurrent"]
        report_pages_at_once(results, args.sessions, single)
    if "mixed_page_s" in results:
        report_page_among_clients(results, args.sessions, single)
    print(f"browser console errors: {len(errors)}")
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1))


def report_pages_at_once(results: dict, sessions: int, single: float) -> None:
    concurrent = statistics.median(results["concurrent_fast_s"])
    print(f"{sessions} concurrent sessions: median {concurrent * 1e3:.0f} ms "
          f"(n = {len(results['concurrent_fast_s'])}, "
          f"p90 {sorted(results['concurrent_fast_s'])[int(0.9 * len(results['concurrent_fast_s']))] * 1e3:.0f})"
          f" = {concurrent / single:.2f} x single")
    cpu = results["concurrent_cpu"]
    print(f"  during it ({cpu['wall_s']:.1f} s, {cpu['changes']} changes): server "
          f"{cpu['server_cpu_s']:.1f} CPU-s ({cpu['server_cpu_s'] / cpu['changes'] * 1e3:.0f} ms per "
          f"change), browsers {cpu['browser_cpu_s']:.1f} CPU-s "
          f"({cpu['browser_cpu_s'] / cpu['changes'] * 1e3:.0f} ms per change); capacity "
          f"{2 * cpu['wall_s']:.1f} CPU-s (2 cores)")


def report_page_among_clients(results: dict, sessions: int, single: float) -> None:
    mixed = statistics.median(results["mixed_page_s"])
    alone = statistics.median(results["alone_page_s"])
    clients = results["mixed_clients_s"]
    print(f"1 page alone (the same steps before the clients connect): median "
          f"{alone * 1e3:.0f} ms (n = {len(results['alone_page_s'])}, "
          f"max {max(results['alone_page_s']) * 1e3:.0f})")
    print(f"1 page + {sessions - 1} protocol clients: page median {mixed * 1e3:.0f} ms "
          f"(n = {len(results['mixed_page_s'])}, max {max(results['mixed_page_s']) * 1e3:.0f}) "
          f"= {mixed / alone:.2f} x alone ({mixed / single:.2f} x the single session's "
          f"back-to-back steps); clients median "
          f"{statistics.median(clients) * 1e3:.0f} ms (n = {len(clients)})")
    cpu = results["mixed_cpu"]
    print(f"  during it ({cpu['wall_s']:.1f} s): server {cpu['server_cpu_s']:.1f} CPU-s, its "
          f"background workers {cpu['background_cpu_s']:.1f} CPU-s, browser "
          f"{cpu['browser_cpu_s']:.1f} CPU-s, protocol clients {cpu['clients_cpu_s']:.1f} CPU-s")


if __name__ == "__main__":
    main()
