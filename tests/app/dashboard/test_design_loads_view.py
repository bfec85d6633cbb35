"""The dashboard's design loads without a server: the worst case over every fault instant at the
dashboard's point, the load spectrum of the history on screen, the grid envelope from the Design
loads tab on the server's study queue (run here in this process: tests/conftest.py
``InProcessEngine``), the peak table / CSV / report of the nonlinear history, and the report's
Design loads section.  The served tab in Chromium: tests/app/dashboard/test_design_loads_browser.py.

Expectations come from model/ (single responses, the model's envelope, the ``rainflow``
package), never from numbers typed in here.  Tolerances, and why:

* **1e-6 of the output's peak** between the worst case's history at the dashboard's Δt and the
  Response tab's history, and for "the scenario a link opens reproduces the peak": both sides are
  the same exact closed form evaluated from different inputs (three responses combined against
  one), which agree to ≈ 1e-8 of the peak (tests/model/studies/test_envelope.py); 1e-6 is the modal form's
  own error bound (docs/response.md).
* **1e-6 of the peak** for "every fault instant ≥ each of 36 single responses at other Δt":
  a + √(b² + c²) ≥ a + b cos φ + c sin φ holds exactly for the three-term family, but the single
  responses differ from the family by up to ≈ 1e-8 of the peak (above): the margin covers that
  difference, as the 1e-6 above.
* **1 % of the peak** for "the closed form is within a 36-instant grid": the grid misses the worst
  phase by at most 5°, so by at most 1 − cos 5° = 0.38 % of the oscillating part.
* **1e-6 relative** for the equivalent ranges against ``rainflow.count_cycles`` (the
  target; both sum the same terms in another order).
* The plots are float32 (half the bytes to the browser): 1e-6 relative against the float64
  results.
"""

from __future__ import annotations

import io
import threading

import numpy as np
import param
import pytest
import rainflow
from bokeh.document import Document
from conftest import InProcessEngine, install_study_queue

from app.results import compute
from app.results.case import Case
from app.results.tables import format_kilo, format_load
from model.analysis.load_spectrum import N_REF

# s0, v [km/h], N0 [kN], b_M; M0 [kN m], f, D, Δt automatic, t_end [s]
CASE = Case(s0=0.005, v=120.0, N0=100.0, b_M=3000.0, M0=50.0, f=90.0, D=0.04, dt=None, t_end=1.0)


# --- the cached computations ---------------------------------------------------------------------

def test_worst_case_bounds_every_single_response_and_keeps_the_response_tabs_history():
    worst = compute.worst_case_result(CASE)
    response = compute.response_result(CASE)
    assert set(worst.units) == set(compute.DRIVE_PARTS)
    assert worst.dt == pytest.approx(response.fault_instant, abs=1e-15)
    assert worst.dt_auto
    for name in compute.DRIVE_PARTS:
        y = response.outputs[name]
        scale = np.abs(y).max()
        # the history at the dashboard's Δt is the Response tab's history
        assert worst.at_dt_max[name] == pytest.approx(y.max(), abs=1e-6 * scale)
        assert worst.at_dt_min[name] == pytest.approx(y.min(), abs=1e-6 * scale)
    # 36 single responses (the Response tab's own computation) at fault instants over a period
    period = 1.0 / CASE.f
    grid = np.arange(36) / 36 * period - period / 2
    singles = [compute.response_result(CASE.replace(dt=dt * 1e3)) for dt in grid]
    for name in compute.DRIVE_PARTS:
        highest = max(r.outputs[name].max() for r in singles)
        lowest = min(r.outputs[name].min() for r in singles)
        scale = max(abs(highest), abs(lowest))
        assert worst.max[name] >= highest - 1e-6 * scale, name
        assert worst.min[name] <= lowest + 1e-6 * scale, name
        assert worst.max[name] - highest <= 0.01 * scale, name
        assert lowest - worst.min[name] <= 0.01 * scale, name
    # the Δt and time of the max reproduce it in a single response
    name = "ID1.driving_shaft.torque"
    again = compute.response_result(CASE.replace(dt=worst.phase_of_max[name] * 1e3))
    k = round(worst.time_of_max[name] * compute.RESPONSE_FS)
    assert again.outputs[name][k] == pytest.approx(worst.max[name],
                                                   abs=1e-6 * abs(worst.max[name]))
    # the worst case is above the history at the continuity root for the driving shaft (the
    # 90 Hz oscillation reaches it directly: docs/design-loads.md)
    assert worst.max[name] > 1.1 * worst.at_dt_max[name]
    # plots: the whole horizon (stable point), decimated with every extreme kept
    t, upper, lower, at_dt = worst.plot[name]
    assert worst.plot_cut is None
    assert t[-1] == pytest.approx(CASE.t_end)
    assert float(upper.max()) == pytest.approx(worst.max[name], rel=1e-6)
    assert float(lower.min()) == pytest.approx(worst.min[name], rel=1e-6)
    assert float(at_dt.max()) == pytest.approx(worst.at_dt_max[name], rel=1e-6)
    assert compute.worst_case_result(CASE) is worst  # cached


