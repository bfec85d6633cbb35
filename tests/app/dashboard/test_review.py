"""The dashboard as a design-review tool, without a server: the dense root locus and
Fig. 6, shareable URL state, design variants, the report, click-through modes and the fuzz of
user input.

Expectations come from the model or from the inputs the test makes up, never from numbers of
the current parameter set (it may be re-calibrated).  Tests that build a dashboard compute a
root locus and the stability limit (seconds) and are marked slow.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import assert_self_contained_html

from app.results import compute, locus_geometry
from app.results.case import Case
from app.results.eigenvalue_sweep import fig6_series
from model.mechanics.operating_point import OperatingPoint

# --- root locus: grid, jumps, broken lines -------------------------------------------------------


def test_refine_grid_is_denser_where_branches_move_fast():
    values = np.linspace(0.0, 1.0, 11)
    lam = np.zeros((11, 2), dtype=complex)
    lam[:, 0] = -1.0 + 2j * math.pi * 5.0  # a branch that does not move
    lam[6:, 1] = 10.0  # one that moves only across the interval [0.5, 0.6]
    grid = locus_geometry.refine_grid(values, lam, 200)
    assert len(grid) == 200
    assert grid[0] == values[0]
    assert grid[-1] == values[-1]
    assert np.all(np.diff(grid) > 0)
    inside = np.sum((grid > 0.5) & (grid < 0.6))
    elsewhere = np.sum((grid > 0.1) & (grid < 0.2))
    assert inside > 10 * elsewhere  # the fast interval holds most of the points
    # every coarse point stays a grid point (the dense sweep passes through the coarse one)
    assert np.all(np.isin(values, grid))


def test_refine_grid_without_motion_is_even():
    values = np.linspace(0.0, 1.0, 5)
    grid = locus_geometry.refine_grid(values, np.ones((5, 3), dtype=complex), 201)
    np.testing.assert_allclose(np.diff(grid), 1.0 / 200, rtol=1e-9)


def test_a_jump_breaks_the_line():
    values = np.linspace(0.0, 1.0, 50)
    lam = (-1.0 + 0.1 * values + 2j * math.pi * (3.0 + values))[:, None].astype(complex)
    lam[30:, 0] += 5.0  # a jump of 5 [1/s] between points 29 and 30
    jumps = locus_geometry.locus_jumps(values, lam)
    assert jumps.shape == (49, 1)
    assert np.flatnonzero(jumps[:, 0]).tolist() == [29]
    (re,) = locus_geometry.broken_columns(lam.real, jumps)
    assert len(re) == 51
    assert np.isnan(re[30])
    assert np.isfinite(np.delete(re, 30)).all()


def test_a_smooth_branch_has_no_jumps():
    values = np.linspace(0.0, 1.0, 200) ** 2  # uneven grid: the rate per unit decides, not steps
    lam = (np.exp(3 * values) * (-1 + 1j))[:, None]
    assert not locus_geometry.locus_jumps(values, lam).any()


def test_an_unresolved_acceleration_breaks_the_line():
    """A branch running into a collision: its steps grow 4, 5, 7, 10, 16, 50 [1/s], then 5.
    The two long, unresolved steps are breaks; the short ones before and after are not, nor
    are the even steps of a second branch that sets the plot's spans (−250…0 1/s, 0…20 Hz:
    each of its steps is 10 % of the plot, but no faster than its neighbours)."""
    steps = np.array([4.0, 4.0, 5.0, 7.0, 10.0, 16.0, 50.0, 5.0, 3.0, 3.0])
    lam = np.empty((len(steps) + 1, 2), dtype=complex)
    lam[:, 0] = -80.0 - np.concatenate([[0.0], np.cumsum(steps)]) + 2j * math.pi * 10.0
    lam[:, 1] = np.linspace(-250.0, 0.0, len(lam)) + 2j * math.pi * np.linspace(0.0, 20.0, len(lam))
    values = np.linspace(0.001, 0.002, len(lam))
    jumps = locus_geometry.locus_jumps(values, lam)
    assert np.flatnonzero(jumps[:, 0]).tolist() == [5, 6]
    assert not jumps[:, 1].any()


def test_fig6_series_splits_complex_and_real_branches():
    values = np.linspace(0.001, 0.02, 20)
    lam = np.zeros((20, 3), dtype=complex)
    lam[:, 0] = -0.5 + 100 * (values - 0.01) + 2j * math.pi * 4.0  # crosses Re = 0 at 0.015
    lam[:, 1] = -3.0 - values  # real throughout
    lam[:10, 2] = -1.0 + 2j * math.pi * 1.0  # complex (ζ = 0.16), then real
    lam[10:, 2] = -2.5
    locus = compute.LocusResult("s0", values, lam, lam.real.max(axis=1) <= 0, True,
                                locus_geometry.locus_jumps(values, lam))
    series = fig6_series(locus)
    assert len(series.x) == 2
    assert len(series.real_x) == 2
    np.testing.assert_allclose(series.im_hz[0], 4.0)
    assert np.isnan(series.im_hz[1][10:]).all()
    assert np.isfinite(series.im_hz[1][:10]).all()
    assert np.isnan(series.real[1][:10]).all()
    assert series.crossing == pytest.approx(0.015, abs=1e-12)  # linear branch: exact


@pytest.mark.slow
def test_dense_locus_is_the_models_eigenvalues():
    """The dense sweep has LOCUS_DENSE_POINTS points and contains the coarse grid; at sample
    points every tracked eigenvalue is an eigenvalue of the full model (model.analysis.eigen) — within
    1e-5 of max(|λ|, 1 1/s): root_locus controls its estimated error to 1e-6 of
    max(|λ|, LOCUS_LAMBDA_FLOOR) inside the tracked disc (the estimate is conservative)."""
    assert compute.LOCUS_LAMBDA_FLOOR <= 1.0
    from model import eigen_analysis

    key = Case(s0=0.005, v=120.0, N0=100.0, b_M=3000.0).sweep("s0")
    coarse = compute.locus_result(key)
    dense = compute.dense_locus_result(key)
    assert dense.dense
    assert not coarse.dense
    assert len(dense.values) == compute.LOCUS_DENSE_POINTS >= 200
    assert np.all(np.isin(coarse.values, dense.values))
    m = compute.model("", "calibrated")
    for i in (1, len(dense.values) // 2, len(dense.values) - 2):
        op = OperatingPoint.from_kmh(float(dense.values[i]), 120.0, 100e3, 3000.0)
        exact = eigen_analysis(m, op, vectors=False).eigenvalues
        for lam in dense.eigenvalues[i]:
            if abs(lam) < 1.5 * 2 * math.pi * compute.LOCUS_MAX_HZ:
                assert np.min(np.abs(exact - lam)) < 1e-5 * max(abs(lam), 1.0), (i, lam)


# --- shareable state: URL query ---------------------------------------------------------------------

ISSUE_QUERY = {"s0": "0.014", "v": "200", "n0": "100000", "bm": "3000", "m0": "50000", "f": "90",
               "decay": "0.04", "t_end": "2"}


def _class_params():
    from app.dashboard.dashboard import BogieDashboard

    return BogieDashboard.param


def test_query_with_the_cli_names_and_units():
    from app.dashboard.url_state import parse_query

    values, variant, tab, notices = parse_query(
        {**ISSUE_QUERY, "phase": "0.002", "rail": "wet", "locus": "v", "mode": "3",
         "tab": "fig-6", "variant": "gear_ratio:4.5"}, _class_params(), ["response", "fig-6"])
    assert notices == []
    assert values["s0"] == 0.014
    assert values["v"] == 200.0
    assert values["N0"] == pytest.approx(100.0)  # n0 [N] -> N0 [kN]
    assert values["M0"] == pytest.approx(50.0)  # m0 [N m] -> M0 [kN m]
    assert values["dt"] == pytest.approx(2.0)
    assert values["dt_auto"] is False
    assert (values["rail"], values["locus"], values["mode"], tab) == ("wet", "v", 3, "fig-6")
    assert variant == "gear_ratio:4.5"


@pytest.mark.parametrize(("name", "text"), [
    ("s0", "nan"), ("s0", "inf"), ("s0", "-1"), ("v", "1e400"), ("v", "fast"), ("n0", "1e30"),
    ("t_end", ""), ("rail", "icy"), ("locus", "<script>"), ("mode", "0"), ("mode", "2.5"),
    ("tab", "nowhere"), ("variant", "gear_ratio:nan"), ("variant", "no_such:1"),
    ("variant", "gear_ratio"), ("variant", "polach_kS:0.9,polach_kA:0.1"), ("s0", "1" * 500),
    ("variant", "gear_ratio:1e300"), ("variant", "x" * 5000),
    ("bogus", "1")])
def test_bad_query_values_give_a_notice_and_the_default(name, text):
    from app.dashboard.url_state import parse_query

    values, variant, tab, notices = parse_query({name: text, "f": "100"}, _class_params(),
                                                ["response"])
    assert len(notices) == 1
    assert (name in notices[0] or "variant" in notices[0])
    assert values == {"f": 100.0}  # the good value is used, the bad one left at its default
    assert variant == ""
    assert tab is None


def test_variant_text_round_trips():
    from app.results import variants

    base = variants.base_parameters("")
    changes = {"gear_ratio": base["gear_ratio"] * 1.1,
               "driving_shaft_stiffness": base["driving_shaft_stiffness"] * 0.7,
               "yaw_damping": base["yaw_damping"] / 3}
    text = variants.encode(changes)
    assert text.split(",")[0].startswith("driving_shaft_stiffness:")  # sorted: canonical
    assert variants.decode(text) == changes  # exact: shortest round-trip repr
    key = variants.set_key("", changes)
    assert variants.split_key(key) == ("", changes)
    assert variants.set_key("", {}) == ""
    varied = variants.parameters_of_key(key)
    assert variants.differences(base, varied).keys() == changes.keys()
    assert variants.set_hash(varied) != variants.set_hash(base)


@pytest.mark.slow
def test_link_restores_the_state_and_the_controls():
    from app.dashboard.dashboard import BogieDashboard

    query = {**ISSUE_QUERY, "rail": "dry", "tab": "fig-6", "variant": "gear_ratio:4.5"}
    dash = BogieDashboard(query=query)
    assert not dash.input_notice.visible
    assert (dash.s0, dash.v, dash.N0, dash.M0, dash.rail) == (0.014, 200.0, 100.0, 50.0, "dry")
    assert dash.sliders["v"].value == 200.0
    assert dash.sliders["s0"].value == 0.014
    assert dash.tab_names[dash.tabs.active] == "fig-6"
    assert dash.set_key == "|gear_ratio:4.5"
    assert dash.point.case.set_key == dash.set_key
    assert compute.parameters(dash.set_key, "dry")["gear_ratio"] == 4.5
    # the link of this session restores the same settings
    from urllib.parse import parse_qsl

    again = dict(parse_qsl(dash.share_query()))
    assert {k: again[k] for k in query} == query


# --- design variants ---------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def dash():
    from app.dashboard.dashboard import BogieDashboard

    return BogieDashboard()


def _toml_bytes(**changes) -> bytes:
    from model.mechanics.parameters import dumps_parameters, load_parameters

    return dumps_parameters(load_parameters().replace(**changes)).encode()


@pytest.mark.slow
def test_variant_editor_upload_and_comparison(dash):
    from model import build_model, eigen_analysis

    view = dash.variant_view
    dash.tabs.active = dash.tab_names.index("variant")  # the comparison runs while shown
    base_ratio = view.base["gear_ratio"]
    view.inputs["gear_ratio"].value = base_ratio * 1.15
    assert view.apply_inputs()
    assert dash.variant == f"gear_ratio:{base_ratio * 1.15!r}"
    # the dashboard shows the variant's eigenvalues (the model of the changed set)
    varied = compute.parameters(dash.set_key, "calibrated")
    assert varied["gear_ratio"] == base_ratio * 1.15
    op = dash.state().operating_point()
    expected = eigen_analysis(build_model(varied), op).complex_pairs[0]
    assert complex(dash.point.modes[0].eigenvalue) == pytest.approx(expected, rel=1e-9)
    # beside the baseline: both sides computed, the changed set differs in its loads
    base_side, variant_side = view.comparison
    assert base_side.key == ""
    assert variant_side.key == dash.set_key
    assert base_side.response.peaks != variant_side.response.peaks
    assert 'class="changed"' in view.table.object
    assert len(view.limit_sources["variant"].data["v"]) >= 3
    assert "gear_ratio" in view.summary.object
    # upload: a whole set, kept as its differences from the bundled one
    upload = _toml_bytes(silent_block_stiffness_z=view.base["silent_block_stiffness_z"] * 3)
    view.upload.value = upload
    assert set(view.changes) == {"silent_block_stiffness_z"}
    assert view.inputs["gear_ratio"].value == base_ratio  # the editor follows the variant
    # download: a valid parameter file of the variant
    import tomllib

    from model.mechanics.parameters import parse_parameters

    downloaded = parse_parameters(tomllib.loads(view._download().read()))
    assert downloaded["silent_block_stiffness_z"] == view.base["silent_block_stiffness_z"] * 3
    view.set_changes({})
    assert dash.set_key == ""


BAD_UPLOADS = {
    "malformed": b"gear_ratio = { value = ",
    "not utf-8": b"\xff\xfe\x00bad",
    "oversized": b"#" * 300_000,
    "nan": b"",  # filled in below: a full set with NaN
    "wrong type": b"",
    "unknown name": b"",
    "missing names": b'gear_ratio = { value = 4.0, unit = "1" }\n',
    "out of range": b"",
}


def _bad_upload(kind: str) -> bytes:
    text = _toml_bytes().decode()
    line = next(x for x in text.splitlines() if x.startswith("gear_ratio ="))
    if kind == "nan":
        return text.replace(line, 'gear_ratio = { value = nan, unit = "1", note = "" }').encode()
    if kind == "wrong type":
        return text.replace(line, 'gear_ratio = { value = "4", unit = "1", note = "" }').encode()
    if kind == "unknown name":
        return (text + 'warp_drive = { value = 1.0, unit = "1", note = "" }\n').encode()
    if kind == "out of range":
        return text.replace(line, 'gear_ratio = { value = -4.0, unit = "1", note = "" }').encode()
    return BAD_UPLOADS[kind]


@pytest.mark.slow
@pytest.mark.parametrize("kind", list(BAD_UPLOADS))
def test_bad_uploads_give_a_notice_and_change_nothing(dash, kind):
    before = (dash.variant, dash.point, dash.s0)
    dash.input_notice.visible = False
    dash.variant_view.upload.value = _bad_upload(kind)
    assert dash.input_notice.visible, kind
    assert "not used" in dash.input_notice.object
    assert (dash.variant, dash.point, dash.s0) == before


@pytest.mark.slow
@pytest.mark.parametrize("value", [float("nan"), float("inf"), -1.0, 0.0, 1e300, None, "4"])
def test_bad_editor_values_give_a_notice_and_change_nothing(dash, value):
    view = dash.variant_view
    before = (dash.variant, dash.point)
    dash.input_notice.visible = False
    try:
        view.inputs["gear_ratio"].value = value
    except ValueError:  # the widget itself refused it (a string): also nothing changed
        assert (dash.variant, dash.point) == before
        return
    finally_ok = view.apply_inputs()
    assert not finally_ok
    assert dash.input_notice.visible
    assert (dash.variant, dash.point) == before
    view.inputs["gear_ratio"].value = view.base["gear_ratio"]


# --- report ----------------------------------------------------------------------------------------

@pytest.mark.slow
def test_report_of_a_variant_is_self_contained_and_complete():
    from app.report.page import build_report
    from app.results.variants import parameters_of_key, set_hash

    base = compute.parameters("", "calibrated")
    key = f"|gear_ratio:{base['gear_ratio'] * 1.1!r}"
    case = Case(set_key=key, s0=0.014, v=120.0, N0=100.0, b_M=3000.0, M0=50.0, f=90.0, D=0.04,
                dt=None, t_end=0.5)
    text = build_report(case)
    assert_self_contained_html(text)
    point = compute.point_result(case)
    verdict = "STABLE" if point.stable else "UNSTABLE"
    assert f'">{verdict}</span>' in text
    assert set_hash(parameters_of_key(key)) in text
    assert "gear_ratio" in text  # the difference from the baseline
    # Table 1 layout ("Eigenvalues at"), Table 2 layout ("Mode shapes"), code version and date
    for heading in ("Operating point", "Root locus", "Fig. 6", "Eigenvalues at", "Mode shapes",
                    "Peaks", "code 0.", " UTC", "Differences from the baseline", "Resonances",
                    "Crossings"):
        assert heading in text, heading
    for name in ("root-locus", "fig6-im", "fig6-re", "fig6-real", "campbell", "frf-magnitude",
                 "ripple-response"):
        assert f'"{name}"' in text, name  # the figures, by name, in the embedded document
    assert f"{point.max_real_part:+.4f}" in text


# --- click-through modes -------------------------------------------------------------------------

@pytest.mark.slow
def test_clicking_a_table_row_or_a_diamond_shows_that_mode(dash):
    from model import build_model, eigen_analysis
    from model.analysis.modes import mode_character

    dash.param.update(s0=0.005, v=120.0)
    click = dash.click
    click.table.table.selection = [3]  # a click on the fourth row
    assert dash.mode == 4
    mode = dash.point.modes[3]
    assert mode.description in click.detail.object
    assert "ν = 4" in click.detail.object
    # the energy shares are the model's (model.analysis.modes) for that mode
    m = build_model(compute.parameters("", "calibrated"))
    result = eigen_analysis(m, dash.state().replace(s0=0.005, v=120.0).operating_point())
    character = mode_character(m, result, int(result.complex_index[3]))
    top = max(character.kinetic, key=character.kinetic.get)
    assert mode.kinetic[top] == pytest.approx(character.kinetic[top], rel=1e-9)
    assert f"{character.kinetic[top]:.1%}" in click.detail.object
    # the shape views show that mode
    moved = dash.mode_plot.views["side"][3].data["x"]
    dash.locus_plot.current.selected.indices = [0]  # a tap on the first diamond
    assert dash.mode == 1
    assert dash.mode_plot.views["side"][3].data["x"] != moved
    assert dash.point.modes[0].description in click.detail.object


@pytest.mark.slow
def test_tapping_a_sweep_point_shows_the_mode_there(dash):
    dash.param.update(s0=0.005, v=120.0, locus="s0")
    data = dash.locus_plot.points.data
    index = int(np.argmin(np.abs(np.asarray(data["s0"]) - 0.012)
                          + 1e3 * (np.asarray(data["y"]) < 0.5)))  # a complex point near 0.012
    dash.locus_plot.points.selected.indices = [index]
    shown = dash.click.shown
    # the mode shown is the model's eigenvalue nearest to the tapped one at that s0
    tapped = data["x"][index] + 1j * data["y"][index] * 2 * math.pi
    assert abs(shown.eigenvalue - tapped) < 1e-4 * abs(tapped)
    assert f"s0 = {data['s0'][index]:.5g}" in dash.click.detail.object
    assert shown.description in dash.click.detail.object
