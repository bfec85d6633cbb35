"""``bogie response``: files (.npz, .csv, .json), the summary, and one-line exit-2 errors."""

from __future__ import annotations

import csv
import json
import subprocess
import sys

import numpy as np
import pytest
from test_cli import run  # the in-process CLI runner (tests/ is on sys.path under pytest)

BASE = ["response", "--t-end", "0.2", "--fs", "1000"]



def test_summary_table_lists_every_output_with_peaks_and_frequencies(capsys):
    code, out, err = run(BASE, capsys)
    assert code == 0, err
    assert "ID1.disc_clutch.torque" in out
    assert "ID2.wheelset.adhesion_moment" in out
    assert "dominant frequencies [Hz]" in out
    assert "M_ad" in out


def test_npz_has_t_each_output_and_mc(tmp_path, capsys):
    path = tmp_path / "r.npz"
    code, _, err = run([*BASE, "--out", str(path)], capsys)
    assert code == 0, err
    data = np.load(path, allow_pickle=False)
    assert len(data["t"]) == 201
    assert data["t"][-1] == pytest.approx(0.2)
    for name in data["names"]:
        assert data[str(name)].shape == data["t"].shape
    assert data["M_C"].shape == data["t"].shape
    # the step removes the motor torque: M_C → −M(s0, v) once the oscillation has decayed
    assert data["M_C"][-1] < 0


def test_csv_has_a_column_per_output_with_units(tmp_path, capsys):
    path = tmp_path / "r.csv"
    code, _, err = run([*BASE, "--out", str(path), "--outputs",
                        "ID1.driving_shaft.torque,ID1.rotor.ry"], capsys)
    assert code == 0, err
    with path.open() as handle:
        rows = list(csv.reader(handle))
    assert rows[0] == ["t [s]", "M_C [N m]", "ID1.driving_shaft.torque [N m]",
                       "ID1.rotor.ry [rad]"]
    assert len(rows) == 202
    float(rows[-1][2])


def test_json_summary_and_series(tmp_path, capsys):
    path = tmp_path / "r.json"
    code, out, err = run([*BASE, "--json", "--out", str(path), "--s0", "0.014"], capsys)
    assert code == 0, err
    summary = json.loads(out)
    assert summary["operating_point"]["s0"] == 0.014
    assert {"peak", "peak_time", "dominant_frequencies_hz", "unit"} <= set(
        summary["outputs"]["ID1.disc_clutch.torque"])
    data = json.loads(path.read_text())
    assert len(data["series"]["ID1.disc_clutch.torque"]) == len(data["t"])


@pytest.mark.parametrize(("argv", "word"), [
    (["--t-end", "0"], "--t-end"),
    (["--t-end", "1e5"], "--t-end"),
    (["--fs", "100"], "--fs"),  # below 2.5 × 90 Hz
    (["--fs", "300"], "highest excited frequency"),  # below 2.5 × the driving-shaft mode
    (["--m0", "-5"], "--m0"),
    (["--decay", "-1"], "--decay"),
    (["--f", "abc"], "--f"),
    (["--out", "x.xlsx"], "must end in .npz or .csv or .json"),
    (["--outputs", "ID1.nonsense"], "unknown output"),
    (["--s0", "2"], "--s0"),
])
def test_bad_input_is_one_line_exit_2(argv, word, capsys):
    code, out, err = run(["response", "--t-end", "0.1", "--fs", "1000", *argv], capsys)
    assert code == 2
    assert word in err
    assert len(err.strip().splitlines()) == 1
    assert "Traceback" not in err
    assert out == ""


def test_process_level_error_has_no_traceback(tmp_path):
    result = subprocess.run([sys.executable, "-m", "app", "response", "--fs", "10",
                             "--out", str(tmp_path / "a.npz")], capture_output=True, text=True,
                            timeout=300)
    assert result.returncode == 2
    assert len(result.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "a.npz").exists()  # bad input changes nothing