def test_spectra_of_the_linear_and_the_nonlinear_history():
    linear = compute.spectra_result(CASE, None)
    nonlinear_key = (CASE, (False, 0.1, 0.3, 10.0))
    nonlinear = compute.spectra_result(*nonlinear_key)
    assert linear.history == compute.LINEAR_HISTORY
    assert nonlinear.history == "nonlinear creep, anti-slip off"
    for result, history in ((linear, compute.response_result(CASE)),
                            (nonlinear, compute.nonlinear_histories(*nonlinear_key).response)):
        assert set(result.spectra) == set(compute.DRIVE_PARTS)
        for name, spectrum in result.spectra.items():
            counted = rainflow.count_cycles(history.outputs[name])
            assert spectrum.total_cycles == sum(n for _, n in counted)
            for m in (3.0, 5.0):
                reference = (sum(n * r**m for r, n in counted) / N_REF) ** (1 / m)
                assert spectrum.equivalent_range[m] == pytest.approx(reference, rel=1e-6)
            counts, range_edges, _ = result.matrices[name]
            assert counts.sum() == pytest.approx(spectrum.total_cycles, rel=1e-12)
            assert range_edges[-1] == pytest.approx(spectrum.largest_range, rel=1e-12)
    # the two histories differ (nonlinear creep changes the cycles)
    assert linear.spectra["ID1.disc_clutch.torque"].largest_range != pytest.approx(
        nonlinear.spectra["ID1.disc_clutch.torque"].largest_range, rel=1e-3)


def test_the_folder_tells_envelope_stores_from_maps(tmp_path):
    """An envelope store (its zarr.json says study = envelope) is listed as an envelope only;
    every other store as a map (the Studies tab says when one is not a map), a store whose
    zarr.json is not a regular file in neither; a name of the other list is refused with that
    list's one notice."""
    import json
    import os

    from app.services.studies_folder import StudiesFolder, StudyNameRefused, refusal

    folder = StudiesFolder(tmp_path / "studies")
    root = folder.ensure()
    for name, attributes in (("e.zarr", {"study": "envelope"}), ("m.zarr", {"study": "map"}),
                             ("plain.zarr", {})):
        (root / name).mkdir()
        (root / name / "zarr.json").write_text(json.dumps({"attributes": attributes}))
    (root / "broken.zarr").mkdir()
    (root / "broken.zarr" / "zarr.json").write_text("{not json")
    (root / "pipe.zarr").mkdir()
    os.mkfifo(root / "pipe.zarr" / "zarr.json")  # never opened (a reader would wait forever)
    assert folder.names("envelope") == ["e.zarr"]
    assert sorted(folder.names("map")) == ["broken.zarr", "m.zarr", "plain.zarr"]
    with pytest.raises(StudyNameRefused) as refused:
        folder.path("m.zarr", "envelope")
    assert str(refused.value) == refusal("envelope")
    with pytest.raises(StudyNameRefused):
        folder.path("e.zarr", "map")
    assert folder.path("e.zarr", "envelope") == root / "e.zarr"


