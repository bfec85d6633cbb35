"""The Design loads tab's screenshot, taken from the served app in headless Chromium.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/screenshot_design_loads.py \
        [--out assets/screenshots/tab_design_loads.png]

``bogie serve`` on a free port with a fresh studies folder; the page opens at the study's
unstable case (``?s0=0.014&v=120&tab=design-loads``), switches the nonlinear creep model on
(the worst case over every fault instant is the linear closed form, the load spectrum then that
of the nonlinear history), runs a small grid envelope on the server's study engine (s0 × v,
4 × 3 points, nonlinear creep, continuity roots: 24 nonlinear runs) and saves the whole page.
About a minute on two cores.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))
import served_app  # noqa: E402 - the scripts' own helpers

CHROMIUM = "/usr/bin/chromium"
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync"]
SET_MODEL = """([cls, value]) => {
  const m = [...Bokeh.documents[0].all_models].find(m => (m.css_classes || []).includes(cls));
  m.value = value; return true; }"""
TEXT = """(cls) => { const m = [...Bokeh.documents[0].all_models]
  .find(m => (m.css_classes || []).includes(cls)); return m ? m.text || '' : ''; }"""


def design_loads_page(browser, url: str, grid: bool = True, timeout_ms: float = 600_000):
    """A page of the app at s0 = 0.014, 120 km/h on the Design loads tab, nonlinear creep on,
    the worst case and the nonlinear history's spectrum shown and (``grid``) a 4 x 3 grid
    envelope done; ``page.errors`` holds console errors and page errors."""
    page = browser.new_page(viewport={"width": 1600, "height": 1000})
    page.errors = []
    page.on("console", lambda m: page.errors.append(f"console: {m.text}")
            if m.type == "error" else None)
    page.on("pageerror", lambda e: page.errors.append(f"pageerror: {e}"))
    page.goto(f"{url}/app?s0=0.014&v=120&tab=design-loads", timeout=timeout_ms)
    page.wait_for_function("() => window.Bokeh && Bokeh.documents.length > 0",
                           timeout=timeout_ms)
    page.locator(".stability-status", has_text="UNSTABLE").wait_for(timeout=timeout_ms)
    page.locator(".ctl-creep button", has_text="nonlinear").click()
    page.wait_for_function(f"() => ({TEXT})('loads-spectra-note').includes('nonlinear creep')",
                           timeout=timeout_ms)
    page.wait_for_function(f"() => ({TEXT})('loads-worst').includes('fault instant')",
                           timeout=timeout_ms)
    if grid:
        page.evaluate(SET_MODEL, ["loads-range-x", [0.006, 0.015]])
        page.evaluate(SET_MODEL, ["loads-range-y", [80.0, 160.0]])
        for css, value in (("loads-points-x", "4"), ("loads-points-y", "3")):
            box = page.locator(f".{css} input")
            box.fill(value)
            box.press("Enter")
        page.wait_for_timeout(800)
        page.locator(".loads-start button").click()
        page.wait_for_function(f"() => ({TEXT})('loads-status').startsWith('done')",
                               timeout=timeout_ms)
        page.wait_for_function(f"() => ({TEXT})('loads-envelope-table').includes('open')",
                               timeout=timeout_ms)
    page.wait_for_timeout(3000)  # the last changes drawn
    return page


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(ROOT / "assets" / "screenshots"
                                             / "tab_design_loads.png"))
    args = parser.parse_args()
    from playwright.sync_api import sync_playwright

    port = served_app.free_port()
    server = served_app.start_server(port, "screenshot_design_loads")
    try:
        with sync_playwright() as playwright:
            browser = playwright.chromium.launch(executable_path=CHROMIUM, args=ARGS)
            page = design_loads_page(browser, f"http://127.0.0.1:{port}")
            page.screenshot(path=args.out, full_page=True)
            if page.errors:
                print("page errors:", *page.errors, sep="\n  ", file=sys.stderr)
            browser.close()
    finally:
        server.terminate()
        server.wait(timeout=60)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
