"""The command line ``bogie`` / ``python -m app``: documented JSON contracts, and bad input
answered by ONE line on stderr with exit status 2 and no traceback.

Most cases run in-process through :func:`app.cli.main.main` (fast); a few go through a real
subprocess (``sys.executable -m model``) so that the process-level contract is checked too.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from app.cli.main import main
from model import build_model, eigen_analysis, load_parameters, motor_torque
from model.analysis.eigen import EigenResult
from model.mechanics.operating_point import OperatingPoint, damping_matrix
from model.mechanics.outputs import output_matrices
from model.mechanics.parameters import ESTIMATE_FILE, dumps_parameters

EIGEN_KEYS = {"operating_point", "stable", "complex", "real", "rigid_body"}
EXPORT_ARRAYS = {"M", "B", "K", "dofs", "f_mc", "motor_torque", "C_q", "C_v", "outputs",
                 "G_irr_q", "G_irr_v", "G_irr_a", "irregularity_inputs", "M_irr_coupling",
                 "B_irr_coupling", "K_irr_coupling"}


def run(argv: list[str], capsys) -> tuple[int, str, str]:
    """Run the CLI in-process: (exit status, stdout, stderr).  argparse errors exit via
    SystemExit, which the console script turns into the exit status too."""
    try:
        code = main(argv)
    except SystemExit as exit_:
        code = exit_.code
    out, err = capsys.readouterr()
    return code, out, err


def run_process(argv: list[str], timeout: float = 300) -> subprocess.CompletedProcess:
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}  # see app.services.thread_pools.limit_blas_threads
    return subprocess.run([sys.executable, "-m", "app", *argv], capture_output=True, text=True,
                          timeout=timeout, check=False, env=env)


def assert_one_line_error(code, out, err):
    assert code == 2, (code, err)
    assert "Traceback" not in err
    assert err.endswith("\n")
    assert err.count("\n") == 1, f"expected one line on stderr, got:\n{err}"
    assert err.startswith("bogie")
    assert "error" in err
    assert out == ""


@pytest.fixture(scope="module")
def model():
    return build_model(load_parameters())


# ------------------------------------------------------------------------------------------------
# bad parameter files


@pytest.fixture(scope="module")
def bad_files(tmp_path_factory):
    """Parameter files broken in one way each (built from the estimate set)."""
    directory = tmp_path_factory.mktemp("params")
    good = dumps_parameters(load_parameters(ESTIMATE_FILE))
    lines = good.splitlines(keepends=True)
    files = {
        "malformed": "wheel_radius = { value = 0.6, unit = \"m\"\n",
        "unknown key": good + 'flux_capacitor = { value = 1.0, unit = "1", note = "" }\n',
        "missing key": "".join(line for line in lines if not line.startswith("track_damping")),
        "wrong unit": good.replace('wheel_radius = { value = 0.625, unit = "m"',
                                   'wheel_radius = { value = 0.625, unit = "mm"'),
        "text value": good.replace("gear_ratio = { value = 3.9,", 'gear_ratio = { value = "x",'),
        "nan value": good.replace("gear_ratio = { value = 3.9,", "gear_ratio = { value = nan,"),
        "out of range": good.replace("rotor_mass = { value = 550.0,",
                                     "rotor_mass = { value = -550.0,"),
    }
    paths = {}
    for name, text in files.items():
        if name != "malformed":
            assert text != good, f"the '{name}' edit did not apply"
        path = directory / (name.replace(" ", "_") + ".toml")
        path.write_text(text, encoding="utf-8")
        paths[name] = str(path)
    paths["missing file"] = str(directory / "does_not_exist.toml")
    return paths


# ------------------------------------------------------------------------------------------------
# bad input

BAD_ARGUMENTS = [
    pytest.param(["--v", "0"], "--v", id="speed 0"),
    pytest.param(["--v", "-120"], "--v", id="negative speed"),
    pytest.param(["--s0", "0"], "--s0", id="creepage 0"),
    pytest.param(["--s0", "1"], "--s0", id="creepage 1"),
    pytest.param(["--s0", "-0.1"], "--s0", id="creepage -0.1"),
    pytest.param(["--s0", "1.5"], "--s0", id="creepage 1.5"),
    pytest.param(["--n0", "0"], "--n0", id="wheel force 0"),
    pytest.param(["--n0", "-1e5"], "--n0", id="negative wheel force"),
    pytest.param(["--v", "nan"], "--v", id="speed nan"),
    pytest.param(["--s0", "nan"], "--s0", id="creepage nan"),
    pytest.param(["--v", "inf"], "--v", id="speed inf"),
    pytest.param(["--n0", "inf"], "--n0", id="wheel force inf"),
    pytest.param(["--v", "fast"], "--v", id="speed text"),
    pytest.param(["--s0", "0,005"], "--s0", id="creepage decimal comma"),
    pytest.param(["--bm", "-1"], "--bm", id="negative motor slope"),
    pytest.param(["--count", "two"], "--count", id="count text"),
    pytest.param(["--no-such-option"], "unrecognized", id="unknown option"),
]

BAD_FILES = [
    pytest.param("missing file", "does not exist", id="missing file"),
    pytest.param("malformed", "not valid TOML", id="malformed TOML"),
    pytest.param("unknown key", "unknown parameter 'flux_capacitor'", id="unknown key"),
    pytest.param("missing key", "missing parameter(s) track_damping", id="missing key"),
    pytest.param("wrong unit", "has unit 'mm', expected 'm'", id="wrong unit"),
    pytest.param("text value", "must be a number", id="text value"),
    pytest.param("nan value", "must be finite", id="nan value"),
    pytest.param("out of range", "'rotor_mass' = -550.0 kg is outside", id="out of range"),
]


@pytest.mark.parametrize(("arguments", "mention"), BAD_ARGUMENTS)
def test_bad_arguments_one_line_exit_2(capsys, arguments, mention):
    code, out, err = run(["eigen", "--count", "1", *arguments], capsys)
    assert_one_line_error(code, out, err)
    assert mention in err


@pytest.mark.parametrize("command", ["eigen", "limit", "export"])
def test_bad_speed_rejected_by_every_command(capsys, tmp_path, command):
    extra = ["--out", str(tmp_path / "x.npz")] if command == "export" else []
    code, out, err = run([command, "--v", "-1", *extra], capsys)
    assert_one_line_error(code, out, err)
    assert not (tmp_path / "x.npz").exists()


@pytest.mark.parametrize(("which", "mention"), BAD_FILES)
def test_bad_parameter_files_one_line_exit_2(capsys, bad_files, which, mention):
    code, out, err = run(["eigen", "--count", "1", "--params", bad_files[which]], capsys)
    assert_one_line_error(code, out, err)
    assert mention in err


@pytest.mark.parametrize("arguments", [
    pytest.param([], id="no command"),
    pytest.param(["eigenvalues"], id="unknown command"),
    pytest.param(["export"], id="export without --out"),
])
def test_usage_errors(capsys, arguments):
    assert_one_line_error(*run(arguments, capsys))


@pytest.mark.parametrize("arguments", [
    pytest.param(["export", "--out", "result.txt"], id="wrong suffix"),
    pytest.param(["export", "--out", "/no/such/directory/x.npz"], id="missing directory"),
])
def test_bad_export_target(capsys, tmp_path, monkeypatch, arguments):
    monkeypatch.chdir(tmp_path)
    assert_one_line_error(*run(arguments, capsys))
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(("arguments", "mention"), [
    pytest.param([], "--out FILE is required", id="no output"),
    pytest.param(["--max-evaluations", "3"], "--out FILE is required", id="no output, a budget"),
    pytest.param(["--out", "set.toml", "--max-evaluations", "0"], "--max-evaluations",
                 id="no evaluations"),
    pytest.param(["--out", "set.toml", "--max-evaluations", "x"], "--max-evaluations",
                 id="not a number"),
    pytest.param(["--out", "/no/such/directory/set.toml"], "does not exist", id="missing dir"),
    pytest.param(["--out", "set.toml", "--from", "/no/such/start.toml"], "does not exist",
                 id="missing start"),
])
def test_bad_calibrate_arguments_change_nothing(capsys, tmp_path, monkeypatch, arguments,
                                                mention):
    """Rejected before any search: one line, exit 2, no file written — the bundled default
    set above all (``bogie calibrate`` writes only to ``--out``)."""
    from model.mechanics.parameters import CALIBRATED_FILE

    bundled = CALIBRATED_FILE.read_bytes()
    monkeypatch.chdir(tmp_path)
    code, out, err = run(["calibrate", *arguments], capsys)
    assert_one_line_error(code, out, err)
    assert mention in err
    assert list(tmp_path.iterdir()) == []
    assert CALIBRATED_FILE.read_bytes() == bundled


# a process start costs ~1–2 s (numpy, scipy): one case in the fast set, the others slow
@pytest.mark.parametrize("arguments", [
    pytest.param(["eigen", "--s0", "1.5"], id="creepage"),
    pytest.param(["eigen", "--v", "nan"], id="speed nan", marks=pytest.mark.slow),
    pytest.param(["eigen", "--params", "/no/such/file.toml"], id="missing file",
                 marks=pytest.mark.slow),
    pytest.param([], id="no command", marks=pytest.mark.slow),
])
def test_bad_input_in_a_real_process(arguments):
    done = run_process([*arguments, "--count", "1"] if arguments else [])
    assert_one_line_error(done.returncode, done.stdout, done.stderr)


@pytest.mark.slow
@pytest.mark.parametrize(("which", "mention"), BAD_FILES)
def test_bad_parameter_files_in_a_real_process(bad_files, which, mention):
    done = run_process(["eigen", "--count", "1", "--params", bad_files[which]])
    assert_one_line_error(done.returncode, done.stdout, done.stderr)
    assert mention in done.stderr


# ------------------------------------------------------------------------------------------------
# good input: documented output


def test_eigen_json_contract(capsys, model):
    code, out, err = run(["eigen", "--count", "6", "--json", "--s0", "0.005", "--v", "120"],
                         capsys)
    assert code == 0, err
    data = json.loads(out)
    assert set(data) >= EIGEN_KEYS
    # drivetrain spins, vehicle translation and yaw, and the rolling velocity nothing damps
    assert data["rigid_body"] == 5
    assert isinstance(data["stable"], bool)
    assert len(data["complex"]) == 6
    assert len(data["real"]) == 6
    im = [row["im_hz"] for row in data["complex"]]
    assert all(value > 0 for value in im)
    assert im == sorted(im)
    re = [row["re"] for row in data["real"]]
    assert re == sorted(re, reverse=True)
    assert all(isinstance(row["description"], str) for row in data["complex"])
    assert all(row["description"] for row in data["complex"])
    op = data["operating_point"]
    assert op["s0"] == 0.005
    assert op["v_kmh"] == pytest.approx(120.0)
    # the same numbers as the library at the same point
    p = model.parameters
    result: EigenResult = eigen_analysis(
        model, OperatingPoint.from_kmh(0.005, 120.0, p["wheel_force"], p["motor_slope"]))
    assert data["stable"] == result.stable
    assert np.allclose([row["re"] for row in data["complex"]], result.complex_pairs[:6].real,
                       rtol=1e-9, atol=1e-9 * np.abs(result.eigenvalues).max())
    assert np.allclose(im, result.complex_pairs[:6].imag / (2 * np.pi), rtol=1e-9)
    assert np.allclose(re, result.real_eigenvalues[:6], rtol=1e-9, atol=1e-9 * np.abs(result.eigenvalues).max())


def test_eigen_human_readable(capsys):
    code, out, err = run(["eigen", "--count", "3"], capsys)
    assert code == 0, err
    assert "verdict:" in out
    assert "Im [Hz]" in out
    assert err == ""


def test_eigen_in_a_real_process():
    done = run_process(["eigen", "--count", "2", "--json", "--s0", "0.014"])
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""
    data = json.loads(done.stdout)
    assert set(data) >= EIGEN_KEYS
    assert data["operating_point"]["s0"] == 0.014


@pytest.mark.slow
def test_limit_json_contract(capsys, model):
    """The limit is where the largest real part crosses zero: just below stable, just above not."""
    code, out, err = run(["limit", "--v", "120", "--json"], capsys)
    assert code == 0, err
    data = json.loads(out)
    assert set(data) >= {"v_kmh", "s0_limit"}
    assert data["v_kmh"] == 120.0
    s0 = data["s0_limit"]
    assert 0 < s0 < 1
    p = model.parameters
    for factor, stable in ((0.999, True), (1.001, False)):
        op = OperatingPoint.from_kmh(s0 * factor, 120.0, p["wheel_force"], p["motor_slope"])
        assert eigen_analysis(model, op, vectors=False).stable is stable, factor


def test_export_contract(capsys, tmp_path, model):
    path = tmp_path / "x.npz"
    code, _, err = run(["export", "--out", str(path), "--s0", "0.014", "--v", "100"], capsys)
    assert code == 0, err
    with np.load(path, allow_pickle=False) as data:
        arrays = {name: data[name] for name in data.files}
    assert set(arrays) >= EXPORT_ARRAYS
    n = model.n
    for name in ("M", "B", "K"):
        assert arrays[name].shape == (n, n), name
        assert arrays[name].dtype == np.float64
    assert tuple(arrays["dofs"]) == model.dofs.names
    assert arrays["f_mc"].shape == (n,)
    n_out = len(arrays["outputs"])
    assert n_out > 0
    assert arrays["C_q"].shape == arrays["C_v"].shape == (n_out, n)
    assert arrays["motor_torque"].shape == ()
    # the arrays are the model's, at the requested operating point
    p = model.parameters
    op = OperatingPoint.from_kmh(0.014, 100.0, p["wheel_force"], p["motor_slope"])
    assert np.array_equal(arrays["M"], model.M)
    assert np.array_equal(arrays["K"], model.K)
    assert np.allclose(arrays["B"], damping_matrix(model, op), rtol=1e-14, atol=0)
    assert np.array_equal(arrays["f_mc"], model.short_circuit_force)
    assert float(arrays["motor_torque"]) == pytest.approx(motor_torque(p, op), rel=1e-14)
    outputs = output_matrices(model, op)
    assert tuple(arrays["outputs"]) == outputs.names
    assert np.allclose(arrays["C_q"], outputs.C_q, rtol=1e-14, atol=0)
    assert np.allclose(arrays["C_v"], outputs.C_v, rtol=1e-14, atol=0)
    # the irregularities' inputs at that point (model.mechanics.irregularity)
    from model.mechanics.irregularity import irregularity_forces

    forces = irregularity_forces(model, op)
    assert tuple(arrays["irregularity_inputs"]) == forces.names
    for name, value in (("G_irr_q", forces.G_q), ("G_irr_v", forces.G_v), ("G_irr_a", forces.G_a),
                        ("M_irr_coupling", forces.M_c), ("B_irr_coupling", forces.B_c),
                        ("K_irr_coupling", forces.K_c)):
        assert np.array_equal(arrays[name], value), name


def test_export_with_torque_control(capsys, tmp_path):
    """With a torque control on ID2's converter (``--motor-bandwidth`` > 0) the model has the
    filter's massless coordinate: the export names it, gives its unit (rad, as the naming
    scheme declares it) and counts it among the massless coordinates; the bandwidth is in the
    file."""
    from model.mechanics.assembly import CONVERTER_FILTER

    path = tmp_path / "controlled.npz"
    code, _, err = run(["export", "--s0", "0.005", "--v", "120", "--motor-bandwidth", "5",
                        "--out", str(path)], capsys)
    assert code == 0, err
    controlled = build_model(load_parameters().replace(motor_bandwidth=5.0))
    with np.load(path, allow_pickle=False) as data:
        dofs, units = tuple(data["dofs"]), tuple(data["dof_units"])
        massless, bandwidth = data["massless"], float(data["motor_bandwidth"])
        shape = data["M"].shape
    assert dofs == controlled.dofs.names
    assert dofs[-1] == CONVERTER_FILTER == "ID2.converter.filtered_angle"
    assert units[-1] == "rad"
    assert len(units) == len(dofs) == shape[0] == 198
    assert len(dofs) - 1 in massless
    assert bandwidth == 5.0
