"""``bogie compare BASE.toml VARIANT.toml``: JSON layout, differences consistent with both sides,
each side equal to the model's own analyses, and one-line exit-2 errors.

The variant is made here from the bundled set (one value changed), so nothing depends on the
numbers of the current calibration.
"""

from __future__ import annotations

import json

import pytest
from conftest import assert_self_contained_html
from test_cli import run  # the in-process CLI runner (tests/ is on sys.path under pytest)

from model.mechanics.parameters import CALIBRATED_FILE, load_parameters, save_parameters

OP = ["--s0", "0.005", "--v", "120", "--t-end", "0.3"]


@pytest.fixture(scope="module")
def variant_file(tmp_path_factory):
    base = load_parameters(CALIBRATED_FILE)
    path = tmp_path_factory.mktemp("sets") / "variant.toml"
    save_parameters(base.replace(gear_ratio=base["gear_ratio"] * 1.1,
                                 silent_block_stiffness_x=base["silent_block_stiffness_x"] * 2),
                    path, "test variant")
    return path


@pytest.mark.slow
def test_json_has_both_sides_and_their_difference(variant_file, capsys):
    code, out, err = run(["compare", str(CALIBRATED_FILE), str(variant_file), *OP, "--json"],
                         capsys)
    assert code == 0, err
    data = json.loads(out)
    assert set(data) >= {"base", "variant", "delta", "operating_point", "parameter_differences"}
    assert set(data["parameter_differences"]) == {"gear_ratio", "silent_block_stiffness_x"}
    for side in ("base", "variant"):
        assert set(data[side]) >= {"s0_limit", "max_real_part", "pairs", "peak_loads"}
        assert len(data[side]["pairs"]) == 10
        assert len(data[side]["peak_loads"]) == 10
    base, variant, delta = data["base"], data["variant"], data["delta"]
    assert delta["max_real_part"] == pytest.approx(variant["max_real_part"]
                                                   - base["max_real_part"])
    assert delta["s0_limit"] == pytest.approx(variant["s0_limit"] - base["s0_limit"])
    for name, d in delta["peak_loads"].items():
        assert d == pytest.approx(variant["peak_loads"][name] - base["peak_loads"][name])
    assert delta["pairs"][0]["im_hz"] == pytest.approx(variant["pairs"][0]["im_hz"]
                                                       - base["pairs"][0]["im_hz"])
    # each side is the model's own analysis of that set
    from model import build_model, eigen_analysis
    from model.mechanics.operating_point import OperatingPoint

    p = load_parameters(variant_file)
    result = eigen_analysis(build_model(p), OperatingPoint.from_kmh(
        0.005, 120.0, p["wheel_force"], p["motor_slope"]), vectors=False)
    # (eigenvalues without vectors: another LAPACK path, equal to ~1e-7 relative here)
    assert variant["max_real_part"] == pytest.approx(result.max_real_part, rel=1e-5)
    # a stiffer silent block and another gear ratio change the loads
    assert any(abs(d) > 0 for d in delta["peak_loads"].values())


@pytest.mark.slow
def test_same_set_twice_has_no_difference(capsys):
    code, out, err = run(["compare", str(CALIBRATED_FILE), str(CALIBRATED_FILE), *OP, "--json"],
                         capsys)
    assert code == 0, err
    data = json.loads(out)
    assert data["parameter_differences"] == {}
    assert data["delta"]["max_real_part"] == 0.0
    assert all(d == 0.0 for d in data["delta"]["peak_loads"].values())


@pytest.mark.parametrize("args", [
    ["compare", "/no/such.toml", str(CALIBRATED_FILE), *OP],
    ["compare", str(CALIBRATED_FILE), str(CALIBRATED_FILE), "--s0", "nan"],
    ["compare", str(CALIBRATED_FILE), str(CALIBRATED_FILE), *OP, "--params", "x.toml"],
    ["compare", str(CALIBRATED_FILE)],
])
def test_bad_input_is_one_line_and_exit_2(args, capsys):
    code, _out, err = run(args, capsys)
    assert code == 2
    assert len(err.strip().splitlines()) == 1
    assert "Traceback" not in err


@pytest.mark.slow
def test_report_command_writes_a_self_contained_file(tmp_path, capsys):

    out = tmp_path / "report.html"
    code, stdout, err = run(["report", "--s0", "0.005", "--v", "120", "--t-end", "0.3",
                             "--variant", "yaw_damping:1e5", "--out", str(out)], capsys)
    assert code == 0, err
    text = out.read_text()
    assert_self_contained_html(text)
    assert "yaw_damping" in text
    assert str(out) in stdout


@pytest.mark.parametrize("args", [
    ["report", "--s0", "0.005", "--out", "/no/such/dir/r.html"],
    ["report", "--s0", "0.005", "--out", "r.txt"],
    ["report", "--s0", "0.005", "--variant", "gear_ratio:nan", "--out", "r.html"],
    ["report", "--s0", "0.005", "--variant", "gear_ratio:1e300", "--out", "r.html"],
    ["report", "--s0", "0.005", "--f", "1e9", "--out", "r.html"],
])
def test_report_bad_input_is_one_line_and_exit_2(args, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, _out, err = run(args, capsys)
    assert code == 2, err
    assert len(err.strip().splitlines()) == 1
    assert not list(tmp_path.iterdir())  # nothing written
