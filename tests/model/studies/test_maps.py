"""Studies without a cluster: the s0-line against the dense reference point by point, s0* against
the stability limit's own search, the parameter hash, the store (resume, refusal), bad input."""

from __future__ import annotations

import json
import socket
import time

import numpy as np
import pytest

from app.cli.main import main
from model import KMH, build_model, load_parameters, stability_limit
from model.mechanics.parameters import parameter_hash
from model.studies.engine import serial_map_unordered
from model.studies.maps import LimitStudy, MapStudy, dense_line, run_serial, s0_line
from model.studies.store import StoreMismatch, finished_chunks, open_study, run_into_store

# largest real part: the error-controlled Ritz values are within rtol·max(|λ|, 1 1/s) = 1e-6 x
# |λ| ≤ 2π·60 Hz of the dense solution (measured: 3e-9 1/s); 1e-5 1/s leaves room for it
GROWTH_ATOL = 1e-5
# s0*: both searches stop within xtol = 1e-6 of the crossing, so they differ by at most 2e-6
LIMIT_ATOL = 2e-6


@pytest.fixture(scope="module")
def setup():
    parameters = load_parameters()
    return parameters, build_model(parameters)


@pytest.mark.parametrize(("v_kmh", "n0_factor", "b_M", "method"), [
    pytest.param(50.0, 1.0, None, "reduced", marks=pytest.mark.slow),
    (160.0, 1.0, None, "reduced"), (160.0, 1.0, None, "continuation"),
    pytest.param(240.0, 0.6, 0.0, "reduced", marks=pytest.mark.slow),
    pytest.param(50.0, 1.0, None, "continuation", marks=pytest.mark.slow),
    pytest.param(240.0, 0.6, 0.0, "continuation", marks=pytest.mark.slow)])
def test_line_equals_dense_reference(setup, v_kmh, n0_factor, b_M, method):
    """Every point of an s0-line (largest real part, flutter pairs, divergent reals, verdict) as a
    full eigen-analysis gives it, across the stability limit; s0* as on the dense grid; both
    methods of s0_line (the continuation, the reduced model)."""
    parameters, model = setup
    N0 = parameters["wheel_force"] * n0_factor
    b_M = parameters["motor_slope"] if b_M is None else b_M
    s0 = np.linspace(0.001, 0.02, 17)
    line = s0_line(model, s0, v_kmh * KMH, N0, b_M, method=method)
    reference = dense_line(model, s0, v_kmh * KMH, N0, b_M)
    assert line.method == method
    assert np.count_nonzero(line.dense_points) < len(s0)  # the reduced model did the work
    np.testing.assert_allclose(line.largest_real_part, reference.largest_real_part, rtol=0,
                               atol=GROWTH_ATOL)
    np.testing.assert_array_equal(line.flutter_pairs, reference.flutter_pairs)
    np.testing.assert_array_equal(line.divergent_real, reference.divergent_real)
    np.testing.assert_array_equal(line.stable, reference.stable)
    assert line.stable[0]
    assert not line.stable[-1]
    assert abs(line.s0_limit - reference.s0_limit) <= LIMIT_ATOL
    if method == "reduced":
        assert line.basis_size > 0
        assert line.outside_max_real_part < -5.0  # outside the basis: damped at the ends
    else:
        # grid points solved densely: the first anchor and the fallbacks there (s0* may add more)
        assert line.fallbacks >= np.count_nonzero(line.dense_points) - 1


def test_reduced_basis_falls_back_to_both_ends_when_a_check_fails(setup, monkeypatch):
    """The reduced line's basis is the last creepage's eigenvectors and creep responses; when the
    dense eigenvalues at the first or the steepest creepage have no Ritz value next to them, it
    falls back to the exact eigenvectors at both ends.  With the check made impossible (MATCH = 0)
    the fallback runs: a larger basis, and every point still as the dense reference gives it."""
    import model.studies.maps as study

    parameters, model = setup
    N0, b_M = parameters["wheel_force"], parameters["motor_slope"]
    s0 = np.linspace(0.001, 0.02, 17)
    v = 160 * KMH
    reference = dense_line(model, s0, v, N0, b_M)
    normal = s0_line(model, s0, v, N0, b_M)
    monkeypatch.setattr(study, "MATCH", 0.0)
    fallback = s0_line(model, s0, v, N0, b_M)
    assert fallback.basis_size > normal.basis_size
    for line in (normal, fallback):
        np.testing.assert_allclose(line.largest_real_part, reference.largest_real_part, rtol=0,
                                   atol=GROWTH_ATOL)
        np.testing.assert_array_equal(line.flutter_pairs, reference.flutter_pairs)
        np.testing.assert_array_equal(line.divergent_real, reference.divergent_real)


