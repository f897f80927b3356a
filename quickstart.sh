#!/usr/bin/env bash
# softgl quickstart: installs everything on a fresh Debian/Ubuntu machine, then runs a job.
#   ./quickstart.sh showcase   render the showcase images and print where they are
#   ./quickstart.sh test       run the whole test suite
set -euo pipefail
cd "$(dirname "$0")"
job="${1:-showcase}"
shift || true

# System packages: GLM (C++ math headers) for the build; Mesa's EGL/GLES (llvmpipe), the speed
# reference the benchmarks and their tests compare against.
SYSTEM_PACKAGES="libglm-dev g++ cmake python3-venv libegl1 libgles2 libegl-mesa0 libgl1-mesa-dri"
if ! dpkg -s $SYSTEM_PACKAGES >/dev/null 2>&1; then
    SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
    $SUDO apt-get update -qq
    $SUDO apt-get install -y -qq $SYSTEM_PACKAGES >/dev/null
fi

# Python packages and the build, in a virtual environment of the repository's own.
if [ ! -x .venv/bin/python ]; then
    python3 -m venv .venv
fi
.venv/bin/python -m pip install -q ".[test]"

case "$job" in
    showcase) exec .venv/bin/python -m softgl.showcase "$@" ;;
    test)     exec .venv/bin/python -m pytest -q "$@" ;;
    *)        echo "usage: $0 showcase|test" >&2; exit 2 ;;
esac
