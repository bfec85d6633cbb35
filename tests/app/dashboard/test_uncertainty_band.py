"""The s0*(v) uncertainty band in the Studies view (app/dashboard/uncertainty_band.py), without a server.

The result files are written by the model's own :meth:`UncertaintyResult.as_dict` (a small
result assembled from plain arrays: the band's logic needs the provenance and the percentiles,
not a model run; a real CLI run is in tests/model/studies/test_posterior.py).  Checked: a result of the set
and conditions on screen draws its 5–95 % band and median at its speeds, with the method and
sample count in the legend; a different wheel force, motor slope, rail condition or parameter
set clears the band and the notice says which; a result without provenance (the older format:
the stored study with its hash removed) is not drawn; a bad file keeps the previous band; with a
map on screen the map's set and conditions count.
"""

from __future__ import annotations

import json

import numpy as np
import param
import pytest
from conftest import ROOT, SPEEDS, dashboard_with_study_queue, uncertainty_result_file

from app.dashboard.studies_view import MapView
from app.dashboard.uncertainty_band import band_mismatch, read_band
from app.results import compute
from app.services.studies_folder import refusal
from model.mechanics.parameters import parameter_hash

B_M = compute.parameters("", "calibrated")["motor_slope"]  # the set's b_M [N m s/rad]


@pytest.fixture(scope="module")
def dash(tmp_path_factory):
    yield from dashboard_with_study_queue(tmp_path_factory.mktemp("studies"))


def _in_folder(view, name: str, parameters, **kwargs) -> str:
    """Write a result into the server's studies folder; its name (what a reviewer picks)."""
    uncertainty_result_file(view.queue.folder.root / name, parameters, **kwargs)
    return name


@pytest.fixture
def view(dash):
    with param.parameterized.discard_events(dash):
        dash.N0, dash.b_M, dash.rail = 100.0, B_M, "calibrated"
    view = dash.studies
    view.map, view.uncertainty = None, None
    view.plot.band.update(None)
    view.band_notice.visible = False
    return view


def test_matching_result_draws_its_band(view, dash):
    parameters = compute.parameters("", "calibrated")
    assert parameters["wheel_force"] == 100e3
    path = view.queue.folder.root / _in_folder(view, "u.json", parameters)
    band = read_band(path)
    view.refresh_lists()
    assert "u.json" in view.uncertainty_select.options
    view.uncertainty_select.value = "u.json"
    view.uncertainty_button.clicks += 1  # the button's own callback
    assert view.uncertainty is not None
    assert not view.band_notice.visible, view.band_notice.object
    assert view.plot.band.shown
    assert len(view.plot.image.data["image"]) == 0  # no map: the axes fit the band
    data = view.plot.band.source.data
    np.testing.assert_array_equal(data["v"], SPEEDS)
    np.testing.assert_array_equal(data["low"], band.p5)
    np.testing.assert_array_equal(data["high"], band.p95)
    assert np.all(data["low"] < data["median"])
    assert np.all(data["median"] < data["high"])
    stored = json.loads(path.read_text())
    p5 = [o["p5"] for o in stored["outputs"] if o["name"].startswith("s0_limit_")]
    np.testing.assert_allclose(data["low"], p5)
    labels = [item.label["value"] for item in view.plot.figure.legend[0].items]
    assert "s0* 5–95 % (posterior, n = 8) [-]" in labels
    assert "posterior, n = 8" in view.band_status.object
    assert "40, 120, 200 km/h" in view.band_status.object
    # the same band on the Variant tab's baseline s0*(v)
    assert view.variant_band.shown
    np.testing.assert_array_equal(view.variant_band.source.data["high"], band.p95)
    assert view.variant_band.area in dash.variant_view.limits_figure.renderers
    assert "also on the Variant tab" in view.band_status.object


