"""The Resonances tab in the served dashboard (headless Chromium): opened by its link
(``tab=resonances``), the Campbell diagram, its crossings table, the FRF and the forced response
arrive, and the random track's PSD with its source; a wheel polygon typed in gives its forced
response over speed, a bad one the notice (the response kept); a bad order typed in gives the
notice and keeps the diagram; a tapped point of the driving-shaft mode opens the Modes tab on
that mode; no console errors.  A screenshot goes to
test-artifacts/."""

from __future__ import annotations

import html

import pytest
from conftest import ROOT

pytestmark = [pytest.mark.browser, pytest.mark.slow]

ARTIFACTS = ROOT / "test-artifacts"  # git-ignored
TEXT = """(cls) => { const m = [...Bokeh.documents[0].all_models]
  .find(m => (m.css_classes || []).includes(cls)); return m ? m.text || '' : ''; }"""
COLUMN = """([name, col]) => { const d = Bokeh.documents[0].get_model_by_name(name).data;
  const v = d instanceof Map ? d.get(col) : d[col]; return Array.from(v); }"""
TAP = """(index) => { Bokeh.documents[0].get_model_by_name('campbell-modes').selected.indices =
  [index]; return true; }"""


def _text(page, css: str) -> str:
    return html.unescape(page.evaluate(TEXT, css))


def test_resonances_tab_in_the_browser(app_server, chromium):
    page = chromium.new_page(viewport={"width": 1600, "height": 1000})
    errors: list[str] = []
    page.on("console", lambda m: errors.append(f"console: {m.text}") if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(f"pageerror: {e}"))
    ARTIFACTS.mkdir(exist_ok=True)
    try:
        page.goto(f"{app_server}/app?s0=0.005&v=120&tab=resonances", timeout=180_000)
        page.wait_for_function("() => window.Bokeh && Bokeh.documents.length > 0",
                               timeout=180_000)
        assert page.locator(".bk-tab.bk-active").first.inner_text() == "Resonances"
        page.wait_for_function(f"() => ({TEXT})('resonance-crossings').includes('Crossings')",
                               timeout=300_000)
        assert "twisting of driving shaft 1" in _text(page, "resonance-crossings")
        names = page.evaluate(COLUMN, ["campbell-modes", "name"])
        assert len(names) > 100
        assert len(page.evaluate(COLUMN, ["campbell-crossings", "v"])) > 3
        page.wait_for_function(f"() => ({COLUMN})(['frf', 'f']).length > 2000", timeout=120_000)
        page.wait_for_function(f"() => ({COLUMN})(['ripple', 'label']).length == 3",
                               timeout=120_000)
        # the random track's PSD at this point (a minute or two on two cores), its source named
        page.wait_for_function(f"() => ({COLUMN})(['track', 'psd']).length > 100",
                               timeout=600_000)
        assert "Guo" in _text(page, "resonance-track-source")
        assert all(x > 0 for x in page.evaluate(COLUMN, ["track", "psd"]))
        # a wheel polygon: its response over speed (the sum and the one order)
        polygon = page.locator(".ctl-resonance-polygon input")
        polygon.fill("20=30")
        polygon.press("Enter")
        page.wait_for_function(f"() => ({COLUMN})(['polygon', 'label']).length == 2",
                               timeout=600_000)
        assert page.evaluate(COLUMN, ["polygon", "label"])[1] == "order 20: 30 µm"
        page.wait_for_timeout(1000)
        page.screenshot(path=str(ARTIFACTS / "resonances_tab.png"), full_page=True)
        # a bad polygon: the notice, the response kept
        polygon.fill("20=")
        polygon.press("Enter")
        page.locator(".input-notice", has_text="previous settings are kept").wait_for(
            timeout=60_000)
        assert page.evaluate(COLUMN, ["polygon", "label"])[1] == "order 20: 30 µm"
        polygon.fill("20=30")  # taken again: the notice goes
        polygon.press("Enter")
        page.locator(".input-notice", has_text="previous settings are kept").wait_for(
            state="hidden", timeout=60_000)
        # a negative order: the notice, the diagram kept
        box = page.locator(".ctl-resonance-orders input")
        box.fill("el:-6")
        box.press("Enter")
        page.locator(".input-notice", has_text="previous settings are kept").wait_for(
            timeout=60_000)
        assert len(page.evaluate(COLUMN, ["campbell-modes", "name"])) == len(names)
        # a tap on the driving-shaft mode of ID1: the Modes tab shows it
        index = next(i for i, name in enumerate(names) if "twisting of driving shaft 1" in name)
        page.evaluate(TAP, index)
        page.locator(".bk-tab.bk-active", has_text="Modes").wait_for(timeout=60_000)
        page.wait_for_function(
            f"() => ({TEXT})('mode-detail').includes('tapped on the Campbell diagram')",
            timeout=60_000)
        assert "driving shaft 1" in _text(page, "mode-detail")
        assert errors == [], errors
    except BaseException:
        page.screenshot(path=str(ARTIFACTS / "resonances_tab_failed.png"), full_page=True)
        raise
    finally:
        page.close()
