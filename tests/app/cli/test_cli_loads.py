"""``bogie envelope`` and ``bogie spectrum``: JSON keys, stores and files, resume, the local
cluster, and one-line exit-2 errors."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
from test_cli import assert_one_line_error, run, run_process

SMALL = ["--t-end", "0.3", "--fs", "2000"]
ENVELOPE = ["envelope", "--serial", *SMALL, "--outputs",
            "ID1.disc_clutch.torque,ID2.disc_clutch.torque,ID1.driving_shaft.torque"]


def test_envelope_json_keys_and_fault_treatment(capsys):
    code, out, err = run([*ENVELOPE, "--s0", "0.005,0.014", "--json"], capsys)
    assert code == 0, err
    data = json.loads(out)
    assert data["scenarios"] == 4  # two creepages × two continuity roots
    assert data["fault_instants"]["treatment"] == "roots"
    assert "continuous motor torque" in data["fault_instants"]["description"]
    assert [o["name"] for o in data["outputs"]] == ["ID1.disc_clutch.torque",
                                                    "ID2.disc_clutch.torque",
                                                    "ID1.driving_shaft.torque"]
    first = data["outputs"][0]
    assert {"name", "unit", "max", "min", "max_at", "min_at"} <= set(first)
    assert {"s0", "v_kmh", "phase_s", "rail", "n0", "bm", "m0", "f", "decay",
            "time_s"} == set(first["max_at"])
    assert first["unit"] == "N m"
    assert first["max"] >= first["min"]
    # the text says which fault instants were used
    code, out, _ = run([*ENVELOPE, "--phase", "all"], capsys)
    assert code == 0
    assert "every fault instant" in out
    assert "conservative" in out


def test_envelope_all_is_at_least_the_roots(capsys):
    results = {}
    for phase in ([], ["--phase", "all"]):
        code, out, err = run([*ENVELOPE, "--s0", "0.005", "--json", *phase], capsys)
        assert code == 0, err
        results[bool(phase)] = json.loads(out)["outputs"]
    for every, roots in zip(results[True], results[False], strict=True):
        scale = max(abs(every["max"]), abs(every["min"]))
        assert every["max"] >= roots["max"] - 1e-9 * scale
        assert every["min"] <= roots["min"] + 1e-9 * scale


def test_envelope_store_and_resume(tmp_path, capsys):
    import xarray as xr

    store = tmp_path / "e.zarr"
    argv = [*ENVELOPE, "--v", "80,120", "--m0", "30e3,50e3", "--out", str(store), "--json"]
    code, out, err = run(argv, capsys)
    assert code == 0, err
    first = json.loads(out)
    assert first["computed_chunks"] == 2
    assert first["skipped_chunks"] == 0
    with xr.open_zarr(store, consolidated=False) as dataset:
        assert dataset["max"].dims[:3] == ("output", "rail", "s0")
        assert dataset.sizes["v"] == 2
        assert dataset.sizes["M0"] == 2
        assert dataset.sizes["fault"] == 2
        assert list(dataset["unit"].values) == ["N m", "N m", "N m"]
        assert dataset["v_kmh"].values.tolist() == [80.0, 120.0]
        assert dataset["time_of_max"].attrs["units"] == "s"
        assert dataset.attrs["study"] == "envelope"
        top = float(dataset["max"].sel(output="ID1.disc_clutch.torque").max())
    assert top == first["outputs"][0]["max"]
    code, out, err = run([*argv, "--resume"], capsys)
    assert code == 0, err
    again = json.loads(out)
    assert again["computed_chunks"] == 0
    assert again["skipped_chunks"] == 2
    assert again["outputs"] == first["outputs"]
    # the same store with other arguments is refused, and an existing store is not overwritten
    code, out, err = run([*ENVELOPE, "--v", "80,120", "--out", str(store), "--resume"], capsys)
    assert_one_line_error(code, out, err)
    assert "other study arguments" in err
    code, out, err = run(argv, capsys)
    assert_one_line_error(code, out, err)
    assert "exists" in err


def test_envelope_nonlinear_with_anti_slip(capsys):
    code, out, err = run([*ENVELOPE, "--s0", "0.014", "--creep", "nonlinear", "--anti-slip",
                          "off,on", "--anti-slip-delay", "0,0.1", "--phase", "0,0.002", "--json"],
                         capsys)
    assert code == 0, err
    data = json.loads(out)
    assert data["scenarios"] == 2 * 3
    assert data["fault_instants"]["treatment"] == "grid"
    at = data["outputs"][1]["max_at"]
    assert at["anti_slip"] in ("on", "off")
    assert at["phase_s"] in (0.0, 0.002)
    assert (at["anti_slip_delay_s"] is None) == (at["anti_slip"] == "off")


@pytest.mark.slow
def test_envelope_on_the_local_cluster_equals_serial(tmp_path):
    """The default engine (a local cluster of worker processes, as ``bogie study``)."""
    argv = [a for a in ENVELOPE if a != "--serial"] + ["--s0", "0.005,0.01,0.014", "--json"]
    cluster = run_process([*argv, "--out", str(tmp_path / "c.zarr"), "--workers", "2"])
    assert cluster.returncode == 0, cluster.stderr
    assert "local cluster of 2 worker process(es)" in cluster.stderr
    serial = run_process([*argv, "--serial"])
    assert serial.returncode == 0, serial.stderr
    assert json.loads(cluster.stdout)["outputs"] == json.loads(serial.stdout)["outputs"]


@pytest.mark.parametrize(("extra", "message"), [
    (["--s0", "0.01:0.005:3"], "empty range"),
    (["--s0", ","], "--s0 is empty"),
    (["--rail", "icy"], "icy"),
    (["--rail", "dry,"], "--rail"),
    (["--phase", "all", "--creep", "nonlinear"], "--phase all needs --creep linear"),
    (["--phase", "0.01,0.001"], "--phase must increase"),
    (["--anti-slip", "on"], "--anti-slip on needs --creep nonlinear"),
    (["--anti-slip-delay", "0.1", "--creep", "nonlinear"], "needs --anti-slip on"),
    (["--anti-slip", "maybe", "--creep", "nonlinear"], "--anti-slip must be"),
    (["--m0", "-5"], "--m0"),
    (["--v", "0.5"], "--v"),
    (["--f", "1000"], "--fs"),
    (["--fs", "500"], "highest excited frequency"),
    (["--outputs", "ID1.nothing"], "unknown output"),
    (["--outputs", "ID1.rotor.ry", "--creep", "nonlinear"], "not available with nonlinear"),
    (["--resume"], "--resume needs --out"),
    (["--method", "expm", "--creep", "tangent"], "--method applies to --creep linear only"),
])
def test_envelope_bad_input_one_line_exit_2(capsys, extra, message):
    code, out, err = run([*ENVELOPE, *extra], capsys)
    assert_one_line_error(code, out, err)
    assert message in err, err


# --- bogie spectrum -----------------------------------------------------------------------------------

SPECTRUM = ["spectrum", *SMALL, "--outputs", "ID1.disc_clutch.torque,ID1.driving_shaft.torque"]


def test_spectrum_json_keys(capsys):
    code, out, err = run([*SPECTRUM, "--json", "--slopes", "3,5,8"], capsys)
    assert code == 0, err
    data = json.loads(out)
    assert data["history"]["fault_instant"]["treatment"].startswith("continuity root")
    assert data["n_ref"] == 1e7
    first = data["outputs"][0]
    assert first["name"] == "ID1.disc_clutch.torque"
    assert first["unit"] == "N m"
    assert set(first["equivalent_range"]) == {"3", "5", "8"}
    cycles = np.array(first["cycles"])
    assert cycles.shape[1] == 3
    assert set(cycles[:, 2]) <= {0.5, 1.0}
    assert first["total_cycles"] == pytest.approx(cycles[:, 2].sum())
    assert first["exceedance"]["cycles"][-1] == pytest.approx(first["total_cycles"])
    # the table names the fault instant and the counting convention
    code, out, _ = run([*SPECTRUM, "--phase", "0.001"], capsys)
    assert code == 0
    assert "given by --phase" in out
    assert "residue as half cycles" in out


def test_spectrum_nonlinear(capsys):
    code, out, err = run([*SPECTRUM, "--s0", "0.014", "--creep", "nonlinear", "--anti-slip", "on",
                          "--json"], capsys)
    assert code == 0, err
    data = json.loads(out)
    assert data["history"]["creep"] == "nonlinear"
    assert data["outputs"][0]["total_cycles"] > 0


@pytest.mark.parametrize("suffix", [".npz", ".csv", ".json"])
def test_spectrum_files(tmp_path, capsys, suffix):
    path = tmp_path / f"s{suffix}"
    code, out, err = run([*SPECTRUM, "--json", "--out", str(path)], capsys)
    assert code == 0, err
    summary = json.loads(out)
    assert summary["out"] == str(path)
    cycles = np.array(summary["outputs"][1]["cycles"])
    if suffix == ".npz":
        data = np.load(path, allow_pickle=False)
        assert list(data["names"]) == ["ID1.disc_clutch.torque", "ID1.driving_shaft.torque"]
        np.testing.assert_array_equal(data["ID1.driving_shaft.torque.cycles"], cycles)
        assert data["equivalent_range"].shape == (2, 2)
        assert data["ID1.driving_shaft.torque.exceedance_count"][-1] == cycles[:, 2].sum()
    elif suffix == ".csv":
        with path.open() as handle:
            rows = list(csv.reader(handle))
        assert rows[0] == ["output", "unit", "range", "mean", "count"]
        shaft = [r for r in rows[1:] if r[0] == "ID1.driving_shaft.torque"]
        np.testing.assert_array_equal(np.array([r[2:] for r in shaft], dtype=float), cycles)
    else:
        assert json.loads(path.read_text())["outputs"] == summary["outputs"]


@pytest.mark.parametrize(("extra", "message"), [
    (["--slopes", "0"], "--slopes"),
    (["--slopes", "3,-5"], "must be a number > 0"),
    (["--slopes", "3,x"], "not a number"),
    (["--slopes", "3,3"], "repeated"),
    (["--out", "s.txt"], "must end in .npz or .csv or .json"),
    (["--fs", "100"], "--fs"),
    (["--anti-slip", "on"], "--anti-slip on needs --creep nonlinear"),
    (["--outputs", "ID1.nothing"], "unknown output"),
])
def test_spectrum_bad_input_one_line_exit_2(capsys, extra, message):
    code, out, err = run([*SPECTRUM, *extra], capsys)
    assert_one_line_error(code, out, err)
    assert message in err, err


def test_process_level_errors_have_no_traceback():
    for argv in (["envelope", "--serial", "--rail", "wet,icy"], ["spectrum", "--slopes", "-1"]):
        done = run_process(argv, timeout=120)
        assert done.returncode == 2
        assert "Traceback" not in done.stderr
        assert done.stderr.count("\n") == 1, done.stderr
