"""Dashboard tests without a browser: the Viewer object, an in-process render of the whole
layout into a Bokeh document, and the served app's liveness endpoint.

Expectations come from the model (the dashboard must show what model/ computes), never from
numbers typed in here.  Building a dashboard computes the stability limit and a root locus
(seconds), so the tests that build one are marked slow.
"""

from __future__ import annotations

import io
import json
import tomllib
import urllib.request

import numpy as np
import pytest

from app.results import compute, mode_drawing
from model import eigen_analysis
from model.mechanics.parameters import parse_parameters

CONTROLS = ("s0", "v", "N0", "b_M", "M0", "f", "D", "dt", "t_end")


# --- cheap pieces --------------------------------------------------------------------------------

def test_decimation_keeps_every_extreme():
    t = np.linspace(0.0, 1.0, 100_001)
    y = np.sin(2 * np.pi * 97 * t) * np.exp(-t)
    y[54_321] = 7.5  # a one-sample spike must survive
    td, (yd,) = compute.decimate(t, [y], buckets=500)
    assert len(td) < 2_100
    assert yd.max() == y.max()
    assert yd.min() == y.min()
    assert np.all(np.diff(td) > 0)


def test_mode_drawing_moves_carried_points_rigidly():
    """A unit roll of the bogie frame moves the secondary spring seats by θ × r."""
    m = compute.model("", "calibrated")
    q = np.zeros(m.n)
    q[m.dofs.index("BF.rx")] = 1.0
    shift = mode_drawing.point_displacements(m, q)
    r = m.positions["secondary.P1"] - m.positions["BF"]
    np.testing.assert_allclose(shift["secondary.P1"], np.cross([1.0, 0.0, 0.0], r))
    assert not np.any(shift["ID1.rim12"])  # the wheelset does not move


# --- the dashboard object --------------------------------------------------------------------------

@pytest.fixture(scope="module")
def dash():
    from app.dashboard.dashboard import BogieDashboard

    return BogieDashboard()


def _verdict(dashboard) -> bool:
    m = compute.model("", dashboard.rail)
    op = dashboard.state().operating_point()
    return eigen_analysis(m, op, vectors=False).stable


def test_an_s0_limit_search_stops_once_no_session_wants_its_speed(dash):
    """Served, s0*(v) searches with a hook that stops it (LimitSuperseded, a Superseded: the
    cache's waiters compute it themselves) once no live session's scheduler wants its key."""
    from app.dashboard.scheduler import LimitSuperseded, _stop_unless_wanted
    from app.results.cache import Superseded

    wanted = dash.state().limit_key()
    other = dash.state().replace(v=dash.v + 7.0).limit_key()
    previous = dash.scheduler._limit.wanted
    dash.scheduler._limit.want(wanted)
    try:
        _stop_unless_wanted(wanted)  # wanted: the search goes on
        with pytest.raises(LimitSuperseded) as stopped:
            _stop_unless_wanted(other)
        assert isinstance(stopped.value, Superseded)
    finally:
        dash.scheduler._limit.want(previous)


@pytest.mark.slow
def test_status_follows_the_model_and_the_published_cases_flip(dash):
    for s0 in (0.005, 0.014, 0.005):
        dash.show_published_case(s0)
        expected = "STABLE" if _verdict(dash) else "UNSTABLE"
        assert dash.s0 == s0
        assert dash.v == 120.0
        assert f">{expected}<" in dash.status.object
    dash.show_published_case(0.005)
    stable_text = dash.status.object
    dash.show_published_case(0.014)
    assert dash.status.object != stable_text, "the two published cases must differ in verdict"


@pytest.mark.slow
def test_peak_table_of_the_published_cases(dash):
    """The first screen's peak table: at s0 = 0.005 ID1's disc clutch swing with its time (the
    model's largest |Δy|, not the pre-fault value at 0 s); at s0 = 0.014 "unbounded with linear
    creep", the model's growth rate and the nonlinear creep's peaks beside it."""
    from model.analysis.response import short_circuit_response

    name = "ID1.disc_clutch.torque"
    m = compute.model("", "calibrated")
    for s0 in (0.005, 0.014):
        dash.show_published_case(s0)
        op = dash.state().replace(s0=s0).operating_point()
        r = short_circuit_response(m, op, dash.state().replace(dt=None).short_circuit(),
                                   dash.t_end, compute.sampling_rate(dash.f), [name])
        table = dash.peaks.object
        if s0 == 0.005:
            swing = r.perturbation(name)
            k = int(np.argmax(np.abs(swing)))
            assert r.t[k] > 0.0
            row = f"{swing[k] / 1e3:.1f}</td><td class=\"t\">{r.t[k]:.4f}</td>"
            assert row in table
            assert "unbounded" not in table
        else:
            growth = eigen_analysis(m, op, vectors=False).max_real_part
            assert growth > 0
            assert "unbounded with linear creep" in table
            assert f"σ = <b>{growth:+.4g} 1/s</b>" in table
            first = min(c.time for c in r.limit_crossings)
            assert f"<td>{first:.4f}</td>" in table  # when it passes M_ad
            assert "the physical answer" in table  # the nonlinear creep's peaks beside it
            assert dash.companion is not None
            assert dash.companion.history.startswith("nonlinear")


