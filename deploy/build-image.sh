#!/usr/bin/env bash
# Build the linecrew image (default linecrew:dev) without pulling anything:
#  1. a wheelhouse of the project and its dependencies on the host
#     (deploy/wheels; pip on the host reaches the package index, pip inside
#     a container here cannot verify TLS);
#  2. docker build --network none, installing from that wheelhouse only.
# The base is python:3.11-slim if this engine has it, else the local
# local/python-base:bookworm (built by deploy/build-base-image.sh if missing).
# Environment: LINECREW_IMAGE (tag), LINECREW_BASE_IMAGE (force a base),
# PYTHON (the host Python 3.11 that builds the wheels; default .venv/bin/python
# if there is one, else python3).
set -euo pipefail
cd "$(dirname "$0")/.."

IMAGE="${LINECREW_IMAGE:-linecrew:dev}"
if [[ -z "${PYTHON:-}" ]]; then
    if [[ -x .venv/bin/python ]]; then PYTHON=.venv/bin/python; else PYTHON=python3; fi
fi
# The wheels must fit the image's CPython 3.11 (compiled ones are cp311).
if ! "$PYTHON" -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))'; then
    echo "build-image: $PYTHON is not Python 3.11; set PYTHON=/path/to/python3.11" >&2
    exit 1
fi
WHEELS=deploy/wheels

if [[ -n "${LINECREW_BASE_IMAGE:-}" ]]; then
    BASE="$LINECREW_BASE_IMAGE"
elif docker image inspect python:3.11-slim >/dev/null 2>&1; then
    BASE=python:3.11-slim
else
    BASE=local/python-base:bookworm
fi
if [[ "$BASE" == local/python-base:bookworm ]]; then
    LINECREW_BASE_IMAGE="$BASE" bash deploy/build-base-image.sh
fi

echo "build-image: wheelhouse in $WHEELS"
mkdir -p "$WHEELS"
rm -f "$WHEELS"/linecrew-*.whl # always this checkout's code
"$PYTHON" -m pip wheel -q --disable-pip-version-check -w "$WHEELS" . "setuptools>=61" wheel
# pip wheel leaves a build/ tree behind; it is ignored by git.

echo "build-image: docker build $IMAGE from $BASE"
previous=$(docker image inspect -f '{{.Id}}' "$IMAGE" 2>/dev/null || true)
docker build --network none --build-arg BASE_IMAGE="$BASE" \
    --label org.opencontainers.image.title=linecrew \
    -f deploy/Dockerfile -t "$IMAGE" deploy
# The build this one replaces, unless a container still uses it (rmi refuses).
current=$(docker image inspect -f '{{.Id}}' "$IMAGE")
if [[ -n "$previous" && "$previous" != "$current" ]]; then
    docker rmi "$previous" >/dev/null 2>&1 || true
fi
echo "build-image: built $IMAGE"
