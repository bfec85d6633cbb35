"""The Resonances view (app/dashboard/resonance_view.py) without a server: it computes only while
its tab is open, shows the model's Campbell diagram, FRF and forced response, keeps the previous
settings on a text the model does not take, and a tapped Campbell point opens its mode in the
Modes view.  Expectations come from the model's results, never typed in.  Building a dashboard
and a Campbell diagram takes seconds: slow."""

from __future__ import annotations

import numpy as np
import pytest
from bokeh.document import Document

from app.results import resonance
from model.mechanics.excitation import DEFAULT_ORDERS

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def dash():
    from app.dashboard.dashboard import BogieDashboard

    dashboard = BogieDashboard()
    doc = Document()
    doc.add_root(dashboard.layout.get_root(doc))
    return dashboard


def test_view_computes_when_opened_and_shows_the_models_results(dash):
    view = dash.resonances
    assert view.campbell is None  # nothing computed while the tab is closed
    dash.tabs.active = dash.view_tabs.names.index("resonances")
    state = dash.state()
    keys = view.keys(state)
    assert keys["campbell"] == (state.point().without("v"), DEFAULT_ORDERS, (),
                                "ID1.motor.torque")
    expected = resonance.campbell_result(*keys["campbell"])  # the cached result
    assert view.campbell is expected
    points = view.campbell_plot.modes.data
    assert set(points["name"]) <= {m.name for m in expected.modes}
    assert len(view.campbell_plot.crossings.data["v"]) == len(expected.crossings)
    assert "Crossings" in view.table.object
    assert expected.crossings[0].mode in view.table.object
    frf = resonance.frf_result(*keys["frf"])
    row = frf.output(resonance.DEFAULT_OUTPUT)
    np.testing.assert_array_equal(view.frf_plot.source.data["abs"], frf.magnitude[row, 1:])
    assert len(view.frf_plot.peaks.data["f"]) == len(frf.peaks[row])
    ripple = view.ripple_view
    assert ripple.ripple == resonance.DEFAULT_RIPPLE
    np.testing.assert_array_equal(view.ripple_plot.source.data["ys"][0],
                                  ripple.total[ripple.names.index(resonance.DEFAULT_OUTPUT)])
    assert view.campbell_plot.speed.location == pytest.approx(dash.v)


def test_a_bad_text_gives_a_notice_and_keeps_the_previous_settings(dash):
    view = dash.resonances
    dash.tabs.active = dash.view_tabs.names.index("resonances")
    before = (view.settings, view.campbell)
    many = ",".join(f"el:{k}" for k in range(1, 26))  # more lines than a session may ask for
    for widget, text in ((view.orders, "el:-6"), (view.orders, many), (view.fixed, "5000"),
                         (view.ripple, "el:6")):
        dash.input_notice.visible = False
        widget.value = text
        assert dash.input_notice.visible
        assert "previous settings are kept" in dash.input_notice.object
        assert (view.settings, view.campbell) == before
    view.orders.value = "el:6,mesh:1"
    view.fixed.value = ""
    view.ripple.value = resonance.DEFAULT_RIPPLE
    assert not dash.input_notice.visible
    assert [name for name, _, _ in view.campbell.orders] == ["el:6", "mesh:1"]


def test_output_choice_redraws_frf_and_ripple(dash):
    view = dash.resonances
    dash.tabs.active = dash.view_tabs.names.index("resonances")
    view.output.value = "ID1.disc_clutch.torque"
    assert view.frf_plot.magnitude.title.text.startswith("ID1.disc_clutch.torque")
    assert view.frf_plot.magnitude.yaxis.axis_label == "|H| [N m/N m] from ID1.motor.torque"
    row = view.frf.output("ID1.disc_clutch.torque")
    np.testing.assert_array_equal(view.frf_plot.source.data["abs"], view.frf.magnitude[row, 1:])
    view.output.value = resonance.DEFAULT_OUTPUT


def test_tapping_a_campbell_point_opens_its_mode(dash):
    view = dash.resonances
    dash.tabs.active = dash.view_tabs.names.index("resonances")
    data = view.campbell_plot.modes.data
    index = next(i for i, name in enumerate(data["name"]) if "driving shaft 1" in name)
    view.campbell_plot.modes.selected.indices = [index]  # a tap
    assert dash.view_tabs.shown == "modes"
    assert "tapped on the Campbell diagram" in dash.click.detail.object
    assert dash.click.shown.im_hz == pytest.approx(data["im"][index] / (2 * np.pi), rel=1e-6)
    assert "driving shaft 1" in dash.click.shown.description
