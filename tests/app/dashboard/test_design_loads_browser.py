"""The Design loads tab in the served dashboard (headless Chromium, a ``bogie serve`` of its own
with a fresh studies folder): opened by its link (``tab=design-loads``) at the study's unstable
case, with nonlinear creep on the worst case over every fault instant and the nonlinear
history's load spectrum appear, a small grid envelope runs on the server's study engine and
its table links to the scenarios; no console errors.  A screenshot goes to test-artifacts/."""

from __future__ import annotations

import html
import re

import pytest
from conftest import ROOT

pytestmark = [pytest.mark.browser, pytest.mark.slow]

ARTIFACTS = ROOT / "test-artifacts"  # git-ignored
TEXT = """(cls) => { const m = [...Bokeh.documents[0].all_models]
  .find(m => (m.css_classes || []).includes(cls)); return m ? m.text || '' : ''; }"""
LENGTH = """(name, col) => { const d = Bokeh.documents[0].get_model_by_name(name).data;
  const v = d instanceof Map ? d.get(col) : d[col];
  return Array.from(v).filter(Number.isFinite).length; }"""
SET_MODEL = """([cls, value]) => {
  const m = [...Bokeh.documents[0].all_models].find(m => (m.css_classes || []).includes(cls));
  m.value = value; return true; }"""


def _text(page, css: str) -> str:
    """The HTML of a pane (its Bokeh model holds it escaped)."""
    return html.unescape(page.evaluate(TEXT, css))


def test_design_loads_tab_in_the_browser(own_server, chromium):
    url = own_server[0]
    page = chromium.new_page(viewport={"width": 1600, "height": 1000})
    errors: list[str] = []
    page.on("console", lambda m: errors.append(f"console: {m.text}") if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(f"pageerror: {e}"))
    ARTIFACTS.mkdir(exist_ok=True)
    try:
        page.goto(f"{url}/app?s0=0.014&v=120&tab=design-loads", timeout=180_000)
        page.wait_for_function("() => window.Bokeh && Bokeh.documents.length > 0",
                               timeout=180_000)
        page.locator(".stability-status", has_text="UNSTABLE").wait_for(timeout=180_000)
        active = page.locator(".bk-tab.bk-active").first.inner_text()
        assert active == "Design loads"
        # the worst case over every fault instant (linear closed form) at the point
        page.wait_for_function(f"() => ({TEXT})('loads-worst').includes('ID1 disc clutch')",
                               timeout=120_000)
        worst = _text(page, "loads-worst")
        assert re.search(r"ID1 driving shaft torque \[N m\]</td><td><b>[-0-9.,e+]+</b>", worst)
        assert "The operating point is unstable" in _text(page, "loads-worst-note")
        page.wait_for_function(f"() => ({LENGTH})('worst-case-ID1', 'upper') > 100",
                               timeout=60_000)
        # nonlinear creep on: the spectrum is the nonlinear history's, overlaid in red
        page.locator(".ctl-creep button", has_text="nonlinear").click()
        page.wait_for_function(
            f"() => ({TEXT})('loads-spectra-note').includes('nonlinear creep, anti-slip off')",
            timeout=180_000)
        spectra = _text(page, "loads-spectra")
        assert re.search(r"ID2 disc clutch torque \[N m\]</td><td>[0-9.]+</td>", spectra)
        page.wait_for_function(f"() => ({LENGTH})('worst-case-nonlinear-ID2', 'y') > 100",
                               timeout=60_000)
        page.wait_for_function(f"() => ({LENGTH})('collective-ID1', 'H') > 1", timeout=60_000)
        # a small grid envelope (2 x 2 points, continuity roots, nonlinear creep) on the server
        page.evaluate(SET_MODEL, ["loads-range-x", [0.008, 0.014]])
        for css in ("loads-points-x", "loads-points-y"):
            box = page.locator(f".{css} input")
            box.fill("2")
            box.press("Enter")
        page.wait_for_timeout(800)
        page.locator(".loads-start button").click()
        page.wait_for_function(f"() => /^(waiting|running|done)/.test(({TEXT})('loads-status'))",
                               timeout=60_000)
        # with nonlinear creep a chunk is one scenario: 2 x 2 points x 2 continuity roots
        page.wait_for_function(f"() => ({TEXT})('loads-status').startsWith('done: 8/8')",
                               timeout=600_000)
        page.wait_for_function(f"() => ({TEXT})('loads-envelope-table').includes('open')",
                               timeout=60_000)
        table = _text(page, "loads-envelope-table")
        assert "8 scenarios" in _text(page, "loads-status")
        links = re.findall(r"href='\?([^']+)'", table)
        assert len(links) == 16  # max and min of 8 drive parts
        assert all("tab=response" in link and "s0=" in link for link in links)
        assert str(own_server[2]) not in table + _text(page, "loads-status")  # no server path
        # the cells the browser drew are the store's envelope
        from app.dashboard.envelope_grid import envelope_rows, read_envelope

        stores = [p for p in own_server[2].iterdir() if (p / "zarr.json").is_file()]
        assert len(stores) == 1, stores
        envelope = envelope_rows(read_envelope(stores[0], stores[0].name))
        drawn = [cells for cells in (tr.locator("td").all_inner_texts() for tr in
                                     page.locator(".loads-envelope-table table tr").all())
                 if cells]
        assert len(drawn) == len(envelope.outputs)
        for cells, output in zip(drawn, envelope.outputs, strict=True):
            assert cells[0].endswith(f"[{output.unit}]")
            for cell, value in ((cells[1], output.max), (cells[3], output.min)):
                # printed as "1,234" (to 0.5) or "1.234e+07" (to 4 digits)
                assert abs(float(cell.replace(",", "")) - value) <= max(0.51, 5e-4 * abs(value))
            assert f"s0 = {output.max_at['s0']:.5g}" in cells[2]
        page.wait_for_timeout(1500)  # the heat map drawn
        page.screenshot(path=str(ARTIFACTS / "design_loads_tab.png"), full_page=True)
        assert errors == [], errors
    except BaseException:
        page.screenshot(path=str(ARTIFACTS / "design_loads_tab_failed.png"), full_page=True)
        raise
    finally:
        page.close()
