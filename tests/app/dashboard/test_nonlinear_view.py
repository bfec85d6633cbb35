"""The dashboard's nonlinear creep without a browser: the creep-model switch, the anti-slip controls,
the overlays, the creepage paths and the required reaction time in the status.

Expectations come from model/ (the dashboard must show what the model computes).  Tests that
build a dashboard are slow (it computes the stability limit and a root locus)."""

from __future__ import annotations

import numpy as np
import pytest

from app.dashboard.nonlinear_view import (
    REACTION_DELAYS,
    anti_slip_key,
    nonlinear_histories,
    reaction,
    reaction_key,
)
from app.results import compute
from app.results.case import Case
from model.analysis.antislip import required_reaction_time
from model.analysis.nonlinear import AntiSlip, NonlinearError, nonlinear_response
from model.analysis.response import ShortCircuit


def test_anti_slip_key_validates():
    assert anti_slip_key(True, 0.1, 0.3, 10.0) == (True, 0.1, 0.3, 10.0)
    for bad in ((True, -0.1, 0.3, 10.0), (True, 0.1, 0.0, 10.0), (True, 0.1, 0.3, -1.0)):
        with pytest.raises(NonlinearError):
            anti_slip_key(*bad)


def _case(s0: float, t_end: float = 2.0) -> Case:
    """The case at 120 km/h, N0 = 100 kN, b_M = 3000 N m s/rad, the default short circuit."""
    return Case(s0=s0, v=120.0, N0=100.0, b_M=3000.0, M0=50.0, f=90.0, D=0.04, dt=None,
                t_end=t_end)


def test_histories_are_the_model_result():
    shown = nonlinear_histories(_case(0.014, t_end=1.0), (True, 0.1, 0.3, 10.0))
    m = compute.model("", "calibrated")
    op = _case(0.014).operating_point()
    r = nonlinear_response(m, op, ShortCircuit(), 1.0, compute.RESPONSE_FS,
                           anti_slip=AntiSlip(True, 0.1, 0.3, 10.0))
    for name in compute.RESPONSE_OUTPUTS:
        assert shown.peaks[name] == pytest.approx(r.peaks[name], rel=1e-12)
        _, y = shown.plot[name]
        assert np.abs(y).max() == pytest.approx(abs(r.peaks[name]), rel=1e-6)  # float32
    assert shown.detection_time == pytest.approx(r.detection_time)
    assert set(shown.paths) == set(r.creepage)


@pytest.fixture(scope="module")
def dash():
    from app.dashboard.dashboard import BogieDashboard

    return BogieDashboard()


@pytest.mark.slow
def test_creep_switch_overlays_and_paths(dash):
    view = dash.nonlinear
    dash.param.update(s0=0.005, v=120.0)
    assert len(view.sources.series("ID2.disc_clutch.torque")["t"]) == 0  # linear: nothing extra
    view.creep.value = "nonlinear"
    shown = view.sources.series("ID2.disc_clutch.torque")
    t, y = shown["t"], shown["y"]
    assert len(t) > 100
    assert np.abs(y).max() == pytest.approx(abs(view.histories.peaks["ID2.disc_clutch.torque"]),
                                            rel=1e-6)
    assert len(view.paths.series("ID2.rim12")["s"]) > 100
    assert "nonlinear creep shown" in view.status.object
    # the linear result is still there beside it
    assert len(dash.response_plots.sources.series("ID2.disc_clutch.torque")["t"]) > 100
    view.creep.value = "linear"
    assert len(view.sources.series("ID2.disc_clutch.torque")["t"]) == 0


@pytest.mark.slow
def test_bad_anti_slip_input_shows_a_notice_and_keeps_the_state(dash):
    view = dash.nonlinear
    view.creep.value = "nonlinear"
    view.anti_slip.value = True
    before_key, before = view.valid, view.histories
    view.threshold.value = 0.0
    assert view.notice.visible
    assert "threshold" in view.notice.object
    assert view.valid == before_key
    assert view.histories is before
    view.threshold.value = 0.3
    assert not view.notice.visible
    view.delay.value = -1.0
    assert view.notice.visible
    assert "delay" in view.notice.object
    view.delay.value = 0.1
    assert not view.notice.visible
    view.anti_slip.value = False
    view.creep.value = "linear"


