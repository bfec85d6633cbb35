"""Measure the dashboard in a real browser (headless Debian Chromium via Playwright).

    .venv/bin/python scripts/bench_app.py [--presses 15] [--sessions 10] [--screenshots]

Starts ``bogie serve`` on a free port (a separate process, as users run it), then:

1. single session: keyboard steps on the s0 slider handle (each a new value, so no cache
   hit); latency = key press → the browser holds new eigenvalues (root-locus current point)
   *and* new time histories (both must have changed; the status is sent with the eigenvalues);
2. root-locus refresh: keyboard steps on the speed slider (new v → new s0*(v) and a new locus
   over s0); latency = key press → new locus branches in the browser;
3. ``--sessions`` pages at once, each with its own wheel force N0 (so no session profits from
   another's cache), pressing s0 steps at random moments (0.3–1.5 s apart);
4. ``--screenshots``: assets/screenshots/stable.png and unstable.png (published cases).

Prints medians and writes the numbers as JSON (``--json FILE``).
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import random
import socket
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CHROMIUM = "/usr/bin/chromium"
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync"]
DATA = """(name, col) => { const d = Bokeh.documents[0].get_model_by_name(name).data;
  const v = d instanceof Map ? d.get(col) : d[col]; return Array.from(v).slice(0, 60).join(','); }"""
FAST = f"() => ({DATA})('locus_current', 'x') + '|' + ({DATA})('response:ID1.disc_clutch.torque', 'y')"
SLOW = f"() => ({DATA})('locus_points', 'x')"


def log(message: str) -> None:
    print(f"bench_app: {time.strftime('%H:%M:%S')} {message}", file=sys.stderr, flush=True)


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


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_server(port: int) -> subprocess.Popen:
    server_log = Path(tempfile.gettempdir()) / f"bench_app_server_{port}.log"
    log(f"server log: {server_log}")
    process = subprocess.Popen([str(ROOT / ".venv/bin/bogie"), "serve", "--port", str(port)],
                               cwd=ROOT, stdout=subprocess.DEVNULL,
                               stderr=server_log.open("w"))
    deadline = time.monotonic() + 180
    while time.monotonic() < deadline:
        try:
            with urllib.request.urlopen(f"http://127.0.0.1:{port}/liveness?endpoint=/app",
                                        timeout=120) as r:
                if r.status == 200:
                    return process
        except OSError:
            time.sleep(0.5)
    process.kill()
    raise SystemExit("bench_app: the server did not come up")


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
    return page


async def step(page, control: str, key: str, probe: str, timeout: float = 120_000) -> float:
    """Seconds from a key press on a slider handle until ``probe`` changed in the browser."""
    before = (await page.evaluate(probe)).split("|")
    handle = page.locator(f".{control} .noUi-handle")
    await handle.focus()
    t0 = time.perf_counter()
    await handle.press(key)
    # every part of the probe must have changed (eigenvalues AND time histories): they may
    # arrive in separate messages
    await page.wait_for_function(
        f"() => {{ const now = ({probe})().split('|'); const before = {json.dumps(before)};"
        " return now.every((part, i) => part !== before[i]); }", polling=5, timeout=timeout)
    return time.perf_counter() - t0


async def wait_idle(page) -> None:
    """Let the session's background stage (s0*, root locus) finish."""
    await page.wait_for_function(f"() => ({SLOW})().length > 0", timeout=300_000)
    await asyncio.sleep(2.0)


async def settle_n0(page, presses: int) -> None:
    for _ in range(presses):
        await step(page, "ctl-N0", "ArrowLeft", SLOW, timeout=300_000)


