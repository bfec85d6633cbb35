"""Studies on a real Dask cluster started by the test on 127.0.0.1 (no mocks): a ``dask
scheduler`` and a ``dask worker`` with two worker processes of one thread each, both stopped by
the process ids started here.

* the map on the cluster equals the serial computation exactly (bitwise);
* a worker process killed with SIGKILL mid-study: the study completes, results identical;
* ``bogie study map`` interrupted by SIGINT (Ctrl-C) exits 130 leaving a resumable store; the
  resume computes exactly the unfinished chunks (counted), rewrites no finished one.
"""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT

from model import KMH, load_parameters
from model.studies.engine import StudyEngine
from model.studies.maps import MapStudy, run_serial
from model.studies.store import finished_chunks, open_study, run_into_store

pytestmark = pytest.mark.slow
BIN = Path(sys.executable).parent
ENV = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1",
       "DASK_DISTRIBUTED__NANNY__PRE_SPAWN_ENVIRON__MALLOC_TRIM_THRESHOLD_": "None"}


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _stop(process: subprocess.Popen) -> None:
    """SIGTERM to the process started here, then SIGKILL after 20 s."""
    if process.poll() is None:
        process.send_signal(signal.SIGTERM)
        try:
            process.wait(timeout=20)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(timeout=10)


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    """Address of a scheduler with two single-thread worker processes (127.0.0.1 only)."""
    logs = tmp_path_factory.mktemp("dask")
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    with open(logs / "scheduler.log", "w") as scheduler_log, \
            open(logs / "worker.log", "w") as worker_log:
        scheduler = subprocess.Popen(
            [str(BIN / "dask"), "scheduler", "--host", "127.0.0.1", "--port", str(port),
             "--no-dashboard"], cwd=ROOT, env=ENV, stdout=subprocess.DEVNULL, stderr=scheduler_log)
        worker = subprocess.Popen(
            [str(BIN / "dask"), "worker", address, "--nworkers", "2", "--nthreads", "1",
             "--no-dashboard", "--host", "127.0.0.1"], cwd=ROOT, env=ENV,
            stdout=subprocess.DEVNULL, stderr=worker_log)
        try:
            from distributed import Client

            with Client(address, timeout=60, set_as_default=False) as client:
                client.wait_for_workers(2, timeout=120)
            yield address
        finally:
            _stop(worker)
            _stop(scheduler)


@pytest.fixture(scope="module")
def study_and_reference():
    parameters = load_parameters()
    study = MapStudy(np.linspace(0.002, 0.016, 8), np.linspace(50, 240, 6) * KMH,
                     [parameters["wheel_force"]], [parameters["motor_slope"]])
    return parameters, study, run_serial(study, parameters)


@pytest.fixture(scope="module")
def long_study_reference():
    """24 speed lines (chunks): on the set calibrated by rank a chunk of 8 points takes ~0.5 s,
    and 6 chunks leave too short a window for the Ctrl-C tests; 24 run ~7 s on two workers."""
    parameters = load_parameters()
    study = MapStudy(np.linspace(0.002, 0.016, 8), np.linspace(50, 240, 24) * KMH,
                     [parameters["wheel_force"]], [parameters["motor_slope"]])
    return run_serial(study, parameters)


def _as_in_a_terminal():
    """The child gets Ctrl-C as in a terminal: a shell's background job (``… &``, as CI runners
    and ``nohup`` start them) runs with SIGINT ignored, an ignored signal stays ignored across
    exec, and Python then installs no KeyboardInterrupt handler — the study ignored the
    interrupt and ran to its end (exit 0) when the suite was started that way."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _assert_equal_to_reference(path, reference):
    dataset = open_study(path)
    assert (dataset["chunk_done"].values == 1).all()
    for (i, j, k), result in reference.items():
        for name in ("largest_real_part", "stable", "flutter_pairs", "divergent_real"):
            np.testing.assert_array_equal(dataset[name].values[:, i, j, k], result[name])
        np.testing.assert_array_equal(dataset["s0_limit"].values[i, j, k], result["s0_limit"])


def test_cluster_equals_serial(cluster, study_and_reference, tmp_path):
    parameters, study, reference = study_and_reference
    with StudyEngine(scheduler=cluster, connect_timeout=30) as engine:
        run = run_into_store(study, parameters, tmp_path / "m.zarr", engine.map_unordered)
    assert run.computed == len(reference)
    _assert_equal_to_reference(tmp_path / "m.zarr", reference)


def test_cluster_equals_serial_continuation(cluster, tmp_path):
    """The same with s0_line's exact continuation (model.analysis.continuation): bitwise identical."""
    parameters = load_parameters()
    study = MapStudy(np.linspace(0.002, 0.016, 30), np.linspace(60, 220, 3) * KMH,
                     [parameters["wheel_force"]], [parameters["motor_slope"]],
                     method="continuation")
    reference = run_serial(study, parameters)
    with StudyEngine(scheduler=cluster, connect_timeout=30) as engine:
        run = run_into_store(study, parameters, tmp_path / "c.zarr", engine.map_unordered)
    assert run.computed == len(reference)
    _assert_equal_to_reference(tmp_path / "c.zarr", reference)


