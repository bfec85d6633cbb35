"""The served dashboard in headless Chromium (Debian's /usr/bin/chromium via Playwright).

The page loads, the plots on screen render, the browser console stays free of errors, and switching
from the published stable case (s0 = 0.005) to the unstable one (s0 = 0.014) flips the status
and changes the plots; screenshots go to ``test-artifacts/`` (the README's screenshots are made
by ``scripts/bench_app.py --screenshots``).
"""

from __future__ import annotations

import pytest
from conftest import ROOT, open_app

OUTPUT = ROOT / "test-artifacts"  # git-ignored
pytestmark = [pytest.mark.browser, pytest.mark.slow]

# JS: fingerprint of what a change must update (eigenvalues on the locus, time histories)
FINGERPRINT = """() => {
  const doc = Bokeh.documents[0];
  const get = (name, col) => { const d = doc.get_model_by_name(name).data;
                                const v = d instanceof Map ? d.get(col) : d[col];
                                return Array.from(v).slice(0, 40).join(','); };
  return get('locus_current', 'x') + '|' + get('response', 'y:ID1.disc_clutch.torque');
}"""
PLOTS = """() => {
  const doc = Bokeh.documents[0];
  const plots = [...doc.all_models].filter(m => m.type === 'Figure' || m.type === 'Plot');
  return plots.length;
}"""


def status_text(page) -> str:
    return page.locator(".stability-status").inner_text(timeout=60_000)


def test_page_loads_plots_render_and_published_cases_flip(app_server, chromium):
    OUTPUT.mkdir(exist_ok=True)
    page = open_app(chromium, app_server)
    page.locator(".stability-status", has_text="STABLE").wait_for(timeout=60_000)
    # only the open tab is in the browser (dynamic tabs): the locus and the Response tab's
    # creep, 2 torques, forces, M_C, each drawn on a canvas with a size
    assert page.evaluate(PLOTS) == 6
    sizes = page.locator("canvas").evaluate_all("cs => cs.map(c => c.width * c.height)")
    assert sum(1 for s in sizes if s > 0) >= 6
    # the other tabs' plots arrive when their tab is opened: 2 mode views, Fig. 6 (3), variant
    # s0*(v), sensitivity tornado, study heat map
    for title, plots in (("Fig. 6", 9), ("Modes", 11), ("Variant", 12), ("Sensitivity", 13),
                         ("Studies", 14)):
        page.locator(".bk-tab", has_text=title).first.click()
        page.wait_for_function(f"() => ({PLOTS})() === {plots}", timeout=60_000)
    page.locator(".bk-tab", has_text="Response").first.click()

    page.locator(".case-stable button").click()
    page.locator(".stability-status", has_text="STABLE").wait_for(timeout=60_000)
    page.wait_for_timeout(500)
    assert "UNSTABLE" not in status_text(page)
    stable = page.evaluate(FINGERPRINT)
    page.screenshot(path=str(OUTPUT / "stable.png"), full_page=True)

    page.locator(".case-unstable button").click()
    page.locator(".stability-status", has_text="UNSTABLE").wait_for(timeout=60_000)
    page.wait_for_function(f"() => ({FINGERPRINT})() !== {stable!r}", timeout=60_000)
    page.screenshot(path=str(OUTPUT / "unstable.png"), full_page=True)
    assert (OUTPUT / "unstable.png").stat().st_size > 10_000

    assert page.errors == [], page.errors
    page.close()


def test_keyboard_on_the_s0_slider_is_a_real_input(app_server, chromium):
    page = open_app(chromium, app_server)
    page.locator(".stability-status", has_text="STABLE").wait_for(timeout=60_000)
    before = page.evaluate(FINGERPRINT)
    handle = page.locator(".ctl-s0 .noUi-handle")
    handle.focus()
    handle.press("ArrowRight")
    page.wait_for_function(f"() => ({FINGERPRINT})() !== {before!r}", timeout=60_000)
    assert page.errors == [], page.errors
    page.close()
