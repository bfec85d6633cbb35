"""Dashboard latency of the nonlinear creep model in a real browser (target: the
nonlinear result on screen ≤ 1.5 s after a change, median; the linear path still ≤ 300 ms).

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/bench_nonlinear_app.py [--presses 12]

Starts ``bogie serve`` (helpers of ``scripts/bench_app.py``), opens one headless Chromium page,
switches the creep model to nonlinear, settles on its own wheel force (nothing cached), then
presses keyboard steps (PageUp: 0.0005) on the s0 slider.  Per press, two latencies from the key press: until the
linear result is in the browser (new eigenvalues and new linear time histories, as
``bench_app.py`` measures) and until the nonlinear histories have changed too.  Prints medians
and the single values; the machine is shared (say so when quoting).
"""

from __future__ import annotations

import argparse
import asyncio
import json
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import served_app
from bench_app import (
    ARGS,
    CHROMIUM,
    DATA,
    FAST,
    S0_KEY,
    free_port,
    log,
    open_page,
    settle_n0,
    start_server,
    wait_settled,
)

NONLINEAR = f"() => ({DATA})('nonlinear', 'y:ID1.disc_clutch.torque')"


async def press(page, key: str = S0_KEY, timeout: float = 120_000) -> tuple[float, float]:
    """(seconds to the linear result, seconds to the nonlinear result) of one s0 step."""
    fast_before = (await page.evaluate(FAST)).split("|")
    slow_before = await page.evaluate(NONLINEAR)
    handle = page.locator(".ctl-s0 .noUi-handle")
    await handle.focus()
    t0 = time.perf_counter()
    await handle.press(key)
    await page.wait_for_function(
        f"() => {{ const now = ({FAST})().split('|'); const before = {json.dumps(fast_before)};"
        " return now.every((part, i) => part !== before[i]); }", polling=5, timeout=timeout)
    t_fast = time.perf_counter() - t0
    await page.wait_for_function(
        f"() => ({NONLINEAR})() !== {json.dumps(slow_before)}", polling=5, timeout=timeout)
    return t_fast, time.perf_counter() - t0


async def run(args) -> dict:
    from playwright.async_api import async_playwright

    port = free_port()
    server = start_server(port)
    url = f"http://127.0.0.1:{port}"
    try:
        async with async_playwright() as p:
            browser = await p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
            page = await open_page(browser, url)
            log("switching to nonlinear creep")
            await page.locator(".ctl-creep button", has_text="nonlinear").click()
            await page.wait_for_function(f"() => ({NONLINEAR})().length > 0", timeout=120_000)
            await settle_n0(page, 1)
            await wait_settled(page)  # the N0 change's dense root locus and s0*(v)
            await page.wait_for_timeout(2000)  # and its nonlinear history
            times = [await press(page) for _ in range(args.presses)]
            errors = list(page.errors)
            await browser.close()
    finally:
        server.terminate()
        server.wait(timeout=30)
    return {"linear_s": [a for a, _ in times], "nonlinear_s": [b for _, b in times],
            "errors": errors}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--presses", type=int, default=12)
    args = parser.parse_args()
    results = asyncio.run(run(args))
    linear, nonlinear = results["linear_s"], results["nonlinear_s"]
    print(served_app.machine_yardstick())
    print(f"one session, {args.presses} s0 steps with the creep model on nonlinear:")
    print(f"  linear result on screen:    median {1e3 * statistics.median(linear):.0f} ms "
          f"(min {1e3 * min(linear):.0f}, max {1e3 * max(linear):.0f})")
    print(f"  nonlinear result on screen: median {1e3 * statistics.median(nonlinear):.0f} ms "
          f"(min {1e3 * min(nonlinear):.0f}, max {1e3 * max(nonlinear):.0f})")
    print(f"  browser console errors: {len(results['errors'])}")
    print(json.dumps(results))


if __name__ == "__main__":
    main()