def test_worker_killed_mid_study(cluster, study_and_reference, tmp_path):
    """SIGKILL to one worker process after the first chunk arrived: Dask reschedules its task
    on the surviving worker (the nanny restarts the dead one); nothing finished is lost and the
    results are identical."""
    parameters, study, reference = study_and_reference
    killed = []
    with StudyEngine(scheduler=cluster, connect_timeout=30) as engine:
        pids = engine.client.run(os.getpid)
        assert len(pids) == 2

        def progress(finished, total, elapsed):
            if finished == 1 and not killed:
                pid = next(iter(pids.values()))
                os.kill(pid, signal.SIGKILL)  # a worker process of the worker started above
                killed.append(pid)

        run = run_into_store(study, parameters, tmp_path / "k.zarr", engine.map_unordered,
                             progress=progress)
    assert killed
    assert run.computed == len(reference)
    _assert_equal_to_reference(tmp_path / "k.zarr", reference)


def test_interrupt_then_resume_recomputes_nothing_finished(cluster, long_study_reference,
                                                            tmp_path):
    reference = long_study_reference
    out = tmp_path / "r.zarr"
    argv = [str(BIN / "bogie"), "study", "map", "--s0", "0.002:0.016:8", "--v", "50:240:24",
            "--out", str(out), "--scheduler", cluster, "--connect-timeout", "30", "--json"]
    process = subprocess.Popen(argv, cwd=ROOT, env=ENV, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, preexec_fn=_as_in_a_terminal)
    started = time.monotonic()
    deadline, polls = started + 300, 0
    while time.monotonic() < deadline and process.poll() is None:
        polls += 1
        if (out / "chunk_done" / "zarr.json").exists() and finished_chunks(out):
            break
        time.sleep(0.05)
    waited = f"interrupt after {time.monotonic() - started:.1f} s and {polls} polls\n"
    process.send_signal(signal.SIGINT)  # Ctrl-C
    _, err = process.communicate(timeout=120)
    assert process.returncode == 130, waited + err
    assert "continue with --resume" in err
    assert "Traceback" not in err
    finished = finished_chunks(out)
    assert 1 <= len(finished) < len(reference), "interrupt came too late to test a resume"
    # the finished chunks' markers must not be rewritten.  (Not the data files: a line whose
    # values were written but whose marker was not when Ctrl-C came is unfinished, and its
    # recomputation rewrites them; the task counts below say nothing finished was recomputed)
    markers = {p: p.stat().st_mtime_ns for p in (out / "chunk_done").rglob("*")
               if p.is_file() and p.name != "zarr.json"}

    resumed = subprocess.run([*argv, "--resume"], cwd=ROOT, env=ENV, capture_output=True,
                             text=True, timeout=600)
    assert resumed.returncode == 0, resumed.stderr
    summary = json.loads(resumed.stdout)
    assert summary["skipped_chunks"] == len(finished)
    assert summary["computed_chunks"] == len(reference) - len(finished)
    for path, stamp in markers.items():  # finished chunks were not rewritten
        assert path.stat().st_mtime_ns == stamp
    _assert_equal_to_reference(out, reference)


def test_ctrl_c_with_the_local_cluster_stops_everything_cleanly(tmp_path):
    """Ctrl-C in a terminal reaches the whole process group (the client and its local worker
    processes): exit 130, one message and no traceback, no process of the group left; the
    resume on the default local cluster finishes the rest."""
    out = tmp_path / "c.zarr"
    argv = [str(BIN / "bogie"), "study", "map", "--s0", "0.002:0.016:8", "--v", "50:240:24",
            "--out", str(out), "--json"]  # 24 chunks: see long_study_reference
    process = subprocess.Popen(argv, cwd=ROOT, env=ENV, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, start_new_session=True,
                               preexec_fn=_as_in_a_terminal)
    started = time.monotonic()
    deadline, polls = started + 300, 0
    while time.monotonic() < deadline and process.poll() is None:
        polls += 1
        if (out / "chunk_done" / "zarr.json").exists() and finished_chunks(out):
            break
        time.sleep(0.05)
    waited = f"interrupt after {time.monotonic() - started:.1f} s and {polls} polls\n"
    os.killpg(process.pid, signal.SIGINT)  # the group started here (a new session)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 130, waited + err
    assert "Traceback" not in err
    assert "continue with --resume" in err
    time.sleep(2)
    left = subprocess.run(["ps", "-o", "pid=", "-g", str(process.pid)], capture_output=True,
                          text=True).stdout.split()
    assert left == []
    finished = len(finished_chunks(out))
    resumed = subprocess.run([*argv, "--resume"], cwd=ROOT, env=ENV, capture_output=True,
                             text=True, timeout=600)
    assert resumed.returncode == 0, resumed.stderr
    assert json.loads(resumed.stdout)["computed_chunks"] == 24 - finished