@pytest.mark.parametrize(("change", "reason"), [
    ({"N0": 120.0}, "wheel force N0: result 100 kN, screen 120 kN"),
    ({"b_M": 2000.0}, f"motor slope b_M: result sampled around {B_M:g} N m s/rad, screen 2000"),
    ({"rail": "wet"}, "rail condition: result 'calibrated', screen 'wet'"),
])
def test_other_conditions_clear_the_band_and_say_why(view, dash, change, reason):
    view.open_uncertainty(_in_folder(view, "u.json", compute.parameters("", "calibrated")))
    assert view.plot.band.shown
    with param.parameterized.discard_events(dash):
        dash.param.update(**change)
    view.check_band()
    assert not view.plot.band.shown
    assert not view.variant_band.shown
    assert view.band_notice.visible
    assert reason in view.band_notice.object
    assert "does not match the dashboard's set" in view.band_notice.object
    with param.parameterized.discard_events(dash):
        dash.N0, dash.b_M, dash.rail = 100.0, B_M, "calibrated"
    view.check_band()
    assert view.plot.band.shown
    assert not view.band_notice.visible


def test_slider_change_rechecks_the_band(view, dash):
    view.open_uncertainty(_in_folder(view, "u.json", compute.parameters("", "calibrated")))
    assert view.plot.band.shown
    dash.N0 = 110.0  # the watcher re-checks (the dashboard recomputes its point too)
    assert not view.plot.band.shown
    assert "wheel force N0" in view.band_notice.object
    dash.N0 = 100.0
    assert view.plot.band.shown


def test_other_parameter_set_and_old_format_are_not_drawn(view):
    other = compute.parameters("", "calibrated").replace(yaw_damping=3e5)
    view.open_uncertainty(_in_folder(view, "u.json", other))
    assert not view.plot.band.shown
    assert "parameter set: result" in view.band_notice.object
    assert "re-calibrated" in view.band_notice.object
    # a result written before studies recorded their set: the stored study without its hash
    stored = json.loads((ROOT / "assets" / "data"
                         / "uncertainty_n16.json").read_text(encoding="utf-8"))
    stored.pop("parameters_hash")
    stored.pop("conditions", None)
    (view.queue.folder.root / "old.json").write_text(json.dumps(stored), encoding="utf-8")
    view.open_uncertainty("old.json")
    assert not view.plot.band.shown
    assert "does not say which parameter set" in view.band_notice.object


def test_bad_file_keeps_the_previous_band(view, tmp_path):
    view.open_uncertainty(_in_folder(view, "u.json", compute.parameters("", "calibrated")))
    shown = view.uncertainty
    (view.queue.folder.root / "bad.json").write_text("{not json", encoding="utf-8")
    (tmp_path / "outside.json").write_text("{}", encoding="utf-8")
    for bad, message in (("bad.json", "'bad.json' is not JSON"),
                         ("missing.json", refusal("uncertainty")),
                         (str(tmp_path / "outside.json"), refusal("uncertainty"))):
        view.open_uncertainty(bad)
        assert view.band_notice.visible
        assert message in view.band_notice.object
        assert "previous one kept" in view.band_notice.object
        assert view.uncertainty is shown
        assert view.plot.band.shown


def test_the_map_on_screen_decides(view):
    parameters = compute.parameters("", "calibrated")
    view.open_uncertainty(_in_folder(view, "u.json", parameters))
    assert view.plot.band.shown

    def map_view(hash_, N0=100e3, b_M=B_M):
        return MapView(np.array([0.005, 0.01]), np.array([40.0, 200.0]), np.zeros((2, 2)),
                       np.full(2, np.nan), 2, 2, {"parameters_hash": hash_}, N0, b_M)

    view._show(map_view(parameter_hash(compute.parameters("", "wet"))))  # a wet-rail map
    assert not view.plot.band.shown
    assert "does not match the map on screen" in view.band_notice.object
    view._show(map_view(parameter_hash(parameters), N0=90e3))
    assert "wheel force N0: result 100 kN, screen 90 kN" in view.band_notice.object
    assert view.variant_band.shown  # the Variant tab shows the dashboard's set, which matches
    view._show(map_view(parameter_hash(parameters)))
    assert view.plot.band.shown


def test_band_mismatch_without_sampled_motor_slope(tmp_path):
    parameters = compute.parameters("", "calibrated")
    names = ("creep_slope",)
    band = read_band(uncertainty_result_file(tmp_path / "u.json", parameters, method="prior", names=names))
    assert band.method == "prior"
    assert not band.motor_slope_sampled
    assert band_mismatch(band, parameter_hash(parameters), 100e3, B_M, "calibrated") is None
    reason = band_mismatch(band, parameter_hash(parameters), 100e3, 2000.0, "calibrated")
    assert reason == f"motor slope b_M: result {B_M:g} N m s/rad, screen 2000 N m s/rad"