def test_line_limit_equals_stability_limit(setup):
    """s0* of a line (Brent on the reduced evaluation) against model.analysis.stability.stability_limit
    (bracket doubling and Brent on dense eigen-analyses)."""
    parameters, model = setup
    v = 120 * KMH
    line = s0_line(model, np.linspace(0.002, 0.016, 8), v, parameters["wheel_force"],
                   parameters["motor_slope"])
    limit = stability_limit(model, v, parameters["wheel_force"], parameters["motor_slope"],
                            xtol=1e-7)
    assert abs(line.s0_limit - limit.s0_limit) <= LIMIT_ATOL


def test_parameter_hash(setup):
    """Equal values give equal hashes (notes and source do not count); any change changes it."""
    parameters, _ = setup
    same = type(parameters)(dict(parameters.values), {}, "elsewhere")
    assert parameter_hash(same) == parameter_hash(parameters)
    assert len(parameter_hash(parameters)) == 64
    changed = parameters.replace(yaw_damping=parameters["yaw_damping"] * (1 + 1e-12))
    assert parameter_hash(changed) != parameter_hash(parameters)


def _small_map(parameters, n_v=3):
    return MapStudy(np.linspace(0.002, 0.016, 6), np.linspace(60, 200, n_v) * KMH,
                    [parameters["wheel_force"]], [parameters["motor_slope"]])


def test_store_resume_computes_only_unfinished(setup, tmp_path):
    """A run stopped after one chunk leaves that chunk finished; the resume computes the other
    chunks only (counted), does not rewrite the finished one, and the store equals a run in one
    go; the dataset carries units, hash, code version and arguments."""
    parameters, _ = setup
    study = _small_map(parameters)
    path = tmp_path / "map.zarr"

    def first_only(function, items):
        for index, item in enumerate(items[:1]):
            yield index, function(item)
        raise KeyboardInterrupt  # as Ctrl-C after the first chunk

    with pytest.raises(KeyboardInterrupt):
        run_into_store(study, parameters, path, first_only)
    assert finished_chunks(path) == {(0, 0, 0)}
    marker = next(p for p in (path / "chunk_done").rglob("*") if p.is_file())
    stamp = marker.stat().st_mtime_ns
    calls = []

    def counting(function, items):
        calls.extend(items)
        yield from serial_map_unordered(function, items)

    run = run_into_store(study, parameters, path, counting, resume=True)
    assert (run.skipped, run.computed, run.total) == (1, 2, 3)
    assert sorted(calls) == [(1, 0, 0), (2, 0, 0)]
    assert marker.stat().st_mtime_ns == stamp
    dataset = open_study(path)
    reference = run_serial(study, parameters)
    for key, result in reference.items():
        i, j, k = key
        np.testing.assert_array_equal(dataset["largest_real_part"].values[:, i, j, k],
                                      result["largest_real_part"])
        assert dataset["s0_limit"].values[i, j, k] == result["s0_limit"]
    assert dataset["largest_real_part"].attrs["units"] == "1/s"
    assert dataset["v"].attrs["units"] == "m/s"
    assert dataset.attrs["parameters_hash"] == parameter_hash(parameters)
    assert json.loads(dataset.attrs["arguments"]) == study.arguments()
    assert dataset.attrs["code_version"]
    assert set(dataset.data_vars) >= {"largest_real_part", "stable", "flutter_pairs",
                                      "divergent_real", "s0_limit"}


def test_store_of_another_study_refused(setup, tmp_path):
    parameters, _ = setup
    study = _small_map(parameters, n_v=2)
    path = tmp_path / "map.zarr"
    run_into_store(study, parameters, path, serial_map_unordered)
    other = parameters.replace(yaw_damping=parameters["yaw_damping"] * 1.1)
    with pytest.raises(StoreMismatch, match="another parameter set"):
        run_into_store(study, other, path, serial_map_unordered, resume=True)
    with pytest.raises(StoreMismatch, match="other study arguments"):
        run_into_store(_small_map(parameters, n_v=3), parameters, path, serial_map_unordered,
                       resume=True)
    limit = LimitStudy(study.v, study.N0, study.b_M)
    with pytest.raises(StoreMismatch, match="map study, not a limit study"):
        run_into_store(limit, parameters, path, serial_map_unordered, resume=True)
    with pytest.raises(StoreMismatch, match="exists"):
        run_into_store(study, parameters, path, serial_map_unordered)


def _cli(capsys, *argv):
    code = main(list(argv))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