async def screenshots(browser, url: str) -> None:
    out = ROOT / "assets" / "screenshots"
    out.mkdir(parents=True, exist_ok=True)
    page = await open_page(browser, url)
    for case in ("stable", "unstable"):
        await page.locator(f".case-{case} button").click()
        word = "UNSTABLE" if case == "unstable" else "STABLE"
        await page.locator(".stability-status", has_text=word).wait_for()
        await wait_idle(page)
        await page.screenshot(path=str(out / f"{case}.png"), full_page=True)
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
            log("single session: s0 steps, then speed steps")  # own N0 = 99 kN: nothing cached from earlier runs
            fast = [await step(page, "ctl-s0", "ArrowRight", FAST) for _ in range(args.presses)]
            slow = [await step(page, "ctl-v", "ArrowRight", SLOW)
                    for _ in range(args.locus_presses)]
            results["single_fast_s"] = fast
            results["locus_refresh_s"] = slow
            results["errors_single"] = list(page.errors)
            await page.close()
            # 3: concurrent sessions, each with its own N0 (no shared cache hits)
            if args.sessions == 0:
                return results
            log(f"{args.sessions} sessions: opening the pages")
            pages = [await open_page(browser, url) for _ in range(args.sessions)]
            log(f"{args.sessions} sessions: own wheel forces")
            await asyncio.gather(*(settle_n0(pg, 2 + i) for i, pg in enumerate(pages)))
            for pg in pages:
                await wait_idle(pg)

            async def session(pg, seed):
                rng = random.Random(seed)
                out = []
                for _ in range(args.concurrent_presses):
                    await asyncio.sleep(rng.uniform(0.3, 1.5))
                    out.append(await step(pg, "ctl-s0", "ArrowRight", FAST))
                return out

            log(f"{args.sessions} sessions: s0 steps")
            cpu_server, cpu_browser = cpu_seconds("bogie serve"), cpu_seconds("chrom")
            began = time.perf_counter()
            latencies = await asyncio.gather(*(session(pg, i) for i, pg in enumerate(pages)))
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
            if args.screenshots:
                await screenshots(browser, url)
            await browser.close()
    finally:
        if server is not None:
            server.terminate()
            server.wait(timeout=30)
    return results


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--presses", type=int, default=15)
    parser.add_argument("--locus-presses", type=int, default=5)
    parser.add_argument("--sessions", type=int, default=10)
    parser.add_argument("--concurrent-presses", type=int, default=5)
    parser.add_argument("--screenshots", action="store_true")
    parser.add_argument("--only-screenshots", action="store_true")
    parser.add_argument("--json", default=None, help="write the raw numbers here")
    parser.add_argument("--url", default=None,
                        help="measure a running server (e.g. http://127.0.0.1:5006) instead of "
                             "starting one")
    args = parser.parse_args()
    results = asyncio.run(run(args))
    if args.only_screenshots:
        return
    single = statistics.median(results["single_fast_s"])
    locus = statistics.median(results["locus_refresh_s"])
    print(f"slider change -> eigenvalues, status, time histories: median {single * 1e3:.0f} ms "
          f"(n = {len(results['single_fast_s'])}, max {max(results['single_fast_s']) * 1e3:.0f})")
    print(f"root-locus refresh (new speed): median {locus * 1e3:.0f} ms "
          f"(n = {len(results['locus_refresh_s'])}, max {max(results['locus_refresh_s']) * 1e3:.0f})")
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1))
    if "concurrent_fast_s" not in results:
        print(f"browser console errors: {len(results['errors_single'])}")
        return
    concurrent = statistics.median(results["concurrent_fast_s"])
    print(f"{args.sessions} concurrent sessions: median {concurrent * 1e3:.0f} ms "
          f"(n = {len(results['concurrent_fast_s'])}, "
          f"p90 {sorted(results['concurrent_fast_s'])[int(0.9 * len(results['concurrent_fast_s']))] * 1e3:.0f})"
          f" = {concurrent / single:.2f} x single")
    cpu = results["concurrent_cpu"]
    print(f"  during it ({cpu['wall_s']:.1f} s, {cpu['changes']} changes): server "
          f"{cpu['server_cpu_s']:.1f} CPU-s ({cpu['server_cpu_s'] / cpu['changes'] * 1e3:.0f} ms per "
          f"change), browsers {cpu['browser_cpu_s']:.1f} CPU-s "
          f"({cpu['browser_cpu_s'] / cpu['changes'] * 1e3:.0f} ms per change); capacity "
          f"{2 * cpu['wall_s']:.1f} CPU-s (2 cores)")
    print(f"browser console errors: {len(results['errors_single']) + len(results['errors_concurrent'])}")
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
