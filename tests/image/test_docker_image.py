"""Build the container image for real and serve it (buildah, no Docker engine; see docs/docker.md).

scripts/build_image.sh makes a stand-in base (debootstrap bookworm + python3, cached in
/var/tmp/bogie-rootfs) when Docker Hub's python:3.11-slim cannot be pulled, builds ./Dockerfile
with ``buildah bud --isolation chroot`` and runs the image's CMD with ``buildah run``.  From nothing
this takes a few minutes (debootstrap about a minute, build one to three); later runs reuse the
cached root filesystem, base image and dependency layer.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import signal
import socket
import subprocess
import time
import urllib.error
import urllib.request
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
from conftest import ROOT

pytestmark = [pytest.mark.slow, pytest.mark.docker]

ROOT = ROOT
SCRIPT = ROOT / "scripts" / "build_image.sh"
IMAGE = "localhost/bogie:test"


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def get(url: str, timeout: float = 10) -> tuple[int | str, str]:
    try:
        with urllib.request.urlopen(url, timeout=timeout) as response:
            return response.status, response.read().decode()
    except urllib.error.HTTPError as error:
        return error.code, ""
    except (urllib.error.URLError, OSError) as error:
        return str(error), ""


def script(*args: str, timeout: float) -> subprocess.CompletedProcess:
    return subprocess.run(["bash", str(SCRIPT), *args], env={**os.environ, "IMAGE": IMAGE},
                          capture_output=True, text=True, timeout=timeout, check=False)


@pytest.fixture(scope="module")
def image():
    missing = [tool for tool in ("buildah", "debootstrap")
               if not (shutil.which(tool) or Path("/usr/sbin", tool).is_file())]
    if missing:
        pytest.fail(f"{' and '.join(missing)} missing: 'apt-get install -y {' '.join(missing)}' "
                    "(bash run.sh test installs them)")
    start = time.monotonic()
    build = script("build", timeout=3600)
    assert build.returncode == 0, f"image build failed:\n{build.stderr[-4000:]}"
    print(f"\nimage built in {time.monotonic() - start:.0f} s")
    return IMAGE


@pytest.fixture(scope="module")
def served(image, tmp_path_factory):
    """The image's CMD running with ``buildah run`` on a free port of this machine."""
    port = free_port()
    log_path = tmp_path_factory.mktemp("serve") / "serve.log"
    env = {key: value for key, value in os.environ.items() if key != "BOGIE_ALLOWED_ORIGINS"}
    with log_path.open("w") as log:  # a file, not a pipe: a full pipe would block the server
        process = subprocess.Popen(["bash", str(SCRIPT), "serve", str(port)],
                                   env={**env, "IMAGE": image}, stdout=log,
                                   stderr=subprocess.STDOUT, start_new_session=True)
    base = f"http://127.0.0.1:{port}"
    start = time.monotonic()
    status: int | str = "not polled"
    try:
        while time.monotonic() - start < 180 and process.poll() is None:
            status, _ = get(f"{base}/liveness?endpoint=/app")
            if status == 200:
                break
            time.sleep(0.5)
        print(f"\nfirst liveness answer {status} after {time.monotonic() - start:.1f} s")
        yield base, port, status
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGINT)
            try:
                process.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(process.pid, signal.SIGKILL)
                process.wait(timeout=20)
        # ``buildah run --isolation chroot`` has no process namespace of its own: what the
        # server started inside (its worker processes' forkserver, which ignores SIGINT) would
        # outlive the run, where stopping a container ends every process in it
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGKILL)
        print(log_path.read_text()[-3000:])


def test_liveness_endpoint_answers_200(served):
    _, _, status = served
    assert status == 200


def test_app_page_holds_the_bokeh_document(served):
    """/app is Bokeh's server page (its document follows over the websocket): pull it."""
    # Panel's model types for deserialization, the mode table's DataTabulator too (not loaded
    # by ``import panel`` alone)
    import panel.models.tabulator  # noqa: F401
    from bokeh.client import pull_session

    base, _, _ = served
    status, page = get(f"{base}/app", timeout=60)
    assert status == 200
    assert "Bokeh.embed.embed_items(docs_json, render_items)" in page
    assert '"token"' in page  # the session the page's websocket opens
    def pull() -> tuple[int, int, str]:
        with pull_session(url=f"{base}/app") as session:
            document = session.document
            return len(document.roots), len(list(document.models)), document.title

    # in a thread of its own: an earlier test (Playwright, pn.serve) may leave an asyncio loop
    # running in this one, and bokeh.client cannot run its loop inside another
    with ThreadPoolExecutor(max_workers=1) as pool:
        roots, models, title = pool.submit(pull).result(timeout=120)
    assert roots
    assert models > 10
    assert title == "Bogie drive dynamics"


def websocket_handshake(port: int, origin: str) -> int:
    """HTTP status of a websocket upgrade request to /app/ws from the given Origin."""
    request = (f"GET /app/ws HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nOrigin: {origin}\r\n"
               "Connection: Upgrade\r\nUpgrade: websocket\r\nSec-WebSocket-Version: 13\r\n"
               "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Protocol: bokeh\r\n"
               "\r\n")
    with socket.create_connection(("127.0.0.1", port), timeout=30) as sock:
        sock.sendall(request.encode())
        status_line = sock.makefile("rb").readline().decode()
    return int(status_line.split()[1])


def test_websocket_origins_default_to_localhost_only(served):
    _, port, status = served
    assert status == 200
    assert websocket_handshake(port, f"http://127.0.0.1:{port}") == 101
    assert websocket_handshake(port, f"http://localhost:{port}") == 101
    assert websocket_handshake(port, "http://elsewhere.example.org") == 403


def test_healthcheck_command_passes_inside_the_container(served):
    """The image's own HEALTHCHECK command (python3 + urllib, no curl) run in the container."""
    _, port, status = served
    assert status == 200
    inspect = subprocess.run(["buildah", "inspect", "--type", "image", IMAGE],
                             capture_output=True, text=True, timeout=60, check=True)
    test = json.loads(inspect.stdout)["Docker"]["config"]["Healthcheck"]["Test"]
    assert test[0] == "CMD"
    run = subprocess.run(["buildah", "run", "--isolation", "chroot", "--env", f"BOGIE_PORT={port}",
                          f"bogie-serve-{port}", "--", *test[1:]],
                         capture_output=True, text=True, timeout=60, check=False)
    assert run.returncode == 0, run.stderr


def test_server_runs_as_the_unprivileged_user(served):
    _, port, _ = served
    run = subprocess.run(["buildah", "run", "--isolation", "chroot", f"bogie-serve-{port}", "--",
                          "id", "-u"], capture_output=True, text=True, timeout=60, check=False)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() not in {"", "0"}
