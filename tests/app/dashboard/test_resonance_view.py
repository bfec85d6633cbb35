"""The Resonances view (app/dashboard/resonance_view.py) without a server: it computes only while
its tab is open, shows the model's Campbell diagram, FRF and forced response, keeps the previous
settings on a text the model does not take, and a tapped Campbell point opens its mode in the
Modes view.  Expectations come from the model's results, never typed in.  Building a dashboard
and a Campbell diagram takes seconds: slow."""

from __future__ import annotations

import html
import json

import numpy as np
import pytest
from bokeh.document import Document

from app.results import compute, resonance
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


def _cli(argv, capsys) -> dict:
    """``bogie … --json``'s answer (the command line in this process)."""
    from app.cli.main import main

    try:
        code = main([*argv, "--json"])
    except SystemExit as exit_:
        code = exit_.code
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


def test_frf_input_offers_the_wheels_irregularities(dash, capsys):
    from model.analysis.frequency_response import frequency_response
    from model.mechanics.irregularity import irregularity_inputs

    view = dash.resonances
    dash.tabs.active = dash.view_tabs.names.index("resonances")
    state = dash.state()
    model = compute.model_for(state.point())
    wheels = irregularity_inputs(model)
    assert len(wheels) == 4
    assert list(view.frf_input.options) == ["ID1.motor.torque", "ID2.motor.torque", *wheels]
    view.frf_input.value = wheels[0]
    assert view.frf.input == wheels[0]
    assert view.frf is resonance.frf_result(state.point(), wheels[0])
    assert view.frf_plot.magnitude.yaxis.axis_label == f"|H| [N m/m] from {wheels[0]}"
    # the model's answer for the same input and grid, computed afresh
    expected = frequency_response(model, state.point().operating_point(), input=wheels[0],
                                  points=resonance.FRF_POINTS)
    row = expected.output(resonance.DEFAULT_OUTPUT)
    np.testing.assert_allclose(view.frf_plot.source.data["abs"], expected.magnitude[row, 1:],
                               rtol=1e-9)
    # and the command line's for the same input and point (the motor slope as the dashboard
    # holds it: the set's value rounded to the slider's step)
    answer = _cli(["frf", "--s0", repr(state.s0), "--v", repr(state.v), "--bm", repr(state.b_M),
                   "--input", wheels[0]], capsys)
    assert answer["operating_point"]["N0"] == state.point().operating_point().N0
    (cli,) = [o for o in answer["outputs"] if o["name"] == resonance.DEFAULT_OUTPUT]
    np.testing.assert_allclose(view.frf_plot.source.data["abs"], cli["abs"][1:], rtol=1e-9)
    # the rippling motor (tab closed: nothing recomputed): a wheel's input stays, a motor's follows
    dash.tabs.active = 0
    view.input.value = "ID2.motor.torque"
    assert view.frf_input.value == wheels[0]
    view.frf_input.value = "ID2.motor.torque"
    view.input.value = "ID1.motor.torque"
    assert view.frf_input.value == "ID1.motor.torque"