@pytest.mark.parametrize(("arguments", "message"), [
    (["--s0", "0.01:0.002:5", "--v", "60:120:2"], "empty range"),
    (["--s0", "0.002:0.01:0", "--v", "60:120:2"], "N = 0 is not allowed"),
    (["--s0", "0.002:0.01:3", "--v", "60:120:-1"], "N = -1 is not allowed"),
    (["--s0", "0.002:0.01:3", "--v", "60:900:2"], "must be in [1, 500] km/h"),
    (["--s0", "a:b:c", "--v", "60:120:2"], "must be A:B:N"),
    (["--s0", "0.002:0.01:3", "--v", "60:120:2", "--n0", ""], "--n0 is empty"),
])
def test_bad_input_one_line_exit_2(capsys, tmp_path, arguments, message):
    code, _out, err = _cli(capsys, "study", "map", *arguments, "--out", str(tmp_path / "x.zarr"),
                          "--serial")
    assert code == 2
    assert err.count("\n") == 1
    assert message in err
    assert "Traceback" not in err
    assert not (tmp_path / "x.zarr").exists()  # nothing changed


def test_wrong_store_refused_by_cli(capsys, tmp_path):
    """--resume on a missing store or on a store with other arguments; a new study on an
    existing path: one line, exit 2, the store untouched."""
    out = tmp_path / "m.zarr"
    base = ["study", "map", "--s0", "0.002:0.016:4", "--v", "100", "--out", str(out), "--serial"]
    code, _, err = _cli(capsys, *base, "--resume")
    assert code == 2
    assert "nothing to resume" in err
    assert err.count("\n") == 1
    assert _cli(capsys, *base)[0] == 0
    stamp = (out / "zarr.json").stat().st_mtime_ns
    code, _, err = _cli(capsys, *base)
    assert code == 2
    assert "exists" in err
    assert err.count("\n") == 1
    code, _, err = _cli(capsys, *base[:-3], "--out", str(out), "--serial", "--resume",
                        "--rail", "wet")
    assert code == 2
    assert "another parameter set" in err
    assert err.count("\n") == 1
    code, _, err = _cli(capsys, "study", "map", "--s0", "0.002:0.016:5", "--v", "100",
                        "--out", str(out), "--serial", "--resume")
    assert code == 2
    assert "other study arguments" in err
    assert err.count("\n") == 1
    assert (out / "zarr.json").stat().st_mtime_ns == stamp