@pytest.mark.slow
def test_views_show_the_current_point(dash):
    dash.param.update(s0=0.0065, v=100.0)
    m = compute.model("", "calibrated")
    op = dash.state().replace(s0=0.0065, v=100.0).operating_point()
    result = eigen_analysis(m, op)
    # highlighted eigenvalues on the root locus = the model's lowest complex pairs
    shown = np.array(dash.locus_plot.current.data["x"]) + 1j * np.array(
        dash.locus_plot.current.data["y"]) * 2 * np.pi
    # two dense eigen-solves of the same matrix (the dashboard's worker and this test) agree to
    # about eps·κ(λ): on the set calibrated by rank the heavily damped pair −11.4 ± 10.9j
    # differed by 4.3e-9 relative (1e-9 held on the previous set); 1e-7 is still 5 decades
    # below any difference between neighbouring modes
    np.testing.assert_allclose(shown, result.complex_pairs[: len(shown)], rtol=1e-7)
    # status details: largest real part, flutter and divergence counts
    assert f"{result.max_real_part:+.4f}" in dash.details.object
    assert f"flutter pairs (Re &gt; 0): <b>{result.flutter}</b>" in dash.details.object
    # the stability limit and the margin to it
    from model.analysis.stability import stability_limit

    limit = stability_limit(m, op.v, op.N0, op.b_M).s0_limit
    assert f"{limit:.5f}" in dash.details.object
    assert f"{limit - 0.0065:+.5f}" in dash.details.object
    # creep characteristic: operating point on the curve, s0* marked
    assert dash.creep_plot.point.data["s"] == [0.0065]
    assert dash.creep_plot.limit.visible
    # the dashboard finds s0* to LIMIT_XTOL (shown with 5 decimals), the reference to 1e-7
    assert dash.creep_plot.limit.location == pytest.approx(limit, abs=compute.LIMIT_XTOL)
    # root locus over s0 at the current speed: colour = s0, branches tracked in columns
    values = np.array(dash.locus_plot.points.data["value"])
    assert values.min() == pytest.approx(compute.LOCUS_S0[0])
    assert len(dash.locus_plot.lines.data["xs"]) == dash.locus_result.eigenvalues.shape[1]
    # tables: one row per complex pair / real eigenvalue, in Table 1 / Table 2 layout
    assert dash.click.table.descriptions == [mode.description for mode in dash.point.modes]
    assert f"{result.real_eigenvalues[0]:+.4g}" in dash.eigen_table.object


@pytest.mark.slow
def test_time_histories_change_with_the_excitation(dash):
    dash.param.update(s0=0.005, v=120.0, M0=50.0)
    before = dict(dash.response.peaks)
    sources = dash.response_plots.sources
    assert {"M_C", "ID1.disc_clutch.torque", "ID2.driving_shaft.torque"} <= set(sources.names)
    shown = sources.series("ID1.disc_clutch.torque")
    assert len(shown["t"]) == len(shown["y"]) > 100
    # the decimated curve keeps the extremes of the full-resolution history
    full = dash.response.outputs["ID1.disc_clutch.torque"]
    assert float(np.max(shown["y"])) == pytest.approx(full.max(), rel=1e-6)
    assert float(np.min(shown["y"])) == pytest.approx(full.min(), rel=1e-6)
    dash.M0 = 80.0
    after = dash.response.peaks
    assert abs(after["ID1.driving_shaft.torque"]) != pytest.approx(
        abs(before["ID1.driving_shaft.torque"]))
    assert "ID1.driving_shaft.torque" in dash.peaks.object
    # ±M_ad reference lines at the model's maximal adhesion moment
    from model import adhesion_moment

    m = compute.model("", "calibrated")
    expected = adhesion_moment(m.parameters, 120.0 / 3.6, dash.N0 * 1e3)
    for _, span in dash.response_plots.ad_spans:
        assert abs(span.location) == pytest.approx(expected)
    dash.M0 = 50.0


@pytest.mark.slow
def test_speed_locus_on_demand(dash):
    dash.locus = "v"
    assert dash.locus_result.parameter == "v"
    assert dash.locus_plot.colorbar.title == "v [km/h]"
    dash.locus = "s0"
    assert dash.locus_plot.colorbar.title == "s0 [-]"


@pytest.mark.slow
def test_rail_condition_changes_the_creep_law(dash):
    calibrated = np.array(dash.creep_plot.curve.data["mu"])
    dash.rail = "wet"
    assert not np.array_equal(dash.creep_plot.curve.data["mu"], calibrated)
    toml = tomllib.loads(dash.downloads.parameters_toml().read())
    from model.contact.creep import CREEP_PRESETS

    for name, value in CREEP_PRESETS["wet"].items():
        assert toml[name]["value"] == value
    dash.rail = "calibrated"
    np.testing.assert_array_equal(dash.creep_plot.curve.data["mu"], calibrated)


