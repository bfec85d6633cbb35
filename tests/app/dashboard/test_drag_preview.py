"""A dragged slider's preview on the dashboard object (no server: a preview is shown at once):
shown in the lighter style over the committed status, taken down by the full answer or by a
release that changes nothing; no preview for the committed value (a keyboard step's ``value``)
nor for a value the parameter refuses."""

from __future__ import annotations

import pytest

pytestmark = pytest.mark.slow  # the dashboard computes its first view, s0*(v) and the dense locus


@pytest.fixture(scope="module")
def dash():
    from app.dashboard.dashboard import BogieDashboard

    return BogieDashboard()


def test_a_held_slider_previews_and_the_full_answer_replaces_it(dash):
    from model.analysis.linear_system import dense_decompositions

    assert dash.limit is not None  # s0*(120 km/h) is known: the s0 previews are exact verdicts
    committed = dash.status.object
    assert "preview" not in committed
    before = dense_decompositions()
    dash.drag_preview.request("s0", dash.s0)  # the committed value (a release, a key step)
    dash.drag_preview.request("s0", float("nan"))  # refused by the parameter: ignored
    dash.drag_preview.request("s0", 1.0)
    assert dash.status.object == committed
    assert len(dash.locus_plot.preview.data["x"]) == 0

    dash.drag_preview.request("s0", 0.0121)
    assert 'data-verdict="unstable"' in dash.status.object
    assert "preview" in dash.status.object
    assert "s0 = 0.0121, limit s0* = " in dash.status.object
    assert len(dash.locus_plot.preview.data["x"]) > 0
    assert list(dash.creep_plot.preview.data["s"]) == [0.0121]
    assert dash.details.styles == {"opacity": "0.45"}
    for v in (135.0, 140.0):  # the reduced model of the locus on screen
        dash.drag_preview.request("v", v)
    assert 'data-v="140"' in dash.status.object
    assert dense_decompositions() == before
    assert dash.drag_preview.shown == 3

    # dragged back to the committed value: the committed status again
    dash.drag_preview.request("s0", dash.s0)
    assert dash.status.object == committed
    dash.drag_preview.request("s0", 0.0121)
    assert "preview" in dash.status.object

    # a release that changes nothing: the preview goes at once
    dash.drag_preview.release()
    dash.drag_preview.end()
    assert dash.status.object == committed
    assert len(dash.locus_plot.preview.data["x"]) == 0
    assert len(dash.creep_plot.preview.data["s"]) == 0
    assert dash.details.styles == {}

    # a release to a new value: its full answer replaces the preview
    dash.drag_preview.request("s0", 0.0121)
    dash.s0 = 0.0121
    assert "preview" not in dash.status.object
    assert ">UNSTABLE<" in dash.status.object
    assert len(dash.locus_plot.preview.data["x"]) == 0
    dash.s0 = 0.005