# --- the dashboard ----------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def dash(tmp_path_factory):
    from app.dashboard.dashboard import BogieDashboard

    queue, restore = install_study_queue(tmp_path_factory.mktemp("studies"), max_study_points=40)
    dashboard = BogieDashboard(query={"tab": "design-loads"})
    assert dashboard.design_loads.grid.queue is queue
    doc = Document()
    doc.add_root(dashboard.layout.get_root(doc))
    yield dashboard
    restore()


def test_the_tab_shows_the_worst_case_and_the_spectrum_at_the_point(dash):
    assert "design-loads" in dash.tab_names
    assert dash.tab_names[dash.tabs.active] == "design-loads"  # tab=design-loads opens it
    assert "tab=design-loads" in dash.share_query()
    view = dash.design_loads
    state = dash.state()
    expected = compute.worst_case_result(state)
    assert view.worst is expected
    for name in compute.DRIVE_PARTS:
        assert format_load(expected.max[name]) in view.worst_table.object
        assert format_load(expected.min[name]) in view.worst_table.object
        assert f"{expected.phase_of_max[name]:.6f}" in view.worst_table.object
    spectra = compute.spectra_result(state, None)
    assert view.spectra is spectra
    assert "linear creep" in view.spectra_note.object
    for name, spectrum in spectra.spectra.items():
        assert f"{spectrum.equivalent_range[3.0]:,.4g}" in view.spectra_table.object, name
    for part in compute.PARTS:
        view.part.value = part
        for drive in ("ID1", "ID2"):
            name = f"{drive}.{part}"
            data = view.worst_plot.sources[drive].data
            assert float(np.max(data["upper"])) == pytest.approx(expected.max[name], rel=1e-6)
            assert float(np.min(data["lower"])) == pytest.approx(expected.min[name], rel=1e-6)
            collective = view.collective.sources[drive].data
            np.testing.assert_array_equal(collective["range"],
                                          spectra.spectra[name].exceedance_range)
            assert len(view.worst_plot.nonlinear[drive].data["t"]) == 0  # linear creep
        assert compute.PART_LABELS[part] in view.worst_plot.figures["ID1"].title.text
    view.part.value = "disc_clutch.torque"


def test_the_worst_case_follows_the_sliders(dash):
    view = dash.design_loads
    before = view.worst
    dash.M0 = 80.0
    assert view.worst is not before
    assert view.worst.case.M0 == 80.0
    assert view.worst.max["ID1.driving_shaft.torque"] > before.max["ID1.driving_shaft.torque"]
    dash.M0 = 50.0


def _small(grid, x=3, y=2):
    grid.axis_x.value, grid.axis_y.value = "s0", "v"
    grid.range_x.value, grid.range_y.value = (0.002, 0.008), (80.0, 160.0)
    grid.points_x.value, grid.points_y.value = x, y
    grid.fault.value = "roots"


