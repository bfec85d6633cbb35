"""What the browser draws in every table of the dashboard's first tabs is what the views computed
(served, headless Chromium; one page).

A view's data can be right while the page shows something else: a Tabulator created from an
empty frame drew every text column as ``NaN`` with pandas 3.1 and Panel 1.9, while the tests that
compared the frame passed.  So each test here reads the cells the browser rendered (the first
rows of each table, from the DOM, through Bokeh's shadow roots) and compares them with the data
the session's own views hold — text exactly, numbers to the table's printed precision.  The
Verdicts table is compared with ``bogie assess --json`` at the same point as well.  The Variant
tab's tables and the Design loads tab's grid envelope need an uploaded set and a study run; their
rendered cells are read in test_review_browser.py and test_design_loads_browser.py.

The page opens with a simulated time no other test of the served module uses (``T_END``; it
changes no table but the histories' length), so that the session's dashboard is found among the
server's live sessions by its state.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys

import pytest
from conftest import ROOT, live_dashboards, open_app, until

pytestmark = [pytest.mark.browser, pytest.mark.slow]

S0 = 0.005  # the page's creepage [-] (the study's stable case at 120 km/h)
T_END = 2.5  # the page's simulated time [s]: this module's session among the server's
ROWS = 5  # rows compared per table (a Tabulator renders only its visible rows)


def _dashboard():
    """The served dashboard of this module's page (the live session with T_END)."""
    found = live_dashboards(T_END)
    assert len(found) == 1, f"{len(found)} live sessions with t_end = {T_END} s"
    return found[0]


def tabulator_rows(page, css: str, columns) -> list[dict[str, str]]:
    """The rendered cells of the first :data:`ROWS` rows of the Tabulator of CSS class ``css``,
    each row as {column: text as drawn}, once every row has a cell for each of ``columns``."""
    cells = """(row) => [...row.querySelectorAll('.tabulator-cell')].map(
        c => [c.getAttribute('tabulator-field'), c.innerText])"""

    def read():
        rows = [dict(row.evaluate(cells))
                for row in page.locator(f".{css} .tabulator-row").all()[:ROWS]]
        return rows if rows and all(set(columns) <= set(r) for r in rows) else None
    return until(read, f"the rows of .{css}")


def html_rows(page, selector: str, expected_rows: int) -> list[list[str]]:
    """The rendered body cells (``td``) of the first rows of the HTML table at ``selector``."""
    def read():
        rows = [cells for cells in (tr.locator("td").all_inner_texts()
                                    for tr in page.locator(f"{selector} tr").all())
                if cells][:expected_rows]
        return rows if len(rows) == expected_rows else None
    return until(read, f"the rows of {selector}")


def number(cell: str) -> float:
    """A number as a table prints it (thousands separators, a leading +)."""
    return float(cell.replace(",", "").replace("+", "").strip())


def close(cell: str, value: float, decimals: int) -> bool:
    """Whether the printed ``cell`` is ``value`` to ``decimals`` decimals."""
    return abs(number(cell) - value) <= 0.51 * 10.0 ** -decimals


@pytest.fixture(scope="module")
def page(app_server, chromium):
    page = open_app(chromium, app_server, timeout_ms=180_000, query=f"s0={S0}&v=120&t_end={T_END}")
    yield page
    page.close()


def _open_tab(page, title: str) -> None:
    page.get_by_text(title, exact=True).click()
    page.locator(".bk-tab.bk-active", has_text=title).wait_for(timeout=60_000)


def test_verdicts_table_shows_the_checks_as_bogie_assess_gives_them(page):
    _open_tab(page, "Verdicts")
    dashboard = until(_dashboard, "the page's session")
    from app.dashboard.verdicts_view import COLUMNS

    rows = tabulator_rows(page, "verdict-table", COLUMNS)
    shown = until(lambda: dashboard.verdicts.rows, "the session's verdict")
    # the data the view computed: text as it is, numbers to the frame's decimals
    for drawn, row in zip(rows, shown, strict=False):
        for name, dtype in COLUMNS.items():
            if dtype == "object":
                assert drawn[name] == row[name], (name, drawn, row)
            else:
                assert close(drawn[name], row[name], 3), (name, drawn, row)
    # the command line at the same point: the same checks in the same order (worst margin
    # first, as the table sorts them); the tab's running case is a checkbox, off by default
    cli = subprocess.run([sys.executable, "-m", "app", "assess", "--s0", str(S0), "--v", "120",
                          "--no-running", "--json", "--serial"], capture_output=True, text=True,
                         cwd=ROOT, timeout=600, check=True)
    checks = sorted(json.loads(cli.stdout)["checks"],
                    key=lambda c: -c["required"] / c["safety_factor"])
    from model.analysis.assessment import KIND_NAMES

    for drawn, check in zip(rows, checks, strict=False):
        assert (drawn["component"], drawn["check"], drawn["load case"]) == (
            check["component"], KIND_NAMES[check["kind"]], check["load_case"])
        assert close(drawn["safety factor"], check["safety_factor"], 3)
        assert close(drawn["load [kN m]"], check["load"] / 1e3, 2)


