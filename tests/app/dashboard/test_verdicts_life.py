"""The Verdicts tab's life column, damage plot and running case, without a server: each shaft
section's fatigue row gives its life over a route equal to ``bogie life --route … --json``'s
``life_km`` for the same section, the damage-over-speed plot is the least-life section's, and the
"running case" checkbox adds the running case's checks to the table.

The route is a short one of two speed bins (written here) with the sources ripple, track and
short circuit, so that a life takes seconds, not minutes; the dashboard's view is pointed at it
the way it holds the bundled route (``life_route``, ``life_sources``)."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
from bokeh.document import Document
from conftest import ROOT

from app.results.life import FATIGUE_CHECK, life_words

pytestmark = pytest.mark.slow

SOURCES = ("ripple", "track", "short_circuit")
ROUTE = """name = "short test route"
source = "a test's route: two speed bins of the running speeds"
annual_distance_km = 100000

[speeds]
edges_kmh = [100, 120, 140]
share = [40, 60]

[track]
spectrum = "low"

[short_circuit]
per_year = 0.1
s0 = 0.005
v_kmh = [120]
"""


@pytest.fixture(scope="module")
def route(tmp_path_factory):
    path = tmp_path_factory.mktemp("route") / "short.toml"
    path.write_text(ROUTE, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def dash(route):
    from app.dashboard.dashboard import BogieDashboard

    dashboard = BogieDashboard()
    doc = Document()
    doc.add_root(dashboard.layout.get_root(doc))
    view = dashboard.verdicts
    view.life_route, view.life_sources = str(route), SOURCES
    view.on_shown(True)  # not served: the verdict is computed when the tab opens
    return dashboard


@pytest.fixture(scope="module")
def cli_life(route) -> dict:
    """``bogie life --route`` over the same route and sources at the same (default) set."""
    out = subprocess.run([sys.executable, "-m", "app", "life", "--route", str(route),
                          "--sources", ",".join(SOURCES), "--json"], capture_output=True,
                         text=True, cwd=ROOT, timeout=900, check=True)
    return json.loads(out.stdout)


def test_the_fatigue_rows_say_computing_until_the_life_is_there(dash):
    view = dash.verdicts
    assert view.result is not None
    assert view.life is None
    fatigue = [row for row in view.rows if row["check"] == FATIGUE_CHECK]
    assert fatigue, "the verdict has fatigue rows"
    assert all(row["life [km]"] == "computing…" for row in fatigue)
    assert all(row["life [km]"] == "" for row in view.rows if row["check"] != FATIGUE_CHECK)
    assert list(view.table.value["life [km]"]) == [row["life [km]"] for row in view.rows]


def test_the_life_column_is_bogie_life_over_the_same_route(dash, cli_life):
    view = dash.verdicts
    view.compute_life()
    assert view.life is not None
    cli = {s["name"]: s for s in cli_life["sections"]}
    # the same computation in two processes; the dashboard's model is the results cache's, which
    # keeps the decompositions of its last operating points, so the floating-point operations
    # differ in order: 1.2e-8 relative was seen on the smallest damage (ID2's axle, 5e28 km);
    # 1e-6 is far below the table's three digits and far above that rounding
    for section in view.life.sections:
        assert section.life_km == pytest.approx(cli[section.section.name]["life_km"], rel=1e-6)
    fatigue = [row for row in view.rows if row["check"] == FATIGUE_CHECK]
    assert {row["component"] for row in fatigue} == set(cli)
    for row in fatigue:
        expected = cli[row["component"]]
        assert row["life [km]"] == life_words(expected["life_km"])
        assert float(row["life [km]"]) == pytest.approx(expected["life_km"], rel=5e-3)
        assert f"route life {expected['life_years']:.3g} years" in row["note"]
    assert list(view.table.value["life [km]"]) == [row["life [km]"] for row in view.rows]
    assert "short test route" in view.life_text.object
    assert "ripple, track, short_circuit" in view.life_text.object


def test_the_damage_plot_is_the_least_life_sections(dash, cli_life):
    view = dash.verdicts
    fig = view.life_chart.object
    least = min(cli_life["sections"], key=lambda s: s["life_km"])
    assert least["name"] in fig.title.text
    assert fig.yaxis[0].axis_label.startswith("damage a year [1/year]")
    assert fig.xaxis[0].axis_label.startswith("speed [km/h]")
    # the lines: per source over speed, the orders of a bin summed, as the CLI's contributions
    drawn = {}
    for renderer in fig.renderers:
        data = renderer.data_source.data
        if data["source"]:
            drawn[data["source"][0]] = dict(zip(data["v"], data["damage"], strict=True))
    expected: dict = {}
    for c in least["contributions"]:
        if c["v_kmh"] is not None:
            by_speed = expected.setdefault(c["source"], {})
            by_speed[c["v_kmh"]] = by_speed.get(c["v_kmh"], 0.0) + c["damage"]
    assert set(drawn) == {s for s, v in expected.items() if any(d > 0 for d in v.values())}
    for source, by_speed in drawn.items():
        for v, damage in by_speed.items():
            assert damage == pytest.approx(expected[source][v], rel=1e-9)
    events = sum(c["damage"] for c in least["contributions"] if c["v_kmh"] is None)
    assert f"{events:.3g} 1/year" in fig.title.text


def test_the_running_checkbox_adds_the_running_case(dash):
    view = dash.verdicts
    assert "running" not in {row["load case"] for row in view.rows}
    before = len(view.rows)
    view.running.value = True  # not served, the tab open: assessed at once
    running = [row for row in view.rows if row["load case"] == "running"]
    assert running
    assert len(view.rows) == before + len(running)
    assert any(case.name == "running" for case in view.result.cases)
    # the life is the set's, not the load cases': it stays on screen
    fatigue = [row for row in view.rows if row["check"] == FATIGUE_CHECK]
    assert all(row["life [km]"] not in ("", "computing…") for row in fatigue)
    view.running.value = False
    assert "running" not in {row["load case"] for row in view.rows}
