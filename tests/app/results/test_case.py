"""The case record (app.results.case): each quantity declared once, everything else derived from
the declarations.  The test of the design: a made-up quantity, declared in a fixture and nowhere
else, follows into the record, its key, the command line's options, the dashboard's slider and
parameter, the link's query, the files and the report's table — and into the computation, as a
value of the parameter set it overrides."""

from __future__ import annotations

import math

import pytest

from app.results import compute
from app.results.case import QUANTITIES, Case, Quantity, case_type

# a made-up operating-point quantity: the secondary yaw damping, applied to the parameter set
# (role "override": parameters.replace(yaw_damping=…), a model per value), shown in kN s/m
YAW = Quantity("c_yaw", "yaw damping c_yaw", "secondary yaw damper's damping c_yaw", "override",
               "yaw_damping", "kN s/m", from_set="yaw_damping", low=50.0, high=1000.0, step=10.0,
               format="0", digits=3, si=1e3, link="cyaw", outer_unit="N s/m", outer=1e3,
               option="--c-yaw", option_label="--c-yaw (yaw damping, N s/m)",
               option_interval="(0, 1e9]", files=("yaw_damping",))


@pytest.fixture
def made_up():
    """The record of the declared quantities and the made-up one."""
    return case_type((*QUANTITIES, YAW), name="CaseWithYaw")


def test_the_record_rounds_and_keys_by_name():
    case = Case(s0=0.0050000000001, v=120.0, N0=100.0, b_M=1138.4709360188367)
    assert case.s0 == 0.005  # no float noise in a key
    assert case.b_M == 1138.471
    assert case == Case(s0=0.005, v=120.0, N0=100.0, b_M=1138.471)
    point = case.point()
    assert (point.M0, point.f, point.D, point.dt, point.t_end) == (None,) * 5
    assert point == Case(s0=0.005, v=120.0, N0=100.0, b_M=1138.471, M0=80.0).point()
    assert case.limit_key().s0 is None
    sweep = case.sweep("v")
    assert sweep.case.v is None
    assert sweep.at(150.0).v == 150.0
    op = case.operating_point()
    assert (op.s0, op.v_kmh, op.N0, op.b_M) == pytest.approx((0.005, 120.0, 1e5, 1138.471))
    shock = case.short_circuit()
    assert (shock.M0, shock.f, shock.D, shock.dt) == (50e3, 90.0, 0.04, None)
    with pytest.raises(TypeError):
        Case(0.005, 120.0)  # keyword fields only: nothing is read by position


def test_a_made_up_quantity_follows_into_the_record_and_its_physics(made_up):
    parameters = compute.parameters("")
    defaults = made_up.defaults(parameters)
    assert defaults["c_yaw"] == pytest.approx(parameters["yaw_damping"] / 1e3)
    case = made_up(**{**defaults, "c_yaw": 500.0})
    assert case.c_yaw == 500.0
    assert case.point().c_yaw == 500.0  # a value of the set: the point depends on it
    overrides = {name: (value, tolerance) for name, value, tolerance in case.overrides()}
    assert overrides["yaw_damping"] == (5e5, 0.5)  # N s/m, within half a record digit
    assert case.files()["yaw_damping"] == 5e5
    assert ("yaw damping c_yaw [N s/m]", "500000") in case.rows()
    # the computation takes the set with the value replaced: its own model and results
    assert compute.parameters_for(case)["yaw_damping"] == 5e5
    base = made_up(**defaults)
    assert compute.model_for(case) is not compute.model_for(base)
    assert compute.model_for(base) is compute.model("")  # the set's own value: the set's model
    assert compute.point_result(case).max_real_part != compute.point_result(base).max_real_part


def test_a_made_up_quantity_is_an_option_of_every_command_with_an_operating_point(made_up,
                                                                                monkeypatch,
                                                                                capsys):
    from app.cli import options
    from app.cli.main import build_parser, main

    monkeypatch.setattr(options, "Case", made_up)
    parser = build_parser()
    args = parser.parse_args(["eigen", "--c-yaw", "5e5"])
    assert args.c_yaw == 5e5
    model, _, _ = options.load_model(args)
    assert model.parameters["yaw_damping"] == 5e5
    args = parser.parse_args(["eigen"])
    assert args.c_yaw is None  # the set's value
    report = parser.parse_args(["report", "--s0", "0.005", "--c-yaw", "4e5", "--out", "r.html"])
    case = options.case_from_args(report, "", compute.parameters(""))
    assert case.c_yaw == 400.0
    with pytest.raises(SystemExit) as stop:
        main(["eigen", "--c-yaw", "-1"])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "--c-yaw (yaw damping, N s/m) = -1 is not allowed: must be in (0, 1e9] N s/m" in err


@pytest.mark.slow
def test_a_made_up_quantity_is_a_slider_a_parameter_and_a_link_argument(made_up):
    from bokeh.document import Document

    from app.dashboard.controls import case_parameters
    from app.dashboard.dashboard import BogieDashboard

    class Dashboard(BogieDashboard):
        case_type = made_up
        locals().update(case_parameters((YAW,)))

    dashboard = Dashboard(query={"cyaw": "400000", "s0": "0.006"})
    Document().add_root(dashboard.layout.get_root(Document()))
    assert not dashboard.input_notice.visible
    assert dashboard.c_yaw == 400.0
    slider = dashboard.controls.sliders["c_yaw"]
    assert (slider.label, slider.start, slider.end, slider.step) == ("yaw damping c_yaw [kN s/m]",
                                                                     50.0, 1000.0, 10.0)
    assert "ctl-c_yaw" in slider.css_classes
    state = dashboard.state()
    assert (state.s0, state.c_yaw) == (0.006, 400.0)
    assert dashboard.point.case == state.point()  # computed with it
    assert compute.parameters_for(state)["yaw_damping"] == 4e5
    assert "cyaw=400000" in dashboard.share_query()
    dashboard.c_yaw = 600.0  # the parameter is computed like every quantity's
    assert dashboard.point.case.c_yaw == 600.0
    refused = Dashboard(query={"cyaw": "1"})  # outside the slider's range: a notice, the set's
    assert refused.input_notice.visible
    assert "cyaw = 1 N s/m is outside [50000, 1e+06] N s/m" in refused.input_notice.object
    assert refused.c_yaw == pytest.approx(compute.parameters("")["yaw_damping"] / 1e3)


def test_declarations_are_consistent():
    """Every number's default lies in its range, its option's interval holds the range (in the
    command line's unit), and names, links and options are unique."""
    from app.cli.options import interval_ends

    for q in QUANTITIES:
        if q.choice:
            assert q.default in q.choices
            continue
        if q.default is not None:
            assert q.low <= q.default <= q.high, q.name
        low, high, _, _ = interval_ends(q.option_interval)
        assert low <= q.to_outer(q.low), q.name
        assert q.to_outer(q.high) <= high, q.name
        assert math.isclose(q.outer_to_si(q.to_outer(1.0)), q.to_si(1.0)), q.name
    for attribute in ("name", "link", "option"):
        values = [getattr(q, attribute) for q in QUANTITIES]
        assert len(set(values)) == len(values), attribute
