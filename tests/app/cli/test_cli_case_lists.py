"""Every quantity of the case record in every command that computes a case: the value lists of
``bogie envelope`` and ``bogie study`` and the short_circuit grid of ``bogie assess`` come from
the record's declarations (:data:`app.results.case.QUANTITIES`), and the converter's torque
control ``--motor-bandwidth`` reaches the models they build."""

from __future__ import annotations

import json

import numpy as np
import pytest
from test_cli import run
from test_cli_bad_values import leaf_commands

from app.cli.main import build_parser
from app.results.case import Case
from model.mechanics.assembly import CONVERTER_FILTER
from model.mechanics.operating_point import KMH
from model.mechanics.parameters import load_parameters

POINT_ROLES = ("point", "override")


def _options(parser) -> dict[str, object]:
    return {s: a for a in parser._actions for s in a.option_strings}


def test_every_command_of_an_operating_point_has_every_quantity_of_it():
    """A command with an option of the operating point (``--bm``) has one for every quantity of
    the point and of the set's values it replaces (``--motor-bandwidth`` included)."""
    wanted = {q.option for q in Case.of_role(*POINT_ROLES)} - {"--s0", "--v"}
    with_point = [(" ".join(words), _options(parser)) for words, parser in leaf_commands()
                  if "--bm" in _options(parser)]
    assert {"eigen", "export", "envelope", "assess", "study map", "study limit"} <= {
        name for name, _ in with_point}
    for name, options in with_point:
        assert wanted <= set(options), (name, wanted - set(options))


@pytest.mark.parametrize(("words", "roles", "without"), [
    (["envelope"], ("set", "point", "override", "short_circuit"), ()),
    (["study", "map"], POINT_ROLES, ()),
    (["study", "limit"], POINT_ROLES, ("s0",)),
])
def test_value_lists_are_the_case_quantities(words, roles, without):
    """The value-list options are the record's quantities: each its declared option, doc, unit
    and default (the declared one in the command line's unit, else the set's)."""
    parser = dict((tuple(w), p) for w, p in leaf_commands())[tuple(words)]
    options = _options(parser)
    for q in Case.of_role(*roles):
        if q.automatic or q.name in without:  # the fault instant: --phase LIST|all
            continue
        action = options[q.option]
        assert action.metavar == "LIST"
        assert q.doc in action.help
        if q.choice:
            assert action.default == q.default
            continue
        assert f"[{q.outer_unit}]" in action.help
        if action.required:
            assert q.name in ("s0", "v")
        elif q.from_set:
            assert action.default is None
        else:
            assert float(action.default) == pytest.approx(q.to_outer(q.default))
    for name in without:
        assert Case.quantity(name).option not in options


def test_assess_grid_and_torque_control(capsys):
    """assess: the short_circuit grid's lists come from the record (its own default lists), and
    ``--motor-bandwidth`` (one value, every case) reaches the set the assessment runs with."""
    from app.cli.assess import options_from_args

    args = build_parser().parse_args(["assess", "--motor-bandwidth", "5", "--v", "100,150"])
    parameters, options = options_from_args(args)
    assert parameters["motor_bandwidth"] == 5.0
    assert options.s0 == (0.002, 0.005)
    assert options.v == pytest.approx((100 * KMH, 150 * KMH), rel=1e-15)
    code, _, err = run(["assess", "--motor-bandwidth", "-1"], capsys)
    assert code == 2
    assert "--motor-bandwidth" in err


@pytest.mark.parametrize("study_kind", ["map", "limit"])
def test_study_runs_each_chunk_with_its_bandwidth(study_kind, monkeypatch):
    """A map or limit study with a list of f_c builds each chunk's model with its value (the
    converter's filter coordinate only where f_c > 0); without the list the study, its
    arguments and its store's dimensions are those of a study without the option."""
    from model.studies import maps
    from model.studies.store import store_layout

    parameters = load_parameters()
    seen = []

    def capture(model, *args, **kwargs):
        seen.append((model.parameters["motor_bandwidth"], CONVERTER_FILTER in model.dofs.names))
        raise maps.NoStabilityLimit("captured")

    monkeypatch.setattr(maps, "stability_limit", capture)
    monkeypatch.setattr(maps, "s0_line", capture)
    grid = dict(v=(120 * KMH,), N0=(parameters["wheel_force"],), b_M=(parameters["motor_slope"],))
    make = (lambda **k: maps.MapStudy((0.004, 0.012), **grid, **k)) if study_kind == "map" \
        else (lambda **k: maps.LimitStudy(**grid, **k))
    plain, listed = make(), make(motor_bandwidth=(0.0, 5.0))
    assert "motor_bandwidth" not in plain.arguments()
    assert store_layout(plain).marker_dims == ("v", "N0", "b_M")
    assert listed.arguments()["motor_bandwidth"] == [0.0, 5.0]
    layout = store_layout(listed)
    assert layout.marker_dims == ("v", "N0", "b_M", "motor_bandwidth")
    assert list(layout.coords["motor_bandwidth"][1]) == [0.0, 5.0]
    assert layout.coords["motor_bandwidth"][2]["units"] == "Hz"
    for key in listed.chunks():
        if study_kind == "map":
            with pytest.raises(maps.NoStabilityLimit):
                listed.run_chunk(parameters, key)
        else:
            listed.run_chunk(parameters, key)
    assert seen == [(0.0, False), (5.0, True)]
    with pytest.raises(ValueError, match="motor_bandwidth"):
        make(motor_bandwidth=(-1.0,))


def test_envelope_with_a_list_of_bandwidths(capsys, tmp_path):
    """``bogie envelope --serial --motor-bandwidth 0,5`` runs: the envelope over both is the
    extreme of the envelopes of each (same scenarios, same code: to rounding), its worst case
    names its f_c, and the store keeps the f_c dimension in Hz."""
    import xarray as xr

    base = ["envelope", "--serial", "--t-end", "0.3", "--fs", "2000", "--outputs",
            "ID1.driving_shaft.torque,ID2.driving_shaft.torque", "--json"]
    store = tmp_path / "fc.zarr"
    code, out, err = run([*base, "--motor-bandwidth", "0,5", "--out", str(store)], capsys)
    assert code == 0, err
    both = json.loads(out)
    single = {}
    for fc in ("0", "5"):
        code, out, err = run([*base, "--motor-bandwidth", fc], capsys)
        assert code == 0, err
        single[float(fc)] = json.loads(out)
    assert both["scenarios"] == 2 * single[0.0]["scenarios"]
    for j, output in enumerate(both["outputs"]):
        maxima = {fc: data["outputs"][j]["max"] for fc, data in single.items()}
        assert output["max"] == pytest.approx(max(maxima.values()), rel=1e-12)
        assert output["max_at"]["motor_bandwidth"] in maxima
        assert maxima[output["max_at"]["motor_bandwidth"]] == pytest.approx(output["max"],
                                                                             rel=1e-12)
    with xr.open_zarr(str(store), consolidated=False) as dataset:
        assert list(dataset["motor_bandwidth"].values) == [0.0, 5.0]
        assert dataset["motor_bandwidth"].attrs["units"] == "Hz"
        assert "motor_bandwidth" in dataset["max"].dims
        assert np.isfinite(dataset["max"].values).all()
