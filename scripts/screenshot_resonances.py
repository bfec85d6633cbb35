"""The Resonances tab's screenshot, taken from the served app in headless Chromium.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python scripts/screenshot_resonances.py \
        [--out assets/screenshots/tab_resonances.png]

``bogie serve`` on a free port; the page opens at the study's stable case on the Resonances tab
(``?s0=0.005&v=120&tab=resonances``), waits for the Campbell diagram with its crossings, the
frequency response, the forced response and the random track's PSD, types the illustrative wheel
polygon ``20=30`` (order 20, 30 µm: docs/resonance.md, no measured amplitude) and waits for its
response, and saves the whole page (≈ 2 min on two cores).
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
TEXT = """(cls) => { const m = [...Bokeh.documents[0].all_models]
  .find(m => (m.css_classes || []).includes(cls)); return m ? m.text || '' : ''; }"""
LENGTH = """([name, col]) => { const d = Bokeh.documents[0].get_model_by_name(name).data;
  const v = d instanceof Map ? d.get(col) : d[col]; return v ? v.length : 0; }"""
POLYGON = "20=30"  # the illustrative polygon of docs/resonance.md's examples


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(ROOT / "assets" / "screenshots"
                                             / "tab_resonances.png"))
    args = parser.parse_args()
    from playwright.sync_api import sync_playwright

    port = served_app.free_port()
    server = served_app.start_server(port, "screenshot_resonances")
    timeout = 600_000
    try:
        with sync_playwright() as playwright:
            browser = playwright.chromium.launch(executable_path=CHROMIUM, args=ARGS)
            page = browser.new_page(viewport={"width": 1600, "height": 1000})
            errors: list[str] = []
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.goto(f"http://127.0.0.1:{port}/app?s0=0.005&v=120&tab=resonances",
                      timeout=timeout)
            page.wait_for_function("() => window.Bokeh && Bokeh.documents.length > 0",
                                   timeout=timeout)
            page.wait_for_function(f"() => ({TEXT})('resonance-crossings').includes('Crossings')",
                                   timeout=timeout)
            page.wait_for_function(f"() => ({LENGTH})(['ripple', 'label']) > 0",
                                   timeout=timeout)
            page.wait_for_function(f"() => ({LENGTH})(['track', 'psd']) > 0", timeout=timeout)
            polygon = page.locator(".ctl-resonance-polygon input")
            polygon.fill(POLYGON)
            polygon.press("Enter")
            page.wait_for_function(f"() => ({LENGTH})(['polygon', 'label']) > 0",
                                   timeout=timeout)
            page.wait_for_timeout(3000)  # the last changes drawn
            page.screenshot(path=args.out, full_page=True)
            if errors:
                print("page errors:", *errors, sep="\n  ", file=sys.stderr)
            browser.close()
    finally:
        server.terminate()
        server.wait(timeout=60)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