@pytest.mark.slow
def test_unstable_point_shows_the_required_reaction_time(dash):
    dash.param.update(s0=0.014, v=120.0)
    assert not dash.point.stable
    status = dash.nonlinear.status.object
    assert "required anti-slip reaction time" in status
    m = compute.model("", "calibrated")
    op = dash.state().replace(s0=0.014, v=120.0).operating_point()
    expected = required_reaction_time(m, op, delays=REACTION_DELAYS, t_end=2.0,
                                      fs=compute.RESPONSE_FS / 2)
    shown = dash.nonlinear.reaction
    assert shown.reason == expected.reason
    if expected.required_delay is not None:
        assert shown.required_delay == pytest.approx(expected.required_delay, abs=1e-9)
        assert f"{expected.required_delay:.2f} s" in status
    dash.param.update(s0=0.005)
    assert "reaction time" not in dash.nonlinear.status.object


def test_reaction_is_cached_plain_data():
    key = (_case(0.014), 0.3, 10.0)
    first = reaction(*key)
    assert reaction(*key) is first
    assert first.limit > 0


def test_a_reaction_search_no_session_wants_stops_at_once():
    """A reaction-time search whose key no live view wants (superseded, or its session closed)
    stops before its first nonlinear run instead of holding the shared worker for ≈ 20 runs."""
    import time

    from app.dashboard.nonlinear_view import ReactionSuperseded, wanted_reaction

    start = time.perf_counter()
    with pytest.raises(ReactionSuperseded):
        wanted_reaction(_case(0.01371), 0.3, 10.0)
    assert time.perf_counter() - start < 5.0  # no nonlinear run (each ≈ 0.5 s) was started


def _questions_until_stopped(wants: str, key, call, superseded) -> int:
    """How many times ``call()`` asks a stand-in view (its method ``wants``: wants_reaction or
    wants_companion) whether ``key`` is still wanted before it raises ``superseded``; the view
    wants it for its first three questions."""
    from app.dashboard.nonlinear_view import _VIEWS

    class MovingView:
        asked = 0

    def answer(view, asked_key):
        assert asked_key == key
        view.asked += 1
        return view.asked <= 3

    setattr(MovingView, wants, answer)
    view = MovingView()
    _VIEWS.add(view)
    try:
        with pytest.raises(superseded):
            call()
    finally:
        _VIEWS.discard(view)
    return view.asked


def test_a_reaction_search_stops_inside_a_run_once_its_view_moves_on():
    """The search asks whether it is still wanted before every block of every nonlinear run (not
    only between runs): a view whose sliders moved on stops it within one block."""
    from app.dashboard.nonlinear_view import ReactionSuperseded, wanted_reaction

    arguments = (_case(0.01372), 0.3, 10.0)
    asked = _questions_until_stopped("wants_reaction", reaction_key(*arguments),
                                     lambda: wanted_reaction(*arguments), ReactionSuperseded)
    # asked before the search and before each block of the first run (2 s at 5 kHz: 5 blocks);
    # the fourth question, the first run's third block, stopped it
    assert asked == 4


def test_a_companion_history_no_session_wants_stops_at_once():
    """The companion history (beside a linear history that grows without bound) whose key no
    live view wants stops before its run: served, it would hold a background worker."""
    from app.dashboard.nonlinear_view import CompanionSuperseded, wanted_companion

    key = compute.HistoryKey(_case(0.01373), anti_slip_key(False, 0.1, 0.3, 10.0))
    with pytest.raises(CompanionSuperseded):
        wanted_companion(key)
    assert compute._known("nonlinear", key.case, key.anti_slip) is None


def test_a_companion_history_stops_inside_its_run_once_its_view_moves_on():
    """The companion asks whether it is still wanted before every block of its run: a view
    that moved on stops it within one block, and nothing is kept in the results cache."""
    from app.dashboard.nonlinear_view import CompanionSuperseded, wanted_companion

    key = compute.HistoryKey(_case(0.01374), anti_slip_key(False, 0.1, 0.3, 10.0))
    asked = _questions_until_stopped("wants_companion", key, lambda: wanted_companion(key),
                                     CompanionSuperseded)
    # asked before the run and before each of its blocks: the run's third block stopped it
    assert asked == 4
    assert compute._known("nonlinear", key.case, key.anti_slip) is None