def test_a_grid_envelope_from_the_tab_equals_the_models(dash):
    from app.dashboard.url_state import parse_query
    from model.studies.envelope import run_envelope

    grid = dash.design_loads.grid
    _small(grid)
    grid.start()
    grid.wait(600)
    grid.poll()
    assert grid.outcome == "done", grid.status.object
    assert grid.status.object.startswith("done: 6/6 chunks")
    assert grid.ticket.name in grid.status.object
    assert grid.ticket.name.startswith("envelope-")
    assert str(grid.queue.folder.root) not in grid.status.object + grid.table.object
    assert grid.store_select.options[0] == grid.ticket.name  # listed as an envelope …
    assert grid.ticket.name not in grid.queue.folder.names("map")  # … not as a map
    study, parameters = grid.study()
    assert study.scenarios == 12  # 3 x 2 points x 2 continuity roots
    assert study.s0 == pytest.approx((0.002, 0.005, 0.008))
    assert study.N0 == (dash.N0 * 1e3,)
    reference = run_envelope(study, parameters)  # the model, in this process
    shown = {o.name: o for o in reference.outputs}
    assert set(shown) == set(compute.DRIVE_PARTS)
    # the heat map: the max over the scenarios of each grid point
    image = grid.plot.image.data["image"][0]
    assert image.shape == (2, 3)
    assert np.nanmax(image) == pytest.approx(shown[grid.map_output.value].max, rel=1e-12)
    # the table: every drive part's max and min, and a link that opens its scenario
    for output in reference.outputs:
        assert format_load(output.max) in grid.table.object
        assert format_load(output.min) in grid.table.object
    import re

    links = re.findall(r"href='\?([^']+)'", grid.table.object)
    assert len(links) == 2 * len(compute.DRIVE_PARTS)
    query = dict(part.split("=", 1) for part in links[0].replace("&amp;", "&").split("&"))
    values, _variant, tab, notices = parse_query(query, type(dash).param, dash.tab_names)
    assert notices == []
    assert tab == "response"
    first = reference.outputs[0]  # the first row's max
    assert values["s0"] == pytest.approx(first.max_at["s0"])
    # the link holds the scenario's quantities; one it leaves out (the converter's bandwidth,
    # a set's own value) takes the record's default
    again = compute.response_result(Case(rail=values.get("rail", "calibrated"),
                                         **{name: values[name] for name in Case.names()
                                            if name != "rail" and name in values}))
    k = round(first.max_at["time_s"] * study.fs)
    assert again.outputs[first.name][k] == pytest.approx(first.max, abs=1e-6 * abs(first.max))
    # the heat map of another output and of the min
    grid.map_output.value = "ID2.gear_mesh.force"
    grid.map_statistic.value = "min"
    assert np.nanmin(grid.plot.image.data["image"][0]) == pytest.approx(
        shown["ID2.gear_mesh.force"].min, rel=1e-12)
    grid.map_statistic.value = "max"
    # reopened from the folder's list: the same envelope
    grid.data = None
    grid.open(grid.ticket.name)
    assert grid.data is not None
    assert grid.data.complete
    assert not grid.notice.visible
    assert np.nanmax(grid.plot.image.data["image"][0]) == pytest.approx(
        shown["ID2.gear_mesh.force"].max, rel=1e-12)


def test_a_grid_of_a_variant_links_to_the_variant(dash):
    """The grid is computed with the dashboard's set, its variant included, and its links open
    that variant; opened with another set on screen, the table says so and links to the bundled
    set."""
    from model.mechanics.parameters import parameter_hash

    grid = dash.design_loads.grid
    with param.parameterized.discard_events(dash):  # no recomputation of the dashboard needed
        dash.variant = "gear_ratio:4.5"
    try:
        _small(grid, x=2, y=1)
        study, parameters = grid.study()
        assert study.scenarios == 4
        assert parameter_hash(parameters) == parameter_hash(
            compute.parameters(dash.set_key, "calibrated"))
        assert parameters["gear_ratio"] == 4.5
        grid.start()
        grid.wait(600)
        grid.poll()
        assert grid.outcome == "done", grid.status.object
        name = grid.ticket.name
        assert grid.data.attrs["parameters_hash"] == parameter_hash(parameters)
        assert "variant=gear_ratio:4.5" in grid.table.object
    finally:
        with param.parameterized.discard_events(dash):
            dash.variant = ""
    grid.open(name)  # the dashboard now shows the bundled set
    assert "variant=" not in grid.table.object
    assert "computed with another parameter set than the dashboard" in grid.table.object