def test_wheel_polygon_response_is_the_models(dash, capsys):
    from dataclasses import replace

    from app.dashboard.resonance_view import NO_POLYGON
    from model.analysis.wheel_excitation import combined_response, polygon_frequency_hz

    view = dash.resonances
    dash.tabs.active = dash.view_tabs.names.index("resonances")
    view.polygon.value = ""
    assert view.polygon_view is None  # no default polygon: the model has no sourced amplitude
    assert view.polygon_plot.figure.title.text == NO_POLYGON
    assert view.polygon_plot.source.data["xs"] == []
    view.polygon.value = "20=30"
    state = dash.state()
    polygon = view.polygon_view
    assert polygon is resonance.polygon_result(state.point().without("v"), "20=30")
    assert polygon.orders == (20,)
    assert polygon.v_kmh[[0, -1]] == pytest.approx(resonance.SPEEDS_KMH, rel=1e-12)
    assert polygon.amplitudes[0] == pytest.approx(30e-6, rel=1e-12)
    row = polygon.names.index(resonance.DEFAULT_OUTPUT)
    np.testing.assert_array_equal(view.polygon_plot.source.data["ys"][0], polygon.total[row])
    assert view.polygon_plot.figure.yaxis.axis_label == "steady amplitude [N m]"
    # the amplitude at a speed of the grid is a |Σ_j H_j e^(iφ_j)| solved afresh at that speed
    model = compute.model_for(state.point())
    i = int(np.nanargmax(polygon.total[row]))
    v = float(polygon.v[i])
    op = replace(state.point().operating_point(), v=v)
    f = float(polygon_frequency_hz(20, v, model.parameters["wheel_radius"]))
    H, _ = combined_response(model, op, f)
    assert polygon.total[row, i] == pytest.approx(30e-6 * abs(H[row]), rel=1e-9)
    # the command line's answer for the same polygon, point and speeds
    answer = _cli(["ripple", "--v", f"{resonance.SPEEDS_KMH[0]:g}:{resonance.SPEEDS_KMH[1]:g}:"
                   f"{resonance.POLYGON_SPEEDS}", "--s0", repr(state.s0), "--bm", repr(state.b_M),
                   "--wheel-polygon", "20=30"], capsys)
    (cli,) = [o for o in answer["outputs"] if o["name"] == resonance.DEFAULT_OUTPUT]
    np.testing.assert_allclose(answer["v_kmh"], polygon.v_kmh, rtol=1e-12)
    np.testing.assert_allclose([np.nan if x is None else x for x in cli["amplitude"]],
                               polygon.total[row], rtol=1e-9)
    assert answer["unstable_v_kmh"] == pytest.approx(list(polygon.unstable_kmh), rel=1e-12)
    # the running system's growth is stated where the model finds it
    title = view.polygon_plot.figure.title.text
    assert ("no steady state" in title) == bool(polygon.unstable_kmh)
    # a bad polygon: the notice, the response kept
    for text in ("20", "0=30", "20=abc", "20=9000"):
        dash.input_notice.visible = False
        view.polygon.value = text
        assert dash.input_notice.visible
        assert "previous settings are kept" in dash.input_notice.object
        assert view.settings["polygon"] == "20=30"
        assert view.polygon_view is polygon
    view.polygon.value = ""
    assert not dash.input_notice.visible
    assert view.polygon_view is None


def test_random_track_psd_is_the_models(dash):
    from model.analysis.track_spectrum import LOW
    from model.analysis.wheel_excitation import combined_response

    view = dash.resonances
    dash.tabs.active = dash.view_tabs.names.index("resonances")
    state = dash.state()
    track = view.track
    assert track is resonance.track_result(state.point())
    assert track.spectrum is LOW
    row = track.output(resonance.DEFAULT_OUTPUT)
    np.testing.assert_array_equal(view.track_plot.source.data["psd"],
                                  track.psd[row][track.psd[row] > 0])
    title = view.track_plot.figure.title.text
    assert f"RMS {track.rms[row]:.4g} N m" in title
    assert ("no stationary response" in title) == (not track.stable)
    assert view.track_plot.figure.yaxis.axis_label == "PSD [(N m)²/Hz]"
    # a point of the PSD is G(f) |Σ_j H_j e^(iφ_j)|², solved afresh
    model = compute.model_for(state.point())
    k = len(track.f_hz) // 2
    f = float(track.f_hz[k])
    H, _ = combined_response(model, state.point().operating_point(), f)
    expected = LOW.temporal(f, state.point().operating_point().v) * abs(H[row]) ** 2
    assert track.psd[row, k] == pytest.approx(float(expected), rel=1e-9)
    assert LOW.source in html.unescape(view.track_source.object)
