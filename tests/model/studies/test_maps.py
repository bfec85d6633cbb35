"""Studies without a cluster: the parameter hash, the store (resume, refusal), the command line's
refusals of bad input and of an unreachable scheduler, the ordered view of an unordered map."""

from __future__ import annotations

import json
import socket
import time

import numpy as np
import pytest

from app.cli.main import main
from model import KMH, build_model, load_parameters
from model.mechanics.parameters import parameter_hash
from model.studies.engine import serial_map_unordered
from model.studies.maps import LimitStudy, MapStudy, run_serial
from model.studies.store import StoreMismatch, finished_chunks, open_study, run_into_store


@pytest.fixture(scope="module")
def setup():
    parameters = load_parameters()
    return parameters, build_model(parameters)


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
