#!/usr/bin/env bash
# Build, serve and smoke-test the dashboard's container image WITHOUT a Docker engine (buildah).
#
#   bash scripts/build_image.sh base          # only make the stand-in base image (see below)
#   bash scripts/build_image.sh build         # base (if needed) + build the image from ./Dockerfile
#   bash scripts/build_image.sh serve [PORT]  # run the image's CMD in the foreground (Ctrl-C stops)
#   bash scripts/build_image.sh check [PORT]  # build, serve in the background, wait for
#                                             # /liveness?endpoint=/app = 200, fetch /app, run the
#                                             # image's HEALTHCHECK command, stop; exit 0 if all ok
#
# Stand-in base.  The Dockerfile's base is the official `python:3.11-slim` (build argument
# BASE_IMAGE).  Where Docker Hub cannot be reached, this script makes a stand-in: a Debian bookworm
# root filesystem from `debootstrap` (+ python3, python3-venv, python3-pip), cached in
# $BOGIE_ROOTFS_CACHE, with this machine's CA bundle copied in (pip inside the build must trust the
# same certificates as pip on this machine), imported into buildah as $STANDIN_BASE.  The
# Dockerfile only relies on `python3` and `sh`, which both bases have.  On a machine that can pull,
# give the real base: BASE_IMAGE=docker.io/library/python:3.11-slim bash scripts/build_image.sh build
#
# Environment (all optional):
#   BASE_IMAGE          base for the Dockerfile's FROM   (default: the stand-in $STANDIN_BASE)
#   IMAGE               tag of the built image           (default: localhost/bogie:latest)
#   STANDIN_BASE        tag of the stand-in base         (default: localhost/bogie-base:bookworm)
#   BOGIE_ROOTFS_CACHE  debootstrap cache directory      (default: /var/tmp/bogie-rootfs)
#   DEBIAN_MIRROR       Debian mirror for debootstrap    (default: this machine's apt source)
#   PIP_INDEX_URL       forwarded to the build when it is an http(s) URL (default: this machine's
#                       pip configuration, read with `pip config get global.index-url`)
#   BOGIE_ALLOWED_ORIGINS  passed on to the served container (serve, check)
#
# Needs root (buildah, debootstrap; re-runs itself with sudo when not root) and Debian's packages
# buildah and debootstrap (`bash run.sh test` installs them with apt-get).
set -euo pipefail
cd "$(dirname "$0")/.."

IMAGE=${IMAGE:-localhost/bogie:latest}
STANDIN_BASE=${STANDIN_BASE:-localhost/bogie-base:bookworm}
BOGIE_ROOTFS_CACHE=${BOGIE_ROOTFS_CACHE:-/var/tmp/bogie-rootfs}
SUITE=bookworm
DEFAULT_PORT=5006

die() { echo "build_image.sh: error: $*" >&2; exit 1; }
say() { echo "build_image.sh: $*" >&2; }
now() { date +%s.%N; }
elapsed() { python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.1f}')" "$1" "$(now)"; }

