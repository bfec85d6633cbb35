"""The dashboard's "Studies" view without a server: a map started at the dashboard's N0, b_M and
rail runs in the background, its progress and heat map follow, the result equals the serial
study, a store can be opened, bad input shows a notice and keeps the map."""

from __future__ import annotations

import numpy as np
import param
import pytest
from bokeh.document import Document

from app import compute
from app.dashboard import BogieDashboard
from model.study import run_serial


@pytest.fixture(scope="module")
def dash(tmp_path_factory):
    dashboard = BogieDashboard()
    dashboard.studies.folder = tmp_path_factory.mktemp("studies")
    doc = Document()
    doc.add_root(dashboard.layout.get_root(doc))
    return dashboard


def _small(view, where="this process (no Dask)"):
    view.s0_range.value = (0.002, 0.016)
    view.s0_points.value = 6
    view.v_range.value = (60.0, 200.0)
    view.v_points.value = 3
    view.where.value = where


def test_map_at_the_dashboards_point_equals_serial_study(dash):
    view = dash.studies
    assert any(o is view.layout for o in dash.tabs.objects)  # hooked into the dashboard's tabs
    with param.parameterized.discard_events(dash):  # no dashboard recomputation needed here
        dash.N0, dash.b_M, dash.rail = 90.0, 2500.0, "wet"
    _small(view)
    view.start()
    assert view.running or view._outcome == "done"
    view.wait(600)
    view.poll()
    assert view._outcome == "done", view.status.object
    assert "done: 3/3" in view.status.object
    assert view.progress.value == 3
    assert not view.start_button.disabled
    study = view.study()
    assert study.N0 == (90e3,)
    assert study.b_M == (2500.0,)
    reference = run_serial(study, compute.parameters("", "wet"))
    shown = view.plot.image.data["image"][0]
    for (i, _, _), result in reference.items():
        np.testing.assert_array_equal(shown[:, i], result["largest_real_part"])
    expected = [r["s0_limit"] for r in reference.values() if np.isfinite(r["s0_limit"])]
    assert view.plot.limit.data["s0"] == expected
    assert view.map.attrs["parameters_hash"] != ""
    with param.parameterized.discard_events(dash):
        dash.N0, dash.b_M, dash.rail = 100.0, 3000.0, "calibrated"


def test_open_store_and_bad_input_keep_the_map(dash, tmp_path):
    view = dash.studies
    if view.path is None:
        _small(view)
        view.start()
        view.wait(600)
    path = view.path
    view.map = None
    view.open(str(path))
    assert view.map is not None
    assert view.map.finished == view.map.total == 3
    assert not view.notice.visible
    shown = view.map
    view.open(str(tmp_path / "missing.zarr"))
    assert view.notice.visible
    assert "not a Zarr store" in view.notice.object
    assert view.map is shown
    view.s0_range.value = (0.01, 0.01)
    view.s0_points.value = 5
    view.start()
    assert not view.running
    assert "s0 range is empty" in view.notice.object
    assert view.map is shown
    view.where.value = "Dask cluster at the address"
    view.address.value = ""
    _small(view, where="Dask cluster at the address")
    view.start()
    assert not view.running
    assert "scheduler address" in view.notice.object


@pytest.mark.slow
def test_map_on_the_local_dask_cluster(dash):
    view = dash.studies
    _small(view, where="local Dask cluster")
    view.v_points.value = 2
    view.start()
    view.wait(900)
    view.poll()
    assert view._outcome == "done", view.status.object
    assert view.map.finished == 2
    reference = run_serial(view.study(), compute.parameters("", "calibrated"))
    for (i, _, _), result in reference.items():
        np.testing.assert_array_equal(view.plot.image.data["image"][0][:, i],
                                      result["largest_real_part"])
