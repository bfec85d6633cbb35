"""The dashboard's "Studies" view without a server: a map asked for at the dashboard's N0, b_M and
rail runs on the server's study queue in the background, its progress and heat map follow, the
result equals the serial study, a finished store is opened by its name from the server's list,
bad input (an empty range, too many points, a name not in the list) shows a notice and keeps the
map.  The queue runs in this process here (tests/conftest.py ``InProcessEngine``); the served app
with the local Dask cluster is in tests/app/server/test_boundary.py."""

from __future__ import annotations

import threading

import numpy as np
import param
import pytest
from bokeh.document import Document
from conftest import InProcessEngine, install_study_queue

from app.dashboard.dashboard import BogieDashboard
from app.dashboard.studies_view import StudiesView
from app.results import compute
from app.services.settings import ServerSettings
from app.services.studies_folder import refusal
from app.services.study_queue import StudyQueue
from model.studies.maps import run_serial


@pytest.fixture(scope="module")
def dash(tmp_path_factory):
    queue, restore = install_study_queue(tmp_path_factory.mktemp("studies"), max_study_points=500)
    dashboard = BogieDashboard()
    assert dashboard.studies.queue is queue
    doc = Document()
    doc.add_root(dashboard.layout.get_root(doc))
    yield dashboard
    restore()


def _small(view):
    view.s0_range.value = (0.002, 0.016)
    view.s0_points.value = 6
    view.v_range.value = (60.0, 200.0)
    view.v_points.value = 3


def test_map_at_the_dashboards_point_equals_serial_study(dash):
    view = dash.studies
    assert any(o is view.layout for o in dash.tabs.objects)  # hooked into the dashboard's tabs
    assert "at most 500 points" in view.where.object  # the server's limit, shown
    with param.parameterized.discard_events(dash):  # no dashboard recomputation needed here
        dash.N0, dash.b_M, dash.rail = 90.0, 2500.0, "wet"
    _small(view)
    view.start()
    assert view.running or view.outcome == "done"
    view.wait(600)
    view.poll()
    assert view.outcome == "done", view.status.object
    assert "done: 3/3" in view.status.object
    assert view.ticket.name in view.status.object  # the store's name, never its path
    assert str(view.queue.folder.root) not in view.status.object
    assert view.progress.value == 3
    assert not view.start_button.disabled
    assert view.store_select.options[0] == view.ticket.name  # the list knows the new store
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
    if view.ticket is None:
        _small(view)
        view.start()
        view.wait(600)
    name = view.ticket.name
    view.map = None
    view.open(name)
    assert view.map is not None
    assert view.map.finished == view.map.total == 3
    assert not view.notice.visible
    shown = view.map
    for bad in ("missing.zarr", str(view.queue.folder.root / name), f"../{name}", ""):
        view.open(bad)
        assert view.notice.visible
        assert refusal("map") in view.notice.object
        assert view.map is shown
    view.s0_range.value = (0.01, 0.01)
    view.s0_points.value = 5
    view.start()
    assert not view.running
    assert "s0 range is empty" in view.notice.object
    assert view.map is shown
    _small(view)
    view.s0_points.value, view.v_points.value = 100, 6  # 600 points > the server's 500
    view.start()
    assert not view.running
    assert "600 points asked; the server runs studies of at most 500 points" in view.notice.object


def test_queue_position_and_stopping_only_ones_own(dash, tmp_path):
    """K = 1: a second session's study waits behind the first and sees its position; a session
    stops its own study only (another session's ticket in hand changes nothing); a stopped
    waiting study leaves the queue; a closed session's waiting study is dropped."""
    gate = threading.Event()

    class GatedEngine(InProcessEngine):  # every study waits at its first chunk for the gate
        @staticmethod
        def map_unordered(function, items):
            gate.wait(120)
            yield from InProcessEngine.map_unordered(function, items)

    queue = StudyQueue(ServerSettings(studies_dir=tmp_path), engine_factory=GatedEngine)
    view = StudiesView(dash, queue=queue)
    _small(view)
    parameters = compute.parameters("", "calibrated")
    try:
        first = queue.submit("another-session", view.study(), parameters)
        assert first.state == "running"
        view.start()
        assert view.ticket.state == "waiting"
        assert "waiting: 0 studies ahead in the queue, 1 running" in view.status.object
        third = queue.submit("third-session", view.study(), parameters)
        assert queue.position(third) == 1
        line, ended = queue.status_line(first, "s0-lines")  # the running one, as its page reads it
        assert not ended
        assert line.startswith("running: 0/"), line
        assert line.endswith("server: 1 of at most 1 running, 2 waiting"), line
        assert not queue.stop(first, view.owner)  # another session's ticket: nothing happens
        assert not first.stop_requested.is_set()
        view.stop()
        assert view.outcome == "stopped"
        assert queue.position(third) == 0
        queue.drop_owner("third-session")  # its browser has left
        assert third.state == "dropped"
        assert queue.counts() == (1, 0)
    finally:
        gate.set()
    assert first.ended.wait(120)
    assert first.state == "done"
    assert queue.counts() == (0, 0)
    queue.close()
