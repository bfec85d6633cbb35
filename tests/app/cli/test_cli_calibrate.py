"""``bogie calibrate --starts N`` and ``--start K``: the global calibration's options (fast, with
a stubbed least squares), their bad input, and the reproduction of a start alone (slow: real
least squares on a budget of one trial set per phase)."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest
from test_cli import run

from model.studies import global_calibration as gc
from model.studies.calibration_bounds import SEARCH_PARAMETERS
from model.studies.numerics import (
    BLAS_KERNELS,
    disabled_numpy_targets,
    pinnable,
    pinned_values,
)


@pytest.fixture
def stubbed(monkeypatch):
    """run_start and write_start without the least squares: every start meets the divergence,
    start k has 10 − |k − 1| ranks within 5 % (start 1 is the best by the rule) and costs
    (k − 1)² + 1."""
    values = {f.name: f.low for f in SEARCH_PARAMETERS}
    written = []

    def fake_start(k, start_file=None, phases=None, progress=None):
        return gc.StartResult(k, gc.start_values(k), values, float((k - 1) ** 2 + 1),
                              0.01 + 0.1 * abs(k - 1), 10 - abs(k - 1), 10, 7.0 + 0.1 * k,
                              0.02 * k, 0.5)

    def fake_write(result, out, start_file=None, divergence_weight=None):
        out.write_text(f"start {result.index}\n", encoding="utf-8")
        written.append(result.index)
        return [], "targets table"

    monkeypatch.setattr(gc, "run_start", fake_start)
    monkeypatch.setattr(gc, "write_start", fake_write)
    return written


def test_starts_serial_writes_the_best_start_and_reports_every_start(capsys, tmp_path, stubbed):
    out = tmp_path / "best.toml"
    code, stdout, err = run(["calibrate", "--starts", "3", "--serial", "--out", str(out),
                             "--json"], capsys)
    assert code == 0, err
    data = json.loads(stdout)
    assert data["starts"] == 3
    assert data["best"] == 1  # the most ranks within 5 %
    assert [r["index"] for r in data["results"]] == [0, 1, 2, 3]  # start 0: the file's values
    assert data["front"] == [0, 1]  # the smallest divergence and frequency errors
    assert {row["name"] for row in data["spread"]} == {f.name for f in SEARCH_PARAMETERS}
    assert out.read_text(encoding="utf-8") == "start 1\n"
    assert stubbed == [1]
    assert "global calibration: start 0 and 3 Sobol' starts on this process (serial)" in err


def test_sixteen_starts_and_the_table(capsys, tmp_path, stubbed):
    code, stdout, err = run(["calibrate", "--starts", "16", "--serial", "--out",
                             str(tmp_path / "best.toml")], capsys)
    assert code == 0, err
    assert "17 starts" in stdout  # start 0 and the 16 Sobol' starts
    assert "spread of the best starts" in stdout
    assert "best: start 1" in stdout


def test_start_k_runs_that_start_alone(capsys, tmp_path, stubbed):
    out = tmp_path / "s4.toml"
    code, stdout, err = run(["calibrate", "--start", "4", "--out", str(out), "--json"], capsys)
    assert code == 0, err
    assert json.loads(stdout)["start"] == 4
    assert out.read_text(encoding="utf-8") == "start 4\n"


@pytest.mark.parametrize(("arguments", "mention"), [
    pytest.param(["--starts", "2", "--start", "1"], "not allowed with", id="both"),
    pytest.param(["--starts", "0"], "--starts", id="no starts"),
    pytest.param(["--start", "-1"], "--start", id="negative start"),
    pytest.param(["--start", "x"], "--start", id="start not a number"),
    pytest.param(["--starts", "2", "--scheduler", "tcp://127.0.0.1:9", "--connect-timeout",
                  "0.5"], "cannot reach", id="unreachable scheduler"),
])
def test_bad_global_arguments_one_line_exit_2(capsys, tmp_path, stubbed, arguments, mention):
    out = tmp_path / "set.toml"
    code, stdout, err = run(["calibrate", "--out", str(out), *arguments], capsys)
    assert code == 2
    assert stdout == ""
    assert err.strip().count("\n") == 0, err
    assert "Traceback" not in err
    assert mention in err
    assert not out.exists()


@pytest.mark.slow
def test_start_alone_reproduces_the_global_searchs_best_byte_for_byte(capsys, tmp_path):
    """The real least squares (one trial set per phase): ``--starts 2`` on the default local
    cluster writes its best start's set; ``--start K`` of that start in this process writes the
    same bytes (one BLAS thread either way)."""
    best = tmp_path / "best.toml"
    code, stdout, err = run(["calibrate", "--starts", "2", "--max-evaluations", "1", "--workers",
                             "2", "--out", str(best), "--json"], capsys)
    assert code == 0, err
    k = json.loads(stdout)["best"]
    alone = tmp_path / "alone.toml"
    code, _, err = run(["calibrate", "--start", str(k), "--max-evaluations", "1", "--out",
                        str(alone)], capsys)
    assert code == 0, err
    assert alone.read_bytes() == best.read_bytes()
    assert f"start {k} of the global calibration" in alone.read_text(encoding="utf-8")


@pytest.mark.slow
def test_the_single_calibration_is_start_0(capsys, tmp_path):
    """``bogie calibrate`` without ``--start`` fits the start file's own values: start 0 of the
    global calibration, the same bytes as ``--start 0`` (the bundled set's header names the
    command; its re-run: scripts/bench_calibration.py)."""
    single, alone = tmp_path / "single.toml", tmp_path / "start0.toml"
    code, _, err = run(["calibrate", "--max-evaluations", "1", "--out", str(single)], capsys)
    assert code == 0, err
    assert "start 0 of the global calibration" in err
    code, _, err = run(["calibrate", "--start", "0", "--max-evaluations", "1", "--out",
                        str(alone)], capsys)
    assert code == 0, err
    assert single.read_bytes() == alone.read_bytes()
    assert "(the same as `--start 0`)" in single.read_text(encoding="utf-8")


def _calibrate_process(out, environment: dict) -> subprocess.CompletedProcess:
    """``python -m app calibrate --start 0`` on a budget of one trial set per phase, as its own
    process started with ``environment`` (added to this one's, less the pins' variables)."""
    pins = pinned_values()
    base = {k: v for k, v in os.environ.items() if k not in pins and not k.startswith("OPENBLAS_")}
    return subprocess.run([sys.executable, "-m", "app", "calibrate", "--start", "0",
                           "--max-evaluations", "1", "--out", str(out), "--json"],
                          capture_output=True, text=True, timeout=300, check=False,
                          env={**base, **environment})


@pytest.mark.slow
def test_the_command_pins_its_numerics_and_writes_the_same_bytes_from_any_environment(tmp_path):
    """Started with OpenBLAS's Sandybridge kernels on two threads, or with the libraries'
    own choice for this processor, the command runs itself again with the pins
    (model.studies.numerics) and writes the same bytes; unpinned, these two write different
    values in their last digits (measured: one trial set per phase is enough).  A processor
    that cannot take the pins is told so on stderr."""
    first, second = tmp_path / "sandybridge.toml", tmp_path / "native.toml"
    runs = [_calibrate_process(first, {"OPENBLAS_CORETYPE": "Sandybridge",
                                       "OPENBLAS_NUM_THREADS": "2"}),
            _calibrate_process(second, {})]
    for done in runs:
        assert done.returncode == 0, done.stderr
    if not pinnable():
        assert all("cannot take the pinned numerics" in done.stderr for done in runs)
        return
    for done in runs:
        assert "numerics pinned for reproducible bytes" in done.stderr
        numerics = json.loads(done.stdout)["numerics"]
        assert numerics["blas"], numerics
        assert all(blas["kernels"] == BLAS_KERNELS and blas["threads"] == 1
                   for blas in numerics["blas"]), numerics
        assert not set(numerics["numpy_targets"]) & set(disabled_numpy_targets()), numerics
    assert first.read_bytes() == second.read_bytes()


def test_the_pins_name_numpys_targets_above_avx2():
    """NumPy 2.4's grouped targets and NumPy 1.x's single features: the AVX-512 family is
    disabled, AVX2's level kept; processors without AVX2 and FMA, or not x86-64, take no pins."""
    assert disabled_numpy_targets(["X86_V3", "X86_V4", "AVX512_ICL", "AVX512_SPR"]) == [
        "X86_V4", "AVX512_ICL", "AVX512_SPR"]
    assert disabled_numpy_targets(["SSE42", "AVX2", "FMA3", "AVX512F", "AVX512_SKX"]) == [
        "AVX512F", "AVX512_SKX"]
    assert "NPY_DISABLE_CPU_FEATURES" not in pinned_values(["SSE42", "AVX2"])
    assert pinned_values([])["OPENBLAS_CORETYPE"] == "Haswell"
    assert not pinnable({"AVX2": True, "FMA3": True}, "aarch64")
    assert not pinnable({"AVX2": False, "FMA3": True}, "x86_64")
    assert pinnable({"AVX2": True, "FMA3": True}, "x86_64")