def test_uncertainty_study_on_the_cluster_equals_serial(cluster):
    """The Monte-Carlo/Sobol study of model.studies.uncertainty through the engine (the map used by
    ``bogie study uncertainty``) gives exactly the serial samples and outputs (two uncertain
    parameters, n = 2: 8 model runs)."""
    from model.studies.engine import in_order
    from model.studies.uncertainty import UNCERTAIN_PARAMETERS, run_uncertainty

    parameters = load_parameters()
    uncertain = UNCERTAIN_PARAMETERS[:2]
    serial = run_uncertainty(parameters, 2, uncertain, chunk_size=1, n_resamples=9)
    with StudyEngine(scheduler=cluster, connect_timeout=30) as engine:
        on_cluster = run_uncertainty(parameters, 2, uncertain, chunk_size=1, n_resamples=9,
                                     map_fn=in_order(engine.map_unordered))
    assert np.array_equal(on_cluster.samples, serial.samples)
    assert np.array_equal(on_cluster.values, serial.values, equal_nan=True)
    assert np.array_equal(on_cluster.first_order, serial.first_order, equal_nan=True)


def test_a_local_cluster_whose_workers_do_not_join_in_time_is_unavailable():
    """``start`` waits for every worker of a local cluster; when they do not all join within
    ``worker_timeout`` (here far shorter than a worker's ≈ 0.5 s start-up) it closes the
    cluster and says so, instead of leaving a study to wait for workers forever."""
    from model.studies.engine import EngineUnavailable

    engine = StudyEngine(None, workers=2, use_environment=False, supervised=False,
                         worker_timeout=0.001)
    with pytest.raises(EngineUnavailable, match=r"of the local cluster's 2 workers joined"):
        engine.start()
    assert engine.client is None
    assert engine.cluster is None


@pytest.mark.parametrize("supervised", [False, True], ids=["plain-workers", "nannies"])
def test_a_local_cluster_starts_when_port_8787_is_taken(supervised):
    """A scheduler serves HTTP (health, metrics) on 8787 unless told otherwise; with that port
    held by someone else (another cluster, another server: CI ran into it) Dask warns and moves,
    which the suite treats as an error.  The engine's local cluster takes any free loopback port,
    so it starts silently whoever holds 8787, and its HTTP server listens on 127.0.0.1 only."""
    holder = socket.socket()
    try:
        holder.bind(("127.0.0.1", 8787))
    except OSError:
        holder.close()
        holder = None  # 8787 is already taken here, which is the case under test anyway
    else:
        holder.listen()
    engine = StudyEngine(None, workers=1, use_environment=False, supervised=supervised)
    try:
        engine.start()  # a warning here fails the test (filterwarnings = error)
        http = engine.client.scheduler_info()["services"]
        assert set(http) == {"dashboard"}
        assert http["dashboard"] != 8787
        assert engine.map(abs, [-1, 2, -3]) == [1, 2, 3]
        address = engine.client.run_on_scheduler(
            lambda dask_scheduler: dask_scheduler.http_server.address)
        assert address == "127.0.0.1"
    finally:
        engine.close()
        if holder is not None:
            holder.close()


@pytest.mark.parametrize("address", ["abc", "tcp://scheduler", "tcp://host:port"])
def test_a_malformed_scheduler_address_is_refused_before_a_client_exists(address):
    """No client is made for an address without a port (distributed's half-made client would
    print a traceback while the interpreter exits): one-line EngineUnavailable at once."""
    from model.studies.engine import EngineUnavailable, StudyEngine

    engine = StudyEngine(address, connect_timeout=1.0)
    start = time.monotonic()
    with pytest.raises(EngineUnavailable, match="is not valid"):
        engine.start()
    assert engine.client is None
    assert time.monotonic() - start < 1.0  # refused, not timed out