def test_bad_grids_are_refused_with_a_notice(dash):
    from app.services.studies_folder import refusal

    grid = dash.design_loads.grid
    if grid.data is None:
        _small(grid)
        grid.start()
        grid.wait(600)
        grid.poll()
    shown = grid.data
    cases = [
        (dict(x=5, y=5), "50 scenarios asked; the server runs studies of at most 40 scenarios"),
        # the largest counts the inputs take (a doctored client): refused before any grid
        (dict(x=40, y=40), "3200 scenarios asked"),
    ]
    for sizes, message in cases:
        _small(grid, **sizes)
        grid.start()
        assert not grid.running
        assert message in grid.notice.object, grid.notice.object
        assert grid.data is shown
    _small(grid)
    grid.axis_y.value = "s0"
    grid.start()
    assert "two different axes" in grid.notice.object
    _small(grid)
    grid.range_x.value = (0.005, 0.005)
    grid.start()
    assert "range is empty" in grid.notice.object
    _small(grid)
    dash.nonlinear.creep.value = "nonlinear"
    grid.fault.value = "all"
    grid.start()
    assert "every fault instant needs linear creep" in grid.notice.object
    dash.nonlinear.creep.value = "linear"
    assert grid.data is shown
    # names that are not envelope stores of the list: one notice, the envelope stays
    seen = set()
    for name in ("missing.zarr", str(grid.queue.folder.root / grid.ticket.name),
                 f"../{grid.ticket.name}", "", None, "x" * 10_000):
        grid.notice.visible = False
        grid.open(name)
        assert grid.notice.visible
        seen.add(grid.notice.object)
        assert grid.data is shown
    assert len(seen) == 1
    assert refusal("envelope") in seen.pop()


def test_one_study_per_session_and_the_queue_position(dash, tmp_path):
    """K = 1: the envelope waits behind another session's study and sees its position; while it
    waits, neither a second envelope nor a map of the Studies tab starts for this session; it
    stops only its own study; queue-level, an envelope's scenarios are what the limit counts."""
    from app.dashboard.envelope_grid import EnvelopeGrid
    from app.dashboard.studies_view import StudiesView
    from app.services.settings import ServerSettings
    from app.services.study_queue import StudyQueue, StudyRefused

    gate = threading.Event()

    class GatedEngine(InProcessEngine):  # every study waits at its first chunk for the gate
        @staticmethod
        def map_unordered(function, items):
            gate.wait(120)
            yield from InProcessEngine.map_unordered(function, items)

    queue = StudyQueue(ServerSettings(studies_dir=tmp_path, max_study_points=40),
                       engine_factory=GatedEngine)
    grid = EnvelopeGrid(dash, queue=queue)
    studies = StudiesView(dash, queue=queue)
    assert grid.owner == studies.owner == dash.study_owner  # one claim per session
    _small(grid)
    study, parameters = grid.study()
    try:
        first = queue.submit("another-session", study, parameters)
        assert first.state == "running"
        grid.start()
        assert grid.ticket.state == "waiting"
        assert "waiting: 0 studies ahead in the queue, 1 running" in grid.status.object
        ticket = grid.ticket
        grid.ticket = None  # as a second view of the same session would ask
        grid.start()
        assert "this session's envelope study is still waiting" in grid.notice.object
        grid.ticket = ticket
        studies.s0_points.value, studies.v_points.value = 2, 2
        studies.start()
        assert "this session's envelope study is still waiting" in studies.notice.object
        assert not queue.stop(first, grid.owner)  # another session's study: nothing happens
        grid.stop()
        assert grid.outcome == "stopped"
        big = type(study)(**{**{k: getattr(study, k) for k in study.__dataclass_fields__
                                if k != "kind"}, "s0": tuple(np.linspace(0.002, 0.01, 11))})
        with pytest.raises(StudyRefused, match="44 scenarios asked; the server runs studies of "
                                               "at most 40 scenarios"):
            queue.submit("third-session", big, parameters)
    finally:
        gate.set()
    assert first.ended.wait(120)
    assert first.state == "done"
    queue.close()


# --- the history on screen: linear, or nonlinear creep -------------------------------------------