def test_unreachable_scheduler_fails_within_timeout(capsys, tmp_path):
    """A port on 127.0.0.1 where nothing listens: one line, exit 2, within the time-out."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    start = time.monotonic()
    code, _, err = _cli(capsys, "study", "limit", "--v", "100", "--out", str(tmp_path / "l.zarr"),
                        "--scheduler", f"tcp://127.0.0.1:{port}", "--connect-timeout", "2")
    elapsed = time.monotonic() - start
    assert code == 2
    assert err.count("\n") == 1
    assert f"cannot reach the Dask scheduler at tcp://127.0.0.1:{port}" in err
    assert elapsed < 15  # 2 s time-out plus start-up; never a hang
    assert not (tmp_path / "l.zarr").exists()


@pytest.mark.parametrize(("args", "message"), [
    (["--samples", "3"], "must be a power of 2"),
    (["--samples", "0"], "--samples"),
    (["--samples", "4", "--workers", "0"], "--workers"),
])
def test_uncertainty_study_bad_input(capsys, tmp_path, args, message):
    """``bogie study uncertainty``: one line, exit 2, nothing written, no cluster started."""
    out = tmp_path / "u.json"
    try:  # option values are refused by argparse (SystemExit), the rest by the command
        code, _, err = _cli(capsys, "study", "uncertainty", *args, "--out", str(out))
    except SystemExit as stop:
        code, err = stop.code, capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1
    assert message in err
    assert not out.exists()


def test_uncertainty_study_unreachable_scheduler(capsys, tmp_path):
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    code, _, err = _cli(capsys, "study", "uncertainty", "--samples", "2", "--out",
                        str(tmp_path / "u.json"), "--scheduler", f"tcp://127.0.0.1:{port}",
                        "--connect-timeout", "2")
    assert code == 2
    assert err.count("\n") == 1
    assert "cannot reach the Dask scheduler" in err
    assert not (tmp_path / "u.json").exists()


def test_in_order_yields_in_item_order_as_soon_as_possible():
    """The ordered view of an unordered map: results in item order, none held back longer than
    the earlier items it waits for."""
    from model.studies.engine import in_order

    seen = []

    def unordered(function, items):
        for i in (2, 0, 1, 4, 3):
            seen.append(i)
            yield i, function(items[i])

    out = []
    for value in in_order(unordered)(lambda x: 10 * x, [0, 1, 2, 3, 4]):
        out.append((value, len(seen)))
    # 0 is ready after two finished tasks, 1 and 2 after three, 3 and 4 after five
    assert out == [(0, 2), (10, 3), (20, 3), (30, 5), (40, 5)]


def test_basis_check_at_the_most_destabilizing_point(setup):
    """The reduced line's basis comes from the two ends; at the creepage of the most negative
    b11 the dense eigenvalues check it: with both ends every eigenvalue the selection takes there
    has a Ritz value next to it, with the first end alone (the ≈ 50 Hz rim modes are damped by
    more than 5 1/s there and not in the basis) some have none and the check fails."""
    from model.analysis.locus import pattern_coefficients
    from model.mechanics.operating_point import OperatingPoint
    from model.studies.maps import _dense_point, _LineModel, _missing_modes

    parameters, model = setup
    v, N0, b_M = 120 * KMH, parameters["wheel_force"], parameters["motor_slope"]
    s0 = np.linspace(0.001, 0.02, 100)
    points = [OperatingPoint(float(s), v, N0, b_M) for s in s0]
    b11 = [pattern_coefficients(model, op)[0] for op in points]
    middle = int(np.argmin(b11))
    assert 0 < middle < len(s0) - 1
    c = pattern_coefficients(model, points[middle])
    eigenvalues = _dense_point(model, points[middle]).eigenvalues
    radius = 2 * np.pi * 10.0
    ends = [_dense_point(model, points[i], vectors=True) for i in (0, len(s0) - 1)]
    both = _LineModel(model, v, N0, b_M, ends, 10.0, 1e-6)
    first = _LineModel(model, v, N0, b_M, ends[:1], 10.0, 1e-6)
    assert not _missing_modes(eigenvalues, both.ritz_values(c), radius)
    assert _missing_modes(eigenvalues, first.ritz_values(c), radius)


def test_line_limit_few_evaluations(setup, monkeypatch):
    """s0* of a reduced line takes at most 8 reduced evaluations (secant steps on the crossing
    branch, bracket closed within xtol; Brent's method from the grid bracket took 9-12) and
    agrees with the dense line's Brent search within both tolerances."""
    from model.studies import maps as study

    parameters, model = setup
    calls = []
    point = study._LineModel.point

    def counted(self, s0, c=None):
        calls.append(s0)
        return point(self, s0, c)

    s0 = np.linspace(0.001, 0.02, 40)
    v, N0, b_M = 250 * KMH, parameters["wheel_force"], parameters["motor_slope"]
    monkeypatch.setattr(study._LineModel, "point", counted)
    line = s0_line(model, s0, v, N0, b_M)
    monkeypatch.undo()
    grid_calls = len(s0) - np.count_nonzero(line.dense_points)
    assert len(calls) - grid_calls <= 8
    reference = dense_line(model, s0, v, N0, b_M)
    assert abs(line.s0_limit - reference.s0_limit) <= LIMIT_ATOL


def test_point_at_the_crossing_needs_no_full_analysis(setup):
    """At s0* the crossing eigenvalue is real and ≈ 0, next to the rigid-body zeros: its Newton
    refinement divides the rigid rows by λ and converges; the point is not sent to a full
    eigen-analysis, and its largest real part is the dense one within rtol = 1e-6 1/s."""
    from model.analysis.eigen import eigen_analysis
    from model.analysis.locus import pattern_coefficients
    from model.mechanics.operating_point import OperatingPoint
    from model.studies.maps import _dense_point, _LineModel

    parameters, model = setup
    v, N0, b_M = 250 * KMH, parameters["wheel_force"], parameters["motor_slope"]
    reference = dense_line(model, np.linspace(0.001, 0.02, 17), v, N0, b_M)
    s0_limit = reference.s0_limit
    ends = [_dense_point(model, OperatingPoint(s, v, N0, b_M), vectors=True)
            for s in (0.001, 0.02)]
    line_model = _LineModel(model, v, N0, b_M, ends, 10.0, 1e-6)
    for s in (s0_limit - 2e-7, s0_limit + 2e-7):
        op = OperatingPoint(s, v, N0, b_M)
        (growth, _, _), dense = line_model.point(s, pattern_coefficients(model, op))
        assert not dense
        dense_growth = eigen_analysis(model, op, vectors=False).max_real_part
        assert abs(growth) < 1e-2  # the crossing eigenvalue: ≈ 0
        assert abs(growth - dense_growth) <= 1e-6
