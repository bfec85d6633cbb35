#!/usr/bin/env bash
# The project's two commands (see README.md):
#   bash run.sh app    -> install into .venv (first time) and serve the dashboard on http://localhost:5006/app
#   bash run.sh test   -> install into .venv (+ Debian's chromium, buildah, debootstrap) and run ruff, the
#                         import contract and the whole test suite on every core
set -euo pipefail
cd "$(dirname "$0")"
PY=${PYTHON:-python3}
VENV=.venv

ensure_venv() {
    if [ ! -x "$VENV/bin/python" ]; then
        "$PY" -m venv "$VENV"
    fi
    # editable install: only a changed pyproject.toml needs pip again (stamp = its last copy)
    local stamp="$VENV/.installed-pyproject$1.toml"
    if [ -f "$stamp" ] && cmp -s pyproject.toml "$stamp"; then
        return
    fi
    "$VENV/bin/python" -m pip install -q --upgrade pip
    "$VENV/bin/python" -m pip install -q -e ".$1"
    cp pyproject.toml "$stamp"
}

case "${1:-}" in
    app)
        shift
        ensure_venv ""
        exec "$VENV/bin/bogie" serve "$@"
        ;;
    test)
        shift
        ensure_venv "[test]"
        if [ ! -x /usr/bin/chromium ] || ! command -v buildah >/dev/null || { [ ! -x /usr/sbin/debootstrap ] && ! command -v debootstrap >/dev/null; }; then
            echo "run.sh: installing Debian packages chromium, buildah, debootstrap for the browser and image tests" >&2
            SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
            $SUDO apt-get update -qq
            DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq chromium buildah debootstrap >/dev/null
        fi
        "$VENV/bin/ruff" check model app tests scripts
        "$VENV/bin/lint-imports"  # the import contract of pyproject.toml (docs/architecture.md)
        # one pytest worker per core (pytest-xdist; tests/conftest.py says which tests go together),
        # the 25 slowest tests and the total at the end
        status=0
        "$VENV/bin/python" -m pytest -n auto --durations=25 "$@" || status=$?
        echo "run.sh: test: ${SECONDS} s in all (install included), exit status ${status}" >&2
        exit "$status"
        ;;
    *)
        echo "usage: bash run.sh app [bogie serve options] | bash run.sh test [pytest options]" >&2
        exit 2
        ;;
esac