@pytest.mark.slow
def test_peaks_csv_and_report_describe_the_nonlinear_history(dash):
    """At the unstable case the linear history grows without bound; with nonlinear creep on, the
    peak table, its limit crossings, the CSV and the report describe the bounded nonlinear
    history (the one drawn), and say so."""
    from model.analysis.nonlinear import nonlinear_response

    with param.parameterized.discard_events(dash):
        dash.M0 = 50.0
    dash.show_published_case(0.014)
    assert not dash.point.stable
    linear = dash.response
    assert "linear creep" in dash.peaks.object
    # the blow-up: orders of magnitude beyond anything the wheelset can pass
    assert abs(linear.peaks["ID1.disc_clutch.torque"]) > 1e4 * linear.limits["M_ad"]
    assert dash.downloads.widgets[0].filename == "time_histories.csv"
    dash.nonlinear.creep.value = "nonlinear"
    shown = dash.history
    assert shown is not None
    assert shown.nonlinear
    assert "nonlinear creep, anti-slip off" in dash.peaks.object
    m = compute.model("", "calibrated")
    state = dash.state()  # the primitives the dashboard computes with (rounded)
    op = state.operating_point()
    r = nonlinear_response(m, op, state.short_circuit(),
                           state.t_end, compute.RESPONSE_FS,
                           outputs=list(compute.HISTORY_OUTPUTS))
    for name in compute.HISTORY_OUTPUTS:
        assert shown.peaks[name] == pytest.approx(r.peaks[name], rel=1e-12)
        y, unit = r.outputs[name], r.units[name]
        row = dash.peaks.object.split(f">{name} [")[1].split("</tr>")[0]
        for value in (y.max(), y.min(), r.perturbation_peaks[name]):
            assert f">{format_kilo(value, unit)}</td>" in row, name
    assert "e+" not in dash.peaks.object  # no blow-up in the table
    crossings = [(c.output, c.limit_name, c.time) for c in r.limit_crossings]
    assert [(o, n, t) for o, n, t, _ in shown.crossings] == crossings
    # the CSV: the nonlinear history, named so
    assert dash.downloads.widgets[0].filename == "time_histories_nonlinear.csv"
    csv = dash.downloads.time_histories_csv().read()
    data = np.loadtxt(io.StringIO(csv), delimiter=",", skiprows=1)
    column = 1 + list(shown.outputs).index("ID2.disc_clutch.torque")
    assert np.abs(data[:, column]).max() == pytest.approx(abs(r.peaks["ID2.disc_clutch.torque"]),
                                                          rel=1e-7)  # 8 digits in the CSV
    # the Design loads tab counts the nonlinear history and overlays it
    view = dash.design_loads
    assert "nonlinear creep, anti-slip off" in view.spectra_note.object
    assert view.spectra.history == "nonlinear creep, anti-slip off"
    assert len(view.worst_plot.nonlinear["ID2"].data["t"]) > 100
    assert "The operating point is unstable" in view.worst_note.object
    # the report
    report = dash.downloads.report_html().read()
    assert "Short-circuit response (nonlinear creep, anti-slip off)" in report
    peak = r.outputs["ID2.disc_clutch.torque"].max()
    assert f">{format_kilo(peak, 'N m')}</td>" in report.split(">ID2.disc_clutch.torque [")[1]
    assert "Load spectrum of the history above (nonlinear creep, anti-slip off)" in report
    # back to linear creep: the linear history again
    dash.nonlinear.creep.value = "linear"
    assert dash.history is dash.response
    assert "linear creep" in dash.peaks.object
    assert dash.downloads.widgets[0].filename == "time_histories.csv"
    dash.show_published_case(0.005)


# --- the report ------------------------------------------------------------------------------------

@pytest.mark.slow
def test_the_report_has_a_design_loads_section():
    from app.report.page import build_report

    text = build_report(CASE)
    worst = compute.worst_case_result(CASE)
    spectra = compute.spectra_result(CASE, None)
    section = text[text.index("<h2>Design loads</h2>"):]
    assert "Worst case over every fault instant (linear creep, closed form)" in section
    for name in compute.DRIVE_PARTS:
        assert format_load(worst.max[name]) in section
        assert format_load(worst.min[name]) in section
        assert f"{spectra.spectra[name].equivalent_range[5.0]:,.4g}" in section
    assert "Load spectrum of the history above (linear creep)" in section
    assert "The operating point is unstable" not in section
    assert "Load collective: claw clutch torque" in section  # the figures are embedded