@pytest.mark.slow
def test_downloads(dash):
    csv = dash.downloads.time_histories_csv().read()
    header, first = csv.splitlines()[:2]
    assert header.startswith("t [s],ID1.driving_shaft.torque [N m]")
    assert float(first.split(",")[0]) == 0.0
    data = np.loadtxt(io.StringIO(csv), delimiter=",", skiprows=1)
    # every output of the history (the plotted ones and the drive parts), time and M_C
    assert data.shape == (len(dash.response.t), 2 + len(compute.HISTORY_OUTPUTS))
    eig = json.loads(dash.downloads.eigenvalues_json().read())
    assert eig["stable"] == dash.point.stable
    assert len(eig["eigenvalues"]) == len(dash.point.eigenvalues)
    toml = dash.downloads.parameters_toml().read()
    parse_parameters(tomllib.loads(toml))  # a valid parameter file


@pytest.mark.slow
def test_rejected_combination_keeps_the_last_result(dash, monkeypatch):
    from model import OperatingPointError

    dash.s0 = 0.005
    last = dash.point

    def reject(*args):
        raise OperatingPointError("creepage s0 = 0.0055 is not allowed: test")

    monkeypatch.setattr(compute, "point_result", reject)
    dash.s0 = 0.0055
    assert dash.notice.visible
    assert "not allowed" in dash.notice.object
    assert dash.point is last
    assert "STABLE" in dash.status.object
    monkeypatch.undo()
    dash.s0 = 0.005
    assert not dash.notice.visible
    assert dash.error == ""


@pytest.mark.slow
def test_sessions_do_not_share_state(dash):
    from app.dashboard.dashboard import BogieDashboard

    other = BogieDashboard()
    other.s0 = 0.014
    assert dash.s0 != 0.014 or dash.point is not other.point
    assert other.sliders["s0"] is not dash.sliders["s0"]
    assert other.sliders["s0"].value == 0.014
    assert dash.sliders["s0"].value == dash.s0


# --- the whole layout rendered into a Bokeh document -------------------------------------------

@pytest.mark.slow
def test_render_whole_layout(dash):
    import panel as pn
    from bokeh.document import Document
    from bokeh.models import Plot

    from app.server.serve import create_app

    doc = Document()
    app = create_app()
    doc.add_root(app.get_root(doc))
    models = list(doc.models)
    classes = {c for model in models for c in (getattr(model, "css_classes", None) or [])}
    for name in CONTROLS:
        assert f"ctl-{name}" in classes, name
    assert "stability-status" in classes
    # only the open tab is in the document (dynamic tabs): the locus and the Response tab's
    # creep, 2 torques, forces, M_C; each other tab's plots join when it is opened
    assert sum(isinstance(model, Plot) for model in doc.models) == 6
    (tabs,) = [t for t in app.select(pn.Tabs) if "views" in t.css_classes]
    plots = {}
    for index in range(len(tabs)):
        tabs.active = index
        plots.update({model.id: model for model in doc.models if isinstance(model, Plot)})
    plots = list(plots.values())
    # locus, creep, 2 torques, forces, M_C, side and top view, Fig. 6 (Im, Re, real), variant s0*,
    # sensitivity tornado, study heat map; design loads: worst case ID1 and ID2, load
    # collective, rainflow matrix ID1 and ID2, envelope heat map; resonances: Campbell diagram,
    # FRF magnitude and phase, forced response to the ripple and to polygonal wheels, the random
    # track's PSD; the verdicts' safety factors
    assert len(plots) == 27
    assert {"root-locus", "fig6-im", "fig6-re", "fig6-real", "variant-limits", "campbell",
            "frf-magnitude", "frf-phase", "ripple-response", "polygon-response",
            "track-psd"} <= {p.name for p in plots}
    titled = {model.title for model in models if getattr(model, "css_classes", None)
              and "ctl-s0" in model.css_classes}
    assert titled == {"creepage s0 [-]"}


# --- served --------------------------------------------------------------------------------------

@pytest.mark.slow
def test_liveness_endpoint_builds_the_app(app_server):
    with urllib.request.urlopen(f"{app_server}/liveness?endpoint=/app", timeout=120) as r:
        assert r.status == 200
    with urllib.request.urlopen(f"{app_server}/app", timeout=120) as r:
        assert r.status == 200
        assert b"Bokeh" in r.read()


def test_displacement_map_matches_the_kinematics():
    """The cached linear map gives the same point translations as the direct kinematics."""
    m = compute.model("", "calibrated")
    q = np.random.default_rng(3).standard_normal(m.n)
    direct = mode_drawing._point_displacements_direct(m, q)
    mapped = mode_drawing.point_displacements(m, q)
    assert direct.keys() == mapped.keys()
    for name in direct:
        np.testing.assert_allclose(mapped[name], direct[name], rtol=1e-12, atol=1e-12)
