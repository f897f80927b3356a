#!/usr/bin/env bash
# Builds softgl's Python module with clang, AddressSanitizer and UndefinedBehaviorSanitizer into
# build/asan/, with a venv (build/asan/venv, system site-packages, no softgl installed) whose
# softgl package is python/softgl plus the sanitized _core. Prints the command prefix that runs
# Python under the sanitizers:
#   eval "$(tools/build_asan_module.sh)"; $ASAN_PY tools/fuzz_api.py --minutes 10
# Needs clang-14 and libclang-rt-14-dev (Debian).
set -euo pipefail
cd "$(dirname "$0")/.."
CXX="${CXX:-clang++-14}"
PY="${PYTHON:-python3}"
out=build/asan
mkdir -p "$out"
pybind11_dir=$("$PY" -c "import pybind11; print(pybind11.get_cmake_dir())")
if [ ! -f "$out/build.ninja" ]; then
    cmake -S . -B "$out" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER="$CXX" \
        -DPython_EXECUTABLE="$(command -v "$PY")" -Dpybind11_DIR="$pybind11_dir" \
        -DCMAKE_CXX_FLAGS="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer" \
        -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined -shared-libasan" >&2
fi
cmake --build "$out" --target _core >&2
pkg="$out/pkg/softgl"
mkdir -p "$pkg"
for f in python/softgl/*.py; do ln -sf "$PWD/$f" "$pkg/"; done
ln -sf "$PWD/$out/"_core*.so "$pkg/"
if [ ! -x "$out/venv/bin/python" ]; then
    base=$("$PY" -c "import sys; print(sys._base_executable)")
    "$base" -m venv --system-site-packages --without-pip "$out/venv" >&2
fi
asan_rt=$("$CXX" -print-file-name=libclang_rt.asan-x86_64.so)
echo "export ASAN_PY=\"env LD_PRELOAD=$asan_rt ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 PYTHONPATH=$PWD/$out/pkg:$PWD/tests/fuzz_api $PWD/$out/venv/bin/python\""