preflight() {
    local missing=()
    command -v buildah >/dev/null || missing+=(buildah)
    if [ -z "${BASE_IMAGE:-}" ]; then
        command -v debootstrap >/dev/null || [ -x /usr/sbin/debootstrap ] || missing+=(debootstrap)
    fi
    command -v python3 >/dev/null || missing+=(python3)
    if [ ${#missing[@]} -gt 0 ]; then
        die "missing ${missing[*]}: install with 'apt-get install -y ${missing[*]}' (bash run.sh test does this)"
    fi
    if [ "$(id -u)" -ne 0 ]; then
        if command -v sudo >/dev/null; then
            say "re-running as root with sudo (buildah and debootstrap need root here)"
            exec sudo -E bash "$0" "$@"
        fi
        die "must run as root (buildah --isolation chroot and debootstrap need it); sudo not found"
    fi
    export PATH="$PATH:/usr/sbin:/sbin"
}

debian_mirror() {
    if [ -n "${DEBIAN_MIRROR:-}" ]; then echo "$DEBIAN_MIRROR"; return; fi
    # The first plain Debian archive URI of this machine's apt sources (deb822 or one-line format).
    local uri
    uri=$(grep -hsE '^(URIs:|deb )' /etc/apt/sources.list.d/*.sources /etc/apt/sources.list \
          | grep -oE 'https?://[^ ]+/debian/?( |$)' | grep -v security | head -n1 | tr -d ' ' || true)
    echo "${uri:-http://deb.debian.org/debian}"
}

make_base() {
    # one maker at a time (two test runs at once would race on the cache)
    exec 9>"$BOGIE_ROOTFS_CACHE.lock"
    flock 9
    if buildah inspect --type image "$STANDIN_BASE" >/dev/null 2>&1; then
        say "stand-in base $STANDIN_BASE exists (remove with 'buildah rmi $STANDIN_BASE' to remake)"
        exec 9>&-
        return
    fi
    local t0 rootfs="$BOGIE_ROOTFS_CACHE/$SUITE"
    t0=$(now)
    if [ ! -f "$rootfs/.bogie-complete" ]; then
        local mirror tmp="$BOGIE_ROOTFS_CACHE/$SUITE.partial"
        mirror=$(debian_mirror)
        say "debootstrap $SUITE from $mirror into $rootfs (about a minute)"
        mkdir -p "$BOGIE_ROOTFS_CACHE"
        rm -rf "$tmp" "$rootfs"
        debootstrap --variant=minbase --include=python3,python3-venv,python3-pip,ca-certificates \
            "$SUITE" "$tmp" "$mirror" >"$BOGIE_ROOTFS_CACHE/debootstrap.log" 2>&1 \
            || { tail -n 20 "$BOGIE_ROOTFS_CACHE/debootstrap.log" >&2; die "debootstrap failed (log: $BOGIE_ROOTFS_CACHE/debootstrap.log)"; }
        rm -rf "$tmp/var/cache/apt/archives/"*.deb "$tmp/var/lib/apt/lists/"*
        touch "$tmp/.bogie-complete"
        mv "$tmp" "$rootfs"
        say "debootstrap done in $(elapsed "$t0") s"
    else
        say "using cached root filesystem $rootfs"
    fi
    local ctr mnt
    ctr=$(buildah from scratch)
    mnt=$(buildah mount "$ctr")
    cp -a "$rootfs/." "$mnt/"
    rm -f "$mnt/.bogie-complete"
    if [ -f /etc/ssl/certs/ca-certificates.crt ]; then
        cp /etc/ssl/certs/ca-certificates.crt "$mnt/etc/ssl/certs/ca-certificates.crt"
    fi
    buildah umount "$ctr" >/dev/null
    buildah config --env PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
        --env LANG=C.UTF-8 --env PIP_CERT=/etc/ssl/certs/ca-certificates.crt \
        --cmd python3 --label org.opencontainers.image.description="stand-in for python:3.11-slim: debootstrap $SUITE + python3" \
        "$ctr"
    buildah commit --rm -q "$ctr" "$STANDIN_BASE" >/dev/null
    say "stand-in base $STANDIN_BASE made in $(elapsed "$t0") s"
    exec 9>&-
}

build() {
    local base=${BASE_IMAGE:-}
    if [ -z "$base" ]; then
        make_base
        base=$STANDIN_BASE
    fi
    local args=(--isolation chroot --format docker --layers --build-arg "BASE_IMAGE=$base")
    local index=${PIP_INDEX_URL:-}
    if [ -z "$index" ] && command -v pip3 >/dev/null; then
        index=$(pip3 config get global.index-url 2>/dev/null || true)
    fi
    case "$index" in
        http://*|https://*) args+=(--build-arg "PIP_INDEX_URL=$index") ;;
    esac
    local t0
    t0=$(now)
    say "building $IMAGE from Dockerfile on $base"
    buildah bud "${args[@]}" -t "$IMAGE" -f Dockerfile . >&2
    say "image $IMAGE built in $(elapsed "$t0") s"
}

# The image's CMD and HEALTHCHECK command, read from its configuration, as NUL-separated words.
image_words() {
    buildah inspect --type image "$IMAGE" | python3 -c '
import json, sys
config = json.load(sys.stdin)["Docker"]["config"]
if sys.argv[1] == "cmd":
    words = (config.get("Entrypoint") or []) + (config.get("Cmd") or [])
else:
    test = (config.get("Healthcheck") or {}).get("Test") or []
    if not test or test[0] not in ("CMD", "CMD-SHELL"):
        sys.exit("build_image.sh: the image has no HEALTHCHECK")
    words = test[1:] if test[0] == "CMD" else ["/bin/sh", "-c", test[1]]
sys.stdout.write("\0".join(words))' "$1"
}

container_name() { echo "bogie-serve-$1"; }

serve() {
    local port=${1:-$DEFAULT_PORT} name cmd=()
    name=$(container_name "$port")
    buildah inspect --type image "$IMAGE" >/dev/null 2>&1 || die "no image $IMAGE: run 'bash scripts/build_image.sh build' first"
    buildah rm "$name" >/dev/null 2>&1 || true
    buildah from --name "$name" "$IMAGE" >/dev/null
    while IFS= read -r -d '' word; do cmd+=("$word"); done < <(image_words cmd; printf '\0')
    say "serving $IMAGE as container $name: ${cmd[*]} (BOGIE_PORT=$port) on http://localhost:$port/app"
    # --isolation chroot shares this machine's network: the port is reachable directly.
    # shellcheck disable=SC2064
    trap "buildah rm '$name' >/dev/null 2>&1 || true" EXIT
    local env=(--env "BOGIE_PORT=$port")
    [ -n "${BOGIE_ALLOWED_ORIGINS:-}" ] && env+=(--env "BOGIE_ALLOWED_ORIGINS=$BOGIE_ALLOWED_ORIGINS")
    buildah run --isolation chroot "${env[@]}" "$name" -- "${cmd[@]}"
}

free_port() { python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }

check() {
    local port=${1:-} t0 pid code=0
    [ -n "$port" ] || port=$(free_port)
    build
    t0=$(now)
    setsid bash "$0" serve "$port" &
    pid=$!
    # shellcheck disable=SC2064
    trap "kill -INT -- -$pid 2>/dev/null || true" EXIT
    python3 - "$port" "$pid" <<'EOF' || code=$?
import os, sys, time, urllib.request, urllib.error
port, pid = sys.argv[1], int(sys.argv[2])
base = f"http://127.0.0.1:{port}"
deadline = time.monotonic() + 120
while True:
    try:
        with urllib.request.urlopen(f"{base}/liveness?endpoint=/app", timeout=10) as r:
            status = r.status
    except (urllib.error.URLError, OSError) as error:
        status = getattr(error, "code", None) or str(error)
    if status == 200:
        break
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        sys.exit(f"build_image.sh: the server exited before it answered (last: {status})")
    if time.monotonic() > deadline:
        sys.exit(f"build_image.sh: liveness endpoint never answered 200 (last: {status})")
    time.sleep(0.5)
with urllib.request.urlopen(f"{base}/app", timeout=30) as r:
    page = r.read().decode()
if "docs_json" not in page or "Bokeh" not in page:
    sys.exit("build_image.sh: /app answered but holds no Bokeh document")
print(f"build_image.sh: liveness 200 and /app with a Bokeh document ({len(page)} bytes)", file=sys.stderr)
EOF
    if [ "$code" -eq 0 ]; then
        say "first liveness 200 after $(elapsed "$t0") s"
        local hc=()
        while IFS= read -r -d '' word; do hc+=("$word"); done < <(image_words healthcheck; printf '\0')
        if buildah run --isolation chroot --env "BOGIE_PORT=$port" "$(container_name "$port")" -- "${hc[@]}"; then
            say "the image's HEALTHCHECK command passes inside the container"
        else
            say "the image's HEALTHCHECK command FAILED inside the container"; code=1
        fi
    fi
    kill -INT -- "-$pid" 2>/dev/null || true
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.2; done
    kill -KILL -- "-$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
    trap - EXIT
    [ "$code" -eq 0 ] && say "check passed" || say "check FAILED"
    return "$code"
}

case "${1:-}" in
    base) preflight "$@"; make_base ;;
    build) preflight "$@"; build ;;
    serve) preflight "$@"; serve "${2:-}" ;;
    check) preflight "$@"; check "${2:-}" ;;
    *) sed -n '2,9p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2 ;;
esac
