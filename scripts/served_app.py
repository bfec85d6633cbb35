"""Start ``bogie serve`` for a benchmark or reliability script: a free port, the server as a
separate process (as users run it, one BLAS thread per computation), its log in the temporary
directory, and a wait until its liveness endpoint answers."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def alive(url: str, timeout: float = 60.0) -> bool:
    """Whether ``/liveness?endpoint=/app`` answers 200 (it builds the app) within ``timeout``
    [s]."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            with urllib.request.urlopen(f"{url}/liveness?endpoint=/app", timeout=120) as r:
                if r.status == 200:
                    return True
        except (OSError, urllib.error.URLError):
            time.sleep(0.5)
    return False


def start_server(port: int, name: str, *options: str) -> subprocess.Popen:
    """``bogie serve --port PORT [options]`` with its log in ``<tmp>/<name>_server_<port>.log``
    and its studies in a new temporary folder (unless the options name one); exits the calling
    script if the server is not up within 180 s."""
    server_log = Path(tempfile.gettempdir()) / f"{name}_server_{port}.log"
    if "--studies-dir" not in options:
        options = (*options, "--studies-dir", tempfile.mkdtemp(prefix=f"{name}_studies_"))
    print(f"{name}: {time.strftime('%H:%M:%S')} server log: {server_log}", file=sys.stderr,
          flush=True)
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    process = subprocess.Popen([str(ROOT / ".venv/bin/bogie"), "serve", "--port", str(port),
                                *options],
                               cwd=ROOT, stdout=subprocess.DEVNULL,
                               stderr=server_log.open("w"), env=env)
    if not alive(f"http://127.0.0.1:{port}", timeout=180):
        process.kill()
        raise SystemExit(f"{name}: the server did not come up")
    return process


def machine_yardstick() -> str:
    """This machine's speed in the dashboard's main unit of work, for comparing latencies
    measured on different machines: one cold eigen-analysis with vectors at the default point
    (s0 = 0.005, 120 km/h, one BLAS thread; best of 5) [ms], and the load average."""
    from threadpoolctl import threadpool_limits

    from model import KMH, build_model, eigen_analysis, load_parameters
    from model.analysis.eigen import forget_systems
    from model.mechanics.operating_point import OperatingPoint

    parameters = load_parameters()
    model = build_model(parameters)
    op = OperatingPoint(0.005, 120 * KMH, parameters["wheel_force"], parameters["motor_slope"])
    times = []
    with threadpool_limits(1):
        for _ in range(5):
            forget_systems(model)
            start = time.perf_counter()
            eigen_analysis(model, op)
            times.append(time.perf_counter() - start)
    return (f"machine: one eigen-analysis with vectors {min(times) * 1e3:.1f} ms (best of 5, one "
            f"BLAS thread), {os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f}")
