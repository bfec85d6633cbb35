"""The s0*(v) uncertainty band in the served Studies tab (headless Chromium).

A result of the calibrated set at the dashboard's default N0 and b_M (written by the model's
``UncertaintyResult.as_dict``, see tests/app/dashboard/test_uncertainty_band.py) into the server's studies
folder is picked by its name from the list (after ↻ made the list again); the
band's data reach the browser, the figure renders without console errors, and a result of
another wheel force shows the notice instead.  Screenshot: ``test-artifacts/uncertainty_band.png``.
"""

from __future__ import annotations

import pytest
from conftest import ROOT, SPEEDS, open_app, uncertainty_result_file

from app.results import compute

OUTPUT = ROOT / "test-artifacts"  # git-ignored
pytestmark = [pytest.mark.browser, pytest.mark.slow]

BAND = """() => {
  const source = Bokeh.documents[0].get_model_by_name('study-s0-band');
  const d = source.data;
  const v = d instanceof Map ? d.get('v') : d['v'];
  return Array.from(v);
}"""


def _open(page, name: str) -> None:
    page.locator(".study-refresh button").click()
    page.locator(".study-uncertainty option", has_text=name).wait_for(state="attached",
                                                                        timeout=30_000)
    page.locator(".study-uncertainty select").select_option(name)
    page.locator(".study-open-uncertainty button").click()


def test_band_is_drawn_and_a_mismatch_is_explained(own_server, chromium):
    OUTPUT.mkdir(exist_ok=True)
    parameters = compute.parameters("", "calibrated")
    studies = own_server[2]
    uncertainty_result_file(studies / "good.json", parameters)
    uncertainty_result_file(studies / "other.json", parameters.replace(wheel_force=120e3))
    # a server of its own: an earlier test in this process may have registered Panel models
    # whose scripts a page of the in-process server then asks a CDN for (vizzu.min.js, seen)
    page = open_app(chromium, own_server[0])
    page.locator(".stability-status", has_text="STABLE").wait_for(timeout=60_000)
    page.locator(".bk-tab", has_text="Studies").first.click()
    _open(page, "good.json")
    page.wait_for_function(f"() => ({BAND})().length === {len(SPEEDS)}", timeout=60_000)
    assert page.evaluate(BAND) == list(SPEEDS)
    page.locator(".study-band-status", has_text="posterior, n = 8").wait_for(timeout=30_000)
    page.wait_for_timeout(500)
    page.screenshot(path=str(OUTPUT / "uncertainty_band.png"), full_page=True)
    _open(page, "other.json")
    page.locator(".study-band-notice", has_text="wheel force N0: result 120 kN, screen 100 kN"
                 ).wait_for(timeout=30_000)
    page.wait_for_function(f"() => ({BAND})().length === 0", timeout=30_000)
    assert page.errors == [], page.errors
    page.close()
