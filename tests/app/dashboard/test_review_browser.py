"""The design-review features in headless Chromium: the dense root locus and Fig. 6,
a shared link restoring the state (and a bad one giving a notice), design variants (upload,
comparison), the offline report, and click-through modes.

Nothing here depends on the numbers of the current parameter set: the tests read what the
served page shows and compare it with what they asked for.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import open_app
from playwright.sync_api import TimeoutError as PlaywrightTimeout

pytestmark = [pytest.mark.browser, pytest.mark.slow]

DATA = """([name, col]) => { const d = Bokeh.documents[0].get_model_by_name(name).data;
  const v = d instanceof Map ? d.get(col) : d[col]; return v ? Array.from(v) : null; }"""
LOCUS_TITLE = "() => Bokeh.documents[0].get_model_by_name('root-locus').title.text"
WIDGET_VALUE = """(cls) => { const doc = Bokeh.documents[0];
  const m = [...doc.all_models].find(m => (m.css_classes || []).includes(cls));
  return m ? m.value : null; }"""


MODE_TABLE_MODEL = """() => { const doc = Bokeh.documents[0];
  const m = [...doc.all_models].find(m => (m.css_classes || []).includes('mode-table'));
  if (!m) return null;
  const d = m.source.data, first = d instanceof Map ? [...d.values()][0] : Object.values(d)[0];
  return {rows: first ? first.length : 0, visible: m.visible, height: m.height}; }"""


def _what_the_modes_tab_shows(page, server_log) -> str:
    """What the page holds when the mode table shows no row: the active tab, the table's element
    (its box: zero where it is laid out hidden), the rows in the DOM (attached, visible or not),
    the rows of the table's model in the browser (zero: the server never sent the modes), the
    page's errors and the server's log."""
    active = page.locator(".bk-tab.bk-active").all_inner_texts()
    tables = page.locator(".mode-table")
    box = tables.first.bounding_box() if tables.count() else None
    attached = page.locator(".mode-table .tabulator-row").count()
    model = page.evaluate(MODE_TABLE_MODEL)
    log_tail = server_log.read_text()[-2000:] if server_log.exists() else "(no server log)"
    return (f"no visible mode-table row within 120 s; active tabs {active}, .mode-table elements "
            f"{tables.count()}, its box {box}, rows in the DOM {attached}, its model in the "
            f"browser {model}, page errors {page.errors}, server log tail:\n{log_tail}")


def _tab(page, title: str) -> None:
    """Open a tab and wait until the browser shows it active (its view is rendered then)."""
    tab = page.locator(".bk-tab", has_text=title).first
    tab.click()
    page.wait_for_function("(el) => el.classList.contains('bk-active')", arg=tab.element_handle(),
                           timeout=60_000)


def test_shared_link_restores_state_dense_locus_and_fig6(own_server, chromium):
    query = "s0=0.014&v=200&n0=100000&bm=3000&m0=50000&f=90&decay=0.04&t_end=2&tab=fig-6"
    page = chromium.new_page(viewport={"width": 1600, "height": 1000})
    errors: list[str] = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(f"{own_server[0]}/app?{query}", timeout=120_000)
    page.wait_for_function("() => window.Bokeh && Bokeh.documents.length > 0", timeout=120_000)
    # the controls show the link's values (N0 in kN, M0 in kN m on the sliders)
    page.wait_for_function(f"() => ({WIDGET_VALUE})('ctl-v') === 200", timeout=120_000)
    assert page.evaluate(WIDGET_VALUE, "ctl-s0") == pytest.approx(0.014)
    assert page.evaluate(WIDGET_VALUE, "ctl-N0") == pytest.approx(100.0)
    assert page.evaluate(WIDGET_VALUE, "ctl-M0") == pytest.approx(50.0)
    # the Fig. 6 tab is the one open, its three figures drawn
    assert "bk-active" in (page.locator(".bk-tab", has_text="Fig. 6").first
                           .get_attribute("class") or "")
    # progressive root locus: the dense sweep (>= 200 points per branch) replaces the coarse one
    page.wait_for_function(f"() => ({LOCUS_TITLE})().includes('200 points')", timeout=180_000)
    s0 = page.evaluate(DATA, ["locus_points", "s0"])
    assert s0 is not None
    assert len(set(s0)) >= 200
    for name in ("fig6-im", "fig6-re", "fig6-real"):
        xs = page.evaluate(DATA, [f"{name}-data", "xs"])
        assert xs, name
    canvases = page.locator("canvas").evaluate_all(
        "cs => cs.filter(c => c.width * c.height > 0).length")
    assert canvases >= 4  # root locus + Fig. 6 (three figures)
    # the address follows the controls: a keyboard step on s0 changes s0= in the URL
    handle = page.locator(".ctl-s0 .noUi-handle")
    handle.focus()
    handle.press("ArrowRight")
    page.wait_for_function("() => !window.location.search.includes('s0=0.014&')",
                           timeout=60_000)
    assert "v=200" in page.url
    assert errors == [], errors
    page.close()


def test_bad_link_gives_a_notice_and_the_defaults(own_server, chromium):
    page = chromium.new_page(viewport={"width": 1600, "height": 1000})
    page.goto(f"{own_server[0]}/app?s0=nan&v=fast&variant=gear_ratio:-1&tab=nowhere",
              timeout=120_000)
    page.locator(".input-notice", has_text="not used").wait_for(timeout=120_000)
    for name in ("s0 = nan", "v = 'fast'", "gear_ratio", "tab = 'nowhere'"):
        assert page.locator(".input-notice", has_text=name).count() > 0, name
    page.wait_for_function("() => window.Bokeh && Bokeh.documents.length > 0", timeout=60_000)
    page.locator(".stability-status", has_text="STABLE").wait_for(timeout=120_000)
    assert page.evaluate(WIDGET_VALUE, "ctl-v") == 120.0  # the default
    page.close()


def test_variant_upload_comparison_click_through_and_report(own_server, chromium, tmp_path):
    from model.mechanics.parameters import dumps_parameters, load_parameters

    page = open_app(chromium, own_server[0])
    page.errors.clear()
    page.locator(".stability-status", has_text="STABLE").wait_for(timeout=120_000)

    # click-through: a row of the mode table shows that mode's description and energy shares
    _tab(page, "Modes")
    # the table shows ν as an integer and each mode's description (not a number column's NaN)
    # (the tab's view is created when it is opened and filled by the server then: under the CI
    # run's load that took longer than Playwright's default 30 s once, so wait as for the rest)
    try:
        page.locator(".mode-table .tabulator-row").first.wait_for(timeout=120_000)
    except PlaywrightTimeout:
        # seen once in a CI run (not reproduced since, loaded or not): say what the page and the
        # server showed, so that the next occurrence can be diagnosed
        pytest.fail(_what_the_modes_tab_shows(page, own_server[2].parent / "serve.log"))
    first_row = page.locator(".mode-table .tabulator-row").first.inner_text()
    assert first_row.startswith("1\n"), first_row
    assert "NaN" not in first_row, first_row
    assert any(c.isalpha() for c in first_row), first_row
    page.locator(".mode-table .tabulator-row").nth(2).click()
    detail = page.locator(".mode-detail")
    detail.filter(has_text="ν = 3").wait_for(timeout=60_000)
    assert detail.filter(has_text="kinetic energy").count() == 1

    # a malformed upload: a notice, nothing else changes
    _tab(page, "Variant")
    bad = tmp_path / "bad.toml"
    bad.write_text("gear_ratio = { value = ")
    page.locator(".var-upload input[type=file]").set_input_files(str(bad))
    page.locator(".input-notice", has_text="not used").wait_for(timeout=60_000)
    # a valid set with one stiffness doubled: listed, compared, highlighted
    base = load_parameters()
    good = tmp_path / "variant.toml"
    good.write_text(dumps_parameters(base.replace(
        silent_block_stiffness_z=2 * base["silent_block_stiffness_z"])))
    page.locator(".var-upload input[type=file]").set_input_files(str(good))
    page.locator(".variant-summary", has_text="silent_block_stiffness_z").wait_for(
        timeout=60_000)
    # the comparison computes both sets' eigenvalues, limits and verdicts: minutes on a loaded
    # machine (a suite run beside another took more than 240 s once)
    page.locator(".variant-comparison td.changed").first.wait_for(timeout=600_000)
    assert "variant=silent_block_stiffness_z" in page.url
    _compare_variant_tables(page, base)

    # the report: downloaded, opened offline, every figure drawn, nothing fetched
    with page.expect_download(timeout=240_000) as info:
        page.locator(".dl-report button").click()
    path = tmp_path / "report.html"
    info.value.save_as(path)
    text = path.read_text()
    assert "silent_block_stiffness_z" in text
    context = chromium.new_context(offline=True)
    report = context.new_page()
    requests: list[str] = []
    report.on("request", lambda r: requests.append(r.url)
              if not r.url.startswith(("file:", "data:", "blob:")) else None)
    report.goto(Path(path).as_uri())
    report.wait_for_selector("canvas", timeout=60_000)  # (locators pierce Bokeh's shadow roots)
    report.wait_for_timeout(1000)
    assert report.locator("canvas").count() >= 9  # locus, Fig. 6 (3), creep, responses (4)
    assert requests == []
    context.close()
    assert page.errors == [], page.errors
    page.close()


def _drawn_rows(page, selector: str) -> list[list[str]]:
    """The body cells (``td``) of the table at ``selector`` as the browser drew them."""
    return [cells for cells in (tr.locator("td").all_inner_texts()
                                for tr in page.locator(f"{selector} tr").all()) if cells]


def _compare_variant_tables(page, base) -> None:
    """The Variant tab's tables as drawn: the comparison's baseline column is the baseline's
    point (computed here for the page's default state), the variant differs where it is
    highlighted; the calibration bounds are those of the baseline's fitted parameters."""
    from app.results import compute
    from app.results.case import Case
    from model.studies.calibration_bounds import parameter_rows

    point = compute.point_result(Case(**Case.defaults(base)))
    rows = {cells[0]: cells[1:] for cells in _drawn_rows(page, ".variant-comparison table")}
    assert abs(float(rows["largest Re λ [1/s]"][0]) - point.max_real_part) <= 0.51e-4
    assert rows["verdict"][0] == ("STABLE" if point.stable else "UNSTABLE")
    for mode in point.modes[:5]:
        baseline, variant, delta = rows[f"ν = {mode.number}: Im [Hz]"]
        assert abs(float(baseline) - mode.im_hz) <= 0.51e-3
        assert abs(float(variant) - float(baseline) - float(delta)) <= 1.1e-3
    page.get_by_text("Calibration bounds of the baseline").click()
    drawn = _drawn_rows(page, ".variant-bounds table")
    fitted = [row for row in parameter_rows(base) if row["lower"] is not None]
    assert [cells[0] for cells in drawn] == [row["name"] for row in fitted]
    for cells, row in zip(drawn, fitted, strict=True):
        assert float(cells[1]) == pytest.approx(row["value"], rel=5e-4)
        low, high = (float(x) for x in cells[2].split(" … "))
        assert (low, high) == (pytest.approx(row["lower"], rel=5e-4),
                               pytest.approx(row["upper"], rel=5e-4))
        assert cells[3] == row["unit"]

