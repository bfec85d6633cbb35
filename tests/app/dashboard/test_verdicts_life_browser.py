"""The Verdicts tab's life column and damage plot as the browser draws them (served, headless
Chromium; one page): once the life over the bundled route is computed (in the background, after
the verdict), every shaft section's fatigue row shows the life the session's view holds — text
exactly, and the number within the printed precision of the view's life in km; the damage-over-
speed plot is drawn; the "running case" checkbox adds the running case's rows.  A screenshot of
the tab is written to the test's temporary folder.

The page opens with a simulated time no other served test uses (``T_END``), so that the
session's dashboard is found among the server's live sessions by its state.  The life over the
whole bundled route takes one to three minutes on a busy 2-core machine: the waits are long."""

from __future__ import annotations

import pytest
from conftest import live_dashboards, open_app, until

from app.results.life import FATIGUE_CHECK

pytestmark = [pytest.mark.browser, pytest.mark.slow]

T_END = 2.7  # the page's simulated time [s]: this module's session among the server's
LIFE_WAIT_S = 900.0  # the life over the bundled route, and the running case [s]
TEXT = """(cls) => { const m = [...Bokeh.documents[0].all_models]
  .find(m => (m.css_classes || []).includes(cls)); return m ? m.text || '' : ''; }"""
ROWS = """(holder) => [...holder.querySelectorAll('.tabulator-row')].map(
    row => Object.fromEntries([...row.querySelectorAll('.tabulator-cell')].map(
        c => [c.getAttribute('tabulator-field'), c.innerText])))"""


def _dashboard():
    found = live_dashboards(T_END)
    return found[0] if len(found) == 1 else None


def rendered_rows(page) -> dict[tuple, dict]:
    """Every row of the Verdicts table as drawn, by (component, check, load case): the table is
    virtual (only the rows in view exist), so it is scrolled through; {} if the table is redrawn
    meanwhile (the caller asks again)."""
    from playwright.sync_api import Error

    holder = page.locator(".verdict-table .tabulator-tableholder")
    rows: dict[tuple, dict] = {}
    try:
        height = holder.evaluate("h => h.scrollHeight", timeout=10_000)
        for top in range(0, int(height) + 200, 150):
            holder.evaluate("(h, y) => { h.scrollTop = y }", top, timeout=10_000)
            page.wait_for_timeout(100)
            for cells in holder.evaluate(ROWS, timeout=10_000):
                if "component" in cells:
                    rows[(cells["component"], cells["check"], cells["load case"])] = cells
        holder.evaluate("h => { h.scrollTop = 0 }", timeout=10_000)
    except Error:
        return {}
    return rows


def test_life_cells_show_the_life_computed(app_server, chromium, tmp_path):
    page = open_app(chromium, app_server, timeout_ms=180_000, query=f"t_end={T_END}")
    try:
        page.get_by_text("Verdicts", exact=True).click()
        page.locator(".bk-tab.bk-active", has_text="Verdicts").wait_for(timeout=60_000)
        dashboard = until(_dashboard, "the page's session")
        view = dashboard.verdicts
        page.locator(".verdict-table .tabulator-row").first.wait_for(timeout=300_000)
        life = until(lambda: view.life, "the life over the route", LIFE_WAIT_S)
        lives = {s.section.name: s.life_km for s in life.sections}

        def drawn_as_computed():
            shown = {(r["component"], r["check"], r["load case"]): r for r in view.rows}
            drawn = rendered_rows(page)
            fatigue = {k: v for k, v in drawn.items() if k[1] == FATIGUE_CHECK}
            if not fatigue or len(drawn) != len(shown):
                return None
            if any(cells["life [km]"] != shown[key]["life [km]"] for key, cells in
                   fatigue.items()):
                return None
            return fatigue
        fatigue = until(drawn_as_computed, "the life cells drawn as the view holds them", 120)
        assert {key[0] for key in fatigue} == set(lives)
        for (component, _, _), cells in fatigue.items():
            # the cell is the life in km to three significant digits
            assert float(cells["life [km]"]) == pytest.approx(lives[component], rel=5e-3)
            assert "route life" in cells["note"]
            assert "years" in cells["note"]
        page.wait_for_function(
            "() => [...Bokeh.documents[0].all_models].some(m => m.name === 'life-damage')",
            timeout=60_000)
        text = page.evaluate(TEXT, "verdict-life-text")
        assert "Life over the route" in text
        assert "mixed passenger duty" in text
        page.locator(".life-chart canvas").first.scroll_into_view_if_needed()
        page.screenshot(path=str(tmp_path / "verdicts-life.png"), full_page=True)

        # the running case, on request
        label = page.evaluate("""() => [...Bokeh.documents[0].all_models].find(
            m => (m.css_classes || []).includes('ctl-verdict-running')).label""")
        from app.dashboard.verdicts_view import RUNNING_LABEL

        assert label == RUNNING_LABEL
        page.locator(".ctl-verdict-running input").check()
        until(lambda: any(r["load case"] == "running" for r in view.rows),
               "the running case's checks", LIFE_WAIT_S)
        running = until(lambda: {k: v for k, v in rendered_rows(page).items()
                                  if k[2] == "running"}, "the running rows drawn", 120)
        expected = {(r["component"], r["check"], r["load case"]) for r in view.rows
                    if r["load case"] == "running"}
        assert set(running) == expected
        page.screenshot(path=str(tmp_path / "verdicts-running.png"), full_page=True)
        assert page.errors == []
    finally:
        page.close()
