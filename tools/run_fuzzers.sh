#!/usr/bin/env bash
# Builds softgl's libFuzzer targets with clang, AddressSanitizer and UndefinedBehaviorSanitizer,
# and runs each for a bounded time over its committed corpus.
#   tools/run_fuzzers.sh [seconds per target, default 60]
# Needs clang-14 and libclang-rt-14-dev (Debian). New inputs go to a temporary directory; a crash
# leaves its input in build/fuzz/ and makes this script fail.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
CXX="${CXX:-clang++-14}"
out=build/fuzz
mkdir -p "$out"
flags="-std=c++17 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined -ffp-contract=off -Icpp"
# The compiler and what it stands on: glsl uses only core (docs/architecture.md, "Layers").
glsl_sources=$(ls cpp/softgl/glsl/*.cpp cpp/softgl/core/*.cpp)
if [ ! -x "$out/glsl_compile_fuzzer" ] || [ -n "$(find cpp/softgl/glsl cpp/softgl/core cpp/fuzz -newer "$out/glsl_compile_fuzzer" -name '*.[ch]*' | head -1)" ]; then
    echo "building glsl_compile_fuzzer ..."
    $CXX $flags cpp/fuzz/glsl_compile_fuzzer.cpp $glsl_sources -o "$out/glsl_compile_fuzzer"
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp tests/glsl/fuzz_corpus/* "$work/"   # byte 0: stage (bit 0) and WebGL version (bit 1)
echo "fuzzing the GLSL compiler for ${seconds}s ..."
(cd "$out" && ./glsl_compile_fuzzer -max_total_time="$seconds" -max_len=4096 -timeout=10 -rss_limit_mb=2048 \
    -print_final_stats=1 "$work" 2>&1 | grep -E "^#[0-9]+.*(DONE|pulse)|stat::number_of_executed_units|stat::peak_rss|ERROR|SUMMARY" | tail -6)

# Optional: the WebGL command-stream fuzzer (tests/fuzz_api) on a Python module built with
# ASan+UBSan (tools/build_asan_module.sh; the first build takes several minutes), for
# SOFTGL_FUZZ_API_MINUTES minutes. Not run by CI by default (the pytest suite runs the same fuzzer,
# unsanitized and bounded); set the variable for a sanitized run, e.g.
#   SOFTGL_FUZZ_API_MINUTES=10 tools/run_fuzzers.sh 60
# A crash, hang or contract violation prints its seed; replay one with
#   $ASAN_PY tools/fuzz_api.py --seed SEED --steps 1000
if [ -n "${SOFTGL_FUZZ_API_MINUTES:-}" ]; then
    echo "building the sanitized module ..."
    eval "$(tools/build_asan_module.sh)"
    echo "fuzzing the WebGL command stream under ASan+UBSan for ${SOFTGL_FUZZ_API_MINUTES} min ..."
    $ASAN_PY tools/fuzz_api.py --minutes "$SOFTGL_FUZZ_API_MINUTES" --steps 1000 --first-seed "${SOFTGL_FUZZ_API_SEED:-0}"
fi
