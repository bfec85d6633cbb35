"""``bogie parameters``: the set as a table with the calibration's bounds."""

from __future__ import annotations

import json

import pytest

from app.cli.main import main
from model.mechanics.parameters import ALL_SCHEMA, ESTIMATE_FILE, load_parameters
from model.studies.calibration_bounds import FREE_PARAMETERS


def run(argv: list[str], capsys) -> tuple[int, str, str]:
    try:
        code = main(argv)
    except SystemExit as exit_:
        code = exit_.code
    out, err = capsys.readouterr()
    return code, out, err


def test_json_rows_are_the_set_with_the_calibration_bounds(capsys):
    code, out, err = run(["parameters", "--json"], capsys)
    assert code == 0, err
    rows = json.loads(out)["parameters"]
    assert [row["name"] for row in rows] == list(ALL_SCHEMA)  # the strength data last
    parameters = load_parameters()
    free = {f.name: f for f in FREE_PARAMETERS}
    for row in rows:
        assert set(row) == {"name", "value", "unit", "note", "lower", "upper", "on_bound",
                            "bounds_source"}
        assert row["value"] == parameters[row["name"]]
        assert row["unit"] == ALL_SCHEMA[row["name"]][0]
        assert row["note"] == parameters.notes[row["name"]]
        f = free.get(row["name"])
        if f is None:
            assert (row["lower"], row["upper"], row["on_bound"], row["bounds_source"]) == (
                None, None, None, None)
        else:
            assert (row["lower"], row["upper"]) == (f.low, f.high)
            assert row["bounds_source"].strip()
            assert f.reason in row["bounds_source"]
            assert row["on_bound"] is f.on_bound(row["value"])
    assert sum(row["lower"] is not None for row in rows) == len(FREE_PARAMETERS)


def test_every_calibrated_parameter_names_the_data_of_its_bounds():
    """Each bound comes from published data on real vehicles of this class, or says that it is
    an engineering estimate for want of such data; the vertical dampers' ranges are those of
    real hydraulic dampers (tens of kN s/m), not the near-zero damping of Table 1's real parts."""
    for f in FREE_PARAMETERS:
        assert f.source.strip(), f.name
        assert f.source in f.bounds_source
        assert f.reason in f.bounds_source
    free = {f.name: f for f in FREE_PARAMETERS}
    assert free["primary_damping_z"].low >= 1e4
    assert (free["secondary_damping_z"].low, free["secondary_damping_z"].high) == (1e4, 1.2e5)


def test_table_of_another_file(capsys):
    code, out, err = run(["parameters", "--params", str(ESTIMATE_FILE)], capsys)
    assert code == 0, err
    lines = out.splitlines()
    assert str(ESTIMATE_FILE) in lines[0]
    assert "on bound" in lines[2]
    row = next(line for line in lines if line.startswith("primary_stiffness_x "))
    for text in ("N/m", "1.7e+06", "1.5e+07", "| bounds: "):
        assert text in row
    # the vertical dampers' bounds name the published vehicle sets they come from
    damper = next(line for line in lines if line.startswith("primary_damping_z "))
    for text in ("1e+04", "1e+05", "Manchester", "Zhai"):
        assert text in damper
    assert len(lines) == 3 + len(ALL_SCHEMA)


@pytest.mark.parametrize(("arguments", "mention"), [
    pytest.param(["--params", "/no/such/set.toml"], "does not exist", id="missing file"),
    pytest.param(["--params", "{bad}"], "does not exist", id="odd name"),
    pytest.param(["--colour"], "unrecognized", id="unknown option"),
])
def test_bad_input_one_line_exit_2(capsys, arguments, mention):
    code, out, err = run(["parameters", *arguments], capsys)
    assert code == 2
    assert out == ""
    assert err.count("\n") == 1
    assert "Traceback" not in err
    assert mention in err


def test_a_file_that_is_not_a_parameter_set(capsys, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('wheel_radius = { value = "big", unit = "m" }\n', encoding="utf-8")
    code, out, err = run(["parameters", "--params", str(bad)], capsys)
    assert code == 2
    assert out == ""
    assert err.count("\n") == 1
    assert "wheel_radius" in err