def test_modes_tables_show_the_point_computed(page):
    _open_tab(page, "Modes")
    dashboard = until(_dashboard, "the page's session")
    point = until(lambda: dashboard.point, "the session's point")
    modes = point.modes
    rows = tabulator_rows(page, "mode-table", ("nu", "im_hz", "re", "zeta", "description"))
    for cells, mode in zip(rows, modes, strict=False):
        assert int(cells["nu"]) == mode.number
        assert close(cells["im_hz"], mode.im_hz, 3)
        assert close(cells["re"], mode.eigenvalue.real, 4)
        assert close(cells["zeta"], mode.damping_ratio, 4)
        assert cells["description"] == mode.description
    # Table 1's layout: the complex pairs (Re ± i Im [Hz]) and the real eigenvalues
    rows = html_rows(page, ".eigen-table table", ROWS)
    for i, cells in enumerate(rows):
        assert int(cells[0]) == i + 1
        re, im = cells[1].split(" ± i ")
        assert close(re, modes[i].eigenvalue.real, 4)
        assert close(im, modes[i].im_hz, 3)
        real = float(point.real[i])
        assert math.isclose(number(cells[2]), real, rel_tol=1e-3, abs_tol=1e-12)


def test_peak_table_shows_the_history_computed(page):
    _open_tab(page, "Response")
    dashboard = until(_dashboard, "the page's session")
    history = until(lambda: dashboard.history, "the session's history")
    names = list(history.outputs)
    rows = html_rows(page, ".peak-table table.peaks", len(names))
    for cells, name in zip(rows, names, strict=True):
        extremes, unit = history.load_peaks.extremes[name], history.units[name]
        assert cells[0].startswith(f"{name} [")
        scale = 1e3 if unit in ("N m", "N") else 1.0
        for cell, value in ((cells[1], extremes.pre_fault), (cells[2], extremes.maximum),
                            (cells[4], extremes.minimum), (cells[6], extremes.swing)):
            assert math.isclose(number(cell), value / scale, rel_tol=5e-3, abs_tol=5e-3), (
                name, cell, value)
        assert close(cells[3], extremes.time_of_maximum, 4)
        assert close(cells[7], extremes.time_of_swing, 4)


def test_design_loads_tables_show_the_worst_case_and_the_spectra_computed(page):
    _open_tab(page, "Design loads")
    dashboard = until(_dashboard, "the page's session")
    worst = until(lambda: getattr(dashboard.design_loads, "worst", None), "the worst case")
    names = list(worst.units)
    rows = html_rows(page, ".loads-worst table.worst-case", len(names))
    for cells, name in zip(rows, names, strict=True):
        assert cells[0].endswith(f"[{worst.units[name]}]")
        assert math.isclose(number(cells[1]), worst.max[name], abs_tol=0.51)
        assert close(cells[2], worst.phase_of_max[name], 6)
        assert math.isclose(number(cells[4]), worst.min[name], abs_tol=0.51)
        assert close(cells[6], worst.time_of_min[name], 4)
    spectra = until(lambda: getattr(dashboard.design_loads, "spectra", None), "the spectra")
    names = list(spectra.spectra)
    rows = html_rows(page, ".loads-spectra table.spectra", len(names))
    for cells, name in zip(rows, names, strict=True):
        spectrum = spectra.spectra[name]
        assert cells[0].endswith(f"[{spectrum.unit}]")
        assert number(cells[1]) == pytest.approx(spectrum.total_cycles)
        assert math.isclose(number(cells[2]), spectrum.largest_range, abs_tol=0.51)
        for cell, m in zip(cells[3:], spectrum.equivalent_range, strict=True):
            assert math.isclose(number(cell), spectrum.equivalent_range[m], rel_tol=1e-3)


def test_resonance_crossings_table_shows_the_crossings_computed(page):
    _open_tab(page, "Resonances")
    dashboard = until(_dashboard, "the page's session")
    view = until(lambda: getattr(dashboard.resonances, "campbell", None), "the Campbell view",
                  timeout=600)
    listed = view.crossings[:ROWS]
    rows = html_rows(page, ".resonance-crossings table", len(listed))
    for cells, crossing in zip(rows, listed, strict=True):
        assert close(cells[0], crossing.v_kmh, 1)
        assert close(cells[1], crossing.f_hz, 2)
        assert cells[2] == crossing.label
        assert close(cells[3], crossing.zeta, 4)
        assert math.isclose(number(cells[4]), crossing.severity, rel_tol=5e-3)
        assert (cells[5], cells[6]) == (crossing.worst_output, crossing.mode)
    assert page.errors == []
