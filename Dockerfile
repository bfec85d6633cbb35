# The bogie dashboard (Panel) as a container image.  See docs/docker.md.
#   docker build -t bogie . && docker run --rm -p 5006:5006 bogie   ->  http://localhost:5006/app
# Base: the official slim Python image; any image with `python3` (with venv and pip) and `sh` works:
#   docker build --build-arg BASE_IMAGE=python:3.12-slim -t bogie .
# Without a Docker engine: bash scripts/build_image.sh check   (buildah; stand-in Debian base)
ARG BASE_IMAGE=python:3.11-slim
FROM ${BASE_IMAGE}

# Forwarded to pip during the build only (e.g. a package mirror); unset by default.
ARG PIP_INDEX_URL

ENV PYTHONDONTWRITEBYTECODE=1 \
    PYTHONUNBUFFERED=1 \
    PIP_DISABLE_PIP_VERSION_CHECK=1 \
    PIP_NO_CACHE_DIR=1 \
    BOGIE_PORT=5006 \
    BOGIE_STUDIES_DIR=/data/studies \
    PATH=/app/.venv/bin:$PATH

WORKDIR /app

# Installed as the README does it (python -m venv .venv; pip install -e .), in two steps so that
# the dependency layer is reused while only the code changes: first the dependencies from
# pyproject.toml (empty package stubs), then the project itself.
COPY pyproject.toml ./
RUN mkdir model app \
    && touch README.md model/__init__.py app/__init__.py \
    && python3 -m venv .venv \
    && .venv/bin/python -m pip install --no-cache-dir -e . \
    && rm -rf model app README.md
COPY . .
RUN .venv/bin/python -m pip install --no-cache-dir --no-deps -e . \
    && bogie --help >/dev/null \
    && useradd --create-home --uid 10001 --user-group --shell /usr/sbin/nologin bogie \
    && mkdir -p /data/studies && chown -R 10001:10001 /data

# Run as the unprivileged user bogie (uid 10001); the code and the virtual environment stay owned
# by root, read-only for the server.  Studies are written to /data/studies (BOGIE_STUDIES_DIR),
# owned by bogie: mount a volume there to keep them (docs/docker.md).
USER 10001
EXPOSE 5006
# Python handles SIGINT (KeyboardInterrupt) even as PID 1; the default SIGTERM would be ignored.
STOPSIGNAL SIGINT

# Panel's liveness endpoint builds the app for real and answers 500 if that fails (no curl needed).
HEALTHCHECK --interval=30s --timeout=10s --start-period=30s --retries=3 \
    CMD ["python3", "-c", "import os, urllib.request as u; u.urlopen('http://127.0.0.1:%s/liveness?endpoint=/app' % os.environ.get('BOGIE_PORT', '5006'), timeout=8)"]

# Operator settings (docs/security.md), as environment variables: BOGIE_ALLOWED_ORIGINS
# (comma-separated host[:port]; default: localhost only), BOGIE_SCHEDULER, BOGIE_STUDIES_DIR,
# BOGIE_MAX_STUDY_POINTS, BOGIE_MAX_RUNNING_STUDIES, BOGIE_MAX_WAITING_STUDIES.
CMD ["sh", "-c", "exec bogie serve --address 0.0.0.0 --port \"${BOGIE_PORT}\""]
