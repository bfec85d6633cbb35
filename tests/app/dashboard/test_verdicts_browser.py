"""The verdict indicator beside the stability status and the Verdicts tab, served and in
headless Chromium (one page load): the indicator shows the governing safety factor with its
colour, the tab lists all 48 checks and draws the bar chart, a row opens the Response tab at the
operating point of its load; on the same first screen the peak table gives ID1's disc clutch
swing with its time after the fault and its quasi-static and dynamic parts."""

from __future__ import annotations

import html
import re

import pytest
from conftest import open_app

pytestmark = [pytest.mark.browser, pytest.mark.slow]
TEXT = """(cls) => { const m = [...Bokeh.documents[0].all_models]
  .find(m => (m.css_classes || []).includes(cls)); return m ? m.text || '' : ''; }"""


def test_verdict_indicator_and_view(app_server, chromium):
    page = open_app(chromium, app_server)
    box = page.locator(".verdict-status [data-verdict]")
    box.wait_for(timeout=180_000)
    colour = box.get_attribute("data-verdict")
    assert colour in ("green", "amber", "red")
    detail = re.sub(r"<[^>]+>", "", html.unescape(page.evaluate(TEXT, "verdict-status")))
    factor = float(re.search(r"governing safety factor\s*([0-9.e+-]+)", detail).group(1))
    required = float(re.search(r"required\s*([0-9.e+-]+)", detail).group(1))
    # the colour follows the factor against the required one
    assert colour == ("green" if factor >= required else "amber" if factor >= 1 else "red")
    # the peak table of the first screen (the stable default point): the swing, not the
    # pre-fault value at 0 s, and its split
    peaks = html.unescape(page.evaluate(TEXT, "peak-table"))
    assert "quasi-static at" in peaks
    row = peaks.split(">ID1.disc_clutch.torque [kN m]<")[1].split("</tr>")[0]
    cells = re.findall(r"<td[^>]*>([^<]*)</td>", row)
    assert float(cells[6]) > 0.0  # the swing's time [s]
    page.get_by_text("Verdicts", exact=True).click()
    rows = page.locator(".verdict-table .tabulator-row")
    rows.first.wait_for(timeout=60_000)
    assert rows.count() >= 10  # the table is virtual: the first rows are rendered
    first = rows.first.inner_text()
    assert any(case in first for case in ("short_circuit", "starting", "unstable_adhesion",
                                          "ripple"))
    page.wait_for_function(
        "() => [...Bokeh.documents[0].all_models].some(m => m.name === 'verdict-bars')",
        timeout=60_000)
    rows.filter(has_text="short_circuit").first.click()  # a starting row has no history
    page.locator(".bk-tab.bk-active", has_text="Response").wait_for(timeout=30_000)
    assert page.errors == []


def test_the_verdict_is_answered_when_the_root_locus_is_rejected(app_server, chromium,
                                                                 monkeypatch):
    """The verdict starts from the state change, not from another view's answer: when the
    model rejects the coarse root locus of a state (its follow-ups never run), the indicator
    still gets its verdict instead of saying "computing…" until the next change."""
    from app.dashboard import stages
    from model import OperatingPointError

    coarse = stages.coarse_locus

    def rejected_at_145(sweep):
        if sweep.case.v == 145.0:
            raise OperatingPointError("the root locus at 145 km/h is rejected (test)")
        return coarse(sweep)

    monkeypatch.setattr(stages, "coarse_locus", rejected_at_145)
    page = chromium.new_page(viewport={"width": 1600, "height": 1000})
    try:
        page.goto(f"{app_server}/app?v=145", timeout=120_000)
        page.wait_for_function("() => window.Bokeh && Bokeh.documents.length > 0",
                               timeout=120_000)
        notice = page.locator(".model-notice", has_text="rejected (test)")
        notice.wait_for(timeout=120_000)
        box = page.locator(".verdict-status [data-verdict]")
        box.wait_for(timeout=180_000)
        assert box.get_attribute("data-verdict") in ("green", "amber", "red")
    finally:
        page.close()
